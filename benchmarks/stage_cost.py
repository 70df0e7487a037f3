"""The constants of the stage-iteration cost model (``limits.iteration_costs``), measured: a
script, not a test.

For each case (method, problem, h) it runs the compiled float64 loop with the stage iteration
forced to fixed point and to simplified Newton and prints κ = h·‖A_q‖∞·ρ(f′(y₀)), the fixed-point
rate the model assumes (κ², the q stages of a separable problem), the sweeps per step of each,
``gap`` = (fixed-point sweeps − 1)·ln(1/rate) (the model's ``START_GAP``: the sweeps are
1 + START_GAP/ln(1/rate)), µs per step of each (median of 3; on a shared machine compare the
two of a row, not rows), the model's operation counts and its choice, and which was faster.
Last, the largest gap and the median Newton sweeps, against ``limits.START_GAP`` and
``limits.NEWTON_SWEEPS``.

Run: python benchmarks/stage_cost.py
"""
import math
import statistics

import numpy as np
import sympy as sp

from tableau_lab.experiments.runs import prepare_run
from tableau_lab.numeric import limits
from tableau_lab.numeric.integrate import integrate, stage_iteration

CASES = [("gauss3", "kepler", "1/100", 50000), ("gauss3", "kepler", "1/25", 50000), ("gauss3", "kepler", "1/10", 50000),
         ("gauss2", "pendulum", "1/10", 50000),
         ("gauss2", "fpu", "1/1000", 10000), ("gauss2", "fpu", "1/100", 10000), ("gauss2", "fpu", "1/50", 10000),
         ("gauss2", "fpu", "1/20", 5000),
         ("gauss2", "outer_solar_system", "50", 1000), ("gauss2", "outer_solar_system", "100", 1000),
         ("gauss3", "outer_solar_system", "100", 1000), ("glm6_moonshot", "fpu", "1/500", 5000),
         ("glm6_moonshot", "outer_solar_system", "100", 500)]
NAMES = {limits.NEWTON: "newton", limits.FIXED: "fixed", limits.SPLIT: "split"}


def timed(nm, cp, h, steps, solver):
    integrate(nm, cp, cp.y0, h, 1, solver=solver, kernel="compiled")     # compile or load the cache
    runs = [integrate(nm, cp, cp.y0, h, steps, record_every=steps, solver=solver, kernel="compiled")
            for _ in range(3)]
    return statistics.median(r.seconds for r in runs) / steps * 1e6, runs[-1]


def main():
    print(f"{'method':<14} {'problem':<19} {'h':>6} {'kappa':>6} {'rate':>7} {'sweeps fp':>9} {'gap':>5} "
          f"{'sweeps N':>8} {'us fp':>8} {'us N':>8} {'ops fp':>8} {'ops N':>8} {'model':>6} {'faster':>6}")
    gaps, newton_sweeps = [], []
    for method, problem, h, steps in CASES:
        _, _, cp, nm = prepare_run(f"methods/{method}.json", problem, "float64", None)
        h = sp.Rational(h)
        d = len(cp.y0)
        rho = float(np.max(np.abs(np.linalg.eigvals(np.asarray(cp.jac(cp.y0), float)))))
        kappa = nm.stage_scale(h) * rho
        separable = cp.problem.separable
        rate = kappa ** 2 if separable else kappa
        us_fp, fp = timed(nm, cp, h, steps, "fixedpoint")
        us_n, nw = timed(nm, cp, h, steps, "newton")
        sw_fp, sw_n = fp.newton_iterations / steps, nw.newton_iterations / steps
        gap = (sw_fp - 1) * math.log(1 / rate) if 0 < rate < 1 and fp.fallbacks == 0 else float("nan")
        if not math.isnan(gap):
            gaps.append(gap)
        newton_sweeps.append(sw_n)
        ops_fp, ops_n = limits.iteration_costs(kappa, separable=separable, s=nm.s, d=d, f_ops=cp.problem.operations,
                                               lower=nm.lower)
        model = NAMES[stage_iteration("auto", nm, cp, cp.y0, h, d)]
        print(f"{method:<14} {problem:<19} {str(h):>6} {kappa:6.3f} {rate:7.4f} {sw_fp:9.2f} {gap:5.1f} {sw_n:8.2f} "
              f"{us_fp:8.3f} {us_n:8.3f} {ops_fp:8.3g} {ops_n:8.3g} {model:>6} "
              f"{'fp' if us_fp < us_n else 'newton':>6}", flush=True)
    print(f"largest gap {max(gaps):.1f} (limits.START_GAP = {limits.START_GAP}); median Newton sweeps "
          f"{statistics.median(newton_sweeps):.2f} (limits.NEWTON_SWEEPS = {limits.NEWTON_SWEEPS})")


if __name__ == "__main__":
    main()
