"""Runge–Kutta families generated exactly for any number of stages: the collocation methods
Gauss–Legendre, Radau IIA and Lobatto IIIA ([HW96] §IV.5).

Each is built in ℚ on the roots of its node polynomial (:mod:`conjugate`: Ã, b̃ from C(s) and
B(s)); its tableau is written with the nodes as real radicals where they have them (Gauss
s ≤ 5, say) and as exact real roots (``CRootOf``, ``root(P, k)`` in a tableau file) otherwise.

>>> gauss(2).A
Matrix([
[            1/4, 1/4 - sqrt(3)/6],
[1/4 + sqrt(3)/6,             1/4]])
>>> str(gauss(6).c[0])
'CRootOf(924*X**6 - 2772*X**5 + 3150*X**4 - 1680*X**3 + 420*X**2 - 42*X + 1, 0)'
"""
from __future__ import annotations

from functools import lru_cache

import sympy as sp

from .conjugate import X, collocation, lagrange_at, lobatto_nodes, radau_left, radau_right, shifted_legendre, \
    solve_conditions
from .field import field_of, from_dm, to_dm
from .methods import RungeKutta

__all__ = ["gauss", "radau_ia", "radau_iia", "lobatto_iiia", "lobatto_iiib", "lobatto_iiic", "lobatto_iiic_star",
           "sdirk_crouzeix", "sdirk_alexander", "MAX_STAGES"]

#: the largest s generated: the order analysis of 8-stage Gauss checks 376 465 trees (order ≤ 16
#: and one of order 17) in about 14 s; each further stage multiplies that by about seven
MAX_STAGES = 8


def _method(P, name: str, source: str, alg=None) -> RungeKutta:
    alg = alg or collocation(P)
    A, b, c = alg.tableau()
    if not any(x.has(sp.RootOf) for x in c):      # radicals: the entries in the field's normal form
        K = field_of([c])
        A, b = from_dm(to_dm(A, K)), from_dm(to_dm(b, K))
    return RungeKutta(A=A, b=b, c=c, conjugate=alg, name=name, source=source)


@lru_cache(maxsize=None)          # immutable: built once per process
def gauss(s: int) -> RungeKutta:
    """The s-stage Gauss–Legendre method: nodes the roots of P_s(2x − 1); order 2s."""
    return _method(shifted_legendre(s), f"Gauss–Legendre, {s} stages",
                   "generated: collocation at the roots of P_s(2x-1) ([HW96] Table IV.5.13)")


@lru_cache(maxsize=None)          # immutable: built once per process
def radau_iia(s: int) -> RungeKutta:
    """The s-stage Radau IIA method: nodes the roots of P_s(2x − 1) − P_{s−1}(2x − 1) (c_s = 1);
    order 2s − 1."""
    return _method(radau_right(s), f"Radau IIA, {s} stages",
                   "generated: collocation at the roots of P_s(2x-1) - P_{s-1}(2x-1) ([HW96] Table IV.5.13)")


@lru_cache(maxsize=None)          # immutable: built once per process
def lobatto_iiia(s: int) -> RungeKutta:
    """The s-stage Lobatto IIIA method (s ≥ 2): nodes 0, 1 and the roots of P′_{s−1}(2x − 1);
    order 2s − 2."""
    if s < 2:
        raise ValueError(f"Lobatto methods have at least 2 stages, not {s}")
    return _method(lobatto_nodes(s), f"Lobatto IIIA, {s} stages",
                   "generated: collocation at 0, 1 and the roots of P'_{s-1}(2x-1) ([HW96] Table IV.5.13)")


@lru_cache(maxsize=None)
def radau_ia(s: int) -> RungeKutta:
    """The s-stage Radau IA method: nodes the roots of P_s(2x − 1) + P_{s−1}(2x − 1) (c₁ = 0), A
    from D(s); order 2s − 1 ([HW96] IV.5, Ehle 1969)."""
    P = radau_left(s)
    return _method(P, f"Radau IA, {s} stages", "generated: Radau left nodes, A from D(s) ([HW96] Table IV.5.13)",
                   solve_conditions(P, D=s, name=f"Radau IA, s = {s}"))


def _lobatto(s):
    if s < 2:
        raise ValueError(f"Lobatto methods have at least 2 stages, not {s}")
    return lobatto_nodes(s)


@lru_cache(maxsize=None)
def lobatto_iiib(s: int) -> RungeKutta:
    """The s-stage Lobatto IIIB method: Lobatto nodes, A from D(s); order 2s − 2."""
    P = _lobatto(s)
    return _method(P, f"Lobatto IIIB, {s} stages", "generated: Lobatto nodes, A from D(s) ([HW96] Table IV.5.13)",
                   solve_conditions(P, D=s, name=f"Lobatto IIIB, s = {s}"))


@lru_cache(maxsize=None)
def lobatto_iiic(s: int) -> RungeKutta:
    """The s-stage Lobatto IIIC method: Lobatto nodes, aᵢ₁ = b₁ for all i and C(s − 1); order
    2s − 2 ([HW96] IV.5, Chipman 1971)."""
    P = _lobatto(s)
    first = lagrange_at(P, 0)                         # the stage vector of node c₁ = 0
    b1 = sp.integrate(first, (X, 0, 1))
    images = [(first, b1)] + [(X ** m, X ** (m + 1) / (m + 1)) for m in range(s - 1)]
    return _method(P, f"Lobatto IIIC, {s} stages", "generated: Lobatto nodes, a_i1 = b_1, C(s-1) ([HW96] IV.5)",
                   solve_conditions(P, images, name=f"Lobatto IIIC, s = {s}"))


@lru_cache(maxsize=None)
def lobatto_iiic_star(s: int) -> RungeKutta:
    """The s-stage Lobatto IIIC* method: Lobatto nodes, aᵢₛ = 0 for all i and C(s − 1); order
    2s − 2 ([HLW06] II.2, Jay 1996)."""
    P = _lobatto(s)
    images = [(lagrange_at(P, 1), 0)] + [(X ** m, X ** (m + 1) / (m + 1)) for m in range(s - 1)]
    return _method(P, f"Lobatto IIIC*, {s} stages", "generated: Lobatto nodes, a_is = 0, C(s-1) ([HLW06] II.2)",
                   solve_conditions(P, images, name=f"Lobatto IIIC*, s = {s}"))


@lru_cache(maxsize=None)
def sdirk_crouzeix(s: int) -> RungeKutta:
    """The A-stable SDIRK methods of Crouzeix (1975) and Nørsett (1974) of order s + 1 ([HW96]
    §IV.6): s = 2, γ = 1/2 + √3/6, order 3; s = 3, γ = 1/2 + cos(π/18)/√3
    (the root > 1 of 24γ³ − 36γ² + 12γ − 1 = 0), order 4."""
    if s == 2:
        g = sp.Rational(1, 2) + sp.sqrt(3) / 6
        A, b = [[g, 0], [1 - 2 * g, g]], [sp.Rational(1, 2), sp.Rational(1, 2)]
    elif s == 3:
        g = sp.Rational(1, 2) + sp.cos(sp.pi / 18) / sp.sqrt(3)
        d = 1 / (6 * (2 * g - 1) ** 2)
        A, b = [[g, 0, 0], [sp.Rational(1, 2) - g, g, 0], [2 * g, 1 - 4 * g, g]], [d, 1 - 2 * d, d]
    else:
        raise ValueError(f"Crouzeix–Nørsett SDIRK methods are generated for s = 2, 3, not {s}")
    return RungeKutta.from_lists(A, b, name=f"SDIRK (Crouzeix–Nørsett), {s} stages, order {s + 1}",
                                 source="M. Crouzeix, thesis, Paris 1975; S. P. Nørsett 1974; [HW96] IV.6")


@lru_cache(maxsize=None)
def sdirk_alexander(s: int) -> RungeKutta:
    """Alexander's L-stable, stiffly accurate SDIRK methods of order s (SIAM J. Numer. Anal. 14
    (1977); [HW96] IV.6): s = 2, γ = 1 − √2/2; s = 3, γ the root of 6γ³ − 18γ² + 9γ − 1 = 0 in
    (1/6, 1/2) (≈ 0.4358665)."""
    if s == 2:
        g = 1 - sp.sqrt(2) / 2
        A, b = [[g, 0], [1 - g, g]], [1 - g, g]
    elif s == 3:
        x = sp.Symbol("x")
        g = next(r for r in sp.Poly(6 * x ** 3 - 18 * x ** 2 + 9 * x - 1, x).real_roots()
                 if sp.Rational(1, 6) < r < sp.Rational(1, 2))
        t2 = (1 + g) / 2
        b1 = -(6 * g ** 2 - 16 * g + 1) / 4
        b2 = (6 * g ** 2 - 20 * g + 5) / 4
        A, b = [[g, 0, 0], [t2 - g, g, 0], [b1, b2, g]], [b1, b2, g]
    else:
        raise ValueError(f"Alexander's SDIRK methods are generated for s = 2, 3, not {s}")
    return RungeKutta.from_lists(A, b, name=f"SDIRK (Alexander), {s} stages, order {s}, L-stable",
                                 source="R. Alexander, SIAM J. Numer. Anal. 14 (1977) 1006-1021; [HW96] IV.6")
