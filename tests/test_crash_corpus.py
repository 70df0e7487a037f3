"""The crashes of issue 15 on legal input, each with its verdict, checked against facts computed
here with plain sympy (independent of the analyses under test):

1. an RK method whose weights do not sum to 1 has order 0, the residual Σbᵢ − 1 shown;
2. `verify` of a tableau with free parameters decides its claims for all parameter values
   (the order that holds identically, the conditions for one more) or says why it cannot;
3. `solve` of the explicit 3-stage order-3 design input returns the family, re-verified
   (a zeroth power c₁⁰ with c₁ = 0 no longer raises "0**0" in the rational function field).
"""
import json
from pathlib import Path

import pytest
import sympy as sp

from tableau_lab.analysis.design import solve_file
from tableau_lab.analysis.order import order
from tableau_lab.analysis.rk_order import simplifying_assumptions
from tableau_lab.analysis.verify import verify
from tableau_lab.cli import main
from tableau_lab.exact.field import is_zero
from tableau_lab.exact.methods import GeneralLinearMethod, MethodError
from tableau_lab.exact.tableau_json import load, loads

ROOT = Path(__file__).parent.parent
R = sp.Rational


def _write(tmp_path, name, data):
    path = tmp_path / name
    path.write_text(json.dumps(data))
    return str(path)


def _rk_conditions_order_3(A, b):
    """Φ(t) − 1/γ(t) for the four trees of order ≤ 3, in plain sympy."""
    s = len(b)
    c = [sum(A[i][j] for j in range(s)) for i in range(s)]
    return [sum(b) - 1,
            sum(b[i] * c[i] for i in range(s)) - R(1, 2),
            sum(b[i] * c[i] ** 2 for i in range(s)) - R(1, 3),
            sum(b[i] * A[i][j] * c[j] for i in range(s) for j in range(s)) - R(1, 6)]


# ------------------------------------------------------------- 1. weights not summing to 1

ROUNDED = {"name": "rounded weights", "kind": "rk", "A": [[0, 0, 0], ["1/2", 0, 0], [-1, 2, 0]],
           "b": ["1/3", "1/3", "1/3+1/1000"]}
B99 = {"name": "b sums to 99/100", "kind": "rk", "A": [[0]], "b": ["99/100"]}


@pytest.mark.parametrize("data, weights", [(ROUNDED, [R(1, 3), R(1, 3), R(1, 3) + R(1, 1000)]),
                                           (B99, [R(99, 100)])])
def test_weights_not_summing_to_one_have_order_0(data, weights):
    m = loads(json.dumps(data))
    defect = sum(weights) - 1                       # 1/1000 and -1/100, known nonzero
    assert defect != 0
    r = order(m)
    assert r.order == 0 and r.effective_order == 0 and r.B == 0 and r.stage_order == 0
    assert r.C >= 1                                 # c = A·1: C(1) holds by construction
    assert r.residuals == {"τ": defect}
    assert f"Σbᵢ − 1 = {defect}" in str(r)
    assert r.to_json()["residuals"] == {"τ": str(defect)}
    # the same method as a GLM (V = [1], B = bᵀ) is inconsistent, not refused
    g = m.as_glm()
    assert g.B.T == sp.Matrix(weights)
    v = verify(m)
    assert v.order.order == 0 and "Σbᵢ − 1" in str(v)
    assert v.to_json()["order"]["residuals"] == {"τ": str(defect)}


def test_weights_not_summing_to_one_cli(tmp_path, capsys):
    claimed0 = _write(tmp_path, "rounded0.json", {**ROUNDED, "claims": {"order": 0}})
    claimed3 = _write(tmp_path, "rounded3.json", {**ROUNDED, "claims": {"order": 3}})
    assert main(["order", claimed0]) == 0
    out = capsys.readouterr().out
    assert "classical order 0" in out and "Σbᵢ − 1 = 1/1000" in out
    assert main(["order", "--json", claimed0]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["order"] == 0 and js["residuals"] == {"τ": "1/1000"}
    assert main(["verify", claimed0]) == 0
    assert "order = 0 (holds)" in capsys.readouterr().out
    assert main(["verify", "--json", claimed3]) == 1
    js = json.loads(capsys.readouterr().out)
    assert js["claims"]["failed"] == ["order"] and js["claims"]["found"] == {"order": 0}


def test_consistent_glm_with_a_wrong_c_is_still_refused():
    """Only a method that is not consistent at all keeps its c: Example 4 (consistent) with its
    abscissae swapped is still an error."""
    ex4 = load(ROOT / "methods" / "example4_glm.json")
    with pytest.raises(MethodError, match="c is not consistent"):
        GeneralLinearMethod(A=ex4.A, U=ex4.U, B=ex4.B, V=ex4.V, c=sp.Matrix([ex4.c[1], ex4.c[0]]))


# ------------------------------------------------------------- 2. free parameters in verify

THETA = {"name": "theta method", "kind": "rk", "A": [["theta"]], "b": [1]}
ERK2 = {"name": "explicit 2-stage family", "kind": "rk", "A": [[0, 0], ["a", 0]], "b": ["1 - 1/(2*a)", "1/(2*a)"]}
KUTTA3 = {"name": "explicit 3-stage family", "kind": "rk",
          "A": [[0, 0, 0], ["c2", 0, 0], ["c3 - c3*(c3-c2)/(c2*(2-3*c2))", "c3*(c3-c2)/(c2*(2-3*c2))", 0]],
          "b": ["1 - (3*c2+3*c3-2)/(6*c2*c3)", "(3*c3-2)/(6*c2*(c3-c2))", "(2-3*c2)/(6*c3*(c3-c2))"]}


def test_theta_method_order_1_for_all_values_and_2_exactly_at_one_half(tmp_path, capsys):
    """Φ(τ) = 1 and Φ([τ]) = θ: order 1 for every θ, order 2 exactly where θ − 1/2 = 0
    (θ = 1/2 is the implicit midpoint rule)."""
    th = sp.Symbol("theta", real=True)
    v = verify(loads(json.dumps({**THETA, "claims": {"order": 1}})))
    assert v.ok and v.order.order == 1
    (cond,) = v.next_order.values()
    assert is_zero(cond - (th - R(1, 2))) and not v.next_order_never
    assert "order 2 exactly where [τ]: theta - 1/2 = 0" in str(v)
    js = v.to_json()["order"]["for_all_parameter_values"]
    assert js["order"] == 1 and js["next_order_never"] is False
    path = _write(tmp_path, "theta2.json", {**THETA, "claims": {"order": 2}})
    assert main(["verify", path]) == 1
    assert "order = 2 (FAILS: found 1)" in capsys.readouterr().out


def test_explicit_two_stage_family_order_2_never_3(tmp_path, capsys):
    a = sp.Symbol("a", real=True)
    b = [1 - 1 / (2 * a), 1 / (2 * a)]
    assert is_zero(sum(b) - 1) and is_zero(b[1] * a - R(1, 2))   # order 2 identically
    # order 3 needs Φ([[τ]]) = b₂a₂₁c₁ = 0 to equal 1/6: never
    path = _write(tmp_path, "erk2.json", {**ERK2, "claims": {"order": 2}})
    assert main(["verify", path]) == 0
    out = capsys.readouterr().out
    assert "for all values of a: order 2; order 3 for no values" in out
    assert "order = 2 (holds for generic parameter values)" in out
    v = verify(loads(json.dumps(ERK2)))
    assert v.next_order_never and v.next_order["[[τ]]"] == -R(1, 6)


def test_kutta_two_parameter_family_has_order_3_identically(tmp_path, capsys):
    c2, c3 = sp.symbols("c2 c3", real=True)
    m = loads(json.dumps(KUTTA3))
    A = [[m.A[i, j] for j in range(3)] for i in range(3)]
    assert all(is_zero(e) for e in _rk_conditions_order_3(A, list(m.b)))
    assert m.parameters == (c2, c3)
    path = _write(tmp_path, "kutta3.json", {**KUTTA3, "claims": {"order": 3}})
    assert main(["verify", "--json", path]) == 0
    js = json.loads(capsys.readouterr().out)
    assert js["claims"]["found"] == {"order": 3}
    assert js["order"]["for_all_parameter_values"]["next_order_never"] is True   # explicit: p ≤ s


def test_partitioned_family_order_2_exactly_at_stormer_verlet():
    """Lobatto IIIA for q with (â₁₁, â₂₁) = (a, a) for p: b = b̂ = (1/2, 1/2), order 1 for all a;
    the order-2 conditions Σ bᵢâᵢⱼ = 1/2 read a − 1/2 = 0, and a = 1/2 is Störmer–Verlet (order 2)."""
    data = {"name": "prk family", "kind": "prk", "A": [[0, 0], ["1/2", "1/2"]], "b": ["1/2", "1/2"],
            "Ahat": [["a", 0], ["a", 0]], "bhat": ["1/2", "1/2"], "claims": {"order": 1}}
    a = sp.Symbol("a", real=True)
    v = verify(loads(json.dumps(data)))
    assert v.ok and v.order.order == 1 and not v.next_order_never
    assert v.next_order and all(is_zero(e - (a - R(1, 2))) for e in v.next_order.values())
    assert v.to_json()["order"]["for_all_parameter_values"]["order"] == 1


def test_parasitism_claim_with_parametric_V_is_reported_not_checked(tmp_path, capsys):
    """V = diag(1, v): its eigenvalues on the unit circle depend on v, so parasitism_free cannot
    be decided; the claim is reported as not checked (exit 1), never a traceback.  The order is:
    3 for all v, and 4 exactly where the conditions vanish, among them v = −1 (Example 4)."""
    data = json.loads((ROOT / "methods" / "example4_glm.json").read_text())
    data.update(V=[[1, 0], [0, "v"]], claims={"parasitism_free": False, "order": 3})
    del data["c"]
    path = _write(tmp_path, "ex4_v.json", data)
    assert main(["verify", "--json", path]) == 1
    js = json.loads(capsys.readouterr().out)
    assert js["claims"]["failed"] == ["parasitism_free"]
    assert "V holds the free parameter(s) v" in js["claims"]["unchecked"]["parasitism_free"]
    assert js["claims"]["found"] == {"order": 3}
    v = verify(load(path))
    vs = sp.Symbol("v", real=True)
    assert v.next_order and all(is_zero(e.subs(vs, -1)) for e in v.next_order.values())
    assert "NOT CHECKED" in str(v)


def test_glm_without_order_theory_gives_a_message(tmp_path, capsys):
    """A GLM that is not preconsistent: `order` exits 2 with the reason, `verify` reports the
    order claim as not checked."""
    path = _write(tmp_path, "nopre.json", {"name": "no u", "kind": "glm", "A": [[0]], "U": [[0]], "B": [[1]],
                                           "V": [["1/2"]], "c": [0], "claims": {"order": 1}})
    assert main(["order", path]) == 2
    assert "not preconsistent" in capsys.readouterr().err
    assert main(["verify", path]) == 1
    assert "order = 1 (NOT CHECKED: " in capsys.readouterr().out


# ------------------------------------------------------------- 3. solve: explicit 3 stages, order 3

def test_simplifying_assumptions_with_a_zero_node_and_parameters():
    """c₁ = 0 in the field of rational functions in c2, c3: B(3) for the Kutta family, C(1)."""
    B, C, D = simplifying_assumptions(loads(json.dumps(KUTTA3)))
    assert (B, C) == (3, 1)


def test_explicit_three_stage_order_3_family_solved_and_verified(capsys):
    res = solve_file(ROOT / "methods" / "design" / "erk3_general.json", ["order=3"])
    assert res.status == "solved" and not res.rejected
    assert all("0**0" not in s.label and s.verified == {"order=3": True} for s in res.solutions)
    main_ = res.solutions[0]
    assert main_.label == "irreducible" and {str(x) for x in main_.free} == {"b3", "c3"}
    for sol in res.solutions:
        A = [[sol.method.A[i, j] for j in range(3)] for i in range(3)]
        assert all(is_zero(e) for e in _rk_conditions_order_3(A, list(sol.method.b)))
    # Kutta's method (c = 0, 1/2, 1; b = 1/6, 2/3, 1/6; a32 = 2) is the member b3 = 1/6, c3 = 1
    sub = {x: {"b3": R(1, 6), "c3": 1}[str(x)] for x in main_.free}
    kutta = main_.method.A.subs(sub), main_.method.b.subs(sub)
    assert kutta[0] == sp.Matrix([[0, 0, 0], [R(1, 2), 0, 0], [-1, 2, 0]])
    assert kutta[1] == sp.Matrix([R(1, 6), R(2, 3), R(1, 6)])
    assert main(["solve", str(ROOT / "methods" / "design" / "erk3_general.json"), "--require", "order=3"]) == 0
    out = capsys.readouterr().out
    assert "0**0" not in out and "failed re-verification" not in out and "re-verified: order=3 yes" in out


def test_stage_order_requirement_with_a_zero_node():
    """C(1) written with c₁⁰ for c₁ = 0 (the same 0**0 in the design equations)."""
    res = solve_file(ROOT / "methods" / "design" / "erk3_general.json", ["order=2", "stage-order=1"])
    assert res.status == "solved"
    for sol in res.solutions:
        A = [[sol.method.A[i, j] for j in range(3)] for i in range(3)]
        assert all(is_zero(e) for e in _rk_conditions_order_3(A, list(sol.method.b))[:2])
