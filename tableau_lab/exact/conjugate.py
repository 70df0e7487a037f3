r"""Runge–Kutta methods whose nodes are all the roots of one polynomial, in exact rational
arithmetic (the Gauss, Radau and Lobatto families for any s).

The nodes c₁ < … < c_s of the s-stage Gauss method are the roots of the shifted Legendre
polynomial P; for s ≥ 6 they have no real radicals, and the field of all of them has degree up
to s!·… (48 for s = 6).  But the method does not need that field.  Its entries are values of
fixed rational polynomials at the nodes, aᵢⱼ = L(cᵢ, cⱼ), bⱼ = β(cⱼ), so A is *equivariant* and
the Vandermonde matrix Vⱼₘ = cⱼ^m (m = 0 … s−1) carries it to rational matrices:

    Ã = V⁻¹AV  (column m: the coefficients of Σⱼ L(X, cⱼ)cⱼ^m, a polynomial mod P),
    b̃ = bᵀV    (b̃ₘ = Σⱼ bⱼcⱼ^m),       V⁻¹1 = e₀,   V⁻¹c = e₁.

A stage vector (φ(c₁), …, φ(c_s)) is a polynomial φ mod P; the componentwise product of stage
vectors is the product mod P; A acts as Ã; bᵀ as the functional b̃.  So every elementary weight,
simplifying assumption, stability function (det(I − zA) = det(I − zÃ)) and the symplecticity
form (congruent by V: Vᵀ M V) is computed in ℚ, for any s.  For a collocation method with
nodes P (Gauss, Radau IIA, Lobatto IIIA, [HW96] IV.5) C(s) and B(s) give Ã and b̃ at once:
Ã X^m = X^{m+1}/(m+1) mod P, b̃ₘ = 1/(m+1).

>>> g = collocation(shifted_legendre(6))
>>> g.s, g.A_tilde[0], g.b_tilde[:3]
(6, (0, 0, 0, 0, 0, -1/5544), (1, 1/2, 1/3))
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import sympy as sp

__all__ = ["Conjugate", "collocation", "shifted_legendre", "radau_right", "radau_left", "lobatto_nodes", "ANY",
           "detect", "solve_conditions", "lagrange_at"]

X, Y = sp.symbols("X Y")
#: (off, diag) of :func:`detect`: L_ab(Y, X) per pair of node polynomials, L_a(Y) per node polynomial
Entries = tuple[dict[tuple[sp.Poly, sp.Poly], sp.Poly], dict[sp.Poly, sp.Poly]]


class _AnyZero:
    """The additive identity of every arithmetic (the start of sums of algebra elements and of
    rationals alike)."""

    def __add__(self, other: Any) -> Any:
        return other

    __radd__ = __add__


ANY = _AnyZero()


def shifted_legendre(s: int) -> sp.Poly:
    """P_s(2x − 1), monic: its roots are the Gauss nodes."""
    return sp.Poly(sp.legendre(s, 2 * X - 1), X).monic()


def radau_right(s: int) -> sp.Poly:
    """P_s(2x − 1) − P_{s−1}(2x − 1), monic: the Radau IIA nodes (c_s = 1)."""
    return sp.Poly(sp.legendre(s, 2 * X - 1) - sp.legendre(s - 1, 2 * X - 1), X).monic()


def lobatto_nodes(s: int) -> sp.Poly:
    """x(x − 1) P′_{s−1}(2x − 1), monic: the Lobatto nodes (c₁ = 0, c_s = 1), s ≥ 2."""
    return sp.Poly(X * (X - 1) * sp.diff(sp.legendre(s - 1, 2 * X - 1), X), X).monic()


@dataclass(frozen=True)
class Conjugate:
    """An RK method on the roots of ``P`` (monic, squarefree, real roots) as rational data:
    ``A_tilde`` (rows of Ã) and ``b_tilde`` (module docstring)."""

    P: sp.Poly
    A_tilde: tuple[tuple[sp.Rational, ...], ...]
    b_tilde: tuple[sp.Rational, ...]
    collocation: bool = False     # Ã is integration from 0 mod P and b̃ integration over [0, 1]

    @cached_property
    def s(self) -> int:
        return int(self.P.degree())

    # -- arithmetic in ℚ[X]/(P) (python-flint) ---------------------------------------------
    @cached_property
    def _flint(self) -> tuple[Any, Any, list[list[Any]], list[Any]]:
        import flint
        mod = flint.fmpq_poly([flint.fmpq(int(c.p), int(c.q)) for c in reversed(self.P.all_coeffs())])
        At = [[flint.fmpq(int(x.p), int(x.q)) for x in row] for row in self.A_tilde]
        bt = [flint.fmpq(int(x.p), int(x.q)) for x in self.b_tilde]
        return flint, mod, At, bt

    def element(self, coeffs: Iterable[Any]) -> _Elt:
        """A polynomial mod P from its coefficients (constant first; rationals)."""
        flint, mod, _, _ = self._flint
        return _Elt(flint.fmpq_poly([flint.fmpq(int(sp.Rational(c).p), int(sp.Rational(c).q)) for c in coeffs]) % mod,
                    self)

    def operators(self) -> tuple[_Elt, _Elt, _AOp, _BFun]:
        """(one, X, Ã as an operator, b̃ as a functional): ``Ã * φ`` is the polynomial of A applied
        to the stage vector φ, ``b̃ * φ`` the rational bᵀφ."""
        return self.element([1]), self.element([0, 1]), _AOp(self), _BFun(self)

    def is_zero(self, e: Any) -> bool:
        return bool(e.p.is_zero()) if isinstance(e, _Elt) else not e

    # -- the tableau as exact expressions ----------------------------------------------------
    @cached_property
    def nodes(self) -> list[sp.Expr]:
        """The roots of P, ascending: radicals where sympy finds real ones, else CRootOf."""
        roots = sp.roots(self.P, X)
        if sum(roots.values()) == self.s and not any(r.has(sp.I) for r in roots):
            return sorted((sp.radsimp(r) for r in roots), key=lambda r: float(r))
        return [sp.CRootOf(self.P.as_expr(), k) for k in range(self.s)]

    def _lagrange(self) -> list[sp.Poly]:
        """ℓ_m(X): the coefficient of t^m in P(t)/((t − X)P′(X)), as a polynomial in X mod P: the
        rows of V⁻¹ (V⁻¹)ₘⱼ = ℓ_m(cⱼ)."""
        t = sp.Symbol("t")
        P, s = self.P, self.s
        Pt = sp.Poly(P.as_expr().subs(X, t), t)
        quotient = sp.Poly(sp.div(Pt.as_expr(), t - X, t)[0], t)          # polynomial in t with coefficients in ℚ[X]
        inv = sp.Poly(sp.invert(P.diff(X).as_expr(), P.as_expr(), X), X)  # 1/P′(X) mod P
        out = []
        for m in range(s):
            coef = sp.Poly(quotient.as_expr(), t).coeff_monomial(t ** m)
            out.append(sp.Poly(sp.rem(sp.expand(coef * inv.as_expr()), P.as_expr(), X), X))
        return out

    @cached_property
    def polynomials(self) -> tuple[sp.Expr, sp.Expr]:
        """(L(Y, X), β(X)) with aᵢⱼ = L(cᵢ, cⱼ), bⱼ = β(cⱼ): L = Σₙₘ Yⁿ Ãₙₘ ℓₘ(X), β = Σₘ b̃ₘ ℓₘ(X)."""
        ell = self._lagrange()
        L = sp.expand(sum(Y ** n * self.A_tilde[n][m] * ell[m].as_expr()
                          for n in range(self.s) for m in range(self.s)))
        beta = sp.expand(sum(self.b_tilde[m] * ell[m].as_expr() for m in range(self.s)))
        return L, beta

    @cached_property
    def c_polynomial(self) -> sp.Expr:
        """The polynomial of c = A·1 (Ã e₀): X for a method with C(1), i.e. cᵢ the nodes."""
        return sp.expand(sum(self.A_tilde[n][0] * X ** n for n in range(self.s)))

    def abscissae(self) -> list[sp.Expr]:
        """c = A·1 at the nodes (the nodes themselves when Ã e₀ = X)."""
        if self.c_polynomial == X:
            return list(self.nodes)
        return [sp.expand(self.c_polynomial.subs(X, x)) for x in self.nodes]

    def tableau(self) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix, sp.ImmutableMatrix]:
        """(A, b, c) as exact sympy matrices with the nodes substituted (c = A·1)."""
        L, beta = self.polynomials
        c = self.nodes
        diag = sp.rem(sp.expand(L.subs(Y, X)), self.P.as_expr(), X)      # L(cᵢ, cᵢ), reduced mod P
        A = sp.ImmutableMatrix(self.s, self.s, lambda i, j: sp.expand(
            diag.subs(X, c[i]) if i == j else L.subs({Y: c[i], X: c[j]}, simultaneous=True)))
        b = sp.ImmutableMatrix([sp.expand(beta.subs(X, cj)) for cj in c])
        return A, b, sp.ImmutableMatrix(self.abscissae())

    # -- analyses in ℚ ----------------------------------------------------------------------
    def stability_matrices(self) -> tuple[sp.Matrix, sp.Matrix]:
        """(Ã, Ã − e₀b̃) as sympy matrices: det(I − zA) and det(I − z(A − 1bᵀ)) are theirs."""
        At = sp.Matrix(self.A_tilde)
        e0 = sp.zeros(self.s, 1)
        e0[0] = 1
        return At, At - e0 * sp.Matrix([list(self.b_tilde)])

    def symplecticity_form(self) -> sp.Matrix:
        """Vᵀ M V with M = diag(b)A + Aᵀdiag(b) − bbᵀ: entry (a, b) = b̃(Xᵃ·ÃX^b) + b̃(X^b·ÃXᵃ)
        − b̃(Xᵃ)b̃(X^b).  Congruent to M (V real, invertible): zero iff M is, same inertia."""
        one, x, A, b = self.operators()
        powers = [one]
        for _ in range(1, self.s):
            powers.append(powers[-1] * x)
        images = [A * p for p in powers]
        out = sp.zeros(self.s, self.s)
        for a in range(self.s):
            for c in range(self.s):
                v = b * (powers[a] * images[c]) + b * (powers[c] * images[a]) - (b * powers[a]) * (b * powers[c])
                out[a, c] = sp.Rational(int(v.p), int(v.q))
        return out


class _Elt:
    """A polynomial mod P (python-flint fmpq_poly)."""

    __slots__ = ("p", "alg")

    def __init__(self, p: Any, alg: Conjugate) -> None:
        self.p, self.alg = p, alg

    def __mul__(self, o: _Elt) -> _Elt:
        return _Elt((self.p * o.p) % self.alg._flint[1], self.alg)

    def __add__(self, o: _Elt | _AnyZero) -> _Elt:
        return self if isinstance(o, _AnyZero) else _Elt(self.p + o.p, self.alg)

    __radd__ = __add__

    def __sub__(self, o: _Elt) -> _Elt:
        return _Elt(self.p - o.p, self.alg)

    def __eq__(self, o: object) -> bool:
        return isinstance(o, _Elt) and self.p == o.p

    def __hash__(self) -> int:
        return hash(str(self.p))

    def coeffs(self) -> list[Any]:
        """The coefficients, constant first, padded to s."""
        c = list(self.p.coeffs())
        return c + [self.alg._flint[0].fmpq(0)] * (self.alg.s - len(c))


class _AOp:
    """Ã acting on a polynomial mod P (its coefficient vector)."""

    def __init__(self, alg: Conjugate) -> None:
        self.alg = alg

    def __mul__(self, e: _Elt) -> _Elt:
        flint, mod, At, _ = self.alg._flint
        if self.alg.collocation:                  # Ãφ = ∫₀^X φ mod P (C(s))
            return _Elt(e.p.integral() % mod, self.alg)
        v = e.coeffs()
        s = self.alg.s
        return _Elt(flint.fmpq_poly([sum((At[n][m] * v[m] for m in range(s)), flint.fmpq(0)) for n in range(s)]),
                    self.alg)


class _BFun:
    """b̃: the rational bᵀφ of a polynomial φ mod P."""

    def __init__(self, alg: Conjugate) -> None:
        self.alg = alg

    def __mul__(self, e: _Elt) -> Any:
        flint, _, _, bt = self.alg._flint
        if self.alg.collocation:                  # b̃(φ) = ∫₀¹ φ (B(s))
            return e.p.integral()(flint.fmpq(1))
        v = e.coeffs()
        return sum((bt[m] * v[m] for m in range(self.alg.s)), flint.fmpq(0))


def collocation(P: sp.Poly) -> Conjugate:
    """The collocation method on the roots of P (monic, squarefree): C(s) and B(s) define it,
    Ã X^m = X^{m+1}/(m+1) mod P, b̃ₘ = 1/(m+1) ([HW96] Thm IV.5.2)."""
    P = sp.Poly(P, X).monic()
    s = P.degree()
    if sp.gcd(P, P.diff(X)).degree() > 0:
        raise ValueError(f"{P.as_expr()} has a repeated root: not s distinct nodes")
    cols = []
    for m in range(s):
        r = sp.Poly(sp.rem(X ** (m + 1), P.as_expr(), X), X) * sp.Rational(1, m + 1)
        cols.append([r.coeff_monomial(X ** n) for n in range(s)])
    At = tuple(tuple(sp.Rational(cols[m][n]) for m in range(s)) for n in range(s))
    return Conjugate(P=P, A_tilde=At, b_tilde=tuple(sp.Rational(1, m + 1) for m in range(s)), collocation=True)


# ------------------------------------------------------------------ recognising such a method

def _power_sums(Q: sp.Poly, n: int) -> list[sp.Expr]:
    """pₖ = Σ rᵏ over the roots r of Q (with multiplicity), k = 0 … n, by Newton's identities."""
    a = [c / Q.LC() for c in Q.all_coeffs()]          # monic: X^d + a₁X^{d−1} + … + a_d
    d = Q.degree()
    p = [sp.Integer(d)]
    for k in range(1, n + 1):
        v = -k * a[k] if k <= d else sp.Integer(0)
        v -= sum(a[i] * p[k - i] for i in range(1, min(k, d + 1)))
        p.append(v)
    return p


def _trace(poly_x: sp.Poly, Q: sp.Poly, psums: list[sp.Expr]) -> sp.Expr:
    """Σ over the roots r of Q of poly_x(r) (poly_x: a Poly in X whose coefficients may hold Y)."""
    return sp.expand(sum(c * psums[k] for (k,), c in poly_x.terms()))


def _crt(residues: list[tuple[sp.Expr, sp.Poly]]) -> sp.Poly:
    """The polynomial mod Π Qₐ congruent to rₐ mod Qₐ for each (rₐ, Qₐ) (pairwise coprime)."""
    r, m = sp.Poly(0, Y), sp.Poly(1, Y)
    for ra, Qa in residues:
        ra, Qa = sp.Poly(ra, Y), sp.Poly(Qa.as_expr().subs(X, Y), Y)
        s_, t_, g = sp.gcdex(m, Qa)                     # s·m + t·Qa = 1
        r = (r + m * ((ra - r) * s_).rem(Qa)).rem(m * Qa)
        m = m * Qa
    return r


def detect(A: sp.Matrix, b: Sequence[sp.Expr], c: Sequence[sp.Expr]) -> Conjugate | None:
    """The :class:`Conjugate` form of the tableau (A, b, c) when its nodes are all the roots of a
    squarefree polynomial (rational nodes and complete sets of conjugate real roots, CRootOf)
    and its entries are the same polynomials of the nodes for every conjugate (aᵢⱼ = L(cᵢ, cⱼ),
    bⱼ = β(cⱼ), as a tableau written from :func:`collocation` is); else None.  Exact: the
    polynomials are read off the entries and compared, nothing is evaluated."""
    s = len(c)
    nodes = _node_factors(c)
    if nodes is None:
        return None
    factors, atom = nodes
    distinct = list(dict.fromkeys(factors))
    P = sp.Poly(sp.prod([Q.as_expr() for Q in distinct]), X)
    if P.degree() != s:
        return None
    beta = _weight_polynomials(b, factors, atom)
    entries = _entry_polynomials(A, factors, atom)
    if beta is None or entries is None:
        return None
    psums = {Q: _power_sums(Q, 2 * s + 2) for Q in distinct}
    # b̃ₘ = Σⱼ bⱼcⱼ^m = Σ over factors Tr(β_Q(X)X^m)
    b_tilde = tuple(sum(_trace((beta[Q] * sp.Poly(X ** m, X)).rem(Q), Q, psums[Q]) for Q in distinct)
                    for m in range(s))
    columns = [_column(m, s, distinct, entries, psums) for m in range(s)]
    A_tilde = tuple(tuple(sp.Rational(columns[m][n]) for m in range(s)) for n in range(s))
    return Conjugate(P=P.monic(), A_tilde=A_tilde, b_tilde=tuple(sp.Rational(x) for x in b_tilde))


def _node_factors(c: Sequence[sp.Expr]) -> tuple[list[sp.Poly], list[sp.Expr | None]] | None:
    """Per node, its monic minimal polynomial in X and its CRootOf atom (None for a rational node),
    when the nodes are complete sets of distinct conjugates; else None."""
    factors, atom = [], []
    for x in c:
        if x.is_Rational:
            Q, a = sp.Poly(X - x, X), None
        elif isinstance(x, sp.RootOf) and x.is_real:
            Q, a = sp.Poly(x.poly.as_expr().subs(x.poly.gen, X), X).monic(), x
        else:
            return None
        factors.append(Q)
        atom.append(a)
    for Q in dict.fromkeys(factors):
        roots = [a for F, a in zip(factors, atom, strict=True) if F == Q]
        if len(roots) != Q.degree() or len(set(roots)) != Q.degree():
            return None                                  # not every conjugate, or a repeated node
    return factors, atom


def _rational_poly(e: sp.Expr, subs: dict[Any, Any], gens: tuple[Any, ...]) -> sp.Poly | None:
    """The entry e, with the node atoms replaced by the generators, as a polynomial over ℚ, or None."""
    e = sp.expand(sp.sympify(e).xreplace(subs))
    try:
        p = sp.Poly(e, *gens)
    except sp.PolynomialError:
        return None
    return p if p.domain.is_QQ or p.domain.is_ZZ else None


def _weight_polynomials(b: Sequence[sp.Expr], factors: list[sp.Poly], atom: list[sp.Expr | None]
                        ) -> dict[sp.Poly, sp.Poly] | None:
    """β_Q(X) per node polynomial Q with bⱼ = β_Q(cⱼ), the same at every conjugate; else None."""
    beta: dict[sp.Poly, sp.Poly] = {}
    for j, Q in enumerate(factors):
        p = _rational_poly(b[j], {atom[j]: X} if atom[j] is not None else {}, (X,))
        if p is None or beta.setdefault(Q, p.rem(Q)) != p.rem(Q):
            return None                                  # not the same polynomial at every conjugate
    return beta


def _entry_polynomials(A: sp.Matrix, factors: list[sp.Poly], atom: list[sp.Expr | None]) -> Entries | None:
    """(off, diag): the off-diagonal aᵢⱼ = L_ab(cᵢ, cⱼ) (in Y, X) per pair of node polynomials and the
    diagonal aᵢᵢ = L_a(cᵢ) (in Y), compared over every pair; None when they differ between conjugates."""
    off: dict[tuple[sp.Poly, sp.Poly], sp.Poly] = {}
    diag: dict[sp.Poly, sp.Poly] = {}
    for i, Qa in enumerate(factors):
        Qa_y = Qa.as_expr().subs(X, Y)
        for j, Qb in enumerate(factors):
            sub = {}
            if atom[i] is not None:
                sub[atom[i]] = Y
            if atom[j] is not None and i != j:
                sub[atom[j]] = X
            p = _rational_poly(A[i, j], sub, (Y,) if i == j else (Y, X))
            if p is None:
                return None
            if i == j:
                p = p.rem(sp.Poly(Qa_y, Y))
                if diag.setdefault(Qa, p) != p:
                    return None
            else:
                p = sp.Poly(sp.rem(sp.rem(p.as_expr(), Qa_y, Y), Qb.as_expr(), X), Y, X)
                if off.setdefault((Qa, Qb), p) != p:
                    return None
    return off, diag


def _column(m: int, s: int, distinct: list[sp.Poly], entries: Entries, psums: dict[sp.Poly, list[sp.Expr]]
            ) -> list[sp.Expr]:
    """Column m of Ã: row i ↦ Σⱼ aᵢⱼcⱼ^m as a polynomial in cᵢ, per factor of cᵢ, then CRT."""
    off, diag = entries
    residues = []
    for Qa in distinct:
        Qa_y = Qa.as_expr().subs(X, Y)
        total = diag[Qa].as_expr() * Y ** m
        for Qb in distinct:
            if (Qa, Qb) not in off:
                continue                             # a factor of degree 1 paired with itself
            L = off[Qa, Qb]
            term = sp.Poly(sp.rem(sp.expand(L.as_expr() * X ** m), Qb.as_expr(), X), X)
            total += _trace(term, Qb, psums[Qb])
            if Qb == Qa:                             # the trace ran over cᵢ itself: not an off-diagonal term
                total -= L.as_expr().subs(X, Y) * Y ** m
        residues.append((sp.rem(sp.expand(total), Qa_y, Y), Qa))
    col = _crt(residues)
    return [col.coeff_monomial(Y ** n) for n in range(s)]


# ------------------------------------------------------------------ methods defined by conditions

def _coeffs(p: sp.Expr, P: sp.Poly) -> list[sp.Expr]:
    """The coefficients (constant first, length s) of the polynomial p mod P."""
    r = sp.Poly(sp.rem(sp.expand(p), P.as_expr(), X), X)
    return [r.coeff_monomial(X ** n) for n in range(P.degree())]


def lagrange_at(P: sp.Poly, node: sp.Expr) -> sp.Expr:
    """ℓ(X) = P(X)/((X − node)P′(node)) for a rational root ``node`` of P: the stage vector that is
    1 at that node and 0 at the others."""
    q = sp.quo(P.as_expr(), X - node, X)
    return sp.expand(q / q.subs(X, node))


def solve_conditions(P: Any, images: Iterable[tuple[sp.Expr, sp.Expr]] = (), D: int = 0, name: str = "") -> Conjugate:
    """The method on the roots of P with b̃ₘ = 1/(m+1) (B(s) at least) and Ã fixed by linear
    conditions in ℚ: ``images`` ((φ, ψ): Ãφ = ψ, polynomials in X) and D(1) … D(``D``)
    (b̃(X^{k−1}·Ãφ) = b̃(φ(1 − X^k))/k for φ = 1, X, …, X^{s−1}); the solution must be unique."""
    P = sp.Poly(P, X).monic()
    s = P.degree()
    bt = [sp.Rational(1, m + 1) for m in range(s)]
    unknowns = sp.symbols(f"a0:{s * s}")
    At = sp.Matrix(s, s, unknowns)                  # At[n, m]: coefficient of X^n in ÃX^m

    def apply(phi: sp.Expr) -> sp.Expr:          # Ãφ as a polynomial in X (linear in the unknowns)
        c = _coeffs(phi, P)
        return sum(At[n, m] * c[m] * X ** n for n in range(s) for m in range(s))

    def bfun(p: sp.Expr) -> sp.Expr:
        c = _coeffs(p, P)
        return sum(bt[m] * c[m] for m in range(s))

    eqs = []
    for phi, psi in images:
        eqs += [a - b for a, b in zip(_coeffs(apply(phi), P), _coeffs(psi, P), strict=False)]
    for k in range(1, D + 1):
        for m in range(s):
            eqs.append(bfun(X ** (k - 1) * apply(X ** m)) - bfun(X ** m * (1 - X ** k)) / k)
    sol = sp.linsolve([sp.expand(e) for e in eqs], unknowns)
    if not sol:
        raise ValueError(f"{name}: the conditions have no solution")
    values = next(iter(sol))
    if any(v.free_symbols for v in values):
        raise ValueError(f"{name}: the conditions do not fix the method")
    A_tilde = tuple(tuple(sp.Rational(values[n * s + m]) for m in range(s)) for n in range(s))
    return Conjugate(P=P, A_tilde=A_tilde, b_tilde=tuple(bt))


def radau_left(s: int) -> sp.Poly:
    """P_s(2x − 1) + P_{s−1}(2x − 1), monic: the Radau IA nodes (c₁ = 0)."""
    return sp.Poly(sp.legendre(s, 2 * X - 1) + sp.legendre(s - 1, 2 * X - 1), X).monic()
