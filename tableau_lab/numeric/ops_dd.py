"""Double-double arithmetic of the step core (:mod:`stepcore`; see :mod:`ops_f64` for the
contract): a working value is a pair (hi, lo) of float64 (:mod:`ddmath`), arrays carry a
trailing axis of length 2; low-precision values are float64 — the Newton matrix is factorised
in float64 while residuals are formed in double-double (mixed-precision iterative
refinement: the iteration still converges to double-double accuracy).  Compiled only.
"""
import math

import numpy as np

from .ddmath import dd_add, dd_add_d, dd_mul, dd_sub


def kernel(fn):         # replaced by numba's njit in a compiled module
    return fn


helper = prim = heavy = alloc = kernel

# ---- operations ----


@prim
def wzero():
    return (0.0, 0.0)


@prim
def wint(n):
    return (float(n), 0.0)


@prim
def wadd(a, b):
    return dd_add(a, b)


@prim
def wsub(a, b):
    return dd_sub(a, b)


@prim
def wmul(a, b):
    return dd_mul(a, b)


@prim
def wmadd(acc, a, b):
    return dd_add(acc, dd_mul(a, b))


@prim
def wlo(x):
    return x[0] + x[1]


@prim
def waddlo(x, dz):
    return dd_add_d(x, dz)


@prim
def isnz(a):
    return a[0] != 0.0


@prim
def lofinite(x):
    return math.isfinite(x)


@prim
def g1(a, i):
    return (a[i, 0], a[i, 1])


@prim
def p1(a, i, v):
    a[i, 0] = v[0]
    a[i, 1] = v[1]


@prim
def g2(a, i, j):
    return (a[i, j, 0], a[i, j, 1])


@prim
def p2(a, i, j, v):
    a[i, j, 0] = v[0]
    a[i, j, 1] = v[1]


@prim
def g3(a, i, j, k):
    return (a[i, j, k, 0], a[i, j, k, 1])


@prim
def p3(a, i, j, k, v):
    a[i, j, k, 0] = v[0]
    a[i, j, k, 1] = v[1]


@alloc
def wvec(n):
    return np.zeros((n, 2))


@alloc
def wmat(n, m):
    return np.zeros((n, m, 2))


@alloc
def lovec(n):
    return np.zeros(n)


@alloc
def lomat(n, m):
    return np.zeros((n, m))
