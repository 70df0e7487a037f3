"""Scenes: files written atomically, metadata that matches a direct run, bad scenes refused
before anything is written, failed and interrupted runs kept as data marked incomplete."""
import json
from pathlib import Path

import numpy as np
import pytest

from tableau_lab.cli import main
from tableau_lab.experiments.runs import quick_run
from tableau_lab.experiments.scene import SceneError, load_scene, run_scene

METHODS = (Path(__file__).parent.parent / "methods").resolve()


def _scene(tmp_path, **over):
    d = {"format": "tableau_lab/scene/1", "name": "t1", "problem": {"name": "kepler", "set": {"e": "0.6"}},
         "h": "1/100", "steps": 300,
         "runs": [{"method": str(METHODS / "gauss2.json")},
                  {"method": str(METHODS / "rk4.json"), "project": ["H", "L"]}],
         "record_every": 10, "plots": ["invariants", "orbit"]}
    d.update(over)
    p = tmp_path / "scene.json"
    p.write_text(json.dumps(d))
    return p


def test_scene_writes_data_meta_plots(tmp_path):
    meta = run_scene(_scene(tmp_path), out_root=tmp_path / "out", progress=False)
    out = tmp_path / "out" / "t1"
    assert meta["complete"] and (out / "data.npz").exists() and (out / "meta.json").exists()
    assert {p.name for p in out.glob("*.png")} == {"t1_invariants.png", "t1_orbit.png"}
    data = np.load(out / "data.npz")
    assert len(data["run0_t"]) == 31 and data["run0_y"].shape == (31, 4)      # 300 steps, every 10, and t = 0
    direct = quick_run(METHODS / "gauss2.json", "kepler", h=0.01, steps=300)
    assert abs(meta["runs"][0]["max_invariant_error"]["H"] - direct["max_invariant_error"]["H"]) < 1e-15
    assert meta["runs"][1]["max_invariant_error"]["L"] < 1e-14                  # projected onto H and L
    assert json.loads((out / "meta.json").read_text())["h"] == "1/100"
    assert not list(out.glob(".*"))                                            # no temporary files left


@pytest.mark.parametrize("over, match", [
    ({"problem": "nope"}, "unknown problem"),
    ({"h": "-1/100"}, "h must be a positive"),
    ({"h": 0.01}, "exact strings"),
    ({"color": "red"}, "unknown keys"),
    ({"T": "1/3"}, "exactly one of steps and T"),              # steps given too
    ({"runs": [{"method": "missing.json"}]}, "no file missing.json"),
    ({"runs": [{"method": str(METHODS / "rk4.json"), "project": ["Q"]}]}, "not invariants"),
    ({"runs": [{"method": str(METHODS / "rk4.json"), "precision": "mp:2"}]}, "precision"),
    ({"plots": ["pie"]}, "unknown plots"),
    ({"problem": {"name": "kepler", "set": {"q0": ["0", "0"]}}}, "not finite"),
    ({"name": "../evil"}, "file-name-safe"),
])
def test_bad_scenes_refused_and_nothing_written(tmp_path, capsys, over, match):
    d = _scene(tmp_path, **over)
    with pytest.raises(SceneError, match=match):
        load_scene(d)
    assert main(["run", str(d), "--out", str(tmp_path / "out")]) == 2
    assert match.split()[0] in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_failed_run_kept_as_incomplete_data(tmp_path, capsys):
    good = _scene(tmp_path, problem="pendulum", h="1/10", steps=10, runs=[{"method": str(METHODS / "gauss2.json")}])
    assert main(["run", str(good), "--out", str(tmp_path / "out")]) == 0          # an earlier complete run
    p = _scene(tmp_path, problem="pendulum", h="20", steps=10, record_every=1,
               runs=[{"method": str(METHODS / "gauss2.json")}], plots=["invariants"])
    assert main(["run", str(p), "--out", str(tmp_path / "out")]) == 1
    out = tmp_path / "out" / "t1"
    assert not (out / "data.npz").exists() and (out / "data.incomplete.npz").exists()
    assert not (out / "meta.json").exists() and not (out / "t1_orbit.png").exists()   # nothing stale left
    meta = json.loads((out / "meta.incomplete.json").read_text())
    assert meta["runs"][0]["status"] == "failed" and "step 3 (t = 60)" in meta["runs"][0]["message"]
    assert len(np.load(out / "data.incomplete.npz")["run0_t"]) == 3                 # t = 0, 20, 40


def test_ctrl_c_leaves_valid_incomplete_file(tmp_path, monkeypatch):
    from tableau_lab.numeric import kernels
    real = kernels.pure_loop

    def interrupted(prob, arith_name):          # the pure loop, interrupted during step 150
        loop = real(prob, arith_name)
        g = loop.run.__globals__
        after_step = g["after_step"]

        def after(n, *a):
            if n == 150:
                raise KeyboardInterrupt
            return after_step(n, *a)
        g["after_step"] = after
        return loop
    monkeypatch.setattr(kernels, "pure_loop", interrupted)
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "python")
    with pytest.raises(KeyboardInterrupt):
        run_scene(_scene(tmp_path), out_root=tmp_path / "out", progress=False)
    out = tmp_path / "out" / "t1"
    meta = json.loads((out / "meta.incomplete.json").read_text())
    assert meta["runs"][0]["status"] == "interrupted" and meta["runs"][0]["completed_steps"] == 149
    assert len(np.load(out / "data.incomplete.npz")["run0_t"]) == 15               # records up to step 140


def test_user_defined_problem_in_a_scene(tmp_path):
    """A problem written in the scene (safe grammar): a harmonic oscillator with k = 4, whose
    exact energy is conserved by Gauss2 to round-off, and a malicious entry refused."""
    define = {"name": "osc", "q": ["x"], "p": ["v"], "H": "v^2/2 + k*x^2/2", "parameters": {"k": "4"},
              "q0": ["1"], "p0": ["0"]}
    p = _scene(tmp_path, problem={"define": define}, runs=[{"method": str(METHODS / "gauss2.json")}],
               plots=["invariants", "state"])
    meta = run_scene(p, out_root=tmp_path / "out", progress=False)
    assert meta["complete"] and meta["runs"][0]["max_invariant_error"]["H"] < 1e-14
    bad = _scene(tmp_path, problem={"define": {**define, "H": "__import__('os').system('touch x')"}})
    with pytest.raises(SceneError, match="problem"):
        load_scene(bad)


def test_ctrl_c_in_the_compiled_loop_leaves_valid_incomplete_file(tmp_path, monkeypatch):
    """The compiled loop runs in chunks; Ctrl-C between chunks keeps the records so far."""
    from tableau_lab.numeric import kernels as K
    real = K.drive

    def drive(*a, record, **kw):
        seen = []

        def rec(n, Y):
            if len(seen) == 12:
                raise KeyboardInterrupt
            seen.append(n)
            record(n, Y)
        return real(*a, record=rec, **{**kw, "chunk": 20})
    monkeypatch.setattr(K, "drive", drive)
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "auto")                 # the compiled loop
    with pytest.raises(KeyboardInterrupt):
        run_scene(_scene(tmp_path), out_root=tmp_path / "out", progress=False)
    meta = json.loads((tmp_path / "out" / "t1" / "meta.incomplete.json").read_text())
    assert meta["runs"][0]["status"] == "interrupted"
    t = np.load(tmp_path / "out" / "t1" / "data.incomplete.npz")["run0_t"]
    assert len(t) == 13 and np.all(np.diff(t) > 0)            # t = 0 and the 12 records before the interrupt


def test_modified_energy_key_plots_H_beside_Htilde(tmp_path, capsys):
    """"modified_energy": {"terms": 2}: per run |H − H₀| and |H̃ − H̃₀| at the records; a method
    without a modified energy (RK4) is drawn with H alone and the reason, not an error."""
    p = _scene(tmp_path, problem="pendulum", steps=2000, record_every=10, plots=["invariants"],
               modified_energy={"terms": 2},
               runs=[{"method": str(METHODS / "implicit_midpoint.json")},
                     {"method": str(METHODS / "stormer_verlet.json")}, {"method": str(METHODS / "rk4.json")}])
    assert load_scene(p).modified_energy == 2
    assert main(["run", str(p), "--out", str(tmp_path / "out")]) == 0
    assert "t1_modified_energy.png" in capsys.readouterr().out
    out = tmp_path / "out" / "t1"
    meta = json.loads((out / "meta.json").read_text())
    assert meta["modified_energy"] == {"terms": 2}
    assert {q.name for q in out.glob("*.png")} == {"t1_invariants.png", "t1_modified_energy.png"}
    mid, sv, rk4 = (r["modified_energy"] for r in meta["runs"])
    for me in (mid, sv):
        assert me["powers"] == [2, 4] and me["evaluated_at"] == "y_n"
        assert me["max_abs_H_error"] > 1e-7 and me["ratio"] >= 100, me
    assert "no modified energy" in rk4["none"] and "ratio" not in rk4
    data = np.load(out / "data.npz")
    assert len(data["run1_modified_Htilde"]) == len(data["run1_t"]) == 201
    assert "run2_modified_H" in data and "run2_modified_Htilde" not in data
    # H from the states agrees with the integrator's own record of H
    assert np.max(np.abs(data["run0_modified_H"] - data["run0_H"])) < 1e-14


@pytest.mark.parametrize("value, match", [
    ({"terms": 0}, "modified_energy.terms must be an integer between 1 and 3"),
    ({"terms": 4}, "modified_energy.terms must be an integer between 1 and 3"),
    ({"terms": "2"}, "modified_energy.terms"),
    ({"terms": True}, "modified_energy.terms"),
    ({"terms": 2.0}, "modified_energy.terms"),
    ({"term": 2}, "modified_energy: unknown keys"),
    (True, "modified_energy must be an object"),
    ([2], "modified_energy must be an object"),
])
def test_modified_energy_key_bad_values_refused(tmp_path, value, match):
    p = _scene(tmp_path, problem="pendulum", modified_energy=value)
    with pytest.raises(SceneError, match=match) as info:
        load_scene(p)
    assert str(p) in str(info.value)


def test_modified_energy_key_needs_a_hamiltonian_problem(tmp_path):
    define = {"name": "decay", "y": ["x"], "f": ["-x"], "y0": ["1"]}
    p = _scene(tmp_path, problem={"define": define}, modified_energy={"terms": 1},
               runs=[{"method": str(METHODS / "gauss2.json")}], plots=["invariants"])
    with pytest.raises(SceneError, match="modified_energy: the problem decay is not Hamiltonian"):
        load_scene(p)


def test_scene_methods_by_library_and_family_name(tmp_path, monkeypatch):
    """Issue 30: a scene names methods as the README says it can — "gauss2" (a library name) and
    "gauss:2" (a family) — beside files; both are the same method as methods/gauss2.json, so their
    runs agree with the file's to the last bit (the old refusal "no file gauss2" is gone)."""
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "python")            # no cold compile: the Python loop
    p = _scene(tmp_path, problem="harmonic", steps=50, record_every=10, plots=["invariants"],
               runs=[{"method": str(METHODS / "gauss2.json")}, {"method": "gauss2"}, {"method": "gauss:2"}])
    sc = load_scene(p)
    assert [r["label"] for r in sc.runs] == ["gauss2", "gauss2", "gauss:2"]
    meta = run_scene(p, out_root=tmp_path / "out", progress=False)
    assert meta["complete"] and [r["file"] for r in meta["runs"]] == [str(METHODS / "gauss2.json"), "gauss2", "gauss:2"]
    data = np.load(tmp_path / "out" / "t1" / "data.npz")
    assert np.array_equal(data["run0_H"], data["run1_H"])
    assert np.max(np.abs(data["run0_H"] - data["run2_H"])) < 1e-15   # the family's exact tableau, rounded alike
    with pytest.raises(SceneError, match=r"runs\[1\].method: gauss:9: the number of stages"):
        load_scene(_scene(tmp_path, runs=[{"method": "gauss:9"}]))
    with pytest.raises(SceneError, match="no file gaus2 .*library method or family"):
        load_scene(_scene(tmp_path, runs=[{"method": "gaus2"}]))


def test_scene_format_doc_is_generated_from_the_schema():
    """docs/scenes.md's reference is benchmarks/scene_doc.py's text, made from the schema the
    validator uses: every key it accepts is in the doc and the doc names no other; the example
    scene of the page is a valid scene."""
    import re

    from conftest import benchmark_script

    from tableau_lab.experiments import scene as S
    from tableau_lab.numeric.problems import DEFINE_KEYS
    root = Path(__file__).resolve().parents[1]
    block = benchmark_script("doc_blocks").read_block(root / "docs" / "scenes.md", "scene-format")
    assert block == benchmark_script("scene_doc").make()
    documented = set(re.findall(r"^\| `([A-Za-z_0-9]+)` \|", block, re.M))
    from tableau_lab.experiments.scene_keys import MODIFIED_ENERGY_KEYS, WP_KEYS
    assert S.KEYS | S.RUN_KEYS | MODIFIED_ENERGY_KEYS | WP_KEYS | set(S.PLOTS) | set(DEFINE_KEYS) <= documented
    page = (root / "docs" / "scenes.md").read_text()
    example = json.loads(page.split("```json", 1)[1].split("```", 1)[0])
    assert set(example) <= S.KEYS
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "example.json"
        p.write_text(json.dumps(example))
        sc = load_scene(p)
    assert [r["label"] for r in sc.runs] == ["gauss2", "rk4", "Gauss 3"] and sc.steps == 2000
    # a key outside the schema is refused, naming the allowed ones (the schema's)
    with pytest.raises(SceneError, match="unknown keys"):
        S.load_scene(_scene(Path(tempfile.mkdtemp()), colour="red"))


def test_workprecision_keys_read_by_the_scene_table_rules(tmp_path):
    """A work-precision scene is read by the same table loop as a scene (experiments/scene_keys.py):
    its name by the scene's file-name rule, its unknown keys listed against its table, every
    optional key of its tables accepted with the documented default applied when absent."""
    from tableau_lab.experiments import scene_keys as K
    from tableau_lab.experiments.workprecision import load_wp_scene
    rk4 = str(METHODS / "rk4.json")
    base = {"format": "tableau_lab/workprecision/1", "name": "w", "problem": "harmonic", "T": 1,
            "methods": [{"method": rk4, "steps": [10]}], "peers": [{"method": "RK45", "rtol": ["1e-6"]}]}

    def load(**over):
        p = tmp_path / "wp.json"
        p.write_text(json.dumps({**base, **over}))
        return load_wp_scene(p)
    with pytest.raises(SceneError, match="name: \"../x\" is not a file-name-safe name"):
        load(name="../x")                              # the scene's rule, word for word
    with pytest.raises(SceneError, match=r"peers\[1\]: unknown keys \['colour'\] \(allowed: \['atol_factor', "):
        load(peers=[{"method": "RK45", "rtol": ["1e-6"], "colour": 1}])
    sc = load()
    assert (sc.title, sc.invariant) == ("w", "H")                       # defaults: the name, "H"
    assert sc.methods[0][2] == "rk4" and sc.peers[0][2] == 1.0           # the file stem; atol_factor 1
    full = load(title="t", notes=["a", "b"], invariant="H",
                methods=[{"method": rk4, "steps": [10, 20], "label": "RK4"}],
                peers=[{"method": "DOP853", "rtol": [1e-6, "1e-8"], "atol_factor": "1/2"}])
    assert full.methods[0][1:] == ((10, 20), "RK4") and full.peers[0] == ("DOP853", (1e-6, 1e-8), 0.5)
    documented = {k.name for table in (K.WP_SCHEMA, K.WP_METHOD_SCHEMA, K.WP_PEER_SCHEMA) for k in table}
    given = set(base) | {"title", "notes", "invariant", "label", "steps", "method", "rtol", "atol_factor"}
    assert documented == given
