"""Issue 29, outputs and inputs on disk (tableau_lab/files.py): no command writes over one of its
inputs (each writing command: the input's bytes unchanged, exit 2 naming both paths), outside
the folder the user named, over anything but a regular file it made; every read back bounded and
checked against its writer's schema (exit 2 naming the file and the key).  Everything in
process (tableau_lab.cli.main), small, refused before any run."""
import io
import json
import os
import shutil
import time
import zipfile
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pytest

from tableau_lab.cli import main

ROOT = Path(__file__).resolve().parents[1]
METHODS = ROOT / "methods"
RK4 = METHODS / "rk4.json"


def cli(*argv, env=None, monkeypatch=None):
    """(exit code, stderr) of ``tableau-lab ARGV`` in this process."""
    err = io.StringIO()
    with redirect_stderr(err), redirect_stdout(io.StringIO()):
        try:
            code = main([str(a) for a in argv])
        except SystemExit as exc:
            code = exc.code
    return code, err.getvalue()


def refused(code, err, *paths):
    """Exit 2, one message naming every path, no traceback."""
    assert code == 2, err[-600:]
    assert "Traceback" not in err and "internal error" not in err, err[-600:]
    for p in paths:
        assert str(p) in err, (str(p), err[-600:])


def tree(folder: Path) -> dict:
    return {p: (p.read_bytes() if p.is_file() else None) for p in sorted(folder.rglob("*"))}


# ---- item 2: every writing command refuses to write over one of its inputs --------------------------------------

def test_report_beside_its_method_keeps_the_method(tmp_path, monkeypatch):
    """The issue's case: `report myglm.json --out .` beside the method.  The facts go to
    myglm.report.json; the tableau is unchanged and still loads."""
    from tableau_lab.exact.tableau_json import load
    shutil.copy(METHODS / "example4_glm.json", tmp_path / "myglm.json")
    before = (tmp_path / "myglm.json").read_bytes()
    monkeypatch.chdir(tmp_path)
    code, err = cli("report", "myglm.json", "--out", ".")
    assert code == 0, err
    assert (tmp_path / "myglm.json").read_bytes() == before
    assert load(tmp_path / "myglm.json").kind == "glm"
    facts = json.loads((tmp_path / "myglm.report.json").read_text())
    assert facts and (tmp_path / "myglm.tex").is_file()


def _rk4(tmp_path, out=None):
    """A copy of RK4 as m.json, its bytes, and an empty output folder ``out`` when named."""
    m = tmp_path / "m.json"
    shutil.copy(RK4, m)
    if out:
        (tmp_path / out).mkdir()
    return m, m.read_bytes()


@pytest.mark.parametrize("link", ["hard", "symbolic"])
def test_report_refuses_an_output_that_is_its_input(tmp_path, link):
    m, before = _rk4(tmp_path, "out")
    tex = tmp_path / "out" / "m.tex"
    os.link(m, tex) if link == "hard" else os.symlink(m, tex)
    refused(*cli("report", m, "--out", tmp_path / "out"), tex, m)
    assert m.read_bytes() == before and not (tmp_path / "out" / "m.report.json").exists()


def _scene(tmp_path, name="s", **extra):
    return json.dumps({"format": "tableau_lab/scene/1", "name": name, "problem": "harmonic", "h": "1/10", "steps": 10,
                       "runs": [{"method": str(RK4)}], **extra})


def test_run_scene_refuses_to_write_its_metadata_over_the_scene_file(tmp_path):
    """The scene file kept in its own output folder under the name the metadata gets."""
    (tmp_path / "out" / "s").mkdir(parents=True)
    scene = tmp_path / "out" / "s" / "meta.json"
    scene.write_text(_scene(tmp_path))
    before = scene.read_bytes()
    refused(*cli("run", scene, "--out", tmp_path / "out"), scene)
    assert scene.read_bytes() == before and sorted(p.name for p in scene.parent.iterdir()) == ["meta.json"]


def test_run_scene_never_removes_an_input_with_a_figure_name(tmp_path):
    """The previous run's figures are removed after a run: never an input that looks like one."""
    (tmp_path / "out" / "s").mkdir(parents=True)
    scene = tmp_path / "out" / "s" / "s_notes.png"            # <name>_* : the pattern of the scene's figures
    scene.write_text(_scene(tmp_path))
    before = scene.read_bytes()
    refused(*cli("run", scene, "--out", tmp_path / "out"), scene)
    assert scene.read_bytes() == before


def _free(tmp_path):
    """A tableau with an unknown (solve's and design's input)."""
    m = tmp_path / "m.json"
    shutil.copy(METHODS / "design" / "pn_family.json", m)
    return m


def test_solve_save_refuses_its_input(tmp_path):
    m = _free(tmp_path)
    before = m.read_bytes()
    refused(*cli("solve", m, "--require", "g-symplectic", "--save", m), m)
    assert m.read_bytes() == before


@pytest.mark.parametrize("option", ["--save", "--checkpoint"])
def test_design_refuses_to_write_over_its_input(tmp_path, option):
    m = _free(tmp_path)
    before = m.read_bytes()
    refused(*cli("design", m, "--require", "g-symplectic", "--maximize", "imaginary-interval", option, m), m)
    assert m.read_bytes() == before


@pytest.mark.parametrize("command", ["convergence", "roundoff"])
def test_convergence_and_roundoff_refuse_their_input(tmp_path, command):
    m, before = _rk4(tmp_path, "out")
    if command == "convergence":
        out, argv = tmp_path / "out" / "convergence_harmonic_float64.json", ("convergence", m, "--problem", "harmonic")
    else:
        out, argv = tmp_path / "out" / "roundoff_m_pendulum.png", ("roundoff", "--method", m, "--problem", "pendulum",
                                                                    "--h", "1/10", "--steps", "10")
    os.link(m, out)
    refused(*cli(*argv, "--out", tmp_path / "out"), out, m)
    assert m.read_bytes() == before


def test_workprecision_refuses_its_scene(tmp_path):
    folder = tmp_path / "out" / "wp"
    folder.mkdir(parents=True)
    scene = folder / "data.json"
    scene.write_text(json.dumps({"format": "tableau_lab/workprecision/1", "name": "wp", "problem": "harmonic",
                                 "T": 1, "methods": [{"method": str(RK4), "steps": [10]}]}))
    before = scene.read_bytes()
    refused(*cli("workprecision", scene, "--out", tmp_path / "out", "--workers", "1"), scene)
    assert scene.read_bytes() == before


def test_suite_refuses_its_scenes(tmp_path):
    (tmp_path / "scenes").mkdir()
    scene = tmp_path / "scenes" / "s.json"
    scene.write_text(_scene(tmp_path))
    before = scene.read_bytes()
    os.link(scene, tmp_path / "summary.md")
    refused(*cli("suite", tmp_path, "--workers", "1"), tmp_path / "summary.md", scene)
    assert scene.read_bytes() == before


def _wp_data(name="wp", series=None):
    return {"name": name, "title": "t", "problem": "harmonic", "T": 1.0, "invariant": "H",
            "reference_error_bound": 1e-30, "speedup": {},
            "series": series if series is not None else
            {"RK4": [{"steps": 10, "cpu": 0.01, "nfev": 40, "error": 1e-3, "invariant_error": 1e-4},
                     {"steps": 20, "cpu": 0.02, "nfev": 80, "error": 1e-4, "invariant_error": 1e-5}]}}


def test_replot_refuses_to_draw_over_its_data(tmp_path):
    folder = tmp_path / "wp"
    folder.mkdir()
    data = folder / "data.json"
    data.write_text(json.dumps(_wp_data()))
    before = data.read_bytes()
    os.link(data, folder / "wp.png")
    refused(*cli("replot", folder), folder / "wp.png", data)
    assert data.read_bytes() == before


def test_stability_plot_refuses_its_input(tmp_path):
    m, before = _rk4(tmp_path, "plots")
    os.link(m, tmp_path / "plots" / "m_axis.png")
    refused(*cli("stability", m, "--plot", tmp_path / "plots"), tmp_path / "plots" / "m_axis.png", m)
    assert m.read_bytes() == before


# ---- item 11: outside the folder, non-regular targets, files it did not make -------------------------------------

@pytest.mark.parametrize("name", ["../../x", "ABS", "", ".", "a/b", "x\u0000y"])
def test_replot_writes_no_figure_outside_its_folder(tmp_path, name):
    """A data.json whose "name" points elsewhere (or nowhere): exit 2 naming the file and the
    key, nothing written anywhere."""
    base = tmp_path / "a" / "b"
    folder = base / "wp"
    folder.mkdir(parents=True)
    name = str(tmp_path / "abs") if name == "ABS" else name
    (folder / "data.json").write_text(json.dumps(_wp_data(name)))
    before = tree(tmp_path)
    code, err = cli("replot", folder)
    refused(code, err, folder / "data.json")
    assert "name" in err and tree(tmp_path) == before


@pytest.mark.parametrize("kind", ["fifo", "directory", "symlink"])
@pytest.mark.parametrize("command", ["solve", "design", "checkpoint"])
def test_save_and_checkpoint_refuse_a_target_that_is_not_a_regular_file(tmp_path, kind, command):
    """`solve --save`, `design --save`, `--checkpoint` onto a FIFO, a folder or a symbolic link:
    exit 2 before any work, the target as it was (a FIFO stays a FIFO)."""
    m = _free(tmp_path)
    target = tmp_path / "target"
    if kind == "fifo":
        os.mkfifo(target)
    elif kind == "directory":
        target.mkdir()
    else:
        (tmp_path / "elsewhere.json").write_text("{}")
        os.symlink(tmp_path / "elsewhere.json", target)
    argv = (["solve", m, "--require", "g-symplectic", "--save", target] if command == "solve" else
            ["design", m, "--require", "g-symplectic", "--maximize", "imaginary-interval",
             "--save" if command == "design" else "--checkpoint", target])
    t0 = time.perf_counter()
    refused(*cli(*argv), target)
    assert time.perf_counter() - t0 < 10
    assert {"fifo": target.is_fifo, "directory": target.is_dir, "symlink": target.is_symlink}[kind]()
    if kind == "symlink":
        assert (tmp_path / "elsewhere.json").read_text() == "{}"


def test_checkpoint_refuses_a_file_that_is_not_a_checkpoint(tmp_path):
    """The issue's case: --checkpoint naming a tableau replaced it by 556 bytes of JSON."""
    m = _free(tmp_path)
    other = tmp_path / "gauss2.json"
    shutil.copy(METHODS / "gauss2.json", other)
    before = other.read_bytes()
    refused(*cli("design", m, "--require", "g-symplectic", "--maximize", "imaginary-interval",
                 "--checkpoint", other), other)
    assert other.read_bytes() == before


def test_save_refuses_a_file_it_did_not_make(tmp_path):
    m = _free(tmp_path)
    other = tmp_path / "mine.json"
    shutil.copy(METHODS / "gauss2.json", other)
    before = other.read_bytes()
    refused(*cli("solve", m, "--require", "g-symplectic", "--save", other), other)
    assert other.read_bytes() == before


@pytest.mark.parametrize("command", ["solve", "design"])
@pytest.mark.parametrize("name", ["a\u001b[2Jb", "x\u0000", "line\u0085break", "\u202eevil", " "])
def test_save_name_without_control_characters(tmp_path, command, name):
    m = _free(tmp_path)
    argv = (["solve", m, "--require", "g-symplectic"] if command == "solve" else
            ["design", m, "--require", "g-symplectic", "--maximize", "imaginary-interval"])
    code, err = cli(*argv, "--save", tmp_path / "out.json", "--name", name)
    refused(code, err, "--name")
    assert not (tmp_path / "out.json").exists()


# ---- bounded reads -------------------------------------------------------------------------------------------------

def _scene_folder(tmp_path, npz_bytes=None):
    """A scene output folder (meta.json naming an existing scene file, data.npz as given)."""
    scene = tmp_path / "s.json"
    scene.write_text(_scene(tmp_path))
    folder = tmp_path / "out" / "s"
    folder.mkdir(parents=True)
    meta = {"scene": str(scene), "name": "s", "title": "s", "complete": True, "problem": "harmonic", "h": "1/10",
            "steps": 10, "record_every": 1,
            "runs": [{"label": "RK4", "status": "completed", "max_invariant_error": {"H": 1e-9}, "message": "",
                      "file": str(RK4), "completed_steps": 10, "t_end": 1.0}]}
    (folder / "meta.json").write_text(json.dumps(meta))
    if npz_bytes is not None:
        (folder / "data.npz").write_bytes(npz_bytes)
    return folder


def _npy_header(shape) -> bytes:
    from numpy.lib import format as npformat
    buf = io.BytesIO()
    npformat.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": shape})
    return buf.getvalue()


def _bomb(total: int) -> bytes:
    """An npz whose one member is ``total`` bytes of zeros: a few hundred kB compressed."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        with zf.open("run0_t.npy", "w", force_zip64=True) as fh:
            fh.write(_npy_header((total // 8,)))
            chunk = bytes(1 << 22)
            for _ in range(total // len(chunk)):
                fh.write(chunk)
    return buf.getvalue()


def test_replot_refuses_a_zip_bomb_before_decompressing(tmp_path):
    import resource

    from tableau_lab.files import MAX_NPZ_UNPACKED
    folder = _scene_folder(tmp_path, _bomb(MAX_NPZ_UNPACKED + (16 << 20)))
    assert (folder / "data.npz").stat().st_size < 2 << 20
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.perf_counter()
    code, err = cli("replot", folder)
    refused(code, err, folder / "data.npz")
    assert "decompresses" in err and time.perf_counter() - t0 < 5
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - peak < 100 * 1024      # kB: nothing decompressed


def test_replot_refuses_an_npz_whose_header_lies(tmp_path):
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("run0_t.npy", _npy_header((10 ** 9,)) + bytes(80))
    folder = _scene_folder(tmp_path, buf.getvalue())
    code, err = cli("replot", folder)
    refused(code, err, folder / "data.npz", "run0_t.npy")


@pytest.mark.parametrize("damage", ["truncated", "empty", "not a zip", "object array", "text member"])
def test_replot_refuses_a_damaged_npz(tmp_path, damage):
    good = io.BytesIO()
    np.savez_compressed(good, run0_t=np.linspace(0, 1, 11), run0_y=np.zeros((11, 2)))
    raw = good.getvalue()
    if damage == "object array":
        buf = io.BytesIO()
        np.savez(buf, run0_t=np.array([{"a": 1}], dtype=object))
        raw = buf.getvalue()
    elif damage == "text member":
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w") as zf:
            zf.writestr("notes.txt", "hello")
        raw = buf.getvalue()
    raw = {"truncated": raw[: len(raw) // 2], "empty": b"", "not a zip": b"PK\x03\x04" + bytes(100)}.get(damage, raw)
    folder = _scene_folder(tmp_path, raw)
    refused(*cli("replot", folder), folder / "data.npz")


def test_replot_bounds_the_series_it_draws(tmp_path):
    """3000 series ran replot past 60 s at 814 MB: refused at once, naming the key."""
    from tableau_lab.experiments.replot import MAX_SERIES
    folder = tmp_path / "wp"
    folder.mkdir()
    point = {"cpu": 0.01, "nfev": 40, "error": 1e-3, "invariant_error": 1e-4}
    (folder / "data.json").write_text(json.dumps(_wp_data(series={f"m{i}": [point] for i in range(3000)})))
    t0 = time.perf_counter()
    code, err = cli("replot", folder)
    refused(code, err, folder / "data.json", "series", f"at most {MAX_SERIES}")
    assert time.perf_counter() - t0 < 5


def test_checkpoint_of_3_gb_is_not_read(tmp_path):
    """A sparse 3 GB file named as --checkpoint: refused from its size, at once (it was read whole)."""
    m = _free(tmp_path)
    big = tmp_path / "big.json"
    with open(big, "wb") as fh:
        fh.truncate(3 * 2 ** 30)
    t0 = time.perf_counter()
    refused(*cli("design", m, "--require", "g-symplectic", "--maximize", "imaginary-interval", "--checkpoint", big),
            big)
    assert time.perf_counter() - t0 < 10 and big.stat().st_size == 3 * 2 ** 30


# ---- saved outputs read back: the writer's schema ------------------------------------------------------------------

def _roundoff():
    return {"method": str(RK4), "problem": "pendulum", "h": "1/10", "steps": 100, "starts": 2, "digits": 32,
            "n": [0, 10, 100], "plain": [0.0, 1e-16, 3e-16], "compensated": [0.0, 1e-17, 1e-17],
            "slope_plain": 0.5, "slope_compensated": 0.1}


def _convergence():
    return [{"method": "RK4", "problem": "harmonic", "precision": "float64", "T": 10.0, "order": 4,
             "h": [0.2, 0.1, 0.05], "error": [1e-4, 6.25e-6, 3.9e-7], "slope": 4.0, "verdict": "order confirmed"}]


def _suite():
    return {"scenes": [{"name": "s"}], "rows": [{"scene": "s", "file": "rk4", "projection": [], "status": "completed",
                                                 "max_H_error": 1e-9, "t_end": 1.0, "T": 1.0}]}


def _drop(d, key):
    d = json.loads(json.dumps(d))
    target = d[0] if isinstance(d, list) else d
    target.pop(key)
    return d


def _set(d, key, value):
    d = json.loads(json.dumps(d))
    (d[0] if isinstance(d, list) else d)[key] = value
    return d


# (file name, data, the key the message must name); each refused with exit 2 naming the file
CORRUPT = {
    "roundoff-no-slope_plain": ("roundoff_x.json", _drop(_roundoff(), "slope_plain"), "slope_plain"),
    "roundoff-no-problem": ("roundoff_x.json", _drop(_roundoff(), "problem"), "problem"),
    "roundoff-plain-text": ("roundoff_x.json", _set(_roundoff(), "plain", "x"), "plain"),
    "roundoff-n-strings": ("roundoff_x.json", _set(_roundoff(), "n", ["a", "b", "c"]), "n[1]"),
    "roundoff-unequal": ("roundoff_x.json", _set(_roundoff(), "plain", [1e-16]), "roundoff"),
    "roundoff-slope-null": ("roundoff_x.json", _set(_roundoff(), "slope_compensated", None), "slope_compensated"),
    "convergence-no-problem": ("convergence_x.json", _drop(_convergence(), "problem"), "problem"),
    "convergence-h-text": ("convergence_x.json", _set(_convergence(), "h", "0.1"), "h"),
    "convergence-error-text": ("convergence_x.json", _set(_convergence(), "error", ["x", 1, 2]), "error"),
    "convergence-T-text": ("convergence_x.json", _set(_convergence(), "T", "ten"), "T"),
    "suite-no-file": ("summary.json", {**_suite(), "rows": [{k: v for k, v in _suite()["rows"][0].items()
                                                           if k != "file"}]}, "file"),
    "suite-unknown-scene": ("summary.json", {**_suite(), "rows": [{**_suite()["rows"][0], "scene": "t"}]}, "summary"),
    "suite-scenes-empty": ("summary.json", {**_suite(), "scenes": []}, "scenes"),
    "wp-no-title": ("data.json", {k: v for k, v in _wp_data().items() if k != "title"}, "title"),
    "wp-point-no-cpu": ("data.json", _wp_data(series={"RK4": [{"nfev": 1, "error": 1.0}]}), "series"),
    "wp-series-list": ("data.json", _wp_data(series=[1, 2]), "series"),
    "wp-T-text": ("data.json", {**_wp_data(), "T": "1"}, "T"),
}


@pytest.mark.parametrize("case", sorted(CORRUPT))
def test_replot_refuses_a_damaged_saved_output(tmp_path, case):
    name, data, key = CORRUPT[case]
    folder = tmp_path / "wp" if name == "data.json" else tmp_path
    folder.mkdir(exist_ok=True)
    path = folder / name
    path.write_text(json.dumps(data))
    before = tree(tmp_path)
    code, err = cli("replot", path if name != "data.json" else folder)
    refused(code, err, path, key)
    assert tree(tmp_path) == before


@pytest.mark.parametrize("case", ["runs-empty", "runs-not-objects", "no-scene", "label-number"])
def test_replot_refuses_damaged_scene_metadata(tmp_path, case):
    good = io.BytesIO()
    np.savez_compressed(good, run0_t=np.linspace(0, 1, 11))
    folder = _scene_folder(tmp_path, good.getvalue())
    meta = json.loads((folder / "meta.json").read_text())
    if case == "runs-empty":
        meta["runs"] = []
    elif case == "runs-not-objects":
        meta["runs"] = [1]
    elif case == "no-scene":
        del meta["scene"]
    else:
        meta["runs"][0]["label"] = 5
    (folder / "meta.json").write_text(json.dumps(meta))
    code, err = cli("replot", folder)
    refused(code, err, folder / "meta.json")
    assert {"runs-empty": "runs", "runs-not-objects": "runs[1]", "no-scene": "scene",
            "label-number": "label"}[case] in err


def test_replot_good_saved_outputs_still_draw(tmp_path):
    """The hand-made files above, undamaged, draw (the schemas accept what the writers write:
    the suite's own outputs are replotted in tests/test_figures.py)."""
    (tmp_path / "roundoff_x.json").write_text(json.dumps(_roundoff()))
    (tmp_path / "convergence_x.json").write_text(json.dumps(_convergence()))
    (tmp_path / "wp").mkdir()
    (tmp_path / "wp" / "data.json").write_text(json.dumps(_wp_data()))
    code, err = cli("replot", tmp_path)
    assert code == 0, err
    assert (tmp_path / "roundoff_x.png").is_file() and (tmp_path / "wp" / "wp.png").is_file()


def test_replot_of_a_folder_with_nothing_to_draw_exits_2(tmp_path):
    (tmp_path / "notes.txt").write_text("x")
    (tmp_path / "other.json").write_text("{}")
    refused(*cli("replot", tmp_path), tmp_path)


# ---- the environment ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("value", ["nan", "inf", "-1", "x", "1e999"])
def test_lock_timeout_must_be_a_finite_number(tmp_path, monkeypatch, value):
    """TABLEAU_LAB_LOCK_TIMEOUT=nan waited forever after printing "at most 0 s": refused before any work."""
    monkeypatch.setenv("TABLEAU_LAB_LOCK_TIMEOUT", value)
    m = tmp_path / "m.json"
    shutil.copy(RK4, m)
    t0 = time.perf_counter()
    refused(*cli("report", m, "--out", tmp_path / "out"), "TABLEAU_LAB_LOCK_TIMEOUT")
    assert time.perf_counter() - t0 < 5 and not (tmp_path / "out").exists()


def test_cache_that_is_a_file_is_refused(tmp_path, monkeypatch):
    from tableau_lab.errors import InputError
    from tableau_lab.numeric.kernels import cache_dir
    (tmp_path / "file").write_text("x")
    monkeypatch.setenv("TABLEAU_LAB_CACHE", str(tmp_path / "file"))
    with pytest.raises(InputError, match="TABLEAU_LAB_CACHE"):
        cache_dir()


@pytest.mark.parametrize("argv", [("verify", "a" * 300 + ".json"), ("modified", "bdf:" + "9" * 5000),
                                  ("order", "x/" + "b" * 256 + "/m.json")])
def test_names_longer_than_name_max(argv):
    code, err = cli(*argv)
    assert code == 2 and "internal error" not in err and "Traceback" not in err, err[:300]


def test_guard_confines_nested_phases(tmp_path):
    """Inside output_phase(folder) nothing is made or written outside it (a nested phase's folder
    is checked before it is made)."""
    from tableau_lab.files import OutputRefused, atomic_write_text, output_phase
    with pytest.raises(OutputRefused, match="outside"):
        with output_phase(tmp_path / "a"):
            with output_phase(tmp_path / "b"):
                pass
    with pytest.raises(OutputRefused, match="outside"):
        with output_phase(tmp_path / "a"):
            atomic_write_text(tmp_path / "a" / ".." / "x.txt", "x")
    os.symlink(tmp_path, tmp_path / "a" / "up")
    with pytest.raises(OutputRefused, match="outside"):
        with output_phase(tmp_path / "a"):
            atomic_write_text(tmp_path / "a" / "up" / "x.txt", "x")
    assert not (tmp_path / "b").exists() and not (tmp_path / "x.txt").exists()
