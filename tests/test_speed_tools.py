"""Work–precision sweeps and the benchmark command: shapes, independent checks of the
reference, failures with clear messages.  No timed assertions (benchmarks are not tests)."""
import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from tableau_lab.cli import main
from tableau_lab.experiments.workprecision import load_wp_scene, reference_state, run_wp
from tableau_lab.numeric.codegen import reference
from tableau_lab.numeric.problems import get_problem

METHODS = Path(__file__).parent.parent / "methods"


def _scene(tmp_path, **over):
    d = {"format": "tableau_lab/workprecision/1", "name": "wp_t", "problem": {"name": "kepler", "set": {"e": "0.6"}},
         "T": 5, "methods": [{"method": str(METHODS / "gauss2.json"), "steps": [100, 200, 400]}],
         "peers": [{"method": "DOP853", "rtol": ["1e-6", "1e-9"]}]}
    d.update(over)
    p = tmp_path / "wp.json"
    p.write_text(json.dumps(d))
    return p


def test_dd_reference_against_kepler_equation():
    """The work–precision reference (3-stage Gauss in double-double at n and 2n steps) against the
    exact solution of the unperturbed Kepler problem (Kepler's equation at 40 digits)."""
    P = get_problem("kepler_unperturbed")
    ref, gap = reference_state(P, 10)
    exact = np.array([float(x) for x in reference(P, 10, dps=40, method="exact")])
    assert gap < 1e-12 and np.max(np.abs(ref - exact)) <= 2 * gap + 1e-15


def test_workprecision_sweep(tmp_path):
    data = run_wp(load_wp_scene(_scene(tmp_path)), out_root=tmp_path / "out", workers=1)
    out = tmp_path / "out" / "wp_t"
    assert (out / "wp_t.png").exists() and json.loads((out / "data.json").read_text())["series"]
    ours, dop = data["series"]["gauss2"], data["series"]["DOP853"]
    errs = [p["error"] for p in ours]
    # order 4: halving h divides the error by about 16
    assert all(8 < a / b < 32 for a, b in zip(errs, errs[1:], strict=False)), errs
    assert dop[1]["error"] < dop[0]["error"] and dop[1]["nfev"] > dop[0]["nfev"]
    assert all(p["invariant_error"] > 0 and p["nfev"] > 0 for p in ours + dop)


def test_workprecision_bad_scene(tmp_path, capsys):
    bad = _scene(tmp_path, peers=[{"method": "Euler", "rtol": ["1e-6"]}])
    assert main(["workprecision", str(bad), "--out", str(tmp_path / "o"), "--workers", "1"]) == 2
    assert "peers[1].method must be one of" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_bench_one_case_json(capsys):
    assert main(["bench", "--method", str(METHODS / "gauss2.json"), "--problem", "pendulum", "--steps", "2000",
                 "--reps", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert {"steps_per_second", "compile_seconds", "nfev", "max_invariant_error"} <= set(out)
    assert out["nfev"] > 2000 and out["max_invariant_error"]["H"] < 1e-9


def test_bench_step_sizes_interleaved(capsys):
    """Several --h in one command: each h's row is the single-h command's (same f-evaluations,
    same invariant error: the runs do not depend on their order), and the printed f-evaluation
    ratio is theirs; a larger step takes more sweeps of the stage iteration (Kepler, e = 0.6)."""
    single = []
    for h in ("1/100", "1/25"):
        assert main(["bench", "--method", str(METHODS / "gauss3.json"), "--problem", "kepler", "--steps", "400",
                     "--h", h, "--reps", "1", "--json"]) == 0
        single.append(json.loads(capsys.readouterr().out))
    assert main(["bench", "--method", str(METHODS / "gauss3.json"), "--problem", "kepler", "--steps", "400",
                 "--h", "1/100, 1/25", "--reps", "2", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    for one, row in zip(single, res["cases"], strict=False):
        assert row["h"] == one["h"] and row["nfev"] == one["nfev"] and row["reps"] == 2
        assert row["max_invariant_error"] == one["max_invariant_error"]
    (q,) = res["cost_ratios"]
    assert q["nfev_per_step_over_first"] == pytest.approx(single[1]["nfev"] / single[0]["nfev"], rel=1e-12)
    assert q["nfev_per_step_over_first"] > 1 and q["us_per_step_over_first"] > 0
    assert main(["bench", "--method", str(METHODS / "gauss3.json"), "--problem", "harmonic", "--steps", "400",
                 "--h", "1/100,1/2", "--reps", "1"]) in (0, 1)
    assert "cost at h = 1/2 over h = 1/100" in capsys.readouterr().out


def test_bench_dd_agrees_with_mpmath(capsys):
    """The same case at precision dd and mp:32: the invariant errors, printed as float64, are the
    same float (they agree far below its ulp; tests/test_kernels.py measures how far)."""
    res = []
    for prec in ("dd", "mp:32"):
        assert main(["bench", "--method", str(METHODS / "rk4.json"), "--problem", "kepler", "--steps", "50",
                     "--reps", "1", "--precision", prec, "--json"]) == 0
        res.append(json.loads(capsys.readouterr().out)["max_invariant_error"])
    assert res[0]["H"] == res[1]["H"] != 0


def test_speed_doc_bench_block_is_the_saved_bench():
    """docs/speed.md quotes `tableau-lab bench`'s saved tables and the goals' standing, generated
    from reports/bench/ by benchmarks/bench_block.py (no number typed by hand); a goal missed is
    named in the standing sentence."""
    from conftest import benchmark_script
    block = benchmark_script("bench_block")
    root = Path(__file__).resolve().parents[1]
    assert benchmark_script("doc_blocks").read_block(root / "docs" / "speed.md", "bench-table") == block.make()
    res = {"float64": [{"method": "gauss2", "problem": "pendulum", "over_c": 1.3, "goal": 1.0, "us_per_step": 0.1,
                        "c_us_per_step": 0.077}]}
    assert "but 2-stage Gauss on the pendulum, 1.30× the C loop" in block.standing(res)
    res["float64"][0]["over_c"] = 0.9
    assert "every row is within its goal." in block.standing(res)


def test_speed_doc_workprecision_block_is_the_saved_sweep():
    """docs/speed.md's Kepler work–precision tables and the f-evaluation winner per threshold are
    generated from reports/workprecision/wp_kepler/ by benchmarks/wp_block.py."""
    from conftest import benchmark_script
    block = benchmark_script("wp_block")
    root = Path(__file__).resolve().parents[1]
    assert benchmark_script("doc_blocks").read_block(root / "docs" / "speed.md", "wp-kepler") == block.make()
    pts = [{"nfev": 10, "invariant_error": 1e-5}, {"nfev": 20, "invariant_error": 1e-7},
           {"nfev": 40, "invariant_error": 1e-9}]
    assert [block.cheapest(pts, "nfev", t) for t in (1e-6, 1e-8, 1e-10)] == [20, 40, None]


def test_compiled_dop853_peer_is_scipys_algorithm():
    """The compiled peer (numbalsoda's DOP853, experiments/compiled_peer.py) and scipy's DOP853 are
    two implementations of Hairer's method: in the saved Kepler sweep they take about the same
    f-evaluations at each tolerance and reach errors of the same size; the compiled one is the
    faster (no Python in its loop)."""
    root = Path(__file__).resolve().parents[1]
    data = json.loads((root / "reports" / "workprecision" / "wp_kepler" / "data.json").read_text())
    scipy_ = {p["rtol"]: p for p in data["series"]["DOP853"] if "cpu" in p}
    compiled = {p["rtol"]: p for p in data["series"]["DOP853 (compiled)"] if "cpu" in p}
    common = sorted(set(scipy_) & set(compiled))
    assert len(common) >= 5
    for r in common:
        a, b = compiled[r], scipy_[r]
        assert 0.75 <= a["nfev"] / b["nfev"] <= 1.25, (r, a["nfev"], b["nfev"])
        assert 0.1 <= a["error"] / b["error"] <= 10, (r, a["error"], b["error"])
        assert a["cpu"] < b["cpu"], (r, a["cpu"], b["cpu"])
    assert all("DOP853 (compiled)" in v["peer_over_best"] for v in data["speedup"].values())


def test_compiled_peer_runs_where_numbalsoda_is_installed():
    from tableau_lab.experiments import compiled_peer
    from tableau_lab.experiments.workprecision import peer_point
    problem = get_problem("kepler", e=sp.Rational(3, 5))
    if not compiled_peer.available():
        res = compiled_peer.dop853_point(problem, 10, 1e-8, 1.0, "H")
        assert "numbalsoda is not installed" in res["failed"]
        pytest.skip("numbalsoda not installed (pip install -e '.[bench]', needs gfortran)")
    a = compiled_peer.dop853_point(problem, 10, 1e-8, 1.0, "H")
    b = peer_point("DOP853", problem, 10, 1e-8, 1.0, "H")
    assert np.max(np.abs(np.array(a["final"]) - np.array(b["final"]))) < 1e-5
    assert 0.75 <= a["nfev"] / b["nfev"] <= 1.25 and a["invariant_error"] < 1e-6


def test_readme_speed_headline_is_the_saved_sweep():
    """README's work-precision headline quotes the saved Kepler sweep: the compiled DOP853's CPU
    time over our best's, and scipy's DOP853's, over the three energy-error levels."""
    root = Path(__file__).resolve().parents[1]
    data = json.loads((root / "reports" / "workprecision" / "wp_kepler" / "data.json").read_text())
    compiled = [v["peer_over_best"]["DOP853 (compiled)"] for v in data["speedup"].values()]
    scipy_ = [r for v in data["speedup"].values() if (r := v["peer_over_best"]["DOP853"]) is not None]
    assert None not in compiled                      # the compiled peer reaches every level
    readme = " ".join((root / "README.md").read_text().split())
    assert f"{min(compiled):.1f}–{max(compiled):.1f}× the CPU time of our best method" in readme
    assert f"{min(scipy_):.0f}–{max(scipy_):.0f}× faster than scipy's DOP853" in readme
    speed_doc = " ".join((root / "docs" / "speed.md").read_text().split())
    assert f"our compiled loop looks {min(scipy_):.0f}–{max(scipy_):.0f}× faster" in speed_doc


def test_readme_bench_figures_are_the_saved_bench():
    """README's speed paragraph quotes the saved `tableau-lab bench`: 2-stage Gauss's f-evaluations
    and µs per step on the pendulum and Kepler, and the range of cold compile times."""
    root = Path(__file__).resolve().parents[1]
    res = json.loads((root / "reports" / "bench" / "bench.json").read_text())
    g2 = {r["problem"]: r for r in res["float64"] if r["method"] == "gauss2"}
    cold = [r["compile_seconds"] for r in res["float64"] if r.get("compile_seconds") is not None]
    readme = " ".join((root / "README.md").read_text().split())
    assert (f"needs {g2['pendulum']['nfev_per_step']:.2f} force evaluations per step on the pendulum and "
            f"{g2['kepler']['nfev_per_step']:.2f} on perturbed Kepler") in readme
    assert f"runs at {g2['pendulum']['us_per_step']:.3f} and {g2['kepler']['us_per_step']:.3f} µs/step" in readme
    assert f"{min(cold):.1f}–{max(cold):.1f} s, `reports/bench/bench.md`" in readme
