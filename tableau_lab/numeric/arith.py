r"""The one place that chooses float64 or mpmath arithmetic for the integrators.

Vectors are numpy arrays: ``float64`` for the double-precision path, ``object`` arrays of
``mpmath.mpf`` for the multiprecision path, so the integrator's vector code (+, *, @) is the
same for both; only what differs lives here: conversion of exact numbers, linear solves, norms,
the working tolerance and the machine epsilon.  Multiprecision code runs inside
``a.context()`` (mpmath's working precision is global).  sympy is imported only where an
exact number is converted, so that a run can go on in a process without it.

>>> import sympy as sp
>>> a = arith("mp:40")
>>> x = a.number(sp.sqrt(2))
>>> mpmath.nstr(x, 30)
'1.41421356237309504880168872421'
>>> arith("float64").number(sp.Rational(1, 3)) == 1 / 3
True
"""
from __future__ import annotations

from functools import lru_cache

import mpmath
import numpy as np

__all__ = ["arith", "Arith"]


def is_exact(v) -> bool:
    """A sympy object (number, matrix), told without importing sympy."""
    return type(v).__module__.startswith("sympy.")


class Arith:
    """Arithmetic of one precision.  ``name`` is "float64" or "mp:DIGITS"."""

    name = "float64"
    dps = 16
    dtype = float
    backend = "numpy"          # the code generated for problems (numeric/codegen.py)

    @property
    def eps(self) -> float:
        return float(np.finfo(float).eps)

    @property
    def tol(self) -> float:
        """Newton / projection tolerance: about 10 ulp."""
        return 10 * self.eps

    def loop_tolerances(self) -> tuple:
        """(eps, tol) as the step loop's low-precision numbers (float; mpf for mpmath, where a
        float would underflow beyond 308 digits)."""
        return float(self.eps), float(self.tol)

    def number(self, e):
        """An exact sympy number at this precision (a rational is rounded once, exactly)."""
        if isinstance(e, int):
            return float(e)
        import sympy as sp
        e = sp.sympify(e)
        return float(e) if e.is_Rational else float(sp.N(e, 30))

    def array(self, values):
        return np.array([self.number(v) if is_exact(v) else v for v in values], dtype=self.dtype)

    def matrix(self, M):
        import sympy as sp
        M = sp.Matrix(M)
        return np.array([[self.number(M[i, j]) for j in range(M.cols)] for i in range(M.rows)], dtype=self.dtype)

    def zeros(self, *shape):
        return np.zeros(shape, dtype=float)

    def norm(self, x) -> float:
        """Max norm, as a float (for convergence tests and reports)."""
        return float(np.max(np.abs(x))) if len(x) else 0.0

    def finite(self, x) -> bool:
        return bool(np.all(np.isfinite(x)))

    def to_float(self, x):
        return np.asarray(x, dtype=float)

    def context(self):
        """The context in which this arithmetic's operations run at its precision."""
        import contextlib
        return contextlib.nullcontext()


class MpArith(Arith):
    dtype = object
    backend = "mpmath"

    def __init__(self, dps: int):
        self.dps = dps
        self.name = f"mp:{dps}"

    @property
    def eps(self) -> float:
        return float(self.loop_tolerances()[0])

    @property
    def tol(self) -> float:
        return float(self.loop_tolerances()[1])

    def loop_tolerances(self) -> tuple:
        with mpmath.workdps(self.dps):
            return mpmath.mpf(10) ** (-self.dps), mpmath.mpf(10) ** (2 - self.dps)

    def number(self, e):
        if isinstance(e, int):
            with mpmath.workdps(self.dps):
                return mpmath.mpf(e)
        import sympy as sp
        e = sp.sympify(e)
        with mpmath.workdps(self.dps):
            if e.is_Rational:
                return mpmath.mpf(int(e.p)) / int(e.q)
            return mpmath.mpf(str(sp.N(e, self.dps + 10)))

    def zeros(self, *shape):
        with mpmath.workdps(self.dps):
            return np.full(shape, mpmath.mpf(0), dtype=object)

    def norm(self, x) -> float:
        return float(max((abs(v) for v in x), default=0))

    def finite(self, x) -> bool:
        return all(mpmath.isfinite(v) for v in x)

    def to_float(self, x):
        return np.array([float(v) for v in x])

    def context(self):
        return mpmath.workdps(self.dps)


class DDArith(MpArith):
    """Double-double: the compiled loop computes in pairs of float64 (about 32 digits, u² =
    2^-106); everything around it (starting values, finishing, records, a step handed back
    to Python) runs in mpmath at 32 digits."""

    def __init__(self):
        super().__init__(32)
        self.name = "dd"

    @property
    def eps(self) -> float:
        return 2.0 ** -104

    tol = Arith.tol                # about 10 ulp, as in float64
    loop_tolerances = Arith.loop_tolerances     # floats: the dd loop's low precision is float64


@lru_cache(maxsize=None)
def arith(precision: str = "float64") -> Arith:
    """``"float64"``, ``"dd"`` (double-double, compiled) or ``"mp:DIGITS"`` (e.g. ``"mp:32"``)."""
    if precision == "float64":
        return Arith()
    if precision == "dd":
        return DDArith()
    if isinstance(precision, str) and precision.startswith("mp:"):
        try:
            dps = int(precision[3:])
        except ValueError:
            dps = 0
        if 5 <= dps <= 10000:
            return MpArith(dps)
    raise ValueError(f"precision {precision!r}: use float64, dd or mp:DIGITS with 5 <= DIGITS <= 10000 (e.g. mp:32)")
