r"""The real-axis stability interval [−β, 0] of a decimal Runge–Kutta tableau, certified in ball
arithmetic (the exact version, with the definition, is :mod:`real_interval`; [HW96] IV.2).

R = N/D with D(z) = det(I − zA) and N(z) = det(I − z(A − 1bᵀ)), each the reversed characteristic
polynomial of its matrix (arb's certified ``charpoly``), and D(0) = N(0) = 1 by definition.  On the
negative axis |R(x)| ≤ 1 ⇔ P(x) = D(x)² − N(x)² ≥ 0 (D ≠ 0) ⇔ Q(x) = P(x)/x ≤ 0, where Q is a
polynomial because P(0) = 0.  The walk from 0 leftwards encloses Q and D over whole intervals
(the mean-value form Q(m) + Q′(X)(X − m), intersected with Horner's): every interval on which
Q ≤ 0 and D excludes 0 is certified for every tableau within the balls, so β ≥ its left end; a
point at which Q > 0 is an upper bound.  β = ∞ (an A-stable method) is not decided: the walk stops
at REAL_X_MAX and says so.

>>> import tableau_lab as tl
>>> rk4 = ('{"name": "RK4", "kind": "rk", "numbers": "decimal", "A": [[0, 0, 0, 0], ["1/2", 0, 0, 0], [0, "1/2", 0, 0],'
...        ' [0, 0, 1, 0]], "b": ["0.16666666666666666667", "0.33333333333333333333", "0.33333333333333333333",'
...        ' "0.16666666666666666667"]}')
>>> f = real_interval(tl.load(rk4))
>>> print(f.statement)          # exact: β = −2·root(x³ + 2x² + 3x + 3) = 2.78529356340528162352…
β ∈ [2.785293563405281582, 2.785293563405281711] (certified bounds; to the stated precision)
"""
from __future__ import annotations

import time

import flint

from ..budget import CERTIFIED_SECONDS, REAL_X_MAX
from ..exact.balls import BallMethod
from .certified_findings import CERTIFIED, STATED, UNDECIDED, Evidence, Finding, decimal_bound

__all__ = ["real_interval"]

NAME = "real stability interval"


def _det_poly(M: list[list[flint.arb]]) -> flint.arb_poly:
    """det(I − zM) as a polynomial in z: the reversed characteristic polynomial, constant term 1."""
    s = len(M)
    chi = flint.arb_mat(M).charpoly().coeffs()          # χ(λ) = λ^s + … + c₀, lowest first
    coeffs = [flint.arb(1)] + [chi[s - k] for k in range(1, s + 1)]
    return flint.arb_poly(coeffs)


def _enclose(p: flint.arb_poly, dp: flint.arb_poly, X: flint.arb) -> flint.arb:
    """p over the ball X: Horner's enclosure intersected with the mean-value form."""
    m = X.mid()
    horner, centred = p(X), p(m) + dp(X) * (X - m)
    return horner.intersection(centred) if horner.overlaps(centred) else centred


def real_interval(m: BallMethod, seconds: float = CERTIFIED_SECONDS) -> Finding:
    """The enclosure of β (module docstring): ``value`` (lo, hi) as rationals (hi None: not
    bounded)."""
    with flint.ctx.workprec(m.prec):
        A, b = m.balls("A"), m.balls("b")
        D = _det_poly(A)
        N = _det_poly([[A[i][j] - b[j] for j in range(m.s)] for i in range(m.s)])
        P = (D * D - N * N).coeffs()
        Q = flint.arb_poly(P[1:] or [flint.arb(0)])
        return _walk(Q, D, m, time.monotonic() + seconds)


def _walk(Q: flint.arb_poly, D: flint.arb_poly, m: BallMethod, deadline: float) -> Finding:
    dQ, dD = Q.derivative(), D.derivative()
    places = max(6, m.least_digits - 2)
    tol = flint.fmpq(1, 10 ** places)
    lo, h = flint.fmpq(0), flint.fmpq(1, 8)
    while -lo < REAL_X_MAX and h >= tol:
        if time.monotonic() > deadline:
            return Finding(NAME, UNDECIDED, f"β ≥ {decimal_bound(-lo, places, False)} (certified); the time budget "
                                            "ran out", (-lo, None))
        X = flint.arb(flint.arb(lo - h / 2), flint.arb(h / 2))
        if _enclose(Q, dQ, X) <= 0 and not _enclose(D, dD, X).contains(0):
            lo, h = lo - h, min(h * 2, flint.fmpq(REAL_X_MAX, 64))
        else:
            h /= 2
    if -lo >= REAL_X_MAX:
        return Finding(NAME, UNDECIDED, f"β ≥ {REAL_X_MAX}: |R(x)| ≤ 1 on [−{REAL_X_MAX}, 0] {STATED}, not decided "
                                        f"beyond (REAL_X_MAX, budget.py; an A-stable method has β = ∞)", (-lo, None))
    step = tol
    while step < REAL_X_MAX:                     # a point beyond with |R| > 1: an upper bound
        x = lo - step
        q = Q(flint.arb(x))
        if q > 0:
            text = f"β ∈ [{decimal_bound(-lo, places, False)}, {decimal_bound(-x, places, True)}]"
            ev = (Evidence(f"D(x)² − N(x)² at x = {decimal_bound(x, places, False)} (|R(x)| > 1)", q * flint.arb(x)),)
            return Finding(NAME, CERTIFIED, f"{text} (certified bounds; {STATED})", (-lo, -x), ev)
        step *= 2
    return Finding(NAME, UNDECIDED, f"β ≥ {decimal_bound(-lo, places, False)} (certified); beyond, |R(x)| = 1 is not "
                                    f"crossed {STATED}", (-lo, None))
