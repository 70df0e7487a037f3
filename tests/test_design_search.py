"""Design search (issue 18): solution families as objects, numeric objectives checked against exact
analyses and known values, and the rediscovery of Butcher, Habib, Hill & Norton's methods P and N
from the G-symplectic family of their structure, with their published μ and imaginary intervals."""
import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from tableau_lab.analysis.family import FamilyError, families_of
from tableau_lab.analysis.method_series import error_terms, method_series
from tableau_lab.analysis.parasitism import growth_parameters
from tableau_lab.analysis.stability import stability
from tableau_lab.analysis.trees import density, symmetry, trees_of_order
from tableau_lab.exact.tableau_json import load
from tableau_lab.experiments.design_search import SearchError, search
from tableau_lab.numeric.objectives import YMAX, NumericGLM, growth, imaginary_interval, series_defects

FAMILY = "methods/design/pn_family.json"


@pytest.fixture(scope="module")
def pn():
    fams = families_of(FAMILY, ["g-symplectic"])
    assert len(fams) == 1 and [str(s) for s in fams[0].free] == ["u"]
    return fams[0]


def test_family_members_are_exact_methods(pn):
    """The member u = 1 + 2/√3 is Example 4 entry by entry; a vanishing branch condition, a float
    and an unknown name are refused."""
    m = pn.member({"u": "1 + 2*sqrt(3)/3"})
    ex4 = load("methods/example4_glm.json")
    for key in "AUBV":
        assert sp.simplify(getattr(m, key) - getattr(ex4, key)) == sp.zeros(2, 2)
    for bad in ({"u": 0}, {"u": 0.5}, {"v": 1}, {}):
        with pytest.raises(FamilyError):
            pn.member(bad)


@pytest.mark.parametrize("name", ["glm43", "example4_glm", "rk4", "gauss2", "lobatto_iiic3"])
def test_numeric_objectives_match_exact_analyses(name):
    m = load(f"methods/{name}.json")
    g = NumericGLM.of(m)
    exact = stability(m).bounded_radius
    y = imaginary_interval(g)
    assert (y == YMAX) if exact == sp.oo or exact >= YMAX else abs(y - float(exact)) < 1e-8
    if m.kind == "glm":
        mus = sorted(complex(sp.N(p.mu, 20)).real for p in growth_parameters(m).items)
        assert np.allclose(sorted(x.real for x in growth(g)), mus, atol=1e-12)
    phi = method_series(m, 5).phi
    p = 4
    err = float(sp.sqrt(sum(((phi[t] - sp.Rational(1, density(t))) / symmetry(t)) ** 2 for t in trees_of_order(5))))
    residual, e = series_defects(g, p)
    assert residual < 1e-12 and abs(e - err) < 1e-12


def test_rk4_imaginary_interval_is_2_sqrt_2():
    """|R(iy)| ≤ 1 for RK4 exactly when y ≤ 2√2 (a classical fact, independent of our exact code)."""
    assert abs(imaginary_interval(NumericGLM.of(load("methods/rk4.json"))) - 2 * np.sqrt(2)) < 1e-9


def test_rediscovers_p_and_n(pn):
    """Maximising Y* over the family under order = 4 returns P (Y* = ∞, μ = 1 + 2/√3) and N
    (μ = 1 − 2/√3 ≈ −0.155, Y* ≈ 2.060 [BHHN14]), both certified exactly."""
    res = search(pn, maximize="imaginary-interval", constraints=("order=4",), box=(-3.0, 3.0), seed=1)
    cert = [c for c in res.candidates if c.certified is not None]
    assert len(cert) == 2
    P, N = cert
    assert sp.simplify(P.exact["u"] - (1 + 2 * sp.sqrt(3) / 3)) == 0 and P.verified["imaginary interval"] == sp.oo
    assert sp.simplify(N.exact["u"] - (1 - 2 * sp.sqrt(3) / 3)) == 0
    assert P.verified["order"] == N.verified["order"] == 4
    assert abs(float(N.verified["mu"][0]) + 0.1547) < 1e-4
    assert abs(float(N.verified["imaginary interval"]) - 2.060) < 1e-3
    assert N.verified["order with θ ≡ 0"] == 4
    float_norm = series_defects(NumericGLM.of(N.certified), 4)[1]          # the float objective
    assert abs(float(N.verified["error norm"]) - float_norm) < 1e-12


def test_rational_snap_certifies_without_constraints(pn):
    """On this family μ = u exactly (so no member is parasitism-free: u = 0 makes G singular).  Minimising
    |μ| over the box [1/2, 2] ends at the edge u = 1/2, which is snapped to the rational 1/2 and certified."""
    res = search(pn, minimize="mu", box=(0.5, 2.0), samples=32, starts=2)
    best = res.candidates[0]
    assert best.certified is not None and best.exact["u"] == sp.Rational(1, 2)
    assert best.verified["mu"] == (sp.Rational(1, 2),)


def test_bad_requests(pn):
    with pytest.raises(SearchError):
        search(pn, maximize="error-norm")
    with pytest.raises(SearchError):
        search(pn, maximize="imaginary-interval", constraints=("order",), box=(1.0, 1.0))
    with pytest.raises(SearchError):
        search(pn, maximize="imaginary-interval", constraints=("bogus",))


def test_cli_design(tmp_path, capsys):
    from tableau_lab.cli import main
    out = tmp_path / "best.json"
    assert main(["design", FAMILY, "--require", "g-symplectic", "--maximize", "imaginary-interval",
                 "--constrain", "order=4", "--box=-3:3", "--seed", "1", "--samples", "32", "--starts", "2",
                 "--json", "--save", str(out)]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["candidates"][0]["certified"] and data["objectives"] == ["imaginary-interval"]
    saved = load(out)
    assert dict(saved.claims) == {"g_symplectic": True, "order": 4, "identity_start_order": 4}
    assert main(["verify", str(out)]) == 0
    capsys.readouterr()
    assert main(["design", FAMILY, "--require", "g-symplectic", "--maximize", "imaginary-interval",
                 "--box", "3:1"]) == 2
    assert main(["design", FAMILY, "--require", "g-symplectic", "--maximize", "imaginary-interval",
                 "--constrain", "order=5", "--samples", "16", "--starts", "2"]) == 1     # no member of order 5


def test_documented_design_output_is_current(capsys):
    """The `$ tableau-lab design …` block of docs/design.md is the command's output."""
    import re
    import shlex
    from pathlib import Path

    from tableau_lab.cli import main
    text = (Path(__file__).resolve().parents[1] / "docs/design.md").read_text()
    blocks = re.findall(r"```\n\$ (tableau-lab design [^\n]*)\n(.*?)```", text, re.S)
    assert blocks
    for cmd, shown in blocks:
        assert main(shlex.split(cmd)[1:]) == 0
        assert capsys.readouterr().out == shown


def test_pareto_front(pn):
    """Two objectives give the non-dominated members: Y* is capped at 20 on u > 0, where P (order 4:
    no order-4 error term) dominates every other member of the order-3 family."""
    res = search(pn, maximize="imaginary-interval", minimize="error-norm", box=(-3.0, 3.0), seed=1, certify=False)
    assert len(res.candidates) == 1
    assert abs(res.candidates[0].point[0] - (1 + 2 / np.sqrt(3))) < 1e-6
    with pytest.raises(SearchError):
        search(pn, maximize=("imaginary-interval", "real-interval"), minimize="mu")


def test_checkpoint_resumes_the_same_search(pn, tmp_path, monkeypatch):
    """An interrupted search (here: half of its finished tasks dropped from the checkpoint) resumes
    to the same result; with every task kept, a rerun computes no sample point again; another request
    ignores the file."""
    import tableau_lab.experiments.design_search as ds
    path = tmp_path / "search.json"
    kw = dict(maximize="imaginary-interval", constraints=("order=4",), box=(-3.0, 3.0), seed=1, samples=32, starts=2,
              certify=False)
    first = str(search(pn, checkpoint=path, **kw))
    data = json.loads(path.read_text())
    assert len(data["sample"]) == 32 and data["refine"]
    for stage in ("sample", "refine"):
        for k in list(data[stage])[::2]:
            del data[stage][k]
    path.write_text(json.dumps(data))
    assert str(search(pn, checkpoint=path, **kw)) == first
    monkeypatch.setattr(ds, "_evaluate", lambda item: 1 / 0)        # nothing left to evaluate
    monkeypatch.setattr(ds, "_refine", lambda item: 1 / 0)
    assert str(search(pn, checkpoint=path, **kw)) == first
    with pytest.raises(ZeroDivisionError):
        search(pn, checkpoint=path, **{**kw, "seed": 2})            # a different request starts afresh


def test_parasitism_free_rows_contain_glm43():
    """Every μ-free member of GLM43's DIRK family is B(h, q) (analysis.family.parasitism_free_rows):
    GLM43 (μ = 0, checked by analysis.parasitism) must come back exactly from q = Q = (β₂, β₃) and
    h = P Q⁻¹, P = (β₁, β₄) as quaternions, and its A and U from dirk_stages; a rational member is
    G-symplectic with G = diag(1, −1/4, −1/4) and μ = 0 (the ordinary analyses)."""
    from tableau_lab.analysis.family import _qmul, dirk_stages, glm43_structure, parasitism_free_rows
    from tableau_lab.analysis.symplectic import g_symplectic
    from tableau_lab.exact.field import is_zero
    from tableau_lab.exact.methods import GeneralLinearMethod
    g43 = load("methods/glm43.json")
    V, G = glm43_structure()
    assert all(is_zero(e) for e in V - g43.V)
    assert growth_parameters(g43).free
    B = g43.B
    P = (B[1, 0], B[2, 0], B[1, 3], B[2, 3])
    Q = (B[1, 1], B[2, 1], B[1, 2], B[2, 2])
    norm = sum(x ** 2 for x in Q)
    h = _qmul(P, (Q[0] / norm, -Q[1] / norm, -Q[2] / norm, -Q[3] / norm))
    B2 = parasitism_free_rows(h, Q)
    assert all(is_zero(e) for e in B2 - B)
    A, U = dirk_stages(B2, G, V, sp.zeros)
    assert all(is_zero(e) for e in A - g43.A) and all(is_zero(e) for e in U - g43.U)
    R = sp.Rational
    B3 = parasitism_free_rows([R(1, 3), R(-1, 2), R(2, 5), 0], [1, R(-3, 4), R(1, 7), 2])
    A3, U3 = dirk_stages(B3, G, V, sp.zeros)
    m = GeneralLinearMethod(A=A3, U=U3, B=B3, V=V)
    assert g_symplectic(m).holds and growth_parameters(m).free


def test_rediscovers_glm43_or_better_in_its_family():
    """Issue 18: started from the family that contains GLM43 (its G-symplectic DIRK structure with
    symmetric output rows, unknowns d1, b21, x, y; methods/design/glm4_symmetric_family.json, no values
    given), the search under order 4 (θ ≡ 0), μ = 0 and an explicit first stage certifies a member at least
    as good as GLM43 on every column of the Pareto table: same stages and implicit stages, order 4 / 4,
    μ = 0, G indefinite, and a larger exact Y* and smaller exact error norm than GLM43's, both computed by
    the ordinary analyses on methods/glm43.json.  The constraints determine three of the four parameters,
    so the certification snaps one to a rational and solves for the others exactly (a partial snap)."""
    from tableau_lab.analysis.symplectic import g_symplectic
    from tableau_lab.exact.field import normal_form
    fam = families_of("methods/design/glm4_symmetric_family.json", [])[0]
    assert [str(s) for s in fam.free] == ["b21", "d1", "x", "y"]
    res = search(fam, minimize="error-norm", constraints=("order=4", "parasitism-free", "explicit-first-stage"),
                 box=(-1.0, 1.0), samples=32, starts=2, seed=0)
    best = next(c for c in res.candidates if c.certified is not None)
    assert "snapped to rationals" in best.note and "solved exactly" in best.note
    m, v = best.certified, best.verified
    g43 = load("methods/glm43.json")
    err43 = sp.sqrt(normal_form(sum(e ** 2 for e in error_terms(method_series(g43, 5).phi, 5))))
    y43 = stability(g43).bounded_radius
    assert v["order"] == 4 and v["order with θ ≡ 0"] == 4 and v["G-symplectic"] and all(mu == 0 for mu in v["mu"])
    assert float(v["imaginary interval"]) > float(y43) and float(v["error norm"]) < float(err43)
    A = m.A
    assert [A[i, i] == 0 for i in range(4)] == [True, False, False, True]             # 2 implicit stages, as GLM43
    assert all(A[i, j] == 0 for i in range(4) for j in range(i + 1, 4))                # DIRK
    assert g_symplectic(m).definite is False and g_symplectic(g43).definite is False
    doc = (Path(__file__).resolve().parents[1] / "docs" / "design.md").read_text()       # the quoted values
    assert f"<!-- g43r-ystar -->{float(v['imaginary interval']):.6f}<!--" in doc and f"(GLM43: {float(y43):.6f})" in doc
    assert f"<!-- g43r-error -->{float(v['error norm']):.6g}<!--" in doc and f"(GLM43: {float(err43):.6g})" in doc


# issue 29: files ---------------------------------------------------------------------------------------------------
TAMPER = {                       # a checkpoint of this request, edited: each refused naming the file and the entry
    "sample-text": lambda d: d["sample"].update({next(iter(d["sample"])): "x"}),
    "sample-short": lambda d: d["sample"].update({next(iter(d["sample"])): [[1.0]]}),
    "sample-objectives": lambda d: d["sample"].update({next(iter(d["sample"])): [[1.0, 2.0], 0.0]}),
    "refine-text": lambda d: d["refine"].update({next(iter(d["refine"])): "x"}),
    "refine-point": lambda d: d["refine"].update({next(iter(d["refine"])): [[], None, 3]}),
    "refine-calls": lambda d: d["refine"].update({next(iter(d["refine"])): [[0.5], None, -1]}),
    "refine-scores-bool": lambda d: d["refine"].update({next(iter(d["refine"])): [[0.5], [[True], 0.0], 1]}),
}
NOT_OURS = {                     # not a checkpoint at all: refused, never replaced
    "truncated": lambda text: text[: len(text) // 2],
    "list": lambda text: "[]",
    "extra-key": lambda text: text[:-1] + ', "x": 1}',
}


@pytest.fixture(scope="module")
def checkpoint_text(pn, tmp_path_factory):
    path = tmp_path_factory.mktemp("cp") / "search.json"
    search(pn, checkpoint=path, **CHECKPOINT_KW)
    return path.read_text()


CHECKPOINT_KW = dict(maximize="imaginary-interval", constraints=("order=4",), box=(-3.0, 3.0), seed=1, samples=32,
                     starts=2, certify=False)


@pytest.mark.parametrize("case", sorted(TAMPER))
def test_tampered_checkpoint_is_refused_naming_the_entry(pn, checkpoint_text, tmp_path, case):
    """3 of 7 such files ended in an internal error (exit 3): each is a SearchError (exit 2)
    naming the file and the entry, and the file is left as it was."""
    data = json.loads(checkpoint_text)
    TAMPER[case](data)
    path = tmp_path / "search.json"
    path.write_text(json.dumps(data))
    before = path.read_bytes()
    stage = case.split("-")[0]
    with pytest.raises(SearchError, match=rf"search\.json: {stage}\["):
        search(pn, checkpoint=path, **CHECKPOINT_KW)
    assert path.read_bytes() == before


@pytest.mark.parametrize("case", sorted(NOT_OURS))
def test_a_file_that_is_not_a_checkpoint_is_not_replaced(pn, checkpoint_text, tmp_path, case):
    from tableau_lab.files import OutputRefused
    path = tmp_path / "search.json"
    path.write_text(NOT_OURS[case](checkpoint_text))
    before = path.read_bytes()
    with pytest.raises(OutputRefused, match="not made by this command"):
        search(pn, checkpoint=path, **CHECKPOINT_KW)
    assert path.read_bytes() == before
# end of issue 29: files --------------------------------------------------------------------------------------------
