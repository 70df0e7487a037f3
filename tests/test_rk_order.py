"""RK order by elementary weights against published facts: orders pinned at p + 1,
simplifying assumptions of the collocation families ([HW96] Table IV.5.13), the tall-tree
error coefficient against the stability function's Taylor expansion, Gauss 5 order 10."""
from pathlib import Path

import pytest
import sympy as sp

from tableau_lab.analysis.glm_order import glm_order
from tableau_lab.analysis.order import order
from tableau_lab.analysis.rk_order import rk_order
from tableau_lab.exact.families import gauss
from tableau_lab.exact.field import is_zero
from tableau_lab.exact.tableau_json import load

METHODS = Path(__file__).parent.parent / "methods"

# (order, B, C, D): HW96 Table IV.5.13 with s = 3 (Gauss: B(2s) C(s) D(s); Radau IIA: B(2s-1) C(s) D(s-1);
# Lobatto IIIA: B(2s-2) C(s) D(s-2); IIIB: B(2s-2) C(s-2) D(s); IIIC: B(2s-2) C(s-1) D(s-1)); s = 2 for gauss2
FACTS = {"gauss2": (4, 4, 2, 2), "gauss3": (6, 6, 3, 3), "radau_iia3": (5, 5, 3, 2), "lobatto_iiia3": (4, 4, 3, 1),
         "lobatto_iiib3": (4, 4, 1, 3), "lobatto_iiic3": (4, 4, 2, 2)}


@pytest.mark.parametrize("name", sorted(FACTS))
def test_collocation_families(name):
    r = rk_order(load(METHODS / f"{name}.json"))
    assert (r.order, r.B, r.C, r.D) == FACTS[name]
    assert r.residuals and not r.capped


@pytest.mark.parametrize("name, p", [("explicit_euler", 1), ("implicit_midpoint", 2), ("rk4", 4), ("rule_3_8", 4)])
def test_orders_agree_with_glm_theory(name, p):
    m = load(METHODS / f"{name}.json")
    assert rk_order(m).order == p == glm_order(m).order_identity_start


@pytest.mark.parametrize("name", ["rk4", "gauss2", "gauss3", "radau_iia3", "lobatto_iiic3", "sdirk34"])
def test_tall_tree_error_coefficient_is_stability_function_defect(name):
    """On y' = λy only the tall tree contributes: its error coefficient (σ = 1) equals the
    z^(p+1) coefficient of R(z) − e^z, with R(z) = det(I − zA + z1bᵀ)/det(I − zA)
    ([HW96] Prop. IV.3.2), expanded by exact power-series division."""
    m = load(METHODS / f"{name}.json")
    r = rk_order(m)
    z = sp.Symbol("z")
    s, n = m.s, r.order + 1
    P = sp.Poly(sp.expand((sp.eye(s) - z * m.A + z * sp.ones(s, 1) * m.b.T).det()), z)
    Q = sp.Poly(sp.expand((sp.eye(s) - z * m.A).det()), z)
    p_, q_ = [P.coeff_monomial(z ** k) for k in range(n + 1)], [Q.coeff_monomial(z ** k) for k in range(n + 1)]
    R = []
    for k in range(n + 1):                                   # R·Q = P, q_0 = 1
        R.append(sp.expand(p_[k] - sum(q_[j] * R[k - j] for j in range(1, k + 1))))
    defect = R[n] - sp.Rational(1, sp.factorial(n))
    tall = "[" * r.order + "τ" + "]" * r.order
    assert is_zero(r.error_coefficients[tall] - defect)
    assert not is_zero(defect)


def test_sdirk34_order_4_in_the_field_of_cos_pi_18():
    """SDIRK34 (γ = 1/2 + cos(π/18)/√3, [HW96] IV.6): order exactly 4 — every condition of order
    ≤ 4 vanishes in ℚ(cos π/18), and an order-5 one does not (the tall tree's, by the test
    above, is the stability function's defect); B(4) as b, c satisfy the quadrature conditions."""
    m = load(METHODS / "sdirk34.json")
    r = rk_order(m)
    assert (r.order, r.B, r.C) == (4, 4, 1) and r.residuals
    assert any(not is_zero(v) for v in r.error_coefficients.values())
    assert all(is_zero(sum(m.b[i] * m.c[i] ** (k - 1) for i in range(3)) - sp.Rational(1, k)) for k in range(1, 5))


def test_gauss5_order_10_by_elementary_weights():
    """All 1205 conditions of order ≤ 10 hold, and of the 1842 of order 11 not all do."""
    r = rk_order(gauss(5))
    assert (r.order, r.B, r.C, r.D, r.effective_order) == (10, 10, 5, 5, 10) and r.residuals
    assert len(r.weights) == 1205 + 1842


def test_butcher_effective_order_5_method():
    """[B21] Sec. 5.7, tableau (5.7d): explicit, 5 stages, classical order 4, effective order 5.
    The book's starter b(t5), ..., b(t8) = 1/480, 1/960, −1/480, −1/960 (trees [τ³], [τ[τ]],
    [[τ²]], [[[τ]]]) with b = 0 on the other trees of order ≤ 5 is the computed θ."""
    r = rk_order(load(METHODS / "butcher_effective5.json"))
    assert (r.order, r.effective_order) == (4, 5) and r.residuals
    published = {"[τ³]": sp.Rational(1, 480), "[τ[τ]]": sp.Rational(1, 960),
                 "[[τ²]]": sp.Rational(-1, 480), "[[[τ]]]": sp.Rational(-1, 960)}
    theta = r.effective.theta
    assert all(theta.get(t, 0) == published.get(t, 0) for t in theta) and set(published) <= set(theta)
    assert r.effective.errors           # pinned: effective order 6 fails


def test_order_dispatch_and_latex():
    assert order(load(METHODS / "stormer_verlet.json")).order == 2
    assert order(load(METHODS / "example4_glm.json")).order == 4
    tex = order(load(METHODS / "rk4.json")).to_latex()
    assert r"\Phi(t)" in tex and r"[[\tau]]" in tex and r"\frac{1}{24}" in tex


@pytest.mark.parametrize("claims, failed", [
    ({"order": 5}, ["order"]),                       # classical order is 4, not the effective 5
    ({"order": 4, "effective_order": 4}, ["effective_order"]),
    ({"order": 4, "effective_order": 5, "stage_order": 2}, ["stage_order"]),
    ({"order": 4, "effective_order": 5}, []),
])
def test_order_claims_checked_exit_codes(tmp_path, capsys, claims, failed):
    import json

    from tableau_lab.cli import main
    data = json.loads((METHODS / "butcher_effective5.json").read_text())
    data["claims"] = claims
    f = tmp_path / "m.json"
    f.write_text(json.dumps(data))
    assert main(["verify", "--json", str(f)]) == (1 if failed else 0)
    out = json.loads(capsys.readouterr().out)
    assert out["claims"]["failed"] == failed
    assert (out["order"]["order"], out["order"]["effective_order"]) == (4, 5)
    assert out["order"]["starting_method"]["[τ³]"] == "1/480"


def test_order_cli_json_glm(capsys):
    import json

    from tableau_lab.cli import main
    assert main(["order", "--json", str(METHODS / "example4_glm.json")]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["order"] == 4 and out["order_identity_start"] == 4 and out["stage_order"] == 2
    assert out["starting_method"]["[τ]"] == ["0", "sqrt(3)/12"]


def test_principal_error_norm():
    """A^(5) of the classical RK4, ‖τ^(5)‖₂ = √1745/2880 ≈ 0.0145046 (NodePy's principal_error_norm
    gives 0.014504582343198208; Kennedy, Carpenter & Lewis, Appl. Numer. Math. 35 (2000), A^(5) =
    1.45·10⁻²); the square is the sum of the squared error coefficients."""
    r = rk_order(load(METHODS / "rk4.json"))
    assert r.principal_error_norm == sp.sqrt(1745) / 2880
    assert abs(float(r.principal_error_norm) - 0.014504582343198208) < 1e-15
    assert r.principal_error_norm ** 2 == sum(v ** 2 for v in r.error_coefficients.values())


def test_embedded_pair_dormand_prince():
    """RK5(4)7M: order 5 with A^(6) = ‖τ^(6)‖₂ = 3.99·10⁻⁴ (Dormand & Prince 1980), the embedded b̂
    of order 4 with ‖τ̂^(5)‖₂ = 1.18·10⁻³ (NodePy: 0.0011829571513510674); b̂ survives a write and
    read of the file."""
    from tableau_lab.exact.tableau_json import dumps, loads
    m = load(METHODS / "dormand_prince54.json")
    r = rk_order(m)
    assert (r.order, r.embedded.order) == (5, 4) and r.embedded.residuals
    assert abs(float(r.principal_error_norm) - 3.99e-4) < 5e-7
    assert abs(float(r.embedded.principal_error_norm) - 0.0011829571513510674) < 1e-15
    assert loads(dumps(m)).bhat == m.bhat and r.to_json()["embedded_order"] == 4
