"""Safe expressions for problem definitions: text -> sympy expression, never ``eval``.

Problems written in scene files (a Hamiltonian, a right-hand side, an invariant, an
initial value) are data.  This precedence-climbing parser builds sympy objects directly
from a whitelist; ``eval``, ``sympify`` and ``parse_expr`` are never called.  Compared
with the tableau grammar (``tableau_lab.exact.grammar``) it also accepts exact decimals
(``0.005`` is 1/200, ``2.95912208286e-4`` is exact too), real powers of expressions and
the functions in ``FUNCTIONS``::

    expr  := expr ('+' | '-' | '*' | '/') expr | ('+' | '-') expr
           | expr ('^' | '**') expr              (right-associative, binds tightest)
           | NUMBER | NAME | FUNCTION '(' expr ')' | '(' expr ')'

Names must be declared (state variables, parameters); exponents are rational constants of
modest size.

>>> parse_expression("__import__('os')")
Traceback (most recent call last):
...
tableau_lab.numeric.expressions.ExpressionError: names must start with a letter, not '_' (at position 1 of "__import__('os')")
>>> parse_expression("0.005/2"), parse_expression("-2^2"), parse_expression("2^3^2")
(1/400, -4, 512)
>>> q, p = sp.symbols("q p", real=True)
>>> parse_expression("p^2/2 - cos(q)", {"q": q, "p": p})
p**2/2 - cos(q)
"""
from __future__ import annotations

import re
from fractions import Fraction

import sympy as sp

__all__ = ["ExpressionError", "parse_expression", "exact_number", "FUNCTIONS", "LIMITS", "NAME"]

FUNCTIONS = {"sqrt": sp.sqrt, "exp": sp.exp, "log": sp.log, "sin": sp.sin, "cos": sp.cos,
             "tan": sp.tan, "sinh": sp.sinh, "cosh": sp.cosh, "tanh": sp.tanh, "atan": sp.atan}
# text length in characters; significant digits of a number literal; |numerator| and
# denominator of a power (|e| in 1e-5 notation: 4 times that); nesting of parentheses,
# signs, powers and calls; digits of any rational produced on the way
LIMITS = dict(text_length=2000, digits=60, exponent=64, depth=50, result_digits=500)

NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")

_TOKEN = re.compile(r"(?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"
                    r"|(?P<name>[A-Za-z][A-Za-z0-9_]*)|(?P<op>\*\*|[-+*/^()])")
# operator -> (precedence, right-associative)
_BINARY = {"+": (1, False), "-": (1, False), "*": (2, False), "/": (2, False),
           "^": (4, True), "**": (4, True)}
_UNARY_PRECEDENCE = 3   # -x^2 is -(x^2); -x*y is (-x)*y


class ExpressionError(ValueError):
    """Text that is not a valid, safe expression."""


def _number(text: str, where) -> sp.Rational:
    mantissa, _, exponent = text.lower().partition("e")
    if len(mantissa.replace(".", "").lstrip("0")) > LIMITS["digits"]:
        raise ExpressionError(f"number {text[:20]!r}... has too many digits (limit {LIMITS['digits']}) {where}")
    if exponent and abs(int(exponent)) > 4 * LIMITS["exponent"]:
        raise ExpressionError(f"exponent of {text!r} is too large {where}")
    return sp.Rational(Fraction(text))


class _Parser:
    def __init__(self, text: str, names):
        self.text, self.names, self.depth, self.i = text, names, 0, 0
        self.toks = []
        pos = 0
        while pos < len(text):
            if text[pos].isspace():
                pos += 1
                continue
            m = _TOKEN.match(text, pos)
            if not m:
                what = "names must start with a letter, not '_'" if text[pos] == "_" else \
                    f"unexpected character {text[pos]!r}"
                raise ExpressionError(f"{what} {self.where(pos)}")
            self.toks.append((m.lastgroup, m.group(m.lastgroup), pos))
            pos = m.end()
        self.toks.append((None, "end of text", len(text)))

    def where(self, pos):
        text = self.text if len(self.text) <= 80 else self.text[:77] + "..."
        return f"(at position {pos + 1} of {text!r})"

    def take(self):
        tok = self.toks[self.i]
        self.i = min(self.i + 1, len(self.toks) - 1)
        return tok

    def expect(self, value):
        kind, v, pos = self.take()
        if v != value or kind is None:
            raise ExpressionError(f"expected {value!r}, found {v!r} {self.where(pos)}")

    def parse(self):
        if len(self.toks) == 1:
            raise ExpressionError("empty expression")
        e = self.expr(1)
        kind, v, pos = self.take()
        if kind is not None:
            raise ExpressionError(f"unexpected {v!r} {self.where(pos)}")
        return e

    def expr(self, min_prec):
        self.depth += 1
        if self.depth > LIMITS["depth"]:
            raise ExpressionError(f"expression nested too deeply (limit {LIMITS['depth']}) {self.where(self.toks[self.i][2])}")
        lhs = self.operand()
        while self.toks[self.i][1] in _BINARY and self.toks[self.i][0] == "op":
            prec, right = _BINARY[self.toks[self.i][1]]
            if prec < min_prec:
                break
            _, op, pos = self.take()
            rhs = self.expr(prec if right else prec + 1)
            lhs = self.apply(op, lhs, rhs, pos)
        self.depth -= 1
        return lhs

    def operand(self):
        kind, v, pos = self.take()
        if v in ("+", "-") and kind == "op":
            u = self.expr(_UNARY_PRECEDENCE)
            return -u if v == "-" else u
        if kind == "number":
            return self.checked(_number(v, self.where(pos)), pos)
        if v == "(" and kind == "op":
            e = self.expr(1)
            self.expect(")")
            return e
        if kind == "name" and self.toks[self.i][1] == "(":
            if v not in FUNCTIONS:
                raise ExpressionError(f"unknown function {v!r} {self.where(pos)}; allowed: {', '.join(FUNCTIONS)}")
            self.take()
            arg = self.expr(1)
            self.expect(")")
            return self.checked(FUNCTIONS[v](arg), pos)
        if kind == "name":
            if v not in self.names:
                known = ", ".join(self.names) or "none"
                raise ExpressionError(f"unknown name {v!r} {self.where(pos)}; known names: {known}")
            return self.names[v]
        raise ExpressionError(f"expected a number, a name or '(', found {v!r} {self.where(pos)}")

    def apply(self, op, a, b, pos):
        if op in ("+", "-"):
            return self.checked(a + b if op == "+" else a - b, pos)
        if op == "*":
            return self.checked(a * b, pos)
        if op == "/":
            if b == 0:
                raise ExpressionError(f"division by zero {self.where(pos)}")
            return self.checked(a / b, pos)
        lim = LIMITS["exponent"]
        if not (b.is_Rational and abs(b.p) <= lim and b.q <= lim):
            raise ExpressionError(f"exponent {str(b)[:30]} must be a rational constant with numerator and "
                                  f"denominator at most {lim} {self.where(pos)}")
        if a == 0 and b < 0:
            raise ExpressionError(f"division by zero (0 to a negative power) {self.where(pos)}")
        if a.is_Rational and b.q > 1 and max(abs(a.p), a.q).bit_length() > 400:
            raise ExpressionError(f"root of a number that is too large {self.where(pos)}")
        return self.checked(a ** b, pos)

    def checked(self, e, pos):
        """e, unless it is infinite, not real, or holds numbers that are too large."""
        bits = 3.33 * LIMITS["result_digits"]
        fault = ("not finite" if e.has(sp.zoo, sp.nan, sp.oo, -sp.oo)
                 else f"made of numbers over {LIMITS['result_digits']} digits"
                 if any(max(abs(r.p), r.q).bit_length() > bits for r in e.atoms(sp.Rational))
                 else "not real" if e.is_real is False else None)
        if fault:
            raise ExpressionError(f"the expression is {fault} {self.where(pos)}")
        return e


def parse_expression(text: str, names=None) -> sp.Expr:
    """Parse ``text``; ``names`` maps the allowed names to their sympy symbols."""
    if not isinstance(text, str):
        raise ExpressionError(f"an expression must be a string, not {type(text).__name__}")
    if len(text) > LIMITS["text_length"]:
        raise ExpressionError(f"expression of {len(text)} characters is too long (limit {LIMITS['text_length']})")
    return _Parser(text, dict(names or {})).parse()


def exact_number(value, names=None) -> sp.Expr:
    """An exact real number from an int, a Fraction, a finite sympy number, a string
    (a constant expression, or one in ``names``) or a float (read as its shortest decimal
    representation: 0.9 is 9/10).

    >>> exact_number(0.9), exact_number("3/5"), exact_number(2), exact_number("sqrt(2)")
    (9/10, 3/5, 2, sqrt(2))
    """
    if isinstance(value, bool) or value is None:
        raise ExpressionError(f"{value!r} is not a number")
    if isinstance(value, float):
        if value != value or value in (float("inf"), float("-inf")):
            raise ExpressionError(f"{value!r} is not a finite number")
        return sp.Rational(Fraction(repr(value)))
    if isinstance(value, (int, Fraction)):
        if abs(Fraction(value).numerator).bit_length() > 3.33 * LIMITS["result_digits"]:
            raise ExpressionError("integer is too long")
        return sp.Rational(value)
    if isinstance(value, str):
        return parse_expression(value, names)
    if isinstance(value, sp.Expr) and value.is_real and value.is_finite:
        return value
    raise ExpressionError(f"{value!r} is not a finite real number")
