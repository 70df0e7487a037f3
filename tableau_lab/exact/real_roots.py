r"""Signs and roots of polynomials over a real number field, certified: the exact-field toolbox of
the stability analyses (``analysis/stability.py``, ``zero_stability.py``, ``a_alpha.py``,
``parasitism.py``, ``ssp.py``, ``real_interval.py``, ``algebraic_stability.py``).  K is ℚ or a
real number field ℚ⟨α⟩ (``exact.field.field_of`` of real radicals, cos/sin(kπ/n), real roots of
polynomials); polynomials are sympy ring elements.

*Certified signs* (:func:`sign`).  An element of K is zero or not by its normal form; a non-zero
element is enclosed in an interval by interval arithmetic (:func:`enclose`, mpmath's
``MPIntervalContext``) at rising precision until the interval excludes 0: a certificate, never a
floating-point guess ([Moore66] R. E. Moore, *Interval Analysis*, 1966, ch. 3).

*Counting real roots* (:func:`cauchy_index`, :func:`count_real_roots`).  The Cauchy index of
p₁/p₀ over the real line is the difference of sign changes of the generalised Sturm chain
p₀, p₁, −rem(p₀, p₁), … at −∞ and +∞ (Sturm's theorem; [BPR06] Basu, Pollack & Roy, *Algorithms
in Real Algebraic Geometry*, Thm. 2.58); with p₁ = p₀′ it counts the distinct real roots, so
with a square-free factorisation the real roots with multiplicity.  Only leading coefficients'
signs are needed, each certified.

*Half-planes* (:func:`half_plane_counts`, :func:`all_roots_right`).  The roots of
f = f_R + i·f_I (f_R, f_I over K) above, on and below the real line follow from the argument
principle as a Cauchy index of f_I/f_R ([BPR06] §2.2.2; [HW96] Hairer & Wanner, *Solving ODEs
II*, §IV.3 for Routh–Hurwitz, Re z > 0 ⟺ Im t > 0 for z = −it).

*The Cayley transform* (:func:`cayley_transform`).  w = (1 + it)/(1 − it) sends the unit circle
to the real t-line (w = −1 to t = ∞) and the open unit disc to Im t > 0, so that counting roots
inside, on and outside the unit circle becomes counting them above, on and below the real line
([HW96] §V.1, the Schur–Cohn idea).

*Norms* (:func:`norm_to_rationals`).  The norm of p ∈ K[y] down to ℚ[y] (the resultant with the
minimal polynomial of α) has the roots of p among its roots; exact isolation over ℚ then
applies.

>>> from sympy import QQ
>>> from sympy.polys.rings import ring
>>> R, t = ring("t", QQ)
>>> count_real_roots((t**2 - 2) * (t**2 + 1) * (t - 1)**2, QQ)
4
>>> half_plane_counts(t**2 - 2, -2 * t, QQ)         # (t − i)² − 3: roots i ± √3, both above
(2, 0, 0)

*Where the roots lie relative to the unit circle* (used by zero-stability, A(α) and the
parasitism analysis).

*Counting* ([HW96] §V.1 and §IV.3 for the Schur–Cohn / Routh–Hurwitz idea).  The Cayley map
w = (1 + it)/(1 − it) sends the unit circle to the real t-line (w = −1 to t = ∞) and the open
unit disc to Im t > 0.  For p of degree n over a real field K,
F(t) = (1 − it)ⁿ p((1 + it)/(1 − it)) = F_R + i F_I has a root at t = ∞ of the multiplicity of
w = −1 (its degree drops by it), the real roots of gcd(F_R, F_I) are the other roots on the
circle, the non-real roots of that gcd are pairs w, 1/w̄ (one inside, one outside), and the rest
are counted above the real line by a Cauchy index (Sturm sequences over K, signs certified):
:func:`disc_counts` gives (inside, on, outside) with multiplicity, exactly.

*Self-reciprocal factors.*  An irreducible f over a real field with a root ζ on the circle also
has the root ζ̄ = 1/ζ, so f and its reciprocal wⁿf(1/w) share a root, hence agree up to sign:
only such factors can have roots on the circle (:func:`self_reciprocal`).

*Certified complex roots* (:func:`outside_roots`).  Approximations x from ``mpmath.polyroots``
are certified with the inclusion disc |x − ζ| ≤ n·|p(x)/p′(x)| for some root ζ (from
p′/p = Σⱼ 1/(x − ζⱼ)), evaluated in interval arithmetic; disjoint discs hold distinct roots, and
the exact count says when all of them are found.

*Certified real roots* (:func:`real_root_boxes`).  Over ℚ, sympy's exact isolation (continued
fractions); over K, the norm to ℚ[t] is isolated and its roots that are not roots of p are
discarded by interval evaluation, until as many remain as p has real roots (Sturm over K).

>>> from sympy import QQ
>>> from sympy.polys.rings import ring
>>> R, w = ring("w", QQ)
>>> disc_counts((w - 1) * (w + 1) * (2 * w - 1) * (w - 3), QQ)
(1, 2, 1)
>>> [str(d) for d in outside_roots(w**2 + w + 2, QQ, 2)]
['w ≈ -0.5 - 1.3228756555322953i (|w| = 1.41421356)', 'w ≈ -0.5 + 1.3228756555322953i (|w| = 1.41421356)']
"""
from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import reduce
from typing import Any, TypeAlias

import mpmath
import sympy as sp
from mpmath.ctx_iv import MPIntervalContext
from sympy import QQ
from sympy.polys.rings import ring

from .field import normal_form
from .subfield import subfield

__all__ = ["enclose", "sign", "sign_at", "rational_between", "last_good_cut", "degree", "cauchy_index",
           "count_real_roots", "half_plane_counts", "all_in_upper_half", "all_roots_right", "cayley_transform",
           "primitive_part", "over_coefficient_field", "norm_to_rationals", "coefficients", "disc_counts",
           "self_reciprocal", "exact_circle_roots", "unit_circle_eigenvalues", "RootDisc", "outside_roots",
           "real_root_boxes", "box", "poly_box", "lower", "upper", "complex_text", "Field", "Element", "RingPoly",
           "Interval", "Pair"]

_PRECISIONS = (64, 160, 400, 1000, 2500, 6000)      # bits tried by :func:`sign`, in turn

Field: TypeAlias = Any        # a sympy domain: QQ or a real algebraic field QQ<α> (``exact.field.field_of``)
Element: TypeAlias = Any      # an element of such a field
RingPoly: TypeAlias = Any     # an element of a sympy polynomial ring over it (``sympy.polys.rings.PolyElement``)
Interval: TypeAlias = Any     # an interval of mpmath's ``MPIntervalContext``
Pair: TypeAlias = tuple[RingPoly, RingPoly]     # (real part, imaginary part)


# ------------------------------------------------------------------ certified signs in a real field

def enclose(e: sp.Expr, ctx: Any) -> Interval:
    """An interval of the interval context ``ctx`` (mpmath ``MPIntervalContext``, at its working
    precision) enclosing the real algebraic sympy expression ``e``: rationals, sums, products,
    rational powers (radicals), cos(kπ/n), sin(kπ/n) and real ``CRootOf`` (certified by sympy's
    Sturm bisection).  Anything else raises ``ValueError``.

    >>> from mpmath.ctx_iv import MPIntervalContext
    >>> ctx = MPIntervalContext()
    >>> ctx.prec = 64
    >>> enclose(sp.sqrt(2) + sp.cos(sp.pi / 7), ctx)       # = 2.31518243027551417503779...
    mpi('2.31518243027551417481', '2.31518243027551417525')
    """
    if e.is_Rational:
        return ctx.mpf(int(e.p)) / ctx.mpf(int(e.q))
    if e.is_Add or e.is_Mul:
        parts = [enclose(a, ctx) for a in e.args]
        return reduce((lambda a, b: a + b) if e.is_Add else (lambda a, b: a * b), parts)
    if e.is_Pow and e.exp.is_Rational:
        base = enclose(e.base, ctx)
        if e.exp.is_Integer:
            n = int(e.exp)
            return base ** n if n >= 0 else 1 / base ** (-n)
        if e.exp == sp.S.Half:
            return ctx.sqrt(base)
        return ctx.exp(ctx.log(base) * ctx.mpf(int(e.exp.p)) / ctx.mpf(int(e.exp.q)))
    if isinstance(e, (sp.cos, sp.sin)) and sp.expand(e.args[0] / sp.pi).is_Rational:
        q = sp.expand(e.args[0] / sp.pi)
        angle = ctx.pi * ctx.mpf(int(q.p)) / ctx.mpf(int(q.q))
        return ctx.cos(angle) if isinstance(e, sp.cos) else ctx.sin(angle)
    if isinstance(e, sp.RootOf) and e.is_real:
        dx = sp.Rational(1, 2 ** (ctx.prec + 8))
        mid = e.eval_rational(dx=dx, dy=dx)          # certified: |mid − e| < dx (Sturm bisection)
        lo, hi = enclose(mid - dx, ctx), enclose(mid + dx, ctx)
        return ctx.mpf([lo.a, hi.b])
    raise ValueError(f"no certified enclosure for {e}")


def sign(K: Field, a: Element) -> int:
    """The sign of an element ``a`` of a real field K (ℚ or ℚ⟨α⟩ of real radicals): exact zero
    test, then interval arithmetic (:func:`enclose`) at rising precision until the enclosure
    excludes 0 (certified).

    >>> from tableau_lab.exact.field import field_of
    >>> K = field_of([sp.sqrt(2)])
    >>> sign(K, K.from_sympy(sp.sqrt(2) - sp.Rational(1414213562373095, 10**15)))
    1
    >>> sign(K, K.from_sympy(sp.sqrt(2) - sp.Rational(1414213562373096, 10**15)))
    -1
    """
    if K.is_zero(a):
        return 0
    if K.is_QQ or K.is_ZZ:
        return 1 if a > 0 else -1
    if not K.is_Algebraic:
        raise ValueError(f"signs need numeric entries, not elements of {K}")
    from mpmath.ctx_iv import MPIntervalContext
    e, ctx = K.to_sympy(a), MPIntervalContext()
    for prec in _PRECISIONS:
        ctx.prec = prec
        box = enclose(e, ctx)
        if box.a > 0:
            return 1
        if box.b < 0:
            return -1
    raise ArithmeticError(f"sign of {e} not decided at {_PRECISIONS[-1]} bits")


def sign_at(p: sp.Poly, x: Any, K: Field) -> int:
    """The certified sign of the univariate sympy Poly ``p`` over K at the rational ``x``
    (Horner in K, then :func:`sign`).

    >>> t = sp.Symbol("t")
    >>> [sign_at(sp.Poly(t**2 - 2, t, domain=QQ), x, QQ) for x in (1, sp.Rational(3, 2), 0)]
    [-1, 1, -1]
    """
    xk, acc = K.convert(sp.Rational(x)), K.zero
    for c in p.rep.to_list():
        acc = acc * xk + c
    return sign(K, acc)


def rational_between(a: sp.Expr, b: sp.Expr) -> sp.Rational:
    """A rational strictly between the real algebraic numbers a < b (compared exactly).

    >>> q = rational_between(sp.sqrt(2), sp.sqrt(3))
    >>> q.is_Rational and sp.sqrt(2) < q < sp.sqrt(3)
    True
    """
    q = (sp.Rational(sp.N(a, 60)) + sp.Rational(sp.N(b, 60))) / 2
    if not (a < q < b):
        raise ArithmeticError(f"no rational separated between {a} and {b}")
    return q


def last_good_cut(start: Any, cuts: Any, fails: Callable[[sp.Rational], Any],
                  step: int) -> tuple[Any, Any]:
    """Walking from ``start`` across ``cuts`` (exact real numbers, sorted in the walking direction,
    ``step`` = +1 rightwards, −1 leftwards), test each open interval between them at a rational
    point: the cut (or ``start``) where the first failing interval begins, with the probe's
    ``fails`` value, or (None, None) when no interval fails.  The conditions keep their sign
    between cuts, so one probe decides an interval.

    >>> last_good_cut(0, [1, sp.sqrt(2)], lambda x: "x² > 2" if x**2 > 2 else "", +1)
    (sqrt(2), 'x² > 2')
    >>> last_good_cut(0, [-1], lambda x: "", -1)
    (None, None)
    """
    prev = start
    for x in [*cuts, None]:
        if x is None:
            probe = sp.Rational(sp.N(prev, 30)) + step
        else:
            probe = rational_between(prev, x) if step > 0 else rational_between(x, prev)
        why = fails(probe)
        if why:
            return prev, why
        prev = x
    return None, None


# ------------------------------------------------------------------ Sturm sequences over K

def degree(p: RingPoly) -> int:
    """The degree of a univariate ring element, −1 for the zero polynomial.

    >>> R, t = ring("t", QQ)
    >>> degree(t**3 + 1), degree(R.one), degree(R.zero)
    (3, 0, -1)
    """
    return -1 if not p else int(p.degree())


def cauchy_index(p0: RingPoly, p1: RingPoly, K: Field) -> int:
    """Ind_{−∞}^{+∞} p₁/p₀ for univariate p₀ ≠ 0 and p₁ over K: the sign changes of the generalised
    Sturm chain at −∞ minus those at +∞ ([BPR06] Thm. 2.58); 0 for p₀ = 0.

    >>> R, t = ring("t", QQ)
    >>> cauchy_index(t**2 - 1, 2 * t, QQ), cauchy_index(t, -R.one, QQ)      # 2 real roots; 1/t jumps −∞ → +∞
    (2, -1)
    """
    if not p0:
        return 0
    chain = [p0, p1]
    while chain[-1]:
        chain.append(-chain[-2].rem(chain[-1]))
    chain.pop()

    def changes(at_minus: bool) -> int:
        signs = [sign(K, p.LC) * (-1 if at_minus and p.degree() % 2 else 1) for p in chain]
        signs = [s for s in signs if s]
        return sum(1 for a, b in zip(signs, signs[1:], strict=False) if a != b)
    return changes(True) - changes(False)


def count_real_roots(p: RingPoly, K: Field) -> int:
    """The number of real roots of a univariate p over K, with multiplicity (square-free
    factorisation, then Sturm on each factor: :func:`cauchy_index` of f′/f).

    >>> from tableau_lab.exact.field import field_of
    >>> K = field_of([sp.sqrt(2)])
    >>> R, t = ring("t", K)
    >>> count_real_roots((t - K.from_sympy(sp.sqrt(2)))**2 * (t**2 + 1), K)
    2
    """
    if degree(p) <= 0:
        return 0
    _, factors = p.sqf_list()
    return sum(m * cauchy_index(f, f.diff(f.ring.gens[0]), K) for f, m in factors)


def _upper_count(fr: RingPoly, fi: RingPoly, K: Field) -> int:
    """N₊, the number of roots with Im t > 0 of fr + i·fi (univariate over K, fr and fi coprime, so
    no real root): arg f grows by π(N₊ − N₋) along the real line, which is −π·Ind(fi/fr) when
    deg fi ≤ deg fr."""
    n = max(degree(fr), degree(fi))
    if n <= 0:
        return 0
    if degree(fi) > degree(fr):         # i·f has the same roots; now the ends of fi/fr are at 0, not ∞
        fr, fi = -fi, fr
    return (n - cauchy_index(fr, fi, K)) // 2


def half_plane_counts(fr: RingPoly, fi: RingPoly, K: Field) -> tuple[int, int, int]:
    """(N₊, N₀, N₋): the roots of fr + i·fi (univariate over K, not both zero) with Im t > 0, real,
    Im t < 0, with multiplicity.  The common factor h = gcd(fr, fi) holds the real roots and the
    conjugate pairs t, t̄ (one above, one below).

    >>> R, t = ring("t", QQ)
    >>> half_plane_counts((t**2 + 1) * (t - 3), R.zero, QQ)       # ±i and 3
    (1, 1, 1)
    """
    h = fr.gcd(fi)
    real = count_real_roots(h, K)
    pairs = (max(degree(h), 0) - real) // 2
    if degree(h) > 0:
        fr, fi = (f.exquo(h) if f else f for f in (fr, fi))
    up = _upper_count(fr, fi, K)
    return up + pairs, real, max(degree(fr), degree(fi), 0) - up + pairs


def all_in_upper_half(fr: RingPoly, fi: RingPoly, K: Field) -> bool:
    """Whether every root of fr + i·fi (univariate over K) has Im t > 0.

    >>> R, t = ring("t", QQ)
    >>> all_in_upper_half(t, -R.one, QQ), all_in_upper_half(t, R.one, QQ)      # t − i, t + i
    (True, False)
    """
    n = max(degree(fr), degree(fi))
    if n <= 0:
        return True
    if degree(fr.gcd(fi)) > 0:        # a real root, or a conjugate pair t, t̄ (one of them below)
        return False
    return _upper_count(fr, fi, K) == n


def all_roots_right(p: RingPoly, K: Field) -> bool:
    """Every root of the univariate p over K has Re z > 0 (Routh–Hurwitz, as a Cauchy index of
    p(−it) = fr + i·fi: Re z > 0 is Im t > 0; [HW96] §IV.3).

    >>> R, z = ring("z", QQ)
    >>> all_roots_right(1 - z/2 + z**2/12, QQ), all_roots_right(1 + z, QQ), all_roots_right(R.one, QQ)
    (True, False, True)
    """
    fr, fi = p.ring.zero, p.ring.zero
    t = p.ring.gens[0]
    for (k,), c in p.terms():
        term = t ** k * c                  # (−i)^k: 1, −i, −1, i
        if k % 2 == 0:
            fr += term if k % 4 == 0 else -term
        else:
            fi += -term if k % 4 == 1 else term
    return all_in_upper_half(fr, fi, K)


# ------------------------------------------------------------------ the Cayley transform

def _complex_mul(a: Pair, b: Pair) -> Pair:
    """(re, im) pairs multiplied."""
    return (a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0])


def cayley_transform(coeff: dict[int, Pair], n: int, t: RingPoly) -> Pair:
    """(F_R, F_I) with F_R + i·F_I = Σ_k q_k (1 + it)^k (1 − it)^(n−k) = (1 − it)^n Σ_k q_k w^k at
    w = (1 + it)/(1 − it), for ``coeff`` k ↦ q_k = (re, im), polynomials of the ring of ``t``: the
    unit circle in w is the real t-line (w = −1 is t = ∞), the open unit disc Im t > 0 ([HW96] §V.1).

    >>> R, t = ring("t", QQ)
    >>> cayley_transform({1: (R.one, R.zero), 0: (-R.one / 2, R.zero)}, 1, t)     # w − 1/2: t = −i/3
    (1/2, 3/2*t)
    """
    R = t.ring
    FR, FI = R.zero, R.zero
    for k, q in coeff.items():
        phi = (R.one, R.zero)
        for _ in range(k):
            phi = _complex_mul(phi, (R.one, t))
        for _ in range(n - k):
            phi = _complex_mul(phi, (R.one, -t))
        term = _complex_mul(q, phi)
        FR, FI = FR + term[0], FI + term[1]
    return FR, FI


# ------------------------------------------------------------------ fields and norms

def primitive_part(P: RingPoly) -> RingPoly:
    """P ∈ K[w, z] divided by its content in w, the gcd of its coefficients as a polynomial in w,
    when that content depends on z (for a characteristic polynomial, a factor of det(I − zA) alone).

    >>> R, w, z = ring("w,z", QQ)
    >>> primitive_part((1 - z) * (w**2 - z)).as_expr()
    -w**2 + z
    """
    w = P.ring.gens[0]
    content = reduce(lambda a, b: a.gcd(b), [P.coeff_wrt(w, k) for k in range(P.degree(w) + 1)])
    return P.exquo(content) if content.degree(P.ring.gens[1]) > 0 else P


def over_coefficient_field(P: RingPoly, K: Field) -> tuple[RingPoly, Field]:
    """(P, F) with F = ℚ(coefficients of P) ⊆ K (``exact.subfield``): ℚ when every coefficient is
    rational (often so for radical tableaux: Gauss, GLM43), ℚ(√265551) for GLM4S whose entries
    need degree 16.  The axis analysis costs a power of the field's degree (norms to ℚ).

    >>> from tableau_lab.exact.field import field_of
    >>> K = field_of([sp.sqrt(2)])
    >>> R, w = ring("w", K)
    >>> over_coefficient_field(w**2 - 2, K)[1]
    QQ
    """
    if K.is_QQ:
        return P, K
    F, coeffs = subfield(K, list(P.values()))
    if F is K:
        return P, K
    R = ring(",".join(map(str, P.ring.symbols)), F)[0]
    return R.from_dict(dict(zip(P.keys(), coeffs, strict=True))), F


def norm_to_rationals(p: RingPoly, K: Field) -> sp.Poly:
    """The norm of p ∈ K[y] down to ℚ[y] as a sympy Poly in y: the resultant in x of the minimal
    polynomial of K's generator and p with that generator replaced by x; its roots contain those
    of p.

    >>> from tableau_lab.exact.field import field_of
    >>> K = field_of([sp.sqrt(2)])
    >>> R, y = ring("y", K)
    >>> norm_to_rationals(y - K.from_sympy(sp.sqrt(2)), K).as_expr()
    y**2 - 2
    """
    Y = sp.Symbol("y")
    if K.is_QQ:
        return sp.Poly.from_dict({m: QQ.convert(c) for m, c in p.terms()}, Y, domain=QQ)
    Rxy, x, y = ring("x,y", QQ)
    lift = Rxy.zero
    for (k,), c in p.terms():
        coeffs = c.to_list()
        lift += sum((x ** (len(coeffs) - 1 - i) * QQ.convert(q) for i, q in enumerate(coeffs)), Rxy.zero) * y ** k
    mod_coeffs = K.mod.to_list()
    mod = sum((x ** (len(mod_coeffs) - 1 - i) * QQ.convert(q) for i, q in enumerate(mod_coeffs)), Rxy.zero)
    n = mod.resultant(lift)
    return sp.Poly.from_dict(dict(n.terms()), Y, domain=QQ)


# ------------------------------------------------------------------ coefficients

def coefficients(p: RingPoly) -> list[Element]:
    """The coefficients of a univariate ring element, highest degree first (none for 0).

    >>> R, w = ring("w", QQ)
    >>> coefficients(2 * w**2 - 1), coefficients(R.zero)
    ([2, 0, -1], [])
    """
    if not p:
        return []
    n = p.degree()
    c = dict(p.terms())
    zero = p.ring.domain.zero
    return [c.get((k,), zero) for k in range(n, -1, -1)]


# ------------------------------------------------------------------ exact counts

def disc_counts(p: RingPoly, K: Field) -> tuple[int, int, int]:
    """(inside, on, outside): the roots of the univariate p ≠ 0 over a real field K with |w| < 1,
    = 1, > 1, with multiplicity, exactly (Cayley map and Cauchy index, module docstring).

    >>> from tableau_lab.exact.field import field_of
    >>> K = field_of([sp.sqrt(2)])
    >>> R, w = ring("w", K)
    >>> disc_counts((w**2 - K.from_sympy(sp.sqrt(2)) * w + 1) * (w - 2), K)    # e^{±iπ/4} and 2
    (0, 2, 1)
    """
    n = p.degree()
    if n <= 0:
        return 0, 0, 0
    Rt = ring("t", K)[0]
    t = Rt.gens[0]
    FR, FI = cayley_transform({k: (Rt(c), Rt.zero) for (k,), c in p.terms()}, n, t)
    up, real, down = half_plane_counts(FR, FI, K)
    return up, real + n - (up + real + down), down


def self_reciprocal(coeffs: Iterable[Any]) -> bool:
    """Whether the coefficient list equals its reverse up to sign (wⁿf(1/w) = ±f): only such an
    irreducible factor can have a root on the unit circle (module docstring).

    >>> self_reciprocal([1, 1, 1]), self_reciprocal([1, 0, -1]), self_reciprocal([1, -3, 2])
    (True, True, False)
    """
    cs = list(coeffs)
    return bool(cs == cs[::-1] or cs == [-c for c in cs[::-1]])


def _on_unit_circle(z: sp.Expr) -> bool:
    return bool(normal_form(sp.expand(z * sp.conjugate(z))) == 1)


def exact_circle_roots(f: sp.Poly) -> list[sp.Expr] | None:
    """The roots of f on the unit circle by radicals (normal forms), or None when sympy finds
    fewer roots than the degree (no radicals).

    >>> w = sp.Symbol("w")
    >>> exact_circle_roots(sp.Poly(w**2 + w + 1, w))          # the primitive cube roots of unity
    [-1/2 - sqrt(3)*I/2, -1/2 + sqrt(3)*I/2]
    """
    roots = sp.roots(f, f.gen)
    if sum(roots.values()) != f.degree():
        return None
    return [z for z in (sp.radsimp(z) for z in roots) if _on_unit_circle(z)]


def unit_circle_eigenvalues(V: sp.MatrixBase) -> list[tuple[sp.Expr, int]]:
    """(ζ, algebraic multiplicity) for the eigenvalues ζ ≠ 1 of V with |ζ| = 1, exactly, without
    computing the others: the characteristic polynomial is factored over ℚ and only its
    self-reciprocal factors (rare: ±1, cyclotomic, Salem) are solved by radicals; the rest (BDF's
    ρ(w)/(w − 1), say, of degree up to 16) cost one factorisation.  V with irrational entries: all
    eigenvalues, as before.

    >>> unit_circle_eigenvalues(sp.Matrix([[1, 0, 0], [0, 0, -1], [0, 1, 0]]))     # 1 and ±i
    [(-I, 1), (I, 1)]
    """
    w = sp.Symbol("w")
    if not all(sp.sympify(v).is_Rational for v in V):
        found = []
        for zeta, mult in V.eigenvals().items():
            zeta = sp.nsimplify(zeta) if zeta.is_Rational else sp.radsimp(zeta)
            if normal_form(zeta - 1) != 0 and _on_unit_circle(zeta):
                found.append((zeta, mult))
        return found
    found = []
    for f, mult in sp.factor_list(V.charpoly(w).as_expr(), w)[1]:
        f = sp.Poly(f, w)
        if not self_reciprocal(f.all_coeffs()):
            continue                          # no root on the unit circle
        roots = exact_circle_roots(f)
        if roots is None:
            raise ValueError(f"V has eigenvalues on the unit circle that are roots of {f.as_expr()} "
                             "(no radicals): not supported")
        found += [(zeta, mult) for zeta in roots if normal_form(zeta - 1) != 0]
    return sorted(found, key=lambda z: sp.default_sort_key(z[0]))


# ------------------------------------------------------------------ interval evaluation

def box(K: Field, c: Element, ctx: Any) -> Interval:
    """An interval (of ``ctx``) enclosing the element c of the real field K (:func:`enclose`).

    >>> ctx = MPIntervalContext()
    >>> ctx.prec = 53
    >>> box(QQ, QQ(1, 3), ctx)
    mpi('0.33333333333333331', '0.33333333333333337')
    """
    if K.is_QQ or K.is_ZZ:
        c = QQ.convert(c)
        return ctx.mpf(int(c.numerator)) / ctx.mpf(int(c.denominator))
    return enclose(K.to_sympy(c), ctx)


def poly_box(coeffs: list[Interval], x: Interval, ctx: Any) -> Interval:
    """Horner's rule in interval arithmetic: p(x) for interval coefficients (highest first) and an
    interval (real or complex) x ([Moore66] ch. 3: an enclosure of the range).

    >>> ctx = MPIntervalContext()
    >>> poly_box([ctx.mpf(1), ctx.mpf(0), ctx.mpf(-2)], ctx.mpf([1, 2]), ctx)     # x² − 2 on [1, 2]
    mpi('-1.0', '2.0')
    """
    out = ctx.mpf(0)
    for c in coeffs:
        out = out * x + c
    return out


# ------------------------------------------------------------------ certified complex roots

@dataclass(frozen=True)
class RootDisc:
    """A root ζ of a polynomial certified by a disc |ζ − center| ≤ radius (:func:`outside_roots`)."""

    center: Any                # the approximation (mpmath mpf or mpc, at least 40 digits)
    radius: float              # an upper bound of |ζ − center|
    modulus: tuple[Any, Any]   # (lo, hi): an enclosure of |ζ| (mpmath mpf)

    @property
    def value(self) -> sp.Expr:
        """The root to 18 significant digits (as a sympy number)."""
        c = self.center
        re, im = (sp.Float(mpmath.nstr(v, 18), 18) for v in (c.real, c.imag))
        return re + sp.I * im if c.imag else re

    def __str__(self) -> str:
        return f"w ≈ {complex_text(self.center)} (|w| = {mpmath.nstr(self.modulus[0], 9)})"


def complex_text(c: Any) -> str:
    """x + yi to 18 digits.

    >>> complex_text(mpmath.mpc(0.5, -0.25)), complex_text(mpmath.mpf(2))
    ('0.5 - 0.25i', '2.0')
    """
    with mpmath.workdps(40):
        re, im = mpmath.nstr(c.real, 18), mpmath.nstr(abs(c.imag), 18)
    if not c.imag:
        return str(re)
    return f"{re} {'-' if c.imag < 0 else '+'} {im}i"


def _endpoint(raw: Any) -> Any:
    """A raw mpmath float (sign, mantissa, exponent, bits) as an mpf, exactly (no rounding to the
    global precision)."""
    with mpmath.workprec(max(raw[3], 1) + 10):
        return mpmath.mpf(raw)


def lower(v: Interval) -> Any:
    """The lower end of an interval of ``MPIntervalContext`` as an exact mpmath mpf (:func:`upper`: the
    upper end).

    >>> ctx = MPIntervalContext()
    >>> v = ctx.mpf([1, 2])
    >>> lower(v), upper(v)
    (mpf('1.0'), mpf('2.0'))
    """
    return _endpoint(v._mpi_[0])


def upper(v: Interval) -> Any:
    """The upper end of an interval as an exact mpmath mpf."""
    return _endpoint(v._mpi_[1])


def _point(ctx: Any, x: Any) -> Interval:
    """The complex number x (binary floating point, so exact) as a point interval."""
    return ctx.mpc(ctx.mpf(x.real), ctx.mpf(x.imag))


def outside_roots(p: RingPoly, K: Field, count: int) -> tuple[RootDisc, ...]:
    """The ``count`` roots of the square-free univariate p over a real field K with |w| > 1 (the
    exact count, from :func:`disc_counts`), each as a certified :class:`RootDisc`, largest first."""
    if count == 0:
        return ()
    cs = coefficients(p)
    n = len(cs) - 1
    ders = [c * (n - i) for i, c in enumerate(cs[:-1])]
    for dps in (40, 80, 160, 320, 640, 1280):
        with mpmath.workdps(dps):
            num = [mpmath.mpf(str(sp.N(K.to_sympy(c), dps + 10))) for c in cs]
            try:
                approx = mpmath.polyroots(num, maxsteps=100 + 20 * n, extraprec=2 * dps)
            except mpmath.NoConvergence:
                continue
        ctx = MPIntervalContext()
        ctx.prec = int(dps * 3.33) + 20
        P, D = [box(K, c, ctx) for c in cs], [box(K, c, ctx) for c in ders]
        found = []
        for x in approx:
            X = _point(ctx, x)            # x keeps the working precision of polyroots
            dp = abs(poly_box(D, X, ctx))
            if dp.a <= 0:
                continue
            rad = (n * abs(poly_box(P, X, ctx)) / dp).b        # a point interval: the upper end
            mod = abs(X)
            lo, hi = lower(mod - rad), upper(mod + rad)
            if lo > 1:
                found.append((x, rad, lo, hi))
        apart = all(lower(abs(_point(ctx, a[0]) - _point(ctx, b[0]))) > upper(a[1] + b[1])
                    for i, a in enumerate(found) for b in found[i + 1:])
        if len(found) == count and apart:
            found.sort(key=lambda f: (-f[2], f[0].imag))
            return tuple(RootDisc(center=x, radius=float(upper(rad)), modulus=(lo, hi))
                         for x, rad, lo, hi in found)
    raise ArithmeticError(f"the {count} roots of {p.as_expr()} outside the unit circle were not certified")


# ------------------------------------------------------------------ certified real roots

def real_root_boxes(p: RingPoly, K: Field, bits: int) -> list[tuple[sp.Rational, sp.Rational]]:
    """Disjoint rational intervals (a, b), b − a ≤ 2^−bits, each holding exactly one real root of
    the square-free univariate p over a real field K (a = b: an exact rational root), in order:
    over ℚ sympy's exact isolation, over K the isolated roots of the norm to ℚ that are roots of p.

    >>> from tableau_lab.exact.field import field_of
    >>> K = field_of([sp.sqrt(2)])
    >>> R, t = ring("t", K)
    >>> boxes = real_root_boxes(t**2 - K.from_sympy(sp.sqrt(2)), K, 4)        # ±2^(1/4) = ±1.1892...
    >>> boxes, all(a < r < b for (a, b), r in zip(boxes, (-2 ** 0.25, 2 ** 0.25), strict=True))
    ([(-6/5, -7/6), (7/6, 6/5)], True)
    """
    if p.degree() <= 0:
        return []
    eps = sp.Rational(1, 2 ** bits)
    if K.is_QQ:
        poly = sp.Poly.from_dict({m: QQ.convert(c) for m, c in p.terms()}, sp.Symbol("t"), domain=QQ)
        return [(sp.Rational(a), sp.Rational(b)) for (a, b), _ in poly.intervals(eps=eps)]
    target = count_real_roots(p, K)
    norm = norm_to_rationals(p, K)
    norm = sp.Poly(sp.sqf_part(norm.as_expr()), norm.gen, domain=QQ)
    cs = coefficients(p)
    for extra in range(0, 40 * 64, 64):
        ctx = MPIntervalContext()
        ctx.prec = bits + extra + 40
        P = [box(K, c, ctx) for c in cs]
        kept = []
        for (a, b), _ in norm.intervals(eps=eps / 2 ** extra):
            a, b = sp.Rational(a), sp.Rational(b)
            val = poly_box(P, ctx.mpf([box(QQ, QQ(a.p, a.q), ctx).a, box(QQ, QQ(b.p, b.q), ctx).b]), ctx)
            if val.a <= 0 <= val.b:
                kept.append((a, b))
        if len(kept) == target:
            return kept
    raise ArithmeticError(f"the real roots of {p.as_expr()} were not separated")
