r"""Double-double ("dd") arithmetic in numba: about 32 significant digits at float64 speed.

A dd number is a 2-tuple ``(hi, lo)`` of float64 (numba ``UniTuple(float64, 2)``) whose value
is the exact sum hi + lo, normalised so that hi = fl(hi + lo), i.e. |lo| ≤ ulp(hi)/2.  The
algorithms are those of Dekker (1971), Shewchuk (1997) and the QD library of Hida, Li and
Bailey (2001): error-free transformations ``two_sum``, ``quick_two_sum`` and ``two_prod``
(Dekker's split with 2^27 + 1: numba exposes no fused multiply-add and Python 3.11 has no
``math.fma``), then +, −, × and ÷ with relative errors of a few units of u² = 2^-106
(≈ 1.2e-32), measured below 1e-31.  Addition is the accurate ("IEEE") one of QD, so a sum
with cancellation is still relatively accurate.

Elementary functions: ``dd_sqrt`` (one Newton/Karp step), ``dd_exp`` (x = m ln 2 + r with a
three-double ln 2, Taylor series of e^(r/32) − 1, five squarings), ``dd_log`` (a = 2^k m,
log m = 2 atanh((m − 1)/(m + 1)) by its series: relatively accurate near 1 too), ``dd_sin``,
``dd_cos``, ``dd_sincos`` (x = n π/2 + r with a four-double π/2 and exact products n·P_i,
Taylor series of sin r on |r| ≤ π/4, cos r = sqrt(1 − sin² r)).  In every series the
high-order terms, smaller than 2^-53 of the sum, are summed in float64 and only the leading
terms in dd.

How they are compiled.  The branch-free primitives (``two_sum`` … ``dd_div``, ``dd_get``,
``dd_set``) are plain Python functions that numba treats as builtins: at each call site in
numba code their instructions are emitted in place (the Python function is traced on LLVM
values, see ``_inline``), so they cost no call, and a generated function with a thousand dd
operations compiles in seconds (as ``@njit`` functions each call adds a stack slot that makes
LLVM quadratic: 400 s for the solar system's Jacobian; ``inline='always'`` inlines numba IR,
slower still).  From Python they run as they are, with the same doubles.  The others (with
branches or loops) are ``@njit(cache=True)``.  Compile callers without ``fastmath``: it lets
LLVM reassociate the error-free transformations away.  A caller compiled with
``cache=True`` in another module keeps the primitives it was compiled with: numba's cache
does not see changes to this file (clear it after editing ddmath).

Range: operands of products and quotients must be below 2^996 ≈ 6.7e299 in magnitude (beyond,
Dekker's split overflows and the result is nan, never a wrong number), and results keep the
full 106 bits above 2^-969 ≈ 2e-292 (below, lo is subnormal).

The Python-side conversions ``to_dd`` / ``from_dd`` (and their array versions) are exact:
``to_dd`` rounds the exact value (a rational, a binary mpmath or sympy float, or an
irrational evaluated to 80 digits), never through a float of the whole value.

>>> third = to_dd("1/3")
>>> third
(0.3333333333333333, 1.850371707708594e-17)
>>> x = dd_mul_d(third, 3.0)
>>> x, dd_sub(x, dd_from_double(1.0))
((1.0, 0.0), (0.0, 0.0))
>>> mpmath.nstr(from_dd(*dd_sqrt(dd_from_double(2.0))), 32)
'1.4142135623730950488016887242097'
>>> a = to_dd_array([[1, 2], [3, "1e-30"]])
>>> a.shape, from_dd_array(a)[1, 1] == from_dd(to_dd("1e-30"))
((2, 2, 2), True)
"""
from __future__ import annotations

import math
import re
from fractions import Fraction
from types import FunctionType

import mpmath
import numpy as np
from llvmlite import ir
from mpmath import libmp
from numba import njit, types
from numba.core import cgutils
from numba.core.typing.templates import ConcreteTemplate, infer_global, signature
from numba.extending import lower_builtin, type_callable

from .arith import is_exact

__all__ = ["dd_get", "dd_set", "two_sum", "quick_two_sum", "two_prod", "two_sqr",
           "dd_from_double", "dd_neg", "dd_abs", "dd_add", "dd_sub", "dd_add_d", "dd_mul", "dd_mul_d",
           "dd_mul_pwr2", "dd_sqr", "dd_div", "dd_sqrt", "dd_pow_int", "dd_exp", "dd_log",
           "dd_sin", "dd_cos", "dd_sincos", "dd_lt", "dd_gt",
           "to_dd", "from_dd", "to_dd_array", "from_dd_array"]

# the primitives with branches or loops: cached machine code, x/0 = inf (no zero-division check)
_jit = njit(cache=True, error_model="numpy")
_DD = types.UniTuple(types.float64, 2)
_DOUBLE = ir.DoubleType()
_INLINE: dict = {}          # name -> the branch-free primitives, as plain Python functions
_TRACING: dict = {}         # their namespace for tracing (see _inline)


class _Traced:
    """A float64 while a primitive is traced into LLVM IR: arithmetic emits the instruction."""
    __slots__ = ("builder", "value")

    def __init__(self, builder, value):
        self.builder, self.value = builder, value

    def _op(self, op, other, swap=False):
        other = _llvm(other)
        lhs, rhs = (other, self.value) if swap else (self.value, other)
        return _Traced(self.builder, getattr(self.builder, op)(lhs, rhs))

    def __neg__(self):
        return _Traced(self.builder, self.builder.fneg(self.value))


for _name, _instruction in [("add", "fadd"), ("sub", "fsub"), ("mul", "fmul"), ("truediv", "fdiv")]:
    setattr(_Traced, f"__{_name}__", lambda self, other, _i=_instruction: self._op(_i, other))
    setattr(_Traced, f"__r{_name}__", lambda self, other, _i=_instruction: self._op(_i, other, True))


def _llvm(x):
    return x.value if isinstance(x, _Traced) else ir.Constant(_DOUBLE, float(x))


def _traced(name):
    """The primitive ``name`` re-bound to a namespace where the primitives it calls are
    re-bound too (so that they trace as well)."""
    if not _TRACING:
        _TRACING.update(globals())
        for n, f in _INLINE.items():
            _TRACING[n] = FunctionType(f.__code__, _TRACING, n, f.__defaults__, f.__closure__)
    return _TRACING[name]


def _inline(*kinds):
    """Register a branch-free primitive, written in plain Python on floats, as a numba builtin.
    Python runs it as it is; numba code that calls it gets its instructions in place: the
    function is traced on _Traced values at each call site.  No call, no stack traffic and
    nothing left to inline: a generated function compiles in time linear in its size (each
    call of an @njit function adds a stack slot, and LLVM's SROA and MemCpyOpt are quadratic in
    their number).  ``kinds``: "d" (a double) or "dd" (a pair of doubles) for each argument,
    converted from any numbers; the result is a pair of doubles."""
    def register(fn):
        _INLINE[fn.__name__] = fn
        cases = [signature(_DD, *[_DD if k == "dd" else types.float64 for k in kinds])]
        infer_global(fn, types.Function(type(f"Typing_{fn.__name__}", (ConcreteTemplate,),
                                             {"key": fn, "cases": cases})))

        @lower_builtin(fn, *[types.Any] * len(kinds))
        def lower(context, builder, sig, args):
            def double(value, ty):
                return _Traced(builder, context.cast(builder, value, ty, types.float64))
            values = [double(v, t) if k == "d" else tuple(double(builder.extract_value(v, i), t[i]) for i in range(2))
                      for v, t, k in zip(args, sig.args, kinds, strict=False)]
            return context.make_tuple(builder, _DD, [_llvm(x) for x in _traced(fn.__name__)(*values)])
        return fn
    return register


# -- exact conversions (Python side) ---------------------------------------------------------

_NUMBER = re.compile(r"\s*[-+]?(?:\d+/\d+|(?:\d+\.?\d*|\.\d+)(?:[eE]([-+]?\d+))?)\s*")


def _exact(x) -> Fraction:
    """The exact value of x as a Fraction (irrational sympy numbers: to 80 digits)."""
    if isinstance(x, (bool, type(None))):
        raise ValueError(f"{x!r} is not a number")
    if isinstance(x, (int, Fraction)):
        return Fraction(x)
    if isinstance(x, (float, np.floating)):
        if not math.isfinite(x):
            raise ValueError(f"to_dd: {x} is not a finite number")
        return Fraction(float(x))
    if isinstance(x, np.integer):
        return Fraction(int(x))
    if isinstance(x, mpmath.mpf):
        return _binary(x._mpf_)
    if isinstance(x, type(mpmath.pi)):          # mpmath.pi, mpmath.e, ...: at 300 bits
        with mpmath.workprec(300):
            return _binary(x._mpf_)
    if isinstance(x, str):
        x = _exact_text(x)
        if isinstance(x, Fraction):
            return x
    if is_exact(x):                             # sympy only when given a sympy number
        import sympy as sp
        if x.free_symbols or not x.is_number:
            raise ValueError(f"to_dd: {x} is not a constant")
        if x.is_Rational:
            return Fraction(int(x.p), int(x.q))
        v = x if isinstance(x, sp.Float) else sp.N(x, 80)
        if not isinstance(v, sp.Float) or not v.is_finite:
            raise ValueError(f"to_dd: {x} is not a finite real number")
        return _binary(v._mpf_)
    raise ValueError(f"to_dd: cannot convert {x!r} (a {type(x).__name__}) exactly")


def _exact_text(x: str):
    """A number written as text: a decimal or a ratio as its exact Fraction (beyond the
    expression parser's limits), else the exact sympy number of the safe parser."""
    number = _NUMBER.fullmatch(x)
    if number:
        if abs(int(number.group(1) or 0)) > 1000:
            raise ValueError(f"to_dd: {x!r} is outside the double range")
        return Fraction(x)
    from .expressions import ExpressionError, exact_number
    try:
        return exact_number(x)
    except ExpressionError as exc:
        raise ValueError(f"to_dd: {exc}") from None


def _binary(mpf_value) -> Fraction:
    """The exact value of a raw mpmath number (sign, mantissa, exponent, bits)."""
    sign, man, exp, _ = mpf_value
    if not man and exp:                     # inf or nan
        raise ValueError(f"to_dd: {libmp.to_str(mpf_value, 5)} is not a finite number")
    v = Fraction(int(man)) * Fraction(2) ** int(exp)
    return -v if sign else v


def _round_parts(v: Fraction, k: int) -> tuple:
    """k doubles: each the double nearest to what the previous ones leave of v."""
    parts = []
    for _ in range(k):
        try:
            d = float(v)           # int / int true division: correctly rounded
        except OverflowError:
            raise ValueError("to_dd: the value is outside the double range") from None
        parts.append(d)
        v -= Fraction(d)
    return tuple(parts)


def to_dd(x) -> tuple:
    """The dd (hi, lo) of x, correctly rounded: hi is the double nearest to x and lo the double
    nearest to x − hi.  x: int, float, Fraction, mpmath mpf, an exact sympy number, or a string
    (read exactly by ``expressions.exact_number``: "0.1" is 1/10, "sqrt(2)", "pi/4").

    >>> to_dd("0.1")
    (0.1, -5.551115123125783e-18)
    >>> import sympy as sp
    >>> to_dd(sp.pi) == to_dd(mpmath.pi) == (math.pi, 1.2246467991473532e-16)
    True
    """
    hi, lo = _round_parts(_exact(x), 2)
    return (hi, lo)


def from_dd(hi, lo=None) -> mpmath.mpf:
    """The exact value hi + lo as an mpmath number (however far apart their exponents);
    ``from_dd((hi, lo))`` works too.

    >>> from_dd(1.0, 2.0 ** -80) - 1 == mpmath.mpf(2) ** -80
    True
    """
    if lo is None:
        hi, lo = hi
    a, b = libmp.from_float(float(hi), 53, "n"), libmp.from_float(float(lo), 53, "n")
    return mpmath.mp.make_mpf(libmp.mpf_add(a, b, 0))      # precision 0: exact


def to_dd_array(values) -> np.ndarray:
    """float64 array of shape (n, 2) for a sequence of n numbers, (m, n, 2) for m rows of n
    (lists of lists, a sympy Matrix, a 2-D array); entries as in ``to_dd``.

    >>> to_dd_array([1, "1/3"])
    array([[1.00000000e+00, 0.00000000e+00],
           [3.33333333e-01, 1.85037171e-17]])
    """
    if isinstance(values, np.ndarray) or is_exact(values):   # a sympy Matrix
        values = values.tolist()

    def convert(v):
        return [convert(u) for u in v] if isinstance(v, (list, tuple)) else list(to_dd(v))
    out = np.array(convert(values), dtype=float)
    return out.reshape(0, 2) if out.size == 0 else out


def from_dd_array(arr) -> np.ndarray:
    """The exact values of a dd array (last axis of length 2) as an object array of mpf.

    >>> from_dd_array(to_dd_array(["1/3"]))[0] * 3
    mpf('1.0')
    """
    arr = np.asarray(arr, dtype=float)
    if arr.ndim == 0 or arr.shape[-1] != 2:
        raise ValueError(f"from_dd_array: the last axis must have length 2, not shape {arr.shape}")
    out = np.empty(arr.shape[:-1], dtype=object)
    for index in np.ndindex(out.shape):
        out[index] = from_dd(arr[index][0], arr[index][1])
    return out


def _consts(values, k=2) -> np.ndarray:
    return np.array([_round_parts(_exact(v), k) for v in values], dtype=float)


with mpmath.workprec(400):
    _PIO2 = tuple(_consts([mpmath.pi / 2], 4)[0])      # π/2 as four doubles (≈ 212 bits)
    _LN2 = tuple(_consts([mpmath.ln2], 3)[0])          # ln 2 as three doubles
    _TWO_OVER_PI = float(_exact(2 / mpmath.pi))
_INV_LN2 = float(1 / Fraction(_LN2[0]))
# sin r / r = Σ (−1)^k r^2k / (2k+1)!: dd for k ≤ 8, float64 for 9 ≤ k ≤ 14 (|r| ≤ π/4)
_SIN_DD = _consts([Fraction((-1) ** k, math.factorial(2 * k + 1)) for k in range(9)])
_SIN_TAIL = _consts([Fraction((-1) ** k, math.factorial(2 * k + 1)) for k in range(9, 15)], 1)[:, 0].copy()
# (e^r − 1)/r = Σ r^n / (n+1)!: dd for n ≤ 6, float64 for 7 ≤ n ≤ 12 (|r| ≤ ln 2 / 64)
_EXP_DD = _consts([Fraction(1, math.factorial(n + 1)) for n in range(7)])
_EXP_TAIL = _consts([Fraction(1, math.factorial(n + 1)) for n in range(7, 13)], 1)[:, 0].copy()
# atanh(z)/z = Σ z^2k / (2k+1): dd for k ≤ 10, float64 for 11 ≤ k ≤ 21 (z² ≤ 0.0295)
_LOG_DD = _consts([Fraction(1, 2 * k + 1) for k in range(11)])
_LOG_TAIL = _consts([Fraction(1, 2 * k + 1) for k in range(11, 22)], 1)[:, 0].copy()



# -- numba array access -------------------------------------------------------------------

def dd_get(a, i):
    """The dd in row i of a float64 array of shape (n, 2): (a[i, 0], a[i, 1]).  In numba code a
    builtin that addresses the data directly, for 0 ≤ i < n (no bounds check, no negative
    indices; numba's a[i, 0] first copies the array descriptor to the stack, and thousands of
    those slow LLVM down quadratically).

    >>> dd_get(np.array([[1.0, 2.0 ** -60], [2.0, 0.0]]), 1)
    (2.0, 0.0)
    """
    return float(a[i, 0]), float(a[i, 1])


def dd_set(a, index, x):
    """a[index + (0,)], a[index + (1,)] = x for a float64 array of shape (..., 2); ``index`` an
    integer or a tuple of integers (one per axis but the last), within the shape.  In numba
    code a builtin, as ``dd_get``.

    >>> out = np.zeros((2, 3, 2))
    >>> dd_set(out, (1, 2), (1.0, 2.0 ** -60))
    >>> out[1, 2].tolist() == [1.0, 2.0 ** -60]
    True
    """
    index = index if isinstance(index, tuple) else (index,)
    a[index + (0,)], a[index + (1,)] = x


def _element_pointer(context, builder, aryty, ary, indices):
    """The address of ary[indices], read from the descriptor's fields (data, shape, strides) as
    values: numba's array proxy would first copy the descriptor to the stack."""
    data, shape, strides = (builder.extract_value(ary, k) for k in (4, 5, 6))
    shape, strides = (cgutils.unpack_tuple(builder, t, aryty.ndim) for t in (shape, strides))
    return cgutils.get_item_pointer2(context, builder, data, shape, strides, aryty.layout, indices)


def _float_array(t, ndim=None):
    return isinstance(t, types.Array) and t.dtype == types.float64 and (ndim is None or t.ndim == ndim)


@type_callable(dd_get)
def _type_dd_get(context):
    return lambda a, i: _DD if _float_array(a, 2) and isinstance(i, types.Integer) else None


@lower_builtin(dd_get, types.Any, types.Any)
def _lower_dd_get(context, builder, sig, args):
    aryty, ity = sig.args
    i = context.cast(builder, args[1], ity, types.intp)
    parts = [builder.load(_element_pointer(context, builder, aryty, args[0], [i, context.get_constant(types.intp, k)]))
             for k in (0, 1)]
    return context.make_tuple(builder, _DD, parts)


def _index_types(index):
    return (index,) if isinstance(index, types.Integer) else tuple(index) if isinstance(index, types.BaseTuple) else ()


@type_callable(dd_set)
def _type_dd_set(context):
    def typer(a, index, x):
        ints = _index_types(index)
        ok = (_float_array(a) and a.mutable and len(ints) == a.ndim - 1
              and all(isinstance(t, types.Integer) for t in ints)
              and isinstance(x, types.BaseTuple) and len(x) == 2 and all(isinstance(t, types.Float) for t in x))
        return types.none if ok else None
    return typer


@lower_builtin(dd_set, types.Any, types.Any, types.Any)
def _lower_dd_set(context, builder, sig, args):
    aryty, indexty, xty = sig.args
    ints = _index_types(indexty)
    raw = [args[1]] if isinstance(indexty, types.Integer) else cgutils.unpack_tuple(builder, args[1], len(ints))
    index = [context.cast(builder, v, t, types.intp) for v, t in zip(raw, ints, strict=False)]
    for k in (0, 1):
        value = context.cast(builder, builder.extract_value(args[2], k), xty[k], types.float64)
        builder.store(value, _element_pointer(context, builder, aryty, args[0],
                                              index + [context.get_constant(types.intp, k)]))
    return context.get_dummy_value()


# -- error-free transformations -----------------------------------------------------------------

@_inline("d", "d")
def two_sum(a, b):
    """(s, e) with s = fl(a + b) and s + e = a + b exactly (Knuth; any a, b).

    >>> two_sum(1.0, 1e-20)
    (1.0, 1e-20)
    """
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@_inline("d", "d")
def quick_two_sum(a, b):
    """(s, e) with s = fl(a + b), s + e = a + b exactly, provided |a| ≥ |b| (Dekker).

    >>> quick_two_sum(1.0, 2.0 ** -60)
    (1.0, 8.673617379884035e-19)
    """
    s = a + b
    return s, b - (s - a)


@_inline("d")
def _split(a):
    """(h, l), h + l = a, each with at most 26 significant bits (Dekker's split with 2^27 + 1;
    |a| < 2^996 ≈ 6.7e299, else h and l are nan)."""
    t = 134217729.0 * a
    h = t - (t - a)
    return h, a - h


@_inline("d", "d")
def two_prod(a, b):
    """(p, e) with p = fl(a b) and p + e = a b exactly (Dekker's product, no underflow).

    >>> two_prod(1.0 + 2.0 ** -30, 1.0 - 2.0 ** -30)
    (1.0, -8.673617379884035e-19)
    """
    p = a * b
    ah, al = _split(a)
    bh, bl = _split(b)
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


@_inline("d")
def two_sqr(a):
    """(p, e) with p = fl(a²) and p + e = a² exactly.

    >>> two_sqr(1.0 + 2.0 ** -30)
    (1.0000000018626451, 8.673617379884035e-19)
    """
    p = a * a
    hi, lo = _split(a)
    return p, ((hi * hi - p) + 2.0 * hi * lo) + lo * lo


# -- dd arithmetic -------------------------------------------------------------------------------

@_inline("d")
def dd_from_double(x):
    """The dd (x, 0).

    >>> dd_from_double(0.5)
    (0.5, 0.0)
    """
    return x, 0.0


@_inline("dd")
def dd_neg(a):
    """−a.

    >>> dd_neg((1.0, 1e-20))
    (-1.0, -1e-20)
    """
    return -a[0], -a[1]


@_jit
def dd_abs(a):
    """|a|.

    >>> dd_abs((-1.0, 1e-20))
    (1.0, -1e-20)
    """
    if a[0] < 0.0:
        return -a[0], -a[1]
    return a


@_inline("dd", "dd")
def dd_add(a, b):
    """a + b, relative error ≤ 3u² even under cancellation (QD's ieee_add).

    >>> dd_add((1.0, 1e-20), (-1.0, 1e-20))
    (2e-20, 0.0)
    """
    s1, s2 = two_sum(a[0], b[0])
    t1, t2 = two_sum(a[1], b[1])
    s2 += t1
    s1, s2 = quick_two_sum(s1, s2)
    s2 += t2
    return quick_two_sum(s1, s2)


@_inline("dd", "dd")
def dd_sub(a, b):
    """a − b.

    >>> dd_sub((1.0, 1e-20), (1.0, 0.0))
    (1e-20, 0.0)
    """
    return dd_add(a, (-b[0], -b[1]))


@_inline("dd", "d")
def dd_add_d(a, b):
    """a + b for a double b.

    >>> dd_add_d((1.0, 2.0 ** -60), 2.0 ** -55) == (1.0, 33 * 2.0 ** -60)
    True
    """
    s1, s2 = two_sum(a[0], b)
    s2 += a[1]
    return quick_two_sum(s1, s2)


@_inline("dd", "dd")
def dd_mul(a, b):
    """a × b.

    >>> dd_mul((3.0, 0.0), (1.0, 2.0 ** -60)) == (3.0, 3 * 2.0 ** -60)
    True
    """
    p1, p2 = two_prod(a[0], b[0])
    p2 += a[0] * b[1] + a[1] * b[0]
    return quick_two_sum(p1, p2)


@_inline("dd", "d")
def dd_mul_d(a, b):
    """a × b for a double b.

    >>> dd_mul_d((1.0, 2.0 ** -60), 3.0) == (3.0, 3 * 2.0 ** -60)
    True
    """
    p1, p2 = two_prod(a[0], b)
    p2 += a[1] * b
    return quick_two_sum(p1, p2)


@_inline("dd", "d")
def dd_mul_pwr2(a, b):
    """a × b for b a power of two (exact, barring overflow and underflow).

    >>> dd_mul_pwr2((1.5, 1e-20), 0.5)
    (0.75, 5e-21)
    """
    return a[0] * b, a[1] * b


@_inline("dd")
def dd_sqr(a):
    """a².

    >>> dd_sqr((3.0, 2.0 ** -60)) == (9.0, 6 * 2.0 ** -60)
    True
    """
    p1, p2 = two_sqr(a[0])
    p2 += 2.0 * a[0] * a[1]
    p2 += a[1] * a[1]
    return quick_two_sum(p1, p2)


@_inline("dd", "dd")
def dd_div(a, b):
    """a ÷ b (QD's division: one correction of the double quotient).

    >>> dd_div((1.0, 0.0), (3.0, 0.0)) == to_dd("1/3")
    True
    """
    q1 = a[0] / b[0]
    r = dd_mul_d(b, q1)
    s1, s2 = two_sum(a[0], -r[0])
    s2 -= r[1]
    s2 += a[1]
    q2 = (s1 + s2) / b[0]
    return quick_two_sum(q1, q2)


@_jit
def dd_sqrt(a):
    """√a (nan for a < 0), one Newton step on the double square root.

    >>> dd_sqrt((4.0, 0.0)), dd_sqrt((0.0, 0.0))
    ((2.0, 0.0), (0.0, 0.0))
    """
    if a[0] <= 0.0:
        if a[0] == 0.0:
            return 0.0, 0.0
        return math.nan, math.nan
    s = math.sqrt(a[0])
    p, e = two_sqr(s)
    return quick_two_sum(s, (((a[0] - p) - e) + a[1]) / (2.0 * s))


@_jit
def dd_pow_int(a, n):
    """a**n for an integer n (binary powering; n < 0: 1 / a**|n|; a**0 = 1).

    >>> dd_pow_int((2.0, 0.0), 10), dd_pow_int((2.0, 0.0), -2)
    ((1024.0, 0.0), (0.25, 0.0))
    """
    m = n if n >= 0 else -n
    r = a
    s = (1.0, 0.0)
    while m > 0:
        if m & 1:
            s = dd_mul(s, r)
        m >>= 1
        if m > 0:
            r = dd_sqr(r)
    if n < 0:
        return dd_div((1.0, 0.0), s)
    return s


@_jit
def dd_lt(a, b):
    """a < b.

    >>> dd_lt((1.0, -1e-20), (1.0, 0.0)), dd_lt((1.0, 0.0), (1.0, 0.0))
    (True, False)
    """
    return a[0] < b[0] or (a[0] == b[0] and a[1] < b[1])


@_jit
def dd_gt(a, b):
    """a > b.

    >>> dd_gt((1.0, 1e-20), (1.0, 0.0)), dd_gt((-2.0, 0.0), (1.0, 0.0))
    (True, False)
    """
    return a[0] > b[0] or (a[0] == b[0] and a[1] > b[1])


# -- elementary functions ------------------------------------------------------------------------

@_inline("dd", "dd")
def _add_dominant(a, b):
    """a + b when |a| ≥ 5 |b| or a and b have one sign (QD's sloppy add: no cancellation to
    guard against, error ≤ 2u² |a + b|)."""
    s, e = two_sum(a[0], b[0])
    return quick_two_sum(s, e + (a[1] + b[1]))


@_jit
def _poly(x, dd_coeffs, tail, x_dd):
    """Σ_k c_k x^k by Horner: the tail coefficients (float64) at the double x, then the dd
    coefficients at the dd x_dd (x = x_dd[0]); each c_k dominates the rest of its sum."""
    t = tail[tail.shape[0] - 1]
    for k in range(tail.shape[0] - 2, -1, -1):
        t = t * x + tail[k]
    p = (t, 0.0)
    for k in range(dd_coeffs.shape[0] - 1, -1, -1):
        p = _add_dominant((dd_coeffs[k, 0], dd_coeffs[k, 1]), dd_mul(p, x_dd))
    return p


@_jit
def dd_exp(a):
    """e^a (0 below −745, inf above 709.78; relative error ≲ 1e-31 while e^a is normal).

    >>> import sympy as sp
    >>> dd_exp((1.0, 0.0)) == to_dd(sp.E), dd_exp((0.0, 0.0))
    (True, (1.0, 0.0))
    """
    if a[0] > 709.78:
        return math.inf, 0.0
    if a[0] < -745.2:
        return 0.0, 0.0
    m = math.floor(a[0] * _INV_LN2 + 0.5)
    mf = float(m)
    r = dd_sub(a, two_prod(mf, _LN2[0]))            # a − m ln 2, ln 2 in three doubles
    r = dd_sub(r, two_prod(mf, _LN2[1]))
    r = dd_add_d(r, -mf * _LN2[2])
    r = (r[0] * 0.03125, r[1] * 0.03125)            # |r| ≤ ln 2 / 64
    e = dd_mul(_poly(r[0], _EXP_DD, _EXP_TAIL, r), r)   # e^r − 1
    for _ in range(5):
        e = dd_mul(e, dd_add_d(e, 2.0))             # e^2r − 1 = (e^r − 1)(e^r + 1)
    e = dd_add_d(e, 1.0)
    return math.ldexp(e[0], m), math.ldexp(e[1], m)


@_jit
def dd_log(a):
    """ln a (nan for a < 0, −inf for 0): a = 2^k m with m in [1/√2, √2], then
    ln a = k ln 2 + 2 atanh((m − 1)/(m + 1)); relatively accurate near a = 1.

    >>> import sympy as sp
    >>> dd_log(to_dd(sp.E))[0], dd_log((1.0, 0.0)), dd_log((2.0, 0.0)) == to_dd(sp.log(2))
    (1.0, (0.0, 0.0), True)
    """
    if not a[0] > 0.0:
        if a[0] == 0.0:
            return -math.inf, 0.0
        return math.nan, math.nan
    if a[0] == math.inf:
        return a
    f, k = math.frexp(a[0])
    if f < 0.7071067811865476:
        k -= 1
    m = (math.ldexp(a[0], -k), math.ldexp(a[1], -k))
    z = dd_div(dd_add_d(m, -1.0), dd_add_d(m, 1.0))
    z2 = dd_sqr(z)
    s = dd_mul_pwr2(dd_mul(_poly(z2[0], _LOG_DD, _LOG_TAIL, z2), z), 2.0)
    if k == 0:
        return s
    kf = float(k)
    s = dd_add(s, two_prod(kf, _LN2[0]))
    s = dd_add(s, two_prod(kf, _LN2[1]))
    return dd_add_d(s, kf * _LN2[2])


@_jit
def _reduce_pio2(a):
    """(n, r) with a = n π/2 + r, |r| ≤ π/4 (plus rounding), r accurate to ~u² |r| + 2^-200 |a|."""
    n = math.floor(a[0] * _TWO_OVER_PI + 0.5)
    if n == 0:
        return 0, a
    nf = float(n)
    r = dd_sub(a, two_prod(nf, _PIO2[0]))
    r = dd_sub(r, two_prod(nf, _PIO2[1]))
    r = dd_sub(r, two_prod(nf, _PIO2[2]))
    return n, dd_add_d(r, -nf * _PIO2[3])


@_jit
def _sin_kernel(r):
    """sin r for |r| ≤ π/4 (Taylor, 15 terms)."""
    r2 = dd_sqr(r)
    return dd_mul(_poly(r2[0], _SIN_DD, _SIN_TAIL, r2), r)


@_jit
def _cos_from_sin(s):
    """cos r = √(1 − sin² r) for |r| ≤ π/4 (well conditioned: cos r ≥ 1/√2)."""
    return dd_sqrt(dd_add_d(dd_neg(dd_sqr(s)), 1.0))


@_jit
def dd_sin(a):
    """sin a (absolute error ≲ 1e-31 for |a| ≤ 100; valid for |a| < 2^50).

    >>> import sympy as sp
    >>> dd_sin((0.0, 0.0)), dd_sin(to_dd(sp.pi / 6))
    ((0.0, 0.0), (0.5, 0.0))
    """
    n, r = _reduce_pio2(a)
    s = _sin_kernel(r)
    j = n & 3
    if j & 1:
        s = _cos_from_sin(s)
    if j >= 2:
        return -s[0], -s[1]
    return s


@_jit
def dd_cos(a):
    """cos a (absolute error ≲ 1e-31 for |a| ≤ 100; valid for |a| < 2^50).

    >>> import sympy as sp
    >>> dd_cos((0.0, 0.0)), dd_cos(to_dd(sp.pi / 3))
    ((1.0, 0.0), (0.5, -0.0))
    """
    n, r = _reduce_pio2(a)
    s = _sin_kernel(r)
    j = n & 3
    if j & 1:
        c = s
    else:
        c = _cos_from_sin(s)
    if j == 1 or j == 2:
        return -c[0], -c[1]
    return c


@_jit
def dd_sincos(a):
    """(sin a, cos a), one argument reduction and one series for both.

    >>> dd_sincos((0.0, 0.0))
    ((0.0, 0.0), (1.0, 0.0))
    """
    n, r = _reduce_pio2(a)
    s = _sin_kernel(r)
    c = _cos_from_sin(s)
    j = n & 3
    if j & 1:
        s, c = c, (-s[0], -s[1])
    if j >= 2:
        return (-s[0], -s[1]), (-c[0], -c[1])
    return s, c
