"""Float64 arithmetic of the step core (:mod:`stepcore`): a working value is a float, and so
is a low-precision value (Newton matrices, corrections, norms).

Every arithmetic module (this one, :mod:`ops_dd`, :mod:`ops_mp`) defines the functions named in
:data:`OPERATIONS`, with the same meaning; :mod:`kernels` writes this module's (each one's
source whole), with the core, into one compiled module per problem (``prim`` becomes numba's
``njit``), or binds them to the core's functions as they are (the pure loop, where the
decorators do nothing; its element reads are :data:`PURE_READS`).  The names: ``w*`` work on
working-precision values (``wadd`` a + b, ``wmadd`` acc + a·b …), ``wlo`` rounds one to the low
precision, ``g1``/``g2``/``g3`` read an element of a 1-, 2- or 3-index array of working values
and ``p1``/``p2``/``p3`` write one
(a double-double array has one more axis: hi and lo), ``wvec``/``wmat`` allocate working
arrays and ``lovec``/``lomat`` low-precision ones.  In float64 each operation is one IEEE-754
operation, rounded to nearest, not fused (numba compiles without contraction, as the C loop
with ``-ffp-contract=off``: both compute the same numbers).

>>> wmadd(1.0, 2.0, 3.0), wlo(0.5), isnz(0.0), wint(3)
(7.0, 0.5, False, 3.0)
>>> Y = wmat(2, 3); p2(Y, 1, 2, wadd(0.1, 0.2)); float(g2(Y, 1, 2))
0.30000000000000004
"""
import math

import numpy as np

# the operations an arithmetic module defines (its contract with stepcore), in the order a
# generated module lists them
OPERATIONS = ("wzero", "wint", "wadd", "wsub", "wmul", "wmadd", "wlo", "waddlo", "isnz", "lofinite",
              "g1", "p1", "g2", "p2", "g3", "p3", "wvec", "wmat", "lovec", "lomat")


def kernel(fn):
    """No-op decorator: stepcore's functions run as they are in Python (a generated module
    imports numba's from :mod:`jit` instead)."""
    return fn


helper = prim = heavy = alloc = kernel


@prim
def wzero():
    """The working-precision zero."""
    return 0.0


@prim
def wint(n):
    """The integer n as a working value (exact for |n| ≤ 2^53)."""
    return float(n)


@prim
def wadd(a, b):
    """fl(a + b)."""
    return a + b


@prim
def wsub(a, b):
    """fl(a − b)."""
    return a - b


@prim
def wmul(a, b):
    """fl(a · b)."""
    return a * b


@prim
def wmadd(acc, a, b):
    """fl(acc + fl(a · b)): two roundings, no fused multiply-add (the C reference's numbers)."""
    return acc + a * b


@prim
def wlo(x):
    """x in the low precision (float64 here: x itself)."""
    return x


@prim
def waddlo(x, dz):
    """A working value plus a low-precision correction: fl(x + dz)."""
    return x + dz


@prim
def isnz(a):
    """a ≠ 0: whether a matrix coefficient enters a sum (:func:`stepcore.uses`)."""
    return a != 0.0


@prim
def lofinite(x):
    """A low-precision value is finite (neither inf nor nan)."""
    return math.isfinite(x)


@prim
def g1(a, i):
    """a[i] of a vector of working values."""
    return a[i]


@prim
def p1(a, i, v):
    """a[i] = v."""
    a[i] = v


@prim
def g2(a, i, j):
    """a[i, j] of a matrix of working values."""
    return a[i, j]


@prim
def p2(a, i, j, v):
    """a[i, j] = v."""
    a[i, j] = v


@prim
def g3(a, i, j, k):
    """a[i, j, k] of a three-index array of working values (A, B: class, row, column)."""
    return a[i, j, k]


@prim
def p3(a, i, j, k, v):
    """a[i, j, k] = v."""
    a[i, j, k] = v


@alloc
def wvec(n):
    """A zero vector of n working values."""
    return np.zeros(n)


@alloc
def wmat(n, m):
    """A zero n × m matrix of working values."""
    return np.zeros((n, m))


lovec, lomat = wvec, wmat        # the low precision is float64 too

# The pure loop reads elements as Python floats (ndarray.item: the same double), whose arithmetic
# is IEEE-754 double rounded to nearest as numpy's scalars' and numba's, and in the interpreter
# several times cheaper than numpy's scalars' (g1 … g3 above are what a compiled module uses).
# Stepcore divides only by guarded values (no ZeroDivisionError for a Python float).
PURE_READS = {"g1": np.ndarray.item, "g2": np.ndarray.item, "g3": np.ndarray.item}
