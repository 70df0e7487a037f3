"""The safe expression grammar: text -> exact sympy expression, one parser for two dialects.

Tableau entries and the problem expressions of scene files are data, so they are read by
one small tokenizer and one recursive-descent parser that build sympy objects directly;
nothing is ever passed to ``eval``, ``sympify`` or ``parse_expr``.  The grammar::

    expr   := term (('+' | '-') term)*
    term   := unary (('*' | '/') unary)*
    unary  := ('+' | '-') unary | power
    power  := atom (('**' | '^') unary)?          right-associative, binds tighter than unary minus
    atom   := NUMBER | NAME | FUNCTION '(' expr (',' expr)* ')' | '(' expr ')'

so -2**2 is -4, 2**3**2 is 512 and -x^2 is -(x^2).  A :class:`Dialect` says what else an
expression of its kind may hold: its functions (how many arguments, which names each argument
binds, how the value is built), whether decimals are exact rationals or refused, what a name
means, whether a non-integer power of an expression in names is allowed, and the limits.

The tableau dialect (:data:`TABLEAU`, :func:`parse_entry`) reads exact real algebraic numbers::

    FUNCTION := 'sqrt'                            sqrt(a) is a**(1/2)
              | 'cos' | 'sin'                     argument a rational multiple of pi
              | 'root'                            root(POLY, k): the k-th real root (k = 1, 2, … ascending)
                                                  root(POLY, a, b): the real root in the interval (a, b)
    POLY     := an expr in the name x with rational coefficients

Exponents must be rational constants of modest size, integers are limited in length, and the
result must be a finite real number (or a real expression in the named parameters, which are
real symbols).  Decimals are refused: a tableau is exact.  Every number the dialect makes is
algebraic: radicals, cos(kπ/n) and sin(kπ/n) (roots of Chebyshev-type polynomials: SDIRK34's
γ = 1/2 + cos(π/18)/√3), and real roots of polynomials (``root``; sympy's ``CRootOf``, exact,
isolated by Sturm sequences), so that :mod:`field` does exact arithmetic with all of them.
The problem dialect (``tableau_lab.numeric.expressions``) reads decimals exactly
(0.005 is 1/200), allows sqrt, exp, log, sin, cos, … of any argument and real powers of
expressions, and only the names declared for the problem.

>>> parse_entry("1/2 + cos(pi/18)/sqrt(3)") == sp.Rational(1, 2) + sp.sqrt(3) * sp.cos(sp.pi / 18) / 3
True
>>> format_entry(parse_entry("root(x**3 - 3*x + 1, 2)"))
'root(x**3 - 3*x + 1, 2)'
>>> parse_entry("root(x**3 - 3*x + 1, 0, 1)") == parse_entry("root(x^3-3*x+1, 2)")
True

>>> parse_entry("(3+sqrt(3))/6")
sqrt(3)/6 + 1/2
>>> parse_entry("-43*sqrt(14595)/35490")
-43*sqrt(14595)/35490
>>> parse_entry("1/(2-2^(1/3))")
1/(2 - 2**(1/3))
>>> parse_entry("theta**2 - 1")
theta**2 - 1
>>> parse_entry("0.5")  # doctest: +NORMALIZE_WHITESPACE
Traceback (most recent call last):
...
tableau_lab.exact.grammar.EntryError: '0.5' is a decimal number, and tableau entries are exact: write it as a
fraction, e.g. "1/2" (at position 1 of '0.5')
>>> parse_entry("__import__('os')")
Traceback (most recent call last):
...
tableau_lab.exact.grammar.EntryError: names must start with a letter, not '_' (at position 1 of "__import__('os')")
"""
from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from types import MappingProxyType
from typing import Any, NamedTuple

import sympy as sp

from ..errors import InputError

__all__ = ["EntryError", "NUMBER_NAMES", "over", "raise_limit", "LIMIT_OPTION", "parse_entry", "parse_number",
           "format_entry", "format_matrix", "parameter", "LIMITS", "RESERVED", "NAME", "Dialect", "Function",
           "TABLEAU", "parse", "sympy_functions", "declared_names"]

LIMITS = {                    # the tableau dialect's (a dialect's limits have these keys; the last two: tableau only)
    "text_length": 10000,     # characters in one entry (an 8-stage Gauss entry: a polynomial in two nodes)
    "integer_digits": 100,    # significant digits in one number literal
    "exponent_size": 64,      # |numerator| and denominator of an exponent (|e| in 1e-5 notation: 4 times that)
    "depth": 60,              # nesting of parentheses / unary signs / powers / function arguments
    "radical_depth": 4,       # roots of roots (Lobatto, Gauss 4 nodes: 2; each level can double the field degree)
    "result_digits": 1000,    # digits in any rational produced on the way
    "radicand_digits": 100,   # digits of a rational under a root
    "trig_denominator": 120,  # n in cos(k*pi/n), sin(k*pi/n) (degree up to φ(2n)/2)
    "root_degree": 40,        # degree of the polynomial of root(...)
}
_DEFAULT_LIMITS = dict(LIMITS)

LIMIT_OPTION = "--entry-limit"   # the command-line option that raises a limit of the tableau dialect


def over(dialect: Dialect, key: str) -> str:
    """The limit a text went over, and how to raise it (tableau entries: ``--entry-limit KEY=N``).

    >>> over(TABLEAU, "depth")
    '(limit depth = 60; raise it with --entry-limit depth=N)'
    """
    raise_it = f"; raise it with {LIMIT_OPTION} {key}=N" if dialect.limits is LIMITS else ""
    return f"(limit {key} = {dialect.limits[key]}{raise_it})"


def raise_limit(key: str, value: int) -> None:
    """Set a limit of the tableau dialect (``--entry-limit KEY=N``): at most 100 times its default."""
    if key not in LIMITS:
        raise EntryError(f"{LIMIT_OPTION} {key}: no such limit (limits: {', '.join(LIMITS)})")
    if not 1 <= value <= 100 * _DEFAULT_LIMITS[key]:
        raise EntryError(f"{LIMIT_OPTION} {key}={value}: give 1 … {100 * _DEFAULT_LIMITS[key]}")
    LIMITS[key] = value
    _parse_text.cache_clear()


_NAME = r"[A-Za-z][A-Za-z0-9_]*"
NAME = re.compile(_NAME + r"\Z")      # a name: a letter, then letters, digits and _


class EntryError(InputError):
    """Text that is not a valid expression of its dialect (a tableau entry, a problem expression)."""


def parameter(name: str) -> sp.Symbol:
    """The sympy symbol for a named free parameter (always real).

    >>> parameter("theta") == parse_entry("theta")
    True
    """
    return sp.Symbol(name, real=True)


# ---------------------------------------------------------------------------- dialects

#: a dialect function's value from the parser, its name, its parsed arguments and its position
Build = Callable[["_Parser", str, list[sp.Expr], int], sp.Expr]

@dataclass(frozen=True)
class Function:
    """A function of a dialect: ``build(parser, name, args, pos)`` makes its value from the
    parsed arguments (the parser checks it is finite, real and of modest size); ``arity``
    the numbers of arguments it takes; ``scopes`` per argument (the last one repeats) the
    names bound in it, e.g. ``{"pi": sp.pi}``, or None to keep the caller's."""
    build: Build
    arity: tuple[int, ...] = (1,)
    scopes: tuple[Mapping[str, sp.Expr] | None, ...] = (None,)


@dataclass(frozen=True, eq=False)
class Dialect:
    """What the one parser reads.

    ``name``: what the texts are, in messages ("tableau entries");
    ``functions``: name -> :class:`Function`, the only functions (their names are reserved);
    ``names``: ``(parser, name, pos)`` -> the value of a name that no argument scope binds,
    or raises (``pi`` is a name like any other: bound only where a function's scope binds it);
    ``decimals``: True reads 0.005 as exactly 1/200, False refuses it with a hint;
    ``roots_of_names``: True allows (q^2 + p^2)^(1/2), False only integer powers of names;
    ``limits``: the keys of :data:`LIMITS` (the last two only where cos, sin, root are used)."""
    name: str
    functions: Mapping[str, Function]
    names: Callable[[_Parser, str, int], sp.Expr]
    decimals: bool
    roots_of_names: bool
    limits: Mapping[str, int]


def _sqrt(p: _Parser, name: str, args: list[sp.Expr], pos: int) -> sp.Expr:
    return p.power(args[0], sp.S.Half, pos)


def sympy_functions(table: Mapping[str, Callable[[sp.Expr], sp.Expr]]) -> Mapping[str, Function]:
    """Dialect functions of one argument, any argument, from sympy functions: ``sp.sqrt`` is
    the power 1/2 (with its rules and limits), the others are applied as they are."""
    return MappingProxyType({n: Function(_sqrt) if f is sp.sqrt
                             else Function(_applying(f)) for n, f in table.items()})


def _applying(f: Callable[[sp.Expr], sp.Expr]) -> Build:
    """The dialect function that applies ``f`` to its one argument."""
    def build(p: _Parser, name: str, args: list[sp.Expr], pos: int) -> sp.Expr:
        return f(args[0])
    return build


def declared_names(p: _Parser, name: str, pos: int) -> sp.Expr:
    """Names resolved from the mapping given to :func:`parse` (all other names are refused)."""
    if name not in p.names:
        raise p.error(f"unknown name {name!r}", pos, f"; known names: {', '.join(p.names) or 'none'}")
    return p.names[name]


# ---------------------------------------------------------------------------- the tokenizer

_TOKEN = re.compile(r"(?P<number>(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?)"    # ASCII digits only
                    rf"|(?P<name>{_NAME})|(?P<op>\*\*|[-+*/^(),])")


class _Token(NamedTuple):
    kind: str | None            # "number", "name", "op"; None: the end of the text
    text: str | None
    pos: int
    value: sp.Rational | None = None      # a number's exact value


def _where(text: str, pos: int) -> str:
    shown = text if len(text) <= 80 else text[:77] + "..."
    return f"(at position {pos + 1} of {shown!r})"


def _tokens(text: str, dialect: Dialect) -> list[_Token]:
    """The tokens of ``text`` and an end token; number literals read (or refused) by ``dialect``."""
    out: list[_Token] = []
    pos = 0
    while pos < len(text):
        if text[pos] in " \t\r\n":                 # ASCII white space only (no NBSP, no zero-width)
            pos += 1
            continue
        m = _TOKEN.match(text, pos)
        if not m:
            what = "names must start with a letter, not '_'" if text[pos] == "_" else \
                f"unexpected character {text[pos]!r}"
            raise EntryError(f"{what} {_where(text, pos)}")
        kind = m.lastgroup
        value = m.group(kind or 0)
        out.append(_Token(kind, value, pos, _number(value, dialect, text, pos) if kind == "number" else None))
        pos = m.end()
    out.append(_Token(None, None, len(text)))
    return out


def _number(literal: str, dialect: Dialect, text: str, pos: int) -> sp.Rational:
    """The exact value of a number literal (decimals as the rationals they denote), within limits."""
    if not dialect.decimals and not literal.isdigit():
        raise EntryError(f"{literal!r} is a decimal number, and {dialect.name} are exact: "
                         f'write it as a fraction, e.g. "{_fraction_hint(literal)}" {_where(text, pos)}')
    mantissa, _, exponent = literal.lower().partition("e")
    digits, lim = len(mantissa.replace(".", "").lstrip("0")), dialect.limits["integer_digits"]
    if digits > lim:
        raise EntryError(f"number with {digits} digits is too long {over(dialect, 'integer_digits')} "
                         f"{_where(text, pos)}")
    if exponent and (len(exponent) > 8 or abs(int(exponent)) > 4 * dialect.limits["exponent_size"]):
        raise EntryError(f"exponent of {literal[:40]!r} is too large {over(dialect, 'exponent_size')} "
                         f"{_where(text, pos)}")
    return sp.Integer(int(literal)) if literal.isdigit() else sp.Rational(Fraction(literal))


def _fraction_hint(text: str) -> str:
    """The literal as a fraction, when that is short (1e999999 is not: then an example)."""
    mantissa, _, exponent = text.lower().partition("e")
    if len(text) >= 40 or (exponent and abs(int(exponent)) > 40):
        return "1/2"
    return str(sp.Rational(text))


def _short(e: object) -> str:
    s = str(e)
    return s if len(s) <= 60 else s[:57] + "..."


# ---------------------------------------------------------------------------- the parser

class _Parser:
    def __init__(self, text: str, dialect: Dialect, names: Mapping[str, sp.Expr] | None = None) -> None:
        self.text, self.dialect, self.names = text, dialect, dict(names or {})
        self.limits = dialect.limits
        self.toks = _tokens(text, dialect)
        self.i = self.depth = 0
        # names bound here by the argument of a function (pi in cos, x in root)
        self.scope: Mapping[str, sp.Expr] = {}

    # -- helpers -----------------------------------------------------------
    def error(self, msg: str, pos: int, tail: str = "") -> EntryError:
        return EntryError(f"{msg} {_where(self.text, pos)}{tail}")

    def peek(self) -> _Token:
        return self.toks[self.i]

    def take(self) -> _Token:
        tok = self.toks[self.i]
        self.i = min(self.i + 1, len(self.toks) - 1)
        return tok

    def expect(self, value: str) -> None:
        tok = self.take()
        if tok.text != value:
            raise self.error(f"expected {value!r}, found {_found(tok)}", tok.pos)

    def nested(self, parse: Callable[[], sp.Expr], scope: Mapping[str, sp.Expr] | None = None) -> sp.Expr:
        """``parse()`` one level deeper (the depth is limited), with ``scope`` bound (None: as it is)."""
        self.depth += 1
        if self.depth > self.limits["depth"]:
            raise self.error(f"expression nested too deeply {over(self.dialect, 'depth')}", self.peek().pos)
        saved = self.scope
        if scope is not None:
            self.scope = scope
        try:
            return parse()
        finally:
            self.depth -= 1
            self.scope = saved

    # -- grammar -----------------------------------------------------------
    def parse(self) -> sp.Expr:
        if len(self.toks) == 1:
            raise EntryError("empty expression")
        e = self.expr()
        tok = self.peek()
        if tok.kind is not None:
            raise self.error(f"unexpected {tok.text!r}", tok.pos)
        return e

    def expr(self) -> sp.Expr:
        e = self.term()
        while self.peek().text in ("+", "-"):
            op = self.take()
            t = self.term()
            e = self.checked(e + t if op.text == "+" else e - t, op.pos)
        return e

    def term(self) -> sp.Expr:
        e = self.unary()
        while self.peek().text in ("*", "/"):
            op = self.take()
            f = self.unary()
            if op.text == "/":
                if f == 0:
                    raise self.error("division by zero", op.pos)
                e = self.checked(e / f, op.pos)
            else:
                e = self.checked(e * f, op.pos)
        return e

    def unary(self) -> sp.Expr:
        if self.peek().text in ("+", "-"):
            op = self.take()
            u = self.nested(self.unary)
            return -u if op.text == "-" else u
        return self.power_expr()

    def power_expr(self) -> sp.Expr:
        base = self.atom()
        if self.peek().text in ("**", "^"):
            op = self.take()
            return self.power(base, self.nested(self.unary), op.pos)
        return base

    def atom(self) -> sp.Expr:
        tok = self.take()
        if tok.kind == "number":
            return tok.value
        if tok.kind == "name" and tok.text is not None:
            name = tok.text
            if name in self.dialect.functions:
                return self.call(name, tok.pos)
            if name in self.scope:
                return self.scope[name]
            if self.peek().text == "(":
                raise self.error(f"unknown function {name!r}", tok.pos,
                                 f"; allowed: {', '.join(self.dialect.functions)}")
            return self.dialect.names(self, name, tok.pos)
        if tok.text == "(":
            e = self.nested(self.expr)
            self.expect(")")
            return e
        raise self.error(f"expected a number, a name or '(', found {_found(tok)}", tok.pos)

    def call(self, name: str, pos: int) -> sp.Expr:
        fn = self.dialect.functions[name]
        self.expect("(")
        args = [self.nested(self.expr, fn.scopes[0])]
        while self.peek().text == ",":
            self.take()
            args.append(self.nested(self.expr, fn.scopes[min(len(args), len(fn.scopes) - 1)]))
        self.expect(")")
        if len(args) not in fn.arity:
            raise self.error(f"{name} takes {' or '.join(map(str, fn.arity))} argument(s), not {len(args)}", pos)
        return self.checked(fn.build(self, name, args, pos), pos)

    # -- values ------------------------------------------------------------
    def power(self, base: sp.Expr, exp: sp.Expr, pos: int) -> sp.Expr:
        """base**exp for a rational constant exp of modest size, exactly."""
        if exp.free_symbols or not exp.is_Rational:
            raise self.error(f"exponent {_short(exp)} is not a rational constant", pos)
        if base.free_symbols and not exp.is_Integer and not self.dialect.roots_of_names:
            raise self.error(f"({_short(base)})**({exp}) takes a root of an expression in parameters; "
                             "only integer powers of parameters are exact field arithmetic here", pos)
        lim = self.limits["exponent_size"]
        if not exp.is_Integer and _radical_depth(base) >= self.limits["radical_depth"]:
            raise self.error(f"roots nested more than {self.limits['radical_depth']} deep "
                             f"{over(self.dialect, 'radical_depth')}; or write the number as root(POLY, k)", pos)
        if abs(exp.p) > lim or exp.q > lim:
            raise self.error(f"exponent {exp} is too large (limit: numerator and denominator at most {lim})", pos)
        if base == 0 and exp < 0:
            raise self.error("division by zero (0 to a negative power)", pos)
        if base.is_Rational and exp.q > 1:
            if base < 0:
                raise self.error(f"({base})**({exp}) is not a real number", pos)
            # r**(p/q) is taken as (r**p)**(1/q): sympy's simplification of a
            # rational power p/q with p != 1 can take minutes on large radicands.
            radicand, digits = base**exp.p, self.limits["radicand_digits"]
            if max(abs(radicand.p), radicand.q).bit_length() > 3.33 * digits:
                raise self.error(f"({_short(base)})**({exp}): the number under the root is too large "
                                 f"{over(self.dialect, 'radicand_digits')}", pos)
            return self.checked(sp.Pow(radicand, sp.Rational(1, exp.q)), pos)
        return self.checked(sp.Pow(base, exp), pos)

    def checked(self, e: sp.Expr, pos: int) -> sp.Expr:
        """e, unless it is infinite, not real, or holds numbers that are too large."""
        if e.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
            raise self.error("the value is not a finite number", pos)
        digits = self.limits["result_digits"]
        if any(max(abs(r.p), r.q).bit_length() > 3.33 * digits for r in e.atoms(sp.Rational)):
            raise self.error(f"the value holds numbers too large to handle {over(self.dialect, 'result_digits')}", pos)
        if e.is_real is False:
            raise self.error("the value is not a real number", pos)
        return e


def _radical_depth(e: sp.Expr) -> int:
    """How deeply roots are nested in e: sqrt(2) 1, sqrt(2 + sqrt(2)) 2."""
    if not e.args:
        return 0
    inner = max(_radical_depth(a) for a in e.args)
    return inner + 1 if e.is_Pow and not e.exp.is_Integer else inner


def _found(tok: _Token) -> str:
    return "end of text" if tok.kind is None else repr(tok.text)


def parse(text: str, dialect: Dialect, names: Mapping[str, sp.Expr] | None = None) -> sp.Expr:
    """Parse ``text`` in ``dialect``; ``names`` (name -> value) for :func:`declared_names`.

    >>> parse("-2**2 + 2^3^2", TABLEAU), parse("-q^2", TABLEAU)
    (508, -q**2)
    """
    lim = dialect.limits["text_length"]
    if len(text) > lim:
        raise EntryError(f"expression of {len(text)} characters is too long {over(dialect, 'text_length')}")
    return _Parser(text, dialect, names).parse()


# ---------------------------------------------------------------------------- the tableau dialect

_X = sp.Symbol("x")


def _trig(p: _Parser, name: str, args: list[sp.Expr], pos: int) -> sp.Expr:
    """cos(k*pi/n), sin(k*pi/n): algebraic for every rational k/n."""
    arg = args[0]
    q = sp.expand(arg / sp.pi)
    if arg.free_symbols or not q.is_Rational:
        raise p.error(f"{name}({_short(arg)}): the argument must be a rational multiple of pi "
                      "(an algebraic value)", pos)
    if q.q > p.limits["trig_denominator"]:
        raise p.error(f"{name}({arg}): denominator {q.q} too large {over(p.dialect, 'trig_denominator')}", pos)
    return (sp.cos if name == "cos" else sp.sin)(q * sp.pi)


def _root(p: _Parser, name: str, args: list[sp.Expr], pos: int) -> sp.Expr:
    """root(POLY, k): the k-th real root of POLY in x, ascending (k = 1, 2, …), or
    root(POLY, a, b): its only real root in the open interval (a, b)."""
    poly, *ends = args
    if poly.free_symbols - {_X} or not poly.is_polynomial(_X):
        raise p.error(f"root(...): {_short(poly)} is not a polynomial in x with rational coefficients", pos)
    P = sp.Poly(poly, _X, domain=sp.QQ)
    if P.degree() < 1 or P.degree() > p.limits["root_degree"]:
        raise p.error(f"root(...): the polynomial must have degree 1 to {p.limits['root_degree']} "
                      f"{over(p.dialect, 'root_degree')}", pos)
    if any(a.free_symbols or not a.is_Rational for a in ends):
        raise p.error("root(...): the index and the interval ends must be rational numbers", pos)
    reals = sp.Poly(P.as_expr(), _X).real_roots()       # exact (CRootOf), ascending, with multiplicity
    distinct = list(dict.fromkeys(reals))
    if len(ends) == 1:
        k = ends[0]
        if not k.is_Integer or not 1 <= k <= len(distinct):
            raise p.error(f"root(...): index {k} is not in 1 … {len(distinct)} "
                          f"(the polynomial has {len(distinct)} real root(s))", pos)
        return distinct[int(k) - 1]
    a, b = ends
    inside = [r for r in distinct if a < r < b]
    if len(inside) != 1:
        raise p.error(f"root(...): ({a}, {b}) holds {len(inside)} real roots, not one", pos)
    return inside[0]


def _parameter_name(p: _Parser, name: str, pos: int) -> sp.Expr:
    """Every name is a real parameter; pi only in the argument of cos, sin (their scope binds it);
    not a name that reads as a number or a constant (:data:`NOT_PARAMETERS`)."""
    if name == "pi":
        raise p.error("pi is not algebraic: it may appear only in the argument of cos or sin", pos)
    if name.lower() in NOT_PARAMETERS:
        raise p.error(f"{name!r} is not a number of a tableau (entries are exact; and it cannot name a "
                      f"parameter)", pos)
    return parameter(name)


# names that read as numbers in every dialect (case-insensitive): never a parameter's name
NUMBER_NAMES = frozenset({"nan", "inf", "infinity", "oo", "zoo", "none", "true", "false"})
# a tableau's parameters are not e, i, j either (constants); a problem may name its eccentricity e
NOT_PARAMETERS = NUMBER_NAMES | {"e", "i", "j"}


_ANGLE = MappingProxyType({"pi": sp.pi})
TABLEAU = Dialect(
    name="tableau entries",
    functions=MappingProxyType({
        "sqrt": Function(_sqrt),
        "cos": Function(_trig, scopes=(_ANGLE,)),
        "sin": Function(_trig, scopes=(_ANGLE,)),
        "root": Function(_root, arity=(2, 3), scopes=(MappingProxyType({"x": _X}), MappingProxyType({}))),
    }),
    names=_parameter_name, decimals=False, roots_of_names=False, limits=LIMITS)

RESERVED = frozenset(TABLEAU.functions) | {"pi"}     # not parameter names


@lru_cache(maxsize=4096)
def _parse_text(text: str) -> sp.Expr:
    e = parse(text, TABLEAU)
    # Canonical form: the fixed point of parse∘print, so that writing an entry and reading
    # it back gives the identical expression (sympy distributes a number over a sum it
    # reads, e.g. 1/(7*(1 + sqrt(2))) is read back as 1/(7 + 7*sqrt(2))).
    for _ in range(3):
        again = _Parser(_print(e), TABLEAU).parse()
        if again == e:
            break
        e = again
    return e


class _Printer(sp.printing.str.StrPrinter):  # type: ignore[misc]  # sympy ships no types: StrPrinter is Any
    """sympy's str printer, with a real root written as ``root(POLY, k)`` (k from 1)."""

    def _print_ComplexRootOf(self, r: sp.Expr) -> str:
        P = sp.Poly(r.poly.as_expr().subs(r.poly.gen, _X), _X, domain=sp.QQ)
        return f"root({self._print(P.as_expr())}, {real_root_index(r, P)})"


def real_root_index(r: sp.Expr, P: sp.Poly | None = None) -> int:
    """k such that the real root ``r`` (a sympy ``CRootOf``) is ``root(P, k)``: its place among the
    distinct real roots of P (default: its own polynomial), ascending, from 1.  Decided on P's
    isolating intervals (rational ends, one distinct root each), not by comparing sympy objects:
    sympy writes one root in several forms (CRootOf(x⁵ + 6x⁴ + 162x³ + …, 0) is also
    3·CRootOf(x⁵ + 2x⁴ + 18x³ + …, 0), a root of a non-squarefree P is counted once here).
    A root that is not real has no ``root(…)`` form: ValueError.

    >>> x = sp.Symbol("x")
    >>> r = sp.CRootOf._new(sp.PurePoly(x**5 + 6*x**4 + 162*x**3 + 648*x**2 + 1944*x + 3888), 0)
    >>> q = sp.CRootOf(x**5 + 2*x**4 + 18*x**3 + 24*x**2 + 24*x + 16, 0)
    >>> real_root_index(r), parse_entry(format_entry(r)) == 3*q
    (1, True)
    """
    P = P if P is not None else sp.Poly(r.poly.as_expr().subs(r.poly.gen, _X), _X, domain=sp.QQ)
    if not r.is_real:
        raise ValueError(f"{r} is not a real number: the grammar's root(POLY, k) writes real roots only")
    for k, ((a, b), _) in enumerate(P.intervals(), 1):
        if a == b:
            if r == a:                          # a rational root (sympy would have made r that number)
                return k
        elif bool(sp.Rational(a) < r) and bool(r < sp.Rational(b)):
            return k
    raise ValueError(f"{r} is not a real root of {P.as_expr()}")


def _print(e: sp.Expr) -> str:
    return str(_Printer({"order": None}).doprint(e))


def parse_entry(value: object) -> sp.Expr:
    """Parse one tableau entry (a string in the grammar, or a Python int).

    Booleans, floats and every other type are refused.

    >>> parse_entry(3), parse_entry("-2/4"), parse_entry("2**(1/3)")
    (3, -1/2, 2**(1/3))
    """
    if isinstance(value, bool):
        raise EntryError(f"{value!r} is a boolean, not a number")
    if isinstance(value, int):
        if abs(value).bit_length() > 3.33 * LIMITS["integer_digits"]:
            raise EntryError(f"integer is too long (limit {LIMITS['integer_digits']} digits)")
        return sp.Integer(value)
    if isinstance(value, float):
        raise EntryError(
            f"{value!r} is a floating-point number, and tableau entries are exact: "
            f'write it as a string such as "{_fraction_hint(repr(value))}" or "sqrt(2)/2"'
        )
    if isinstance(value, str):
        return _parse_text(value.strip())
    raise EntryError(f"an entry must be a string or an integer, not {type(value).__name__}")


def format_entry(e: object) -> str | int:
    """Write an exact expression back in the grammar (integers stay integers).

    ``parse_entry(format_entry(e)) == e`` for every expression the grammar
    produces.

    >>> format_entry(parse_entry("(3+sqrt(3))/6"))
    'sqrt(3)/6 + 1/2'
    >>> format_entry(parse_entry("4/2"))
    2
    """
    x = sp.sympify(e)
    if x.is_Integer:
        return int(x)
    return _print(x)


def format_matrix(M: Any) -> list[str] | list[list[str]]:
    """A matrix (or column vector, as a flat list) as exact strings in the grammar.

    >>> format_matrix(sp.Matrix([[1, sp.sqrt(3)/6]]))
    [['1', 'sqrt(3)/6']]
    >>> format_matrix(sp.Matrix([1, 2]))
    ['1', '2']
    """
    M = sp.Matrix(M)
    if M.cols == 1:
        return [str(format_entry(x)) for x in M]
    return [[str(format_entry(x)) for x in M.row(i)] for i in range(M.rows)]


def parse_number(text: str) -> sp.Expr:
    """A number typed by a user (command line, scene file), exactly: a decimal such as 0.6 or
    1e-3 is read as the rational it denotes (3/5, 1/1000); anything else as a tableau entry
    without names (2/3, sqrt(2)/2).

    >>> parse_number("0.6"), parse_number("1/100"), parse_number("2.5e-2")
    (3/5, 1/100, 1/40)
    """
    import re
    text = str(text).strip()
    if re.fullmatch(r"[+-]?(\d{1,30}\.\d{0,30}|\.\d{1,30}|\d{1,30})([eE][+-]?\d{1,3})?", text):
        return sp.Rational(text)
    v = parse_entry(text)
    if v.free_symbols:
        raise EntryError(f"{text!r} is not a number")
    return v
