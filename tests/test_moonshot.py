"""The moonshot block of docs/design.md (benchmarks/moonshot.py): the members it quotes are what it
says they are, checked from the quoted points alone (the search itself takes minutes and is not rerun)."""
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import benchmark_script

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def moon():
    return benchmark_script("moonshot")


@pytest.fixture(scope="module")
def block(moon):
    return benchmark_script("doc_blocks").read_block(ROOT / "docs" / "design.md", moon.BLOCK)


def _points(block) -> dict:
    return {goal: np.array([float(v) for v in pts.split(",")])
            for goal, pts in re.findall(r"^- (.+?): `([^`]+)`", block, re.M)}


def _row(block, goal) -> list:
    line = next(ln for ln in block.splitlines() if ln.startswith(f"| {goal} "))
    return [c.strip() for c in line.strip("|").split("|")]


def test_quoted_members_meet_the_conditions(moon, block):
    """Each quoted point gives a member with μ = 0 (by construction), order 4 with θ ≡ 0 (residuals of
    the underlying one-step method), and the Y*, error norm and diagonal its row states."""
    pts = _points(block)
    assert set(pts) == set(moon.GOALS)
    glm43 = moon.describe(moon.NumericGLM.of(moon.GLM43))
    for goal, x in pts.items():
        g = moon.member(x)
        v = moon.describe(g)
        assert np.max(np.abs(moon.order_residuals(g, 4))) < 1e-8, goal
        assert v["mu"] < 1e-12, goal
        row = _row(block, goal)
        assert abs(v["Y*"] - float(row[1])) < 1e-3 and abs(v["error"] / float(row[3]) - 1) < 1e-3, goal
        ok, _ = moon.GOALS[goal]
        assert ok(g), goal
    nonneg = moon.describe(moon.member(pts["largest Y*, diagonal ≥ 0"]))
    assert nonneg["Y*"] > glm43["Y*"] and np.all(nonneg["diag"] >= 0)
    wide = moon.describe(moon.member(pts[f"smallest error, Y* ≥ {moon.Y_GOAL:g}"]))
    assert wide["Y*"] >= 2 and np.min(wide["diag"]) < 0


def test_the_order_conditions_are_projected_not_assumed(moon):
    """A random (h, q) is μ-free but not of order 4: the projection is what makes it so."""
    x = np.random.default_rng(3).uniform(-1, 1, 8)
    assert moon.describe(moon.member(x))["mu"] < 1e-12
    assert np.max(np.abs(moon.order_residuals(moon.member(x), 4))) > 1e-3
    y = moon.project(x)
    assert y is not None and np.max(np.abs(moon.order_residuals(moon.member(y), 4))) < 1e-9


def test_symmetric_candidate_is_certified_and_beats_glm43(moon, capsys):
    """methods/glm4_symmetric.json (benchmarks/symmetric_member.py -- -3/20 2/5): the claims
    (G-symplectic, order 4 with θ ≡ 0, μ = 0) hold exactly through `tableau-lab verify`, and in float64 it
    has a larger Y* and real interval and a smaller error norm than GLM43 (docs/design.md)."""
    from tableau_lab.cli import main
    from tableau_lab.exact.tableau_json import load
    path = ROOT / "methods" / "glm4_symmetric.json"
    assert main(["verify", str(path)]) == 0          # the default field-degree budget suffices (degree 16)
    out = capsys.readouterr().out
    assert "(4 with θ ≡ 0)" in out and "all μ = 0" in out and "DA + AᵀD − BᵀGB = 0 exactly" in out
    new = moon.describe(moon.NumericGLM.of(load(path)))
    old = moon.describe(moon.NumericGLM.of(moon.GLM43))
    assert new["Y*"] > old["Y*"] + 0.1 and new["X*"] > old["X*"] and new["error"] < old["error"] / 2
    assert np.all(new["diag"] > 0)
    doc = (ROOT / "docs" / "design.md").read_text()
    assert f"Y* = {new['Y*']:.6f}, X* = {new['X*']:.4g}, error norm = {new['error']:.6g}" in doc


def test_work_precision_block_is_current():
    """docs/design.md's GLM4S work–precision block is what benchmarks/wp_glm4s.py makes of the stored
    sweep (reports/workprecision/wp_kepler_glm/data.json), and that sweep is the scene's: the same methods
    and step counts."""
    import json
    wp = benchmark_script("wp_glm4s")
    data = json.loads(wp.DATA.read_text())
    scene = json.loads((ROOT / "reports" / "workprecision" / "wp_kepler_glm.json").read_text())
    assert {m["label"]: m["steps"] for m in scene["methods"]} == \
        {k: [p["steps"] for p in v] for k, v in data["series"].items()}
    assert benchmark_script("doc_blocks").read_block(ROOT / "docs" / "design.md", wp.BLOCK) == wp.text(data)
