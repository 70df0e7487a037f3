r"""sympy expressions -> the source of one numba function computing them in double-double.

``dd_source(name, args, exprs)`` prints ``def name(y, c, out):``, where y (shape (n, 2)) holds
the dd values of the symbols ``args[0]``, c (shape (k, 2)) those of ``args[1]``, and out
receives the dd values of ``exprs``: shape (m, 2) for a list of m expressions (or one
expression: m = 1), (m, m2, 2) for a matrix (a list of lists or a sympy Matrix).  The text
assumes ``from tableau_lab.numeric.ddmath import *`` in the module it is run in; it allocates
nothing (dd values are tuples) and calls only the ddmath primitives:

* y and c read by ``dd_get``, out written by ``dd_set`` (``out[...] = 0.0`` first when more
  than two entries are 0);
* common subexpressions by sympy's ``cse``, then identical calls once; signs carried along
  rather than computed (−a·b + c is ``dd_sub(c, dd_mul(a, b))``);
* sums as balanced trees of ``dd_add`` with the negative terms subtracted (``dd_sub``);
* products as ``dd_mul``, quotients (negative powers) as one ``dd_div`` of the numerator by the
  product of the denominators; a numeric coefficient is exact: ``dd_mul_pwr2`` or ``dd_mul_d``
  when it is a double, else ``dd_mul`` by its dd literal (1/3 is the dd of 1/3);
* integer powers by squarings and products (``dd_pow_int`` beyond 16), half-integer powers
  x^(k/2) as x^((k−1)/2) · √x; ``sin``/``cos`` (``dd_sincos`` when both of one argument are
  needed), ``exp``, ``log``, ``Abs``; constants (π, √2, …) as dd literals, correctly rounded.

Anything else (other functions, symbolic or non-half-integer exponents, unknown symbols)
raises ValueError naming the expression.  ``dd_function`` compiles the source with numba:
about 2 ms per dd operation (the outer solar system: f in 2 s, its 36 x 36 Jacobian, 1300
operations, in 6 to 10 s).

>>> import sympy as sp
>>> q, p, k = sp.symbols("q p k", real=True)
>>> print(dd_source("f", [(q, p), (k,)], [p, -k * sp.sin(q) / 3]))
def f(y, c, out):
    t0 = dd_get(y, 1)
    dd_set(out, 0, t0)
    t1 = dd_get(c, 0)
    t2 = dd_get(y, 0)
    t3 = dd_sin(t2)
    t4 = dd_mul(t1, t3)
    t5 = dd_mul(t4, (0.3333333333333333, 1.850371707708594e-17))
    t6 = dd_neg(t5)
    dd_set(out, 1, t6)
<BLANKLINE>
>>> from tableau_lab.numeric.ddmath import to_dd_array, from_dd_array
>>> f = dd_function("f", [(q, p), (k,)], [p, -k * sp.sin(q) / 3])
>>> out = np.zeros((2, 2))
>>> f(to_dd_array(["1/2", 2]), to_dd_array([3]), out)
>>> import mpmath
>>> with mpmath.workdps(40):
...     mpmath.nstr(from_dd_array(out)[1], 32), mpmath.nstr(-mpmath.sin(mpmath.mpf(1) / 2), 32)
('-0.47942553860420300027328793521557', '-0.47942553860420300027328793521557')
>>> dd_source("g", [(q,)], [sp.tan(q)])  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
ValueError: dd_source: cannot print tan(q) in double-double (only +, *, integer and half-integer powers, ...)
"""
from __future__ import annotations

import itertools
import keyword
import math

import numpy as np
import sympy as sp

from . import ddmath
from .ddmath import to_dd

__all__ = ["dd_source", "dd_function"]

_UNARY = {sp.sin: "dd_sin", sp.cos: "dd_cos", sp.exp: "dd_exp", sp.log: "dd_log", sp.Abs: "dd_abs"}
_ONE = "(1.0, 0.0)"


def _fail(e, why="only +, *, integer and half-integer powers, sin, cos, exp, log, Abs"):
    return ValueError(f"dd_source: cannot print {e} in double-double ({why})")


def _dd(value) -> tuple:
    """A constant's dd, correctly rounded."""
    try:
        return to_dd(value)
    except (ValueError, TypeError) as exc:
        raise _fail(value, f"not a finite real constant: {exc}") from None


def _literal(value) -> str:
    """A constant as a dd tuple literal."""
    hi, lo = _dd(value)
    return f"({hi!r}, {lo!r})"


class _Printer:
    """Prints expressions as statements.  Signs are carried, not computed: ``signed(e)`` is a
    pair (name, negative) with e = −name when negative, so that −x·y or a − (−b) costs no
    ``dd_neg``; ``value(e)`` is e itself (negated only where a value is needed as it is)."""

    def __init__(self, symbols: dict, sincos_args: set):
        self.symbols = symbols            # Symbol -> text of its load from y or c
        self.sincos_args = sincos_args    # arguments whose sin and cos are both used
        self.lines: list = []
        self.calls: dict = {}             # call text -> temporary (value numbering)
        self.values: dict = {}            # sympy expression -> (temporary or literal, negative)

    def emit(self, text: str) -> str:
        if text not in self.calls:
            self.calls[text] = f"t{len(self.calls)}"
            self.lines.append(f"    {self.calls[text]} = {text}")
        return self.calls[text]

    def signed(self, e) -> tuple:
        if e not in self.values:
            self.values[e] = self._print(e)
        return self.values[e]

    def value(self, e) -> str:
        """The temporary (or literal) holding the dd value of e."""
        name, negative = self.signed(e)
        return self.emit(f"dd_neg({name})") if negative else name

    def _print(self, e) -> tuple:
        if isinstance(e, sp.Symbol):
            if e not in self.symbols:
                raise _fail(e, "a symbol that is neither in args[0] nor in args[1]")
            return self.emit(self.symbols[e]), False
        if not e.free_symbols:
            return _literal(e), False
        if isinstance(e, sp.Add):
            return self._sum(e)
        if isinstance(e, (sp.Mul, sp.Pow)):
            return self._product(e)
        if isinstance(e, (sp.sin, sp.cos, sp.Abs)):          # odd, even, even: the argument's sign
            arg, negative = self.signed(e.args[0])
            odd = negative and isinstance(e, sp.sin)
            if isinstance(e, sp.Abs):
                return self.emit(f"dd_abs({arg})"), False
            if e.args[0] in self.sincos_args:
                both = self.emit(f"dd_sincos({arg})")
                return self.emit(f"{both}[{0 if isinstance(e, sp.sin) else 1}]"), odd
            return self.emit(f"{_UNARY[type(e)]}({arg})"), odd
        if isinstance(e, tuple(_UNARY)) and len(e.args) == 1:
            return self.emit(f"{_UNARY[type(e)]}({self.value(e.args[0])})"), False
        raise _fail(e)

    def _tree(self, op: str, names: list) -> str:
        """names combined by op as a balanced binary tree (short dependency chains)."""
        while len(names) > 1:
            pairs = [self.emit(f"{op}({a}, {b})") for a, b in zip(names[::2], names[1::2], strict=False)]
            names = pairs + names[len(pairs) * 2:]
        return names[0]

    def _sum(self, e) -> tuple:
        constant = sp.Add(*[t for t in e.args if not t.free_symbols])
        plus, minus = [], []
        for t in e.args:
            if t.free_symbols:
                flip = t.as_coeff_Mul()[0].is_negative
                name, negative = self.signed(-t if flip else t)
                (minus if flip != negative else plus).append(name)
        negative = not plus                   # −(sum of the minus terms)
        s = self._tree("dd_add", plus or minus)
        if plus and minus:
            s = self.emit(f"dd_sub({s}, {self._tree('dd_add', minus)})")
        if constant == 0:
            return s, negative
        constant = -constant if negative else constant
        hi, lo = _dd(constant)
        return self.emit(f"dd_add_d({s}, {hi!r})" if lo == 0 else f"dd_add({s}, {_literal(constant)})"), negative

    def _power(self, base: str, n: int) -> str:
        """base**n for an integer n ≥ 1 by squarings and products."""
        if n == 1:
            return base
        if n > 16:
            return self.emit(f"dd_pow_int({base}, {n})")
        if n % 2 == 0:
            return self.emit(f"dd_sqr({self._power(base, n // 2)})")
        return self.emit(f"dd_mul({self._power(base, n - 1)}, {base})")

    def _product(self, e) -> tuple:
        factors = sp.Mul.make_args(e)
        coeff = sp.Mul(*[f for f in factors if not f.free_symbols])
        negative = bool(coeff.is_negative)
        coeff = -coeff if negative else coeff
        numerator, denominator = [], []
        for f in factors:
            if not f.free_symbols:
                continue
            base, exp = f.as_base_exp() if isinstance(f, sp.Pow) else (f, sp.S.One)
            if exp.is_Float and (2 * exp).is_integer:
                exp = sp.Rational(exp)
            if not (exp.is_Rational and exp.q in (1, 2)):
                raise _fail(f, "powers must be integers or halves of odd integers")
            k = abs(exp.p)
            if exp.q == 1:
                b, flip = self.signed(base)
                r = self._power(b, k)
                negative ^= flip and k % 2 == 1
            else:
                b = self.value(base)
                r = self.emit(f"dd_sqrt({b})")
                if k > 1:
                    r = self.emit(f"dd_mul({self._power(b, (k - 1) // 2)}, {r})")
            (denominator if exp < 0 else numerator).append(r)
        num = self._tree("dd_mul", numerator) if numerator else None
        if coeff != 1:
            hi, lo = _dd(coeff)
            if num is None:
                num = _literal(coeff)
            elif lo == 0 and math.frexp(hi)[0] == 0.5:          # a power of two
                num = self.emit(f"dd_mul_pwr2({num}, {hi!r})")
            elif lo == 0:
                num = self.emit(f"dd_mul_d({num}, {hi!r})")
            else:
                num = self.emit(f"dd_mul({num}, {_literal(coeff)})")
        if denominator:
            num = self.emit(f"dd_div({num or _ONE}, {self._tree('dd_mul', denominator)})")
        return num, negative


def _entries(exprs):
    """(flat list of sympy expressions, shape of out without the last axis)."""
    if isinstance(exprs, sp.MatrixBase):
        exprs = exprs.tolist()
    if isinstance(exprs, (sp.Basic, int, float)):
        exprs = [exprs]
    exprs = [list(r) if isinstance(r, (list, tuple, sp.MatrixBase)) else r for r in exprs]
    if exprs and all(isinstance(r, list) for r in exprs):
        if len({len(r) for r in exprs}) != 1:
            raise ValueError("dd_source: the rows of a matrix must have one length")
        return [sp.sympify(v) for r in exprs for v in r], (len(exprs), len(exprs[0]))
    if any(isinstance(r, list) for r in exprs):
        raise ValueError("dd_source: give a list of expressions or a list of rows, not a mixture")
    return [sp.sympify(v) for v in exprs], (len(exprs),)


def dd_source(name: str, args, exprs, at=None, row: bool = False) -> str:
    """The source text of ``def name(y, c, out):`` evaluating ``exprs`` in double-double; see
    the module docstring.  ``args`` = (symbols of y, symbols of c), the second optional.
    ``at``: the rows of ``out`` that a list of expressions goes to (default 0, 1, …); the
    other rows are left as they are.  ``row``: ``def name(y, c, out, i)`` writing a list of
    expressions into row i of a matrix out (no view of the row is made)."""
    if not (isinstance(name, str) and name.isidentifier() and not keyword.iskeyword(name)
            and name not in ddmath.__all__ and name not in ("y", "c", "out")):
        raise ValueError(f"dd_source: {name!r} cannot name the function")
    if len(args) not in (1, 2):
        raise ValueError("dd_source: args is (state symbols,) or (state symbols, parameter symbols)")
    symbols = {}
    for array, syms in zip("yc", args, strict=False):
        for i, s in enumerate(syms):
            if not isinstance(s, sp.Symbol) or s in symbols:
                raise ValueError(f"dd_source: {s} is not a symbol, or appears twice in args")
            symbols[s] = f"dd_get({array}, {i})"
    flat, shape = _entries(exprs)
    dummies = (sp.Dummy(f"cse{i}") for i in itertools.count())
    replacements, reduced = sp.cse(flat, symbols=dummies)
    everything = [r for _, r in replacements] + reduced
    sines = {a.args[0] for e in everything for a in e.atoms(sp.sin)}
    printer = _Printer(symbols, sines & {a.args[0] for e in everything for a in e.atoms(sp.cos)})
    lines = printer.lines
    for s, r in replacements:
        printer.values[s] = printer.signed(r)
    zeros = [e == 0 for e in reduced]
    fill = at is None and not row and sum(zeros) > 2     # one loop, not hundreds of stores (compile time)
    if fill:
        lines.append("    out[...] = 0.0")
    for index, e, zero in zip(np.ndindex(shape), reduced, zeros, strict=False):
        if zero and fill:
            continue
        if at is not None:
            index = (at[index[0]],) + tuple(index[1:])
        if row:
            index = ("i",) + tuple(index)
        where = ", ".join(map(str, index))
        v = printer.value(e)
        lines.append(f"    dd_set(out, {where if len(index) == 1 else f'({where})'}, {v})")
    head = f"def {name}(y, c, out, i):" if row else f"def {name}(y, c, out):"
    return "\n".join([head, *(lines or ["    pass"])]) + "\n"


def dd_function(name: str, args, exprs, **njit_options):
    """``dd_source`` compiled: run in a namespace with ddmath's functions, then ``numba.njit``
    (options passed on; never ``fastmath``, which would undo the dd arithmetic)."""
    from numba import njit
    if njit_options.get("fastmath"):
        raise ValueError("dd_function: fastmath would break double-double arithmetic")
    namespace = {k: getattr(ddmath, k) for k in ddmath.__all__}
    exec(compile(dd_source(name, args, exprs), f"<dd_source {name}>", "exec"), namespace)
    return njit(**njit_options)(namespace[name])
