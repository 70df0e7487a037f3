"""The pure loop with and without its one-line operations written in place (numeric/inliner.py):

    python benchmarks/bench_inliner.py [--rounds 5] [--steps 1000]

Interleaved rounds in one process, the same run (no records but the last) with stepcore's
functions bound as they are and with the inlined text; prints the median seconds of each and
their ratio per case.  A benchmark, not a test (tests/test_inliner.py holds the numbers equal).
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CASES = (("rk4", "kepler"), ("gauss2", "pendulum"), ("glm43", "kepler"), ("gauss3", "henon_heiles"))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--steps", type=int, default=1000)
    args = ap.parse_args()
    from tableau_lab.experiments.runs import prepare_run
    from tableau_lab.numeric import inliner, kernels
    from tableau_lab.numeric.integrate import integrate
    inlined = kernels.inline_functions
    print(f"{'method':8} {'problem':13} {'plain s':>8} {'inlined s':>9} {'ratio':>6}")
    for method, problem in CASES:
        prep = prepare_run(str(ROOT / "methods" / f"{method}.json"), problem, "float64")
        P = prep.compiled
        times: dict = {"plain": [], "inlined": []}
        for _ in range(args.rounds):
            for name, bind in (("plain", inliner.plain_functions), ("inlined", inlined)):
                kernels.inline_functions = bind
                t = time.perf_counter()
                integrate(prep.numeric, P, P.y0, 0.01, args.steps, invariants=tuple(P.problem.invariants),
                          kernel="python", record_every=args.steps)
                times[name].append(time.perf_counter() - t)
        a, b = statistics.median(times["plain"]), statistics.median(times["inlined"])
        print(f"{method:8} {problem:13} {a:8.3f} {b:9.3f} {b / a:6.2f}")
    kernels.inline_functions = inlined
    return 0


if __name__ == "__main__":
    sys.exit(main())
