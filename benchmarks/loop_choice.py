"""The constants of the loop choice (``limits.choose_loop``, ``integrate(..., kernel="auto")`` from
Python), measured: a script, not a test.

1. The pure (Python) float64 loop's seconds per step (median of 3 runs of 300 steps) for
   explicit and implicit Runge–Kutta methods and a GLM on problems of dimension 2 and 4, beside
   ``limits.python_step_seconds``'s prediction (``PYTHON_STAGE_SECONDS``,
   ``PYTHON_COMPONENT_SECONDS``, ``PYTHON_IMPLICIT_FACTOR``).
2. A pendulum callable (np.sin), traced, Gauss 2, 40 000 steps: the compiled loop in a fresh
   process with an empty cache folder (its ``compile_seconds``: ``COMPILE_COLD_SECONDS``), again
   in another process with that folder (a load from numba's disk cache:
   ``COMPILE_CACHED_SECONDS``), and the Python loop in this one; the final states compared.
3. What ``numba.njit`` of an untraceable callable buys in the Python loop: the same callable run
   as Python with and without it (median of 5 interleaved runs of 2000 Gauss 2 and RK4 steps; trace=False).

Run: python benchmarks/loop_choice.py
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

from tableau_lab.exact.tableau_json import load
from tableau_lab.experiments.user import integrate as user_integrate
from tableau_lab.numeric import limits
from tableau_lab.numeric.codegen import compile_problem
from tableau_lab.numeric.export import to_numeric
from tableau_lab.numeric.integrate import integrate

METHODS = ("explicit_euler", "rk4", "gauss2", "gauss3", "example4_glm")
PROBLEMS = ("pendulum", "kepler")
STEPS = 40_000
FIRST_CALL = f"""
import numpy as np
from tableau_lab.exact.tableau_json import load
from tableau_lab.experiments.user import integrate
def pendulum(t, y):
    return np.array([y[1], -np.sin(y[0])])
r = integrate(load("gauss2"), pendulum, ["1/2", 0], (0, {STEPS} // 100), "1/100", kernel="compiled", notice=False)
print(f"{{r.compile_seconds:.2f}} {{r.seconds:.2f}} {{r.final[0]!r}} {{r.final[1]!r}}")
"""


def python_steps():
    print("1. the pure float64 loop, s/step measured and predicted (limits.python_step_seconds)")
    print(f"{'problem':10} {'d':>2} {'method':15} {'s':>2} {'r':>2} {'µs/step':>8} {'predicted':>9} {'ratio':>6}")
    for prob in PROBLEMS:
        cp = compile_problem(prob)
        d = len(cp.y0)
        for name in METHODS:
            nm = to_numeric(load(name))
            integrate(nm, cp, cp.y0, 0.01, 20, kernel="python")
            times = []
            for _ in range(3):
                t = time.perf_counter()
                integrate(nm, cp, cp.y0, 0.01, 300, kernel="python", record_every=300)
                times.append((time.perf_counter() - t) / 300)
            got, want = statistics.median(times), limits.python_step_seconds(nm.s, nm.r, d, nm.explicit)
            print(f"{prob:10} {d:>2} {name:15} {nm.s:>2} {nm.r:>2} "
                  f"{got * 1e6:>8.0f} {want * 1e6:>9.0f} {got / want:>6.2f}")


def first_calls():
    print(f"2. a traced pendulum callable, Gauss 2, {STEPS} steps: the compiled loop in fresh processes, "
          "then the Python loop")
    with tempfile.TemporaryDirectory() as folder:
        env = dict(os.environ, TABLEAU_LAB_CACHE=folder)
        env.pop("TABLEAU_LAB_SPECIALISE", None)
        finals = []
        for what in ("cold (empty cache)", "cached (numba's disk cache)"):
            out = subprocess.run([sys.executable, "-c", FIRST_CALL], env=env, capture_output=True, text=True,
                                 check=True).stdout.split()
            finals.append(out[2:])
            print(f"   compiled, {what:28} compile_seconds {out[0]} s, steps {out[1]} s")

    def pendulum(t, y):
        return np.array([y[1], -np.sin(y[0])])
    r = user_integrate(load("gauss2"), pendulum, ["1/2", 0], (0, STEPS // 100), "1/100", kernel="python", notice=False)
    same = all(f == [repr(r.final[0]), repr(r.final[1])] for f in finals)
    print(f"   Python loop: steps {r.seconds:.2f} s ({r.seconds / STEPS * 1e6:.0f} µs/step, predicted "
          f"{limits.python_step_seconds(2, 1, 2, False) * 1e6:.0f}); final states the same bit for bit: {same}")
    print(f"   limits: COMPILE_COLD_SECONDS = {limits.COMPILE_COLD_SECONDS}, "
          f"COMPILE_CACHED_SECONDS = {limits.COMPILE_CACHED_SECONDS}")


def njit_in_the_python_loop():
    import numba
    print("3. numba.njit of a callable run in the Python loop (trace=False), µs/step, median of 5 interleaved")

    def pendulum(t, y):
        return np.array([y[1], -np.sin(y[0])])
    fast = numba.njit(pendulum)
    t = time.perf_counter()
    fast(0.0, np.array([0.5, 0.0]))
    print(f"   njit compile of f: {time.perf_counter() - t:.2f} s")
    for name in ("rk4", "gauss2"):
        runs = {pendulum: [], fast: []}
        for _ in range(5):                     # interleaved: a shared machine's load moves both alike
            for fn in runs:
                runs[fn].append(user_integrate(load(name), fn, [0.5, 0], (0, 20), "1/100", trace=False,
                                               notice=False).seconds / 2000 * 1e6)
        plain, jit = statistics.median(runs[pendulum]), statistics.median(runs[fast])
        print(f"   {name:8} plain {plain:6.0f}   njit {jit:6.0f}   njit/plain {jit / plain:.2f}")


if __name__ == "__main__":
    python_steps()
    first_calls()
    njit_in_the_python_loop()
