"""Stage order of general linear methods by the textbook definition (issue 29, item 6).

Butcher's definition ([B16] Sec. 53; Butcher, "Diagonally-implicit multi-stage integration methods",
Appl. Numer. Math. 11 (1993) 347-363): with input approximations y_i^[n-1] = Σ_k α_ik h^k y^(k)(x_{n-1})
(w_i(z) = Σ_k α_ik z^k) realising order p, the method has stage order q when the stages are accurate to
O(h^{q+1}):

    exp(cz) = z A exp(cz) + U w(z) + O(z^{q+1}),     exp(z) w(z) = z B exp(cz) + V w(z) + O(z^{p+1}).

For DIMSIMs q = p; for a linear multistep method written as a GLM the stage is the new solution value,
so q = p as well.  The methods below are built or checked from these two series identities alone (sympy
series, no tree code), and then `glm_order` (the B-series solve over trees) must report the same p and
q, with a starting method that realises both (its stage series recomputed here by the textbook
recursion η(t) = A·Π η(t_k) + U ξ(t)).
"""
from pathlib import Path

import pytest
import sympy as sp

from tableau_lab.analysis.glm_order import condition_residuals, glm_order
from tableau_lab.analysis.trees import bracket, trees_of_order
from tableau_lab.exact.methods import GeneralLinearMethod
from tableau_lab.exact.tableau_json import load

METHODS = Path(__file__).parent.parent / "methods"
z = sp.Symbol("z")


def _trunc(e, n):
    """Taylor polynomial of e in z through z^n."""
    return sp.expand(sp.series(e, z, 0, n + 1).removeO())


def _dimsim(c, A, V):
    """A DIMSIM with U = I and p = q = r = s (Butcher 1993): w(z) from the stage conditions,
    B the unique solution of exp(z)w(z) − V w(z) = zB exp(cz) + O(z^{p+1})."""
    s = len(c)
    p = s
    A, V, c = sp.Matrix(A), sp.Matrix(V), sp.Matrix(c)
    E = sp.Matrix([sp.exp(ci * z) for ci in c])
    w = (E - z * A * E).applyfunc(lambda e: _trunc(e, p))
    lhs = (sp.exp(z) * w - V * w).applyfunc(lambda e: _trunc(e, p))
    b = sp.Matrix(s, s, lambda i, j: sp.Symbol(f"b{i}{j}"))
    rhs = (z * b * E).applyfunc(lambda e: _trunc(e, p))
    eqs = [sp.Poly(lhs[i] - rhs[i], z).coeff_monomial(z ** k) for i in range(s) for k in range(p + 1)]
    sol = sp.solve(eqs, list(b), dict=True)
    assert len(sol) == 1
    B = b.subs(sol[0])
    return GeneralLinearMethod(A=A, U=sp.eye(s), B=B, V=V, c=c, name=f"DIMSIM s={s}")


def _linear_orders(m, w, pmax):
    """(p, q) from the two series identities for the given w(z) (the textbook check)."""
    E = sp.Matrix([sp.exp(ci * z) for ci in m.c])
    stage = E - z * m.A * E - m.U * w
    out = sp.exp(z) * w - z * m.B * E - m.V * w

    def acc(vec):
        k = 0
        while k <= pmax and all(_trunc(e, k).coeff(z, k) == 0 for e in vec):
            k += 1
        return k - 1
    return acc(out), acc(stage)


def _stage_series_ok(m, starting, q):
    """η(t) = A·Π η(t_k) + U ξ(t) equals c^|t|/γ(t) for |t| <= q (textbook recursion)."""
    eta = {}

    def gamma(t):
        g = 1 + sum(_size(x) for x in t)
        for x in t:
            g *= gamma(x)
        return g

    for k in range(1, q + 1):
        for t in trees_of_order(k):
            d = sp.ones(m.s, 1)
            for x in t:
                d = sp.Matrix([d[i] * eta[x][i] for i in range(m.s)])
            xi = sp.Matrix(starting[bracket(t)])
            eta[t] = m.A * d + m.U * xi
            want = [ci ** k / gamma(t) for ci in m.c]
            if any(sp.simplify(a - b) != 0 for a, b in zip(eta[t], want, strict=False)):
                return False
    return True


def _size(t):
    return 1 + sum(_size(x) for x in t)


lam = 1 - sp.sqrt(2) / 2
DIMSIMS = {
    # Butcher (1993), type 1 with p = q = r = s = 2, c = (0, 1): A = [[0, 0], [2, 0]], V = ½·1·1ᵀ;
    # the solve reproduces the published B = [[5/4, 1/4], [3/4, −1/4]] (checked below).
    "type1_p2": ([0, 1], [[0, 0], [2, 0]], [[sp.Rational(1, 2)] * 2] * 2),
    # type 2: lower triangular, one diagonal value λ (here the L-stable λ = 1 − √2/2)
    "type2_p2": ([0, 1], [[lam, 0], [sp.Rational(1, 3), lam]], [[0, 1], [0, 1]]),
    # type 3: A = 0 (parallel, explicit)
    "type3_p2": ([0, 1], [[0, 0], [0, 0]], [[sp.Rational(1, 2)] * 2] * 2),
    # type 4: A = λI (parallel, implicit)
    "type4_p2": ([0, 1], [[lam, 0], [0, lam]], [[0, 1], [0, 1]]),
    # type 1, p = q = r = s = 3, c = (0, 1/2, 1)
    "type1_p3": ([0, sp.Rational(1, 2), 1], [[0, 0, 0], [sp.Rational(1, 2), 0, 0], [0, 1, 0]],
                 [[0, 0, 1]] * 3),
}


@pytest.mark.parametrize("name", sorted(DIMSIMS))
def test_dimsim_stage_order_equals_order(name):
    m = _dimsim(*DIMSIMS[name])
    p = m.s
    E = sp.Matrix([sp.exp(ci * z) for ci in m.c])
    w = (E - z * m.A * E).applyfunc(lambda e: _trunc(e, p))
    assert _linear_orders(m, w, p + 1) == (p, p)             # the definition, by series: q = p
    res = glm_order(m)
    assert (res.order, res.stage_order) == (p, p)
    assert _stage_series_ok(m, res.starting, p)                # the printed starting method realises q
    vals, _ = condition_residuals(m, res.starting, p)          # ... and the order p
    assert all(sp.simplify(x) == 0 for v in vals.values() for x in (v if isinstance(v, tuple) else (v,)))


def test_butcher_type1_example_b():
    """The published B of Butcher's type-1 order-2 DIMSIM, from the defining identities."""
    m = _dimsim(*DIMSIMS["type1_p2"])
    assert m.B == sp.Matrix([[sp.Rational(5, 4), sp.Rational(1, 4)], [sp.Rational(3, 4), -sp.Rational(1, 4)]])


def _nordsieck_adams_moulton3():
    """The order-3 Adams–Moulton method in Nordsieck form (y, hy', h²y''/2): predict with the
    Pascal matrix P, correct with l = (5/12, 1, 1/2) [B16 Sec. 45; Gear 1971]; one stage Y = y_n."""
    P = sp.Matrix([[1, 1, 1], [0, 1, 2], [0, 0, 1]])
    ell = sp.Matrix([sp.Rational(5, 12), 1, sp.Rational(1, 2)])
    U = P[0, :] - ell[0] * P[1, :]
    V = P - ell * P[1, :]
    return GeneralLinearMethod(A=sp.Matrix([[ell[0]]]), U=U, B=ell, V=V, c=sp.Matrix([1]), name="AM3 Nordsieck")


def test_nordsieck_adams_moulton3():
    m = _nordsieck_adams_moulton3()
    # Relative to the exact Nordsieck vector (1, z, z²/2) outputs and stage are only O(z³) accurate; the input
    # w(z) = (1, z, z²/2 − z³/4) (the z³ terms solved by hand from both identities: the unique
    # choice with α₁₃ = 0) gives order 3 and stage order 3
    assert _linear_orders(m, sp.Matrix([1, z, z ** 2 / 2]), 4) == (2, 2)
    w = sp.Matrix([1, z, z ** 2 / 2 - z ** 3 / 4])
    assert _linear_orders(m, w, 4) == (3, 3)
    res = glm_order(m)
    assert (res.order, res.stage_order) == (3, 3)
    assert _stage_series_ok(m, res.starting, 3)


@pytest.mark.parametrize("name", ["leapfrog", "adams_bashforth2"])
def test_multistep_as_glm_stage_order_equals_order(name):
    """An LMM as a GLM: the stage is the solution value y_n of the input, so q = p = 2."""
    m = load(METHODS / f"{name}.json")
    res = glm_order(m)
    assert (res.order, res.stage_order) == (2, 2)
    assert _stage_series_ok(m, res.starting, 2)
