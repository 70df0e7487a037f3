"""Parasitism monitor and the hard-case suite (issue 8, items 2, 4, 6): the components of the
input vector at the records, the predicted growth max Re eig(μ f′), the bound that stops a run,
scenes with a monitor, and the suite reduced to 10³ steps on the pendulum at q0 = 2.3."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

from tableau_lab.analysis.parasitism import growth_parameters, numeric_modes, predicted_growth
from tableau_lab.cli import main
from tableau_lab.exact.tableau_json import load
from tableau_lab.experiments.scene import SceneError, load_scene, run_scene
from tableau_lab.experiments.suite import growth_check
from tableau_lab.numeric.codegen import compile_problem
from tableau_lab.numeric.export import to_numeric
from tableau_lab.numeric.integrate import IntegrationError, ParasiticBoundExceeded, integrate

ROOT = Path(__file__).parent.parent
METHODS = ROOT / "methods"


def _pendulum_jacobian(q):
    return [[0.0, 1.0], [-math.cos(q), 0.0]]


def test_predicted_growth_is_max_real_part_of_mu_times_jacobian():
    ex4, g43, lf = (load(METHODS / f"{n}.json") for n in ("example4_glm", "glm43", "leapfrog"))
    mu = 1 + 2 / math.sqrt(3)
    for q in (0.3, 2.0, 2.3, 3.1):          # real eigenvalues ±√(−cos q) only beyond q = π/2
        rate = predicted_growth(ex4, _pendulum_jacobian(q))["-1"]
        assert rate == pytest.approx(mu * math.sqrt(max(0.0, -math.cos(q))), abs=1e-12)
        assert predicted_growth(lf, _pendulum_jacobian(q))["-1"] == pytest.approx(math.sqrt(max(0.0, -math.cos(q))),
                                                                                   abs=1e-12)
    assert set(predicted_growth(g43, _pendulum_jacobian(2.3)).values()) == {0.0}      # all μ = 0
    # the left eigenvectors: y V = ζ y, normalised by y x = 1
    for m in (ex4, g43, lf):
        V = np.array(m.as_glm().V.tolist(), dtype=complex)
        for p, md in zip(growth_parameters(m).items, numeric_modes(m), strict=False):
            x = np.array([complex(v) for v in p.right])
            assert np.allclose(md.left @ V, md.zeta * md.left) and abs(md.left @ x - 1) < 1e-14


def _run(name, steps, h=0.01, **kw):
    cp = compile_problem("pendulum")                       # q0 = 2.3, p0 = 0
    return integrate(to_numeric(load(METHODS / f"{name}.json")), cp, cp.y0, h, steps, invariants=("H",), **kw)


def test_monitor_records_components_and_the_compiled_loop_agrees():
    fast = _run("example4_glm", 1000, record_every=50, kernel="compiled")
    slow = _run("example4_glm", 1000, record_every=50, kernel="python")
    assert list(fast.parasitic_components) == ["-1"]
    assert fast.growth_parameters["-1"].real == pytest.approx(1 + 2 / math.sqrt(3))
    c_fast, c_slow = np.array(fast.parasitic_components["-1"]), np.array(slow.parasitic_components["-1"])
    assert len(c_fast) == len(fast.times) == 21 and np.allclose(c_fast, c_slow, rtol=1e-3, atol=1e-15)
    assert fast.predicted_growth["-1"][0] == 0 and np.all(np.diff(fast.predicted_growth["-1"]) >= 0)
    g43 = _run("glm43", 1000, record_every=50)
    assert len(g43.parasitic_components) == 2 and g43.predicted_growth == {}        # μ = 0: nothing to predict
    assert _run("gauss2", 100).parasitic_components == {}                          # RK: no parasitic modes


def test_monitor_stops_example4_with_a_clear_message_and_glm43_runs_on():
    with pytest.raises(ParasiticBoundExceeded) as info:          # raised from a record of the compiled loop
        _run("example4_glm", 5000, record_every=10, monitor=1e-3, kernel="compiled")
    exc = info.value
    msg = str(exc)
    assert msg.startswith(f"step {exc.step} (t = ") and "parasitic component ζ = -1 reached" in msg
    assert "> bound 0.001" in msg and "growth parameter μ = 2.1547" in msg and "Non-principal" not in msg
    assert isinstance(exc, IntegrationError) and 20 < exc.t < 35 and exc.value > 1e-3
    run = exc.partial
    assert run.completed == exc.step and run.times[-1] == pytest.approx(exc.t)
    assert max(abs(float(x)) for x in run.invariant_errors["H"]) < 1e-3         # stopped before H is lost
    # predicted against measured log-growth up to the stop: the same order of magnitude
    g = growth_check(run.times, run.parasitic_components["-1"], run.predicted_growth["-1"], ceiling=1e-3)
    assert g["measured"] > 15 and 0.5 < g["ratio"] < 2, g
    # GLM43 (all μ = 0) under the same bound: no stop, H kept
    g43 = _run("glm43", 5000, record_every=10, monitor=1e-3)
    assert g43.completed == 5000 and max(max(v) for v in g43.parasitic_components.values()) < 1e-9
    with pytest.raises(ValueError, match="positive"):
        _run("glm43", 10, monitor=0)


MONITORED = {"format": "tableau_lab/scene/1", "name": "mon", "problem": "pendulum", "h": "1/100", "steps": 4000,
             "record_every": 20, "monitor": "1/1000", "plots": ["invariants", "parasitic"],
             "runs": [{"method": str(METHODS / "example4_glm.json")}, {"method": str(METHODS / "glm43.json")}]}


def _scene(tmp_path, **over):
    (tmp_path / "monitored.json").write_text(json.dumps({**MONITORED, **over}))
    return tmp_path / "monitored.json"


def test_scene_monitor_key_stops_a_run_and_keeps_the_scene_complete(tmp_path):
    meta = run_scene(_scene(tmp_path), out_root=tmp_path / "out", progress=False)
    ex4, g43 = meta["runs"]
    assert meta["complete"] and meta["monitor"] == 1e-3
    assert ex4["status"] == "stopped" and "reached" in ex4["message"] and ex4["t_end"] < 40
    assert g43["status"] == "completed" and g43["parasitic_modes"][0]["mu"] == "0"
    data = np.load(tmp_path / "out" / "mon" / "data.npz")
    assert {"run0_parasitic_0", "run0_predicted_0", "run1_parasitic_0", "run1_parasitic_1"} <= set(data)
    assert "run1_predicted_0" not in data
    assert (tmp_path / "out" / "mon" / "mon_parasitic.png").exists()


@pytest.mark.parametrize("value, match", [("-1", "positive bound"), (0.001, "exact strings"), ("x", "monitor")])
def test_bad_monitor_refused(tmp_path, value, match):
    with pytest.raises(SceneError, match=match):
        load_scene(_scene(tmp_path, monitor=value))


def test_reduced_suite(tmp_path, capsys):
    """The suite at 10³ steps on the seed's case: table shape, claims, files."""
    out = tmp_path / "suite"
    code = main(["suite", str(ROOT / "reports" / "suite"), "--out", str(out), "--steps", "1000",
                 "--only", "suite_pendulum_q23", "--workers", "1", "--json"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0, summary["claims"]
    rows = summary["rows"]
    assert len(rows) == 20 and {r["file"] for r in rows} == {
        "gauss2", "gauss3", "implicit_midpoint", "stormer_verlet", "symplectic_euler", "leapfrog", "example4_glm",
        "glm43", "glm4_symmetric", "glm6_moonshot"}
    assert {tuple(r["projection"]) for r in rows} == {(), ("H",)}
    assert all(r["steps"] == 1000 for r in rows)     # t = 10: before any blow-up
    # every run completed; symplectic Euler (order 1) at h = 1/100 oscillates in energy by 1.01 % of |H0|
    # (6.7e-3 of 0.666): just past limits.DEGRADED (issue 29), so "degraded", the reason named
    assert all(r["status"] == "completed" or (r["status"] == "degraded" and r["file"] == "symplectic_euler"
                                              and "H drifted" in r["message"]) for r in rows), \
        [(r["label"], r["status"]) for r in rows if r["status"] != "completed"]
    by = {(r["file"], bool(r["projection"])): r for r in rows}
    ex4, g43 = by["example4_glm", False], by["glm43", False]
    assert complex(ex4["mu"][0]).real > 2 and ex4["growth"]["measured"] > 5 and ex4["growth"]["agree"]
    assert g43["mu"] == ["0", "0"] and g43["growth"] is None and g43["max_parasitic"] < 1e-10
    assert by["gauss2", True]["max_H_error"] < 1e-13 and by["gauss2", False]["max_parasitic"] is None
    assert by["glm4_symmetric", False]["mu"] == ["0", "0"] and by["glm4_symmetric", False]["max_parasitic"] < 1e-10
    assert [c["holds"] for c in summary["claims"]] == [True, True, True, True]
    assert "6 runs of glm43, glm4_symmetric, glm6_moonshot" in summary["claims"][-1]["detail"]
    assert {p.name for p in out.iterdir()} >= {"summary.json", "summary.md", "suite_energy.png",
                                               "suite_time_to_failure.png", "suite_pendulum_q23"}
    table = (out / "summary.md").read_text()
    assert "| pendulum_q23 | example4_glm | — | completed |" in table and "## Claims" in table
    assert main(["suite", str(ROOT / "reports" / "suite"), "--only", "nope", "--out", str(out)]) == 2


def test_docs_suite_tables_are_current():
    """docs/stability.md's suite tables are what benchmarks/suite_tables.py makes of the stored summary, and
    README.md quotes the summary's run count and wall time (minutes, rounded)."""
    from conftest import benchmark_script
    st = benchmark_script("suite_tables")
    summary = json.loads(st.SUMMARY.read_text())
    assert benchmark_script("doc_blocks").read_block(ROOT / "docs" / "stability.md", st.BLOCK) == st.tables(summary)
    readme = (ROOT / "README.md").read_text()
    assert f"{summary['runs']} runs, {round(summary['wall_seconds'] / 60)} minutes on 2 cores" in readme
    free = [r for r in summary["rows"] if r["file"] in ("glm43", "glm4_symmetric", "glm6_moonshot")]
    assert len(free) == 36 and all(r["status"] == "completed" for r in free)     # issue 18: no parasitic blow-up
    plain = {(r["file"], r["scene"]): r["max_H_error"] for r in free if not r["projection"]}
    assert all(plain["glm4_symmetric", sc] < plain["glm43", sc] for _, sc in plain)   # docs/design.md: all six
