"""Every exact Runge–Kutta method of NodePy's library read through tableau-lab, its properties
against NodePy's: order, stage order, real and imaginary stability intervals, SSP coefficient,
algebraic stability.  Where the two disagree, an independent check decides: |R(x)| and |R(iy)|
evaluated at 50 digits (mpmath) just inside and just outside each claimed interval end.

    pip install nodepy && python benchmarks/nodepy_compare.py        # writes reports/nodepy/

NodePy is not a dependency of tableau-lab; without it this script says so and stops.
"""
from __future__ import annotations

import importlib.util
import json
import math
import sys
import time
from pathlib import Path

import sympy as sp

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "benchmarks")]

from tableau_lab.analysis.algebraic_stability import algebraic_stability  # noqa: E402
from tableau_lab.analysis.real_interval import real_stability_interval  # noqa: E402
from tableau_lab.analysis.rk_order import rk_order  # noqa: E402
from tableau_lab.analysis.ssp import ssp_coefficient  # noqa: E402
from tableau_lab.analysis.stability import stability, stability_function  # noqa: E402
from tableau_lab.exact.interop import from_nodepy  # noqa: E402
from tableau_lab.exact.methods import MethodError  # noqa: E402
from tableau_lab.files import atomic_write_text  # noqa: E402

TOL = 1e-6          # relative agreement of NodePy's floats with our exact values


def _f(x):
    if x is None:
        return None
    if x == sp.oo or (isinstance(x, float) and math.isinf(x)):
        return math.inf
    return float(x)


def _agree(a, b):
    if a is None or b is None:
        return None
    if math.isinf(a) or math.isinf(b):
        return math.isinf(a) and math.isinf(b)
    return abs(a - b) <= TOL * max(1.0, abs(a), abs(b))


def _modulus(m, z):
    """|R(z)| at 50 digits from the exact stability function (z a Python or sympy number)."""
    N, D, _ = stability_function(m)
    R = N.as_expr() / D.as_expr()
    return abs(sp.N(R.subs(sp.Symbol("z"), z), 50))


def _decide(m, ours, theirs, axis):
    """Which claimed end an independent evaluation supports: |R| at a point between the two
    claims (beyond the finite one when the other is ∞) decides whether the larger holds."""
    if ours is None or theirs is None:
        return ""
    lo, hi = sorted((ours, theirs))
    probe = lo * 1.01 + 0.01 if math.isinf(hi) else (lo + hi) / 2
    point = sp.I * sp.Float(probe, 50) if axis == "imaginary" else -sp.Float(probe, 50)
    right = hi if _modulus(m, point) <= 1 + sp.Float(10) ** -40 else lo
    return "ours" if right == ours else "NodePy"


def _decide_ssp(m, ours, theirs):
    """Kraaijevanger's inequalities evaluated at 50 digits at the larger claim: if they hold there,
    the larger is the coefficient (the feasible set is [0, R])."""
    if ours is None or theirs is None or math.isinf(ours) or math.isinf(theirs):
        return ""
    r = sp.Float(max(ours, theirs), 50)
    s = m.s
    K = sp.zeros(s + 1, s + 1)
    K[:s, :s] = m.A
    K[s, :s] = m.b.T
    Minv = (K * (sp.eye(s + 1) + r * K).inv()).evalf(50)
    tail = (sp.ones(s + 1, 1) - r * Minv * sp.ones(s + 1, 1)).evalf(50)
    holds = all(x >= -sp.Float(10) ** -35 for x in list(Minv) + list(tail))
    larger_is_right = holds
    return "ours" if (ours > theirs) == larger_is_right else "NodePy"


def compare(rkm, name):
    m = from_nodepy(rkm)
    t0 = time.perf_counter()
    r = rk_order(m)
    st = stability(m)
    ours = {"order": r.order, "stage_order": r.stage_order,
            "real_interval": _f(real_stability_interval(m).beta),
            "imaginary_interval": _f(st.imaginary_interval),
            "ssp_coefficient": _f(ssp_coefficient(m).R),
            "algebraically_stable": algebraic_stability(m, a_stable=st.a_stable).holds,
            "embedded_order": None if r.embedded is None else r.embedded.order}
    ours_seconds = time.perf_counter() - t0
    t0 = time.perf_counter()
    theirs = {}
    for key, call in [("order", lambda: rkm.order()), ("stage_order", lambda: rkm.stage_order()),
                      ("real_interval", lambda: rkm.real_stability_interval()),
                      ("imaginary_interval", lambda: rkm.imaginary_stability_interval()),
                      ("ssp_coefficient", lambda: rkm.absolute_monotonicity_radius()),
                      ("algebraically_stable", lambda: bool(rkm.is_algebraically_stable())),
                      ("embedded_order", lambda: rkm.embedded_method.order())]:
        try:
            v = call()
            theirs[key] = v if isinstance(v, bool) else (int(v) if key in ("order", "stage_order", "embedded_order")
                                                         else _f(v))
        except AttributeError:           # e.g. no imaginary_stability_interval for implicit methods
            theirs[key] = "n/a"
        except Exception as exc:         # NodePy fails on some methods: recorded, not fatal
            theirs[key] = f"error: {type(exc).__name__}"
    nodepy_seconds = time.perf_counter() - t0
    verdicts = {}
    for key in ours:
        a, b = ours[key], theirs.get(key)
        if isinstance(b, str) or a is None:
            verdicts[key] = "—"
            continue
        same = (a == b) if key in ("order", "stage_order", "algebraically_stable", "embedded_order") else _agree(a, b)
        if same:
            verdicts[key] = "="
        elif key in ("real_interval", "imaginary_interval"):
            verdicts[key] = "≠ (" + _decide(m, a, b, key.split("_")[0]) + " right)"
        elif key == "ssp_coefficient":
            verdicts[key] = "≠ (" + _decide_ssp(m, a, b) + " right)"
        else:
            verdicts[key] = "≠"
    return {"name": name, "ours": ours, "nodepy": theirs, "verdicts": verdicts,
            "seconds": {"ours": ours_seconds, "nodepy": nodepy_seconds}}


def main(out=ROOT / "reports" / "nodepy"):
    if importlib.util.find_spec("nodepy") is None:
        print("NodePy is not installed: pip install nodepy", file=sys.stderr)
        return 2
    from nodepy_set import rk_methods
    methods, skipped = rk_methods()
    rows = []
    for name, rkm in methods:
        try:
            rows.append(compare(rkm, name))
        except MethodError as exc:          # floating-point coefficients (InexactMethod), an empty tableau
            skipped.append((name, str(exc)))
        print(name, file=sys.stderr, flush=True)
    keys = ["order", "stage_order", "real_interval", "imaginary_interval", "ssp_coefficient", "algebraically_stable",
            "embedded_order"]
    from importlib.metadata import version
    lines = [f"# NodePy {version('nodepy')} (numpy {version('numpy')}) against tableau-lab", "",
             f"{len(rows)} exact methods: the named ones of `nodepy.rk.loadRKM('All')` and the generated "
             f"families SSPRK2/3, SSPIRK1/2/3, extrap, DC, RKC1/2 ({len(skipped)} skipped: floating-point "
             "coefficients, or a size NodePy does not build). Each cell: ours / NodePy's; = agree (to 1e-6 relative "
             "for the floats); ≠ disagree, with the side an independent 50-digit evaluation supports (|R| between the "
             "two claimed interval ends; Kraaijevanger's inequalities at the larger claimed SSP coefficient).", "",
             "| method | " + " | ".join(keys) + " |", "|---|" + "---|" * len(keys)]

    def fmt(v):
        if isinstance(v, float):
            return "∞" if math.isinf(v) else f"{v:.6g}"
        return str(v)

    def cell(r, k):
        a, b = r["ours"][k], r["nodepy"].get(k)
        return f"{fmt(a)} / {fmt(b)} {r['verdicts'][k]}"
    for r in rows:
        lines.append(f"| {r['name']} | " + " | ".join(cell(r, k) for k in keys) + " |")
    counts = {k: sum(1 for r in rows if r["verdicts"][k] == "=") for k in keys}
    both = {k: sum(1 for r in rows if r["verdicts"][k] != "—") for k in keys}
    lines += ["", "Agreement where both give a value: " + ", ".join(f"{k} {counts[k]}/{both[k]}" for k in keys)
              + f" (of {len(rows)} methods; — : NodePy has no value (n/a: no such method for implicit RK "
              "methods) or ours is not computed).", "",
              "Skipped: " + ", ".join(n for n, _ in skipped) + "."]
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / "compare.md", "\n".join(lines) + "\n")
    atomic_write_text(out / "compare.json", json.dumps({"rows": rows, "skipped": skipped}, indent=1, default=str))
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
