"""Sameness check of the C reference (glm_loop.c) against the compiled numba loop: a script, not
a test.  Prints

* the generated C functions (f, the Jacobian, and fq/fp of separable problems) of every
  built-in problem against sympy (mpmath at 30 digits, from the problem's own expressions) at
  random points near the initial state, and against the numba loop's f_/jac_ (the same
  generated expressions: bit for bit expected);
* for each case of c_reference.CASES, and a few more that exercise simplified Newton (solver
  "newton") and plain fixed point (mode FIXED, forced: every built-in problem is separable, so
  integrate never chooses it), without Kahan summation and from a naive start: the C loop
  against the numba ``run`` called directly with the same Pack arrays — status, f-evaluations
  (nfev), sweeps and velocity evaluations (nvel) equal, the raw final input vectors y^[n]
  (r × d) to round-off: max|ΔY|/max|Y| (0: bit for bit);
* the public path: finish(C's y^[n]) against integrate(..., kernel="compiled").final, and its
  counters (checks that run_numba calls ``run`` as kernels.drive does);
* the two C paths on a few cases: run_c in process (the shared library through ctypes, the
  default) against run_c(inprocess=False) (the executable): equal status and counters,
  bit-identical finals, also over repeated calls of one library and several libraries loaded.

Run: python benchmarks/c_reference/check.py [--steps 1000]
"""
from __future__ import annotations

import argparse
import sys

import mpmath
import numpy as np
import sympy as sp
from c_reference import CASES, NOTES, c_functions, prepare, run_c, run_numba

from tableau_lab.numeric import limits
from tableau_lab.numeric.integrate import finish, integrate
from tableau_lab.numeric.kernels import compiled_loop
from tableau_lab.numeric.problems import PROBLEMS, get_problem

FUNCTION_PROBLEMS = ("pendulum", "kepler", "fpu", "outer_solar_system", "henon_heiles", "harmonic")
# (method, problem, h, steps or None, options): beyond CASES, the other stage iterations and switches
EXTRA = (("gauss2", "kepler", 0.01, None, dict(solver="newton")),
         ("gauss3", "pendulum", 0.01, None, dict(solver="newton")),
         ("example4_glm", "pendulum", 0.01, None, dict(solver="newton")),      # diagonally implicit: block Newton
         ("glm6_moonshot", "fpu", 0.001, None, dict(solver="newton")),
         ("gauss2", "outer_solar_system", 10.0, None, dict(solver="newton")),
         ("implicit_midpoint", "kepler", 0.01, None, dict(mode=limits.FIXED)),
         ("gauss2", "fpu", 0.001, None, dict(mode=limits.FIXED)),
         ("glm43", "pendulum", 0.01, None, dict(mode=limits.FIXED)),
         ("gauss3", "kepler", 0.01, None, dict(compensated=False)),
         ("glm43", "kepler", 0.01, None, dict(start="naive")))
REL_TOL = 1e-12          # round-off after 1000 steps (bit for bit is expected)


def _rel(a, b) -> float:
    """max|a − b| / max|b| (0 when both vanish)."""
    scale = float(np.max(np.abs(b)))
    diff = float(np.max(np.abs(a - b)))
    return diff / scale if scale else diff


def check_functions(rng, n=6) -> bool:
    ok = True
    print("generated C functions against sympy (mpmath, 30 digits; relative: max|C - ref| / max|ref|) and "
          f"against the numba loop's f_/jac_ (entries that differ), at {n} random points near y0")
    print(f"{'problem':<19} {'d':>3} {'f':>9} {'jac':>9} {'fq, fp':>9} {'vs numba':>9}")
    mpmath.mp.dps = 30
    for name in FUNCTION_PROBLEMS:
        P = get_problem(name)
        state, params = list(P.state), list(P.parameter_symbols.values())
        values = [mpmath.mpf(sp.N(v, 40)) for v in P.parameters.values()]
        f = list(P.f_expr)
        f_ref = sp.lambdify(state + params, f, modules="mpmath")
        J_ref = sp.lambdify(state + params, sp.Matrix(f).jacobian(state).tolist(), modules="mpmath")
        d = P.dimension
        y0 = np.array([float(sp.N(v)) for v in P.initial_state()])
        pts = y0 * (1 + 0.2 * rng.uniform(-1, 1, (n, d))) + 0.2 * rng.uniform(-1, 1, (n, d))
        C = c_functions(P, pts)
        ef = eJ = eqp = 0.0
        for k, y in enumerate(pts):
            args = [mpmath.mpf(float(v)) for v in y] + values
            fr = np.array([float(v) for v in f_ref(*args)])
            Jr = np.array([[float(v) for v in row] for row in J_ref(*args)])
            ef = max(ef, _rel(C["f"][k], fr))
            eJ = max(eJ, _rel(C["jac"][k], Jr))
            if P.separable:
                q = len(P.q)
                eqp = max(eqp, _rel(np.concatenate([C["fq"][k][:q], C["fp"][k][q:]]), fr))
        mod = compiled_loop(P, "f64", None)      # numba's f_/jac_ of the same expressions
        c = np.array([float(v) for v in values])
        differ = 0
        for k, y in enumerate(pts):
            fo, Jo = np.zeros((1, d)), np.zeros((d, d))
            mod.f_(y, c, fo, 0)
            mod.jac_(y, c, Jo)
            differ += int(np.sum(fo[0] != C["f"][k]) + np.sum(Jo != C["jac"][k]))
        good = ef < 1e-13 and eJ < 1e-13 and eqp < 1e-13 and differ == 0
        ok &= good
        qp = f"{eqp:9.1e}" if P.separable else f"{'-':>9}"
        print(f"{name:<19} {d:>3} {ef:9.1e} {eJ:9.1e} {qp} {differ:>9}  {'ok' if good else 'MISMATCH'}")
    missing = sorted(set(PROBLEMS) - set(FUNCTION_PROBLEMS))
    if missing:
        print(f"(not checked: {', '.join(missing)})")
    return ok


def _label(opts) -> str:
    out = []
    for k, v in opts.items():
        if k == "mode":
            out.append({limits.FIXED: "mode=FIXED", limits.NEWTON: "mode=NEWTON", limits.SPLIT: "mode=SPLIT"}[v])
        else:
            out.append(f"{k}={v}")
    return ", ".join(out)


def check_loops(steps) -> bool:
    ok = True
    print(f"\nC loop against the numba run (raw y^[n]; rel = max|dY|/max|Y|, 0: bit for bit) and against "
          f"integrate(kernel='compiled') (|finish - final|), {steps} steps")
    print(f"{'method':<18} {'problem':<19} {'options':<18} {'mode':>8} {'steps':>5} {'rel':>8} {'nfev C':>7} "
          f"{'nfev nb':>7} {'sweeps C':>8} {'sweeps nb':>9} {'nvel C':>7} {'nvel nb':>7} {'|fin-int|':>9} "
          f"{'nfev int':>8}")
    cases = [(m, p, h, n, {}) for m, p, h, n in CASES] + list(EXTRA)
    for method, problem, h, n, opts in cases:
        n = min(steps, n) if n else steps
        path = f"methods/{method}.json"
        c = run_c(path, problem, h, n, reps=1, check_status=False, **opts)
        nb = run_numba(path, problem, h, n, reps=1, check_status=False, **opts)
        rel = _rel(c["final"], nb["final"])
        same = (c["status"], c["completed"], c["nfev"], c["sweeps"], c["nvel"]) == \
               (nb["status"], nb["completed"], nb["nfev"], nb["sweeps"], nb["nvel"])
        notes = [NOTES[method, problem]] if (method, problem) in NOTES and not opts else []
        if not same:
            notes.append(f"counters or status differ: C status {c['status']} at {c['completed']}, numba "
                         f"{nb['status']} at {nb['completed']}")
        if c["status"]:
            notes.append(f"C stopped at step {c['completed'] + 1}, status {c['status']}")
        fin, nint = float("nan"), "-"
        good = same and rel <= REL_TOL and c["status"] == 0
        if "mode" not in opts:             # integrate cannot be told a mode: only its own choice
            pr = prepare(path, problem, h, **{k: v for k, v in opts.items()})
            run = integrate(pr.nm, pr.cp, pr.cp.y0, h, n, kernel="compiled", record_every=n,
                            solver=opts.get("solver", "auto"), start=opts.get("start", "exact"),
                            compensated=opts.get("compensated", True))
            z = finish(pr.nm, pr.cp, c["final"], pr.h, series=opts.get("start", "exact") == "exact")
            fin, nint = float(np.max(np.abs(z - run.final))), run.nfev
            if (run.nfev, run.newton_iterations, run.velocity_evaluations) != (c["nfev"], c["sweeps"], c["nvel"]):
                notes.append(f"integrate's counters differ ({run.fallbacks} fallback steps)" if run.fallbacks
                             else "integrate's counters differ")
                good = False
            if fin > REL_TOL * (1 + float(np.max(np.abs(run.final)))):
                good = False
        ok &= good
        print(f"{method:<18} {problem:<19} {_label(opts):<18} {c['mode']:>8} {n:>5} {rel:8.1e} {c['nfev']:>7} "
              f"{nb['nfev']:>7} {c['sweeps']:>8} {nb['sweeps']:>9} {c['nvel']:>7} {nb['nvel']:>7} {fin:9.1e} "
              f"{nint:>8}  {'ok' if good else 'DIFFERENT'}" + ("  (" + "; ".join(notes) + ")" if notes else ""),
              flush=True)
    return ok


# (method, problem, h, options): the in-process library against the executable
PATHS = (("gauss2", "kepler", 0.01, {}), ("rk4", "pendulum", 0.01, {}), ("gauss2", "fpu", 0.001, {}),
         ("glm43", "kepler", 0.01, dict(start="naive")), ("gauss3", "pendulum", 0.01, dict(solver="newton")),
         ("implicit_midpoint", "kepler", 0.01, dict(mode=limits.FIXED)), ("example4_glm", "kepler", 0.01, {}))


def check_paths(steps) -> bool:
    """run_c in process (ctypes) against run_c(inprocess=False) (the executable); each in-process
    case run twice (reps 2, then 1 after the other libraries): a library keeps no state."""
    ok = True
    print(f"\nC in process (ctypes, shared library) against the C executable, {steps} steps: status, counters "
          f"and raw finals (bit for bit), twice in process")
    print(f"{'method':<18} {'problem':<19} {'options':<18} {'status':>6} {'nfev':>7} {'sweeps':>7} {'nvel':>7} "
          f"{'equal':>6}")
    keys = ("status", "completed", "nfev", "sweeps", "nvel")
    first = {}
    for method, problem, h, opts in PATHS:
        path = f"methods/{method}.json"
        lib = run_c(path, problem, h, steps, reps=2, check_status=False, **opts)
        exe = run_c(path, problem, h, steps, reps=1, check_status=False, inprocess=False, **opts)
        first[method, problem] = lib
        good = (sorted(lib) == sorted(exe) and all(lib[k] == exe[k] for k in keys)
                and np.array_equal(lib["final"], exe["final"]) and len(lib["seconds_all"]) == 2)
        ok &= good
        print(f"{method:<18} {problem:<19} {_label(opts):<18} {lib['status']:>6} {lib['nfev']:>7} {lib['sweeps']:>7} "
              f"{lib['nvel']:>7} {'ok' if good else 'DIFFERENT':>6}", flush=True)
    again = all(np.array_equal(run_c(f"methods/{m}.json", p, h, steps, reps=1, check_status=False, **o)["final"],
                               first[m, p]["final"]) for m, p, h, o in PATHS)
    ok &= again
    print(f"in process again, after the other libraries: {'ok' if again else 'DIFFERENT'}")
    return ok


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    ok = check_functions(np.random.default_rng(args.seed))
    ok &= check_loops(args.steps)
    ok &= check_paths(args.steps)
    print("\nall ok" if ok else "\nSOME CHECKS FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
