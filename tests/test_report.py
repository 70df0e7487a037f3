"""LaTeX reports: the facts a document states are read back from its sidecar JSON and checked
against an independent exact computation; every library method's report compiles (pdflatex, as
.ci/run installs it) without errors and without overfull lines."""
import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest
import sympy as sp
from test_printed_formulas import check_report_tex

from tableau_lab.cli import main
from tableau_lab.exact.field import is_zero
from tableau_lab.exact.grammar import parse_entry
from tableau_lab.exact.tableau_json import load
from tableau_lab.proofs.latex import method_document

METHODS = Path(__file__).parent.parent / "methods"
LIBRARY = sorted(METHODS.glob("*.json"))


def test_example4_report_states_the_corrected_D_and_BtGB(tmp_path):
    assert main(["report", str(METHODS / "example4_glm.json"), "--out", str(tmp_path)]) == 0
    facts = json.loads((tmp_path / "example4_glm.report.json").read_text())
    tex = (tmp_path / "example4_glm.tex").read_text()
    assert facts["D"] == ["1/2", "1/2"]                       # the seed prints diag(1/2, -1/2): ERRATA 4
    m = load(METHODS / "example4_glm.json")
    G = sp.Matrix([[parse_entry(x) for x in row] for row in facts["G"]])
    BtGB = sp.Matrix(m.B).T * G * sp.Matrix(m.B)               # recomputed here, plain sympy
    for i in range(2):
        for j in range(2):
            assert is_zero(parse_entry(facts["BtGB"][i][j]) - BtGB[i, j])
    assert is_zero(BtGB[0, 1] + sp.sqrt(3) / 6)                 # −√3/6, not +√3/6
    assert r"- \frac{\sqrt{3}}{6}" in tex and r"\frac{1}{2}" in tex
    assert facts["order"] == 4 and facts["g_symplectic"] is True
    check_report_tex(tex, "example4_glm")        # issue 29: the backward-error terms read back exactly


@pytest.mark.parametrize("name, g_symplectic, order", [
    ("glm43", True, 4),               # seed §3.2.3: G-symplectic, order 4
    ("gauss3", True, 6),              # Gauss–Legendre, s = 3: symplectic, order 2s
    ("stormer_verlet", None, 2),      # a partitioned RK: no G-symplectic block; order 2
    ("glm43_printed", False, None),   # ERRATA 6: not G-symplectic as printed
])
def test_report_facts_are_the_published_ones(name, g_symplectic, order):
    tex, facts = method_document(load(METHODS / f"{name}.json"))
    if name == "glm43":
        check_report_tex(tex, name)              # issue 29: the backward-error terms read back exactly
    assert facts.get("g_symplectic", None) is g_symplectic
    if order is not None:
        assert facts["order"] == order


def test_missing_pdflatex_with_pdf_is_an_error(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    assert main(["report", str(METHODS / "gauss2.json"), "--out", str(tmp_path), "--pdf"]) == 2
    assert "pdflatex is not installed" in capsys.readouterr().err
    assert main(["report", str(METHODS / "gauss2.json"), "--out", str(tmp_path)]) == 0   # .tex only


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="pdflatex not installed (.ci/run installs it)")
@pytest.mark.parametrize("library", [False, True], ids=["each", "library"])
def test_every_report_compiles_without_overfull_lines(tmp_path, library):
    """Each method's report, and the library's report of them all (two tests: the workers share them)."""
    files = [str(p) for p in LIBRARY]
    assert main(["report", *files, "--out", str(tmp_path), "--pdf"] + (["--library"] if library else [])) == 0
    for log in tmp_path.glob("*.log"):
        text = log.read_text(errors="replace")
        assert not [line for line in text.splitlines() if line.startswith("! ")], log.name   # LaTeX errors
        widths = [float(w) for w in re.findall(r"Overfull \\hbox \(([\d.]+)pt too wide\)", text)]
        assert not widths or max(widths) < 1.0, (log.name, widths)
    assert len(list(tmp_path.glob("*.pdf"))) == (1 if library else len(files))
    # issue 19: no Type 3 (bitmap) fonts, every font embedded with a Unicode map (copy-paste
    # keeps ligatures), and byte-identical PDFs when an unchanged report is made again
    if shutil.which("pdffonts"):
        for pdf in tmp_path.glob("*.pdf"):
            fonts = subprocess.run(["pdffonts", str(pdf)], capture_output=True, text=True, check=True).stdout
            rows = fonts.splitlines()[2:]
            assert rows and not [r for r in rows if "Type 3" in r], (pdf.name, rows)
            assert all(r.split()[-5:-2] == ["yes", "yes", "yes"] for r in rows), (pdf.name, rows)   # emb sub uni
    if not library:
        again = tmp_path / "again"
        assert main(["report", str(METHODS / "gauss2.json"), "--out", str(again), "--pdf"]) == 0
        assert (again / "gauss2.pdf").read_bytes() == (tmp_path / "gauss2.pdf").read_bytes()


# issue 19: the order section is a proof — every condition up to p + 1 evaluated exactly, the
# differences / residuals in the facts, checked here against independent computations

def _bushy_tall(m, k):
    """Φ − 1/γ of the bushy tree [τ^(k−1)] (bᵀc^(k−1) − 1/k) and of the tall tree of order k
    (bᵀA^(k−2)c − 1/k!), plain sympy matrix algebra."""
    A, b = sp.Matrix(m.A), sp.Matrix(m.b)
    c = A * sp.ones(A.rows, 1)
    bushy = (b.T * c.applyfunc(lambda x: x ** (k - 1)))[0] - sp.Rational(1, k)
    tall = (b.T * A ** (k - 2) * c)[0] - sp.Rational(1, sp.factorial(k)) if k >= 2 else None
    return bushy, tall


_SUP = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")


@pytest.mark.parametrize("name", ["gauss2", "rk4"])
def test_rk_order_table_differences_are_zero_up_to_p_and_not_at_p_plus_1(name):
    m = load(METHODS / f"{name}.json")
    tex, facts = method_document(m)
    oc = facts["order_conditions"]
    assert (oc["checked_up_to"], oc["all_zero_up_to"]) == (5, 4) and oc["nonzero_at_p_plus_1"]
    diffs = {t: parse_entry(v) for t, v in oc["differences"].items()}
    assert len(diffs) == 1 + 1 + 2 + 4 + 9                       # every rooted tree up to order 5
    for k in range(1, 6):
        bushy, tall = _bushy_tall(m, k)
        key_b = "τ" if k == 1 else "[τ]" if k == 2 else f"[τ{str(k - 1).translate(_SUP)}]"
        assert is_zero(diffs[key_b] - bushy) and (k <= 4) == is_zero(bushy)
        if tall is not None:
            key_t = "[" * (k - 1) + "τ" + "]" * (k - 1)
            assert is_zero(diffs[key_t] - tall) and (k <= 4) == is_zero(tall)
    assert sum(1 for v in diffs.values() if v != 0) == len(oc["nonzero_at_p_plus_1"])
    assert r"\Phi(t) - 1/\gamma(t)" in tex and r"$\ne$" in tex and "so the order is exactly 4" in tex


@pytest.mark.parametrize("name", ["glm43", "example4_glm"])
def test_glm_order_conditions_vanish_up_to_4_and_not_at_5(name):
    from tableau_lab.analysis.order import order
    from tableau_lab.analysis.trees import bracket, trees_of_order
    m = load(METHODS / f"{name}.json")
    o = order(m)
    assert o.order == 4 and o.errors and all(t in {bracket(s) for s in trees_of_order(5)} for t in o.errors)
    tex, facts = method_document(m)
    oc = facts["order_conditions"]
    assert (oc["checked_up_to"], oc["all_zero_up_to"]) == (5, 4)
    assert oc["nonzero_at_p_plus_1"] and oc["theta_can_repair"] is False
    assert len(oc["residuals"]) == 8 and len(oc["solvability"]) == 9
    assert all(is_zero(parse_entry(x)) for v in oc["residuals"].values() for x in v)
    assert set(oc["nonzero_at_p_plus_1"]) == {t for t, v in oc["solvability"].items() if not is_zero(parse_entry(v))}
    assert "no starting method gives order 5" in tex


def test_a_wrong_starting_method_shows_a_nonzero_residual(monkeypatch):
    import tableau_lab.proofs.latex as latex
    from tableau_lab.analysis.glm_order import glm_order
    m = load(METHODS / "example4_glm.json")
    wrong = dict(glm_order(m).starting)
    wrong["[τ]"] = (wrong["[τ]"][0], wrong["[τ]"][1] + sp.Rational(1, 7))      # ξ₂([τ]) perturbed
    original = latex.condition_residuals
    monkeypatch.setattr(latex, "condition_residuals", lambda m, starting, upto: original(m, wrong, upto))
    tex, facts = method_document(m)
    oc = facts["order_conditions"]
    assert oc["all_zero_up_to"] == 1
    assert not all(is_zero(parse_entry(x)) for x in oc["residuals"]["[τ]"])
    assert r"\textbf{Not every $R(t)$" in tex
