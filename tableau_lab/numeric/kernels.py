r"""Compiled float64 step loops: numba code generated from a problem's symbols, cached on disk.

One module per problem (its f, Jacobian, invariants and gradients, then the loop of
:mod:`kernel_source`) is written under the cache directory (``$TABLEAU_LAB_CACHE``, else
``~/.cache/tableau_lab``) with a name that hashes its text, and numba caches the machine code
beside it: the compile cost is paid once per problem (and loop version), not per run and not
per method — the method enters as arrays.  :func:`drive` runs the loop in chunks between
which Python records, reports progress and lets Ctrl-C through; a step the loop cannot finish
is redone by the pure-Python stepper (full Newton, fixed point) or fails with its message.

>>> from tableau_lab.exact.tableau_json import load
>>> from tableau_lab.numeric.export import to_numeric
>>> from tableau_lab.numeric.codegen import compile_problem
>>> from tableau_lab.numeric.integrate import integrate
>>> cp = compile_problem("pendulum")
>>> nm = to_numeric(load("methods/gauss2.json"))
>>> fast = integrate(nm, cp, cp.y0, 0.01, 1000, kernel="compiled")
>>> slow = integrate(nm, cp, cp.y0, 0.01, 1000, kernel="python")
>>> bool(abs(fast.final - slow.final).max() < 1e-13), fast.nfev == slow.nfev
(True, True)
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import time
from pathlib import Path

import numpy as np

from ..files import atomic_write_text

__all__ = ["available", "kernel_module", "write_kernel", "drive", "cache_dir"]

_MODULES: dict = {}
_BY_PROBLEM: dict = {}     # (problem.key, kind) -> module: the source is generated once per process
_COMPILE: dict = {}        # module name -> seconds of the first (compiling or cache-loading) call


def available() -> bool:
    """numba importable."""
    return importlib.util.find_spec("numba") is not None


def cache_dir() -> Path:
    root = os.environ.get("TABLEAU_LAB_CACHE") or Path.home() / ".cache" / "tableau_lab"
    return Path(root) / "kernels"


def write_kernel(problem, kind: str = "f64") -> tuple:
    """Generate the module of ``problem`` (a :class:`~.problems.Problem`) for ``kind`` "f64" or
    "dd" and write it to the cache unless it is there: (module name, path, invariant names).
    The generation needs sympy; loading (:func:`kernel_module`) does not."""
    from .kernel_source import COMMON, DD_HEADER, DD_LOOP, HEADER, LOOP, dd_problem_source, problem_source
    names = tuple(problem.invariants)
    if kind == "dd":
        # numba's cache does not see changes in imported modules: name ddmath's version here
        from . import ddmath
        stamp = hashlib.sha256(Path(ddmath.__file__).read_bytes()).hexdigest()[:16]
        source = (DD_HEADER + f"# ddmath {stamp}\n\n" + dd_problem_source(problem, names) + "\n"
                  + COMMON + DD_LOOP)
    else:
        source = HEADER + "\n" + problem_source(problem, names) + "\n" + LOOP
    name = f"tableau_lab_kernel_{hashlib.sha256(source.encode()).hexdigest()[:20]}"
    path = cache_dir() / f"{name}.py"
    if not path.exists():
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(path, source)
    return name, str(path), names


def kernel_module(problem, kind: str = "f64"):
    """The compiled module of ``problem`` for ``kind`` "f64" or "dd": generated and written on
    first use (:func:`write_kernel`; a frozen problem names its files in ``kernel_files``),
    imported once per process; numba compiles on the first call or loads its disk cache."""
    if (problem.key, kind) in _BY_PROBLEM:
        return _BY_PROBLEM[problem.key, kind]
    files = getattr(problem, "kernel_files", None) or {}
    name, path, names = files[kind] if kind in files else write_kernel(problem, kind)
    if name not in _MODULES:
        spec = importlib.util.spec_from_file_location(name, path)
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        spec.loader.exec_module(mod)
        mod.invariant_index = {k: i for i, k in enumerate(names)}
        _MODULES[name] = mod
    _BY_PROBLEM[problem.key, kind] = _MODULES[name]
    return _MODULES[name]


def _f64(x):
    return np.ascontiguousarray(np.asarray(x, dtype=float))


def _dd(x):
    """Multiprecision numbers (any nesting) → a double-double array (trailing axis hi, lo)."""
    from .ddmath import to_dd_array
    return to_dd_array(np.asarray(x, dtype=object))


class _Pack:
    """The method, problem and run constants as the loop's arrays: float64, or double-double
    (trailing axis hi, lo) rounded from the multiprecision coefficients."""

    def __init__(self, nm, cp, h, masks, project, targets, mod, stepper, dd=False, track=()):
        if dd:
            from .ddmath import to_dd
        num = _dd if dd else _f64
        self.s, self.r, self.dd = nm.s, nm.r, dd
        self.h = to_dd(h) if dd else float(h)
        self.hinv = to_dd(1 / h) if dd else None
        self.mats = [num(x) for x in (nm.Aq, nm.Ap, nm.U, nm.Bq, nm.Bp, nm.V)]
        self.mq, self.mp = _f64([float(x) for x in masks[0]]), _f64([float(x) for x in masks[1]])
        if not np.all(self.mq + self.mp == 1):
            raise ValueError("the compiled loop needs complementary 0/1 component masks")
        z = num(np.zeros((nm.s, nm.s)))
        self.E = num(nm.E) if nm.E is not None else z
        invertible = nm.Aq_inv is not None and nm.Ap_inv is not None
        self.Aqi = num(nm.Aq_inv) if invertible else z
        self.Api = num(nm.Ap_inv) if invertible else z
        # Kahan summation, h·s·max|A| and the stage iteration as the pure stepper has them
        self.flags = np.array([int(nm.explicit), int(nm.E is not None), int(invertible),
                               int(stepper.comp is not None and not dd), 0, int(stepper.fixed)], dtype=np.int64)
        self.c = num(list(cp.constants))
        self.hA = stepper.hA
        self.proj, self.target = self._invariants(mod, project, targets, num)
        self.track, self.ttarget = self._invariants(mod, track, targets, num)
        self.tmax = np.zeros(len(track))
        self.eps = nm.arith.eps

    @staticmethod
    def _invariants(mod, names, targets, num):
        idx = np.array([mod.invariant_index[k] for k in names], dtype=np.int64)
        return idx, num([targets[k] for k in names])

    def args(self):
        head = (self.h, self.hinv) if self.dd else (self.h,)
        return head, (*self.mats, self.mq, self.mp, self.E, self.Aqi, self.Api, self.flags, self.c, self.eps,
                      self.hA, self.proj, self.target, self.track, self.ttarget, self.tmax)


def drive(nm, cp, Y, h, steps, every, *, masks, project, targets, stepper, record, progress, run,
          project_step=None, chunk=1 << 16, track=()):
    """Steps 1..steps of the compiled loop from the input vector Y (r × d); ``record(n, Y)`` at
    the record steps, ``progress(n)`` after each chunk; returns the final Y.  ``stepper`` (the
    pure path) redoes a step the loop hands back; ``project_step(Y0, n)`` → (Y0, iterations)
    projects after it.  ``track``: invariants whose largest error over every step is kept
    (``run.tracked``; of y^[n]_1, unfinished).  With ``nm.arith`` double-double the loop runs in dd and Y, the records
    and the pure path are mpmath numbers at 32 digits."""
    from .integrate import not_finite, projection_failed
    dd = nm.arith.name == "dd"
    if dd:
        from .ddmath import from_dd_array
        to_loop, from_loop = _dd, from_dd_array
    else:
        to_loop, from_loop = (lambda x: _f64(x).copy()), (lambda x: x.copy())
    mod = kernel_module(cp.problem, "dd" if dd else "f64")
    pk = _Pack(nm, cp, h, masks, project, targets, mod, stepper, dd, track)
    head, tail = pk.args()
    Y = to_loop(Y)
    r, d = Y.shape[:2]
    comp = _f64(stepper.comp).copy() if pk.flags[3] else np.zeros(d)
    Fprev = np.zeros((pk.s, *Y.shape[1:]))
    stats = np.zeros(6)
    rec = np.empty((chunk // every + 2, *Y.shape))
    recn = np.empty(chunk // every + 2, dtype=np.int64)
    n = 0

    def call(n0, n1):
        if dd:
            return mod.run_(Y, *head, n0, n1, steps, every, *tail, Fprev, rec, recn, stats)
        return mod.run_(Y, *head, n0, n1, steps, every, *tail, comp, Fprev, rec, recn, stats)

    if mod.__name__ not in _COMPILE:
        t0 = time.perf_counter()
        call(0, 0)
        _COMPILE[mod.__name__] = time.perf_counter() - t0
        run.compile_seconds = _COMPILE[mod.__name__]
    while n < steps:
        n1 = min(steps, n + chunk)
        status = call(n, n1)
        for k in range(int(stats[3])):
            record(int(recn[k]), from_loop(rec[k]))
        stepper.nfev, stepper.newton, run.projection_iterations = int(stats[0]), int(stats[1]), int(stats[2])
        run.tracked = {k: float(v) for k, v in zip(track, pk.tmax)}
        run.completed = n1 if status == 0 else int(stats[4]) - 1
        if status == 0:
            n = n1
        else:
            n = int(stats[4])
            if status == 2:
                raise not_finite(n, n * h)
            if status == 3:
                raise projection_failed(project, n, n * h, stats[5])
            # the pure path redoes this step: full Newton, then fixed point (or its error)
            stepper.comp = comp.copy() if pk.flags[3] else None
            stepper.Fprev = None
            Yp = stepper.step(from_loop(Y), n, n * h)
            if project_step is not None:
                Yp[0], its = project_step(Yp[0], n)
                stats[2] += its
            Y[...] = to_loop(Yp)
            stats[0], stats[1] = stepper.nfev, stepper.newton
            if stepper.comp is not None:
                comp[:] = stepper.comp
            if stepper.Fprev is not None:
                Fprev[...] = to_loop(stepper.Fprev)
                pk.flags[4] = 1
            run.completed = n
            if n % every == 0 or n == steps:
                record(n, Yp)
        if progress is not None:
            progress(n)
    return from_loop(Y)
