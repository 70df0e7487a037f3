"""Micro-benchmark of the double-double primitives (tableau_lab.numeric.ddmath) and of
generated dd code (ddcode.dd_function: f and Jacobian of the Kepler problem and of the outer
solar system): nanoseconds per operation, measured in numba loops, and the seconds to
generate and compile.  Not a test.  Run: python benchmarks/dd_bench.py [--n N]

Latency: each result feeds the next operation (a dependency chain), as in a scalar
recurrence.  Throughput: independent operations over an array, as in a vector update.
"""
import argparse
import time

import numpy as np
import sympy as sp
from numba import njit

from tableau_lab.numeric.ddcode import dd_function
from tableau_lab.numeric.ddmath import dd_add, dd_add_d, dd_div, dd_get, dd_mul, dd_sin, to_dd_array
from tableau_lab.numeric.problems import get_problem


@njit
def chain_mul(x, y, n):
    for _ in range(n):
        x = dd_mul(x, y)
    return x


@njit
def chain_div(x, y, n):
    for _ in range(n):
        x = dd_div(x, y)
    return x


@njit
def chain_sin(x, n):
    for _ in range(n):
        x = dd_add_d(dd_sin(x), 3.0)     # arguments in [2, 4]: one reduction by pi/2
    return x


@njit
def array_mul(a, b, out):
    for i in range(a.shape[0]):
        r = dd_mul((a[i, 0], a[i, 1]), (b[i, 0], b[i, 1]))
        out[i, 0], out[i, 1] = r


@njit
def array_div(a, b, out):
    for i in range(a.shape[0]):
        r = dd_div((a[i, 0], a[i, 1]), (b[i, 0], b[i, 1]))
        out[i, 0], out[i, 1] = r


@njit
def array_sin(a, out):
    for i in range(a.shape[0]):
        r = dd_sin((a[i, 0], a[i, 1]))
        out[i, 0], out[i, 1] = r


def make_loop(f):
    @njit
    def loop(y, c, out, n):
        acc = (0.0, 0.0)
        for _ in range(n):
            f(y, c, out)
            acc = dd_add(acc, dd_get(out.reshape(-1, 2), 0))
            y[0, 1] += 1e-40        # keep the calls from being hoisted
        return acc
    return loop


def generated(problem, what):
    """(ns per evaluation, seconds to generate and compile) of f or the Jacobian in dd."""
    problem = get_problem(problem)
    args = [problem.state, tuple(problem.parameter_symbols.values())]
    exprs = list(problem.f_expr)
    t = time.perf_counter()
    if what == "jacobian":
        exprs = sp.Matrix(exprs).jacobian(problem.state).tolist()
    f = dd_function(f"{problem.name}_{what}", args, exprs)
    loop = make_loop(f)
    y, c = to_dd_array(problem.initial_state()), to_dd_array(list(problem.parameters.values()))
    out = np.empty((len(exprs), len(exprs[0]), 2) if what == "jacobian" else (len(exprs), 2))
    loop(y, c, out, 1)
    seconds = time.perf_counter() - t
    m = max(1, 20_000_000 // (len(out.reshape(-1)) * 50))
    return best(loop, y, c, out, m) / m * 1e9, seconds


def best(fn, *args, repeat=5):
    fn(*args)                       # compile / warm up
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn(*args)
        times.append(time.perf_counter() - t)
    return min(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2_000_000, help="operations per measurement")
    n = parser.parse_args().n
    rng = np.random.default_rng(0)
    x, y = (1.2345678901234567, 1e-17), (1.0000000123, 3e-25)
    a = np.column_stack([rng.uniform(0.5, 2, n), rng.uniform(-1e-17, 1e-17, n)])
    b = np.column_stack([rng.uniform(0.5, 2, n), rng.uniform(-1e-17, 1e-17, n)])
    s = np.column_stack([rng.uniform(-100, 100, n), rng.uniform(-1e-15, 1e-15, n)])
    out = np.empty_like(a)
    print(f"{'operation':32s} {'latency ns':>11s} {'throughput ns':>14s}")
    rows = [("dd_mul", best(chain_mul, x, y, n), best(array_mul, a, b, out)),
            ("dd_div", best(chain_div, x, y, n), best(array_div, a, b, out)),
            ("dd_sin (|x| <= 100)", best(chain_sin, (3.0, 0.0), n), best(array_sin, s, out))]
    for name, lat, thr in rows:
        print(f"{name:32s} {lat / n * 1e9:11.2f} {thr / n * 1e9:14.2f}")
    print(f"\n{'generated code':32s} {'ns / eval':>11s} {'generate + compile s':>22s}")
    for problem, what in [("kepler", "f"), ("kepler", "jacobian"), ("outer_solar_system", "f"),
                          ("outer_solar_system", "jacobian")]:
        ns, seconds = generated(problem, what)
        print(f"{problem + ' ' + what:32s} {ns:11.1f} {seconds:22.1f}")


if __name__ == "__main__":
    main()
