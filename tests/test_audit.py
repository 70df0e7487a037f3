"""``tableau-lab audit`` and ``tl.audit`` (tableau_lab/experiments/audit.py, proofs/audit.py; issue 33
item 5) on a folder made here: the shipped exact methods (their claims are the published facts:
they agree), 20-digit decimal copies of RK4 and Dormand–Prince 5(4) (order 4; 5 with embedded 4:
certified), the same with one coefficient changed in its 10th digit (the order is refuted: the
failing tree and the size of the miss, computed by hand from the change), an exact file with a
false claim (order 5 for RK4: on the bushy tree [τ⁴] Σbᵢcᵢ⁴ = 5/24 against 1/γ = 1/5, a residual
of 1/120 exactly), a bad file, and JSON that is no tableau."""
import json
import shutil
from pathlib import Path

import pytest
import sympy as sp
from test_decimal import decimal_copy, tenth_digit_changed

import tableau_lab as tl
from tableau_lab.cli import main
from tableau_lab.exact.grammar import parse_entry
from tableau_lab.experiments.audit import markdown_report

METHODS = Path("tableau_lab/methods")
#: the two slowest shipped GLMs (5.5 s and 2.5 s of G-symplecticity) are left out to keep the test fast
SLOW = ("glm4_symmetric.json", "glm6_moonshot.json")


def _write(path: Path, data) -> None:
    path.write_text(json.dumps(data) if not isinstance(data, str) else data)


@pytest.fixture(scope="module")
def corpus(tmp_path_factory):
    root = tmp_path_factory.mktemp("corpus")
    shipped = root / "shipped"
    shipped.mkdir()
    for f in sorted(METHODS.glob("*.json")):
        if f.name not in SLOW:
            shutil.copy(f, shipped / f.name)
    dec = root / "decimal"
    dec.mkdir()
    _write(dec / "rk4_20.json", decimal_copy("rk4", order=4))
    _write(dec / "dp54_20.json", decimal_copy("dormand_prince54", order=5, embedded_order=4))
    bad_rk4 = decimal_copy("rk4", order=4)
    bad_rk4["b"][0] = tenth_digit_changed(bad_rk4["b"][0])       # Σbᵢ − 1 = 1e-10
    bad_rk4["name"] = "RK4 with b1 changed"
    bad_rk4["provenance"] = {"repository": "someone/library", "commit": "0" * 40, "file": "tab.jl", "line": 3}
    _write(dec / "rk4_b1_changed.json", bad_rk4)
    bad_dp = decimal_copy("dormand_prince54", order=5)
    bad_dp["A"][2][1] = tenth_digit_changed(bad_dp["A"][2][1])   # a₃₂ += 1e-10
    bad_dp["name"] = "DP54 with a32 changed"
    _write(dec / "dp54_a32_changed.json", bad_dp)
    false = json.loads((METHODS / "rk4.json").read_text())
    false["claims"] = {"order": 5}
    false["name"] = "RK4 claimed order 5"
    _write(root / "false_claim.json", false)
    _write(root / "broken.json", '{"name": "broken", "kind": "rk", "A": [[0]], "b": [1, ')
    _write(root / "INDEX.json", {"methods": ["rk4"]})
    _write(root / "nodepy_reference.json", {"RK44": {"order": 4}})
    _write(root / "notes.json", {"comment": "no tableau here"})
    return root


@pytest.fixture(scope="module")
def result(corpus):
    return tl.audit([corpus], workers=1)


def _row(result, name):
    return next(r for r in result.rows if r.name == name)


def test_shipped_exact_methods_agree(result):
    shipped = [r for r in result.rows if r.library == "shipped"]
    assert len(shipped) == len(list(METHODS.glob("*.json"))) - len(SLOW)
    assert all(r.verdict == "agrees" and r.numbers == "exact" for r in shipped), \
        [(r.name, r.checks) for r in shipped if r.verdict != "agrees"]
    rk4 = _row(result, "classical Runge–Kutta (RK4)")
    assert rk4.found_value("order") == "4" and rk4.found_value("stage_order") == "1"
    dp = next(r for r in shipped if r.name.startswith("Dormand"))
    assert dp.found_value("embedded_order") == "4"          # found though only the order is claimed


def test_decimal_copies_are_certified(result):
    rk4 = _row(result, "classical Runge–Kutta (RK4) (20 digits)")
    assert rk4.numbers == "decimal" and rk4.verdict == "agrees" and rk4.found_value("order") == "4"
    dp = next(r for r in result.rows if r.name.startswith("Dormand") and r.numbers == "decimal")
    assert dp.verdict == "agrees"
    assert {c.prop: (c.claimed, c.found) for c in dp.checks} == {"order": ("5", "5"), "embedded_order": ("4", "4")}


def test_a_tenth_digit_change_disagrees_naming_tree_and_residual(result):
    r = _row(result, "RK4 with b1 changed")
    assert r.verdict == "DISAGREES" and r.library == "someone/library"       # the provenance's repository
    (check,) = r.disagreements
    assert (check.prop, check.claimed, check.found) == ("order", "4", "0")
    assert "tree τ" in check.evidence[0] and "[1.0000" in check.evidence[0] and "e-10" in check.evidence[0]
    dp = _row(result, "DP54 with a32 changed")
    (check,) = dp.disagreements
    assert check.found == "1" and "tree [τ]" in check.evidence[0]
    miss = float(sp.Rational(500, 1113) / 10 ** 10)            # b₃·δ
    assert f"{miss:.5e}"[:6] in check.evidence[0]


def test_a_false_exact_claim_disagrees_with_the_exact_residual(result):
    r = _row(result, "RK4 claimed order 5")
    assert r.verdict == "DISAGREES"
    (check,) = r.disagreements
    assert (check.claimed, check.found) == ("5", "4")
    # the bushy tree [τ⁴]: Σbᵢcᵢ⁴ = (1/3)(1/16)·2 + 1/6 = 5/24 against 1/γ = 1/5, a miss of 1/120
    bushy = next(e for e in check.evidence if "tree [τ⁴]" in e)
    assert parse_entry(bushy.split(" = ")[1].split(" ")[0]) == sp.Rational(5, 24) - sp.Rational(1, 5)
    assert any("conditions of order 5 fail in all" in e for e in check.evidence)


def test_bad_and_skipped_files_are_reported_and_the_rest_audited(result):
    assert [Path(b.file).name for b in result.bad] == ["broken.json"]
    assert "broken.json" in result.bad[0].message and not result.bad[0].bug
    assert sorted(Path(s.file).name for s in result.skipped) == ["INDEX.json", "nodepy_reference.json", "notes.json"]
    assert result.exit_code == 2                                # a bad file outranks the disagreements
    assert result.counts()["DISAGREES"] == 3


def test_the_budget_makes_a_method_undecided(corpus):
    r = tl.audit([corpus / "shipped" / "gauss3.json"], workers=1, seconds=0.001)
    (row,) = r.rows
    assert row.verdict == "undecided" and row.note == "budget"
    assert all(c.verdict == "undecided" and "budget" in c.evidence[0] for c in row.checks)
    assert r.exit_code == 0


def test_reports_in_every_format(result):
    text, md = str(result), markdown_report(result)
    for out in (text, md):
        assert "RK4 with b1 changed" in out and "DISAGREES" in out and "broken.json" in out
    assert "tree [τ⁴]" in text and r"tree \[τ⁴\]" in md and "1/120" in md
    from tableau_lab.proofs.audit import audit_tex
    tex = audit_tex(result)
    assert r"\begin{longtable}" in tex and r"\DeclareUnicodeCharacter{03C4}" in tex    # τ, for pdflatex
    data = result.to_json()
    assert data["counts"]["methods"] == len(result.rows) and json.dumps(data)


def test_cli_writes_inside_out_and_exits_by_verdict(corpus, tmp_path, capsys):
    out = tmp_path / "report"
    files = [str(corpus / "decimal" / "rk4_20.json"), str(corpus / "decimal" / "rk4_b1_changed.json")]
    assert main(["audit", *files, "--out", str(out), "--jobs", "2"]) == 1
    printed = capsys.readouterr().out
    assert "DISAGREES" in printed and "agrees" in printed
    assert {"audit.json", "audit.md", "audit.tex"} <= {p.name for p in out.iterdir()}
    if shutil.which("pdflatex"):                   # the LaTeX compiles (τ, ⁴, → declared for pdflatex), no overfull box
        assert (out / "audit.pdf").exists() and "Overfull" not in (out / "audit.log").read_text()
    assert not [p for p in tmp_path.iterdir() if p != out]          # nothing outside --out
    data = json.loads((out / "audit.json").read_text())
    assert [r["verdict"] for r in data["rows"]] == ["agrees", "DISAGREES"]
    assert main(["audit", files[0], "--out", str(out)]) == 0
    assert main(["audit", files[0], str(corpus / "broken.json")]) == 2
    assert "broken.json" in capsys.readouterr().err
    # never over an input: the report folder holding the file audited
    target = out / "audit.json"
    assert main(["audit", str(target), "--out", str(out)]) == 2
    assert "overwrite the input" in capsys.readouterr().err


def test_the_library_is_the_first_folder_below_the_one_given(tmp_path):
    nested = tmp_path / "libA" / "deeper"
    nested.mkdir(parents=True)
    shutil.copy(METHODS / "rk4.json", nested / "rk4.json")
    shutil.copy(METHODS / "gauss2.json", tmp_path / "gauss2.json")
    r = tl.audit([tmp_path], workers=1)
    assert sorted(row.library for row in r.rows) == sorted(["libA", tmp_path.name])


def test_nothing_to_audit_is_bad_input(tmp_path, capsys):
    _write(tmp_path / "INDEX.json", {"methods": []})
    assert main(["audit", str(tmp_path)]) == 2
    assert "no tableau file to audit" in capsys.readouterr().err
