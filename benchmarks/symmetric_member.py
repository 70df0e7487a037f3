"""An exact member of GLM43's G-symplectic DIRK family with symmetric output rows (issue 18).

Structure (docs/design.md, "The moonshot"): s = 4, r = 3, V the rotation by 2π/3,
G = diag(1, −1/4, −1/4), B = [d₁, ½ − d₁, ½ − d₁, d₁; b₂₁, x, −x, −b₂₁; 0, y, −y, 0] (the rotation
gauge puts b₃₁ = 0), A and U from ``analysis.family.dirk_stages``.  For rational d₁, b₂₁ the order-4
conditions with θ ≡ 0 and μ = 0 leave x and y: ``analysis.design.solve`` finds them exactly (in
nested square roots), and the member is then verified by the ordinary analyses and saved.

    python benchmarks/symmetric_member.py [--save OUT] [--name LABEL] -- D1 B21
    python benchmarks/symmetric_member.py --family methods/design/glm4_symmetric_family.json
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import sympy as sp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tableau_lab.analysis.design import solve  # noqa: E402
from tableau_lab.analysis.family import dirk_stages, glm43_structure  # noqa: E402
from tableau_lab.exact.grammar import parse_entry  # noqa: E402
from tableau_lab.exact.methods import GeneralLinearMethod  # noqa: E402
from tableau_lab.exact.tableau_json import save  # noqa: E402

REQUIREMENTS = ("identity-start-order=4", "parasitism-free")
FAMILY_NOTE = ("G-symplectic for every d1, b21, x, y (D = diag(B[0]), A and U from analysis.family.dirk_stages); "
               "GLM43 is the member d1 = -169/3360, b21 = 2*d1, x = -84839/283920, y = -43*sqrt(14595)/35490. "
               "Search it with tableau-lab design (no --require) under --constrain order=4,parasitism-free,...")
SOURCE = ("tableau_lab, issue 18 (docs/design.md, \"The moonshot\"): GLM43's G-symplectic DIRK structure "
          "(the seed thesis §3.2.3) with symmetric output rows, solved exactly by benchmarks/symmetric_member.py")


def structure(d1, b21, x, y) -> GeneralLinearMethod:
    V, G = glm43_structure()
    half = sp.Rational(1, 2)
    B = sp.Matrix([[d1, half - d1, half - d1, d1], [b21, x, -x, -b21], [0, y, -y, 0]])
    A, U = dirk_stages(B, G, V, sp.zeros)
    return GeneralLinearMethod(A=sp.ImmutableMatrix(A.applyfunc(sp.cancel)),
                               U=sp.ImmutableMatrix(U.applyfunc(sp.cancel)),
                               B=sp.ImmutableMatrix(B), V=V, name="symmetric member")


def member(d1, b21):
    """The exact members (x, y > 0 real) for rational d1, b21, as (x, y, method)."""
    x, y = sp.symbols("x y", real=True)
    res = solve(structure(d1, b21, x, y), list(REQUIREMENTS))
    out = []
    for sol in res.solutions:
        if sol.real and not sol.free and sp.N(sol.parameters["y"]) > 0:
            X, Y = sol.parameters["x"], sol.parameters["y"]
            out.append((X, Y, structure(d1, b21, X, Y)))
    return out


def main(argv=None):
    from dataclasses import replace

    from tableau_lab.analysis.order import order
    from tableau_lab.analysis.parasitism import growth_parameters
    from tableau_lab.analysis.symplectic import g_symplectic
    from tableau_lab.numeric.objectives import NumericGLM, imaginary_interval, real_interval, series_defects
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("d1", nargs="?")
    ap.add_argument("b21", nargs="?")
    ap.add_argument("--save", metavar="OUT")
    ap.add_argument("--name", default=None, metavar="LABEL", help="a short label put before the descriptive name")
    ap.add_argument("--family", metavar="OUT",
                    help="write the family (d1, b21, x, y unknown) as a design tableau and stop")
    args = ap.parse_args(argv)
    if args.family:
        d1, b21, x, y = sp.symbols("d1 b21 x y")
        save(replace(structure(d1, b21, x, y), name="GLM43's G-symplectic DIRK structure with symmetric output rows",
                     source=SOURCE, notes=(FAMILY_NOTE,)), args.family)
        print(f"saved {args.family}")
        return
    if args.d1 is None or args.b21 is None:
        ap.error("D1 and B21 are required (or --family OUT)")
    d1, b21 = parse_entry(args.d1), parse_entry(args.b21)
    t0 = time.perf_counter()
    found = member(d1, b21)
    if not found:
        sys.exit(f"no real member with y > 0 at d1 = {d1}, b21 = {b21}")
    for X, Y, m in found:
        o, gs, mu = order(m, max_order=5), g_symplectic(m), growth_parameters(m)
        g = NumericGLM.of(m)
        print(f"d1 = {d1}, b21 = {b21}\nx = {X}\ny = {Y}")
        print(f"order {o.order}, with θ ≡ 0: {o.order_identity_start}; G-symplectic: {gs.holds}; "
              f"μ = {[i.mu for i in mu.items]}")
        print(f"numeric: Y* = {imaginary_interval(g):.6f}, X* = {real_interval(g):.4g}, "
              f"error norm = {series_defects(g, 4)[1]:.6g}  ({time.perf_counter() - t0:.1f} s)")
        if args.save and o.order_identity_start >= 4 and gs.holds and mu.free:
            claims = {"g_symplectic": True, "order": o.order, "identity_start_order": o.order_identity_start,
                      "parasitism_free": True}
            title = f"G-symplectic, parasitism-free DIRK GLM, symmetric output rows (d1 = {d1}, b21 = {b21})"
            save(replace(m, name=f"{args.name}: {title}" if args.name else title,
                         claims=tuple(sorted(claims.items())), source=SOURCE,
                         notes=(f"benchmarks/symmetric_member.py {args.d1} {args.b21}: GLM43's structure with "
                                f"symmetric output rows; x, y solved exactly for {', '.join(REQUIREMENTS)}.",)),
                 args.save)
            print(f"saved {args.save}")
            break


if __name__ == "__main__":
    main()
