"""benchmarks/nodepy_compare.py end to end on one method (the script writes the table that
docs/nodepy.md quotes): classical RK4 read from NodePy, order 4 and stage order 1 (Kutta 1901)
on both sides, the real interval end 2.785… (|R(-x)| = 1, R the degree-4 Taylor polynomial of
e^z) and the imaginary one 2√2 agreeing."""
import json
import math
import sys
import types

import pytest
from conftest import benchmark_script


def test_compare_writes_the_table(tmp_path, monkeypatch):
    nodepy = pytest.importorskip("nodepy")
    script = benchmark_script("nodepy_compare")
    fake = types.ModuleType("nodepy_set")
    fake.rk_methods = lambda: ([("RK44", nodepy.rk.loadRKM("RK44"))], [("X", "skipped for the test")])
    monkeypatch.setitem(sys.modules, "nodepy_set", fake)
    assert script.main(tmp_path) == 0
    table = (tmp_path / "compare.md").read_text()
    assert "| RK44 | 4 / 4 = | 1 / 1 = |" in table and "Skipped: X." in table
    [row] = json.loads((tmp_path / "compare.json").read_text())["rows"]
    assert row["verdicts"]["real_interval"] == row["verdicts"]["imaginary_interval"] == "="
    assert row["ours"]["imaginary_interval"] == pytest.approx(2 * math.sqrt(2), rel=1e-12)
    x = row["ours"]["real_interval"]
    assert abs(1 - x + x ** 2 / 2 - x ** 3 / 6 + x ** 4 / 24) == pytest.approx(1, abs=1e-12)
