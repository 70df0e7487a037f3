"""Issue 30, the front door: the public API at the package top (``import tableau_lab as tl``),
methods of method objects that delegate to it, the library listed, "did you mean" on unknown
names.  Checked against published values (HLW's modified equations, NodePy's numbers, Padé
approximants, the families' order formulas), not against the code's own output."""
import dataclasses
import inspect
import json
import math

import pytest
import sympy as sp

import tableau_lab as tl
from tableau_lab.cli import main
from tableau_lab.exact.tableau_json import TableauError
from tableau_lab.files import OutputRefused

z, h, y, q, p = sp.symbols("z h y q p")
DELEGATING = ("order", "stability", "imaginary_stability_interval", "principal_error_norm", "stability_function",
              "modified_equation", "modified_hamiltonian", "verify", "report", "g_symplectic", "parasitism",
              "integrate", "plot_stability_region", "plot_order_star", "plot_imaginary_axis", "error_constant",
              "ssp_coefficient")


# ------------------------------------------------------------------ the must-show lines

def test_gauss3_order_is_six():
    r = tl.load("gauss:3").order()
    assert int(r) == 6 and isinstance(int(r), int) and r.order == 6      # Gauss: order 2s ([HW96] IV.5)
    assert list(range(r)) == list(range(6))                                # __index__
    assert r == 6 and 6 == r and r != 5 and r != 6.5 and r != True  # noqa: E712 -- r == True is under test
    assert r == tl.order(tl.load("gauss3")) and r != tl.order(tl.load("gauss2"))    # results: field by field
    assert tl.order(tl.load("glm43")) == 4 and tl.order(tl.load("stormer_verlet")) == 2   # GLM, PRK results


def test_rk4_imaginary_interval_is_two_root_two_exactly():
    Y = tl.load("rk4").imaginary_stability_interval()
    assert Y == 2 * sp.sqrt(2) and isinstance(Y, sp.Expr)                  # [HW96] IV.2: |R(iy)| ≤ 1 iff |y| ≤ 2√2
    assert abs(float(Y) - 2.8284271247461903) < 1e-15
    assert tl.imaginary_stability_interval(tl.load("gauss:2")) == sp.oo
    assert tl.imaginary_stability_interval(tl.load("explicit_euler")) == 0


def test_explicit_euler_modified_equation_hlw():
    """[HLW06] §IX.1: explicit Euler's modified equation ỹ′ = f − h/2 f′f + h²(1/12 f″(f,f) + 1/3 f′f′f) + …"""
    me = tl.load("explicit_euler").modified_equation(3)
    assert set(me.terms) == {(0, "τ", 1), (1, "[τ]", sp.Rational(-1, 2)), (2, "[τ²]", sp.Rational(1, 12)),
                             (2, "[[τ]]", sp.Rational(1, 3))}
    assert "- 1/2 f'f" in str(me).replace("( -1/2", "- 1/2") and "1/12 f''(f, f) + 1/3 f'f'f" in str(me)
    # [HLW06] §IX.1 for y′ = y²: ỹ′ = y² − h y³ + 3/2 h² y⁴ − 8/3 h³ y⁵ + 31/6 h⁴ y⁶ ∓ …
    assert tl.modified_equation(tl.load("explicit_euler"), 5).expression(y ** 2, y) == sp.expand(
        y ** 2 - h * y ** 3 + sp.Rational(3, 2) * h ** 2 * y ** 4 - sp.Rational(8, 3) * h ** 3 * y ** 5
        + sp.Rational(31, 6) * h ** 4 * y ** 6)
    # y′ = λy: Euler is the exact flow of ỹ′ = log(1 + hλ)/h ỹ (an independent series)
    lam = sp.Symbol("lam")
    got = tl.modified_equation(tl.load("explicit_euler"), 6).expression(lam * y, y)
    assert sp.expand(got - sp.series(sp.log(1 + h * lam) / h, h, 0, 6).removeO() * y) == 0


def test_import_is_lazy_and_names_are_listed():
    assert set(tl._LAZY) <= set(dir(tl)) and set(tl._LAZY) <= set(tl.__all__)
    for name in tl._LAZY:
        assert getattr(tl, name) is not None
    with pytest.raises(AttributeError, match="no attribute 'nonesuch'"):
        tl.nonesuch  # noqa: B018 -- the attribute access is what must raise


def test_report_is_one_object_after_its_package_is_imported():
    import tableau_lab.proofs.latex  # a subpackage import sets an attribute of tableau_lab
    assert tl.report is tableau_lab.proofs.latex.report
    assert tl.report(tl.load("implicit_midpoint")).startswith("\\documentclass")
    assert tl.load("implicit_midpoint").report() == tl.report(tl.load("implicit_midpoint"))


# ------------------------------------------------------------------ NodePy's numbers

def test_principal_error_norm_nodepy_doc_value():
    assert tl.principal_error_norm(tl.load("rk4")) == sp.sqrt(1745) / 2880     # NodePy's error_metrics doctest
    assert tl.principal_error_norm(tl.load("explicit_euler")) == sp.Rational(1, 2)
    with pytest.raises(TypeError, match="Runge–Kutta"):
        tl.principal_error_norm(tl.load("bdf:2"))


@pytest.mark.parametrize("name", ["RK44", "Heun33", "SSP33", "BS3", "Merson43"])
def test_against_nodepy(name):
    """The same method through NodePy and through tl.load(nodepy_method): principal_error_norm and
    imaginary_stability_interval agree with NodePy's floats."""
    rk = pytest.importorskip("nodepy.runge_kutta_method")
    npm = rk.loadRKM(name)
    m = tl.load(npm)
    assert abs(float(m.principal_error_norm()) - npm.principal_error_norm()) < 1e-15
    assert abs(float(m.imaginary_stability_interval()) - npm.imaginary_stability_interval()) < 1e-12
    P, Q = npm.stability_function(mode="exact")
    R = m.stability_function()
    assert abs(complex(R(sp.Rational(-3, 7) + sp.I / 5)) - complex(P(-3 / 7 + 0.2j) / Q(-3 / 7 + 0.2j))) < 1e-13


def test_stability_function_pade_and_taylor():
    """Gauss s = 2: the (2,2) Padé approximant of e^z; RK4: the Taylor polynomial of degree 4 ([HW96] IV.3)."""
    R = tl.stability_function(tl.load("gauss:2"))
    assert sp.simplify(R.expression - (1 + z / 2 + z ** 2 / 12) / (1 - z / 2 + z ** 2 / 12)) == 0
    assert R.numerator.subs(z, 0) == R.denominator.subs(z, 0) == 1
    assert tl.stability_function(tl.load("rk4")).expression == sp.series(sp.exp(z), z, 0, 5).removeO()
    text = str(R).removeprefix("R(z) = ")
    from tableau_lab.exact.grammar import parse_entry
    parsed = parse_entry(text)                                             # the printed R(z) reads back exactly
    assert sp.cancel(parsed.subs({s: z for s in parsed.free_symbols}) - R.expression) == 0
    with pytest.raises(TypeError, match="characteristic polynomial"):
        tl.stability_function(tl.load("bdf:2"))


def test_modified_hamiltonian_midpoint_harmonic_oscillator():
    """The midpoint rule rotates (q, p) by θ with tan(θ/2) = h/2 on H = (p² + q²)/2, so its modified
    Hamiltonian is (θ/h) H = (2 arctan(h/2)/h) H = H (1 − h²/12 + h⁴/80 − …)."""
    H = (p ** 2 + q ** 2) / 2
    mh = tl.load("implicit_midpoint").modified_hamiltonian(H, 5)
    assert mh.order == 5
    exact = sp.series(2 * sp.atan(h / 2) / h, h, 0, 5).removeO() * H
    assert sp.expand(mh.expression - exact) == 0
    assert tl.modified_hamiltonian(tl.load("implicit_midpoint"), H, 5).expression == mh.expression
    with pytest.raises(TypeError, match="not evaluated"):
        tl.modified_hamiltonian(tl.load("implicit_midpoint"), "p**2/2", 3)
    # explicit Euler is not symplectic: no modified energy beyond H itself
    assert tl.load("explicit_euler").modified_hamiltonian(H, 4).order < 4


# ------------------------------------------------------------------ methods of method objects

def test_method_objects_offer_the_analyses():
    m = tl.load("gauss2")
    names = set(dir(m))
    assert set(DELEGATING) <= names
    for n in DELEGATING:
        doc = inspect.getdoc(getattr(m, n))
        assert ">>>" in doc and "tl." in doc, n
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.name = "changed"                                                 # still frozen


def test_method_methods_call_the_top_level_function(monkeypatch):
    """The one inversion: m.order() looks tl.order up by name at call time."""
    seen = []
    monkeypatch.setattr(tl, "order", lambda method, *a, **k: seen.append((method, a, k)) or "sentinel")
    m = tl.load("rk4")
    assert m.order(5, extra=1) == "sentinel" and seen == [(m, (5,), {"extra": 1})]


def test_every_public_name_has_an_example_and_a_reference():
    for name in tl._LAZY:
        doc = inspect.getdoc(getattr(tl, name)) or ""
        assert ">>>" in doc, name
        assert any(ref in doc for ref in ("[HW96]", "[HLW06]", "[B16]", "[BHHN14]", "[HNW93]", "[B21]", "[GKS11]",
                                          "docs/")), name
    import pydoc
    assert len(pydoc.render_doc(tl.order).splitlines()) > 10                 # help(tl.order) was two lines


# ------------------------------------------------------------------ load, save

def test_load_every_form(tmp_path):
    text = '{"name": "midpoint", "kind": "rk", "A": [["1/2"]], "b": [1]}'
    assert tl.load(text) == tl.load("implicit_midpoint").__class__.from_lists([["1/2"]], [1], name="midpoint")
    m = tl.load("gauss2")
    assert tl.load(m) is m
    assert tl.load("gauss", s=3) == tl.load("gauss:3")
    path = tl.save(m, tmp_path / "g.json")
    assert tl.load(str(path)) == m
    with pytest.raises(TypeError, match="not int"):
        tl.load(3)


def test_save_refuses(tmp_path):
    m = tl.load("rk4")
    target = tmp_path / "m.json"
    tl.save(m, target)
    with pytest.raises(OutputRefused, match="overwrite=True"):
        tl.save(tl.load("gauss2"), target)
    assert tl.load(str(target)) == m                                       # untouched
    tl.save(tl.load("gauss2"), target, overwrite=True)
    assert tl.load(str(target)) == tl.load("gauss2")
    (tmp_path / "d.json").mkdir()
    with pytest.raises(OutputRefused):
        tl.save(m, tmp_path / "d.json", overwrite=True)


@pytest.mark.parametrize("typed, first", [("RK4", "rk4"), ("bdf4", "bdf:4"), ("gaus:3", "gauss:3"),
                                          ("Gauss-3", "gauss3"), ("midpoint", "implicit_midpoint")])
def test_did_you_mean(typed, first):
    with pytest.raises(TableauError, match=f"did you mean {first}[ ?]"):
        tl.load(typed)


def test_did_you_mean_ssprk3_suggests_something():
    with pytest.raises(TableauError, match=r"the number of stages is missing \(write ssprk3:N, N one of 3, 4, 9"):
        tl.load("ssprk3")                                                   # a family: its sizes named
    for typed, meant in (("SSPRK3", "ssprk:3"), ("ssprk33", "ssprk3:3"), ("SSP104", "ssp104"), ("RK44", "rk4")):
        with pytest.raises(TableauError, match=f"did you mean {meant}\\?"):
            tl.load(typed)
        assert int(tl.load(meant).order()) in (3, 4)                        # and the suggestion loads
    with pytest.raises(TableauError, match="cannot read"):                 # far from every name: no guess
        tl.load("qqqqqq")


def test_cli_did_you_mean(capsys):
    assert main(["order", "RK4"]) == 2
    err = capsys.readouterr().err
    assert "did you mean rk4?" in err and "No such file" not in err


# ------------------------------------------------------------------ the library listed

def test_list_methods_rows():
    from tableau_lab.exact.library import FAMILIES, library_names
    rows = tl.list_methods()
    assert [r.name for r in rows if not r.family] == library_names()
    assert {r.name.split(":")[0] for r in rows if r.family} == set(FAMILIES)
    assert rows["gauss3"].order == "6" and rows["example4_glm"].size == "s = 2, r = 2"
    for r in rows:
        assert r.order != "?" and r.kind in ("rk", "prk", "glm"), r
    assert "| rk4 | rk | s = 4 | 4 |" in rows.markdown()


def test_family_order_formulas():
    """The published orders (Gauss 2s, Radau 2s − 1, Lobatto 2s − 2 [HW96] Table IV.5.13; SDIRK
    [HW96] IV.6; BDF k, Adams–Bashforth k, Adams–Moulton k + 1, Nyström k, Milne–Simpson k + 1 and
    4 for Simpson's rule [HNW93] III.1–2) against the order analysis of the first members."""
    from tableau_lab.analysis.catalog import FAMILY_ORDERS
    from tableau_lab.exact.library import FAMILIES
    for name, (_, formula) in FAMILY_ORDERS.items():
        built = 0
        for n in range(1, min(3, FAMILIES[name][2]) + 1):
            try:
                m = tl.load(f"{name}:{n}")
            except TableauError:
                continue                                                   # Lobatto s = 1, SDIRK s = 1
            assert int(m.order()) == formula(n), (name, n)
            built += 1
        assert built >= 1, name


def test_cli_list_same_rows(capsys):
    assert main(["list", "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == tl.list_methods().to_json()
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[2].split() == ["name", "kind", "size", "order", "source"] and "bdf:k" in out


def test_float_and_int_conversions():
    assert math.isclose(float(tl.load("stormer_verlet").imaginary_stability_interval()), 2.0)   # |hω| < 2
    assert int(tl.order(tl.load("bdf:4"))) == 4 and int(tl.order(tl.load("stormer_verlet"))) == 2


def test_readme_python_block_runs():
    """README's Python section uses only top-level names, and runs (its one failing line raises
    the error it shows)."""
    import re
    from pathlib import Path
    readme = (Path(__file__).resolve().parents[1] / "README.md").read_text()
    section = readme[readme.index("## Python API"):]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    assert "from tableau_lab" not in block and "import tableau_lab as tl" in block
    lines = block.splitlines()
    failing = [ln for ln in lines if "did you mean" in ln]
    assert len(failing) == 1
    env = {}
    exec("\n".join(ln for ln in lines if ln not in failing), env)          # our own README
    assert int(env["m"].order()) == 6 and env["d"].status == "solved"
    # the values the block's comments quote
    rk4 = env["rk4"]
    assert rk4.imaginary_stability_interval() == 2 * sp.sqrt(2) and "2.8284271247461903" in block
    assert rk4.principal_error_norm() == sp.sqrt(1745) / 2880 and "sqrt(1745)/2880" in block
    assert f"# {rk4.stability_function()}" in block
    assert [str(x.mu) for x in env["g"].parasitism().items] == ["1 + 2*sqrt(3)/3"] and "1 + 2*sqrt(3)/3" in block
    assert env["g"].verify().failed == ()
    assert env["m"].order() == 6 and type(env["ax"]).__name__ == "Axes"
    assert max(abs(env["sol"].states[-1] - [1, 0])) < 1e-6 and "back at (1, 0)" in block
    c = tl.load("bdf:4").error_constant()                 # BDF4: C₅ = -12/125 (tests/test_error_constant.py)
    assert (str(c.C), str(c.normalised)) == ("-12/125", "-1/5") and "C₅ = -12/125" in block and "-1/5" in block
    with pytest.raises(TableauError, match="did you mean rk4"):
        exec(failing[0].split("#")[0], env)


def test_load_nodepy_multistep():
    lm = pytest.importorskip("nodepy.linear_multistep_method")
    m = tl.load(lm.backward_difference_formula(3))
    ours = tl.load("bdf:3")
    assert (m.A, m.U, m.B, m.V) == (ours.A, ours.U, ours.B, ours.V) and int(m.order()) == 3


def test_printed_modified_hamiltonian_reads_back():
    """A printed formula is a claim: H̃ as printed re-parses (the problem grammar) to the exact value."""
    from tableau_lab.numeric.expressions import parse_expression
    mh = tl.load("stormer_verlet").modified_hamiltonian(p ** 2 / 2 - sp.cos(q), 3)
    text = str(mh).split("H̃ = ", 1)[1].rsplit(", free trees", 1)[0]
    assert sp.expand(parse_expression(text, names={"h": h, "q": q, "p": p}) - mh.expression) == 0
    assert mh.expression.coeff(h, 2) != 0 and mh.order == 3
