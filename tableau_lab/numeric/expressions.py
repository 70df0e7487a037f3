"""Safe expressions for problem definitions: text -> sympy expression, never ``eval``.

Problems written in scene files (a Hamiltonian, a right-hand side, an invariant, an
initial value) are data.  They are read by the one safe parser of
``tableau_lab.exact.grammar`` (the grammar and precedence of tableau entries: -2^2 is -4,
2^3^2 is 512, -x^2 is -(x^2)) in the problem dialect :data:`PROBLEM`: exact decimals
(``0.005`` is 1/200, ``2.95912208286e-4`` is exact too), real powers of expressions, the
functions in ``FUNCTIONS`` of any argument, and only declared names (state variables,
parameters); exponents are rational constants of modest size.

>>> parse_expression("__import__('os')")  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
tableau_lab.numeric.expressions.ExpressionError: names must start with a letter, not '_' (at position 1 of ...)
>>> parse_expression("0.005/2"), parse_expression("-2^2"), parse_expression("2^3^2")
(1/400, -4, 512)
>>> q, p = sp.symbols("q p", real=True)
>>> parse_expression("p^2/2 - cos(q)", {"q": q, "p": p})
p**2/2 - cos(q)
"""
from __future__ import annotations

from fractions import Fraction

import sympy as sp

from ..exact.grammar import NAME, Dialect, EntryError, declared_names, parse, sympy_functions

__all__ = ["ExpressionError", "parse_expression", "exact_number", "FUNCTIONS", "LIMITS", "NAME", "PROBLEM"]

FUNCTIONS = {"sqrt": sp.sqrt, "exp": sp.exp, "log": sp.log, "sin": sp.sin, "cos": sp.cos,
             "tan": sp.tan, "sinh": sp.sinh, "cosh": sp.cosh, "tanh": sp.tanh, "atan": sp.atan}
# the keys of grammar.LIMITS: text length in characters; significant digits of a number
# literal; |numerator| and denominator of a power (|e| in 1e-5 notation: 4 times that);
# nesting of parentheses, signs, powers and calls; digits of any rational produced on the
# way; digits of a rational under a root
LIMITS = dict(text_length=2000, integer_digits=60, exponent_size=64, depth=50, result_digits=500,
              radicand_digits=120, radical_depth=6)

PROBLEM = Dialect(name="problem expressions", functions=sympy_functions(FUNCTIONS), names=declared_names,
                  decimals=True, roots_of_names=True, limits=LIMITS)


class ExpressionError(EntryError):
    """Text that is not a valid, safe expression."""


def parse_expression(text: str, names=None) -> sp.Expr:
    """Parse ``text``; ``names`` maps the allowed names to their sympy symbols."""
    if not isinstance(text, str):
        raise ExpressionError(f"an expression must be a string, not {type(text).__name__}")
    try:
        return parse(text, PROBLEM, names)
    except EntryError as exc:
        raise ExpressionError(str(exc)) from None


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
