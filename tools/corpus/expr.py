"""Arithmetic expressions of Julia, C and Python source text, read without ever making a float.

One tokenizer and one recursive-descent parser for the expressions the libraries' tableau files
write: numbers, ``+ - * / // ^ **``, calls (``sqrt``, ``SUN_RCONST``, ``big"…"``,
``parse(BigFloat, "…")``, ``convert(T, x)`` …), names bound by earlier assignments, indexing
and Julia's array literals (``[a b; c d]``, ``[a, b]``, ``[[a b] [c d]]``).  Nothing is evaluated
by Python: every value is a :class:`Val`, either exact (a sympy number: integers, rationals,
radicals) or decimal (the literal's text as written, and a flint ``arb`` ball for arithmetic).

Reading rules (the README states them too):

* integer arithmetic is exact: Julia's ``1/3`` and C's ``SUN_RCONST(1.0)/SUN_RCONST(3.0)`` are 1/3
  (the source means the rational; the float is the language's rounding of it);
* a decimal literal with an integer value (``2.0``) or at most ``SHORT`` significant digits
  (``0.161``, ``0.5``) is read as the exact decimal it writes;
* a longer decimal literal is a decimal entry, kept as its text (sign included); arithmetic
  involving one gives a *derived* decimal (a ball: the literal's ball ± half a unit in its last
  digit, propagated by arb at ``PREC`` bits).

>>> parse_value("1 // 3 + 1/6").exact
1/2
>>> parse_value("-.8480655492356988544e-2").text
'-.8480655492356988544e-2'
>>> parse_value("SUN_RCONST(2.0)/SUN_RCONST(3.0)").exact
2/3
>>> parse_value("(3 - 2 * sqrt(3)) / 12").exact
1/4 - sqrt(3)/6
>>> parse_value("0.161").exact
161/1000
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from decimal import Decimal

import sympy as sp
from flint import arb, ctx

PREC = 400          # bits of arb arithmetic for derived decimals
SHORT = 4           # a decimal literal of at most this many significant digits is read as exact
ctx.prec = PREC


class Unsupported(Exception):
    """Source text this reader does not understand (the tableau is skipped and counted)."""


def literal_value(text: str) -> sp.Rational:
    """The exact value of a decimal or integer literal as written (``"-.5e-2"`` → -1/200)."""
    return sp.Rational(str(Decimal(text.replace("_", ""))))


def significant_digits(text: str) -> int:
    mant = re.split(r"[eEdD]", text.lstrip("+-"))[0].replace(".", "").replace("_", "").lstrip("0")
    return len(mant.rstrip("0")) if mant else 0


def half_ulp(text: str) -> sp.Rational:
    """Half a unit in the last written digit of a decimal literal (``"-1.2e-3"`` → 1/20000)."""
    mant, _, exp = text.lstrip("+-").replace("_", "").lower().partition("e")
    places = len(mant.partition(".")[2])
    return sp.Rational(1, 2) * sp.Rational(10) ** (int(exp or 0) - places)


def to_arb(e: sp.Expr) -> arb:
    if e.is_Rational:
        return arb(int(e.p)) / arb(int(e.q))
    digits = PREC // 3 + 10
    text = str(sp.N(e, digits))
    return arb(text) + arb(0, "1e-%d" % (digits - 10))


@dataclass(frozen=True)
class Val:
    """A scalar: exact (sympy) or decimal (``text`` as written when a bare literal; ``ball``)."""

    exact: sp.Expr | None = None
    text: str | None = None
    ball: arb | None = None

    @staticmethod
    def literal(text: str) -> Val:
        value = literal_value(text)
        if value.is_Integer or significant_digits(text) <= SHORT:
            return Val(exact=value)
        return Val(text=text, ball=arb(text) + arb(0, str(sp.N(half_ulp(text), 5))))

    def as_arb(self) -> arb:
        return self.ball if self.exact is None else to_arb(self.exact)

    def neg(self) -> Val:
        if self.exact is not None:
            return Val(exact=-self.exact)
        text = self.text
        if text is not None:
            text = text[1:] if text.startswith("-") else "-" + text.lstrip("+")
        return Val(text=text, ball=-self.ball)


def apply(op: str, a, b):
    if op == "+":
        return a + b
    if op == "-":
        return a - b
    if op == "*":
        return a * b
    if op == "^":
        if not (b.is_Rational and abs(b.p) <= 64 and b.q <= 4):
            raise Unsupported(f"the power {b}")
        return a ** b
    return a / b


def _binary(op: str, x, y):
    if isinstance(x, Array) or isinstance(y, Array):
        return _elementwise(op, x, y)
    if x.exact is not None and y.exact is not None:
        a, b = x.exact, y.exact
        if op in "/" and b == 0:
            raise Unsupported("division by zero")
        out = apply(op, a, b)
        return Val(exact=out if out.is_Rational else sp.radsimp(out))
    if op == "^":
        if y.exact is None or not y.exact.is_Integer:
            raise Unsupported("a decimal power")
        return Val(ball=x.as_arb() ** int(y.exact))
    a, b = x.as_arb(), y.as_arb()
    return Val(ball=apply(op, a, b))


def _elementwise(op: str, x, y):
    """Julia's broadcast of an operation over an array and a scalar (``ones(1, 1) ./ 2``)."""
    if isinstance(x, Array) and isinstance(y, Array):
        if x.items is None or y.items is None or len(x.items) != len(y.items):
            raise Unsupported("an operation on two arrays of different shapes")
        return Array(items=[_binary(op, u, v) for u, v in zip(x.items, y.items, strict=True)])
    arr, scalar = (x, y) if isinstance(x, Array) else (y, x)

    def f(v):
        return _binary(op, v, scalar) if arr is x else _binary(op, scalar, v)
    if arr.items is not None:
        return Array(items=[f(v) for v in arr.items])
    return Array(rows=[[f(v) for v in r] for r in arr.rows])


def vsqrt(x: Val) -> Val:
    if x.exact is not None:
        return Val(exact=sp.sqrt(x.exact))
    return Val(ball=x.ball.sqrt())


# ---------------------------------------------------------------- tokens

TOKEN = re.compile(r"""
    (?P<space>[ \t]+|\\\n|\#=.*?=\#|\#[^\n]*|/\*.*?\*/)
  | (?P<nl>\n)
  | (?P<num>(?:\d[\d_]*\.?[\d_]*|\.\d[\d_]*)(?:[eEdD][+-]?\d+)?)
  | (?P<str>big"[^"]*"|"[^"]*"|'[^'\n]*')
  | (?P<name>[^\W\d][\w\u0300-\u036f!\u2070-\u209f\u221e]*|@\w+)
  | (?P<op>//|\*\*|->|==|\.[-+*/^]|[-+*/^(),;\[\]{}=.:'<>&|?√])
""", re.VERBOSE | re.DOTALL)


@dataclass
class Tok:
    kind: str
    text: str
    space: bool       # whitespace before it
    line: int


def tokenize(text: str, line0: int = 1) -> list[Tok]:
    out, pos, line, space = [], 0, line0, False
    while pos < len(text):
        m = TOKEN.match(text, pos)
        if not m:
            raise Unsupported(f"cannot read {text[pos:pos + 20]!r}")
        kind, s = m.lastgroup, m.group()
        if kind == "space":
            space = True
        else:
            out.append(Tok(kind, s, space, line))
            space = kind == "nl"
        line += s.count("\n")
        pos = m.end()
    return out


# ---------------------------------------------------------------- parser

class Array:
    """A vector (``rows`` is None, ``items`` a list) or a matrix (``rows`` a list of lists)."""

    def __init__(self, items=None, rows=None):
        self.items, self.rows = items, rows

    def as_rows(self):
        return self.rows if self.rows is not None else [[x] for x in self.items]


IGNORED_CALLS = {"convert", "map", "T", "T_time", "big", "BigFloat", "Float64", "SUN_RCONST", "RCONST", "float",
                 "Rational", "BigInt", "mpf", "Float", "sympy.Rational"}
ZERO = Val(exact=sp.Integer(0))
ONE = Val(exact=sp.Integer(1))
BINARY = {"+": 1, "-": 1, "*": 2, "/": 2, "//": 3, "^": 4, "**": 4,
          ".+": 1, ".-": 1, ".*": 2, "./": 2, ".^": 4}


class Parser:
    """Expressions over ``env`` (name → Val or Array); ``space`` makes whitespace separate
    elements (inside a Julia array literal)."""

    def __init__(self, toks: list[Tok], env: dict | None = None, functions: dict | None = None):
        self.toks, self.i, self.env = toks, 0, env if env is not None else {}
        self.functions = functions or {}
        self.space = [False]

    def peek(self, k: int = 0) -> Tok | None:
        j = self.i + k
        return self.toks[j] if j < len(self.toks) else None

    def at(self, *texts: str) -> bool:
        t = self.peek()
        return t is not None and t.text in texts

    def take(self, text: str | None = None) -> Tok:
        t = self.peek()
        if t is None or (text is not None and t.text != text):
            raise Unsupported(f"expected {text!r}, found {t.text if t else 'end'!r}")
        self.i += 1
        return t

    def skip_nl(self):
        while self.peek() is not None and self.peek().kind == "nl":
            self.i += 1

    def expr(self, level: int = 1):
        x = self.unary() if level <= 2 else self.atom()
        while True:
            t = self.peek()
            if t is None or t.kind != "op" or BINARY.get(t.text, 0) < level:
                return x
            if self.space[-1] and t.space and not (self.peek(1) and self.peek(1).space) and t.text in "+-":
                return x                     # Julia: [a -b] is two elements
            self.i += 1
            self.skip_nl()                   # an operator at the end of a line continues it
            op = "^" if t.text in ("**", ".^") else t.text.lstrip(".") or t.text
            if op == "^":
                y = self.unary()             # right-associative, binds tighter than unary minus
            else:
                y = self.expr(BINARY[op] + 1) if BINARY[op] < 3 else self.expr(4)
            x = _binary(op, x, y)

    def unary(self):
        if self.at("-"):
            self.i += 1
            return self.unary_minus(self.expr(2))
        if self.at("+"):
            self.i += 1
            return self.expr(2)
        return self.expr(3)

    @staticmethod
    def unary_minus(x):
        if isinstance(x, Array):
            raise Unsupported("negated array")
        return x.neg()

    def atom(self):
        t = self.take()
        if t.kind == "num":
            x = Val.literal(t.text.replace("d", "e").replace("D", "e"))
            nxt = self.peek()
            if nxt is not None and not nxt.space and (nxt.kind == "name" or nxt.text == "("):
                return _binary("*", x, self.atom())          # Julia: 2sqrt(3)
            return x
        if t.kind == "str" and t.text.startswith('big"'):
            return Val.literal(t.text[4:-1])
        if t.text == "√":                                    # Julia's prefix square root
            return vsqrt(self.atom())
        if t.text == "(":
            self.space.append(False)
            self.skip_nl()
            x = self.expr()
            self.skip_nl()
            self.take(")")
            self.space.pop()
            return self.postfix(x)
        if t.text == "[":
            return self.postfix(self.array())
        if t.kind == "name":
            return self.postfix(self.name(t))
        if t.kind == "str":
            return t.text[1:-1]
        if t.text == ":" and self.peek() is not None and self.peek().kind == "name":
            return self.take().text                         # a Julia symbol, :Name
        raise Unsupported(f"unexpected {t.text!r} at line {t.line}")

    def postfix(self, x):
        while self.at("[") and not self.peek().space:
            self.i += 1
            idx = self.args("]")
            x = index(x, idx)
        return x

    def args_until_end(self) -> list:
        out = [self.expr()]
        while self.at(","):
            self.i += 1
            out.append(self.expr())
        if self.peek() is not None:
            raise Unsupported(f"cannot read {self.peek().text!r}")
        return out

    def args(self, close: str) -> list:
        self.space.append(False)
        out = []
        self.skip_nl()
        while not self.at(close):
            if self.at(";"):                 # keyword arguments of a Julia call
                self.i += 1
                continue
            if self.peek().kind == "name" and self.peek(1) is not None and self.peek(1).text == "=":
                key = self.take().text
                self.take("=")
                out.append((key, self.expr()))
            else:
                out.append(self.expr())
            self.skip_nl()
            if self.at(","):
                self.i += 1
                self.skip_nl()
        self.take(close)
        self.space.pop()
        return out

    def name(self, t: Tok):
        nxt = self.peek()
        if nxt is not None and nxt.text == "{":        # Rational{BigInt}(…), Vector{T}(…)
            depth = 0
            while True:
                s = self.take().text
                depth += (s == "{") - (s == "}")
                if depth == 0:
                    break
            nxt = self.peek()
        if nxt is not None and nxt.text == "(" and not nxt.space:
            self.i += 1
            return call(t.text, self.args(")"), self.functions)
        if t.text in self.env:
            return self.env[t.text]
        if t.text in ("T", "T_time", "BigFloat", "Float64"):
            return t.text
        if t.text == "pi":
            return Val(exact=sp.pi)
        raise Unsupported(f"unknown name {t.text!r} at line {t.line}")

    def array(self):
        """A Julia array literal after its '[': rows split by ';' or newlines, elements by
        whitespace (hcat) or commas (a vector)."""
        self.space.append(True)
        rows, row, commas = [], [], False
        while True:
            t = self.peek()
            if t is None:
                raise Unsupported("unclosed [")
            if t.text == "]":
                self.i += 1
                break
            if t.text in (";",) or t.kind == "nl":
                self.i += 1
                if row:
                    rows.append(row)
                row = []
                continue
            if t.text == ",":
                commas = True
                self.i += 1
                self.skip_nl()
                continue
            row.append(self.expr())
        if row:
            rows.append(row)
        self.space.pop()
        return concat(rows, commas)


def index(x, idx):
    ints = []
    for v in idx:
        if not isinstance(v, Val) or v.exact is None or not v.exact.is_Integer:
            raise Unsupported("a non-integer index")
        ints.append(int(v.exact))
    if isinstance(x, Array) and len(ints) == 1 and x.items is not None:
        return x.items[ints[0] - 1]
    if isinstance(x, Array) and len(ints) == 2:
        return x.as_rows()[ints[0] - 1][ints[1] - 1]
    raise Unsupported("an index of this shape")


def _hcat(row):
    if all(isinstance(v, Val) for v in row):
        return [list(row)]
    blocks = [v.as_rows() if isinstance(v, Array) else [[v]] for v in row]
    if len({len(b) for b in blocks}) != 1:
        raise Unsupported("hcat of blocks of different heights")
    return [sum((b[i] for b in blocks), []) for i in range(len(blocks[0]))]


def concat(rows, commas: bool):
    if commas:
        if len(rows) != 1:
            raise Unsupported("commas and semicolons in one literal")
        items = rows[0]
        if all(isinstance(v, Val) for v in items):
            return Array(items=items)
        return Array(rows=[v.items if v.items is not None else sum(v.rows, []) for v in items])
    if all(len(r) == 1 and isinstance(r[0], Val) for r in rows):
        return Array(items=[r[0] for r in rows])                  # [a; b; c]
    if all(len(r) == 1 and isinstance(r[0], Array) and r[0].items is not None for r in rows):
        return Array(items=sum((r[0].items for r in rows), []))   # vcat of vectors
    out = []
    for r in rows:
        out.extend(_hcat(r))
    if len(out) == 1 and not any(isinstance(v, Array) for v in rows[0]) and len(rows) == 1:
        return Array(rows=out)                                     # [a b c]: a 1×n matrix
    return Array(rows=out)


def _string_literal(x) -> Val:
    if not isinstance(x, str):
        raise Unsupported("parse of a non-string")
    return Val.literal(x.strip())


def call(name: str, args: list, functions: dict):
    if name in functions:
        return functions[name](*args)
    plain = [a for a in args if not isinstance(a, tuple)]
    if name in ("sqrt", "SUNRsqrt", "sympy.sqrt", "np.sqrt", "√"):
        return vsqrt(plain[0])
    if name == "parse":
        return _string_literal(plain[-1])
    if name in IGNORED_CALLS:
        vals = [a for a in plain if not isinstance(a, str) or name in ("BigFloat", "big", "mpf")]
        if len(vals) == 1 and isinstance(vals[0], str):
            return _string_literal(vals[0])
        if len(vals) == 2 and name in ("Rational", "sympy.Rational"):
            return _binary("/", vals[0], vals[1])
        if len(vals) != 1:
            raise Unsupported(f"{name} with {len(vals)} arguments")
        return vals[0]
    if name == "fill" and len(plain) >= 2:
        dims = [int(a.exact) for a in plain[1:]]
        if len(dims) == 1:
            return Array(items=[plain[0]] * dims[0])
        return Array(rows=[[plain[0]] * dims[1] for _ in range(dims[0])])
    if name in ("zeros", "ones", "Matrix", "Vector"):
        dims = [int(a.exact) for a in plain if isinstance(a, Val) and a.exact is not None]
        fill = ZERO if name == "zeros" else ONE
        if len(dims) == 1:
            return Array(items=[fill] * dims[0])
        if len(dims) == 2:
            return Array(rows=[[fill] * dims[1] for _ in range(dims[0])])
    raise Unsupported(f"the function {name}")


def parse_value(text: str, env: dict | None = None):
    p = Parser(tokenize(text), env)
    x = p.expr()
    if p.peek() is not None:
        raise Unsupported(f"trailing {p.peek().text!r}")
    return x
