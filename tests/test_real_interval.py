"""The real-axis stability interval against published values and the stability function itself
evaluated on either side of the computed end."""
import pytest
import sympy as sp

from tableau_lab.analysis.real_interval import real_stability_interval
from tableau_lab.analysis.stability import stability_function
from tableau_lab.exact.tableau_json import load


@pytest.mark.parametrize("name, published", [
    ("explicit_euler", 2), ("rk4", 2.785293563405282), ("rule_3_8", 2.785293563405282),   # [HW96] IV.2; NodePy
    ("gauss2", sp.oo), ("radau_iia3", sp.oo), ("implicit_euler", sp.oo), ("gauss:6", sp.oo)])
def test_published_real_intervals(name, published):
    m = load(name)
    beta = real_stability_interval(m).beta
    if published == sp.oo:
        assert beta == sp.oo
        return
    assert abs(float(beta) - published) < 1e-12
    N, D, _ = stability_function(m)
    R = sp.lambdify(sp.Symbol("z"), N.as_expr() / D.as_expr())
    b = float(beta)
    assert all(abs(R(-b * k / 100)) <= 1 + 1e-12 for k in range(101))
    assert abs(R(-b - 1e-6)) > 1


def test_irrational_stability_functions():
    """Over a number field the cuts come from norms and the signs are certified: SDIRK34 (R in
    ℚ(cos π/18)) is A-stable, so β = ∞; a 2-stage explicit method of order 2 with irrational
    coefficients (c₂ = √2/2) has R = 1 + z + z²/2 whatever them, so β = 2."""
    from tableau_lab.exact.methods import RungeKutta
    assert real_stability_interval(load("sdirk34")).beta == sp.oo
    c = sp.sqrt(2) / 2
    m = RungeKutta.from_lists([[0, 0], [c, 0]], [1 - 1 / (2 * c), 1 / (2 * c)])
    assert real_stability_interval(m).beta == 2
