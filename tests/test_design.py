"""Method design (tableau-lab solve) against independent facts: the 2-stage Gauss method
generated from Legendre roots, the symplectic 2-stage family written by hand, the
composition of implicit midpoint steps ([HLW06] II.4: b₁ = b₃ = 1/(2 − 2^{1/3})), Heun's
method, and the GLM43 repair checked with plain sympy matrices and with numpy eigenvectors."""
import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from tableau_lab.analysis.design import DesignError, parse_requirements, solve_file, solve_text
from tableau_lab.cli import main
from tableau_lab.exact.families import gauss
from tableau_lab.exact.field import is_zero
from tableau_lab.exact.tableau_json import load

ROOT = Path(__file__).parent.parent
DESIGN = ROOT / "methods" / "design"


def _same(M, N):
    return M.shape == N.shape and all(is_zero(x - y) for x, y in zip(M, N, strict=False))


def test_two_stage_order_4_is_gauss_both_orderings():
    res = solve_file(DESIGN / "rk2_general.json", ["order=4"])
    assert res.status == "solved" and len(res.solutions) == 2
    G = gauss(2)
    P = sp.Matrix([[0, 1], [1, 0]])                       # the other ordering of the nodes
    found = [s.method for s in res.solutions]
    assert all(not s.free for s in res.solutions)
    assert any(_same(m.A, G.A) and _same(m.b, G.b) for m in found)
    assert any(_same(m.A, P * G.A * P) and _same(m.b, P * G.b) for m in found)


def test_two_stage_symplectic_order_2_family_and_reducible_components():
    res = solve_file(DESIGN / "rk2_general.json", ["symplectic", "order=2"])
    assert res.status == "solved"
    labels = sorted(s.label for s in res.solutions)
    assert labels == ["irreducible", "reducible: stage 1 does not reach the output",
                      "reducible: stage 2 does not reach the output"]
    main_ = next(s for s in res.solutions if s.label == "irreducible")
    b2, a21 = sp.Symbol("b2", real=True), sp.Symbol("a21", real=True)
    assert set(main_.free) == {a21, b2}
    p = main_.parameters
    assert is_zero(p["a11"] - (1 - b2) / 2) and is_zero(p["a22"] - b2 / 2) and is_zero(p["b1"] - (1 - b2))
    # independent check at random rational points: M = 0, Σb = 1, Σbc = 1/2 with plain sympy
    rng = np.random.default_rng(1)
    for _ in range(3):
        vals = {b2: sp.Rational(int(rng.integers(1, 50)), 97), a21: sp.Rational(int(rng.integers(-50, 50)), 89)}
        m = main_.method
        A, b = m.A.subs(vals), m.b.subs(vals)
        M = sp.diag(*b) * A + A.T * sp.diag(*b) - b * b.T
        assert M == sp.zeros(2, 2) and sum(b) == 1 and (b.T * A * sp.ones(2, 1))[0] == sp.Rational(1, 2)


def test_dirk3_symplectic_order_4_is_the_midpoint_composition():
    res = solve_file(DESIGN / "dirk3_general.json", ["symplectic", "order=4"])
    assert res.status == "solved" and len(res.solutions) == 1
    m = res.solutions[0].method
    b1, b2 = 1 / (2 - sp.cbrt(2)), -sp.cbrt(2) / (2 - sp.cbrt(2))
    expect = sp.Matrix([[b1 / 2, 0, 0], [b1, b2 / 2, 0], [b1, b2, b1 / 2]])
    assert _same(m.A, expect) and _same(m.b, sp.Matrix([b1, b2, b1]))
    assert len(res.rejected) == 4 and all(not s.real for s in res.rejected)   # the complex roots, reported


def test_explicit_symplectic_has_no_solution_with_obstruction(capsys):
    res = solve_file(DESIGN / "erk2_general.json", ["symplectic"])
    assert res.status == "no solution" and not res.solutions
    labels = {lab for lab, _ in res.obstruction}
    assert labels == {"symplectic M[1,1]", "symplectic M[2,2]", "consistency (order 1, tree τ)"}
    assert main(["solve", str(DESIGN / "erk2_general.json"), "--require", "symplectic", "--json"]) == 1
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "no solution" and len(out["obstruction"]) == 3


def test_user_equations_give_heun():
    text = '{"name": "e2", "kind": "rk", "A": [[0, 0], ["a21", 0]], "b": ["b1", "b2"]}'
    res = solve_text(text, ["order=2", "b1 = b2"])
    assert res.status == "solved" and len(res.solutions) == 1
    assert res.solutions[0].parameters == {"a21": 1, "b1": sp.Rational(1, 2), "b2": sp.Rational(1, 2)}


def test_glm43_repair(tmp_path):
    """The two suspect entries as unknowns: the G-symplectic and parasitism-free conditions have
    exactly one solution, a21 = −11/172 (printed −11/127) and u22 equal to the text's definition."""
    res = solve_file(DESIGN / "glm43_suspects.json", ["g-symplectic", "parasitism-free"])
    assert res.status == "solved" and len(res.solutions) == 1
    sol = res.solutions[0]
    u22_text = sp.Rational(-1973, 29068) + 2 * sp.sqrt(3) * sp.sqrt(14595) / 7267
    assert sol.parameters["a21"] == sp.Rational(-11, 172) and is_zero(sol.parameters["u22"] - u22_text)
    assert all(sol.verified.values())
    lib = load(ROOT / "methods" / "glm43.json")
    assert _same(lib.A, sol.method.A) and _same(lib.U, sol.method.U)


def test_glm43_repaired_is_g_symplectic_by_plain_matrix_algebra():
    """Independent of the solver: G = diag(1, −1/4, −1/4), D = diag(b) make all three conditions
    vanish for the repaired tableau, and not for the printed one."""
    for name, ok in (("glm43.json", True), ("glm43_printed.json", False)):
        m = load(ROOT / "methods" / name)
        A, U, B, V = (sp.Matrix(x) for x in (m.A, m.U, m.B, m.V))
        G = sp.diag(1, sp.Rational(-1, 4), sp.Rational(-1, 4))
        D = sp.diag(*B.row(0))
        res = [V.T * G * V - G, D * U - B.T * G * V, D * A + A.T * D - B.T * G * B]
        assert all(sp.radsimp(sp.expand(x)) == 0 for R in res for x in R) is ok


def test_glm43_parasitism_by_numpy_eigenvectors():
    """μ = ζ⁻¹ y B U x from numpy's eigenvectors of V in float64 (a second computation)."""
    m = load(ROOT / "methods" / "glm43.json")
    U, B, V = (np.array(sp.Matrix(x).evalf(30).tolist(), dtype=float) for x in (m.U, m.B, m.V))
    zs, X = np.linalg.eig(V)
    Y = np.linalg.inv(X)
    mus = [Y[k] @ B @ U @ X[:, k] / zs[k] for k in range(3) if abs(zs[k] - 1) > 1e-9]
    assert len(mus) == 2 and max(abs(x) for x in mus) < 1e-13
    e4 = load(ROOT / "methods" / "example4_glm.json")
    U, B = (np.array(sp.Matrix(x).evalf(30).tolist(), dtype=float) for x in (e4.U, e4.B))
    assert abs(-(B @ U)[1, 1] - (1 + 2 / np.sqrt(3))) < 1e-14          # μ of Example 4 (ζ = −1)


@pytest.mark.parametrize("items, match", [
    (["symplectik"], "unknown requirement"), (["order=x"], "positive integer"), (["order=40"], "between 1 and 12"),
    ([], "no requirement"), (["a11 = __import__('os')"], "letter"),
])
def test_bad_requirements(items, match):
    with pytest.raises(DesignError, match=match):
        parse_requirements(items)


def test_equation_with_a_stray_name_is_refused():
    with pytest.raises(DesignError, match="did you mean the condition 'order'"):
        solve_file(DESIGN / "rk2_general.json", ["orderr=4"])


def test_solve_refuses_without_unknowns_and_bad_kinds(capsys, tmp_path):
    assert main(["solve", str(ROOT / "methods" / "rk4.json"), "--require", "order=4"]) == 2
    assert "no unknowns" in capsys.readouterr().err
    prk = tmp_path / "prk.json"
    prk.write_text('{"name": "p", "kind": "prk", "A": [["x"]], "b": [1], "Ahat": [[0]], "bhat": [1]}')
    assert main(["solve", str(prk), "--require", "symmetric"]) == 2
    assert "not partitioned methods" in capsys.readouterr().err
    assert main(["solve", str(DESIGN / "glm43_suspects.json"), "--require", "symmetric"]) == 1   # not symmetric
    with pytest.raises(DesignError, match="stage-order"):
        solve_file(DESIGN / "glm43_suspects.json", ["stage-order=2"])


def test_save_writes_a_library_file_whose_claims_verify(tmp_path, capsys):
    out = tmp_path / "gauss2.json"
    assert main(["solve", str(DESIGN / "rk2_general.json"), "--require", "order=4", "--save", str(out)]) == 2
    assert not out.exists()                                 # two solutions: must choose
    assert main(["solve", str(DESIGN / "rk2_general.json"), "--require", "symplectic,order=4",
                 "--save", str(out), "--solution", "1"]) == 0
    assert json.loads(out.read_text())["claims"] == {"order": 4, "symplectic": True}
    assert main(["verify", str(out)]) == 0


def test_repair_names_printed_and_correct_values(capsys):
    """The printed GLM43 with A[2,1] and U[2,2] as suspects: A[2,1] changes from the printed
    −11/127 to −11/172, U[2,2] (the text's u22) is confirmed."""
    code = main(["solve", str(ROOT / "methods" / "glm43_printed.json"), "--require", "g-symplectic",
                 "--repair", "A[2,1],U[2,2]", "--json"])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["changes"] == [{"A[2,1]": {"printed": "-11/127", "correct": "-11/172"}}]
    assert out["printed"]["U[2,2]"] == "-1973/29068 + 6*sqrt(4865)/7267"


@pytest.mark.parametrize("args, match", [
    (["--repair", "Q[1,1]"], "not a matrix"), (["--repair", "A[9,1]"], "is 4x4"), (["--repair", "A21"], "write it as"),
    (["--locate", "--within", "Z"], "not a matrix"),
])
def test_repair_bad_entries_exit_2(capsys, args, match):
    assert main(["solve", str(ROOT / "methods" / "glm43_printed.json"), "--require", "g-symplectic", *args]) == 2
    assert match in capsys.readouterr().err


def test_effective_order_recovers_butchers_method():
    """[B21] (5.7d) from its b, c and a52 = 0 alone: effective order 5 forces every other entry
    of A (10 unknowns), and the method found is the book's (methods/butcher_effective5.json)."""
    d = json.loads((ROOT / "methods" / "butcher_effective5.json").read_text())
    d["A"] = [[0] * 5] + [[f"a{i}{j}" if j < i else 0 for j in range(1, 6)] for i in range(2, 6)]
    d.pop("claims")
    res = solve_text(json.dumps(d), ["effective-order=5", "a52 = 0"])
    assert res.status == "solved" and len(res.solutions) == 1
    assert res.solutions[0].label == "irreducible"
    assert _same(res.solutions[0].method.A, load(ROOT / "methods" / "butcher_effective5.json").A)


def test_symmetric_glm_design_recovers_example4():
    """Example 4 with a21 and u12 unknown: symmetry alone forces both back to the printed values."""
    d = json.loads((ROOT / "methods" / "example4_glm.json").read_text())
    d["A"][1][0], d["U"][0][1] = "a21", "u12"
    d.pop("claims")
    res = solve_text(json.dumps(d), ["symmetric", "g-symplectic", "order=4"])
    assert res.status == "solved" and len(res.solutions) == 1
    e4 = load(ROOT / "methods" / "example4_glm.json")
    assert _same(res.solutions[0].method.A, e4.A) and _same(res.solutions[0].method.U, e4.U)


def _effective5_as_glm(unknown: str) -> dict:
    """[B21] (5.7d) written as a GLM with r = 1 (U = 1, B = bᵀ, V = 1), A[5,4] the unknown."""
    d = json.loads((ROOT / "methods" / "butcher_effective5.json").read_text())
    A = d["A"]
    A[4][3] = unknown
    return {"format": d["format"], "name": "effective order 5 as a GLM", "kind": "glm", "A": A,
            "U": [[1]] * 5, "B": [d["b"]], "V": [[1]]}


def test_identity_start_order_is_the_order_with_theta_zero():
    """For a GLM, ``order=P`` is relative to the best starting method and ``identity-start-order=P``
    fixes θ ≡ 0.  Butcher's explicit 5-stage method (as a GLM with r = 1) has order 5 with its starter
    but no explicit 5-stage method has classical order 5 (the Butcher barrier, [B21] Sec. 3.5), so with
    a₅₄ unknown: order=5 gives back the book's a₅₄ = 2 and identity-start-order=5 has no solution,
    while identity-start-order=4 does."""
    text = json.dumps(_effective5_as_glm("x"))
    best = solve_text(text, ["order=5"])
    assert best.status == "solved" and [s.parameters["x"] for s in best.solutions] == [2]
    assert solve_text(text, ["identity-start-order=5"]).status == "no solution"
    ident = solve_text(text, ["identity-start-order=4"])
    assert ident.status == "solved" and [s.parameters["x"] for s in ident.solutions] == [2]


def test_locate_exits_0_when_it_finds_the_entries(capsys):
    """`solve --locate` answers with the entries whose replacement restores solvability (GLM43
    as printed: A[2,1] is the misprint, A[1,2] the other single fix): that is a result, exit 0,
    not the 'no solution' exit 1 (issue 19)."""
    assert main(["solve", "methods/glm43_printed.json", "--require", "g-symplectic", "--locate", "--within", "A"]) == 0
    out = capsys.readouterr().out
    assert "located:" in out and "A[2,1]" in out


def test_changes_of_a_located_only_repair_says_nothing_was_solved():
    """A locate run that finds two candidate entries solves no repair (design None): ``changes()``
    says so with the located entries, instead of an AttributeError on None (found by mypy)."""
    from tableau_lab.analysis.design import repair
    r = repair(load("methods/glm43_printed.json"), ["g-symplectic"], locate=True, within=["A"])
    assert r.design is None and r.located == ("A[1,2]", "A[2,1]")     # the repair doctest's located pair
    with pytest.raises(ValueError, match=r"no repair was solved \(located: A\[1,2\], A\[2,1\]\)"):
        r.changes()
