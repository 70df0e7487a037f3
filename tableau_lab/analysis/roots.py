r"""Where the roots of a polynomial lie relative to the unit circle, exactly, and certified values
of the roots that cannot be exact (used by zero-stability, A(α) and the parasitism analysis).

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

from dataclasses import dataclass

import mpmath
import sympy as sp
from mpmath.ctx_iv import MPIntervalContext
from sympy import QQ
from sympy.polys.rings import ring

from ..exact.field import normal_form
from ..exact.real_roots import cayley_transform, count_real_roots, enclose, half_plane_counts, norm_to_rationals

__all__ = ["disc_counts", "self_reciprocal", "exact_circle_roots", "unit_circle_eigenvalues", "RootDisc",
           "outside_roots", "real_root_boxes", "box", "poly_box", "lower", "upper", "coefficients", "complex_text"]


def coefficients(p) -> list:
    """The coefficients of a univariate ring element, highest degree first (none for 0)."""
    if not p:
        return []
    n = p.degree()
    c = dict(p.terms())
    zero = p.ring.domain.zero
    return [c.get((k,), zero) for k in range(n, -1, -1)]


# ------------------------------------------------------------------ exact counts

def disc_counts(p, K) -> tuple[int, int, int]:
    """(inside, on, outside): the roots of the univariate p ≠ 0 over a real field K with |w| < 1,
    = 1, > 1, with multiplicity, exactly (Cayley map and Cauchy index, module docstring)."""
    n = p.degree()
    if n <= 0:
        return 0, 0, 0
    Rt = ring("t", K)[0]
    t = Rt.gens[0]
    FR, FI = cayley_transform({k: (Rt(c), Rt.zero) for (k,), c in p.terms()}, n, t)
    up, real, down = half_plane_counts(FR, FI, K)
    return up, real + n - (up + real + down), down


def self_reciprocal(coeffs) -> bool:
    """Whether the coefficient list equals its reverse up to sign (wⁿf(1/w) = ±f)."""
    coeffs = list(coeffs)
    return coeffs == coeffs[::-1] or coeffs == [-c for c in coeffs[::-1]]


def _on_unit_circle(z) -> bool:
    return normal_form(sp.expand(z * sp.conjugate(z))) == 1


def exact_circle_roots(f: sp.Poly) -> list | None:
    """The roots of f on the unit circle by radicals (normal forms), or None when sympy finds
    fewer roots than the degree (no radicals)."""
    roots = sp.roots(f, f.gen)
    if sum(roots.values()) != f.degree():
        return None
    return [z for z in (sp.radsimp(z) for z in roots) if _on_unit_circle(z)]


def unit_circle_eigenvalues(V) -> list:
    """(ζ, algebraic multiplicity) for the eigenvalues ζ ≠ 1 of V with |ζ| = 1, exactly, without
    computing the others: the characteristic polynomial is factored over ℚ and only its
    self-reciprocal factors (rare: ±1, cyclotomic, Salem) are solved by radicals; the rest (BDF's
    ρ(w)/(w − 1), say, of degree up to 16) cost one factorisation.  V with irrational entries: all
    eigenvalues, as before."""
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

def box(K, c, ctx):
    """An interval (of ``ctx``) enclosing the element c of the real field K."""
    if K.is_QQ or K.is_ZZ:
        c = QQ.convert(c)
        return ctx.mpf(int(c.numerator)) / ctx.mpf(int(c.denominator))
    return enclose(K.to_sympy(c), ctx)


def poly_box(coeffs, x, ctx):
    """Horner's rule in interval arithmetic: p(x) for interval coefficients (highest first) and an
    interval (real or complex) x."""
    out = ctx.mpf(0)
    for c in coeffs:
        out = out * x + c
    return out


# ------------------------------------------------------------------ certified complex roots

@dataclass(frozen=True)
class RootDisc:
    """A root ζ of a polynomial certified by a disc |ζ − center| ≤ radius."""

    center: object             # the approximation (mpmath mpf or mpc, at least 40 digits)
    radius: float              # an upper bound of |ζ − center|
    modulus: tuple             # (lo, hi): an enclosure of |ζ| (mpmath mpf)

    @property
    def value(self) -> sp.Expr:
        """The root to 18 significant digits (as a sympy number)."""
        c = self.center
        re, im = (sp.Float(mpmath.nstr(v, 18), 18) for v in (c.real, c.imag))
        return re + sp.I * im if c.imag else re

    def __str__(self):
        return f"w ≈ {complex_text(self.center)} (|w| = {mpmath.nstr(self.modulus[0], 9)})"


def complex_text(c) -> str:
    """x + yi to 18 digits."""
    with mpmath.workdps(40):
        re, im = mpmath.nstr(c.real, 18), mpmath.nstr(abs(c.imag), 18)
    if not c.imag:
        return re
    return f"{re} {'-' if c.imag < 0 else '+'} {im}i"


def _endpoint(raw):
    """A raw mpmath float (sign, mantissa, exponent, bits) as an mpf, exactly (no rounding to the
    global precision)."""
    with mpmath.workprec(max(raw[3], 1) + 10):
        return mpmath.mpf(raw)


def lower(v):
    """The lower end of an interval of ``MPIntervalContext`` as an exact mpmath mpf."""
    return _endpoint(v._mpi_[0])


def upper(v):
    """The upper end of an interval as an exact mpmath mpf."""
    return _endpoint(v._mpi_[1])


def _point(ctx, x):
    """The complex number x (binary floating point, so exact) as a point interval."""
    return ctx.mpc(ctx.mpf(x.real), ctx.mpf(x.imag))


def outside_roots(p, K, count: int) -> tuple:
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

def real_root_boxes(p, K, bits: int) -> list:
    """Disjoint rational intervals (a, b), b − a ≤ 2^−bits, each holding exactly one real root of
    the square-free univariate p over a real field K (a = b: an exact rational root), in order."""
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
