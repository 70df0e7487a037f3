"""The Pareto table of docs/design.md (benchmarks/pareto_table.py): its exact columns, and that the
table in the docs is current.  The timed runs are not repeated here (``rows(measure_runs=False)``)."""
from pathlib import Path

import pytest
import sympy as sp
from conftest import benchmark_script

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def pareto():
    return benchmark_script("pareto_table")


@pytest.fixture(scope="module")
def table(pareto):
    rows, skipped = pareto.rows(measure_runs=False)
    assert not skipped, skipped
    return {r["method"].split(" (")[0]: r for r in rows}


def test_exact_columns(table):
    for name in ("P", "N", "GLM43", "Gauss2"):
        assert table[name]["_"]["order"] == 4 and table[name]["order"].startswith("4 /"), name
    assert table["midpoint"]["_"]["order"] == 2
    assert all(sp.simplify(mu) == 0 for mu in table["GLM43"]["_"]["mu"]) and table["GLM43"]["mu"] == "0"
    assert table["P"]["_"]["ystar"] == sp.oo and table["P"]["ystar"] == "∞"
    assert table["N"]["ystar"] == "2.0604" and abs(float(table["N"]["_"]["ystar"]) - 2.060) < 5e-4   # [BHHN14]
    assert table["Gauss2"]["mu"] == "—" and table["Gauss2"]["G"].startswith("definite")
    assert table["GLM43"]["implicit"] == "2 (DIRK)" and table["Gauss2"]["implicit"] == "2"
    g4s = table["GLM4S"]            # methods/glm4_symmetric.json: verified claims, exact Y* (tests/test_subfield.py)
    assert g4s["order"] == "4 / 4" and g4s["mu"] == "0" and g4s["implicit"] == "4 (DIRK)"
    assert g4s["ystar"] == "1.7257" and g4s["G"].startswith("indefinite")
    assert g4s["_"]["error"] < table["GLM43"]["_"]["error"] / 2
    g6 = table["GLM6M"]             # the moonshot (methods/glm6_moonshot.json, tests/test_moonshot.py)
    assert g6["order"] == "4 / 4" and g6["mu"] == "0" and g6["implicit"] == "6 (DIRK)" and g6["ystar"] == "2.0779"


def test_docs_table_is_current(pareto, table):
    inside = benchmark_script("doc_blocks").read_block(ROOT / "docs/design.md", pareto.BLOCK)
    headers, cells = pareto.parse_table(inside)
    assert [h for _, h in pareto.EXACT] == headers[:len(pareto.EXACT)]
    want = [[row[k] for k, _ in pareto.EXACT] for row in table.values()]
    assert [c[:len(pareto.EXACT)] for c in cells] == want, "rerun: " + pareto.COMMAND
