"""A hand-written C reference (glm_loop.c, ``gcc -O2``) of the compiled float64 step loop, to
measure the numba kernel against.  A benchmark fixture, not part of the package.

The method and run constants are the arrays of :class:`tableau_lab.numeric.kernels._Pack`
(the very object the numba loop gets), the GLM input vector is ``start_values`` (the exact
start), and the C program runs the same loop as ``kernel_source.LOOP`` (without projection)
with f and the Jacobian written by hand for the pendulum and the perturbed Kepler problem.

    run_c(method_path, problem, h, steps, reps=5) -> dict(us_per_step, final, nfev, newton, ...)
    run_numba(method_path, problem, h, steps, reps=5) -> the same dict, from the numba run_
    c_f_jac(problem, points) -> (f, J) of the hand-written C functions at the points

``final`` is the raw input vector y^[steps] (r × d), not passed through the finishing method.
Timings are the median over ``reps`` whole runs of the step loop alone (C: CLOCK_MONOTONIC
inside the program; numba: perf_counter around the compiled ``run_`` call, compiled before).

Run: python benchmarks/c_reference/c_reference.py [--steps N] [--reps R] [--h H]
"""
from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tableau_lab.exact.tableau_json import load
from tableau_lab.numeric.codegen import compile_problem
from tableau_lab.numeric.export import to_numeric
from tableau_lab.numeric.integrate import _Stepper, component_masks, start_values
from tableau_lab.numeric.kernels import _Pack, kernel_module

__all__ = ["run_c", "run_numba", "c_f_jac", "build", "prepare", "PROBLEMS"]

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
SOURCE = HERE / "glm_loop.c"
BUILD = HERE / "build"
PROBLEMS = ("pendulum", "kepler")          # the problems glm_loop.c has f and J for
EPS = float(np.finfo(float).eps)


def build() -> Path:
    """The compiled glm_loop (``gcc -O2``), cached under build/ by the hash of the source."""
    text = SOURCE.read_bytes()
    digest = hashlib.sha256(text + b"gcc -O2").hexdigest()[:16]
    exe = BUILD / f"glm_loop_{digest}"
    if exe.exists():
        return exe
    BUILD.mkdir(parents=True, exist_ok=True)
    gcc = shutil.which("gcc")
    if gcc is None:
        raise RuntimeError("gcc not found")
    tmp = BUILD / f".glm_loop_{digest}.{os.getpid()}"
    subprocess.run([gcc, "-O2", "-std=c99", "-o", str(tmp), str(SOURCE), "-lm"], check=True)
    os.replace(tmp, exe)                   # atomic: concurrent builds do not see a half-written file
    return exe


def _method_path(method_path) -> Path:
    p = Path(method_path)
    if p.exists():
        return p
    for cand in (ROOT / p, ROOT / "methods" / f"{p}.json", ROOT / "methods" / p):
        if cand.exists():
            return cand
    raise FileNotFoundError(f"method {method_path!r}: no such file (nor under {ROOT / 'methods'})")


class Prepared:
    """What both loops get: the method, the compiled problem, the _Pack arrays, y^[0]."""

    def __init__(self, method_path, problem, h, start="exact", compensated=True):
        if problem not in PROBLEMS:
            raise ValueError(f"glm_loop.c has f and J for {', '.join(PROBLEMS)}, not {problem!r}")
        self.nm = to_numeric(load(str(_method_path(method_path))))
        self.cp = compile_problem(problem)
        self.problem = problem
        d = len(self.cp.y0)
        self.masks = tuple(np.array([float(x) for x in m]) for m in component_masks(self.cp, d))
        self.mod = kernel_module(self.cp.problem)
        # the pure stepper decides Kahan summation, h·s·max|A| and the stage iteration (Newton here)
        stepper = _Stepper(self.nm, self.cp, float(h), d, self.masks, compensated, fixed=False)
        self.pk = _Pack(self.nm, self.cp, float(h), self.masks, (), {}, self.mod, stepper)
        self.Y0 = np.ascontiguousarray(np.asarray(start_values(self.nm, self.cp, self.cp.y0, float(h), start), dtype=float))


def prepare(method_path, problem, h, start="exact", compensated=True) -> Prepared:
    return Prepared(method_path, problem, h, start, compensated)


def _line(key, values) -> str:
    values = np.asarray(values, dtype=float).reshape(-1)
    return f"{key} {values.size} " + " ".join(f"{float(x):.17g}" for x in values)


def _input_text(pr: Prepared, steps, reps, mode=0, Y=None) -> str:
    pk = pr.pk
    Aq, Ap, U, Bq, Bp, V = pk.mats
    Y = pr.Y0 if Y is None else np.asarray(Y, dtype=float)
    d = Y.shape[-1]
    rows = Y.shape[0] if Y.ndim == 2 else 1
    lines = [f"problem {pr.problem}",
             _line("dims", [pk.s, rows if mode == 1 else pk.r, d, reps]),
             _line("steps", [steps]), _line("mode", [mode]),
             _line("h", [pk.h]), _line("eps", [EPS]), _line("hA", [pk.hA]),
             _line("flags", pk.flags[:5]), _line("c", pk.c if pk.c.size else [0.0]),
             _line("Aq", Aq), _line("Ap", Ap), _line("U", U), _line("Bq", Bq), _line("Bp", Bp), _line("V", V),
             _line("mq", pk.mq), _line("mp", pk.mp), _line("E", pk.E), _line("Aqi", pk.Aqi), _line("Api", pk.Api),
             _line("Y", Y)]
    if mode == 1:          # U, Bq, ... are sized for r rows: leave them out of a point evaluation
        lines = [ln for ln in lines if ln.split()[0] in ("problem", "dims", "steps", "mode", "c", "Y")]
    return "\n".join(lines) + "\n"


def _run_exe(text: str) -> dict:
    exe = build()
    with tempfile.NamedTemporaryFile("w", suffix=".txt", prefix="glm_input_", delete=False) as fh:
        fh.write(text)
        path = fh.name
    try:
        out = subprocess.run([str(exe), path], check=True, capture_output=True, text=True).stdout
    finally:
        os.unlink(path)
    parsed: dict = {}
    for ln in out.splitlines():
        key, *rest = ln.split()
        parsed.setdefault(key, []).append(rest)
    return parsed


def run_c(method_path, problem, h, steps, reps=5, *, start="exact", compensated=True, check_status=True) -> dict:
    """The C loop: ``reps`` whole runs of ``steps`` steps from y^[0]; the median time.
    Returns dict(us_per_step (median), us_per_step_min, final (r × d), nfev, newton, seconds
    (median), seconds_all, status, completed).  status 1 (simplified Newton failed) / 2 (non-finite) raise RuntimeError unless
    ``check_status=False`` (the numba driver would redo a status-1 step on the pure path)."""
    pr = prepare(method_path, problem, h, start, compensated)
    out = _run_exe(_input_text(pr, int(steps), int(reps)))
    status, completed = int(out["status"][0][0]), int(out["completed"][0][0])
    if status != 0 and check_status:
        why = "simplified Newton did not converge" if status == 1 else "the state is not finite"
        raise RuntimeError(f"{method_path} on {problem}: the C loop stopped at step {completed + 1}: {why}")
    seconds = float(out["seconds"][0][0])
    times = [float(x) for x in out["seconds_all"][0][1:]]
    return dict(us_per_step=seconds / steps * 1e6, us_per_step_min=min(times) / steps * 1e6,
                final=np.array([float(x) for x in out["final"][0][1:]]).reshape(pr.pk.r, -1),
                nfev=int(out["nfev"][0][0]), newton=int(out["newton"][0][0]),
                seconds=seconds, seconds_all=times, status=status, completed=completed)


def run_numba(method_path, problem, h, steps, reps=5, *, start="exact", compensated=True) -> dict:
    """The compiled kernel's ``run_`` called directly (as kernels.drive calls it, in one chunk,
    no projection, one record at the end): same dict as :func:`run_c`; compiled before timing."""
    pr = prepare(method_path, problem, h, start, compensated)
    pk, mod = pr.pk, pr.mod
    r, d = pr.Y0.shape
    times = []
    for rep in range(int(reps) + 1):       # rep 0: compile / load numba's cache, not timed
        Y = pr.Y0.copy()
        flags = pk.flags.copy()
        comp, Fprev, stats = np.zeros(d), np.zeros((pk.s, d)), np.zeros(6)
        rec, recn = np.empty((2, r, d)), np.empty(2, dtype=np.int64)
        n1 = 0 if rep == 0 else int(steps)
        t0 = time.perf_counter()
        head, tail = pk.args()              # kernels.drive's call, with this rep's flags
        tail = tuple(flags if x is pk.flags else x for x in tail)
        status = mod.run_(Y, *head, 0, n1, int(steps), int(steps), *tail, comp, Fprev, rec, recn, stats)
        if rep:
            times.append(time.perf_counter() - t0)
    seconds = float(np.median(times))
    return dict(us_per_step=seconds / steps * 1e6, us_per_step_min=min(times) / steps * 1e6, final=Y, nfev=int(stats[0]), newton=int(stats[1]),
                seconds=seconds, seconds_all=times, status=int(status),
                completed=int(steps) if status == 0 else int(stats[4]) - 1)


def c_f_jac(problem, points):
    """f and the Jacobian of glm_loop.c's hand-written functions at each point (k × d)."""
    pr = prepare("methods/gauss2.json", problem, 0.01)
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    out = _run_exe(_input_text(pr, 0, 1, mode=1, Y=pts))
    d = pts.shape[1]
    f = np.array([[float(x) for x in row[1:]] for row in out["f"]])
    J = np.array([[float(x) for x in row[1:]] for row in out["jac"]]).reshape(-1, d, d)
    return f, J


METHODS = ("gauss2", "implicit_midpoint", "rk4", "example4_glm")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--h", type=float, default=0.01)
    ap.add_argument("--steps", type=int, default=100000)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--no-numba", action="store_true", help="the C column only")
    args = ap.parse_args(argv)
    print(f"h = {args.h}, {args.steps} steps, median (and min) of {args.reps} runs of the step loop alone; "
          f"numba/C: ratio of the medians; max|dY|: raw final input vectors (indicative timings: other "
          f"processes may run)")
    head = (f"{'method':<18} {'problem':<9} {'steps':>7} {'C us/step':>10} {'(min)':>7} {'nfev/step':>9} "
            f"{'newton/step':>11}")
    if not args.no_numba:
        head += f" {'numba us/step':>13} {'(min)':>7} {'numba/C':>7} {'max|dY|':>9}"
    print(head)
    for method in METHODS:
        for problem in PROBLEMS:
            steps = args.steps
            note = ""
            if method == "example4_glm" and problem == "kepler":
                # Example 4 is destroyed by parasitism on Kepler after some hundred steps
                steps, note = min(steps, 500), "  (parasitism: simplified Newton fails at step 577; 500 steps only)"
            c = run_c(f"methods/{method}.json", problem, args.h, steps, args.reps)
            row = (f"{method:<18} {problem:<9} {steps:>7} {c['us_per_step']:>10.3f} {c['us_per_step_min']:>7.3f} "
                   f"{c['nfev'] / steps:>9.2f} "
                   f"{c['newton'] / steps:>11.2f}")
            if not args.no_numba:
                nb = run_numba(f"methods/{method}.json", problem, args.h, steps, args.reps)
                diff = float(np.max(np.abs(nb["final"] - c["final"])))
                row += (f" {nb['us_per_step']:>13.3f} {nb['us_per_step_min']:>7.3f} "
                        f"{nb['us_per_step'] / c['us_per_step']:>7.2f} {diff:>9.2e}")
            print(row + note, flush=True)


if __name__ == "__main__":
    sys.exit(main())
