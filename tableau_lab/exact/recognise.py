r"""Exact numbers of small height inside a ball: rationals, then algebraic numbers of low degree.

A coefficient known only as a ball (a python-flint ``arb``: midpoint ± radius) is *recognised*
when an exact number of small height lies inside it and the ball has clearly more digits than
that number needs.  Three searches, cheapest first:

1. **Rationals**: the simplest rational of the ball (:func:`~tableau_lab.exact.rationals.simplest_between`,
   the Stern–Brocot / continued-fraction search) has the smallest height of all rationals inside it.
2. **Algebraic numbers of degree k** (2 ≤ k ≤ :attr:`Limits.degree`): an integer relation
   c₀ + c₁x + … + c_k x^k ≈ 0 found by LLL (python-flint's ``fmpz_mat.lll``, exact integers) on the
   lattice of the rows (e_i | round(S·mᶦ)), m the ball's midpoint and S = 10^d (d its digits) —
   the integer-relation method of Lenstra, Lenstra & Lovász [LLL82] as used for "recognising"
   algebraic numbers (Kannan, Lenstra & Lovász [KLL88]; Bailey [Bai00] surveys it beside
   Ferguson–Bailey PSLQ [FB92]).  The relation's irreducible factor with exactly one root in the
   ball (a Sturm count with the ball's exact ends) is the candidate's minimal polynomial.
3. **Elements of a given field Q(θ)** (:func:`recognise_in`): a relation c·x + a₀ + a₁θ + … = 0,
   used by the tableau reconstruction (``analysis/reconstruct.py``) once one entry has shown the
   field: every entry of Gauss 2 lies in Q(√3), every entry of SDIRK34 in Q(γ); and of the field
   several generators make together (:func:`joint_basis`, :func:`recognise_in_basis`): Gauss 4's
   entries lie in the field of degree 8 of two of its quartic nodes.

Every candidate is checked, by certified interval arithmetic (:func:`~tableau_lab.exact.real_roots.enclose`),
to lie inside the ball, and is returned in the tableau grammar's normal form (it re-parses to itself).

**How sure.**  A relation of height H among k + 1 numbers (max |cᵢ| ≤ H) exists by chance for a
number known to d digits when H^(k+1) ≈ 10^d: such a relation is what d digits of noise give.
So a candidate *needs* (k + 1)·log₁₀ H digits (a rational p/q: 2·log₁₀ max(|p|, q)) and is
*strong* when the ball has :attr:`Limits.margin` digits more; otherwise it is reported, flagged
*weak* (the ball cannot tell it from chance).  The ball's digits are log₁₀(max(1, |m|)/r).

>>> import flint
>>> r = recognise(flint.arb("[0.33333333333333333333 +/- 5e-21]"))
>>> r.text, r.kind, r.height, r.strong
('1/3', 'rational', 3, True)
>>> with flint.ctx.workprec(200):         # the ball's midpoint read to 200 bits (53 by default)
...     x = flint.arb("[0.78867513459481288225457439 +/- 5e-28]")
>>> r = recognise(x)     # 1/2 + √3/6: 6x² − 6x + 1
>>> r.text, r.kind, r.height, round(r.needed, 1), r.strong
('sqrt(3)/6 + 1/2', 'quadratic', 6, 2.3, True)
>>> recognise(flint.arb("[0.79 +/- 0.005]")).strong                          # 79/100? 4/5? chance decides
False

References: [LLL82] A. K. Lenstra, H. W. Lenstra, L. Lovász, Factoring polynomials with rational
coefficients, Math. Ann. 261 (1982) 515–534.  [KLL88] R. Kannan, A. K. Lenstra, L. Lovász,
Polynomial factorization and nonrandomness of bits of algebraic and some transcendental numbers,
Math. Comp. 50 (1988) 235–250.  [FB92] H. R. P. Ferguson, D. H. Bailey, A polynomial time,
numerically stable integer relation algorithm, RNR Technical Report RNR-91-032 (1992); H. R. P.
Ferguson, D. H. Bailey, S. Arno, Analysis of PSLQ, Math. Comp. 68 (1999) 351–369.  [Bai00]
D. H. Bailey, Integer relation detection, Computing in Science & Engineering 2(1) (2000) 24–28.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from fractions import Fraction
from functools import lru_cache
from math import gcd, inf, log10
from typing import Any, NamedTuple

import flint
import sympy as sp

from ..budget import computing, time_limit
from .grammar import format_entry, parse_entry
from .rationals import height as rational_height, simplest_between

__all__ = ["Limits", "LIMITS", "LIMIT_OPTION", "CEILINGS", "Ball", "Basis", "Recognition", "ball_of", "recognise",
           "recognise_in", "recognise_in_basis", "joint_basis", "generator", "inside", "limits_with", "field_degree",
           "relation", "PROBE_DIGITS", "field_text"]


@dataclass(frozen=True)
class Limits:
    """The limits of a reconstruction, in one place (``limits_with`` changes some of them, within
    :data:`CEILINGS`; ``tl.reconstruct``'s keywords are these names)."""
    degree: int = 4             # the highest degree of an algebraic candidate (1: rationals only)
    height: int = 10 ** 30      # the largest coefficient of a relation (a rational's numerator or denominator)
    margin: float = 5.0         # digits a ball must have beyond those its candidate needs, else "weak"
    digits: int = 200           # the most digits of a ball used (a tighter ball is used to this many)
    seconds: float = 60.0       # the time budget of one tableau's reconstruction, or of one recognise (0: none)
    fields: int = 3             # the most number fields Q(θ) tried for every entry of one tableau
    basis: int = 16             # the largest degree of the joint field of a tableau's generators tried


LIMITS = Limits()
LIMIT_OPTION = "the reconstruction limit seconds"      # how a user raises the time budget (BudgetError's message)
#: the most a user may raise a limit to (each one's cost grows with it: a lattice of degree + 1 rows
#: of digits-digit numbers, a joint basis of ``basis`` numbers tested at PROBE_DIGITS)
CEILINGS = {"degree": 16, "digits": 5000, "fields": 8, "basis": 64}
_X = sp.Symbol("x")
_GUARD_BITS = 32                # extra bits of an exact enclosure beyond the ball's
PROBE_DIGITS = 600              # digits at which exact numbers are tested for relations (independence, degree)
PROBE_DEGREE = 16               # the highest degree field_degree tries
_PROBE_BITS = int(PROBE_DIGITS * 3.33) + _GUARD_BITS


def limits_with(**changes: Any) -> Limits:
    """:data:`LIMITS` with some values changed; an unknown name or a value out of range: ValueError.

    >>> limits_with(degree=2).degree
    2
    """
    for k, v in changes.items():
        if k not in Limits.__dataclass_fields__:
            raise ValueError(f"unknown reconstruction limit {k!r} (known: {', '.join(Limits.__dataclass_fields__)})")
        least, most = (1 if k in ("degree", "height", "digits", "basis") else 0), CEILINGS.get(k)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or v < least or (most is not None and v > most):
            raise ValueError(f"the reconstruction limit {k} must be a number from {least}"
                             f"{'' if most is None else f' to {most}'}, not {v!r}")
    return replace(LIMITS, **changes)


class Ball(NamedTuple):
    """A ball with exact rational ends, and the digits it states."""
    mid: Fraction
    rad: Fraction
    digits: float               # log10(max(1, |mid|) / rad); inf for a point

    @property
    def lo(self) -> Fraction:
        return self.mid - self.rad

    @property
    def hi(self) -> Fraction:
        return self.mid + self.rad


def _fraction(a: Any) -> Fraction:
    man, exp = a.man_exp()
    return Fraction(int(man)) * Fraction(2) ** int(exp)


def ball_of(x: Any) -> Ball:
    """The ball of a python-flint ``arb`` (its ends exact: the midpoint and radius are dyadic).

    >>> b = ball_of(flint.arb("[0.25 +/- 1e-10]"))
    >>> b.mid, round(b.digits, 3)
    (Fraction(1, 4), 10.0)
    """
    if not isinstance(x, flint.arb):
        raise TypeError(f"a ball is a python-flint arb, not {type(x).__name__}")
    if not x.is_finite():
        raise ValueError(f"the ball {x} is not finite")
    mid, rad = _fraction(x.mid()), _fraction(x.rad())
    return Ball(mid, rad, inf if rad == 0 else _log10(max(Fraction(1), abs(mid)) / rad))


def _log10(f: Fraction) -> float:
    """log10 of a positive rational of any size (a float of it may overflow)."""
    return log10(f.numerator) - log10(f.denominator)


def _used(x: Any, limits: Limits) -> Ball:
    """The ball of ``x`` as the search uses it: a ball tighter than ``limits.digits`` digits widened
    to that many (its midpoint rounded to as many bits; the rounding added to the radius), so that
    no step works at more precision than the limit allows.  Still a ball around the true value."""
    ball = ball_of(x)
    if ball.digits <= limits.digits:
        return ball
    scale = max(Fraction(1), abs(ball.mid))
    step = scale / 10 ** (limits.digits + 2)
    mid = round(ball.mid / step) * step
    rad = ball.rad + abs(mid - ball.mid) + scale / 10 ** limits.digits
    return Ball(mid, rad, _log10(scale / rad))


@dataclass(frozen=True)
class Recognition:
    """What :func:`recognise` found for one ball: ``value`` (exact, in the grammar's normal form;
    None: nothing within the limits), its ``kind``, the ``height`` of the relation that found it,
    the ball's ``digits`` and the digits the candidate ``needed``; ``strong`` when the ball has the
    margin beyond them, else the candidate is *weak*.  ``field``: the generator θ of the field
    Q(θ) (or the generators of the field) the relation was sought in (empty: by its own powers)."""
    value: sp.Expr | None
    kind: str                   # "integer", "rational", "quadratic", "degree 3", …, or "none"
    height: int
    digits: float
    needed: float
    margin: float               # Limits.margin when it was found
    field: tuple[sp.Expr, ...] = ()
    minimal_polynomial: sp.Expr | None = None

    @property
    def strong(self) -> bool:
        return self.value is not None and self.digits - self.needed >= self.margin

    @property
    def weak(self) -> bool:
        return self.value is not None and not self.strong

    @property
    def text(self) -> str | None:
        return None if self.value is None else str(format_entry(self.value))

    @property
    def where(self) -> str:
        """The words " in Q(θ)" for the field its relation was sought in; "" when sought by its own powers."""
        return f" in {field_text(self.field)}" if self.field else ""

    def verdict(self) -> str:
        """One line: the value, how it was found and how sure."""
        if self.value is None:
            return f"not recognised (no candidate of height ≤ the limit from {_digits(self.digits)} digits)"
        sure = "recognised" if self.strong else f"WEAK (fewer than {self.margin:g} digits to spare)"
        return (f"{self.text}: {self.kind}{self.where}, height {self.height}, {_digits(self.digits)} digits given, "
                f"{self.needed:.1f} needed: {sure}")


def field_text(generators: tuple[sp.Expr, ...]) -> str:
    """The field Q(θ₁, …) as text, each generator in the grammar.

    >>> field_text((sp.sqrt(2), sp.sqrt(3)))
    'Q(sqrt(2), sqrt(3))'
    """
    return f"Q({', '.join(str(format_entry(t)) for t in generators)})"


def _digits(d: float) -> str:
    return "exact" if d == inf else f"{d:.1f}"


def _none(ball: Ball, limits: Limits) -> Recognition:
    return Recognition(None, "none", 0, ball.digits, inf, limits.margin)


def _needed(coeffs: list[int]) -> tuple[int, float]:
    """The height of a relation and the digits a relation of that height among its numbers needs."""
    h = max(1, *(abs(c) for c in coeffs))
    return h, len(coeffs) * log10(h)


def _kind(degree: int, value: sp.Expr) -> str:
    if degree == 1:
        return "integer" if value.is_Integer else "rational"
    return "quadratic" if degree == 2 else f"degree {degree}"


def _normal(value: sp.Expr) -> sp.Expr:
    """The grammar's normal form of an exact number (it re-parses to itself)."""
    e = parse_entry(str(format_entry(value)))
    if parse_entry(str(format_entry(e))) != e:       # the grammar's fixed point (grammar._parse_text) holds
        raise ValueError(f"{e} does not re-parse to itself")
    return e


def inside(value: sp.Expr, ball: Ball) -> bool:
    """True when the exact real ``value`` is certainly inside the closed ball (an interval
    enclosure at more bits than the ball states lies within its ends).

    >>> inside(sp.sqrt(2), ball_of(flint.arb("[1.41421356 +/- 1e-8]")))
    True
    >>> inside(sp.sqrt(2), ball_of(flint.arb("[1.4142 +/- 1e-6]")))       # √2 = 1.41421356…
    False
    """
    if value.is_Rational:
        return ball.lo <= Fraction(int(value.p), int(value.q)) <= ball.hi
    width = ball.rad if ball.rad else Fraction(1, 2 ** 64)
    lo, hi = _enclosure(value, max(64, int(_log10(max(Fraction(2), abs(ball.mid)) / width) * 3.33) + _GUARD_BITS))
    return ball.lo <= lo and hi <= ball.hi


def _enclosure(value: sp.Expr, bits: int) -> tuple[Fraction, Fraction]:
    """Exact rational ends of a certified enclosure of the real ``value`` at ``bits`` bits
    (:func:`~tableau_lab.exact.real_roots.enclose`, in an interval context of its own: no global precision)."""
    from mpmath.ctx_iv import MPIntervalContext

    from .real_roots import enclose, lower, upper
    ctx = MPIntervalContext()
    ctx.prec = bits
    box = enclose(value, ctx)
    return _mpf_fraction(lower(box)), _mpf_fraction(upper(box))


def _mpf_fraction(x: Any) -> Fraction:
    sign, man, exp, _ = x._mpf_                        # mpmath's raw float: man_exp would drop the sign
    return Fraction(-1 if sign else 1) * Fraction(int(man)) * Fraction(2) ** int(exp)


# ------------------------------------------------------------------ relations by LLL

def relation(values: list[Fraction], digits: float, limits: Limits) -> list[int] | None:
    """An integer relation Σ cᵢ vᵢ ≈ 0 among numbers known to ``digits`` digits: the first row of the
    LLL-reduced lattice (e_i | round(S·vᵢ)), S = 10^digits; None when its height passes the limit.

    >>> relation([Fraction(1), Fraction(141421356237, 10 ** 11), Fraction(2)], 10, LIMITS)   # 1, √2, 2
    [-2, 0, 1]
    """
    scale = 10 ** max(1, int(min(digits, limits.digits)))
    n = len(values)
    rows = [[int(i == j) for j in range(n)] + [round(scale * v)] for i, v in enumerate(values)]
    reduced = flint.fmpz_mat(rows).lll()
    coeffs = [int(reduced[0, j]) for j in range(n)]
    g = gcd(*coeffs)
    if g == 0 or max(abs(c) for c in coeffs) > limits.height:
        return None
    return [c // g for c in coeffs]


def _rational(ball: Ball, limits: Limits) -> Recognition | None:
    r = simplest_between(ball.lo, ball.hi)
    value = sp.Rational(r.numerator, r.denominator)
    h = rational_height(r)
    if h > limits.height:
        return None
    _, need = _needed([h, 1])
    return Recognition(value, _kind(1, value), h, ball.digits, need, limits.margin,
                       minimal_polynomial=r.denominator * _X - r.numerator)


def _radical_roots(P: sp.Poly) -> list[sp.Expr]:
    """The real roots of P in square roots, when they are: a quadratic, or a quartic that is a
    quadratic in (x − m)² after the shift m = −b/(4a) (the nodes of Gauss 4 and 5:
    1/2 ± √(…± …√30)/70); none otherwise (a cubic's Cardano form is left as ``root(P, k)``).  Not in
    normal form yet: only the one inside the ball is put in it."""
    n = P.degree()
    if n == 2:
        a, b, c = P.all_coeffs()
        return [(-b + s * sp.sqrt(b * b - 4 * a * c)) / (2 * a) for s in (1, -1)]
    if n != 4:
        return []
    a, b = P.all_coeffs()[:2]
    shift = -b / (4 * a)
    Q = sp.Poly(P.as_expr().subs(_X, _X + shift), _X)
    q = Q.all_coeffs()
    if q[1] != 0 or q[3] != 0:
        return []
    A, B, C = q[0], q[2], q[4]                         # A y⁴ + B y² + C with y = x − shift
    disc = B * B - 4 * A * C
    if disc < 0:
        return []
    out = []
    for s in (1, -1):
        y2 = (-B + s * sp.sqrt(disc)) / (2 * A)
        if y2 >= 0:
            out += [shift + t * sp.sqrt(y2) for t in (1, -1)]
    return out


def _root_in(P: sp.Poly, ball: Ball) -> sp.Expr | None:
    """The one root of the irreducible ``P`` (degree ≥ 2) in the ball, exactly (square roots where
    :func:`_radical_roots` finds them, else ``root(P, k)``), or None when the ball does not hold
    exactly one."""
    lo, hi = sp.Rational(ball.lo.numerator, ball.lo.denominator), sp.Rational(ball.hi.numerator, ball.hi.denominator)
    if P.count_roots(lo, hi) != 1:                     # Sturm: exact
        return None
    for v in _radical_roots(P):
        if inside(v, ball):
            return _normal(v)
    if P.degree() == 2:
        return None
    below = P.count_roots(None, lo)                    # lo is no root: P is irreducible of degree ≥ 2
    v = _normal(sp.CRootOf(P.as_expr(), int(below)))
    return v if inside(v, ball) else None


def _algebraic(ball: Ball, degree: int, limits: Limits) -> Recognition | None:
    with computing(f"an integer relation among the powers 0…{degree} of a ball"):
        c = relation([ball.mid ** i for i in range(degree + 1)], ball.digits, limits)
    if c is None or not any(c[1:]):
        return None
    P = sp.Poly(list(reversed(c)), _X, domain=sp.QQ)
    for f, _ in P.factor_list()[1]:
        if f.degree() < 2:
            continue
        f = sp.Poly(f.as_expr(), _X, domain=sp.ZZ).primitive()[1]
        v = _root_in(f, ball)
        if v is not None:
            h, need = _needed([int(a) for a in f.all_coeffs()])
            return Recognition(v, _kind(f.degree(), v), h, ball.digits, need, limits.margin,
                               minimal_polynomial=f.as_expr())
    return None


def recognise(x: Any, limits: Limits = LIMITS) -> Recognition:
    """The exact number of smallest degree and height inside the ball ``x`` (a python-flint
    ``arb``), strong when the ball has :attr:`Limits.margin` digits beyond what the candidate needs;
    else the best weak candidate, or a recognition with ``value`` None (nothing within the limits).

    >>> recognise(flint.arb("[2.1213203435596425732 +/- 1e-19]")).text      # 3/√2
    '3*sqrt(2)/2'
    >>> recognise(flint.arb("[3.14159265358979323846 +/- 1e-20]")).strong     # π: nothing of small height
    False
    """
    ball = _used(x, limits)
    if ball.digits < 0.5:
        return _none(ball, limits)
    with time_limit(limits.seconds, LIMIT_OPTION), computing("recognising a ball"):
        return _search(ball, limits)


def _search(ball: Ball, limits: Limits) -> Recognition:
    found = [r for r in [_rational(ball, limits)] if r is not None]
    if not (found and found[0].strong):
        for k in range(2, limits.degree + 1):
            r = _algebraic(ball, k, limits)
            if r is not None:
                found.append(r)
                if r.strong:
                    break
    strong = [r for r in found if r.strong]
    if strong:
        return strong[0]
    return max(found, key=lambda r: r.digits - r.needed) if found else _none(ball, limits)


# ------------------------------------------------------------------ in a given field

def generator(r: Recognition) -> sp.Expr | None:
    """The generator θ of the field Q(θ) that a non-rational recognition shows: √d (d squarefree)
    for a quadratic, the number itself above (None for a rational).

    >>> with flint.ctx.workprec(200):
    ...     x = flint.arb("[0.78867513459481288225457439 +/- 5e-28]")
    >>> generator(recognise(x))
    sqrt(3)
    """
    if r.value is None or r.value.is_Rational:
        return None
    if r.kind == "quadratic":
        a, b, c = sp.Poly(r.minimal_polynomial, _X).all_coeffs()
        return sp.sqrt(sp.Integer(b * b - 4 * a * c)).as_coeff_Mul()[1]
    return r.value


@lru_cache(maxsize=64)
def _approximation(theta: sp.Expr, bits: int) -> Fraction:
    """θ within 2^−bits (the midpoint of a certified enclosure at that precision); one per field
    and precision, so the entries of a tableau share it."""
    lo, hi = _enclosure(theta, bits)
    return (lo + hi) / 2


@lru_cache(maxsize=64)
def field_degree(theta: sp.Expr) -> int:
    """The degree of Q(θ) over Q (of θ's minimal polynomial), for θ of degree ≤ :data:`PROBE_DEGREE`:
    the least d with a relation among 1, θ, …, θ^d found at :data:`PROBE_DIGITS` digits that needs at
    most half of them (exact algebraic numbers have relations of small height; chance at 600
    digits gives none needing fewer than 600).

    >>> field_degree(sp.sqrt(3)), field_degree(parse_entry("root(24*x**3 - 36*x**2 + 12*x - 1, 3)"))
    (2, 3)
    >>> field_degree(parse_entry("1/2 - sqrt(sqrt(30)/70 + 3/28)"))      # a node of Gauss 4
    4
    """
    if isinstance(theta, sp.CRootOf):
        return int(sp.Poly(theta.poly.as_expr(), theta.poly.gen).degree())
    return _degree_of(_approximation(theta, _PROBE_BITS), range(1, PROBE_DEGREE + 1))


def _degree_of(v: Fraction, degrees: Any) -> int:
    """The least d of ``degrees`` with a small relation among v⁰ … v^d at :data:`PROBE_DIGITS` digits."""
    probe = replace(LIMITS, digits=PROBE_DIGITS, height=10 ** PROBE_DIGITS)
    for d in degrees:
        with computing(f"the degree of a number (at most {d}?)"):
            c = relation([v ** i for i in range(d + 1)], PROBE_DIGITS, probe)
        if c is not None and c[-1] != 0 and _needed(c)[1] < PROBE_DIGITS / 2:
            return int(d)
    raise ValueError(f"a number of degree above {max(degrees)}")


def recognise_in(x: Any, theta: sp.Expr, limits: Limits = LIMITS) -> Recognition:
    """x as an element a₀ + a₁θ + … + a_{n−1}θⁿ⁻¹ of the field Q(θ) of degree n: an integer
    relation c·x + Σ bᵢθⁱ = 0 with c ≠ 0; its height and needed digits are those of this relation
    (n + 1 numbers), which are smaller than those of x's own minimal polynomial when the field is right.

    >>> g = parse_entry("root(24*x**3 - 36*x**2 + 12*x - 1, 3)")     # SDIRK34's γ
    >>> with flint.ctx.workprec(200):
    ...     x = flint.arb("[-3.2743160852065152256753359038 +/- 1e-28]")      # 1 − 4γ
    >>> r = recognise_in(x, g)
    >>> r.text, r.height, r.kind
    ('1 - 4*root(24*x**3 - 36*x**2 + 12*x - 1, 3)', 4, 'degree 3')
    """
    n = field_degree(theta)
    return recognise_in_basis(x, Basis((theta,), tuple((i,) for i in range(n)),
                                       tuple(_element((theta,), (i,)) for i in range(n))), limits)


class Basis(NamedTuple):
    """A basis over Q of the field Q(θ₁, …, θ_k): its ``elements`` (exact, normal form), each the
    product of the ``generators``' powers in ``exponents``."""
    generators: tuple[sp.Expr, ...]
    exponents: tuple[tuple[int, ...], ...]
    elements: tuple[sp.Expr, ...]

    def values(self, bits: int) -> list[Fraction]:
        """The elements as rationals within about 2^−bits (the generators' certified enclosures)."""
        approx = [_approximation(t, bits) for t in self.generators]
        out = []
        for e in self.exponents:
            v = Fraction(1)
            for a, k in zip(approx, e, strict=True):
                v *= a ** k
            out.append(v)
        return out


def _element(generators: tuple[sp.Expr, ...], e: tuple[int, ...]) -> sp.Expr:
    return _normal(sp.expand(sp.Mul(*(t ** k for t, k in zip(generators, e, strict=True)))))


def joint_basis(generators: tuple[sp.Expr, ...], limits: Limits = LIMITS) -> Basis | None:
    """A basis over Q of the field Q(θ₁, …, θ_k): the products θ₁^i₁ ⋯ θ_k^i_k (i_j below the degree
    of θ_j), lowest total degree first, each kept unless it is a rational combination of those kept
    (an integer relation found at :data:`PROBE_DIGITS` digits that needs at most half of them —
    a relation among exact numbers has small coefficients, chance gives none that small); None when
    the basis would pass ``limits.basis`` numbers.

    >>> joint_basis((sp.sqrt(2), sp.sqrt(3))).elements        # Q(√2, √3) has degree 4
    (1, sqrt(2), sqrt(3), sqrt(6))
    >>> joint_basis((sp.sqrt(3), sp.sqrt(12) + 1)).elements   # the same field twice: degree 2
    (1, sqrt(3))
    """
    from itertools import product
    degrees = [field_degree(t) for t in generators]
    exponents = sorted(product(*(range(n) for n in degrees)), key=lambda e: (sum(e), e[::-1]))
    every = Basis(generators, tuple(exponents), ())
    values = every.values(_PROBE_BITS)
    probe = replace(limits, digits=PROBE_DIGITS, height=10 ** PROBE_DIGITS)
    kept: list[tuple[int, ...]] = []
    kept_values: list[Fraction] = []
    for e, v in zip(exponents, values, strict=True):
        if kept:
            with computing(f"a basis of the field of {len(generators)} numbers"):
                c = relation([*kept_values, v], PROBE_DIGITS, probe)
            if c is not None and c[-1] != 0 and _needed(c)[1] < PROBE_DIGITS / 2:
                continue                               # v is a rational combination of the kept ones
        if len(kept) == limits.basis:
            return None
        kept.append(e)
        kept_values.append(v)
    return Basis(generators, tuple(kept), tuple(_element(generators, e) for e in kept))


def recognise_in_basis(x: Any, basis: Basis, limits: Limits = LIMITS) -> Recognition:
    """x as a rational combination of a basis of a field (its first element 1): an integer
    relation c·x + Σ bᵢ·basisᵢ = 0 with c ≠ 0; its height and needed digits are those of this
    relation (len(basis) + 1 numbers)."""
    ball = _used(x, limits)
    values = basis.values(int(min(ball.digits, limits.digits) * 3.33) + 2 * _GUARD_BITS)
    with computing(f"an integer relation of a ball in {field_text(basis.generators)}"):
        c = relation([ball.mid, *values], ball.digits, limits)
    if c is None or c[0] == 0 or not any(c[2:]):
        return _none(ball, limits)
    raw = sp.expand(-sum(b * e for b, e in zip(c[1:], basis.elements, strict=True)) / c[0])
    if not inside(raw, ball):
        return _none(ball, limits)
    value = _normal(raw)
    h, need = _needed(c)
    n = len(basis.elements)
    exact = basis.values(_PROBE_BITS)
    v = -sum((b * e for b, e in zip(c[1:], exact, strict=True)), Fraction(0)) / c[0]
    deg = _degree_of(v, [d for d in range(2, n + 1) if n % d == 0])      # its degree divides the field's
    return Recognition(value, _kind(deg, value), h, ball.digits, need, limits.margin, field=basis.generators)
