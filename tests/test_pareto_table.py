"""The Pareto table of docs/design.md (benchmarks/pareto_table.py): its exact columns, and that the
table in the docs is current.  The timed runs are not repeated here (``rows(measure_runs=False)``)."""
from pathlib import Path

import numpy as np
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


def test_moonshot_member_is_certified(table):
    """Issue 18's moonshot: methods/glm6_moonshot.json (GLM6M; benchmarks/moonshot_member.py) is G-symplectic,
    parasitism-free, of order 4 with θ ≡ 0 (its claims, checked by test_library), diagonally implicit with
    every a_ii > 0, and has an exact Y* ≥ 2 (analysis.stability), which an independent float64 scan of
    ρ(M(iy)) on a grid of 1e-5 confirms: stable (to round-off) below Y* and unstable just above it.
    The script regenerates the file's matrices exactly.  (Here, beside the table, so that its exact Y*,
    20 s of exact work, is computed once.)"""
    from tableau_lab.exact.tableau_json import load
    from tableau_lab.numeric.objectives import NumericGLM, _radii, imaginary_interval
    m = load(ROOT / "methods" / "glm6_moonshot.json")
    A = m.A
    assert all(A[i, j] == 0 for i in range(6) for j in range(i + 1, 6))
    assert all(float(A[i, i]) > 0.06 for i in range(6))
    Y = table["GLM6M"]["_"]["ystar"]        # the exact Y* (analysis.stability), computed once for the table
    assert table["GLM6M"]["_"]["m"] == m
    assert sp.N(Y, 30) > 2
    assert f"Y\\* = 8ρ = {sp.N(Y, 15)}…" in (ROOT / "docs" / "design.md").read_text()      # the quoted value
    g = NumericGLM.of(m)
    y = np.arange(0.0, float(Y) - 1e-5, 1e-5)
    assert np.max(_radii(g, 1j * y)) <= 1 + 1e-9
    assert _radii(g, np.array([1j * (float(Y) + 2e-5)]))[0] > 1 + 1e-9
    assert abs(imaginary_interval(g) - float(Y)) < 1e-8          # the search objective finds the thin band
    mm = benchmark_script("moonshot_member")
    d1, d2 = sp.Rational(-4, 15), sp.Rational(1, 2)
    c = [6851, -8265, 3241, 0, 0]
    assert mm.mu_cone(d1, d2, c) == 0
    lam = mm.lambdas(d1, d2, c)[0]
    assert mm.structure(d1, d2, c, lam).A == m.A and m.B[1, 0] == 6851 * lam
