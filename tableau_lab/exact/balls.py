r"""Decimal tableaux as balls: a method known only to the digits its source wrote, each decimal
entry the interval its digits state, in python-flint's ``arb`` ball arithmetic ([Joh17] F.
Johansson, *Arb: efficient arbitrary-precision midpoint-radius interval arithmetic*, IEEE Trans.
Comput. 66 (2017) 1281–1292).  Read from a tableau file with ``"numbers": "decimal"``
(docs/tableau-format.md, :func:`tableau_json.load_any`); the certified analyses are
:mod:`tableau_lab.analysis.certified`.

A decimal entry ``"0.0815892447"`` is the ball [x − u/2, x + u/2], x its exact decimal value and u
one unit in its last written digit; a file's ``"radius"`` (absolute, every decimal entry) or
``"digits"`` (every entry correctly rounded to that many significant digits) says more.  An exact
entry of the tableau grammar ("1/3", "sqrt(2)/2") stays exact: it is kept, and its ball is its
value enclosed at the working precision (:func:`exact_ball`).

>>> x = coefficient("0.0815892447", HALF_UNIT)
>>> x.center, x.radius, x.digits
(815892447/10000000000, 1/20000000000, 9)
>>> coefficient("-1.2e-3", HALF_UNIT).radius
1/20000
>>> coefficient("1/3", HALF_UNIT).exact, coefficient("2.5", Rounding("digits", 30)).radius
(1/3, 1/200000000000000000000000000000)
"""
from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import flint
import sympy as sp

from ..errors import InputError

__all__ = ["BallError", "Coefficient", "Rounding", "HALF_UNIT", "BallMethod", "coefficient", "exact_ball",
           "is_decimal", "working_precision", "MAX_DECIMAL_DIGITS", "MAX_EXPONENT", "GUARD_BITS", "MIN_PREC",
           "ball_text", "upper_text"]

#: the most significant digits of one decimal entry, and the largest |exponent| (the precision budget: the
#: working precision follows the digits, and 2000 digits are 6.7 kbit, a few ms per order condition)
MAX_DECIMAL_DIGITS = 2000
MAX_EXPONENT = 2000
#: bits of working precision beyond the digits given (the rounding of the arithmetic stays far below the
#: entries' radii), and the least working precision
GUARD_BITS = 64
MIN_PREC = 128
_BITS_PER_DIGIT = 3.3219280948873626     # log2(10), only to size the working precision

_HAS_DECIMAL = re.compile(r"[0-9]\.|\.[0-9]|[0-9][eE][+-]?[0-9]")
DECIMAL = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


class BallError(InputError):
    """A decimal entry that cannot be read as a ball, or a decimal tableau whose shapes do not fit
    (``entry``: the one-based entry, when known); the reader adds the file."""

    def __init__(self, message: str, entry: str | None = None) -> None:
        super().__init__(message)
        self.entry = entry


@dataclass(frozen=True)
class Rounding:
    """How a file's decimal entries were rounded: ``"half-unit"`` (± half a unit in the last
    written digit), ``"radius"`` (± ``value``, absolute) or ``"digits"`` (correctly rounded to
    ``value`` significant digits)."""
    rule: str
    value: Any = None

    def describe(self) -> str:
        if self.rule == "radius":
            return f"each decimal entry ± {upper_text(self.value, 3)} (the file's radius)"
        if self.rule == "digits":
            return f"each decimal entry correctly rounded to {self.value} significant digits (the file's digits)"
        return "each decimal entry ± half a unit in its last written digit"


HALF_UNIT = Rounding("half-unit")


def is_decimal(text: object) -> bool:
    """Whether ``text`` is a decimal numeral ("0.25", "-1.2e-3", "3."), not an exact entry.

    >>> is_decimal("0.25"), is_decimal("1/4"), is_decimal("12"), is_decimal("1e-3")
    (True, False, False, True)
    """
    return isinstance(text, str) and bool(DECIMAL.fullmatch(text)) and any(ch in text for ch in ".eE")


@dataclass(frozen=True)
class Coefficient:
    """One entry: ``text`` as written; ``exact`` its exact value when the file wrote an exact entry
    (radius 0), else None and ``center`` ± ``radius`` (rationals) is its ball; ``digits`` the
    significant digits written (0 for an exact entry)."""
    text: str
    exact: sp.Expr | None = None
    center: flint.fmpq | None = None
    radius: flint.fmpq = field(default_factory=lambda: flint.fmpq(0))
    digits: int = 0

    def ball(self) -> flint.arb:
        """The entry's ball at the current working precision (``flint.ctx.prec``)."""
        if self.exact is not None:
            return exact_ball(self.exact)
        return flint.arb(flint.arb(self.center), flint.arb(self.radius))


def _decimal_parts(text: str) -> tuple[int, int, int]:
    """(mantissa, exponent, significant digits): the value is mantissa·10^exponent, the last written
    digit is worth 10^exponent."""
    body, _, exp = text.lower().partition("e")
    sign = -1 if body.startswith("-") else 1
    body = body.lstrip("+-")
    whole, _, frac = body.partition(".")
    digits = (whole + frac).lstrip("0")
    if len(whole + frac) > MAX_DECIMAL_DIGITS + 1 or len(exp) > 6:
        raise BallError(f"{text[:40]}… has more than the {MAX_DECIMAL_DIGITS} digits a decimal entry may have "
                        "(MAX_DECIMAL_DIGITS, exact/balls.py)")
    e = int(exp or 0) - len(frac)
    if abs(e) > MAX_EXPONENT:
        raise BallError(f"{text} has an exponent beyond ±{MAX_EXPONENT} (MAX_EXPONENT, exact/balls.py)")
    return sign * int(whole + frac or "0"), e, len(digits)


def _power10(e: int) -> flint.fmpq:
    return flint.fmpq(10) ** e if e >= 0 else flint.fmpq(1, 10 ** -e)


def _floor_log10(x: flint.fmpq) -> int:
    """⌊log₁₀ |x|⌋ for a rational x ≠ 0, exactly."""
    p, q = abs(int(x.p)), int(x.q)
    e = len(str(p)) - len(str(q))
    while _power10(e) > flint.fmpq(p, q):
        e -= 1
    while _power10(e + 1) <= flint.fmpq(p, q):
        e += 1
    return e


def coefficient(value: str, rounding: Rounding) -> Coefficient:
    """The coefficient a decimal file's entry ``value`` denotes (module docstring): a decimal numeral
    as a ball by ``rounding``, anything else through the exact tableau grammar."""
    if not is_decimal(value) and _HAS_DECIMAL.search(value):
        raise BallError(f"{value[:60]!r} is neither a decimal numeral (such as \"0.0815892447\" or \"-1.2e-3\") nor an "
                        "exact entry (a decimal is one number, not part of an expression)")
    if not is_decimal(value):
        from .grammar import parse_entry
        e = parse_entry(value)
        if e.free_symbols:
            raise BallError(f"{value!r} has the name(s) {', '.join(sorted(map(str, e.free_symbols)))}: a decimal "
                            "tableau has no free parameters")
        return Coefficient(value, exact=e)
    mantissa, e, digits = _decimal_parts(value)
    center = flint.fmpq(mantissa) * _power10(e)
    if rounding.rule == "radius":
        radius = rounding.value
    elif rounding.rule == "digits":
        radius = (flint.fmpq(0) if mantissa == 0
                  else _power10(_floor_log10(center) - rounding.value + 1) / 2)
        digits = max(digits, rounding.value)
    else:
        radius = _power10(e) / 2
    return Coefficient(value, center=center, radius=radius, digits=digits)


def radius_of(text: str) -> flint.fmpq:
    """The exact value of a file's ``"radius"`` (a non-negative decimal or integer)."""
    if not isinstance(text, str) or not DECIMAL.fullmatch(text) or text.startswith("-"):
        raise BallError(f'radius must be a non-negative decimal string such as "1e-30", not {str(text)[:40]!r}')
    mantissa, e, _ = _decimal_parts(text)
    return flint.fmpq(mantissa) * _power10(e)


def exact_ball(e: sp.Expr) -> flint.arb:
    """An exact entry enclosed at the current working precision: rationals, sums, products,
    rational powers of positive numbers, cos(qπ), sin(qπ) and real roots of polynomials (through
    a rational approximation of certified distance, sympy's ``eval_rational``).

    >>> with flint.ctx.workprec(100):       # √2/2 + 1/3 = 0.70710678118654752440… + 0.33333333333333333333…
    ...     exact_ball(sp.sqrt(2) / 2 + sp.Rational(1, 3)).str(20)
    '[1.0404401145198808577 +/- 3.42e-20]'
    """
    if e.is_Rational:
        return flint.arb(flint.fmpq(int(e.p), int(e.q)))
    if e.is_Add or e.is_Mul:
        parts = [exact_ball(a) for a in e.args]
        out: flint.arb = parts[0]
        for p in parts[1:]:
            out = out + p if e.is_Add else out * p
        return out
    if e.is_Pow and e.exp.is_Rational:
        base = exact_ball(e.base)
        if e.exp.is_Integer:
            return base ** int(e.exp)
        if base > 0:
            num, den = int(e.exp.p), int(e.exp.q)
            return base.root(den) ** num
    if isinstance(e, (sp.cos, sp.sin)):
        q = e.args[0] / sp.pi
        if q.is_Rational:
            f = flint.fmpq(int(q.p), int(q.q))
            return flint.arb.cos_pi_fmpq(f) if isinstance(e, sp.cos) else flint.arb.sin_pi_fmpq(f)
    if isinstance(e, sp.CRootOf) and e.is_real:
        width = sp.Rational(1, 2) ** (flint.ctx.prec + 8)
        x = e.eval_rational(dx=width, dy=width, n=int(flint.ctx.prec * 0.302) + 10)
        return flint.arb(flint.arb(flint.fmpq(int(x.p), int(x.q))), flint.arb(flint.fmpq(int(width.p), int(width.q))))
    raise BallError(f"{e} cannot be enclosed in ball arithmetic here (rationals, radicals of positive numbers, "
                    "cos and sin of rational multiples of pi, real roots of polynomials)")


def working_precision(coefficients: list[Coefficient], rounding: Rounding) -> int:
    """Bits of working precision for these entries: their significant digits (or the file's radius
    against the largest entry), and :data:`GUARD_BITS` more, at least :data:`MIN_PREC`."""
    digits = max((c.digits for c in coefficients), default=0)
    if rounding.rule == "radius" and rounding.value != 0:
        biggest = max((abs(c.center) for c in coefficients if c.center is not None and c.center != 0),
                      default=flint.fmpq(1))
        digits = max(digits, _floor_log10(biggest) - _floor_log10(rounding.value) + 1)
    return max(MIN_PREC, int(digits * _BITS_PER_DIGIT) + 1 + GUARD_BITS)


def ball_text(x: flint.arb, digits: int = 6) -> str:
    """A ball as arb prints it, rigorous: ``[m +/- r]`` (every number in it within the brackets), or
    the exact number when the ball is a point.

    >>> ball_text(flint.arb("0.5")), ball_text(flint.arb(1) / 3, 5)
    ('0.500000', '[0.33333 +/- 3.34e-6]')
    """
    return x.str(digits, radius=True, more=True)


def upper_text(x: flint.arb | flint.fmpq, digits: int = 2) -> str:
    """An upper bound of |x| (a ball, or a rational) in ``digits`` significant digits, rounded up (a
    bound, not an estimate).

    >>> upper_text(flint.arb("2.01e-20")), upper_text(flint.arb(-3)), upper_text(flint.fmpq(1, 10 ** 30), 3)
    ('2.1e-20', '3.0', '1.00e-30')
    """
    if isinstance(x, flint.fmpq):
        u = abs(x)
    else:
        man, exp = x.abs_upper().mid().man_exp()
        u = flint.fmpq(int(man)) * (flint.fmpq(2) ** int(exp) if exp >= 0 else flint.fmpq(1, 2 ** -int(exp)))
    if u == 0:
        return "0"
    e = _floor_log10(u) - digits + 1
    m = -((-u / _power10(e)).floor())          # ⌈u / 10^e⌉
    text = str(int(m))
    if len(text) > digits:                     # rounded up to the next power of ten
        text, e = text[:digits], e + 1
    lead = f"{text[0]}.{text[1:]}" if digits > 1 else text
    point = e + digits - 1
    return lead if point == 0 else f"{lead}e{point}"


Matrix = tuple[tuple[Coefficient, ...], ...]
Vector = tuple[Coefficient, ...]


@dataclass(frozen=True)
class BallMethod:
    """A Runge–Kutta (``kind="rk"``: A, b, optional c and embedded weights bhat) or partitioned
    Runge–Kutta method (``kind="prk"``: A, b, c and Ahat, bhat, chat) whose entries are
    :class:`Coefficient` s, validated once; :meth:`balls` gives them as ``arb`` balls at the working
    precision ``prec`` (bits).  The analyses are :mod:`tableau_lab.analysis.certified`
    (``tl.verify``).

    >>> import tableau_lab as tl
    >>> m = tl.load('{"name": "midpoint", "kind": "rk", "numbers": "decimal", "A": [["0.5"]], "b": [1]}')
    >>> m.s, m.prec, m.entry("A", 1, 1).radius, m.entry("b", 1).exact
    (1, 128, 1/20, 1)
    """

    name: str
    kind: str
    A: Matrix
    b: Vector
    c: Vector | None = None
    bhat: Vector | None = None
    Ahat: Matrix | None = None
    chat: Vector | None = None
    rounding: Rounding = HALF_UNIT
    source: str = ""
    notes: tuple[str, ...] = ()
    claims: tuple[tuple[str, Any], ...] = ()
    provenance: tuple[tuple[str, Any], ...] = ()
    prec: int = field(default=0, compare=False)
    # the entries as balls, computed once on construction: ((key, rows or vector), …)
    _balls: tuple[tuple[str, Any], ...] = field(default=(), init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        s = len(self.A)
        for key, M in (("A", self.A), ("Ahat", self.Ahat)):
            if M is not None and (s == 0 or any(len(row) != s for row in M)):
                raise BallError(f"{key} must be square and non-empty (s = {s} rows)", key)
        for key in ("b", "c", "bhat", "chat"):
            v = getattr(self, key)
            if v is not None and len(v) != s:
                raise BallError(f"{key} has {len(v)} entries, expected {s} (s = {s} stage{'s' * (s != 1)})", key)
        if self.kind == "prk" and (self.Ahat is None or self.bhat is None):
            raise BallError("a partitioned method needs Ahat and bhat", "Ahat")
        if not self.prec:
            object.__setattr__(self, "prec", working_precision(list(self.coefficients()), self.rounding))
        balls: dict[str, Any] = {}
        with flint.ctx.workprec(self.prec):
            for key in ("A", "b", "bhat", "Ahat", "c", "chat"):
                v = getattr(self, key)
                if v is None and key in ("c", "chat"):
                    M = balls.get("A" if key == "c" else "Ahat")
                    balls[key] = None if M is None else tuple(sum(row, flint.arb(0)) for row in M)
                elif v is None:
                    balls[key] = None
                else:
                    balls[key] = tuple(tuple(x.ball() for x in r) if isinstance(r, tuple) else r.ball() for r in v)
        object.__setattr__(self, "_balls", tuple(balls.items()))

    def __repr__(self) -> str:
        """Short: the name, kind, size and precision (the entries are :meth:`entry`, :meth:`balls`)."""
        return (f"BallMethod({self.name!r}, kind={self.kind!r}, s={self.s}, least_digits={self.least_digits}, "
                f"prec={self.prec})")

    @property
    def s(self) -> int:
        """The number of stages."""
        return len(self.A)

    @property
    def claims_dict(self) -> dict[str, Any]:
        return dict(self.claims)

    @property
    def parameters(self) -> tuple[()]:
        """Empty: a decimal tableau has no free parameters."""
        return ()

    def coefficients(self) -> Iterator[Coefficient]:
        """Every coefficient of the tableau (and of a claimed SSP coefficient)."""
        for key in ("A", "b", "c", "bhat", "Ahat", "chat"):
            v = getattr(self, key)
            if v is None:
                continue
            for x in v:
                yield from (x if isinstance(x, tuple) else (x,))
        for _, v in self.claims:
            if isinstance(v, Coefficient):
                yield v

    def entry(self, key: str, i: int, j: int | None = None) -> Coefficient:
        """The coefficient of ``key`` at one-based row ``i`` (and column ``j`` of a matrix)."""
        v = getattr(self, key)
        x: Coefficient = v[i - 1][j - 1] if j is not None else v[i - 1]
        return x

    def explicit(self, key: str = "A") -> bool:
        """The matrix is strictly lower triangular with exact zeros (a decimal 0.0 is a ball, not a zero)."""
        M = getattr(self, key)
        return all(M[i][j].exact == 0 for i in range(self.s) for j in range(i, self.s))

    @property
    def order_bound(self) -> int:
        """No s-stage RK method has order above 2s, nor above s when explicit (:attr:`RungeKutta.order_bound`)."""
        return self.s if self.kind == "rk" and self.explicit() else 2 * self.s

    def balls(self, key: str) -> Any:
        """The entries of ``key`` as balls at :attr:`prec` (a tuple, or a tuple of rows), None when
        absent; c absent is A·1 (computed once, on construction)."""
        return dict(self._balls)[key]

    @property
    def least_digits(self) -> int:
        """The fewest significant digits of a decimal entry (0 when every entry is exact)."""
        return min((c.digits for c in self.coefficients() if c.exact is None), default=0)
