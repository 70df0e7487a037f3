"""mpmath arithmetic of the step core (:mod:`stepcore`; see :mod:`ops_f64` for the contract):
working and low-precision values are both ``mpmath.mpf`` at the working precision (the
Newton matrix too), each operation rounded once to the context's precision (mpmath's
correctly rounded +, −, ×), arrays are numpy object arrays.  Pure Python only; it runs inside
``arith.context()``.

>>> import mpmath
>>> with mpmath.workdps(40):
...     print(mpmath.nstr(wmadd(wzero(), wint(1) / 3, wint(3)), 40))
1.0
>>> lofinite(mpmath.mpf(10) ** 400)
False
"""
import math

import mpmath
import numpy as np

from .limits import HUGE


def kernel(fn):
    """No-op decorator (see :func:`ops_f64.kernel`)."""
    return fn


helper = prim = heavy = alloc = kernel

_ZERO = mpmath.mpf(0)


def wzero():
    """mpf zero."""
    return _ZERO


def wint(n):
    """The integer n as an mpf (exact)."""
    return mpmath.mpf(n)


def wadd(a, b):
    """a + b rounded to the working precision."""
    return a + b


def wsub(a, b):
    """a − b rounded to the working precision."""
    return a - b


def wmul(a, b):
    """a · b rounded to the working precision."""
    return a * b


def wmadd(acc, a, b):
    """acc + a · b, two roundings."""
    return acc + a * b


def wlo(x):
    """The low precision is the working precision: x."""
    return x


def waddlo(x, dz):
    """x + dz rounded to the working precision."""
    return x + dz


def isnz(a):
    """a ≠ 0."""
    return a != 0


def lofinite(x):
    """Finite, and within ±limits.HUGE: mpmath never overflows, so a diverging run stops here as
    the float64 and double-double loops stop at inf."""
    return (mpmath.isfinite(x) if isinstance(x, mpmath.mpf) else math.isfinite(x)) and abs(x) <= HUGE


def g1(a, i):
    """a[i] of an object vector."""
    return a[i]


def p1(a, i, v):
    """a[i] = v."""
    a[i] = v


def g2(a, i, j):
    """a[i, j] of an object matrix."""
    return a[i, j]


def p2(a, i, j, v):
    """a[i, j] = v."""
    a[i, j] = v


def g3(a, i, j, k):
    """a[i, j, k] of a three-index object array."""
    return a[i, j, k]


def p3(a, i, j, k, v):
    """a[i, j, k] = v."""
    a[i, j, k] = v


def wvec(n):
    """A vector of n mpf zeros."""
    return np.full(n, _ZERO, dtype=object)


def wmat(n, m):
    """An n × m matrix of mpf zeros."""
    return np.full((n, m), _ZERO, dtype=object)


lovec, lomat = wvec, wmat
