"""A run's two stages (experiments/job.py): the frozen method and problem give the numbers of
the generated ones bit for bit, the separated command never imports sympy, a short run is built
in the command's own process (issue 32), and errors of the build stage come back with their
messages."""
import json
import os
import pickle
import subprocess
import sys
from pathlib import Path

import pytest
import sympy

from tableau_lab.experiments.job import method_shape, separate_stages
from tableau_lab.experiments.runs import prepare_quick, quick_run
from tableau_lab.numeric.codegen import compile_problem
from tableau_lab.numeric.frozen import freeze
from tableau_lab.numeric.problem_functions import ProblemError

ROOT = Path(__file__).parent.parent
METHODS = ROOT / "methods"
HEAVY = ("numba", "llvmlite", "scipy", "dask", "distributed", "matplotlib")


def _numbers(res):
    """The record without the times, and without the loop's reason (its words name the compile state)."""
    return {k: v for k, v in res.items() if k not in ("seconds", "compile_seconds", "loop_why")}


@pytest.mark.parametrize("name, problem, kw", [
    ("example4_glm", "pendulum", {"monitor": 1e-2}),          # GLM: starting/finishing series, modes, f′
    ("rk4", "kepler", {"project": ("H", "L")}),                 # gradients, projection
    ("gauss2", "kepler", {}),                                   # implicit: Newton on f′
    ("gauss2", "pendulum", {"precision": "dd"}),                # mpmath code, compiled dd loop
])
def test_frozen_job_gives_the_same_numbers(name, problem, kw):
    """The job frozen and sent through pickle (as to the run process) against the job built in
    place: the same code, so every number of the result is equal, not just close."""
    args = (METHODS / f"{name}.json", problem, 0.01, 400)
    here = prepare_quick(*args, **kw).execute()
    job = pickle.loads(pickle.dumps(prepare_quick(*args, frozen=True, **kw)))
    assert job.nm.exact is None                     # no sympy object travels
    # Example 4's V has the one eigenvalue −1 besides 1 (seed §2.7); the monitor's data travel with it
    assert [md.label for md in job.nm.modes] == (["-1"] if name == "example4_glm" else [])
    assert _numbers(job.execute()) == _numbers(here)


def test_frozen_problem_keeps_only_what_was_asked():
    cp = compile_problem("henon_heiles")
    fp = freeze(cp, invariants=("H",), derivatives=3)
    y = [0.1, 0.2, 0.3, -0.1]
    F, G = fp.elementary_differentials(3)(y), cp.elementary_differentials(3)(y)
    assert all((F[t] == G[t]).all() for t in G)
    with pytest.raises(ProblemError, match="'jac' was not frozen"):
        fp.jac(y)
    with pytest.raises(ProblemError, match="has no invariant 'L'"):
        fp.invariant("L", y)


def _cli(*argv):
    """``tableau-lab run`` in a fresh interpreter (the default loop choice); prints its JSON and
    which of the numeric side's heavy libraries and whether sympy got imported."""
    env = {k: v for k, v in os.environ.items() if k != "TABLEAU_LAB_KERNEL"}
    code = ("import sys\nfrom tableau_lab.cli import main\nrc = main(sys.argv[1:])\n"
            "print('HEAVY', sorted({m.split('.')[0] for m in sys.modules} & set(%r)))\n"
            "print('SYMPY-IMPORTED' if 'sympy' in sys.modules else 'NO-SYMPY', rc)\nraise SystemExit(rc)") % (HEAVY,)
    return subprocess.run([sys.executable, "-c", code, "run", *argv], capture_output=True, text=True, env=env,
                          cwd=ROOT, timeout=600)


def test_cli_run_keeps_sympy_out_of_the_run_process(monkeypatch):
    """The compiled quick run (10⁵ steps: more than the compile in Python, limits.build_here):
    the command's process runs the loop without sympy (the build child had it), and prints what
    the in-process run computes."""
    argv = ("--method", "methods/gauss2.json", "--problem", "pendulum", "--h", "0.01", "--steps", "100000", "--json")
    out = _cli(*argv)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.strip().splitlines()
    assert lines[-1] == "NO-SYMPY 0"
    monkeypatch.delenv("TABLEAU_LAB_KERNEL", raising=False)      # the compiled loop, as the command
    direct = quick_run(METHODS / "gauss2.json", "pendulum", h=sympy.Rational(1, 100), steps=100000)
    assert json.loads(lines[0])["loop"] == direct["loop"] == "compiled"
    assert _numbers(json.loads(lines[0])) == _numbers(direct)


def test_cli_build_errors_come_back(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"kind": "rk"}')
    out = _cli("--method", str(bad), "--problem", "kepler", "--h", "0.01", "--steps", "10")
    assert out.returncode == 2 and "entry A: kind 'rk' needs 'A'" in out.stderr and str(bad) in out.stderr
    out = _cli("--method", "methods/gauss2.json", "--problem", "kepler", "--h", "0.01", "--steps", "10",
               "--set", "ee=1")
    assert out.returncode == 2 and "has no parameter or initial value 'ee'" in out.stderr
    assert "Traceback" not in out.stderr


def test_short_run_is_built_in_the_command_process_without_numba():
    """Issue 32: a 1000-step run of Gauss 2 on the pendulum is predicted at 0.16 s in Python
    (limits.build_here, choose_loop): built and run in the command's own process (sympy there),
    numba (or scipy, dask, matplotlib) never imported, and its record says which loop ran, why,
    and what it compiled."""
    argv = ("--method", "methods/gauss2.json", "--problem", "pendulum", "--h", "0.01", "--steps", "1000")
    out = _cli(*argv, "--json")
    assert out.returncode == 0, out.stderr
    lines = out.stdout.strip().splitlines()
    assert lines[-2:] == ["HEAVY []", "SYMPY-IMPORTED 0"]
    rec = json.loads(lines[0])
    assert rec["loop"] == "python" and rec["compile_seconds"] == 0.0
    assert rec["loop_why"].startswith("the Python loop: 1000 steps predicted at")
    assert "compiling" not in out.stderr
    text = _cli(*argv).stdout
    assert ", python loop\n" in text and "compile" not in text


def test_where_a_quick_run_is_built(monkeypatch, tmp_path):
    """The rule is decided from the method's file alone, before anything is built: the shapes
    read with json are the methods' (s, r, explicit), and a run the Python loop may serve is
    built here; a long one, or one whose method is not a readable file, in a child."""
    assert method_shape(METHODS / "gauss3.json") == (3, 1, False)
    assert method_shape(METHODS / "stormer_verlet.json") == (2, 1, False)     # Lobatto IIIA: implicit
    assert method_shape(METHODS / "symplectic_euler.json")[2] is False
    assert method_shape(METHODS / "leapfrog.json") is not None
    bad = tmp_path / "bad.json"
    bad.write_text('{"kind": "rk", "A": "x"}')
    assert method_shape(bad) is None and method_shape(tmp_path / "missing.json") is None
    monkeypatch.delitem(sys.modules, "sympy")             # a command that has not imported sympy
    monkeypatch.delenv("TABLEAU_LAB_KERNEL", raising=False)
    gauss2 = str(METHODS / "gauss2.json")
    assert not separate_stages("float64", gauss2, 1000)
    assert separate_stages("float64", gauss2, 10 ** 5) and separate_stages("float64", "gauss2", 1000)
    assert separate_stages("dd", gauss2, 1000) and not separate_stages("mp:30", gauss2, 1000)
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "python")     # the pure loop: built and run in one process
    assert not separate_stages("float64", gauss2, 10 ** 5)
