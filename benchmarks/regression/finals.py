"""Final states of every method of methods/ on every built-in problem after 10⁵ steps (compiled
float64, the exact start, max |H − H₀| over the run): a regression record of one version of the
step loop, to compare two versions.  A script, not a test.

    python benchmarks/regression/finals.py OUT.json [--steps N] [--perturb] [--precision dd] [--cases C.json]
    python benchmarks/regression/finals.py --compare A.json B.json [--dd DD.json]

``--perturb`` starts from y₀(1 + u), u the unit round-off: the difference to the unperturbed
finals is how far one rounding error reaches after 10⁵ steps (tests/test_regression.py
compares two versions against it).

Run it once with the previous version first on PYTHONPATH (a git worktree of that commit), once
with this one; ``--compare`` prints, per case, max |Δy| / max |y| of the finals and the two
max |H − H₀|.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mpmath
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
STEP = {"harmonic": "1/100", "pendulum": "1/100", "kepler": "1/100", "kepler_unperturbed": "1/100",
        "henon_heiles": "1/100", "fpu": "1/1000", "outer_solar_system": "10"}


def record(out, steps, perturb=False, precision="float64", cases=None):
    import sympy as sp

    from tableau_lab.experiments.runs import prepare_run
    from tableau_lab.numeric.integrate import IntegrationError, integrate
    rows = {}
    for path in sorted((ROOT / "methods").glob("*.json")):
        for problem, h in STEP.items():
            key = f"{path.stem} {problem}"
            if cases is not None and key not in cases:
                continue
            try:
                _, _, cp, nm = prepare_run(str(path), problem, precision, None)
                y0 = cp.y0 * (1 + np.finfo(float).eps) if perturb else cp.y0      # one ulp: round-off's reach
                run = integrate(nm, cp, y0, sp.Rational(h), steps, invariants=("H",), record_every=steps,
                                kernel="compiled" if precision == "float64" else "auto")
                rows[key] = {"final": [float(x) if precision == "float64" else mpmath.nstr(x, 34) for x in run.final],
                             "H": run.max_invariant_error()["H"],
                             "nfev": run.nfev}
            except (IntegrationError, ValueError) as exc:
                rows[key] = {"failed": str(exc)[:200]}
            print(key, rows[key].get("H", rows[key].get("failed")), flush=True)
    Path(out).write_text(json.dumps(rows, indent=1))


def compare(a, b, dd=None):
    A, B = json.loads(Path(a).read_text()), json.loads(Path(b).read_text())
    worst = 0.0
    for key in A:
        x, y = A[key], B.get(key, {})
        if "final" in x and "final" in y:
            fa, fb = np.array(x["final"]), np.array(y["final"])
            rel = float(np.max(np.abs(fa - fb)) / max(np.max(np.abs(fa)), 1e-300))
            if np.all(np.isfinite(fa)):
                worst = max(worst, rel)
            print(f"{key:42s} rel {rel:.2e}  maxH {x['H']:.3e} / {y['H']:.3e}  nfev/step {x['nfev'] / 1e5:.2f} / "
                  f"{y['nfev'] / 1e5:.2f}")
        else:
            print(f"{key:42s} {str(x.get('failed', ''))[:60]!r} / {str(y.get('failed', ''))[:60]!r}")
    print("largest relative difference of finite finals:", f"{worst:.2e}")
    if dd:                                  # both against the double-double run of the same method
        D = json.loads(Path(dd).read_text())
        errs = []
        for key in D:
            exact = np.array([float(x) for x in D[key]["final"]])
            fa, fb = np.array(A[key]["final"]), np.array(B[key]["final"])
            scale = np.max(np.abs(fa))
            errs.append((key, np.max(np.abs(fa - exact)) / scale, np.max(np.abs(fb - exact)) / scale))
        for key, ea, eb in errs:
            print(f"{key:42s} distance to double-double {ea:.2e} (A) / {eb:.2e} (B)")
        print(f"B closer to double-double in {sum(eb < ea for _, ea, eb in errs)} of {len(errs)}; median distance "
              f"A {np.median([e[1] for e in errs]):.1e}, B {np.median([e[2] for e in errs]):.1e}; "
              f"B within 5x of A in {sum(eb <= 5 * ea for _, ea, eb in errs)}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("out", nargs="?")
    ap.add_argument("--steps", type=int, default=10 ** 5)
    ap.add_argument("--compare", nargs=2)
    ap.add_argument("--dd", help="with --compare: finals of the same methods in double-double, to measure both against")
    ap.add_argument("--perturb", action="store_true", help="start from y0 (1 + u): how far round-off reaches")
    ap.add_argument("--precision", default="float64", help="float64 or dd (finals as 32-digit strings)")
    ap.add_argument("--cases", help="a JSON file with a list of 'method problem' keys (default: all)")
    args = ap.parse_args()
    cases = set(json.loads(Path(args.cases).read_text())) if args.cases else None
    if args.compare:
        sys.exit(compare(*args.compare, args.dd))
    sys.exit(record(args.out, args.steps, args.perturb, args.precision, cases))
