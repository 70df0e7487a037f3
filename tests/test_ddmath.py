"""Double-double arithmetic (numeric/ddmath.py) and its code printer (numeric/ddcode.py) against
mpmath at 50 digits: the primitives compiled by numba on random and adversarial inputs
(cancellation, magnitudes from 1e-290 to 1e290, arguments near multiples of pi/2), the same
primitives run as Python (bit for bit the same), and the generated f and Jacobian of the
built-in problems."""
import re
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings, strategies as st
from numba import njit

from tableau_lab.numeric.ddcode import dd_function, dd_source
from tableau_lab.numeric.ddmath import (
    dd_abs,
    dd_add,
    dd_add_d,
    dd_cos,
    dd_div,
    dd_exp,
    dd_from_double,
    dd_get,
    dd_gt,
    dd_log,
    dd_lt,
    dd_mul,
    dd_mul_d,
    dd_mul_pwr2,
    dd_neg,
    dd_pow_int,
    dd_set,
    dd_sin,
    dd_sincos,
    dd_sqr,
    dd_sqrt,
    dd_sub,
    from_dd,
    from_dd_array,
    quick_two_sum,
    to_dd,
    to_dd_array,
    two_prod,
    two_sum,
)
from tableau_lab.numeric.problems import PROBLEMS, get_problem

U2 = Fraction(1, 2 ** 106)          # u² for u = 2^-53
DPS = 50


# -- compiled kernels: every primitive applied to rows of dd arrays --------------------------------

@njit
def binary_ops(a, b, out):
    for i in range(a.shape[0]):
        x, y = dd_get(a, i), dd_get(b, i)
        dd_set(out, (0, i), dd_add(x, y))
        dd_set(out, (1, i), dd_sub(x, y))
        dd_set(out, (2, i), dd_mul(x, y))
        dd_set(out, (3, i), dd_div(x, y))
        dd_set(out, (4, i), dd_mul_d(x, y[0]))
        dd_set(out, (5, i), dd_add_d(x, y[0]))


@njit
def unary_ops(a, out):
    for i in range(a.shape[0]):
        x = dd_get(a, i)
        ax = dd_abs(x)
        dd_set(out, (0, i), dd_sqr(x))
        dd_set(out, (1, i), dd_sqrt(ax))
        dd_set(out, (2, i), dd_pow_int(x, 7))
        dd_set(out, (3, i), dd_pow_int(x, -5))
        dd_set(out, (4, i), dd_neg(x))
        dd_set(out, (5, i), dd_mul_pwr2(x, 0.125))
        dd_set(out, (6, i), dd_from_double(x[0]))


@njit
def function_ops(a, out):
    for i in range(a.shape[0]):
        x = dd_get(a, i)
        s, c = dd_sincos(x)
        dd_set(out, (0, i), dd_sin(x))
        dd_set(out, (1, i), dd_cos(x))
        dd_set(out, (2, i), s)
        dd_set(out, (3, i), c)
        dd_set(out, (4, i), dd_exp(x))
        dd_set(out, (5, i), dd_log(dd_abs(x)))


@njit
def compare_ops(a, b, out):
    for i in range(a.shape[0]):
        x, y = dd_get(a, i), dd_get(b, i)
        out[i, 0] = dd_lt(x, y)
        out[i, 1] = dd_gt(x, y)


def rng(seed=1):
    return np.random.default_rng(seed)


def dd_random(r, n, lo, hi, sign=True):
    """n dd numbers with full 106-bit mantissas, magnitudes 10^lo .. 10^hi."""
    with mpmath.workdps(DPS):
        values = []
        for _ in range(n):
            m = mpmath.mpf(r.uniform(0.5, 1)) * (1 + mpmath.mpf(r.uniform(-1, 1)) * mpmath.mpf(2) ** -52)
            v = m * mpmath.mpf(10) ** r.uniform(lo, hi)
            values.append(-v if sign and r.random() < 0.5 else v)
    return to_dd_array(values)


def fraction(v):
    """The exact value of an mpf (or a Fraction)."""
    if isinstance(v, Fraction):
        return v
    sign, man, exp, _ = (v if isinstance(v, mpmath.mpf) else mpmath.mpf(v))._mpf_     # mpf(v) would round v
    return (-1) ** sign * Fraction(int(man)) * Fraction(2) ** int(exp)


def error(out, ref, relative=True):
    """max |out − ref| (/ |ref|) in units of u², out a dd array, ref exact values (Fractions or mpf)."""
    worst = Fraction(0)
    for got, r in zip(from_dd_array(out), ref, strict=False):
        r = fraction(r)
        e = abs(fraction(got) - r)
        worst = max(worst, e / abs(r) if relative and r else e)
    return float(worst / U2)


def exact(arr):
    return [fraction(v) for v in from_dd_array(arr)]


def reference(fn, arr):
    with mpmath.workdps(DPS):
        return [fn(v) for v in from_dd_array(arr)]


# -- the arithmetic --------------------------------------------------------------------------------

@pytest.mark.parametrize("lo, hi", [(-3, 3), (-140, 140)])
def test_arithmetic_is_accurate(lo, hi):
    r = rng()
    a, b = dd_random(r, 400, lo, hi), dd_random(r, 400, lo, hi)
    out = np.empty((6, len(a), 2))
    binary_ops(a, b, out)
    x, y = exact(a), exact(b)
    yd = [Fraction(v) for v in b[:, 0]]
    bounds = {"add": 3, "sub": 3, "mul": 8, "div": 16, "mul_d": 4, "add_d": 2}
    refs = [[p + q for p, q in zip(x, y, strict=False)], [p - q for p, q in zip(x, y, strict=False)],
            [p * q for p, q in zip(x, y, strict=False)], [p / q for p, q in zip(x, y, strict=False)],
            [p * q for p, q in zip(x, yd, strict=False)], [p + q for p, q in zip(x, yd, strict=False)]]
    for k, (name, bound) in enumerate(bounds.items()):
        assert error(out[k], refs[k]) <= bound, name


def test_addition_under_cancellation():
    """x + y with y = −x(1 + δ), δ from 1e-30 to 1e-5: the accurate (IEEE) addition keeps the
    relative error of the small result at a few u²."""
    r = rng(2)
    a = dd_random(r, 300, -5, 5)
    with mpmath.workdps(DPS):
        b = to_dd_array([-v * (1 + mpmath.mpf(r.uniform(-1, 1)) * mpmath.mpf(10) ** -r.uniform(5, 30))
                         for v in from_dd_array(a)])
    out = np.empty((6, len(a), 2))
    binary_ops(a, b, out)
    x, y = exact(a), exact(b)
    assert error(out[0], [p + q for p, q in zip(x, y, strict=False)]) <= 3
    binary_ops(a, -b, out)
    assert error(out[1], [p + q for p, q in zip(x, y, strict=False)]) <= 3          # x − (−y)


def test_unary_operations():
    r = rng(3)
    a = dd_random(r, 400, -40, 40)
    out = np.empty((7, len(a), 2))
    unary_ops(a, out)
    x = exact(a)
    assert error(out[0], [v * v for v in x]) <= 8
    with mpmath.workdps(DPS):
        assert error(out[1], [mpmath.sqrt(abs(mpmath.mpf(v.numerator) / v.denominator)) for v in x]) <= 4
    assert error(out[2], [v ** 7 for v in x]) <= 80         # 1e-30: six roundings of ≤ 8u²
    assert error(out[3], [v ** -5 for v in x]) <= 80
    assert (out[4] == -a).all() and (out[5] == a / 8).all() and (out[6][:, 1] == 0).all()


def test_extreme_magnitudes():
    """Products, quotients and sums of numbers from 1e-290 to 1e290, square roots of 1e±280;
    factors beyond 2^996 give nan (Dekker's split), not a wrong number."""
    r = rng(4)
    big, small, other = dd_random(r, 200, 140, 290), dd_random(r, 200, -290, -140), dd_random(r, 200, 140, 290)
    out = np.empty((6, len(big), 2))
    binary_ops(big, small, out)
    x, y, z = exact(big), exact(small), exact(other)
    assert error(out[2], [p * q for p, q in zip(x, y, strict=False)]) <= 8
    assert error(out[0], [p + q for p, q in zip(x, y, strict=False)]) <= 3
    binary_ops(big, other, out)
    assert error(out[3], [p / q for p, q in zip(x, z, strict=False)]) <= 16
    edge = to_dd_array(["1e280", "1e-280"])          # full dd precision needs |x| > 2^-969 ≈ 2e-292
    out = np.empty((7, 2, 2))
    unary_ops(edge, out)
    with mpmath.workdps(DPS):
        assert error(out[1], [mpmath.sqrt(v) for v in from_dd_array(edge)]) <= 4
    huge, tiny = np.array([[1e305, 0.0]]), np.array([[1e-305, 0.0]])
    out = np.empty((6, 1, 2))
    binary_ops(huge, tiny, out)
    assert np.isnan(out[2, 0, 0]) and np.isnan(dd_mul((1e305, 0.0), (1e-305, 0.0))[0])
    assert dd_sqrt((0.0, 0.0)) == (0.0, 0.0) and np.isnan(dd_sqrt((-1.0, 0.0))[0])


def test_elementary_functions():
    r = rng(5)
    trig = dd_random(r, 400, -2, 2)
    out = np.empty((6, len(trig), 2))
    function_ops(trig, out)
    with mpmath.workdps(DPS):
        sin, cos = reference(mpmath.sin, trig), reference(mpmath.cos, trig)
        for k, ref in enumerate([sin, cos, sin, cos]):
            assert error(out[k], ref, relative=False) * float(U2) <= 1e-31
        # exp on [-100, 100], log on [1e-100, 1e100]: relative
        assert error(out[4], reference(mpmath.exp, trig)) * float(U2) <= 1e-31
        assert error(out[5], reference(lambda v: mpmath.log(abs(v)), trig)) * float(U2) <= 1e-31
        wide = dd_random(r, 200, -300, 300, sign=False)
        out = np.empty((6, len(wide), 2))
        function_ops(wide, out)
        assert error(out[5], reference(mpmath.log, wide)) * float(U2) <= 1e-31
        near_one = to_dd_array([1 + mpmath.mpf(r.uniform(-1, 1)) * mpmath.mpf(10) ** -r.uniform(1, 25)
                                for _ in range(200)])
        out = np.empty((6, len(near_one), 2))
        function_ops(near_one, out)
        assert error(out[5], reference(mpmath.log, near_one)) * float(U2) <= 1e-31   # relative, log ≈ 1e-25
        large = dd_random(r, 200, 2, 2.845)                                            # |x| up to 700
        out = np.empty((6, len(large), 2))
        function_ops(large, out)
        assert error(out[4], reference(mpmath.exp, large)) * float(U2) <= 1e-30


def test_sin_cos_near_multiples_of_half_pi():
    """x = k pi/2 + d for |k| <= 64 and d from 0 to 1e-8: the argument reduction uses pi/2 in
    four doubles and exact products, so the absolute error stays at the u² level."""
    with mpmath.workdps(DPS):
        args = to_dd_array([k * mpmath.pi / 2 + d for k in range(-64, 65)
                            for d in (0, mpmath.mpf(10) ** -31, -mpmath.mpf(10) ** -20, mpmath.mpf(10) ** -8)])
        out = np.empty((6, len(args), 2))
        function_ops(args, out)
        for k, ref in enumerate([reference(mpmath.sin, args), reference(mpmath.cos, args)] * 2):
            assert error(out[k], ref, relative=False) * float(U2) <= 1e-31


def test_special_values_and_comparisons():
    assert dd_exp((0.0, 0.0)) == (1.0, 0.0) and dd_exp((800.0, 0.0))[0] == np.inf
    assert dd_exp((-800.0, 0.0)) == (0.0, 0.0) and dd_log((1.0, 0.0)) == (0.0, 0.0)
    assert dd_log((0.0, 0.0))[0] == -np.inf and np.isnan(dd_log((-1.0, 0.0))[0])
    assert dd_pow_int((3.0, 0.0), 0) == (1.0, 0.0) and dd_pow_int((2.0, 0.0), -3) == (0.125, 0.0)
    assert dd_abs((-1.0, 2.0 ** -60)) == (1.0, -2.0 ** -60)
    a = np.array([[1.0, -1e-20], [1.0, 0.0], [-2.0, 0.0], [1.0, 1e-20]])
    b = np.array([[1.0, 0.0], [1.0, 0.0], [1.0, 0.0], [1.0, 0.0]])
    out = np.empty((4, 2), dtype=np.bool_)
    compare_ops(a, b, out)
    assert out.tolist() == [[True, False], [False, False], [True, False], [False, True]]


def test_python_and_compiled_agree_bit_for_bit():
    """The branch-free primitives are plain Python functions traced into numba code: both
    must give the same doubles."""
    r = rng(6)
    a, b = dd_random(r, 50, -5, 5), dd_random(r, 50, -5, 5)
    out = np.empty((6, len(a), 2))
    binary_ops(a, b, out)
    for i in range(len(a)):
        x, y = tuple(a[i]), tuple(b[i])
        python = [dd_add(x, y), dd_sub(x, y), dd_mul(x, y), dd_div(x, y), dd_mul_d(x, y[0]), dd_add_d(x, y[0])]
        assert [tuple(out[k, i]) for k in range(6)] == python


@settings(max_examples=200, deadline=None)
@given(st.floats(-1e150, 1e150), st.floats(-1e150, 1e150))
def test_error_free_transformations(a, b):
    s, e = two_sum(a, b)
    assert Fraction(s) + Fraction(e) == Fraction(a) + Fraction(b) and s == a + b
    p, e = two_prod(a, b)
    if a == 0 or b == 0 or abs(p) > 1e-280:              # no underflow of the error term
        assert Fraction(p) + Fraction(e) == Fraction(a) * Fraction(b)
    if abs(a) >= abs(b):
        s, e = quick_two_sum(a, b)
        assert Fraction(s) + Fraction(e) == Fraction(a) + Fraction(b)


# -- conversions -----------------------------------------------------------------------------------

def test_to_dd_is_correctly_rounded():
    for x, v in [("1/3", Fraction(1, 3)), ("0.1", Fraction("0.1")),
                 ("-2.95912208286e-4", Fraction("-2.95912208286e-4")),
                 ("1/1.3e8", 1 / Fraction("1.3e8")), ("1e-300", Fraction("1e-300")),
                 ("123456789.123456789123456789", Fraction("123456789.123456789123456789"))]:
        hi, lo = to_dd(x)
        assert hi == float(v) and lo == float(v - Fraction(hi))
    with mpmath.workdps(60):
        assert to_dd(sp.sqrt(2)) == to_dd(mpmath.sqrt(2)) == to_dd("sqrt(2)")
        assert from_dd(*to_dd(sp.pi)) - mpmath.pi < mpmath.mpf(2) ** -106 * 4
    assert to_dd(mpmath.mpf(1) / 3) == (1 / 3, 0.0)              # an mpf is read exactly as it is
    assert to_dd(sp.Float("0.1", 40)) != to_dd(0.1)
    with mpmath.workprec(300):
        assert from_dd(1.0, 2.0 ** -200) == 1 + mpmath.mpf(2) ** -200 and from_dd((2.0, 0.0)) == 2
    for bad in ["x", "1e400", sp.Symbol("q"), sp.I, None, "nan"]:
        with pytest.raises(ValueError):
            to_dd(bad)


def test_arrays():
    a = to_dd_array([[1, "1/3"], [sp.pi, 0]])
    assert a.shape == (2, 2, 2) and tuple(a[0, 1]) == to_dd("1/3")
    assert (to_dd_array(sp.Matrix([[1, sp.Rational(1, 3)], [sp.pi, 0]])) == a).all()
    assert to_dd_array([]).shape == (0, 2) and to_dd_array(np.array([0.5, 2.0])).tolist() == [[0.5, 0], [2, 0]]
    back = from_dd_array(a)
    assert back.shape == (2, 2) and back[0, 1] == from_dd(*to_dd("1/3"))
    with pytest.raises(ValueError):
        from_dd_array(np.zeros((2, 3)))


# -- generated code --------------------------------------------------------------------------------

GENERATED = ["pendulum", "kepler", "henon_heiles", "fpu", "outer_solar_system"]


def perturbed_state(problem, seed=7):
    """The initial state with every component moved by up to 10 % (zero components by a
    fraction of the typical size), as mpf at 50 digits."""
    r = rng(seed)
    with mpmath.workdps(DPS):
        y0 = [mpmath.mpf(str(sp.N(v, DPS + 10))) for v in problem.initial_state()]
        size = min((abs(v) for v in y0 if v), default=mpmath.mpf(1)) * mpmath.mpf("1e-2")
        return [v + (abs(v) or size) * mpmath.mpf(r.uniform(-0.1, 0.1)) for v in y0]


def compiled(problem, exprs, shape):
    """The dd values of exprs at the perturbed state by generated code, with that state and the
    parameters (the exact values of their dd)."""
    args = [problem.state, tuple(problem.parameter_symbols.values())]
    y = to_dd_array(perturbed_state(problem))
    c = to_dd_array(list(problem.parameters.values()))
    out = np.full(shape + (2,), np.nan)
    dd_function("generated", args, exprs)(y, c, out)
    return from_dd_array(out), list(from_dd_array(y)), list(from_dd_array(c))


def agree(problem, got, ref, tol=1e-29):
    """Relative agreement, measured against 1e-3 of the largest entry where an entry is a
    near-cancellation of larger terms (the sun's rows in the solar system)."""
    ref = np.array(ref, dtype=object).reshape(got.shape)
    scale = max(abs(v) for v in ref.flat)
    for g, v in zip(got.flat, ref.flat, strict=False):
        assert abs(g - v) <= tol * max(abs(v), scale * mpmath.mpf("1e-3")), (problem.name, g, v)


def check_generated(problem, exprs, shape):
    got, y, c = compiled(problem, exprs, shape)
    with mpmath.workdps(DPS):
        args = [problem.state, tuple(problem.parameter_symbols.values())]
        agree(problem, got, sp.lambdify(args, exprs, modules="mpmath")(y, c))


@pytest.mark.parametrize("name", GENERATED)
def test_generated_f_and_jacobian(name):
    """f against mpmath on the same expressions; the Jacobian against central differences of
    that f at 100 digits (step 1e-30: truncation and rounding far below 1e-50).  Of the solar
    system's 36 rows, 9 (pluto's dq/dt, the sun's and jupiter's dp/dt, with the sun's
    cancellations): the whole 36 x 36 Jacobian, 1300 dd operations, takes 6 to 10 s to compile
    (benchmarks/dd_bench.py compiles it)."""
    problem = get_problem(name)
    f = list(problem.f_expr)
    check_generated(problem, f, (len(f),))
    n = problem.dimension
    rows = range(15, 24) if name == "outer_solar_system" else range(n)
    jac = sp.Matrix([f[i] for i in rows]).jacobian(problem.state)
    got, y, c = compiled(problem, jac.tolist(), jac.shape)
    fun = sp.lambdify([problem.state, tuple(problem.parameter_symbols.values())], f, modules="mpmath")
    with mpmath.workdps(100):
        h = mpmath.mpf(10) ** -30
        columns = [[(a - b) / (2 * h) for a, b in zip(fun(y[:j] + [y[j] + h] + y[j + 1:], c),
                                                          fun(y[:j] + [y[j] - h] + y[j + 1:], c), strict=False)]
                   for j in range(n)]
        agree(problem, got, [[columns[j][i] for j in range(n)] for i in rows])


@pytest.mark.parametrize("name", [n for n in PROBLEMS if n != "outer_solar_system"])
def test_generated_invariants_and_gradients(name):
    problem = get_problem(name)
    invariants = list(problem.invariants.values())
    check_generated(problem, invariants, (len(invariants),))
    grads = [[sp.diff(e, s) for s in problem.state] for e in invariants]
    check_generated(problem, grads, (len(grads), problem.dimension))


def test_every_problem_prints():
    """f, Jacobian, invariants and gradients of every built-in problem print (the largest
    ones are compiled above)."""
    for problem in PROBLEMS.values():
        args = [problem.state, tuple(problem.parameter_symbols.values())]
        for e in problem.invariants.values():
            assert "def g(y, c, out):" in dd_source("g", args, [sp.diff(e, s) for s in problem.state])
        assert dd_source("g", args, list(problem.invariants.values())).count("dd_set(") == len(problem.invariants)


def test_printer_choices():
    x, y, k = sp.symbols("x y k", real=True)
    src = dd_source("g", [(x, y), (k,)], [[x / 3 - 2 * y + sp.Rational(1, 3), x ** -sp.Rational(5, 2)],
                                          [sp.sin(x) * sp.cos(x), 0]])
    assert "(0.3333333333333333, 1.850371707708594e-17))" in src                       # 1/3 as a dd
    assert "dd_mul_pwr2(" in src and "dd_sub(" in src                                  # 2y; − 1/3
    assert re.search(r"dd_sqrt\(t\d+\)", src) and re.search(r"dd_div\(\(1\.0, 0\.0\), t\d+\)", src)  # x^(-5/2)
    assert src.count("dd_sincos(") == 1 and "dd_sin(" not in src                       # both from one call
    assert "out[...] = 0.0" not in src and "dd_set(out, (1, 1), (0.0, 0.0))" in src
    g = dd_function("g", [(x, y), (k,)], [[x / 3 - 2 * y + sp.Rational(1, 3), x ** -sp.Rational(5, 2)],
                                          [sp.sin(x) * sp.cos(x), sp.exp(y) + sp.log(x) + sp.Abs(y)]])
    out = np.zeros((2, 2, 2))
    g(to_dd_array(["0.7", "-1.3"]), to_dd_array([1]), out)
    with mpmath.workdps(DPS):
        xv, yv = (from_dd(*to_dd(v)) for v in ("0.7", "-1.3"))
        ref = [xv / 3 - 2 * yv + mpmath.mpf(1) / 3, xv ** -2.5, mpmath.sin(xv) * mpmath.cos(xv),
               mpmath.exp(yv) + mpmath.log(xv) + abs(yv)]
        assert all(abs(g_ - r_) < 1e-30 for g_, r_ in zip(from_dd_array(out).flat, ref, strict=False))


@pytest.mark.parametrize("exprs, message", [
    ([sp.tan(sp.Symbol("x"))], "cannot print tan(x)"),
    ([sp.Symbol("x") ** sp.Rational(1, 3)], "x**(1/3)"),
    ([sp.Symbol("x") ** sp.Symbol("y")], "x**y"),
    ([sp.Symbol("z")], "neither in args"),
    ([[sp.Symbol("x")], [1, 2]], "one length"),
])
def test_printer_refuses(exprs, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)").replace("*", r"\*")):
        dd_source("g", [(sp.Symbol("x"), sp.Symbol("y"))], exprs)
    with pytest.raises(ValueError, match="cannot name"):
        dd_source("dd_add", [()], [1])
