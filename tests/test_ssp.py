"""The SSP coefficient against the published values (Gottlieb, Ketcheson & Shu, Strong Stability
Preserving Runge–Kutta and Multistep Time Discretizations, 2011: Table 3.1 ff.; Kraaijevanger 1991)
and the defining inequalities checked on either side of R with plain sympy."""
import pytest
import sympy as sp

from tableau_lab.analysis.ssp import ssp_coefficient
from tableau_lab.exact.methods import RungeKutta
from tableau_lab.exact.tableau_json import load

R = sp.Rational
SSP33 = RungeKutta.from_lists([[0, 0, 0], [1, 0, 0], [R(1, 4), R(1, 4), 0]], [R(1, 6), R(1, 6), R(2, 3)])
SSP43 = RungeKutta.from_lists([[0, 0, 0, 0], [R(1, 2), 0, 0, 0], [R(1, 2), R(1, 2), 0, 0],
                               [R(1, 6), R(1, 6), R(1, 6), 0]], [R(1, 6), R(1, 6), R(1, 6), R(1, 2)])
CASES = [
    (RungeKutta.from_lists([[0]], [1]), 1),                             # forward Euler
    (RungeKutta.from_lists([[0, 0], [1, 0]], [R(1, 2), R(1, 2)]), 1),   # SSPRK(2,2), Heun
    (SSP33, 1),                                                          # Shu–Osher SSPRK(3,3)
    (SSP43, 2),                                                          # SSPRK(4,3), Kraaijevanger
    (RungeKutta.from_lists([[0, 0], [R(1, 2), 0]], [0, 1]), 0),          # explicit midpoint: b₁ = 0
    (load("rk4"), 0),                                                    # no 4-stage order-4 SSP method
    (load("rule_3_8"), 0),                                               # a₃₂ < 0
    (load("implicit_euler"), sp.oo),
    (load("implicit_midpoint"), 2),
]


def _holds(m, r):
    s = m.s
    K = sp.zeros(s + 1, s + 1)
    K[:s, :s] = m.A
    K[s, :s] = m.b.T
    Minv = K * (sp.eye(s + 1) + r * K).inv()
    return all(x >= 0 for x in Minv) and all(x >= 0 for x in sp.ones(s + 1, 1) - r * Minv * sp.ones(s + 1, 1))


@pytest.mark.parametrize("m, expected", CASES, ids=lambda x: getattr(x, "name", str(x)))
def test_published_ssp_coefficients(m, expected):
    res = ssp_coefficient(m)
    assert res.R == expected
    if expected not in (0, sp.oo):                   # the inequalities hold at R and fail just beyond
        assert _holds(m, expected) and not _holds(m, expected + R(1, 1000))
    if expected == 0:
        assert not _holds(m, R(1, 1000))


def test_irrational_tableaux():
    """Gauss 2 has a₁₂ = 1/4 − √3/6 < 0 (certified sign): R = 0.  The m-stage third-order SSP
    implicit methods (Ketcheson, Macdonald & Gottlieb, Appl. Numer. Math. 59 (2009)) have entries
    in ℚ(√(m² − 1)) — aᵢᵢ = (1 − √((m−1)/(m+1)))/2, aᵢⱼ = 1/√(m² − 1) below the diagonal, bⱼ = 1/m
    (NodePy's SSPIRK3) — and R = m − 1 + √(m² − 1), exactly (NodePy's bisection: 6.87298 for m = 4)."""
    g = ssp_coefficient(load("gauss2"))
    assert g.R == 0 and "a[1,2]" in g.reason
    for m in (2, 3, 4):
        q = sp.sqrt(m * m - 1)
        v = (1 - sp.sqrt(sp.Rational(m - 1, m + 1))) / 2
        A = sp.zeros(m, m)
        for i in range(m):
            A[i, i] = v
            for j in range(i):
                A[i, j] = 1 / q
        b = [1 / sp.Integer(m)] * m
        rk = RungeKutta(A=sp.ImmutableMatrix(A), b=sp.ImmutableMatrix(b))
        res = ssp_coefficient(rk)
        assert abs(sp.N(res.R - (m - 1 + q), 50)) < 1e-45, res
        assert sp.minimal_polynomial(res.R, sp.Symbol("x")) == sp.minimal_polynomial(m - 1 + q, sp.Symbol("x"))


def test_not_computed_says_why():
    assert "Runge–Kutta" in ssp_coefficient(load("example4_glm")).reason
