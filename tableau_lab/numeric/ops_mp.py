"""mpmath arithmetic of the step core (:mod:`stepcore`; see :mod:`ops_f64` for the contract):
working and low-precision values are both ``mpmath.mpf`` at the working precision (the
Newton matrix too), arrays are numpy object arrays.  Pure Python only; it runs inside
``arith.context()``.
"""
import math

import mpmath
import numpy as np

from .limits import HUGE


def kernel(fn):
    return fn


helper = prim = heavy = alloc = kernel

# ---- operations ----

_ZERO = mpmath.mpf(0)


def wzero():
    return _ZERO


def wint(n):
    return mpmath.mpf(n)


def wadd(a, b):
    return a + b


def wsub(a, b):
    return a - b


def wmul(a, b):
    return a * b


def wmadd(acc, a, b):
    return acc + a * b


def wlo(x):
    return x


def waddlo(x, dz):
    return x + dz


def isnz(a):
    return a != 0


def lofinite(x):
    """Finite, and within ±limits.HUGE: mpmath never overflows, so a diverging run stops here as
    the float64 and double-double loops stop at inf."""
    return (mpmath.isfinite(x) if isinstance(x, mpmath.mpf) else math.isfinite(x)) and abs(x) <= HUGE


def g1(a, i):
    return a[i]


def p1(a, i, v):
    a[i] = v


def g2(a, i, j):
    return a[i, j]


def p2(a, i, j, v):
    a[i, j] = v


def g3(a, i, j, k):
    return a[i, j, k]


def p3(a, i, j, k, v):
    a[i, j, k] = v


def wvec(n):
    return np.full(n, _ZERO, dtype=object)


def wmat(n, m):
    return np.full((n, m), _ZERO, dtype=object)


lovec, lomat = wvec, wmat
