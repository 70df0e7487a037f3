"""Faults (issue 16, item 5): SIGKILL and Ctrl-C at random moments of ``run``, concurrent runs
into one folder, a full disk, stale temporary files, pool workers of a killed command.

Afterwards every file of the output folder loads (npz, JSON, PNG, PDF by their magic bytes),
is complete or marked incomplete, and no temporary file is left.  The kill loop runs
``TABLEAU_LAB_FAULT_REPEATS`` times (default 3; 20 locally).  The commands run the pure step loop
(the suite's default, tests/conftest.py): what is under test is the files, the locks and the
processes, which do not depend on the loop, and a cold compile of the loops (one private cache)
cost about 100 s of the suite's time before the first kill."""
import errno
import json
import os
import random
import re
import signal
import subprocess
import sys
import threading
import time
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from tableau_lab import files
from tableau_lab.experiments.figure_style import formats
from tableau_lab.files import OutputError, is_temp, output_lock, remove_stale_temps

METHODS = Path(__file__).resolve().parents[1] / "methods"
REPEATS = int(os.environ.get("TABLEAU_LAB_FAULT_REPEATS", "3"))
PNG, PDF = b"\x89PNG\r\n\x1a\n", b"%PDF-"


def _scene(folder: Path, name="faults", steps=4000, every=10) -> Path:
    path = folder / f"{name}.json"
    path.write_text(json.dumps({
        "format": "tableau_lab/scene/1", "name": name, "title": "faults", "problem": {"name": "pendulum"},
        "h": "1/100", "steps": steps, "record_every": every, "plots": ["invariants", "orbit"],
        "runs": [{"method": str(METHODS / "gauss2.json"), "label": "gauss2"},
                 {"method": str(METHODS / "rk4.json"), "label": "rk4"},
                 {"method": str(METHODS / "rk4.json"), "project": ["H"], "label": "rk4 + projection"}]}))
    return path


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """The environment of the module's commands, a scene, and how long a normal run of it takes."""
    root = tmp_path_factory.mktemp("faults")
    # the pure step loop (a compile would be neither under test nor killed: see the docstring);
    # and a cache folder of the module's own all the same, so that nothing of these commands lands in
    # the user's cache
    env = {**os.environ, "TABLEAU_LAB_CACHE": str(root / "cache"), "TABLEAU_LAB_KERNEL": "python",
           "TABLEAU_LAB_SPECIALISE": "0", "PYTHONUNBUFFERED": "1"}
    scene = _scene(root)
    t = time.monotonic()
    done = subprocess.run(_run_cmd(scene, root / "warm"), env=env, check=False, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    return {"root": root, "env": env, "scene": scene, "seconds": time.monotonic() - t}


@pytest.fixture
def compiled(lab, monkeypatch):
    """In-process runs as the module's commands run them (its environment)."""
    for k in ("TABLEAU_LAB_CACHE", "TABLEAU_LAB_KERNEL", "TABLEAU_LAB_SPECIALISE"):
        monkeypatch.setenv(k, lab["env"][k])
    return lab


def _run_cmd(scene, out):
    return [sys.executable, "-m", "tableau_lab", "run", str(scene), "--out", str(out)]


def _start(cmd, env):
    # SIGINT as the default (a shell may start background jobs with it ignored)
    return subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _check_folder(folder: Path, temps_allowed=False) -> dict:
    """Every file in ``folder`` loads; returns {name: content}.  No temporary file unless
    ``temps_allowed`` (after a SIGKILL, before the next run)."""
    found = {}
    if not folder.exists():
        return found
    for f in sorted(folder.iterdir()):
        if is_temp(f.name) or f.name == files.LOCK_NAME:
            assert temps_allowed, f"left behind: {f.name}"
            continue
        assert not f.name.startswith("."), f"unexpected hidden file {f.name}"
        data = f.read_bytes()
        if f.suffix == ".npz":
            with np.load(f) as z:
                found[f.name] = {k: z[k] for k in z.files}
        elif f.suffix == ".json":
            found[f.name] = json.loads(data)
        elif f.suffix == ".png":
            assert data.startswith(PNG) and len(data) > 100, f.name
            found[f.name] = len(data)
        elif f.suffix == ".pdf":
            assert data.startswith(PDF) and b"%%EOF" in data[-1024:], f.name
            found[f.name] = len(data)
        elif f.suffix == ".svg":
            assert b"<svg" in data[:2048] and data.rstrip().endswith(b"</svg>"), f.name
            found[f.name] = len(data)
        else:
            found[f.name] = data
    return found


def _figures(*stems) -> set:
    """A figure's files: each stem in every format of the figure style (PNG, PDF, SVG)."""
    return {stem + ext for stem in stems for ext in formats()}


def _check_scene_set(found: dict, name="faults") -> bool:
    """The data and the metadata of the folder agree, complete or marked incomplete; returns
    whether the set is complete."""
    complete = "meta.json" in found
    suffix = "" if complete else ".incomplete"
    meta, data = found[f"meta{suffix}.json"], found[f"data{suffix}.npz"]
    assert meta["complete"] is complete
    assert _figures(f"{name}_invariants{suffix}", f"{name}_orbit{suffix}") <= set(found)
    for i, r in enumerate(meta["runs"]):
        if r["status"] == "not run":
            assert f"run{i}_t" not in data and not complete
            continue
        t = data[f"run{i}_t"]
        assert len(data[f"run{i}_H"]) == len(t) and np.all(np.diff(t) > 0)
        if r["status"] == "completed":
            assert abs(t[-1] - r["t_end"]) < 1e-9
        else:                                          # the records up to the interrupt
            h = float(Fraction(meta["h"]))
            assert -1e-9 <= r["t_end"] - t[-1] <= meta["record_every"] * h + 1e-9
        assert r["status"] in (("completed",) if complete else ("completed", "interrupted", "not run"))
    mine = {f"data{suffix}.npz", f"meta{suffix}.json"} | _figures(f"{name}_invariants{suffix}", f"{name}_orbit{suffix}")
    assert not set(found) - mine, f"files of another set beside this one: {sorted(set(found) - mine)}"
    return complete


def test_kill_9_at_random_moments_then_a_complete_run(lab, tmp_path):
    """SIGKILL at seeded random moments (0.2 s … a normal run's time), REPEATS times into one
    folder; each time the files there load; then a run to the end leaves one complete set and
    no temporary file (the killed runs' ones removed)."""
    rng = random.Random(16)
    out = tmp_path / "out"
    folder = out / "faults"
    t0, kills = time.monotonic(), []
    for _ in range(REPEATS):
        delay = rng.uniform(0.2, max(0.3, lab["seconds"]))
        p = _start(_run_cmd(lab["scene"], out), lab["env"])
        time.sleep(delay)
        p.kill()
        p.communicate()
        found = _check_folder(folder, temps_allowed=True)
        if any(n.startswith("meta") for n in found):
            _check_scene_set(found)
        temps = sum(is_temp(f.name) for f in folder.iterdir()) if folder.exists() else 0
        kills.append(f"{delay:.2f} s" + (f" ({temps} temporary files)" if temps else ""))
    done = subprocess.run(_run_cmd(lab["scene"], out), env=lab["env"], check=False, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    found = _check_folder(folder)
    assert _check_scene_set(found)
    assert set(found) == {"data.npz", "meta.json"} | _figures("faults_invariants", "faults_orbit")
    print(f"{REPEATS} kills ({', '.join(kills)}) and a complete run: {time.monotonic() - t0:.1f} s")


def test_ctrl_c_at_random_moments(lab, tmp_path):
    """SIGINT at seeded random moments: exit 130 (or death by SIGINT outside the command, while
    Python starts or exits: then nothing written, or the complete set); the runs that finished
    are kept, the set marked incomplete; nothing half-written."""
    rng = random.Random(130)
    # runs long enough to be interrupted in the pure loop (several seconds each), records every 40 steps
    scene = _scene(tmp_path, steps=12_000, every=40)
    t = time.monotonic()
    done = subprocess.run(_run_cmd(scene, tmp_path / "whole"), env=lab["env"], check=False, capture_output=True,
                          timeout=300)
    seconds = time.monotonic() - t
    assert done.returncode == 0
    seen = []
    for k in range(REPEATS):
        out = tmp_path / f"out{k}"
        p = _start(_run_cmd(scene, out), lab["env"])
        delay = rng.uniform(0.2, seconds)
        seen.append(f"{delay:.2f} s:")
        time.sleep(delay)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=120)
        found = _check_folder(out / "faults")
        if p.returncode == 0:
            assert _check_scene_set(found)
            seen.append("finished")
            continue
        if p.returncode == -signal.SIGINT:     # outside the command: while Python starts or exits
            assert not found or _check_scene_set(found), "interrupted outside the command, yet a partial set"
            seen.append("while Python exits" if found else "while Python starts")
            continue
        assert p.returncode == 130, err
        assert "Traceback" not in err
        if not found:
            seen.append("before any record")           # no run had records yet: nothing written
            continue
        complete = _check_scene_set(found)
        meta = found["meta.json" if complete else "meta.incomplete.json"]
        seen.append("complete" if complete else "/".join(r["status"] for r in meta["runs"]))
    print("outcomes:", seen)


def test_ctrl_c_between_runs_keeps_the_finished_ones(compiled, tmp_path, monkeypatch):
    """Ctrl-C outside the integrator (here: while run 2 loads its method): runs 0 and 1 are
    written, run 2 is listed as not run, the set is marked incomplete."""
    from tableau_lab.experiments import scene as S
    real = S.run_one

    def run_one(sc, i, *args, **kwargs):
        if i == 2:
            raise KeyboardInterrupt
        return real(sc, i, *args, **kwargs)
    monkeypatch.setattr(S, "run_one", run_one)
    with pytest.raises(KeyboardInterrupt):
        S.run_scene(compiled["scene"], out_root=tmp_path / "out", progress=False)
    found = _check_folder(tmp_path / "out" / "faults")
    assert not _check_scene_set(found)
    runs = found["meta.incomplete.json"]["runs"]
    assert [r["status"] for r in runs] == ["completed", "completed", "not run"]
    assert len(found["data.incomplete.npz"]["run1_t"]) == 401


@pytest.fixture
def sigint_raises():
    """SIGINT raising KeyboardInterrupt, as in a terminal: a shell starts background jobs with
    SIGINT ignored, and Python then keeps it ignored (the deferral is then rightly skipped)."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


def test_ctrl_c_while_writing_finishes_the_set(compiled, tmp_path, monkeypatch, sigint_raises):
    """A first Ctrl-C during the write phase is held until the set is written (then raised); a
    second one abandons the set and the folder keeps its previous files."""
    from tableau_lab.experiments import scene as S
    out = tmp_path / "out"
    S.run_scene(compiled["scene"], out_root=out, progress=False)
    before = {f.name: f.read_bytes() for f in (out / "faults").iterdir()}
    real = files._fill
    calls = []

    def fill(tmp, write, times=1):
        calls.append(tmp)
        if len(calls) <= times:
            os.kill(os.getpid(), signal.SIGINT)        # Ctrl-C while the data are written
        return real(tmp, write)
    monkeypatch.setattr(files, "_fill", fill)
    with pytest.raises(KeyboardInterrupt):
        S.run_scene(compiled["scene"], out_root=out, progress=False)
    # data, meta, 2 plots
    assert len(calls) == 2 + 2 * len(formats()) and _check_scene_set(_check_folder(out / "faults"))
    assert {f.name for f in (out / "faults").iterdir()} == set(before)
    before = {f.name: f.read_bytes() for f in (out / "faults").iterdir()}
    calls.clear()
    monkeypatch.setattr(files, "_fill", lambda tmp, write: fill(tmp, write, times=2))
    with pytest.raises(KeyboardInterrupt):
        S.run_scene(compiled["scene"], out_root=out, progress=False)
    assert len(calls) == 2                               # the second Ctrl-C: the set abandoned
    assert {f.name: f.read_bytes() for f in (out / "faults").iterdir()} == before


def test_ctrl_c_in_the_suite_keeps_the_finished_scenes(compiled, tmp_path, monkeypatch):
    """Ctrl-C during the suite's fifth run (of 2 scenes × 3): the first scene was written as
    soon as its runs finished, the second is written incomplete with its finished run; the
    summary is not written."""
    from tableau_lab.experiments import suite
    (tmp_path / "scenes").mkdir()
    for name in ("suite_a", "suite_b"):
        _scene(tmp_path / "scenes", name)
    real, calls = suite.suite_task, []

    def task(item):
        calls.append(item)
        if len(calls) == 5:
            raise KeyboardInterrupt
        return real(item)
    monkeypatch.setattr(suite, "suite_task", task)
    with pytest.raises(KeyboardInterrupt):
        suite.run_suite(tmp_path, scheduler="serial", progress=False)
    a, b = _check_folder(tmp_path / "suite_a"), _check_folder(tmp_path / "suite_b")
    assert _check_scene_set({k: v for k, v in a.items() if "energy" not in k}, "suite_a")
    assert "suite_a_energy.png" in a
    assert not _check_scene_set({k: v for k, v in b.items() if "energy" not in k}, "suite_b")
    assert [r["status"] for r in b["meta.incomplete.json"]["runs"]] == ["completed", "not run", "not run"]
    assert sorted(f.name for f in tmp_path.iterdir()) == ["scenes", "suite_a", "suite_b"]     # no summary


def test_concurrent_runs_into_one_folder(lab, tmp_path):
    """Three runs of one scene at once into one folder, twice: all exit 0 (the folder's lock
    orders their writes), and the folder holds one consistent complete set."""
    out = tmp_path / "out"
    for _ in range(2):
        procs = [_start(_run_cmd(lab["scene"], out), lab["env"]) for _ in range(3)]
        for p in procs:
            _, err = p.communicate(timeout=300)
            assert p.returncode == 0, err
            assert "Traceback" not in err
        found = _check_folder(out / "faults")
        assert _check_scene_set(found)
        assert set(found) == {"data.npz", "meta.json"} | _figures("faults_invariants", "faults_orbit")


def test_a_held_folder_is_reported_clearly(tmp_path):
    """A folder whose lock another writer holds past the timeout: OutputError naming the folder
    and the holder; afterwards the lock file is gone."""
    held, release = threading.Event(), threading.Event()

    def holder():
        with output_lock(tmp_path / "o"):
            held.set()
            release.wait(10)
    t = threading.Thread(target=holder)
    t.start()
    held.wait(10)
    try:
        message = f"{tmp_path / 'o'}: still being written by process {os.getpid()}"
        with pytest.raises(OutputError, match=re.escape(message)), output_lock(tmp_path / "o", timeout=0.3):
            pass
    finally:
        release.set()
        t.join()
    with output_lock(tmp_path / "o", timeout=1):
        assert (tmp_path / "o" / files.LOCK_NAME).exists()
    assert not list((tmp_path / "o").iterdir())


@pytest.mark.parametrize("failing", [1, 2, 3])        # the data, the metadata, the first plot
def test_full_disk_leaves_the_previous_outputs(compiled, tmp_path, monkeypatch, failing):
    """ENOSPC while the k-th file of a scene's set is written (half a file, then the error):
    a clear OutputError naming the file, the previous set byte for byte, no temporary file."""
    from tableau_lab.experiments import scene as S
    out = tmp_path / "out"
    S.run_scene(compiled["scene"], out_root=out, progress=False)
    before = {f.name: f.read_bytes() for f in (out / "faults").iterdir()}
    real, calls = files._fill, []

    def fill(tmp, write):
        calls.append(tmp)
        if len(calls) == failing:
            with open(tmp, "wb") as f:
                f.write(b"half a file")
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(tmp, write)
    monkeypatch.setattr(files, "_fill", fill)
    name = ["data.npz", "meta.json", "faults_invariants.png"][failing - 1]
    with pytest.raises(OutputError, match=rf"faults/{name}: cannot write it: No space left on device \(the disk "
                                          r"is full\); the previous .* is left as it was") as err:
        S.run_scene(compiled["scene"], out_root=out, progress=False)
    assert err.value.errno == errno.ENOSPC
    assert {f.name: f.read_bytes() for f in (out / "faults").iterdir()} == before


def test_full_disk_from_the_command_line(compiled, tmp_path, monkeypatch, capsys):
    """``run`` on a full disk: exit 2, one line naming the file, the previous outputs kept."""
    from tableau_lab.cli import main
    out = tmp_path / "out"
    assert main(["run", str(compiled["scene"]), "--out", str(out)]) == 0
    before = {f.name: f.read_bytes() for f in (out / "faults").iterdir()}
    capsys.readouterr()

    def full(tmp, write):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr(files, "_fill", full)
    assert main(["run", str(compiled["scene"]), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err == (f"tableau-lab: error: {out / 'faults' / 'data.npz'}: cannot write it: No space left on device "
                   "(the disk is full); the previous data.npz, if any, is left as it was\n")
    assert {f.name: f.read_bytes() for f in (out / "faults").iterdir()} == before


@pytest.mark.skipif(not __import__("shutil").which("pdflatex"), reason="pdflatex not installed")
def test_full_disk_while_the_pdf_is_copied(tmp_path, monkeypatch):
    """report --pdf on a full disk: the copy of the PDF fails cleanly (ReportError naming the
    file), the previous PDF is intact."""
    from tableau_lab.proofs.latex import ReportError, compile_pdf
    tex = tmp_path / "r.tex"
    tex.write_text("\\documentclass{article}\\begin{document}Hello\\end{document}\n")
    pdf = compile_pdf(tex, required=True)
    before = pdf.read_bytes()
    tex.write_text("\\documentclass{article}\\begin{document}Hello again, longer\\end{document}\n")

    def full(tmp, write):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr(files, "_fill", full)
    with pytest.raises(ReportError, match=r"r\.(log|pdf): cannot write it: No space left on device"):
        compile_pdf(tex, required=True)
    assert pdf.read_bytes() == before
    assert _check_folder(tmp_path)["r.pdf"] == len(before)


def test_stale_temporary_files_are_removed(tmp_path):
    """Temporary files of dead processes (and unmarked ones of older versions, after an hour)
    are removed by the next write into the folder; those of live processes stay."""
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], check=False, capture_output=True,
                          text=True).stdout.strip()
    names = {"dead": f".data.npz.tltmp-{dead}-0123abcd.npz", "live": f".x.png.tltmp-{os.getppid()}-0123abcd.png",
             "legacy": ".meta.json.k2j_4h9z.tmp", "young": ".data.npz.ab12cd34.npz", "mine": ".notes.txt"}
    for n in names.values():
        (tmp_path / n).write_bytes(b"half")
    old = time.time() - 7200
    os.utime(tmp_path / names["legacy"], (old, old))
    files.atomic_write_text(tmp_path / "a.json", "{}")
    left = {f.name for f in tmp_path.iterdir()}
    assert left == {"a.json", names["live"], names["young"], names["mine"]}
    assert remove_stale_temps(tmp_path) == []


def _marked(marker: str) -> list:
    """Processes whose environment holds ``marker`` (Linux /proc)."""
    found = []
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            env = Path(f"/proc/{pid}/environ").read_bytes().split(b"\0")
            if marker.encode() in env:
                state = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[0]
                if state != "Z":
                    found.append(int(pid))
        except OSError:
            pass
    return found


def _gone(marker, within=10.0) -> list:
    deadline = time.monotonic() + within
    while _marked(marker) and time.monotonic() < deadline:
        time.sleep(0.1)
    return _marked(marker)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_no_worker_outlives_convergence(lab, tmp_path):
    """kill -9 of ``convergence`` while its pool works: the workers, the forkserver and the
    resource tracker end within seconds; a second, normal run leaves no process and no
    temporary file behind, and its files load."""
    out = tmp_path / "conv"
    cmd = [sys.executable, "-m", "tableau_lab", "convergence", str(METHODS / "rk4.json"), str(METHODS / "gauss2.json"),
           "--problem", "pendulum", "--workers", "2", "--out", str(out)]
    marker = f"TABLEAU_LAB_FAULT_MARK={os.getpid()}-{time.monotonic_ns()}"
    env = {**lab["env"], marker.split("=")[0]: marker.split("=")[1]}
    p = _start(cmd, env)
    deadline = time.monotonic() + 60
    while len(_marked(marker)) < 4 and time.monotonic() < deadline and p.poll() is None:
        time.sleep(0.05)                           # the command, the tracker, the forkserver, a worker
    assert len(_marked(marker)) >= 4, "the pool did not start"
    p.kill()
    p.communicate()
    assert _gone(marker) == []
    _check_folder(out, temps_allowed=True)
    done = subprocess.run(cmd, env=env, check=False, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert _gone(marker, within=5) == []
    found = _check_folder(out)
    assert set(found) == {"convergence_pendulum_float64.json"} | _figures("convergence_pendulum_float64")


KILLED = {   # command, and the files a complete run leaves in its output folder
    "convergence": (lambda out: [sys.executable, "-m", "tableau_lab", "convergence", str(METHODS / "rk4.json"),
                                 "--problem", "harmonic", "--T", "1", "--max-steps", "800", "--workers", "1",
                                 "--out", str(out)],
                    {"convergence_harmonic_float64.json"} | _figures("convergence_harmonic_float64")),
    "report": (lambda out: [sys.executable, "-m", "tableau_lab", "report", str(METHODS / "gauss2.json"), "--pdf",
                            "--out", str(out)],
               {"gauss2.report.json", "gauss2.tex", "gauss2.pdf", "gauss2.log"}),
}


@pytest.mark.parametrize("command", sorted(KILLED))
def test_kill_9_of_convergence_and_report(command, lab, tmp_path):
    """SIGKILL at random moments of ``convergence`` and ``report --pdf`` (REPEATS times): the
    files there load each time; then a complete run leaves exactly its set, no temporary file."""
    import shutil
    if command == "report" and shutil.which("pdflatex") is None:
        pytest.skip("no pdflatex")
    make, complete = KILLED[command]
    out = tmp_path / "out"
    t0 = time.monotonic()                # a normal run, timed: the kills fall inside one
    subprocess.run(make(tmp_path / "timing"), env=lab["env"], check=True, capture_output=True, timeout=300)
    normal = time.monotonic() - t0
    rng = random.Random(17)
    for _ in range(REPEATS):
        p = _start(make(out), lab["env"])
        time.sleep(rng.uniform(0.1, max(0.2, normal)))
        p.kill()
        p.communicate()
        _check_folder(out, temps_allowed=True)
    done = subprocess.run(make(out), env=lab["env"], check=False, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert set(_check_folder(out)) == complete
