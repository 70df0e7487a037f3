"""The moonshot member (issue 18): a G-symplectic, parasitism-free, diagonally implicit GLM of order 4
with the identity start and exact Y* ≥ 2 — six stages, GLM43's V and G, symmetric output rows.

Structure (docs/design.md, "The moonshot"): s = 6, r = 3, V the rotation by 2π/3, G = diag(1, −1/4, −1/4),

    B = [d₁, d₂, d₃, d₃, d₂, d₁;  λ·(c₁, c₂, c₃, −c₃, −c₂, −c₁);  λ·(0, c₄, c₅, −c₅, −c₄, 0)],  d₃ = ½ − d₁ − d₂,

A and U from ``analysis.family.dirk_stages`` (G-symplectic identically).  μ = 0 is homogeneous in the
rows 2–3, so it holds for every λ once the rational point c lies on the μ-cone
Σⱼ |βⱼ|²/dⱼ = 0 (βⱼ = b₂ⱼ + i b₃ⱼ).  With the symmetric rows the order conditions with θ ≡ 0 up to
order 4 reduce to one, the order-3 residual, a quadratic in λ²: λ is a nested square root.

    python benchmarks/moonshot_member.py [--save OUT] [--stability] [-- D1 D2 c1,c2,c3[,c4,c5]]

Defaults: d₁ = −4/15, d₂ = 1/2, c = (6851, −8265, 3241, 0, 0) (found by a float64 search with a fine
Y* grid, then a rational point of small height on the μ-cone; row 3 = 0).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import sympy as sp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tableau_lab.analysis.family import dirk_stages, glm43_structure  # noqa: E402
from tableau_lab.analysis.glm_order import order_conditions  # noqa: E402
from tableau_lab.exact.field import field_of  # noqa: E402
from tableau_lab.exact.grammar import parse_entry  # noqa: E402
from tableau_lab.exact.methods import GeneralLinearMethod  # noqa: E402

DEFAULT = ("-4/15", "1/2", "6851,-8265,3241,0,0")
SOURCE = ("tableau_lab, issue 18 (docs/design.md, \"The moonshot\"): GLM43's G-symplectic DIRK structure "
          "(the seed thesis §3.2.3) with six stages and symmetric output rows, solved exactly by "
          "benchmarks/moonshot_member.py")


def structure(d1, d2, c, lam) -> GeneralLinearMethod:
    V, G = glm43_structure()
    d3 = sp.Rational(1, 2) - d1 - d2
    c1, c2, c3, c4, c5 = c
    B = sp.Matrix([[d1, d2, d3, d3, d2, d1], [lam * c1, lam * c2, lam * c3, -lam * c3, -lam * c2, -lam * c1],
                   [0, lam * c4, lam * c5, -lam * c5, -lam * c4, 0]])
    A, U = dirk_stages(B, G, V, sp.zeros)

    def simplify(e):
        return sp.radsimp(sp.expand(e))
    return GeneralLinearMethod(A=sp.ImmutableMatrix(A.applyfunc(simplify)), U=sp.ImmutableMatrix(U.applyfunc(simplify)),
                               B=sp.ImmutableMatrix(B), V=V, name="six-stage member")


def mu_cone(d1, d2, c) -> sp.Expr:
    """Σⱼ |βⱼ|²/dⱼ for rows 2–3 = c (zero: μ = 0 for every λ)."""
    d3 = sp.Rational(1, 2) - d1 - d2
    c1, c2, c3, c4, c5 = c
    return 2 * (c1 ** 2 / d1 + (c2 ** 2 + c4 ** 2) / d2 + (c3 ** 2 + c5 ** 2) / d3)


def lambdas(d1, d2, c) -> list:
    """The positive real λ with order 4 (θ ≡ 0): roots of the order conditions, a polynomial in λ²."""
    lam, L2 = sp.Symbol("lam"), sp.Symbol("L2")
    m = structure(d1, d2, c, lam)
    K = field_of(list(m.matrices().values()))
    polys = [sp.Poly(sp.numer(sp.together(K.to_sympy(e))), lam) for _, e in order_conditions(m, 4, K, free_theta=False)]
    polys = [p for p in polys if not p.is_zero]
    g = polys[0]
    for p in polys[1:]:
        g = sp.gcd(g, p)
    if g.degree() < 1:
        return []
    coeffs = g.all_coeffs()[::-1]
    if any(coeffs[k] != 0 for k in range(1, len(coeffs), 2)):
        raise ValueError("the order conditions are not even in λ")
    q = sp.Poly(sum(coeffs[2 * k] * L2 ** k for k in range(len(coeffs) // 2 + 1)), L2)
    out = []
    for r in sp.solve(q.as_expr(), L2):
        v = complex(sp.N(r, 30))
        if abs(v.imag) < 1e-25 and v.real > 0:
            out.append(sp.sqrt(sp.radsimp(r)))
    return out


def main(argv=None) -> int:
    from dataclasses import replace

    import numpy as np

    from tableau_lab.analysis.order import order
    from tableau_lab.analysis.parasitism import growth_parameters
    from tableau_lab.analysis.symplectic import g_symplectic
    from tableau_lab.exact.tableau_json import save
    from tableau_lab.numeric.objectives import NumericGLM, real_interval, series_defects
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("params", nargs="*", metavar="D1 D2 C", help="d1, d2 and c1,c2,c3[,c4,c5] (exact)")
    ap.add_argument("--save", metavar="OUT")
    ap.add_argument("--name", default="GLM6M", metavar="LABEL")
    ap.add_argument("--stability", action="store_true", help="the exact Y* too")
    args = ap.parse_args(argv)
    d1s, d2s, cs = args.params or DEFAULT
    d1, d2 = parse_entry(d1s), parse_entry(d2s)
    c = [parse_entry(v) for v in cs.split(",")]
    c += [sp.S.Zero] * (5 - len(c))
    t0 = time.perf_counter()
    if mu_cone(d1, d2, c) != 0:
        sys.exit(f"c = {c} is not on the μ-cone for d1 = {d1}, d2 = {d2}: Σ|β|²/d = {mu_cone(d1, d2, c)}")
    for lam in lambdas(d1, d2, c):
        m = structure(d1, d2, c, lam)
        g = NumericGLM.of(m)
        if np.min(np.diag(g.A)) < 0:
            print(f"λ = {lam}: a negative diagonal entry, skipped")
            continue
        o, gs, mu = order(m, max_order=5), g_symplectic(m), growth_parameters(m)
        print(f"d1 = {d1}, d2 = {d2}, c = {c}\nλ = {lam}")
        print(f"order {o.order}, with θ ≡ 0: {o.order_identity_start}; G-symplectic: {gs.holds}; "
              f"μ = {[i.mu for i in mu.items]}")
        print(f"min a_ii = {np.min(np.diag(g.A)):.6f}, error norm = {series_defects(g, 4)[1]:.6g}, "
              f"X* = {real_interval(g):.4g} (float64)  "
              f"({time.perf_counter() - t0:.1f} s)")
        if args.stability:
            from tableau_lab.analysis.stability import stability
            st = stability(m)
            print(f"exact Y* = {sp.N(st.bounded_radius, 15)}  ({time.perf_counter() - t0:.1f} s)")
        if args.save and o.order_identity_start >= 4 and gs.holds and mu.free:
            claims = {"g_symplectic": True, "order": o.order, "identity_start_order": o.order_identity_start,
                      "parasitism_free": True}
            title = f"G-symplectic, parasitism-free DIRK GLM, s = 6, symmetric output rows (d1 = {d1}, d2 = {d2})"
            c_nodes = sp.ImmutableMatrix([[sp.radsimp(sp.expand(sum(m.A.row(i))))] for i in range(m.A.rows)])
            save(replace(m, c=c_nodes, name=f"{args.name}: {title}", claims=tuple(sorted(claims.items())),
                         source=SOURCE,
                         notes=(f"benchmarks/moonshot_member.py -- {d1s} {d2s} {cs}: rows 2-3 = λ·c with c on the "
                                "μ-cone; λ² a root of the order-3 condition (θ ≡ 0), a quadratic in λ².",)),
                 args.save)
            print(f"saved {args.save}")
        return 0
    sys.exit("no real λ with a nonnegative diagonal")


if __name__ == "__main__":
    raise SystemExit(main())
