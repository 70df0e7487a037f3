"""Issue 19, item 5: docs/seed_figures.md's summary table quotes the saved scene runs
(reports/<scene>/meta.json, ``max_invariant_error``).  Each measured number of the table's
"our run" column (decimals and powers of ten; integers there are names: Gauss2, GLM43, 3/8) is
compared with the run and invariant it describes, to its quoted digits (benchmarks/docs_check.py's
rule), so the page cannot drift from the data — and a scene rerun that changes a value fails here
until the page is updated."""
import json
import re
from pathlib import Path

import pytest
from conftest import benchmark_script

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "seed_figures.md"
MEASURED = re.compile(r"(?<![\w.])−?\d*\.\d+(?:e[-−]?\d+)?|(?<![\w.])−?\d+e[-−]?\d+")
# per table row (its Fig cell): what each measured number of the "our run" cell is, in order:
# (scene, run index, invariant), or None for a number that is not a saved maximum (|H0|, say)
ROWS = {
    "2.1": [("fig2_01_kepler_euler", 0, "H"), ("fig2_01_kepler_euler", 0, "L")],
    "2.2": [("fig2_01_kepler_euler", 1, "H"), ("fig2_01_kepler_euler", 1, "L")],
    "2.3": [("fig2_03_harmonic_rk", 0, "H")],
    "2.4": [("fig2_03_harmonic_rk", 1, "H"), ("fig2_03_harmonic_rk", 2, "H")],
    "2.5": [("fig2_05_glm_pendulum", 1, "H"), ("fig2_05_glm_pendulum", 0, "H")],
    "3.1/3.2": [("fig3_01_euler_pendulum", 0, "H"), ("fig3_01_euler_pendulum", 1, "H")],
    "3.3/3.4": [("fig3_03_glm_pendulum", k, "H") for k in range(4)],
    "3.5/3.6": [("fig3_05_euler_harmonic", 0, "H"), ("fig3_05_euler_harmonic", 1, "H")],
    "3.7/3.8": [("fig3_07_rk_harmonic", 0, "H"), ("fig3_07_rk_harmonic", 1, "H")],
    "3.9/3.10": [("fig3_09_srk_harmonic", 0, "H"), ("fig3_09_srk_harmonic", 1, "H")],
    "3.11": [("fig3_11_euler_kepler", 0, "H"), None],
    "3.12": [("fig3_11_euler_kepler", 1, "H"), ("fig3_11_euler_kepler", 1, "L")],
    "3.13": [("fig3_11_euler_kepler", 2, "H"), ("fig3_11_euler_kepler", 2, "L")],
    "3.14": [("fig3_14_sympl_kepler", 0, "H"), ("fig3_14_sympl_kepler", 0, "L")],
    "3.15": [("fig3_14_sympl_kepler", 1, "H"), ("fig3_14_sympl_kepler", 1, "L")],
    "3.16": [("fig3_14_sympl_kepler", 2, "H"), ("fig3_14_sympl_kepler", 2, "L")],
    "3.17": [("fig3_17_glm43_kepler", 0, "H"), ("fig3_17_glm43_kepler", 0, "L"),
             ("fig3_17_glm43_kepler", 3, "H"), ("fig3_17_glm43_kepler", 3, "L")],
    "3.18": [("fig3_17_glm43_kepler", 1, "H"), ("fig3_18_glm43_kepler_long", 0, "H")],
    "3.19": [("fig3_17_glm43_kepler", 2, "H"), ("fig3_17_glm43_kepler", 2, "L")],
}


def _table() -> dict:
    rows = {}
    for line in DOC.read_text().splitlines():
        cells = [c.strip() for c in line.replace("\\|", "¦").strip().strip("|").split("|")]
        if len(cells) == 5 and re.fullmatch(r"[23]\.\d+(/[23]\.\d+)?", cells[0]):
            rows[cells[0]] = cells[3]
    return rows


def _saved(scene, run, invariant) -> float:
    meta = json.loads((ROOT / "reports" / scene / "meta.json").read_text())
    return meta["runs"][run]["max_invariant_error"][invariant]


def test_the_table_has_every_row():
    assert set(_table()) == set(ROWS)


@pytest.mark.parametrize("fig", sorted(ROWS))
def test_table_numbers_are_the_saved_runs(fig):
    same = benchmark_script("docs_check").same_number
    quoted = [m.group().replace("−", "-").lstrip("-") for m in MEASURED.finditer(_table()[fig])]
    assert len(quoted) == len(ROWS[fig]), (fig, quoted)
    for q, where in zip(quoted, ROWS[fig]):
        if where is not None:
            assert same(q, repr(_saved(*where))), f"Fig {fig}: the page says {q}, {where} saved {_saved(*where):.3g}"
