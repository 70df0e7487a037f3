"""What the invariant tracking costs, and what a cold compile costs: a script, not a test.

For 2-stage Gauss on the pendulum and Kepler, RK4 and 3-stage Gauss on Kepler (float64, h = 0.01,
2·10⁵ steps; best of 5) and 2-stage Gauss in double-double (2·10⁴ steps): µs/step without
invariants, with the invariants tracked every step (the default) and every STRIDE = 4 steps, and
the compile seconds of each (problem, shape) loop into an empty cache (a temporary
TABLEAU_LAB_CACHE unless one is set); then what the stride misses: the two-step leapfrog on FPU,
max |H − H₀| over 10⁵ steps tracked every step and every STRIDE steps.

Run: python benchmarks/track_cost.py
"""
import os
import tempfile

os.environ.setdefault("TABLEAU_LAB_CACHE", tempfile.mkdtemp(prefix="tableau_lab_cold_"))

import sympy as sp

from tableau_lab.exact.tableau_json import load
from tableau_lab.numeric.codegen import compile_problem
from tableau_lab.numeric.export import to_numeric
from tableau_lab.numeric.integrate import integrate

METHODS = os.path.join(os.path.dirname(__file__), "..", "methods")
STRIDE = 4


def best(nm, cp, steps, **kw):
    return min(integrate(nm, cp, cp.y0, sp.Rational(1, 100), steps, record_every=steps, **kw).seconds
               for _ in range(5)) / steps * 1e6


def main():
    print(f"cache: {os.environ['TABLEAU_LAB_CACHE']}")
    print(f"precision  method  problem   compile s  µs/step  tracked every step  every {STRIDE} steps  f-evals/step")
    for prec, cases, steps in [("float64", [("gauss2", "pendulum"), ("gauss2", "kepler"), ("rk4", "kepler"),
                                            ("gauss3", "kepler")], 200000),
                               ("dd", [("gauss2", "pendulum"), ("gauss2", "kepler")], 20000)]:
        for m, prob in cases:
            cp = compile_problem(prob) if prec == "float64" else compile_problem(prob, "mpmath", dps=32)
            nm = to_numeric(load(os.path.join(METHODS, f"{m}.json")), prec)
            first = integrate(nm, cp, cp.y0, sp.Rational(1, 100), 10,
                              kernel="compiled" if prec == "float64" else "auto")
            invs = tuple(cp.problem.invariants)
            plain = best(nm, cp, steps)
            every = best(nm, cp, steps, invariants=invs, track_every=1)
            stride = best(nm, cp, steps, invariants=invs, track_every=STRIDE)
            run = integrate(nm, cp, cp.y0, sp.Rational(1, 100), steps, record_every=steps)
            print(f"{prec:9s}  {m:6s}  {prob:8s}  {first.compile_seconds:9.1f}  {plain:7.3f}  "
                  f"{every:7.3f} (+{100 * (every / plain - 1):3.0f} %)    "
                  f"{stride:7.3f} (+{100 * (stride / plain - 1):3.0f} %)"
                  f"   {run.nfev / steps:.2f}", flush=True)
    cp = compile_problem("fpu")
    nm = to_numeric(load(os.path.join(METHODS, "leapfrog.json")))
    errs = [integrate(nm, cp, cp.y0, sp.Rational(1, 1000), 10 ** 5, invariants=("H",), record_every=10 ** 5,
                      track_every=k).max_invariant_error()["H"] for k in (1, STRIDE)]
    print(f"leapfrog on FPU, 10^5 steps: max |H − H0| {errs[0]:.2e} tracked every step, {errs[1]:.2e} every {STRIDE}")


if __name__ == "__main__":
    main()
