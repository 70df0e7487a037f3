"""Double-double arithmetic of the step core (:mod:`stepcore`; see :mod:`ops_f64` for the
contract): a working value is a pair (hi, lo) of float64 (:mod:`ddmath`) whose exact sum is the
value, |lo| ≤ ulp(hi)/2; arrays carry a trailing axis of length 2; low-precision values are
float64 — the Newton matrix is factorised in float64 while residuals are formed in
double-double (mixed-precision iterative refinement: the iteration still converges to
double-double accuracy).  Compiled in the loop; the functions run in Python too (the examples).

The operations are built on the error-free transformations of :mod:`ddmath`: Knuth's TwoSum
(a + b = s + e exactly, any a, b) and Dekker's Fast2Sum (|a| ≥ |b|) for sums, Dekker's
TwoProduct (a·b = p + e exactly, by Veltkamp's split) for products — the building blocks of
Dekker (1971), "A floating-point technique for extending the available precision", and of
Ogita, Rump & Oishi (2005), "Accurate sum and dot product" (SIAM J. Sci. Comput. 26), whose Dot2
is the pattern of ``wmadd`` accumulated over a stage sum; the double-double operations
themselves are those of the QD library (Hida, Li & Bailey 2001), relative error a few
u² = 2^-106.

>>> third = wmul(wint(1), (0.3333333333333333, 1.850371707708594e-17))
>>> wlo(wmadd(wzero(), third, wint(3)))
1.0
>>> a = wvec(2); p1(a, 1, wadd((1.0, 0.0), (1e-20, 0.0))); [float(x) for x in g1(a, 1)]
[1.0, 1e-20]
"""
import math

import numpy as np

from .ddmath import dd_add, dd_add_d, dd_mul, dd_sub


def kernel(fn):
    """No-op decorator (see :func:`ops_f64.kernel`)."""
    return fn


helper = prim = heavy = alloc = kernel


@prim
def wzero():
    """The dd zero (0, 0)."""
    return (0.0, 0.0)


@prim
def wint(n):
    """The integer n as a dd (exact for |n| ≤ 2^53)."""
    return (float(n), 0.0)


@prim
def wadd(a, b):
    """a + b in dd: QD's accurate addition (two TwoSums, then Fast2Sum renormalisation), relative
    error ≤ 3u² even under cancellation (:func:`ddmath.dd_add`)."""
    return dd_add(a, b)


@prim
def wsub(a, b):
    """a − b in dd (:func:`ddmath.dd_sub`: a + (−b))."""
    return dd_sub(a, b)


@prim
def wmul(a, b):
    """a · b in dd: Dekker's TwoProduct of the leading parts plus the cross terms, renormalised by
    Fast2Sum (:func:`ddmath.dd_mul`)."""
    return dd_mul(a, b)


@prim
def wmadd(acc, a, b):
    """acc + a · b in dd, the product rounded to dd first (no fused operation): accumulated over
    a stage sum this is Ogita–Rump–Oishi's Dot2 carried in double-double."""
    return dd_add(acc, dd_mul(a, b))


@prim
def wlo(x):
    """The dd x rounded to float64: fl(hi + lo)."""
    return x[0] + x[1]


@prim
def waddlo(x, dz):
    """x + dz for a dd x and a float64 correction dz, in dd (:func:`ddmath.dd_add_d`: TwoSum of
    the leading parts, the correction's error folded into lo): the Newton update in
    mixed-precision iterative refinement."""
    return dd_add_d(x, dz)


@prim
def isnz(a):
    """a ≠ 0 (a normalised dd is zero exactly when its leading part is)."""
    return a[0] != 0.0


@prim
def lofinite(x):
    """A low-precision (float64) value is finite."""
    return math.isfinite(x)


@prim
def g1(a, i):
    """The dd a[i] of a vector (n × 2 array)."""
    return (a[i, 0], a[i, 1])


@prim
def p1(a, i, v):
    """a[i] = the dd v."""
    a[i, 0] = v[0]
    a[i, 1] = v[1]


@prim
def g2(a, i, j):
    """The dd a[i, j] of a matrix (n × m × 2 array)."""
    return (a[i, j, 0], a[i, j, 1])


@prim
def p2(a, i, j, v):
    """a[i, j] = the dd v."""
    a[i, j, 0] = v[0]
    a[i, j, 1] = v[1]


@prim
def g3(a, i, j, k):
    """The dd a[i, j, k] of a three-index array (… × 2)."""
    return (a[i, j, k, 0], a[i, j, k, 1])


@prim
def p3(a, i, j, k, v):
    """a[i, j, k] = the dd v."""
    a[i, j, k, 0] = v[0]
    a[i, j, k, 1] = v[1]


@alloc
def wvec(n):
    """A zero vector of n dd values (n × 2)."""
    return np.zeros((n, 2))


@alloc
def wmat(n, m):
    """A zero n × m matrix of dd values (n × m × 2)."""
    return np.zeros((n, m, 2))


@alloc
def lovec(n):
    """A zero float64 vector (the low precision)."""
    return np.zeros(n)


@alloc
def lomat(n, m):
    """A zero float64 n × m matrix (the Newton matrix)."""
    return np.zeros((n, m))
