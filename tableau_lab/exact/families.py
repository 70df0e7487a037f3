"""Runge–Kutta families generated exactly for any number of stages: the collocation methods
Gauss–Legendre, Radau IIA and Lobatto IIIA ([HW96] §IV.5), their relatives, and the explicit
strong-stability-preserving (SSP) methods in their Shu–Osher form ([GKS11] Gottlieb, Ketcheson &
Shu, *Strong Stability Preserving Runge–Kutta and Multistep Time Discretizations*, 2011).

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
from typing import Any

import sympy as sp

from .conjugate import (
    Conjugate,
    X,
    collocation,
    lagrange_at,
    lobatto_nodes,
    radau_left,
    radau_right,
    shifted_legendre,
    solve_conditions,
)
from .field import field_of, from_dm, to_dm
from .methods import RungeKutta

__all__ = ["gauss", "radau_ia", "radau_iia", "lobatto_iiia", "lobatto_iiib", "lobatto_iiic", "lobatto_iiic_star",
           "sdirk_crouzeix", "sdirk_alexander", "MAX_STAGES", "shu_osher", "ssprk", "ssprk2", "ssprk3", "ssprk4",
           "MAX_SSP_STAGES"]

#: the largest s generated: the order analysis of 8-stage Gauss checks 376 465 trees (order ≤ 16
#: and one of order 17) in about 14 s; each further stage multiplies that by about seven
MAX_STAGES = 8
#: the largest s of the explicit SSP families: an explicit method's order is pinned in well under
#: a second at any such size, and SSPRK(25,3) is the fifth of Ketcheson's n² family
MAX_SSP_STAGES = 25


def _method(P: sp.Poly, name: str, source: str, alg: Conjugate | None = None) -> RungeKutta:
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


def _lobatto(s: int) -> sp.Poly:
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


# ------------------------------------------------------------------ explicit SSP Runge–Kutta methods

def shu_osher(alpha: Any, beta: Any, **meta: Any) -> RungeKutta:
    r"""The RK method of the Shu–Osher arrays α, β ((s+1)×s, exact; Shu & Osher, J. Comput. Phys.
    77 (1988); [GKS11] ch. 3): y⁽¹⁾ = uₙ and, for i = 2, …, s + 1,

        y⁽ⁱ⁾ = vᵢ uₙ + Σⱼ αᵢⱼ y⁽ʲ⁾ + h Σⱼ βᵢⱼ F(y⁽ʲ⁾),      vᵢ = 1 − Σⱼ αᵢⱼ,

    with u_{n+1} = y⁽ˢ⁺¹⁾ (the weight of uₙ may be written as αᵢ₁ or left to vᵢ: y⁽¹⁾ = uₙ, so
    the method is the same).  Stage i uses only earlier stages (α strictly lower triangular, β
    lower triangular), so the Butcher rows follow by substitution in ℚ:
    aᵢ = Σⱼ αᵢⱼ aⱼ + βᵢ, bᵀ the same for the last row.

    α and β are exact (ints, sympy numbers): these are the families' constructor, not a reader of
    text (a tableau file or ``RungeKutta.from_lists`` parses entries).

    >>> shu_osher([[0], [1]], [[0], [1]]).b.T          # forward Euler
    Matrix([[1]])
    >>> half = sp.Rational(1, 2)
    >>> heun = shu_osher([[0, 0], [1, 0], [half, half]], [[0, 0], [1, 0], [0, half]])
    >>> heun.A, heun.b.T
    (Matrix([
    [0, 0],
    [1, 0]]), Matrix([[1/2, 1/2]]))
    """
    alpha, beta = _exact_matrix(alpha, "α"), _exact_matrix(beta, "β")
    s = alpha.cols
    if alpha.shape != (s + 1, s) or beta.shape != (s + 1, s) or s < 1:
        raise ValueError(f"Shu–Osher arrays are (s+1)×s, the same shape: got α {alpha.shape[0]}×{alpha.shape[1]}, "
                         f"β {beta.shape[0]}×{beta.shape[1]}")
    for i in range(s):
        for j in range(i, s):
            if alpha[i, j] != 0 or (j > i and beta[i, j] != 0):
                what = "α" if alpha[i, j] != 0 else "β"
                raise ValueError(f"{what}[{i + 1},{j + 1}] ≠ 0: stage {i + 1} may use only earlier stages "
                                 "(α strictly lower triangular, β lower triangular)")
    rows: list[list[sp.Expr]] = []
    for i in range(s + 1):
        rows.append([beta[i, j] + sum((alpha[i, k] * rows[k][j] for k in range(min(i, s))), sp.Integer(0))
                     for j in range(s)])
    return RungeKutta.from_lists(rows[:s], rows[s], **meta)


def _exact_matrix(M: Any, what: str) -> sp.Matrix:
    rows = M.tolist() if isinstance(M, sp.MatrixBase) else [list(r) for r in M]
    for i, row in enumerate(rows, 1):
        for j, e in enumerate(row, 1):
            if isinstance(e, bool) or not isinstance(e, (int, sp.Rational)):
                raise ValueError(f"{what}[{i},{j}] = {e!r}: Shu–Osher entries here are exact rationals (int or "
                                 "sympy Rational)")
    return sp.Matrix(rows)


def _ssp_size(s: object, what: str) -> None:
    if not isinstance(s, int) or isinstance(s, bool) or not 1 <= s <= MAX_SSP_STAGES:
        raise ValueError(f"{what}: the number of stages must be an integer 1 … {MAX_SSP_STAGES}, not {s!r}")


def _zeros(s: int) -> list[list[sp.Expr]]:
    return [[sp.Integer(0)] * s for _ in range(s + 1)]


_KETCHESON08 = ("D. I. Ketcheson, Highly efficient strong stability preserving Runge-Kutta methods with low-storage "
                "implementations, SIAM J. Sci. Comput. 30 (2008) 2113-2136")
_NODEPY = "coefficients as in NodePy (ketcheson/nodepy, runge_kutta_method.py"


@lru_cache(maxsize=None)
def ssprk2(s: int) -> RungeKutta:
    r"""SSPRK(s,2), Ketcheson's optimal s-stage second-order SSP method (s ≥ 2; SSP coefficient
    s − 1, effective (s − 1)/s; Ketcheson 2008; [GKS11] ch. 6): s − 1 forward-Euler steps of
    size h/(s − 1), then u_{n+1} = uₙ/s + (s − 1)/s · (y⁽ˢ⁾ + h/(s − 1) F(y⁽ˢ⁾)).  Butcher
    form: every aᵢⱼ (j < i) is 1/(s − 1), every bⱼ is 1/s.

    >>> ssprk2(3).A, ssprk2(3).b.T
    (Matrix([
    [  0,   0, 0],
    [1/2,   0, 0],
    [1/2, 1/2, 0]]), Matrix([[1/3, 1/3, 1/3]]))
    """
    _ssp_size(s, "SSPRK(s,2)")
    if s < 2:
        raise ValueError(f"SSPRK(s,2) has at least 2 stages (one is forward Euler, order 1), not {s}")
    alpha, beta = _zeros(s), _zeros(s)
    r = sp.Integer(s - 1)
    for i in range(1, s):
        alpha[i][i - 1], beta[i][i - 1] = sp.Integer(1), 1 / r
    alpha[s][0], alpha[s][s - 1], beta[s][s - 1] = sp.Rational(1, s), sp.Rational(s - 1, s), sp.Rational(1, s)
    return shu_osher(alpha, beta, name=f"SSPRK({s},2), optimal explicit SSP, SSP coefficient {s - 1}",
                     source=f"{_KETCHESON08}; {_NODEPY} SSPRK2)")


def _shu_osher33() -> RungeKutta:
    R = sp.Rational
    alpha = [[0, 0, 0], [1, 0, 0], [R(3, 4), R(1, 4), 0], [R(1, 3), 0, R(2, 3)]]
    beta = [[0, 0, 0], [1, 0, 0], [0, R(1, 4), 0], [0, 0, R(2, 3)]]
    return shu_osher(alpha, beta, name="SSPRK(3,3), Shu–Osher, SSP coefficient 1",
                     source="C.-W. Shu, S. Osher, J. Comput. Phys. 77 (1988) 439-471; [GKS11] ch. 2 "
                            "(NodePy's loadRKM('SSP33'))")


@lru_cache(maxsize=None)
def ssprk3(s: int) -> RungeKutta:
    r"""SSPRK(s,3), an optimal explicit third-order SSP method, for s = 3 (Shu & Osher 1988: SSP
    coefficient 1) and s = n², n ≥ 2 (Ketcheson 2008; [GKS11] ch. 6: SSP coefficient
    n² − n; s = 4 is Kraaijevanger's SSPRK(4,3)).  Those are the stage numbers with exact
    rational optimal methods; for other s the optimal coefficients are numerical.

    The n² family in Shu–Osher form: forward-Euler steps of size h/(n² − n) from stage to stage,
    except at stage k = n(n + 1)/2 + 1, which is (n − 1)/(2n − 1) · (y⁽ᵏ⁻¹⁾ + h/(n² − n) F) plus
    n/(2n − 1) · y⁽ᵐ⁾, m = (n − 1)(n − 2)/2 + 1.

    >>> ssprk3(4).A, ssprk3(4).b.T
    (Matrix([
    [  0,   0,   0, 0],
    [1/2,   0,   0, 0],
    [1/2, 1/2,   0, 0],
    [1/6, 1/6, 1/6, 0]]), Matrix([[1/6, 1/6, 1/6, 1/2]]))
    >>> ssprk3(5)  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
    ...
    ValueError: SSPRK(s,3) is built exactly for s = 3 and s = n² (4, 9, 16, 25), not 5: the optimal methods for
    other s have numerical coefficients
    """
    _ssp_size(s, "SSPRK(s,3)")
    if s == 3:
        return _shu_osher33()
    n = sp.integer_nthroot(s, 2)[0]
    if n * n != s or n < 2:
        squares = ", ".join(str(k * k) for k in range(2, MAX_SSP_STAGES + 1) if k * k <= MAX_SSP_STAGES)
        raise ValueError(f"SSPRK(s,3) is built exactly for s = 3 and s = n² ({squares}), not {s}: the optimal "
                         "methods for other s have numerical coefficients")
    alpha, beta = _zeros(s), _zeros(s)
    r = sp.Integer(s - n)
    for i in range(1, s + 1):
        alpha[i][i - 1], beta[i][i - 1] = sp.Integer(1), 1 / r
    k = n * (n + 1) // 2                                  # 0-based row of the stage that mixes
    alpha[k][k - 1] = sp.Rational(n - 1, 2 * n - 1)
    beta[k][k - 1] = alpha[k][k - 1] / r
    alpha[k][(n - 1) * (n - 2) // 2] = sp.Rational(n, 2 * n - 1)
    return shu_osher(alpha, beta, name=f"SSPRK({s},3), optimal explicit SSP, SSP coefficient {s - n}",
                     source=f"{_KETCHESON08}; {_NODEPY} SSPRK3)")


@lru_cache(maxsize=None)
def ssprk4(s: int) -> RungeKutta:
    r"""SSPRK(10,4), Ketcheson's ten-stage fourth-order SSP method (SSP coefficient 6; Ketcheson
    2008; [GKS11] ch. 6), the only s with exact rational coefficients: no explicit 4-stage
    fourth-order method is SSP (Kraaijevanger 1991; Ruuth & Spiteri 2002), and the optimal
    methods with s = 5 … 9 (Spiteri & Ruuth's SSP(5,4)…) have irrational numerical coefficients.

    Shu–Osher form: forward-Euler steps of size h/6, except y⁽⁶⁾ = 3/5 uₙ + 2/5 (y⁽⁵⁾ + h/6 F(y⁽⁵⁾))
    and u_{n+1} = 1/25 uₙ + 9/25 (y⁽⁵⁾ + h/6 F(y⁽⁵⁾)) + 3/5 (y⁽¹⁰⁾ + h/6 F(y⁽¹⁰⁾)).

    >>> ssprk4(10).b.T
    Matrix([[1/10, 1/10, 1/10, 1/10, 1/10, 1/10, 1/10, 1/10, 1/10, 1/10]])
    """
    _ssp_size(s, "SSPRK(s,4)")
    if s != 10:
        raise ValueError(f"SSPRK(s,4) is built exactly for s = 10 only (Ketcheson's SSP(10,4)), not {s}: no 4-stage "
                         "fourth-order method is SSP, and the optimal ones with 5 … 9 stages have numerical "
                         "coefficients")
    alpha, beta = _zeros(10), _zeros(10)
    for i in range(1, 11):
        alpha[i][i - 1] = sp.Integer(1)
    alpha[5][4] = sp.Rational(2, 5)
    alpha[10][9] = sp.Rational(3, 5)
    alpha[10][4] = sp.Rational(9, 25)
    beta = [[a / 6 for a in row] for row in alpha]
    return shu_osher(alpha, beta, name="SSPRK(10,4), Ketcheson, SSP coefficient 6",
                     source=f"{_KETCHESON08}; {_NODEPY} loadRKM('SSP104'))")


@lru_cache(maxsize=None)
def ssprk(s: int) -> RungeKutta:
    r"""SSPRK(s,s) for s = 1, 2, 3: the optimal s-stage explicit SSP methods of order s, SSP
    coefficient 1 — forward Euler, Heun's SSPRK(2,2) and Shu & Osher's SSPRK(3,3) (J. Comput.
    Phys. 77 (1988); Gottlieb & Shu, Math. Comp. 67 (1998)).  There is none for s = 4
    (Kraaijevanger 1991): ``ssprk4(10)`` is the classical fourth-order SSP method.

    >>> ssprk(3).A, ssprk(3).b.T
    (Matrix([
    [  0,   0, 0],
    [  1,   0, 0],
    [1/4, 1/4, 0]]), Matrix([[1/6, 1/6, 2/3]]))
    """
    if s == 1:
        return shu_osher([[0], [1]], [[0], [1]], name="SSPRK(1,1), forward Euler, SSP coefficient 1",
                         source="[GKS11] ch. 2")
    if s == 2:
        return ssprk2(2)
    if s == 3:
        return _shu_osher33()
    _ssp_size(s, "SSPRK(s,s)")
    raise ValueError(f"SSPRK(s,s) exists for s = 1, 2, 3, not {s}: no {s}-stage order-{s} explicit method is SSP "
                     "(Kraaijevanger 1991); ssprk4:10 is SSP(10,4)")
