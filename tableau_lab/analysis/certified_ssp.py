r"""The SSP coefficient of a decimal Runge–Kutta tableau, certified in ball arithmetic: an
enclosure [lo, hi] of Kraaijevanger's radius of absolute monotonicity R for every tableau within
the entries' balls (the exact version, with the definitions, is :mod:`ssp`).

With K = [[A, 0], [bᵀ, 0]] and e = 1, the method is absolutely monotonic at r ≥ 0 when I + rK is
invertible, K(I + rK)⁻¹ ≥ 0 and e − rK(I + rK)⁻¹e ≥ 0, and the set of such r is [0, R]
(Kraaijevanger, BIT 31 (1991) 482–528, Thm 4.2; [GKS11] ch. 3).  So a dyadic r at which every
entry is certified ≥ 0 (its ball ≥ 0, or an exact 0) is a lower bound of R, and an r at which one
entry's ball is < 0 an upper bound; bisection between them narrows [lo, hi] until the stated
precision stops deciding the signs (then *undecided*, with the interval) or the interval is as
narrow as the digits given.  Where an entry touches 0 at R (a double root in r, as SSPRK(3,3)'s at
r = 1) the balls decide its sign only at a distance √δ from R, δ the entries' radius: the
enclosure is that wide.  R = 0 is certified when an entry of K is negative, or when an exact
zero entry Kᵢⱼ has (K²)ᵢⱼ > 0 (then K(I + rK)⁻¹ᵢⱼ = −r(K²)ᵢⱼ + O(r²) < 0 for small r > 0).

>>> import tableau_lab as tl
>>> ssp33 = ('{"name": "SSPRK(3,3)", "kind": "rk", "numbers": "decimal", "A": [[0, 0, 0], [1, 0, 0],'
...          ' ["1/4", "1/4", 0]], "b": ["0.1666666666666666667", "0.1666666666666666667",'
...          ' "0.6666666666666666667"], "claims": {"ssp_coefficient": 1}}')
>>> r = tl.verify(tl.load(ssp33))
>>> f = r.finding("SSP coefficient")
>>> f.status, f.value[0] <= 1 <= f.value[1], r.claims[0].status     # Shu–Osher: R = 1
('certified', True, 'holds to the stated precision')
>>> print(f.statement)  # doctest: +NORMALIZE_WHITESPACE
R ∈ [0.99999999922540332, 1.00000000000000001] (certified bounds; the signs between them are not decided to the
stated precision: R may be anywhere in it)
"""
from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import flint

from ..budget import CERTIFIED_SECONDS, SSP_R_MAX
from ..exact.balls import BallMethod, Coefficient
from .certified_findings import (
    CERTIFIED,
    HOLDS,
    REFUTED,
    STATED,
    UNDECIDED,
    ClaimCheck,
    Evidence,
    Finding,
    decimal_bound,
)

__all__ = ["certified_ssp", "ssp_claim"]

NAME = "SSP coefficient"


def _K(m: BallMethod) -> list[list[flint.arb]]:
    s, A, b = m.s, m.balls("A"), m.balls("b")
    zero = flint.arb(0)
    return [list(A[i]) + [zero] for i in range(s)] + [list(b) + [zero]]


def _sign(x: flint.arb) -> int | None:
    """1 (≥ 0 certified: > 0 or an exact 0), −1 (< 0 certified) or None."""
    if x.is_exact() and x == 0 or x > 0:
        return 1
    if x < 0:
        return -1
    return None


def _inverse_times(K: list[list[flint.arb]], r: flint.arb, lower: bool) -> list[list[flint.arb]] | None:
    """(I + rK)⁻¹K: by substitution when K is strictly lower triangular (exact zeros stay exact),
    else by arb's certified solve; None when I + rK is not certified invertible."""
    n = len(K)
    if lower:
        X: list[list[flint.arb]] = []
        for i in range(n):                           # (I + rK) X = K, row by row
            X.append([K[i][j] - r * sum((K[i][k] * X[k][j] for k in range(i)), flint.arb(0)) for j in range(n)])
        return X
    M = flint.arb_mat([[(1 if i == j else 0) + r * K[i][j] for j in range(n)] for i in range(n)])
    try:
        Y = M.solve(flint.arb_mat(K))
    except ZeroDivisionError:
        return None
    return [[Y[i, j] for j in range(n)] for i in range(n)]


def _at(K: list[list[flint.arb]], r: flint.fmpq, lower: bool) -> tuple[bool | None, Evidence | None]:
    """Absolutely monotonic at r: True (certified), False (an entry certified < 0, the evidence) or
    None (undecided, the entry)."""
    rr = flint.arb(r)
    X = _inverse_times(K, rr, lower)
    if X is None:
        return None, None
    n = len(K)
    conds = [(f"K(I + rK)⁻¹ entry ({i + 1}, {j + 1})", X[i][j]) for i in range(n) for j in range(n)]
    conds += [(f"e − rK(I + rK)⁻¹e entry {i + 1}", 1 - rr * sum(X[i], flint.arb(0))) for i in range(n)]
    unsure = None
    for name, x in conds:
        sg = _sign(x)
        if sg == -1:
            return False, Evidence(f"{name} at r = {r}", x)
        if sg is None and unsure is None:
            unsure = Evidence(f"{name} at r = {r}", x)
    return (True, None) if unsure is None else (None, unsure)


def _zero_at_origin(K: list[list[flint.arb]]) -> tuple[bool | None, Evidence | None]:
    """R = 0 certified (True, the entry), undecided at r = 0 (None, the entry) or R > 0 possible."""
    n = len(K)
    unsure = None
    for i in range(n):
        for j in range(n):
            sg = _sign(K[i][j])
            if sg == -1:
                return True, Evidence(f"K entry ({i + 1}, {j + 1}) < 0", K[i][j])
            if sg is None and unsure is None:
                unsure = Evidence(f"K entry ({i + 1}, {j + 1})", K[i][j])
            if K[i][j].is_exact() and K[i][j] == 0:
                k2 = sum((K[i][k] * K[k][j] for k in range(n)), flint.arb(0))
                if k2 > 0:
                    return True, Evidence(f"K entry ({i + 1}, {j + 1}) = 0 and (K²)({i + 1}, {j + 1}) > 0, so "
                                          "K(I + rK)⁻¹ there is −r(K²) + O(r²) < 0 for small r > 0", k2)
    return (None, unsure) if unsure is not None else (False, None)


def certified_ssp(m: BallMethod, seconds: float = CERTIFIED_SECONDS) -> Finding:
    """The enclosure [lo, hi] of the SSP coefficient (module docstring): ``value`` (lo, hi) as
    rationals (hi None: not bounded below SSP_R_MAX); the bisection stops after ``seconds`` (the
    bounds found so far stay certified, the finding says so)."""
    with flint.ctx.workprec(m.prec):
        return _enclosure(m, time.monotonic() + seconds, seconds)


def _enclosure(m: BallMethod, deadline: float, seconds: float) -> Finding:
    K = _K(m)
    lower = m.explicit()
    zero, why = _zero_at_origin(K)
    if zero:
        return Finding(NAME, CERTIFIED, "R = 0 (not absolutely monotonic for any r > 0)",
                       (flint.fmpq(0), flint.fmpq(0)), (why,) if why else ())
    lo, hi, evidence = flint.fmpq(0), None, why
    r = flint.fmpq(1)
    while r <= SSP_R_MAX:                        # an upper bound: r = 1, 2, 4, …
        ok, ev = _at(K, r, lower)
        if ok is False:
            hi, evidence = r, ev
            break
        if ok:
            lo = r
        r *= 2
    if hi is None:
        beyond = (f"(SSP_R_MAX = {SSP_R_MAX}, budget.py)" if lo >= SSP_R_MAX
                  else f"(the signs of the conditions beyond are not decided {STATED})")
        return Finding(NAME, UNDECIDED, f"R ≥ {lo}: absolutely monotonic up to r = {lo}; not decided beyond {beyond}",
                       (lo, None), (evidence,) if evidence else ())
    lo, hi, evidence, unsure = _narrow(K, lower, (lo, hi), evidence, _tolerance(m), deadline)
    places = max(6, m.least_digits - 2)
    text = f"R ∈ [{decimal_bound(lo, places, False)}, {decimal_bound(hi, places, True)}]"
    shown = tuple(e for e in (evidence, unsure) if e is not None)
    if time.monotonic() > deadline and hi - lo > _tolerance(m):
        return Finding(NAME, UNDECIDED, f"{text} (certified bounds; the time budget of {seconds:g} s, "
                                        "CERTIFIED_SECONDS in budget.py, ran out before they met)", (lo, hi), shown)
    if unsure is not None and hi - lo > _tolerance(m):
        return Finding(NAME, CERTIFIED, f"{text} (certified bounds; the signs between them are not decided {STATED}: "
                                        "R may be anywhere in it)", (lo, hi), shown)
    return Finding(NAME, CERTIFIED, f"{text} (certified bounds; {STATED})", (lo, hi), shown)


def _tolerance(m: BallMethod) -> flint.fmpq:
    return flint.fmpq(1, 10 ** max(6, m.least_digits - 2))


def _narrow(K: list, lower: bool, bounds: tuple[flint.fmpq, flint.fmpq], evidence: Evidence | None,
            tol: flint.fmpq, deadline: float) -> tuple[flint.fmpq, flint.fmpq, Evidence | None, Evidence | None]:
    """Bisection between lo (certified monotonic) and hi (certified not): first the last certified
    point, then, when the point after it is undecided, the first certified-not point above that."""
    def at(r: flint.fmpq) -> bool | None:
        return _at(K, r, lower)[0]
    lo, hi = bounds
    lo, b = _bisect(lo, hi, lambda r: at(r) is True, tol, deadline)
    if b == hi:
        return lo, hi, evidence, None
    ok, ev = _at(K, b, lower)
    if ok is False:
        return lo, b, ev, None
    _, hi = _bisect(b, hi, lambda r: at(r) is not False, tol, deadline)
    return lo, hi, _at(K, hi, lower)[1], ev


def _bisect(a: flint.fmpq, b: flint.fmpq, good: Callable[[flint.fmpq], bool], tol: flint.fmpq, deadline: float,
            ) -> tuple[flint.fmpq, flint.fmpq]:
    """(a, b) narrowed to within ``tol`` (at most 400 halvings, until ``deadline``), good(a) and not
    good(b) kept."""
    for _ in range(400):
        if b - a <= tol or time.monotonic() > deadline:
            break
        mid = (a + b) / 2
        a, b = (mid, b) if good(mid) else (a, mid)
    return a, b


def ssp_claim(claimed: Any, f: Finding) -> ClaimCheck:
    """A claimed SSP coefficient (an exact or decimal entry) against the enclosure."""
    c = claimed if isinstance(claimed, Coefficient) else None
    ball = c.ball() if c is not None else flint.arb(claimed)
    lo, hi = f.value
    if hi is not None and ball < flint.arb(lo) or hi is not None and ball > flint.arb(hi) or \
            hi is None and ball < flint.arb(lo):
        return ClaimCheck("ssp_coefficient", claimed, REFUTED, f"{f.statement}: the claimed value is outside",
                          f.evidence[:1])
    if f.status == CERTIFIED and ball.overlaps(flint.arb(lo).union(flint.arb(hi))):
        return ClaimCheck("ssp_coefficient", claimed, HOLDS, f.statement)
    return ClaimCheck("ssp_coefficient", claimed, UNDECIDED, f.statement)
