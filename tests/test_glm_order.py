"""Order theory against independent facts: OEIS tree counts, published orders (pinned:
all conditions hold up to p, one fails at p + 1), an independent elementary-weight
recursion, and for the seed's Example 4 a direct power-series expansion of
M∘S − S∘E on a 2-D polynomial vector field (no B-series code involved)."""
from pathlib import Path

import pytest
import sympy as sp

from tableau_lab.analysis.glm_order import glm_order, theta_matrix
from tableau_lab.analysis.trees import bracket, trees_of_order
from tableau_lab.exact.tableau_json import load

METHODS = Path(__file__).parent.parent / "methods"

# published orders: HNW I Table II.1.2; HLW06 Table II.1.1-4; HW II Tables IV.5.x; seed §2.7 / [BHHN14]
ORDERS = {"explicit_euler": 1, "implicit_euler": 1, "implicit_midpoint": 2, "rk4": 4, "rule_3_8": 4, "gauss2": 4,
          "gauss3": 6, "lobatto_iiia3": 4, "lobatto_iiib3": 4, "lobatto_iiic3": 4, "radau_iia3": 5,
          "adams_bashforth2": 2, "leapfrog": 2, "example4_glm": 4}


def test_tree_counts_oeis_a000081():
    assert [len(trees_of_order(n)) for n in range(1, 11)] == [1, 1, 2, 4, 9, 20, 48, 115, 286, 719]
    assert bracket(trees_of_order(3)[0]) in ("[τ²]", "[[τ]]")
    assert sorted(bracket(t) for t in trees_of_order(3)) == ["[[τ]]", "[τ²]"]


@pytest.mark.parametrize("k", range(3, 10))
def test_theta_matrix_full_column_rank(k):
    """The principal parts θ(s), |s| = k-1, are forced by the order-k conditions."""
    L = sp.Matrix(theta_matrix(k))
    assert L.rank() == len(trees_of_order(k - 1))


def test_theta_tau_does_not_enter():
    assert all(x == 0 for row in theta_matrix(2) for x in row)


@pytest.mark.parametrize("name", sorted(ORDERS))
def test_pinned_orders(name):
    res = glm_order(load(METHODS / f"{name}.json"))
    p = ORDERS[name]
    # none of these needs a nontrivial principal part: θ ≡ 0 reaches the same order
    assert res.order == p and res.order_identity_start == p
    assert res.errors and all(v != 0 for v in res.errors.values())   # fails at p + 1


def _phi(A, b, t):
    """Elementary weight by the textbook recursion (independent of glm_order)."""
    def stage(t):
        v = sp.ones(A.rows, 1)
        for c in t:
            w = A * stage(c)
            v = sp.Matrix([v[i] * w[i] for i in range(A.rows)])
        return v
    return (b.T * stage(t))[0]


def _gamma(t):
    g = 1 + sum(_size(c) for c in t)
    for c in t:
        g *= _gamma(c)
    return g


def _size(t):
    return 1 + sum(_size(c) for c in t)


def _sigma(t):
    """Symmetry coefficient σ(t) by its recursion (independent of the trees module)."""
    out = 1
    for c in set(t):
        out *= sp.factorial(t.count(c)) * _sigma(c) ** t.count(c)
    return out


def _elementary_differential(f, y, t, at):
    """Elementary differential F(t)(at) of the vector field f(y) by directional derivatives."""
    args = [_elementary_differential(f, y, c, at) for c in t]
    expr = f
    for a in args:
        expr = sum((sp.diff(expr, y[j]) * a[j] for j in range(len(y))), sp.zeros(len(y), 1))
    return expr.subs(dict(zip(y, at, strict=True)), simultaneous=True)


@pytest.mark.parametrize("name", ["rk4", "rule_3_8", "gauss2", "radau_iia3", "lobatto_iiia3"])
def test_classical_order_by_independent_elementary_weights(name):
    m = load(METHODS / f"{name}.json")
    p = ORDERS[name]
    for k in range(1, p + 2):
        ok = all(sp.radsimp(sp.expand(_phi(m.A, m.b, t) - sp.Rational(1, _gamma(t)))) == 0 for t in trees_of_order(k))
        assert ok == (k <= p), (name, k)


def test_example4_starting_method_by_power_series():
    """M∘S = S∘E + O(h^5) but not O(h^6), expanded directly in h on f(y) = (y2², y1 + y1*y2)."""
    m = load(METHODS / "example4_glm.json")
    res = glm_order(m)
    h = sp.Symbol("h")
    y = sp.symbols("y1 y2")
    f = sp.Matrix([y[1] ** 2, y[0] + y[0] * y[1]])
    y0 = sp.Matrix([sp.Rational(1, 2), sp.Rational(1, 3)])
    N = 6  # keep terms up to h^5

    def trunc(e):
        e = sp.expand(e)
        return sum(e.coeff(h, k) * h ** k for k in range(N))

    def F(v):
        return f.subs(dict(zip(y, v, strict=False)), simultaneous=True)

    trees = [t for k in range(1, 5) for t in trees_of_order(k)]

    def S(at):
        out = []
        for i in range(m.r):
            v = res.u[i] * at
            for t in trees:
                xi = res.starting[bracket(t)][i]
                if xi != 0:
                    v += h ** _size(t) / _sigma(t) * xi * _elementary_differential(f, y, t, at)
            out.append(v.applyfunc(trunc))
        return out

    # exact solution y(h) as a Taylor series from the same vector field, to h^5
    yh = y0.copy()
    term = sp.Matrix(y)
    for k in range(1, N):
        term = (term.jacobian(y) * f)
        yh += h ** k / sp.factorial(k) * term.subs(dict(zip(y, y0, strict=False)), simultaneous=True)
    yh = yh.applyfunc(trunc)

    start = S(y0)
    # one GLM step with implicit stages solved by fixed-point iteration on truncated series
    Y = [start[0] * 0 + sum((m.U[i, j] * start[j] for j in range(m.r)), sp.zeros(2, 1)) for i in range(m.s)]
    for _ in range(N):
        FY = [F(Yi).applyfunc(trunc) for Yi in Y]
        Y = [(sum((m.U[i, j] * start[j] for j in range(m.r)), sp.zeros(2, 1))
              + h * sum((m.A[i, j] * FY[j] for j in range(m.s)), sp.zeros(2, 1))).applyfunc(trunc) for i in range(m.s)]
    FY = [F(Yi).applyfunc(trunc) for Yi in Y]
    out = [(sum((m.V[i, j] * start[j] for j in range(m.r)), sp.zeros(2, 1))
            + h * sum((m.B[i, j] * FY[j] for j in range(m.s)), sp.zeros(2, 1))).applyfunc(trunc) for i in range(m.r)]
    target = S(yh)
    diff = [(o - t_).applyfunc(lambda e: sp.radsimp(trunc(e))) for o, t_ in zip(out, target, strict=False)]
    for k in range(N):
        coeffs = [sp.radsimp(d[j].coeff(h, k)) for d in diff for j in range(2)]
        if k <= 4:
            assert all(c == 0 for c in coeffs), k
        else:
            assert any(c != 0 for c in coeffs)        # order exactly 4


def test_finishing_inverts_principal_part():
    """α·α⁻¹ = identity on τ and [τ]: α⁻¹(τ) = -α(τ), α⁻¹([τ]) = -α([τ]) + α(τ)²."""
    res = glm_order(load(METHODS / "example4_glm.json"))
    a = {k: sum(wi * x for wi, x in zip(res.w, v, strict=False)) for k, v in res.starting.items()}
    assert sp.simplify(res.finishing["τ"] + a["τ"]) == 0
    assert sp.simplify(res.finishing["[τ]"] + a["[τ]"] - a["τ"] ** 2) == 0


def test_glm43_printed_fails_at_order_2():
    res = glm_order(load(METHODS / "glm43_printed.json"))
    assert res.order == 1 and "[τ]" in res.errors


def test_effective_order_exceeds_classical_measured_slope():
    """A 2-stage method with Σb = 1, Σbc = 1/2, bᵀAc = 1/6 but bᵀc² ≠ 1/3: classical order 2,
    effective order 3.  Independent check: processing with the computed starting method
    (θ([τ])) and finishing method raises the measured convergence slope from 2 to 3 on
    y' = y² (exact solution y0/(1 - y0 t))."""
    import numpy as np

    from tableau_lab.exact.methods import RungeKutta

    m = RungeKutta.from_lists([[0, 0], [sp.Rational(2, 3), sp.Rational(1, 3)]], [sp.Rational(1, 2)] * 2)
    res = glm_order(m)
    assert (res.order_identity_start, res.order) == (2, 3)
    th, fin = float(res.theta["[τ]"]), float(res.finishing["[τ]"])
    assert fin == -th and all(float(res.finishing[k]) == 0 for k in ("[τ²]", "[[τ]]"))
    f, fp = (lambda y: y * y), (lambda y: 2 * y)

    def step(y, h):
        Y2 = y
        for _ in range(60):
            Y2 = y + h * (2 / 3 * f(y) + 1 / 3 * f(Y2))
        return y + h * (f(y) + f(Y2)) / 2

    y0, T = 0.5, 1.0
    slopes = []
    for process in (False, True):
        hs, errs = [], []
        for n in (20, 40, 80, 160):
            h, y = T / n, y0
            if process:
                y = y + h * h * th * fp(y) * f(y)        # S: B(ξ, y) with ξ([τ]) = θ([τ]), σ([τ]) = 1
            for _ in range(n):
                y = step(y, h)
            if process:
                y = y + h * h * fin * fp(y) * f(y)       # F = B(α⁻¹, ·)
            hs.append(h)
            errs.append(abs(y - y0 / (1 - y0 * T)))
        slopes.append(np.polyfit(np.log(hs), np.log(errs), 1)[0])
    assert abs(slopes[0] - 2) < 0.2 and abs(slopes[1] - 3) < 0.2


@pytest.mark.parametrize("s", [1, 2, 3])
def test_generated_gauss_order_2s(s):
    from tableau_lab.exact.families import gauss
    res = glm_order(gauss(s), max_order=2 * s)
    assert (res.order_identity_start, res.order, res.stage_order) == (2 * s, 2 * s, s) and res.errors


def test_generated_gauss5_order_10_pinned():
    """Gauss with 5 stages, nodes as nested radicals in a degree-8 number field: all
    conditions through order 10 hold, one of order 11 fails (about 10 s)."""
    from tableau_lab.exact.families import gauss
    res = glm_order(gauss(5), max_order=10)
    assert res.order_identity_start == 10 and res.order == 10 and not res.capped
    assert res.errors_identity_start and all(len(k) > 0 for k in res.errors_identity_start)
