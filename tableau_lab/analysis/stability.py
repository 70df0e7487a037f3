r"""Linear stability of RK methods and GLMs, exactly ([HW96] Hairer & Wanner, *Solving ODEs II*,
§IV.3 and §IV.12; [B16] Butcher (2016) ch. 5; [BHHN14] Butcher, Habib, Hill & Norton, SIAM J.
Numer. Anal. 52 (2014)).  docs/stability.md has the formulas and the library table.

On y′ = λy, z = hλ, a GLM advances its r input values by the stability matrix

    M(z) = V + zB(I − zA)⁻¹U,

and its characteristic polynomial with the denominators cleared is the determinant of the block
matrix (Schur complement)

    P(w, z) = det [[I − zA, −U], [−zB, wI − V]] = det(I − zA) · det(wI − M(z)),

an exact polynomial in w and z over the method's number field (a ``DomainMatrix``
determinant over K[w, z], never eigenvalues of a symbolic matrix).  An RK method has r = 1
and P = w·D(z) − N(z) with D = det(I − zA), N = det(I − zA + z𝟙bᵀ), R = N/D.

*Imaginary axis.*  With z = iy (y real) the roots w are mapped to t by w = (1 + it)/(1 − it):
roots on the unit circle are the real t (w = −1 is t = ∞), roots inside are Im t > 0.  Writing
P((1 + it)/(1 − it), iy)·(1 − it)^r = F_R(t, y) + i F_I(t, y), every y at which a root can
enter, leave or move along the circle is a real root of one of: |lc_w P(·, iy)|², |P(−1, iy)|²,
the resultant in t of F_R/g and F_I/g, and the discriminant and leading coefficient in t of the
square-free part of g = gcd(F_R, F_I) (the curve of roots that stay on the circle, non-trivial for
symplectic methods).  Their product, normed down to ℚ[y], is isolated exactly; one rational
sample y between consecutive critical values is decided exactly: the number of roots on the
circle is the number of real roots of gcd(F_R, F_I)(t, y) (Sturm sequences; signs of algebraic
numbers certified by interval arithmetic), and the roots off the circle are counted inside by a
Cauchy index.  The results are two radii: Y₌ (every root has |w| = 1 for |y| < Y₌) and
Y≤ (every root has |w| ≤ 1 for |y| < Y≤), exact algebraic numbers or ∞.

*A-stability* (roots |w| ≤ 1 for Re z ≤ 0).  RK: the poles of R (after cancelling common
factors) lie in Re z > 0 (Routh–Hurwitz, exactly) and E(y) = |D(iy)|² − |N(iy)|² ≥ 0 for all
real y (square-free factors of odd multiplicity have no real roots) [HW96, Prop. IV.3.1 ff.].
GLMs: the leading coefficient of P in w has its roots in Re z > 0, the roots stay bounded as
z → ∞ (no coefficient of P has a higher degree in z than the leading one) and Y≤ = ∞; then the
largest |w|, subharmonic where the leading coefficient does not vanish (the log spectral radius
of an analytic companion matrix), is ≤ 1 on the whole half-plane by the maximum principle.  Each
failure is a certificate of the contrary, so the verdict is always decided.

A partitioned RK method acts on the harmonic oscillator q′ = ωp, p′ = −ωq (its two tableaux act
on different components, so y′ = λy does not apply): P(w, x) with x = hω real, and the same
axis analysis gives the x-interval of stability; A-stability does not apply.

>>> from tableau_lab.exact.tableau_json import load
>>> rk4 = stability(load("methods/rk4.json"))
>>> rk4.stability_function
z**4/24 + z**3/6 + z**2/2 + z + 1
>>> rk4.bounded_radius, rk4.a_stable
(2*sqrt(2), False)
>>> g2 = stability(load("methods/gauss2.json"))
>>> g2.a_stable, g2.unit_radius, g2.imaginary_interval
(True, oo, oo)
>>> lf = stability(load("methods/leapfrog.json"))
>>> lf.polynomial
w**2 - 2*w*z - 1
>>> lf.imaginary_interval, [(str(r.root), r.multiplicity) for r in lf.endpoint_roots]
(1, [('I', 2)])
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import reduce
from typing import Any

import sympy as sp
from sympy import QQ
from sympy.polys.matrices import DomainMatrix
from sympy.polys.rings import ring

from ..exact.field import field_of, to_dm
from ..exact.grammar import format_entry
from ..exact.methods import Method, PartitionedRungeKutta, RungeKutta
from ..exact.rationals import simplest_between
from ..exact.real_roots import (
    Field,
    Pair,
    RingPoly,
    all_in_upper_half,
    all_roots_right,
    cayley_transform,
    count_real_roots,
    degree,
    norm_to_rationals,
    over_coefficient_field,
    primitive_part,
    sign,
)
from ..render.model import Block, Document, Formula, Math, Paragraph, Plain, Typeset
from .results import Result

__all__ = ["stability", "StabilityResult", "EndpointRoot", "characteristic_polynomial", "stability_function",
           "e_polynomial", "W", "Z", "X", "Y"]

W, Z, X, Y = sp.symbols("w z x y")


# ------------------------------------------------------------------ the polynomials

def _dm_lists(K, *Ms):
    return [to_dm(sp.Matrix(M), K).to_list() for M in Ms]


def characteristic_polynomial(m: Method, parametric: bool = False):
    """(P, K): P(w, z) = det[[I − zA, −U], [−zB, wI − V]] as a ring element of K[w, z]; for a
    partitioned RK method P(w, x) on the harmonic oscillator with x = hω (a ring element of K[w, x]).
    A method with free parameters only with ``parametric`` (K is then their field of rational
    functions: :mod:`parametric_stability`; the numeric analyses here need numbers).

    >>> from tableau_lab.exact.tableau_json import load
    >>> P, K = characteristic_polynomial(load("methods/stormer_verlet.json"))
    >>> P.as_expr()
    w**2 + w*x**2 - 2*w + 1
    """
    if m.parameters and not parametric:
        raise ValueError(f"{m.name}: this stability analysis needs numbers for the free parameters "
                         f"{', '.join(map(str, m.parameters))}")
    if isinstance(m, PartitionedRungeKutta):
        K = field_of([m.A, m.b, m.Ahat, m.bhat])
        R = K["w", "x"]
        w, x = R.gens
        s = m.s
        A, Ah, b, bh = _dm_lists(K, m.A, m.Ahat, m.b.T, m.bhat.T)
        one, zero = R.one, R.zero
        rows = []
        for i in range(s):      # Q_i − x Σ a_ij P_j = q0
            rows.append([one if i == j else zero for j in range(s)] + [-x * A[i][j] for j in range(s)] + [-one, zero])
        for i in range(s):      # x Σ â_ij Q_j + P_i = p0
            rows.append([x * Ah[i][j] for j in range(s)] + [one if i == j else zero for j in range(s)] + [zero, -one])
        rows.append([zero] * s + [-x * b[0][j] for j in range(s)] + [w - 1, zero])
        rows.append([x * bh[0][j] for j in range(s)] + [zero] * s + [zero, w - 1])
        return DomainMatrix(rows, (len(rows), len(rows)), R).det(), K
    if getattr(m, "conjugate", None) is not None:        # r = 1: P(w, z) = w·det(I − zA) − det(I − zA + z𝟙bᵀ)
        N, D, K = stability_function(m)
        return K["w", "z"].from_sympy(W * D.as_expr() - N.as_expr()), K
    g = m.as_glm()
    K = field_of([g.A, g.U, g.B, g.V])
    R = K["w", "z"]
    w, z = R.gens
    A, U, B, V = _dm_lists(K, g.A, g.U, g.B, g.V)
    s, r = g.s, g.r
    rows = [[(R.one if i == j else R.zero) - z * A[i][j] for j in range(s)] + [-R.one * U[i][j] for j in range(r)]
            for i in range(s)]
    rows += [[-z * B[i][j] for j in range(s)] + [(w if i == j else R.zero) - V[i][j] for j in range(r)]
             for i in range(r)]
    return DomainMatrix(rows, (s + r, s + r), R).det(), K


def stability_function(m: Method):
    """(N, D, K) of an RK method: N = det(I − zA + z𝟙bᵀ), D = det(I − zA), ring elements of K[z].

    >>> from tableau_lab.exact.tableau_json import load
    >>> N, D, K = stability_function(load("methods/implicit_midpoint.json"))
    >>> N.as_expr(), D.as_expr()
    (z/2 + 1, 1 - z/2)
    """
    if not isinstance(m, RungeKutta):
        raise TypeError(f"the stability function R(z) is for RK methods, not {m.kind!r}")
    s = m.s
    if m.conjugate is not None:            # similar matrices in ℚ (exact.conjugate): V⁻¹AV = Ã, V⁻¹1bᵀV = e₀b̃
        K = QQ
        At, Nt = m.conjugate.stability_matrices()
        A, AmB = _dm_lists(K, At)[0], _dm_lists(K, Nt)[0]
    else:
        K = field_of([m.A, m.b])
        (A,), (b,) = _dm_lists(K, m.A), _dm_lists(K, m.b.T)
        AmB = [[A[i][j] - b[0][j] for j in range(s)] for i in range(s)]
    R = K["z"]
    z = R.gens[0]

    def det(M):
        rows = [[(R.one if i == j else R.zero) - z * M[i][j] for j in range(s)] for i in range(s)]
        return DomainMatrix(rows, (s, s), R).det()
    return det(AmB), det(A), K


# ------------------------------------------------------------------ the axis analysis

def _i_power(c, n, yn, zero):
    """c·(i·y)^n as a (real, imaginary) pair, given yn = y^n: i^n = 1, i, −1, −i."""
    term = yn * c
    return [(term, zero), (zero, term), (-term, zero), (zero, -term)][n % 4]


@dataclass
class _Axis:
    """P on the axis: F = F_R + i F_I in K[t, y] (roots w = (1 + it)/(1 − it)), r, and the
    leading coefficient and the value at w = −1 as (re, im) pairs in K[y]."""
    K: Field
    r: int
    FR: RingPoly
    FI: RingPoly
    lc: tuple
    at_minus_one: tuple


def _axis(P, K, imaginary: bool) -> _Axis:
    Rty = ring("t,y", K)[0]
    t, y = Rty.gens
    zero = Rty.zero
    w = P.ring.gens[0]
    r = P.degree(w)
    coeff: dict[int, Pair] = {}      # k -> Q_k(y) = coefficient of w^k at z = iy (or x = y)
    for (k, n), c in P.terms():          # c·w^k·z^n
        part = _i_power(c, n, y ** n, zero) if imaginary else (y ** n * c, zero)
        old = coeff.get(k, (zero, zero))
        coeff[k] = (old[0] + part[0], old[1] + part[1])
    FR, FI = cayley_transform(coeff, r, t)
    m1 = (zero, zero)
    for k, q in coeff.items():
        m1 = (m1[0] + (-1) ** k * q[0], m1[1] + (-1) ** k * q[1])
    return _Axis(K, r, FR, FI, coeff.get(r, (zero, zero)), m1)


def _drop_t(p):
    return p.drop(p.ring.gens[0])


class _FlintQQ:
    """The operations :func:`_critical_polynomials` needs, on python-flint ``fmpq_mpoly`` (ℚ[t, y]):
    the resultant of two degree-34 polynomials of NodePy's 17-step sand_cc4 takes 0.6 s here and
    126 s in sympy's dense subresultant sequence."""

    def __init__(self, R):
        import flint
        self.R = R
        self.ctx = flint.fmpq_mpoly_ctx.get(tuple(str(g) for g in R.symbols), "lex")
        self.fmpq = flint.fmpq

    def lift(self, p):
        return self.ctx.from_dict({m: self.fmpq(int(c.numerator), int(c.denominator)) for m, c in p.terms()})

    def drop(self, f):
        return self.R.from_dict({m: QQ(int(c.p), int(c.q)) for m, c in f.to_dict().items()})

    @staticmethod
    def is_zero(p):
        return p.is_zero()

    @staticmethod
    def cofactors(a, b):
        g = a.gcd(b)
        return g, a / g, b / g

    @staticmethod
    def degree_t(p):
        return -1 if p.is_zero() else p.degrees()[0]

    @staticmethod
    def sqf_part(p):
        return reduce(lambda x, y: x * y, [f for f, _ in p.factor_squarefree()[1]], p.context().from_dict({(0, 0): 1}))

    @staticmethod
    def coeff_t(p, k):
        return p.context().from_dict({(0, m[1]): c for m, c in p.to_dict().items() if m[0] == k})

    @staticmethod
    def discriminant(p):
        return p.discriminant("t")

    @staticmethod
    def resultant(a, b):
        return a.resultant(b, "t")


class _SympyOps:
    """The same operations on sympy ring elements of K[t, y] (K a number field)."""

    lift = drop = staticmethod(lambda p: p)

    @staticmethod
    def is_zero(p):
        return not p

    @staticmethod
    def cofactors(a, b):
        return a.cofactors(b)

    @staticmethod
    def degree_t(p):
        return p.degree(p.ring.gens[0])

    @staticmethod
    def sqf_part(p):
        return p.sqf_part()

    @staticmethod
    def coeff_t(p, k):
        return p.coeff_wrt(p.ring.gens[0], k)

    @staticmethod
    def discriminant(p):
        return p.discriminant()

    @staticmethod
    def resultant(a, b):
        return a.resultant(b)


def _critical_polynomials(ax: _Axis) -> list:
    """Polynomials in K[y] whose real roots contain every y where the configuration of the roots
    relative to the unit circle can change (see the module docstring); over ℚ computed with
    python-flint (:class:`_FlintQQ`), over a number field with sympy."""
    ops = _FlintQQ(ax.FR.ring) if ax.K.is_QQ else _SympyOps
    lc, m1 = (ops.lift(p) for p in (ax.lc[0] ** 2 + ax.lc[1] ** 2, ax.at_minus_one[0] ** 2 + ax.at_minus_one[1] ** 2))
    polys = [lc, m1]
    g, a, b = ops.cofactors(ops.lift(ax.FR), ops.lift(ax.FI))
    if ops.degree_t(g) > 0:
        gs = ops.sqf_part(g)
        polys += [ops.coeff_t(gs, ops.degree_t(gs)), ops.discriminant(gs)]
    if not ops.is_zero(a) and not ops.is_zero(b):
        da, db = ops.degree_t(a), ops.degree_t(b)
        if da > 0 and db > 0:
            polys.append(ops.resultant(a, b))
        elif da > 0 or db > 0:
            polys.append(a if da == 0 else b)
    out = []
    t = ax.FR.ring.gens[0]
    for p in polys:
        p = ops.drop(p)
        if p.ring.ngens == 2:
            if p.degree(t) > 0:
                raise AssertionError("critical polynomial still depends on t")
            p = _drop_t(p)
        if p.degree() > 0:
            out.append(p)
    return out


def _positive_roots(C: sp.Poly) -> list:
    """Disjoint rational isolating intervals (a, b), 0 ≤ a < b or a = b, of the positive roots of C."""
    low = min(m[0] for m in C.monoms())
    C = sp.Poly.from_dict({(m[0] - low,): c for m, c in C.terms()}, Y, domain=QQ)     # no root at 0
    if C.degree() <= 0:
        return []
    ivs = [(sp.Rational(a), sp.Rational(b)) for (a, b), _ in C.intervals(inf=0)]
    changed = True
    while changed:               # refine until each interval is off 0 and apart from the next
        changed = False
        for k, (a, b) in enumerate(ivs):
            touching = k + 1 < len(ivs) and b >= ivs[k + 1][0] and a != b
            if (a <= 0 < b) or touching:
                a2, b2 = C.refine_root(a, b, eps=(b - a) / 8)
                ivs[k] = (sp.Rational(a2), sp.Rational(b2))
                changed = True
    return ivs


def _sample(ax: _Axis, y0) -> tuple[bool, bool]:
    """(every root on the unit circle, every root in the closed unit disc) at the rational y0."""
    K = ax.K
    y = ax.FR.ring.gens[1]
    c = K.convert(QQ(y0.numerator, y0.denominator))
    fr, fi = ax.FR.evaluate(y, c), ax.FI.evaluate(y, c)
    n = max(degree(fr), degree(fi))
    h = fr.gcd(fi)
    real = count_real_roots(h, K)
    on = (ax.r - n) + real                      # w = −1 (t = ∞) and the real t
    if real < degree(h) and degree(h) > 0:          # a pair w, 1/w̄: one is outside
        return on == ax.r, False
    if degree(h) > 0:
        fr, fi = (f.exquo(h) if f else f for f in (fr, fi))
    return on == ax.r, all_in_upper_half(fr, fi, K)


def _root_value(C: sp.Poly, a, b):
    """The root of C in [a, b] exactly: radicals for degree ≤ 2 (also in y²), else CRootOf."""
    if a == b:
        return a
    for f, _ in sp.factor_list(C.as_expr(), Y)[1]:
        f = sp.Poly(f, Y)
        if f.count_roots(a, b) == 0:
            continue
        cands = []
        expr = f.as_expr()
        if f.degree() <= 2:
            cands = list(sp.roots(f, Y))
        elif f.degree() == 4 and all(m[0] % 2 == 0 for m in f.monoms()):
            u = sp.Symbol("u")
            cands = [sp.sqrt(v) for v in sp.roots(sp.Poly(expr.subs(Y ** 2, u), u), u)]
        for v in cands:
            v = sp.radsimp(sp.sqrtdenest(v))
            if v.is_real and a <= v.evalf(50) <= b:
                return v
        index = f.count_roots(None, a)
        return sp.CRootOf(f, index)
    raise AssertionError("no factor has the isolated root")


@dataclass(frozen=True)
class EndpointRoot:
    root: sp.Expr          # exact when found (factor of degree ≤ 2), else a 15-digit value
    multiplicity: int
    modulus: float


def _numeric_roots(mpmath, coeffs) -> list:
    """The roots of the polynomial with (mpmath) ``coeffs``, highest first, at the working
    precision: Durand–Kerner (``mpmath.polyroots``), and where that does not converge (a cluster of
    multiple roots slows it to a crawl: NodePy's 17-step sand_cc4 at its Y*) the eigenvalues of
    the companion matrix (QR iteration, ``mpmath.eig``), which converge for any multiplicity."""
    if len(coeffs) <= 1:
        return []
    try:
        return mpmath.polyroots(coeffs, maxsteps=200, extraprec=300)
    except mpmath.libmp.NoConvergence:
        n = len(coeffs) - 1
        C = mpmath.matrix(n, n)
        for j in range(n):
            C[0, j] = -coeffs[j + 1] / coeffs[0]
        for i in range(1, n):
            C[i, i - 1] = 1
        return list(mpmath.eig(C, left=False, right=False))


def _endpoint_roots(P, Ystar, imaginary) -> tuple:
    """The roots w of P(w, iY*) (or P(w, Y*)) with multiplicities: exact when Y* is a radical
    (square-free factors of degree ≤ 2 solved), else 40-digit values clustered into multiple roots."""
    if Ystar in (0, sp.oo):
        return ()
    if not Ystar.has(sp.CRootOf):
        zval = sp.I * Ystar if imaginary else Ystar
        poly = sp.Poly(sp.expand(P.as_expr().subs(P.ring.symbols[1], zval)), W, extension=True)
        out = []
        for f, mult in poly.sqf_list()[1]:
            found = list(sp.roots(f, W)) if f.degree() <= 2 else f.nroots(n=15)
            out += [EndpointRoot(sp.radsimp(v), mult, float(abs(complex(v.evalf(30))))) for v in found]
        return tuple(out)
    import mpmath
    K = P.ring.domain
    low = min(k for (k, _), _ in P.terms())          # w^low divides P: the root 0, exactly
    with mpmath.workdps(40):
        yv = mpmath.mpf(str(Ystar.evalf(45)))
        zv = mpmath.mpc(0, yv) if imaginary else yv
        coeffs = [mpmath.mpc(0)] * (P.degree(P.ring.gens[0]) + 1 - low)
        for (k, n), c in P.terms():      # c·w^k·z^n
            coeffs[-1 - (k - low)] += mpmath.mpf(str(sp.N(K.to_sympy(c), 45))) * zv ** n
        roots = _numeric_roots(mpmath, coeffs)
    groups = [[mpmath.mpc(0), low]] if low else []
    for v in roots:
        for g in groups:
            if abs(g[0] - v) < 1e-8:
                g[1] += 1
                break
        else:
            groups.append([v, 1])
    return tuple(EndpointRoot(sp.Float(complex(v).real, 15) + sp.I * sp.Float(complex(v).imag, 15), k,
                              float(abs(v))) for v, k in groups)


# ------------------------------------------------------------------ the result

def _text(x) -> str:
    x = sp.sympify(x)
    if x == sp.oo:
        return "inf"
    try:
        return str(format_entry(x))
    except Exception:  # CRootOf and complex values have no tableau-grammar form
        return str(x)


@dataclass(frozen=True)
class StabilityResult(Result):
    """Linear stability of one method (see the module docstring for the definitions)."""

    method: str
    kind: str
    variable: str                    # "z" (y' = λy, z = hλ) or "x" (harmonic oscillator, x = hω)
    polynomial: sp.Expr              # P(w, z) = det(I − zA) det(wI − M(z))
    r: int
    unit_radius: sp.Expr             # Y₌: every root |w| = 1 on |y| < Y₌ (sp.oo: whole axis)
    bounded_radius: sp.Expr          # Y≤: every root |w| ≤ 1 on |y| < Y≤
    symplectic: bool                 # (G-)symplectic: the reported interval is Y₌
    critical: tuple = ()             # positive critical values (floats; the radii are exact)
    samples: tuple = ()              # (y, all |w| = 1, all |w| ≤ 1) between them
    endpoint_roots: tuple = ()       # roots at y = Y* (reported radius)
    a_stable: bool | None = None
    a_reason: str = ""
    numerator: sp.Expr | None = None     # RK: N(z)
    denominator: sp.Expr | None = None   # RK: D(z)
    e_polynomial: sp.Expr | None = None  # RK: E(y) = |D(iy)|² − |N(iy)|²

    @property
    def imaginary_interval(self):
        """Y* of the reported kind: Y₌ for (G-)symplectic methods, else Y≤."""
        return self.unit_radius if self.symplectic else self.bounded_radius

    @property
    def interval_kind(self) -> str:
        return "|w| = 1" if self.symplectic else "|w| <= 1"

    @property
    def stability_function(self):
        if self.numerator is None:
            return None
        return sp.cancel(self.numerator / self.denominator)

    def _axis_name(self):
        return "z = iy" if self.variable == "z" else "x = hω (harmonic oscillator q' = ωp, p' = −ωq)"

    @property
    def _axis_letter(self):
        return "y" if self.variable == "z" else "x"

    def _lines(self) -> list[str]:
        """The plain face, a line each."""
        head = {"rk": "RK", "glm": "GLM", "prk": "partitioned RK"}[self.kind]
        lines = [f"linear stability ({head}, r = {self.r}):",
                 f"  P(w, {self.variable}) = {_text(self.polynomial)}"]
        if self.numerator is not None:
            lines.append(f"  R(z) = {_text(self.stability_function)}")
            lines.append(f"  E(y) = |D(iy)|² − |N(iy)|² = {_text(self.e_polynomial)}")
        av = {True: "yes", False: "no", None: "not applicable"}[self.a_stable]
        lines.append(f"  A-stable: {av}" + (f" — {self.a_reason}" if self.a_reason else ""))
        lines.append(f"  on the axis {self._axis_name()}:")
        for name, val in (("|w| = 1", self.unit_radius), ("|w| ≤ 1", self.bounded_radius)):
            a = self._axis_letter
            where = "the whole axis" if val == sp.oo else (f"{a} = 0 only" if val == 0 else
                                                           f"|{a}| < {_text(val)} ≈ {float(val):.15g}")
            lines.append(f"    every root {name}: {where}")
        lines.append(f"  reported interval ({self.interval_kind}"
                     f"{', the method is (G-)symplectic' if self.symplectic else ''}): "
                     f"{_text(self.imaginary_interval)}")
        if self.endpoint_roots:
            lines.append(f"  roots at the end {self._axis_letter} = Y*: " + ", ".join(
                f"w = {e.root} (|w| = {e.modulus:.15g}"
                f"{f', multiplicity {e.multiplicity}' if e.multiplicity > 1 else ''})"
                for e in self.endpoint_roots))
        return lines

    def to_json(self):
        Ystar = self.imaginary_interval
        out: dict[str, Any] = {
            "kind": self.kind,
            "variable": self.variable,
            "characteristic_polynomial": _text(self.polynomial),
            "a_stable": self.a_stable,
            "a_stability": self.a_reason,
            "imaginary_interval": _text(Ystar),
            "imaginary_interval_value": None if Ystar == sp.oo else float(Ystar),
            "imaginary_interval_kind": self.interval_kind,
            "unit_modulus_radius": _text(self.unit_radius),
            "bounded_radius": _text(self.bounded_radius),
            "critical_values": list(self.critical),
            "samples": [{"y": str(s), "all_on_unit_circle": e, "all_in_closed_disc": b} for s, e, b in self.samples],
            "endpoint_roots": [{"w": str(e.root), "multiplicity": e.multiplicity, "modulus": e.modulus}
                               for e in self.endpoint_roots],
            "stability_function": None,
            "E_polynomial": None,
        }
        if self.numerator is not None:
            out["stability_function"] = {"R": _text(self.stability_function), "N": _text(self.numerator),
                                         "D": _text(self.denominator)}
            out["E_polynomial"] = _text(self.e_polynomial)
        return out

    def display(self) -> Document:
        """The plain face: the lines above; the typeset face: P(w, z) (R(z) and E(y) for RK) and the
        reported interval in a sentence."""
        v, a = self.variable, self._axis_letter
        typeset: list[Block] = [Formula(f"P(w,{v}) = {sp.latex(self.polynomial)}")]
        if self.numerator is not None:
            typeset.append(Formula(f"R(z) = {sp.latex(self.stability_function)}, \\qquad "
                                   f"E(y) = {sp.latex(self.e_polynomial)}"))
        axis = (" (", Math("z = iy"), "). ") if v == "z" else (" (", Math(r"x = h\omega"), ", harmonic oscillator). ")
        verdict = {True: "The method is A-stable.", False: "The method is not A-stable.", None: ""}[self.a_stable]
        typeset.append(Paragraph("Every root has ", Math("|w| = 1" if self.symplectic else r"|w| \le 1"), " for ",
                                 Math(f"|{a}| < {sp.latex(self.imaginary_interval)}"), *axis, verdict))
        head, *lines = self._lines()
        return Document(head, (Plain(*map(Paragraph, lines)), Typeset(*typeset)))


# ------------------------------------------------------------------ the analyses

def _radii(ax: _Axis):
    """(Y₌, Y≤, critical values, samples) from the exact axis analysis."""
    crit = _critical_polynomials(ax)
    if crit:
        C = reduce(lambda a, b: a * b, [norm_to_rationals(p, ax.K) for p in crit])
        C = sp.Poly(sp.sqf_part(C.as_expr()), Y, domain=QQ)
        ivs = _positive_roots(C)
    else:
        C, ivs = None, []
    points = [(0, 0)] + ivs
    samples = []
    radii: list[tuple[Any, Any] | None] = [None, None]   # per test (|w| = 1, |w| ≤ 1): the first interval failing it
    for k, (a, b) in enumerate(points):
        hi = ivs[k][0] if k < len(ivs) else None
        y0 = simplest_between(b, hi, open_lo=True, open_hi=True)
        eq, le = _sample(ax, y0)
        samples.append((sp.Rational(y0.numerator, y0.denominator), eq, le))
        for i, ok in enumerate((eq, le)):
            if radii[i] is None and not ok:
                radii[i] = (a, b)
    values: dict[tuple[Any, Any], Any] = {}
    for iv_ in {r for r in radii if r is not None}:
        values[iv_] = 0 if iv_ == (0, 0) else _root_value(C, *iv_)
    Yeq, Yle = (sp.oo if r is None else values[r] for r in radii)
    return Yeq, Yle, tuple(_numeric_root(C, a, b) for a, b in ivs), tuple(samples)


def _numeric_root(C, a, b) -> float:
    if a != b:
        a, b = C.refine_root(a, b, eps=sp.Rational(1, 10 ** 18))
    return float((sp.Rational(a) + sp.Rational(b)) / 2)


def e_polynomial(N, D, K):
    """E(y) = |D(iy)|² − |N(iy)|² ∈ K[y] for R = N/D: |R(iy)| ≤ 1 exactly where E(y) ≥ 0 (over a
    field of parameters too, where its sign needs numbers)."""
    Ry = ring("y", K)[0]
    y = Ry.gens[0]

    def on_axis(p):
        re, im = Ry.zero, Ry.zero
        for (n,), c in p.terms():
            part = _i_power(c, n, y ** n, Ry.zero)
            re, im = re + part[0], im + part[1]
        return re * re + im * im
    return on_axis(D) - on_axis(N)


def _a_stability_rk(N, D, K):
    """RK: poles of R in Re z > 0 and E(y) = |D(iy)|² − |N(iy)|² ≥ 0 on the real line."""
    Dr = D.exquo(N.gcd(D))
    E = e_polynomial(N, D, K)
    if not all_roots_right(Dr, K):
        return False, "R(z) has a pole with Re z ≤ 0", E
    if not E:
        return True, "E(y) ≡ 0 (|R(iy)| = 1) and the poles of R lie in Re z > 0", E
    _, factors = E.sqf_list()
    odd = [f for f, m in factors if m % 2 and count_real_roots(f, K)]
    if odd or sign(K, E.LC) < 0:
        return False, "E(y) < 0 for some real y: |R(iy)| > 1 there", E
    return True, "E(y) ≥ 0 for all real y and the poles of R lie in Re z > 0", E


def _a_stability_glm(P, K, bounded_radius):
    """GLM: leading coefficient in w with roots in Re z > 0, bounded roots at z = ∞, Y≤ = ∞."""
    w, z = P.ring.gens
    r = P.degree(w)
    lc = P.coeff_wrt(w, r)
    lcz = lc.drop(w)
    if not all_roots_right(lcz, K):
        return False, "the leading coefficient of P in w vanishes at some z with Re z ≤ 0: a root w → ∞ there"
    if any(P.coeff_wrt(w, k).degree(z) > lc.degree(z) for k in range(r)):
        return False, "a coefficient of P has higher degree in z than the leading one: a root w → ∞ as z → −∞"
    if bounded_radius != sp.oo:
        return False, f"a root has |w| > 1 on the imaginary axis beyond |y| = {_text(bounded_radius)}"
    return True, ("|w| ≤ 1 on the whole imaginary axis, roots bounded at ∞ and no root at ∞ in Re z ≤ 0: "
                  "|w| ≤ 1 on Re z ≤ 0 by the maximum principle")


def _is_symplectic(m, gsym=None) -> bool:
    from .symplectic import g_symplectic, rk_symplectic
    if m.kind == "prk":
        return rk_symplectic(m).holds_separable
    return (gsym or g_symplectic(m)).holds


def stability(m: Method, gsym=None) -> StabilityResult:
    """The exact linear-stability analysis of an RK, partitioned RK or GL method (``tl.stability``,
    ``m.stability()``, ``tableau-lab stability``; ``gsym``: the method's ``g_symplectic`` result,
    when already computed): the characteristic polynomial P(w, z), R(z) for RK, A-stability, and
    the imaginary-axis radii Y₌ (every root |w| = 1) and Y≤ (every root |w| ≤ 1), exact
    algebraic numbers, decided by the certified axis analysis of the module docstring ([HW96]
    Hairer & Wanner, *Solving ODEs II*, §IV.3, §IV.12; [BHHN14] for G-symplectic GLMs).

    >>> import tableau_lab as tl
    >>> s = tl.stability(tl.load("rk4"))
    >>> s.bounded_radius, s.a_stable            # |R(iy)| ≤ 1 for |y| ≤ 2√2 ([HW96] IV.2)
    (2*sqrt(2), False)
    >>> tl.stability(tl.load("radau_iia:2")).a_stable
    True
    """
    P, K = over_coefficient_field(*characteristic_polynomial(m))
    imaginary = m.kind != "prk"
    Pp = primitive_part(P)
    Yeq, Yle, critical, samples = _radii(_axis(Pp, K, imaginary))
    symplectic = _is_symplectic(m, gsym)
    rk = {}
    if m.kind == "rk":
        N, D, KR = stability_function(m)
        a_stable, reason, E = _a_stability_rk(N, D, KR)
        rk = dict(numerator=N.as_expr(), denominator=D.as_expr(), e_polynomial=E.as_expr())
    elif m.kind == "glm":
        a_stable, reason = _a_stability_glm(Pp, K, Yle)
    else:
        a_stable = None
        reason = "A-stability is for y' = λy; a partitioned method is analysed on the harmonic oscillator"
    Ystar = Yeq if symplectic else Yle
    return StabilityResult(method=m.name, kind=m.kind, variable="z" if imaginary else "x", polynomial=P.as_expr(),
                           r=P.degree(P.ring.gens[0]), unit_radius=Yeq, bounded_radius=Yle, symplectic=symplectic,
                           critical=critical, samples=samples, endpoint_roots=_endpoint_roots(P, Ystar, imaginary),
                           a_stable=a_stable, a_reason=reason, **rk)
