r"""Linear multistep methods as general linear methods, and the classical families exactly.

A k-step method Σⱼ₌₀ᵏ αⱼ y_{n+j} = h Σⱼ₌₀ᵏ βⱼ f(y_{n+j}) (αₖ = 1) is the GLM ([B16] §50) with
one stage Y = y_{n+k} and the input values y_{n+k−1}, …, y_{n+k−q} followed by h f_{n+k−1}, …,
h f_{n+k−m}, as many past values and derivatives as the method uses (q = k − min{j < k : αⱼ ≠ 0},
m = k − min{j < k : βⱼ ≠ 0}):

    Y = h βₖ f(Y) − Σ_{j<k} αⱼ y_{n+j} + h Σ_{j<k} βⱼ f_{n+j}       (A = [βₖ], U = that row)
    outputs: y_{n+k} = Y, the y values shifted; h f(Y), the derivatives shifted.

The stage sits at the new step point: c = [1] (the first input value is y_{n+k−1}).  The
natural starting procedure (exact past values and derivatives) makes the GLM's order that of the
LMM.  The families come from their defining interpolation identities in exact rationals
([HNW93] III.1: Adams from ∫ of the interpolating polynomial of f, BDF from its derivative;
Nyström and Milne–Simpson integrate over two steps).

>>> bdf(2).V
Matrix([
[4/3, -1/3],
[  1,    0]])
>>> adams_bashforth(2).U          # Y = y_{n+1} + h(3/2 f_{n+1} − 1/2 f_n), values (y_{n+1}, hf_{n+1}, hf_n)
Matrix([[1, 3/2, -1/2]])
>>> lmm_coefficients("adams_moulton", 2)
([0, -1, 1], [-1/12, 2/3, 5/12])
>>> as_lmm(bdf(2))                  # and back: (α₀ … αₖ, β₀ … βₖ), αₖ = 1
([1/3, -4/3, 1], [0, 0, 2/3])
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import sympy as sp

from .methods import GeneralLinearMethod, Method, MethodError

#: (α₀ … αₖ, β₀ … βₖ) of a linear multistep method
Coefficients = tuple[list[sp.Expr], list[sp.Expr]]

__all__ = ["lmm", "lmm_coefficients", "as_lmm", "bdf", "adams_bashforth", "adams_moulton", "nystrom",
           "milne_simpson", "FAMILIES"]

_T = sp.Symbol("t")

FAMILIES = {
    "adams_bashforth": "Adams–Bashforth", "adams_moulton": "Adams–Moulton", "bdf": "BDF",
    "nystrom": "Nyström", "milne_simpson": "Milne–Simpson",
}
MAX_STEPS = 30      # k beyond which the coefficients (and any analysis of them) are not worth building


def _lagrange_weights(nodes: Sequence[int], a: int, b: int) -> list[sp.Expr]:
    """∫_a^b ℓ_i(t) dt for the Lagrange basis on the integer ``nodes`` (exact)."""
    out = []
    for i, x in enumerate(nodes):
        ell = sp.prod([(_T - y) / (x - y) for j, y in enumerate(nodes) if j != i])
        out.append(sp.integrate(sp.expand(ell), (_T, a, b)))
    return out


def lmm_coefficients(family: str, k: int) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """(α₀ … αₖ, β₀ … βₖ) of the k-step method of ``family`` (αₖ = 1), time measured in steps
    with the new point at t = k."""
    if family not in FAMILIES:
        raise MethodError(f"unknown multistep family {family!r}; known: {', '.join(sorted(FAMILIES))}")
    if not isinstance(k, int) or isinstance(k, bool) or not 1 <= k <= MAX_STEPS:
        raise MethodError(f"{FAMILIES[family]}: the number of steps must be an integer 1 … {MAX_STEPS}, not {k!r}")
    alpha, beta = [sp.Integer(0)] * (k + 1), [sp.Integer(0)] * (k + 1)
    alpha[k] = sp.Integer(1)
    if family == "bdf":                      # ρ from the derivative at t = k of the interpolant of y
        nodes = list(range(k + 1))
        d = []
        for i, x in enumerate(nodes):
            ell = sp.prod([(_T - y) / (x - y) for j, y in enumerate(nodes) if j != i])
            d.append(sp.diff(ell, _T).subs(_T, k))
        alpha = [x / d[k] for x in d]
        beta[k] = 1 / d[k]
        return alpha, beta
    two = family in ("nystrom", "milne_simpson")
    if two and k < 2:
        raise MethodError(f"{FAMILIES[family]} methods have at least 2 steps, not {k}")
    implicit = family in ("adams_moulton", "milne_simpson")
    lo = k - 2 if two else k - 1               # y_k − y_lo = h ∫_lo^k p(t) dt
    alpha[lo] = sp.Integer(-1)
    nodes = list(range(0, k + 1 if implicit else k))      # p interpolates f there
    w = _lagrange_weights(nodes, lo, k)
    for x, v in zip(nodes, w, strict=False):
        beta[x] += v
    return alpha, beta


def lmm(alpha: Sequence[Any], beta: Sequence[Any], *, name: str, source: str = "", **meta: Any
        ) -> GeneralLinearMethod:
    """The GLM of the LMM Σ αⱼ y_{n+j} = h Σ βⱼ f_{n+j} (module docstring); α, β exact, αₖ ≠ 0
    (normalised to 1)."""
    alpha, beta = [sp.sympify(a) for a in alpha], [sp.sympify(b) for b in beta]
    k = len(alpha) - 1
    if k < 1 or len(beta) != k + 1:
        raise MethodError(f"an LMM needs α and β of the same length k + 1 ≥ 2, got {len(alpha)} and {len(beta)}")
    if alpha[k] == 0:
        raise MethodError("αₖ = 0: not a k-step method")
    alpha, beta = [a / alpha[k] for a in alpha], [b / alpha[k] for b in beta]
    ky = k - min(j for j in range(k) if alpha[j] != 0) if any(alpha[:k]) else 0
    used = [j for j in range(k) if beta[j] != 0]
    m = k - min(used) if used else 0
    if ky == 0:
        raise MethodError("α₀ = … = α_{k−1} = 0: not consistent (Σ αⱼ = 0 fails)")
    r = ky + m
    urow = [-alpha[k - i] for i in range(1, ky + 1)] + [beta[k - i] for i in range(1, m + 1)]
    U = sp.Matrix([urow])
    A = sp.Matrix([[beta[k]]])
    B = sp.zeros(r, 1)
    V = sp.zeros(r, r)
    B[0, 0] = beta[k]
    V[0, :] = U
    for i in range(1, ky):
        V[i, i - 1] = 1                       # y values shifted
    if m:
        B[ky, 0] = 1                          # h f(Y), the newest derivative
        for i in range(1, m):
            V[ky + i, ky + i - 1] = 1         # derivatives shifted
    return GeneralLinearMethod(A=A, U=U, B=B, V=V, c=sp.Matrix([1]), name=name, source=source, **meta)


def as_lmm(m: Method) -> Coefficients | None:
    """(α₀ … αₖ, β₀ … βₖ), αₖ = 1, when the method ``m`` is a linear multistep method written
    as a GLM, else None.

    * The GLM that :func:`lmm` builds (the families here, NodePy's multistep methods through
      :mod:`interop`, a tableau file written from one): U's row split into past values and past
      derivatives where B's column has its 1, the GLM rebuilt and compared in every matrix.
    * Any other one-stage GLM whose stage is the solution value — the stage is the first output
      (B₁₁ = A₁₁, V's first row = U) or the first input (A = 0, U = e₁ᵀ), as in the shipped
      ``adams_bashforth2`` and ``leapfrog`` files: its stage values Yₙ satisfy the LMM
      ρ(E)Yₙ = h σ(E)F(Yₙ) with ρ(w) = det(wI − V) and βⱼ = cⱼ A₁₁ + Σ_{i>j} cᵢ U V^{i−1−j} B
      (cᵢ the coefficients of ρ; the past inputs drop out since ρ(V) = 0, Cayley–Hamilton), with
      the common factor of ρ and σ removed; V without free parameters.  ([B16] §50 writes LMMs as
      one-stage GLMs; this is the converse for the stage values.)

    >>> from tableau_lab.exact.tableau_json import load
    >>> as_lmm(load("adams_bashforth2")), as_lmm(load("leapfrog"))
    (([0, -1, 1], [-1/2, 3/2, 0]), ([-1, 0, 1], [0, 2, 0]))
    """
    if not isinstance(m, GeneralLinearMethod) or m.kind != "glm" or m.s != 1:
        return None
    return _as_built(m) or _stage_values(m)


def _stage_values(m: GeneralLinearMethod) -> Coefficients | None:
    """The LMM of the stage values of a one-stage GLM whose stage is the solution (:func:`as_lmm`)."""
    a, U, B, V, r = m.A[0, 0], m.U, m.B, m.V, m.r
    first_output = B[0, 0] == a and V.row(0) == U
    first_input = a == 0 and list(U) == [1] + [0] * (r - 1)
    if not (first_output or first_input) or V.free_symbols:      # det(wI − V) of a parametric V: not attempted
        return None
    w = sp.Dummy("w")
    c = V.charpoly(w).all_coeffs()[::-1]                     # c[i]: the coefficient of wⁱ, c[r] = 1
    P, powers = B, []                                        # U Vᵗ B, t = 0 … r − 1
    for _ in range(r):
        powers.append((U * P)[0, 0])
        P = V * P
    beta = [c[j] * a + sum((c[i] * powers[i - 1 - j] for i in range(j + 1, r + 1)), sp.Integer(0))
            for j in range(r)] + [c[r] * a]
    rho, sigma = sp.Poly(c[::-1], w), sp.Poly(beta[::-1], w)
    g = sp.gcd(rho, sigma)
    rho, sigma = sp.quo(rho, g), sp.quo(sigma, g)
    k = rho.degree()
    if k < 1:
        return None
    lead = rho.LC()
    alpha = [sp.cancel(rho.coeff_monomial(w ** j) / lead) for j in range(k + 1)]
    beta = [sp.cancel(sigma.coeff_monomial(w ** j) / lead) for j in range(k + 1)]
    return alpha, beta


def _as_built(m: GeneralLinearMethod) -> Coefficients | None:
    """(α, β) when ``m`` is exactly the GLM :func:`lmm` builds of them (:func:`as_lmm`)."""
    r, u = m.r, list(m.U.row(0))
    ones = [i for i in range(1, r) if m.B[i, 0] != 0]        # B's column: h f(Y) enters after the ky y values
    if len(ones) > 1:
        return None
    ky = ones[0] if ones else r
    k = max(ky, r - ky)
    alpha, beta = [sp.Integer(0)] * (k + 1), [sp.Integer(0)] * (k + 1)
    alpha[k], beta[k] = sp.Integer(1), m.A[0, 0]
    for i in range(1, ky + 1):
        alpha[k - i] = -u[i - 1]
    for i in range(1, r - ky + 1):
        beta[k - i] = u[ky + i - 1]
    try:
        g = lmm(alpha, beta, name=m.name)
    except MethodError:
        return None
    return (alpha, beta) if g.matrices() == m.matrices() else None


def _family(family: str, k: int) -> GeneralLinearMethod:
    alpha, beta = lmm_coefficients(family, k)
    return lmm(alpha, beta, name=f"{FAMILIES[family]}, {k} step{'s' if k > 1 else ''} (as a GLM)",
               source=f"generated: {FAMILIES[family]} coefficients from the interpolation identity "
                      "(E. Hairer, S. P. Nørsett, G. Wanner, Solving ODEs I, 2nd ed., Springer 1993, §III.1)")


def bdf(k: int) -> GeneralLinearMethod:
    """The k-step backward differentiation formula (order k; zero-stable for k ≤ 6)."""
    return _family("bdf", k)


def adams_bashforth(k: int) -> GeneralLinearMethod:
    """The k-step Adams–Bashforth method (explicit, order k)."""
    return _family("adams_bashforth", k)


def adams_moulton(k: int) -> GeneralLinearMethod:
    """The k-step Adams–Moulton method (implicit, order k + 1)."""
    return _family("adams_moulton", k)


def nystrom(k: int) -> GeneralLinearMethod:
    """The k-step explicit Nyström method (order k)."""
    return _family("nystrom", k)


def milne_simpson(k: int) -> GeneralLinearMethod:
    """The k-step Milne–Simpson method (implicit, order k + 1, but 4 for k = 2: Simpson's rule)."""
    return _family("milne_simpson", k)
