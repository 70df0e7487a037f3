"""Float64 arithmetic of the step core (:mod:`stepcore`): a working value is a float, and so
is a low-precision value (Newton matrices, corrections, norms).

Every arithmetic module (this one, :mod:`ops_dd`, :mod:`ops_mp`) defines the same names below
the marker line; :mod:`kernels` copies them, with the core, into one compiled module per
problem (``kernel``/``helper`` become numba's ``njit``), or runs them as they are (the pure
loop, where the decorators do nothing).

>>> wmadd(1.0, 2.0, 3.0), wlo(0.5), isnz(0.0)
(7.0, 0.5, False)
"""
import math

import numpy as np


def kernel(fn):         # replaced by numba's njit in a compiled module
    return fn


helper = prim = heavy = alloc = kernel

# ---- operations ----


@prim
def wzero():
    return 0.0


@prim
def wint(n):
    return float(n)


@prim
def wadd(a, b):
    return a + b


@prim
def wsub(a, b):
    return a - b


@prim
def wmul(a, b):
    return a * b


@prim
def wmadd(acc, a, b):
    return acc + a * b


@prim
def wlo(x):
    return x


@prim
def waddlo(x, dz):
    return x + dz


@prim
def isnz(a):
    return a != 0.0


@prim
def lofinite(x):
    return math.isfinite(x)


@prim
def g1(a, i):
    return a[i]


@prim
def p1(a, i, v):
    a[i] = v


@prim
def g2(a, i, j):
    return a[i, j]


@prim
def p2(a, i, j, v):
    a[i, j] = v


@prim
def g3(a, i, j, k):
    return a[i, j, k]


@prim
def p3(a, i, j, k, v):
    a[i, j, k] = v


@alloc
def wvec(n):
    return np.zeros(n)


@alloc
def wmat(n, m):
    return np.zeros((n, m))


lovec, lomat = wvec, wmat        # the low precision is float64 too
