"""The safe expression grammar: tableau text -> exact sympy expression.

A tableau file is data, so its entries are parsed by a small recursive-descent
parser that builds sympy objects directly; nothing is ever passed to ``eval``,
``sympify`` or ``parse_expr``.  The grammar::

    expr   := term (('+' | '-') term)*
    term   := unary (('*' | '/') unary)*
    unary  := ('+' | '-') unary | power
    power  := atom (('**' | '^') unary)?          right-associative
    atom   := INTEGER | NAME | 'sqrt' '(' expr ')' | '(' expr ')'
            | ('cos' | 'sin') '(' expr ')'            argument a rational multiple of pi
            | 'root' '(' poly ',' INTEGER ')'          the k-th real root (k = 1, 2, … ascending)
            | 'root' '(' poly ',' expr ',' expr ')'   the real root in the interval (a, b)
    poly   := an expr in the name x with rational coefficients

Exponents must be rational constants of modest size, integers are limited in
length, and the result must be a finite real number (or a real expression in
the named parameters).  Floats are refused: a tableau is exact.  Every number
the grammar makes is algebraic: radicals, cos(kπ/n) and sin(kπ/n) (roots of
Chebyshev-type polynomials: SDIRK34's γ = 1/2 + cos(π/18)/√3), and real roots of
polynomials (``root``; sympy's ``CRootOf``, exact, isolated by Sturm sequences),
so that :mod:`field` does exact arithmetic with all of them.

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
>>> parse_entry("0.5")
Traceback (most recent call last):
...
tableau_lab.exact.grammar.EntryError: '0.5' is a decimal number, and tableau entries are exact: write it as a fraction, e.g. "1/2"
>>> parse_entry("__import__('os')")
Traceback (most recent call last):
...
tableau_lab.exact.grammar.EntryError: names must start with a letter, not '_' (at position 1 of "__import__('os')")
"""
from __future__ import annotations

import re
from functools import lru_cache

import sympy as sp

__all__ = ["EntryError", "parse_entry", "parse_number", "format_entry", "format_matrix", "parameter", "LIMITS"]

LIMITS = {
    "text_length": 10000,     # characters in one entry (an 8-stage Gauss entry: a polynomial in two nodes)
    "integer_digits": 100,    # digits in one integer literal
    "exponent_size": 64,      # |numerator| and denominator of an exponent
    "depth": 60,              # nesting of parentheses / unary signs / powers
    "result_digits": 1000,    # digits in any rational produced on the way
    "radicand_digits": 100,   # digits of a rational under a root
    "trig_denominator": 120,  # n in cos(k*pi/n), sin(k*pi/n) (degree up to φ(2n)/2)
    "root_degree": 40,        # degree of the polynomial of root(...)
}

RESERVED = frozenset({"sqrt", "cos", "sin", "root", "pi"})


class EntryError(ValueError):
    """An entry of a tableau that is not a valid exact expression."""


def parameter(name: str) -> sp.Symbol:
    """The sympy symbol for a named free parameter (always real).

    >>> parameter("theta") == parse_entry("theta")
    True
    """
    return sp.Symbol(name, real=True)


_TOKEN = re.compile(
    r"\s*(?:"
    r"(?P<number>\d+(?:\.\d*)?(?:[eE][+-]?\d+)?|\.\d+(?:[eE][+-]?\d+)?)"
    r"|(?P<name>[A-Za-z][A-Za-z0-9_]*)"
    r"|(?P<op>\*\*|[-+*/^(),])"
    r")"
)


def _tokens(text: str):
    pos = 0
    n = len(text)
    out = []
    while pos < n:
        if text[pos].isspace():
            pos += 1
            continue
        m = _TOKEN.match(text, pos)
        if not m or m.end() == pos:
            ch = text[pos]
            if ch == "_":
                raise EntryError(f"names must start with a letter, not '_' (at position {pos + 1} of {text!r})")
            raise EntryError(f"unexpected character {ch!r} at position {pos + 1} of {text!r}")
        kind = m.lastgroup
        value = m.group(kind)
        start = m.start(kind)
        if kind == "number" and not value.isdigit():
            raise EntryError(
                f"{value!r} is a decimal number, and tableau entries are exact: "
                f'write it as a fraction, e.g. "{_fraction_hint(value)}"'
            )
        if kind == "number" and len(value) > LIMITS["integer_digits"]:
            raise EntryError(f"integer with {len(value)} digits is too long (limit {LIMITS['integer_digits']})")
        out.append((kind, value, start))
        pos = m.end()
    return out


def _fraction_hint(text: str) -> str:
    try:
        r = sp.Rational(text) if len(text) < 40 else None
    except (TypeError, ValueError):
        r = None
    if r is None:
        return "1/2"
    return str(r)


class _Parser:
    def __init__(self, text: str):
        self.text = text
        self.toks = _tokens(text)
        self.i = 0
        self.depth = 0
        self.angle = self.poly = False      # inside cos/sin (pi allowed), inside root's polynomial (x allowed)

    # -- helpers -----------------------------------------------------------
    def peek(self):
        return self.toks[self.i] if self.i < len(self.toks) else (None, None, len(self.text))

    def take(self):
        tok = self.peek()
        self.i += 1
        return tok

    def expect(self, value):
        kind, v, pos = self.take()
        if v != value:
            found = "end of text" if kind is None else repr(v)
            raise EntryError(f"expected {value!r} at position {pos + 1} of {self.text!r}, found {found}")

    def nest(self):
        self.depth += 1
        if self.depth > LIMITS["depth"]:
            raise EntryError(f"expression nested too deeply (limit {LIMITS['depth']}): {self.text[:60]!r}")

    # -- grammar -----------------------------------------------------------
    def parse(self):
        if not self.toks:
            raise EntryError("empty entry")
        e = self.expr()
        kind, v, pos = self.peek()
        if kind is not None:
            raise EntryError(f"unexpected {v!r} at position {pos + 1} of {self.text!r}")
        return e

    def expr(self):
        e = self.term()
        while self.peek()[1] in ("+", "-"):
            op = self.take()[1]
            t = self.term()
            e = _checked(e + t if op == "+" else e - t, self.text)
        return e

    def term(self):
        e = self.unary()
        while self.peek()[1] in ("*", "/"):
            op = self.take()[1]
            f = self.unary()
            if op == "/":
                if f == 0:
                    raise EntryError(f"division by zero in {self.text!r}")
                e = _checked(e / f, self.text)
            else:
                e = _checked(e * f, self.text)
        return e

    def unary(self):
        if self.peek()[1] in ("+", "-"):
            op = self.take()[1]
            self.nest()
            u = self.unary()
            self.depth -= 1
            return -u if op == "-" else u
        return self.power()

    def power(self):
        base = self.atom()
        if self.peek()[1] in ("**", "^"):
            self.take()
            self.nest()
            exp = self.unary()
            self.depth -= 1
            return _power(base, exp, self.text)
        return base

    def atom(self):
        kind, v, pos = self.take()
        if kind == "number":
            return sp.Integer(int(v))
        if kind == "name":
            if v == "sqrt":
                self.expect("(")
                self.nest()
                arg = self.expr()
                self.depth -= 1
                self.expect(")")
                return _power(arg, sp.Rational(1, 2), self.text)
            if v in ("cos", "sin"):
                return self.trig(v)
            if v == "root":
                return self.root()
            if v == "pi" and self.angle:
                return sp.pi
            if v == "x" and self.poly:
                return _X
            if self.peek()[1] == "(":
                raise EntryError(f"unknown function {v!r} in {self.text!r} (sqrt, cos, sin and root are allowed)")
            if v == "pi":
                raise EntryError(f"pi is not algebraic: it may appear only in the argument of cos or sin ({self.text!r})")
            return parameter(v)
        if v == "(":
            self.nest()
            e = self.expr()
            self.depth -= 1
            self.expect(")")
            return e
        found = "end of text" if kind is None else repr(v)
        raise EntryError(f"expected a number, a name or '(' at position {pos + 1} of {self.text!r}, found {found}")

    def inner(self, **mode):
        """An argument expression, with ``pi`` (angle) or ``x`` (poly) allowed in it."""
        saved = (self.angle, self.poly)
        self.angle, self.poly = mode.get("angle", False), mode.get("poly", False)
        self.nest()
        try:
            return self.expr()
        finally:
            self.depth -= 1
            self.angle, self.poly = saved

    def trig(self, name):
        """cos(k*pi/n), sin(k*pi/n): algebraic for every rational k/n."""
        self.expect("(")
        arg = self.inner(angle=True)
        self.expect(")")
        q = sp.expand(arg / sp.pi)
        if arg.free_symbols or not q.is_Rational:
            raise EntryError(f"{name}({arg}) in {self.text!r}: the argument must be a rational multiple of pi "
                             "(an algebraic value)")
        if q.q > LIMITS["trig_denominator"]:
            raise EntryError(f"{name}({arg}) in {self.text!r}: denominator {q.q} too large "
                             f"(limit {LIMITS['trig_denominator']})")
        return _checked((sp.cos if name == "cos" else sp.sin)(q * sp.pi), self.text)

    def root(self):
        """root(POLY, k): the k-th real root of POLY in x, ascending (k = 1, 2, …), or
        root(POLY, a, b): its only real root in the open interval (a, b)."""
        self.expect("(")
        poly = self.inner(poly=True)
        if poly.free_symbols - {_X} or not poly.is_polynomial(_X):
            raise EntryError(f"root(...) in {self.text!r}: {poly} is not a polynomial in x with rational coefficients")
        P = sp.Poly(poly, _X, domain=sp.QQ)
        if P.degree() < 1 or P.degree() > LIMITS["root_degree"]:
            raise EntryError(f"root(...) in {self.text!r}: the polynomial must have degree 1 to {LIMITS['root_degree']}")
        self.expect(",")
        args = [self.inner()]
        if self.peek()[1] == ",":
            self.take()
            args.append(self.inner())
        self.expect(")")
        if any(a.free_symbols or not a.is_Rational for a in args):
            raise EntryError(f"root(...) in {self.text!r}: the index and the interval ends must be rational numbers")
        reals = sp.Poly(P.as_expr(), _X).real_roots()       # exact (CRootOf), ascending, with multiplicity
        distinct = list(dict.fromkeys(reals))
        if len(args) == 1:
            k = args[0]
            if not k.is_Integer or not 1 <= k <= len(distinct):
                raise EntryError(f"root(...) in {self.text!r}: index {k} is not in 1 … {len(distinct)} "
                                 f"(the polynomial has {len(distinct)} real root(s))")
            r = distinct[int(k) - 1]
        else:
            a, b = args
            inside = [r for r in distinct if a < r < b]
            if len(inside) != 1:
                raise EntryError(f"root(...) in {self.text!r}: ({a}, {b}) holds {len(inside)} real roots, not one")
            r = inside[0]
        return _checked(r, self.text)


def _power(base, exp, text):
    if exp.free_symbols or not exp.is_Rational:
        raise EntryError(f"exponent {exp} in {text!r} is not a rational constant")
    if base.free_symbols and not exp.is_Integer:
        raise EntryError(f"{text!r} takes a root of an expression in parameters ({base}); "
                         "only integer powers of parameters are exact field arithmetic here")
    lim = LIMITS["exponent_size"]
    if abs(exp.p) > lim or exp.q > lim:
        raise EntryError(f"exponent {exp} in {text!r} is too large (limit: numerator and denominator at most {lim})")
    if base == 0 and exp < 0:
        raise EntryError(f"division by zero (0 to a negative power) in {text!r}")
    if base.is_Rational and exp.q > 1:
        if base < 0:
            raise EntryError(f"({base})**({exp}) in {text!r} is not a real number")
        # r**(p/q) is taken as (r**p)**(1/q): sympy's simplification of a
        # rational power p/q with p != 1 can take minutes on large radicands.
        radicand = base**exp.p
        if max(abs(radicand.p), radicand.q).bit_length() > 3.33 * LIMITS["radicand_digits"]:
            raise EntryError(f"({base})**({exp}) in {text!r}: the number under the root is too large "
                             f"(limit {LIMITS['radicand_digits']} digits)")
        return _checked(sp.Pow(radicand, sp.Rational(1, exp.q)), text)
    return _checked(sp.Pow(base, exp), text)


def _checked(e, text):
    if e.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
        raise EntryError(f"{text!r} is not a finite number")
    for r in e.atoms(sp.Rational):
        if max(abs(r.p), r.q).bit_length() > 3.33 * LIMITS["result_digits"]:
            raise EntryError(f"{text!r} produces numbers too large to handle (over {LIMITS['result_digits']} digits)")
    if e.is_real is False:
        raise EntryError(f"{text!r} is not a real number")
    return e


@lru_cache(maxsize=4096)
def _parse_text(text: str) -> sp.Expr:
    if len(text) > LIMITS["text_length"]:
        raise EntryError(f"entry of {len(text)} characters is too long (limit {LIMITS['text_length']})")
    e = _Parser(text).parse()
    # Canonical form: the fixed point of parse∘print, so that writing an entry and reading
    # it back gives the identical expression (sympy distributes a number over a sum it
    # reads, e.g. 1/(7*(1 + sqrt(2))) is read back as 1/(7 + 7*sqrt(2))).
    for _ in range(3):
        again = _Parser(_print(e)).parse()
        if again == e:
            break
        e = again
    return e


_X = sp.Symbol("x")


class _Printer(sp.printing.str.StrPrinter):
    """sympy's str printer, with a real root written as ``root(POLY, k)`` (k from 1)."""

    def _print_ComplexRootOf(self, r):
        reals = list(dict.fromkeys(sp.Poly(r.poly.as_expr().subs(r.poly.gen, _X), _X).real_roots()))
        k = reals.index(r) + 1
        return f"root({self._print(r.poly.as_expr().subs(r.poly.gen, _X))}, {k})"


def _print(e) -> str:
    return _Printer({"order": None}).doprint(e)


def parse_entry(value) -> sp.Expr:
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


def format_entry(e) -> str | int:
    """Write an exact expression back in the grammar (integers stay integers).

    ``parse_entry(format_entry(e)) == e`` for every expression the grammar
    produces.

    >>> format_entry(parse_entry("(3+sqrt(3))/6"))
    'sqrt(3)/6 + 1/2'
    >>> format_entry(parse_entry("4/2"))
    2
    """
    e = sp.sympify(e)
    if e.is_Integer:
        return int(e)
    return _print(e)


def format_matrix(M) -> list:
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
