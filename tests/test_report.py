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

from tableau_lab.cli import main
from tableau_lab.exact.field import is_zero
from tableau_lab.exact.grammar import parse_entry
from tableau_lab.exact.tableau_json import load
from tableau_lab.report.latex import method_document

METHODS = Path(__file__).parent.parent / "methods"
LIBRARY = sorted(METHODS.glob("*.json"))


def test_example4_report_states_the_corrected_D_and_BtGB(tmp_path):
    assert main(["report", str(METHODS / "example4_glm.json"), "--out", str(tmp_path)]) == 0
    facts = json.loads((tmp_path / "example4_glm.json").read_text())
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


@pytest.mark.parametrize("name, g_symplectic, order", [
    ("glm43", True, 4),               # seed §3.2.3: G-symplectic, order 4
    ("gauss3", True, 6),              # Gauss–Legendre, s = 3: symplectic, order 2s
    ("stormer_verlet", None, 2),      # a partitioned RK: no G-symplectic block; order 2
    ("glm43_printed", False, None),   # ERRATA 6: not G-symplectic as printed
])
def test_report_facts_are_the_published_ones(name, g_symplectic, order):
    _, facts = method_document(load(METHODS / f"{name}.json"))
    assert facts.get("g_symplectic", None) is g_symplectic
    if order is not None:
        assert facts["order"] == order


def test_missing_pdflatex_with_pdf_is_an_error(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    assert main(["report", str(METHODS / "gauss2.json"), "--out", str(tmp_path), "--pdf"]) == 2
    assert "pdflatex is not installed" in capsys.readouterr().err
    assert main(["report", str(METHODS / "gauss2.json"), "--out", str(tmp_path)]) == 0   # .tex only


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="pdflatex not installed (.ci/run installs it)")
def test_every_report_compiles_without_overfull_lines(tmp_path):
    files = [str(p) for p in LIBRARY]
    assert main(["report", *files, "--out", str(tmp_path), "--pdf"]) == 0
    assert main(["report", *files, "--out", str(tmp_path), "--pdf", "--library"]) == 0
    for log in tmp_path.glob("*.log"):
        text = log.read_text(errors="replace")
        assert not [line for line in text.splitlines() if line.startswith("! ")], log.name   # LaTeX errors
        widths = [float(w) for w in re.findall(r"Overfull \\hbox \(([\d.]+)pt too wide\)", text)]
        assert not widths or max(widths) < 1.0, (log.name, widths)
    assert len(list(tmp_path.glob("*.pdf"))) == len(files) + 1
    # issue 19: no Type 3 (bitmap) fonts, every font embedded with a Unicode map (copy-paste
    # keeps ligatures), and byte-identical PDFs when an unchanged report is made again
    if shutil.which("pdffonts"):
        for pdf in tmp_path.glob("*.pdf"):
            rows = subprocess.run(["pdffonts", str(pdf)], capture_output=True, text=True, check=True).stdout.splitlines()[2:]
            assert rows and not [r for r in rows if "Type 3" in r], (pdf.name, rows)
            assert all(r.split()[-5:-2] == ["yes", "yes", "yes"] for r in rows), (pdf.name, rows)   # emb sub uni
    again = tmp_path / "again"
    assert main(["report", str(METHODS / "gauss2.json"), "--out", str(again), "--pdf"]) == 0
    assert (again / "gauss2.pdf").read_bytes() == (tmp_path / "gauss2.pdf").read_bytes()
