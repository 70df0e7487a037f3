r"""The A(α)-stability angle of methods whose characteristic polynomial has degree 1 in z — linear
multistep methods, one-stage GLMs — certified ([HW96] Hairer & Wanner, *Solving ODEs II*, §V.2,
Def. V.2.1 and the boundary locus; Table V.2.3 for BDF).

A method is A(α)-stable when the sector S_α = {z ≠ 0 : |arg(−z)| < α} lies in its stability region
(every root of P(w, z) in |w| < 1).  With P(w, z) = P₀(w) + z P₁(w) (P₀ = det(wI − V)), common
factors of P₀ and P₁ removed (roots that do not move with z), the boundary locus

    z(θ) = −p₀(e^{iθ}) / p₁(e^{iθ})

is the set of z with a root on the unit circle.  Let α₀ = inf_θ |arg(−z(θ))| (arg ∈ (−π, π]).  The
open sector S_α₀ misses the locus, is connected and contains z = −1, so every z in it has as
many roots in the open disc as z = −1 has; a root of P(w, −1) on or outside the circle leaves no
sector at all (for an explicit method no sector survives z → ∞: α₀ = 0).  Roots common to P₀ and
P₁ do not move with z; as in [HW96]'s stability domain (roots |w| ≤ 1, multiple roots |w| < 1)
they may lie on the circle when simple (inside the disc they are, by zero-stability).  Conversely any larger
sector holds a point of the locus and, the roots moving with z, unstable points next to it.  So,
for a zero-stable method (:mod:`zero_stability`; a method that is not has no A(α)) whose
P(w, −1) has all its moving roots in |w| < 1 (checked exactly, :func:`roots.disc_counts`),

    α = min(π/2, α₀).

*Certified.*  With e^{iθ} = (1 + it)/(1 − it), −z = A(t)/B(t) for the Cayley transforms A, B of
p₀, p₁ (θ = π is t = ∞), and arg(−z) = arg N(t), N = A·B̄ = X + iY with X, Y real polynomials
over the method's field K.  With G = gcd(X, Y) (its real roots are the points where z → 0 or
z → ∞, e.g. θ = 0), X̃ = X/G, Ỹ = Y/G, |arg(−z(t))| = |arg(sign G(t)·(X̃ + iỸ)(t))|.  The infimum is
attained among: the real roots of X̃Ỹ′ − X̃′Ỹ (stationary points of arg), the real roots of Ỹ
(where −z is real: the value is 0 or π exactly), the two one-sided limits at each real root of
G, and the limits t → ±∞.  Candidates where X̃ = 0 (the value is exactly π/2) are dropped (they
cannot push α below π/2).  The real roots are isolated exactly (:func:`roots.real_root_boxes`)
and |arg| is enclosed by interval arithmetic (mpmath ``iv``) on the isolating intervals, the
precision raised until the minimum is known to 30 digits and its side of π/2 is decided.

>>> from tableau_lab.exact.library import family
>>> [round(a_alpha(family("bdf", k=k)).degrees, 2) for k in (2, 3, 4, 5, 6)]
[90.0, 86.03, 73.35, 51.84, 17.84]
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import mpmath
import sympy as sp
from mpmath.ctx_iv import MPIntervalContext
from sympy import QQ
from sympy.polys.rings import ring

from ..exact.methods import Method
from ..exact.real_roots import (
    Field,
    Interval,
    RingPoly,
    box,
    cayley_transform,
    coefficients,
    disc_counts,
    lower,
    over_coefficient_field,
    poly_box,
    primitive_part,
    real_root_boxes,
    sign,
    upper,
)
from ..render.model import Document, Formula, Math, Paragraph, Plain, Typeset
from .results import Result
from .stability import characteristic_polynomial

__all__ = ["a_alpha", "AAlphaResult"]

_DIGITS = 30                         # the minimum is enclosed to this many digits (in radians)


@dataclass(frozen=True)
class AAlphaResult(Result):
    """The A(α) angle of one method (module docstring)."""

    method: str
    status: str                      # "computed", "none" (no sector), "not computed", "not applicable"
    reason: str
    degree: int | None = None        # degree of P(w, z) in z
    alpha: sp.Expr | None = None     # radians: 0, pi/2 exactly, or a Float with ≥ 30 digits
    enclosure: tuple = ()            # (lo, hi) of α in radians (mpmath mpf) when not exact
    theta: float | None = None       # |θ| in degrees where the minimum of |arg(−z(θ))| is attained
    where: str = ""                  # how the minimum is attained (stationary point, limit z → 0, …)
    z_at: complex | None = None      # z(θ) there (15 digits; None for a limit)
    locus: sp.Expr | None = None     # z(w) = −p₀(w)/p₁(w)
    conditions: tuple = field(default=())     # what was checked

    @property
    def degrees(self) -> float | None:
        return None if self.alpha is None else float(sp.deg(self.alpha).evalf(20))

    def degrees_text(self, digits: int = _DIGITS) -> str | None:
        if self.alpha is None:
            return None
        return str(sp.N(sp.deg(self.alpha), digits))

    def _lines(self) -> list[str]:
        """The plain face, a line each."""
        if self.status in ("not computed", "not applicable"):
            return [f"A(α): {self.status} ({self.reason})"]
        if self.status == "none":
            return [f"A(α): {'none' if self.alpha is None else 'no sector (α = 0)'} — {self.reason}"]
        a = self.degrees
        if self.alpha == sp.pi / 2:
            head = "A(α): α = 90° — the boundary locus does not enter the sector |arg(−z)| < 90°"
        else:
            head = f"A(α): α = {a:.2f}° (= {self.degrees_text(20)}°) — {self.where}"
        lines = [head]
        if self.locus is not None:
            lines.append(f"  boundary locus z(w) = {self.locus}, w = e^(iθ); checked: " + "; ".join(self.conditions))
        return lines

    def to_json(self):
        out = {"status": self.status, "reason": self.reason, "degree_in_z": self.degree,
               "alpha_degrees": self.degrees, "alpha_degrees_digits": self.degrees_text(),
               "alpha_radians": None if self.alpha is None else str(self.alpha if self.alpha.is_Rational or
                                                                    self.alpha == sp.pi / 2 else
                                                                    sp.N(self.alpha, _DIGITS)),
               "enclosure_radians": [mpmath.nstr(v, _DIGITS + 5) for v in self.enclosure],
               "theta_degrees": self.theta, "attained": self.where,
               "z_at_minimum": None if self.z_at is None else str(self.z_at),
               "boundary_locus": None if self.locus is None else str(self.locus),
               "conditions": list(self.conditions)}
        return out

    def display(self) -> Document:
        """The plain face: the lines above; the typeset face: the boundary locus and α in a sentence."""
        head, *lines = self._lines()
        plain = Plain(*map(Paragraph, lines))
        if self.status in ("not computed", "not applicable"):
            return Document(head, (plain, Typeset(Paragraph(Math(r"A(\alpha)"),
                                                            f": {self.status} ({self.reason.replace('|', '')})."))))
        if self.status == "none":
            return Document(head, (plain, Typeset(Paragraph("No sector ", Math(r"|\arg(-z)| < \alpha"), " with ",
                                                            Math(r"\alpha > 0"), " lies in the stability region."))))
        assert self.degrees is not None, "a computed angle"
        where = () if self.theta is None else (" (attained at ", Math(f"\\theta = {self.theta:.4f}^\\circ"), ")")
        locus = () if self.locus is None else (Formula(f"z(w) = {sp.latex(self.locus)}, \\quad w = e^{{i\\theta}}"),)
        return Document(head, (plain, Typeset(*locus, Paragraph(
            "The method is ", Math(r"A(\alpha)"), "-stable with ", Math(f"\\alpha = {self.degrees:.2f}^\\circ"),
            *where, "."))))


# ------------------------------------------------------------------ intervals

class _Undecided(Exception):
    """The working precision does not decide a sign: raise it."""


def _interval(a, b, ctx):
    return ctx.mpf([box(QQ, QQ(a.p, a.q), ctx).a, box(QQ, QQ(b.p, b.q), ctx).b])


def _sign(v) -> int:
    if lower(v) > 0:
        return 1
    if upper(v) < 0:
        return -1
    raise _Undecided


def _abs_arg(s, x, y, ctx):
    """|arg(s·(x + iy))| for a sign s and intervals x, y (not both containing 0)."""
    ay = abs(y)
    sx = x * s
    if _contains_zero(sx) and lower(ay) <= 0:
        raise _Undecided
    return ctx.atan2(ay, sx)


# ------------------------------------------------------------------ the locus

@dataclass
class _Locus:
    K: Field
    G: RingPoly          # gcd(X, Y) in K[t]
    X: RingPoly          # X̃, Ỹ: N/G = X̃ + iỸ
    Y: RingPoly
    A: tuple             # Cayley parts of p₀ (for telling z → 0 from z → ∞)


def _locus(p0, p1, K) -> _Locus:
    Rt = ring("t", K)[0]
    t = Rt.gens[0]
    n = max(p0.degree(), p1.degree())
    Ar, Ai = cayley_transform({k: (Rt(c), Rt.zero) for (k,), c in p0.terms()}, n, t)
    Br, Bi = cayley_transform({k: (Rt(c), Rt.zero) for (k,), c in p1.terms()}, n, t)
    X, Y = Ar * Br + Ai * Bi, Ai * Br - Ar * Bi
    G = X.gcd(Y) if Y else X.monic()
    return _Locus(K, G, X.exquo(G), Y.exquo(G) if Y else Rt.zero, (Ar, Ai))


def _sqf(p):
    return p.sqf_part() if p.degree() > 0 else p


def _without(q, *others):
    """q with the common factors with each of ``others`` removed (repeatedly)."""
    for o in others:
        if not o or o.degree() <= 0:
            continue
        g = q.gcd(o)
        while g.degree() > 0:
            q = q.exquo(g)
            g = q.gcd(g)
    return q


@dataclass
class _Candidate:
    value: Interval | sp.Expr    # an interval (radians), or an exact sympy value
    t: Any               # the point (rational mid of its box, or sp.oo)
    where: str


class _Boxes:
    """Interval values of polynomials over K at intervals of t, at ``bits`` + 64 bits; each
    polynomial's coefficient boxes computed once."""

    def __init__(self, K, bits: int):
        self.K = K
        self.ctx = MPIntervalContext()
        self.ctx.prec = bits + 64
        self._coeffs: dict[int, tuple[RingPoly, list[Interval]]] = {}   # id(p) -> (p kept alive, boxes)

    def at(self, p, iv):
        """p(iv) as an interval (0 for the zero polynomial)."""
        key = id(p)
        if key not in self._coeffs:
            self._coeffs[key] = (p, [box(self.K, c, self.ctx) for c in coefficients(p)])
        return poly_box(self._coeffs[key][1], iv, self.ctx) if p.degree() >= 0 and p else self.ctx.mpf(0)


def _limits_at_poles(L: _Locus, ev: _Boxes, bits: int) -> list:
    """The one-sided limits at the real roots of G (z → 0 or z → ∞)."""
    K, ctx, at = L.K, ev.ctx, ev.at
    t = L.X.ring.gens[0]
    Xt, Yt, G = L.X, L.Y, L.G
    a0 = L.A[0].gcd(L.A[1]) if L.A[1] else L.A[0]
    out = []
    for g, k in (G.sqf_list()[1] if G.degree() > 0 else []):
        other, dg = G.exquo(g ** k), g.diff(t)
        on_axis = g.gcd(Yt) if Yt else g           # there −z → 0 or ∞ along the real axis: |arg| = 0 or π
        for part, exact in ((_without(g, Xt, on_axis), False), (on_axis, True)):
            for a, b in real_root_boxes(part, K, bits):
                iv = _interval(a, b, ctx)
                so, sd = _sign(at(other, iv)), _sign(at(dg, iv))
                kind = "z → 0" if a0.degree() > 0 and _contains_zero(at(a0, iv)) else "z → ∞"
                for side, s in (("right", so * sd ** k), ("left", so * (-sd) ** k)):
                    where = f"the limit {kind} of the boundary locus ({side} of θ)"
                    if not exact:
                        out.append(_Candidate(_abs_arg(s, at(Xt, iv), at(Yt, iv), ctx), (a + b) / 2, where))
                    elif s * _sign(at(Xt, iv)) > 0:
                        out.append(_Candidate(sp.S.Zero, (a + b) / 2, where + " along the negative real axis"))
    return out


def _axis_crossings_and_stationary_points(L: _Locus, ev: _Boxes, bits: int) -> list[_Candidate]:
    """Where −z is real (|arg| = 0 or π exactly) and the stationary points of arg(−z)."""
    K, ctx, at = L.K, ev.ctx, ev.at
    t = L.X.ring.gens[0]
    Xt, Yt, G = L.X, L.Y, L.G
    out: list[_Candidate] = []
    if not Yt:
        return out
    for a, b in real_root_boxes(_without(_sqf(Yt), G), K, bits):
        iv = _interval(a, b, ctx)
        if _sign(at(G, iv)) * _sign(at(Xt, iv)) > 0:
            out.append(_Candidate(sp.S.Zero, (a + b) / 2, "the boundary locus crosses the negative real axis"))
    W = Xt * Yt.diff(t) - Xt.diff(t) * Yt
    if W:
        for a, b in real_root_boxes(_without(_sqf(W), G, Yt, Xt), K, bits):
            iv = _interval(a, b, ctx)
            out.append(_Candidate(_abs_arg(_sign(at(G, iv)), at(Xt, iv), at(Yt, iv), ctx), (a + b) / 2,
                                  "a stationary point of arg z(θ)"))
    return out


def _limits_at_infinity(L: _Locus, ev: _Boxes) -> list:
    """The limits t → ±∞ (θ = π, w = −1)."""
    K, ctx = L.K, ev.ctx
    Xt, Yt, G = L.X, L.Y, L.G
    d = max(Xt.degree(), Yt.degree() if Yt else -1)
    cx = Xt.LC if Xt.degree() == d else K.zero
    cy = Yt.LC if Yt and Yt.degree() == d else K.zero
    sG = sign(K, G.LC)
    out = []
    for s in (sG, sG * (-1) ** (G.degree() + d)):
        if K.is_zero(cx):
            continue                                    # |arg| = π/2 exactly
        if K.is_zero(cy):
            if s * sign(K, cx) > 0:
                out.append(_Candidate(sp.S.Zero, sp.oo, "the boundary locus crosses the negative real axis"))
            continue
        out.append(_Candidate(_abs_arg(s, box(K, cx, ctx), box(K, cy, ctx), ctx), sp.oo, "the limit θ → π"))
    return out


def _candidates(L: _Locus, bits: int) -> list:
    """Every candidate for the minimum of |arg(−z(t))| at this precision (raises _Undecided): the
    limits at the poles, the crossings of the real axis, the stationary points, the limits at ∞."""
    if not L.X:
        return []                                       # the locus lies on the imaginary axis: |arg| = π/2
    ev = _Boxes(L.K, bits)
    return (_limits_at_poles(L, ev, bits) + _axis_crossings_and_stationary_points(L, ev, bits)
            + _limits_at_infinity(L, ev))


def _contains_zero(v) -> bool:
    return lower(v) <= 0 <= upper(v)


def _minimum(L: _Locus):
    """(α as an exact value or a Float, enclosure, the candidate attaining it)."""
    for bits in (96, 192, 384, 768, 1536, 3072, 6144):
        try:
            cands = _candidates(L, bits)
        except _Undecided:
            continue
        exact = [c for c in cands if not hasattr(c.value, "a")]
        if exact:                                       # only exact zeros are kept
            return sp.S.Zero, (), exact[0]
        ctx = MPIntervalContext()
        ctx.prec = bits + 64
        half = (lower(ctx.pi / 2), upper(ctx.pi / 2))
        below = [c for c in cands if lower(c.value) < half[1]]
        if any(upper(c.value) >= half[0] for c in below):
            continue                                    # a candidate straddles π/2
        if not below:
            return sp.pi / 2, (), None
        best = min(below, key=lambda c: upper(c.value))
        lo, hi = min(lower(c.value) for c in below), upper(best.value)
        if hi - lo < mpmath.mpf(10) ** (-_DIGITS - 3):
            with mpmath.workdps(_DIGITS + 10):
                mid = (lo + hi) / 2
                return sp.Float(mpmath.nstr(mid, _DIGITS + 5), _DIGITS + 5), (lo, hi), best
    raise ArithmeticError("the A(α) angle was not certified at 6144 bits")


def _z_at(p0, p1, t0) -> complex | None:
    if t0 == sp.oo:
        w0 = -1
    else:
        t0 = complex(sp.N(t0, 20)).real
        w0 = (1 + 1j * t0) / (1 - 1j * t0)
    K = p0.ring.domain
    num = sum(complex(sp.N(K.to_sympy(c), 20)) * w0 ** k for (k,), c in p0.terms())
    den = sum(complex(sp.N(K.to_sympy(c), 20)) * w0 ** k for (k,), c in p1.terms())
    return None if abs(den) < 1e-300 else -num / den


def _theta(t0) -> float:
    return 180.0 if t0 == sp.oo else abs(float(2 * mpmath.atan(mpmath.mpf(sp.N(t0, 30)))) * 180 / float(mpmath.pi))


# ------------------------------------------------------------------ the analysis

def _sample_point(Pp, K):
    """(z_s, r, P(w, z_s)) for the first z_s of −1, −2, −1/2, … where P keeps its degree r in w."""
    w, z = Pp.ring.gens
    r = Pp.degree(w)
    lc = Pp.coeff_wrt(w, r).drop(w)
    for zs in (sp.Integer(-1), sp.Integer(-2), sp.Rational(-1, 2), sp.Integer(-3)):
        c = K.convert(QQ(zs.p, zs.q))
        if not K.is_zero(lc(c)):
            return zs, r, Pp.evaluate(z, c)
    raise AssertionError("the leading coefficient of P in w is at most linear in z")


def a_alpha(m: Method, zero=None, polynomial=None) -> AAlphaResult:
    """The A(α) angle (module docstring).  ``zero``: the method's ``zero_stability`` result and
    ``polynomial``: P(w, z) as a sympy expression, when already computed."""
    if m.kind == "prk":
        return AAlphaResult(method=m.name, status="not applicable",
                            reason="a partitioned method is analysed on the harmonic oscillator")
    if polynomial is not None:
        d = sp.Poly(polynomial, sp.Symbol("z")).degree() if polynomial.has(sp.Symbol("z")) else 0
        if d != 1:
            return AAlphaResult(method=m.name, status="not computed", degree=d, reason=f"P has degree {d} in z")
        if zero is not None and not zero.holds:
            return AAlphaResult(method=m.name, status="none", degree=1, reason="the method is not zero-stable")
    P, K = over_coefficient_field(*characteristic_polynomial(m))
    z = P.ring.gens[1]
    d = P.degree(z)
    Pp = primitive_part(P)
    if d != 1:
        return AAlphaResult(method=m.name, status="not computed", degree=d, reason=f"P has degree {d} in z")
    if Pp.degree(z) != 1:
        return AAlphaResult(method=m.name, status="not computed", degree=d,
                            reason="P(w, z) = c(z)·q(w): its roots do not move with z")
    if zero is None:
        from .zero_stability import zero_stability
        zero = zero_stability(m)
    conditions = ["zero-stable"]
    if not zero.holds:
        return AAlphaResult(method=m.name, status="none", degree=1, reason="the method is not zero-stable")
    P0, P1 = (Pp.coeff_wrt(z, k).drop(z) for k in (0, 1))
    g = P0.gcd(P1)
    p0, p1 = P0.exquo(g), P1.exquo(g)
    locus = sp.cancel(-p0.as_expr() / p1.as_expr())
    zs, _, Ps = _sample_point(Pp, K)
    moving = Ps.exquo(g)
    inside = disc_counts(moving, K)[0]
    fixed = "" if g.degree() <= 0 else " moving with z"
    conditions.append(f"every root{fixed} of P(w, {zs}) in |w| < 1")
    if inside != moving.degree():
        return AAlphaResult(method=m.name, status="none", degree=1, alpha=sp.S.Zero, locus=locus,
                            conditions=tuple(conditions),
                            reason=f"P(w, {zs}) has {moving.degree() - inside} root(s){fixed} with |w| ≥ 1, and "
                                   f"z = {zs} lies in every sector")
    if g.degree() > 0 and disc_counts(g, K)[1]:
        conditions.append("the roots that do not move with z (common to P(w, 0) and ∂P/∂z) on |w| = 1 simple")
        if disc_counts(g.gcd(g.diff(g.ring.gens[0])), K)[1]:
            return AAlphaResult(method=m.name, status="none", degree=1, alpha=sp.S.Zero, locus=locus,
                                conditions=tuple(conditions),
                                reason="a multiple root on |w| = 1 does not move with z")
    alpha, enclosure, best = _minimum(_locus(p0, p1, K))
    if alpha == 0:
        z0 = _z_at(p0, p1, best.t)
        where = f"{best.where} at θ = {_theta(best.t):.4f}°" + (f" (z = {z0.real:.6g})" if z0 is not None else "")
        return AAlphaResult(method=m.name, status="none", degree=1, alpha=alpha, locus=locus, theta=_theta(best.t),
                            where=where, reason=where, conditions=tuple(conditions))
    if best is None:
        return AAlphaResult(method=m.name, status="computed", degree=1, alpha=alpha, locus=locus,
                            reason="|arg(−z(θ))| ≥ 90° on the whole boundary locus", conditions=tuple(conditions))
    theta = _theta(best.t)
    z0 = _z_at(p0, p1, best.t) if "limit" not in best.where else None
    where = f"attained at θ = ±{theta:.4f}°, {best.where}" + (
        f", z(θ) = {z0.real:.6g} ± {abs(z0.imag):.6g}i" if z0 is not None else "")
    return AAlphaResult(method=m.name, status="computed", degree=1, alpha=alpha, enclosure=enclosure, theta=theta,
                        where=where, z_at=z0, locus=locus, reason=where, conditions=tuple(conditions))
