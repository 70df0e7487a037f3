"""Sameness check of the C reference (glm_loop.c) against the compiled numba kernel: a script,
not a test.  Prints, for each method × problem:

* the raw input vector y^[n] (r × d) of the C loop against the numba ``run_`` called directly
  with the same _Pack arrays: max |ΔY| and max |ΔY| / max |Y| (round-off: ~1e-12 after 1000
  steps; the pendulum is bit-identical, Kepler's f is written differently by hand);
* nfev and Newton iterations, C against numba (the same algorithm: equal);
* the public path: finish(C's y^[n]) against integrate(..., kernel="compiled").final, and its
  nfev (checks that run_ is called here as kernels.drive calls it);

and first the hand-written f and Jacobian of glm_loop.c against sympy (at 30 digits, from the
problem's own symbols) and against central differences of the C f, at random points.

Run: python benchmarks/c_reference/check.py [--steps 1000]
"""
from __future__ import annotations

import argparse
import sys

import mpmath
import numpy as np
import sympy as sp

from c_reference import PROBLEMS, c_f_jac, prepare, run_c, run_numba
from tableau_lab.numeric.integrate import finish, integrate
from tableau_lab.numeric.problems import get_problem

METHODS = ("gauss2", "implicit_midpoint", "rk4", "example4_glm")


def check_jacobians(rng) -> bool:
    ok = True
    print("hand-written f and J of glm_loop.c against sympy (30 digits) and central differences of the C f")
    for name in PROBLEMS:
        prob = get_problem(name)
        state = list(prob.state)
        subs_c = {s: v for s, v in zip(prob.parameter_symbols.values(), prob.parameters.values())}
        f_sym = sp.Matrix(prob.f_expr).xreplace(subs_c)
        J_sym = f_sym.jacobian(state)
        d = len(state)
        pts = rng.uniform(-1.5, 1.5, size=(6, d))
        if name == "kepler":          # keep away from the singularity r = 0
            pts[:, :2] += np.sign(pts[:, :2]) * 0.3
        f_c, J_c = c_f_jac(name, pts)
        ef = eJ = eFD = 0.0
        for k, y in enumerate(pts):
            at = {s: sp.Float(repr(float(v)), 30) for s, v in zip(state, y)}
            f_ref = np.array([float(sp.N(e.xreplace(at), 30)) for e in f_sym])
            J_ref = np.array([[float(sp.N(e.xreplace(at), 30)) for e in row] for row in J_sym.tolist()])
            ef = max(ef, float(np.max(np.abs(f_c[k] - f_ref)) / (1 + np.max(np.abs(f_ref)))))
            eJ = max(eJ, float(np.max(np.abs(J_c[k] - J_ref)) / (1 + np.max(np.abs(J_ref)))))
            # central differences of the C f, step 1e-6: truncation ~1e-12, round-off ~1e-10
            step = 1e-6
            plus = np.array([y + step * e for e in np.eye(d)])
            minus = np.array([y - step * e for e in np.eye(d)])
            fp, _ = c_f_jac(name, plus)
            fm, _ = c_f_jac(name, minus)
            J_fd = ((fp - fm) / (2 * step)).T          # column l: ∂f/∂y_l
            eFD = max(eFD, float(np.max(np.abs(J_c[k] - J_fd)) / (1 + np.max(np.abs(J_ref)))))
        good = ef < 1e-14 and eJ < 1e-14 and eFD < 1e-7
        ok &= good
        print(f"  {name:<9} f vs sympy {ef:.1e}   J vs sympy {eJ:.1e}   J vs central difference {eFD:.1e}"
              f"   {'ok' if good else 'MISMATCH'}  (relative, max over {len(pts)} random points)")
    return ok


def check_loops(h, steps) -> bool:
    ok = True
    print(f"\nC loop against numba run_ (raw y^[n]) and against integrate(kernel='compiled'), h = {h}")
    print(f"{'method':<18} {'problem':<9} {'steps':>6} {'max|dY|':>9} {'rel':>9} {'nfev C':>7} {'nfev nb':>7} "
          f"{'newton C':>8} {'newton nb':>9} {'|finish-final|':>14} {'nfev int':>8}")
    for method in METHODS:
        for problem in PROBLEMS:
            n = steps
            note = ""
            if method == "example4_glm" and problem == "kepler":
                n, note = min(steps, 500), "  (parasitism: Newton fails at step 577)"
            path = f"methods/{method}.json"
            c = run_c(path, problem, h, n, reps=1)
            nb = run_numba(path, problem, h, n, reps=1)
            diff = float(np.max(np.abs(c["final"] - nb["final"])))
            rel = diff / float(np.max(np.abs(nb["final"])))
            pr = prepare(path, problem, h)
            run = integrate(pr.nm, pr.cp, pr.cp.y0, h, n, kernel="compiled")
            fin = float(np.max(np.abs(finish(pr.nm, pr.cp, c["final"], h) - run.final)))
            same_counts = c["nfev"] == nb["nfev"] == run.nfev and c["newton"] == nb["newton"] == run.newton_iterations
            good = rel < 1e-11 and same_counts and fin < 1e-10 * (1 + float(np.max(np.abs(run.final))))
            ok &= good
            print(f"{method:<18} {problem:<9} {n:>6} {diff:>9.2e} {rel:>9.2e} {c['nfev']:>7} {nb['nfev']:>7} "
                  f"{c['newton']:>8} {nb['newton']:>9} {fin:>14.2e} {run.nfev:>8}  {'ok' if good else 'DIFFERENT'}{note}")
    return ok


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--h", type=float, default=0.01)
    args = ap.parse_args(argv)
    mpmath.mp.dps = 30
    ok = check_jacobians(np.random.default_rng(1))
    ok &= check_loops(args.h, args.steps)
    print("\nall ok" if ok else "\nSOME CHECKS FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
