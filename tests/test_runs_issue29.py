"""Issue 29, numeric runs and their messages: round-off on Kepler (symbolic initial values), a
run destroyed by parasitism reported as "degraded" (summary, meta.json, figure, exit code 4),
phase plots that wrap angles and name the problem's own variables, exact step sizes in the
Python API, a misplaced argument of ``from_lists`` named, the TeX packages a PDF needs, and
starts that overflow the working precision refused with the step named.  Every run is tiny
(the pure loop: tests/conftest.py)."""
import json
import math
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from tableau_lab.cli import main
from tableau_lab.errors import EXIT_DEGRADED
from tableau_lab.experiments import figure_style
from tableau_lab.numeric.limits import DEGRADED

ROOT = Path(__file__).parent.parent
METHODS = (ROOT / "methods").resolve()


@pytest.fixture
def figures(monkeypatch):
    """The matplotlib figures the plots save, by file name (drawn as before)."""
    seen = {}
    save = figure_style.save

    def keep(fig, target, caption=None):
        seen[Path(target).name] = fig
        return save(fig, target, caption)
    monkeypatch.setattr(figure_style, "save", keep)
    return seen


# -- item 3: round-off on Kepler ------------------------------------------------------------------

def test_roundoff_on_kepler_runs(tmp_path, capsys):
    """Kepler's initial values are symbolic in e (q1 = 1 − e): they reach float64 through the
    arithmetic layer (5ea0488: "Cannot convert expression to float", exit 3).  The round-off of
    a few steps of Gauss 2 is a few ulps of the state (|y| ≤ 2)."""
    code = main(["roundoff", "--method", str(METHODS / "gauss2.json"), "--problem", "kepler", "--h", "1/10",
                 "--steps", "2", "--starts", "1", "--digits", "20", "--out", str(tmp_path)])
    out = capsys.readouterr()
    assert code == 0, out.err
    data = json.loads((tmp_path / "roundoff_gauss2_kepler.json").read_text())
    assert len(data["plain"]) == len(data["n"]) == 3
    assert max(data["plain"]) < 100 * np.finfo(float).eps and data["plain"][0] == 0.0
    assert "exponent —" in out.out             # two nonzero records: too few to fit, said (5ea0488: a TypeError)


# -- item 4: a destroyed run says so ---------------------------------------------------------------

def _pendulum_scene(tmp_path, runs, steps=600, plots=("invariants", "state")):
    d = {"format": "tableau_lab/scene/1", "name": "ex4", "title": "Example 4 on the pendulum, h = 1/20",
         "problem": "pendulum", "h": "1/20", "steps": steps, "record_every": 5, "plots": list(plots),
         "runs": [{"method": str(METHODS / f), "label": label} for f, label in runs]}
    p = tmp_path / "scene.json"
    p.write_text(json.dumps(d))
    return p


def _relative_H_drift(y):
    """max |H(y_n) − H(y_0)| / |H(y_0)| from the recorded states, H = p²/2 − cos q (the
    pendulum's energy written here, not the code's)."""
    H = y[:, 1] ** 2 / 2 - np.cos(y[:, 0])
    return float(np.max(np.abs(H - H[0])) / abs(H[0]))


def test_a_destroyed_run_is_degraded(tmp_path, capsys, figures):
    """Example 4 on the pendulum (q0 = 2.3) at h = 1/20: the parasitic component blows up by
    t ≈ 20 (step 400) and the energy drifts by order one.  5ea0488 printed "completed" and
    exited 0; now: status "degraded" with the reason, exit 4, the figure's title says so and
    the phase plot draws the run in a panel of its own, q wrapped into [−π, π).  Gauss 2 in
    the same scene stays "completed"."""
    scene = _pendulum_scene(tmp_path, [("example4_glm.json", "Example 4"), ("gauss2.json", "Gauss 2")])
    code = main(["run", str(scene), "--out", str(tmp_path / "out")])
    out = capsys.readouterr().out
    assert code == EXIT_DEGRADED == 4, out
    meta = json.loads((tmp_path / "out" / "ex4" / "meta.json").read_text())
    ex4, g2 = meta["runs"]
    assert meta["complete"] and ex4["status"] == "degraded" and g2["status"] == "completed"
    assert "H drifted" in ex4["message"] and "parasitic component" in ex4["message"]
    assert "Example 4: DEGRADED" in out and "Gauss 2: completed" in out
    data = np.load(tmp_path / "out" / "ex4" / "data.npz")
    assert _relative_H_drift(data["run0_y"]) >= DEGRADED > _relative_H_drift(data["run1_y"])
    assert max(abs(data["run0_y"][:, 0])) > 2 * math.pi              # it went over the top
    title = figures["ex4_invariants.png"]._suptitle.get_text()
    assert "DEGRADED" in title
    state = figures["ex4_state.png"]
    good, bad = [ax for ax in state.axes if ax.get_lines()]
    assert [ln.get_label() for ln in good.get_lines()] == ["Gauss 2"]
    assert [ln.get_label() for ln in bad.get_lines()] == ["Example 4 (DEGRADED)"]
    q = bad.get_lines()[0].get_xdata()
    assert np.nanmax(np.abs(q)) <= math.pi and np.isnan(q).any()    # wrapped, broken where it wraps
    assert "mod" in good.get_xlabel()


def test_a_good_run_is_not_degraded(tmp_path, capsys):
    """Gauss 2 alone on the same problem: completed, exit 0, one phase panel."""
    scene = _pendulum_scene(tmp_path, [("gauss2.json", "Gauss 2")], steps=100, plots=("state",))
    assert main(["run", str(scene), "--out", str(tmp_path / "out")]) == 0
    meta = json.loads((tmp_path / "out" / "ex4" / "meta.json").read_text())
    assert meta["runs"][0]["status"] == "completed" and meta["runs"][0]["message"] == ""


def test_quick_run_degraded_exit_4(capsys):
    """``run --method``: the same verdict (the JSON says why; 5ea0488 had no such key)."""
    code = main(["run", "--method", str(METHODS / "example4_glm.json"), "--problem", "pendulum", "--h", "1/20",
                 "--steps", "500", "--json"])
    out = capsys.readouterr()
    res = json.loads(out.out)
    assert code == EXIT_DEGRADED and "parasitic component" in res["degraded"], out.err
    assert "DEGRADED" in out.err


# -- item 10: API and messages ---------------------------------------------------------------------

def test_quick_run_takes_exact_strings():
    """``quick_run(m, "pendulum", "1/100", …)`` as the CLI's ``--h 1/100`` (5ea0488: a TypeError)."""
    from tableau_lab.errors import InputError
    from tableau_lab.experiments.runs import quick_run
    a = quick_run(METHODS / "gauss2.json", "pendulum", "1/100", 5)
    b = quick_run(METHODS / "gauss2.json", "pendulum", sp.Rational(1, 100), 5)
    assert a["h"] == 0.01 and a["final"] == b["final"]
    for bad, words in (("0", "positive"), ("x", "not a number"), ("1e-999", "rounds to 0.0"),
                       (None, "not a step size")):
        with pytest.raises(InputError, match=words):
            quick_run(METHODS / "gauss2.json", "pendulum", bad, 5)
    with pytest.raises(InputError, match="steps"):
        quick_run(METHODS / "gauss2.json", "pendulum", "1/100", 10 ** 12)


def test_from_lists_names_the_misplaced_argument():
    """A name passed where A goes (5ea0488: sympy's "Data type not understood")."""
    from tableau_lab.exact.methods import MethodError, PartitionedRungeKutta, RungeKutta
    with pytest.raises(MethodError, match=r"argument 1 \(A\) is the string 'x'.*name="):
        RungeKutta.from_lists("x", [[0]], [1])
    with pytest.raises(MethodError, match=r"argument 3 \(c\)"):
        RungeKutta.from_lists([[0]], [1], 5)
    with pytest.raises(MethodError, match=r"argument 2 \(b\)"):
        PartitionedRungeKutta.from_lists([[0]], "b", [[0]], [1])
    assert RungeKutta.from_lists([[0]], [1]).b.tolist() == [[1]]


def test_missing_tex_names_every_package_ci_installs(tmp_path, monkeypatch, capsys):
    """``report --pdf`` without pdflatex names what .ci/run installs for the PDF, lmodern
    included (5ea0488 left it out)."""
    line = next(s for s in (ROOT / ".ci" / "run").read_text().splitlines() if "texlive-latex-base" in s)
    wanted = [w for w in line.split() if w.startswith(("texlive", "lmodern"))]
    assert "lmodern" in wanted
    monkeypatch.setattr(shutil, "which", lambda name: None)
    assert main(["report", str(METHODS / "gauss2.json"), "--out", str(tmp_path), "--pdf"]) == 2
    err = capsys.readouterr().err
    assert all(w in err for w in wanted), err


ODE = {"name": "osc", "y": ["x", "v"], "f": ["v", "-x"], "y0": ["1", "0"]}


def test_user_ode_summary_and_phase_plot(tmp_path, capsys, figures):
    """A user ODE without invariants: the summary says so (5ea0488: an empty "max |ΔI|: ,"),
    and the phase plot is labelled with its own variables x, v (5ea0488: q, p)."""
    p = tmp_path / "scene.json"
    p.write_text(json.dumps({"format": "tableau_lab/scene/1", "name": "ode", "problem": {"define": ODE},
                             "h": "1/10", "steps": 10, "runs": [{"method": str(METHODS / "gauss2.json")}]}))
    assert main(["run", str(p), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "max |ΔI|: none" in out and not re.search(r"max \|ΔI\|: ,", out), out
    ax = figures["ode_state.png"].axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("$x$", "$v$")


def test_invariants_plot_of_a_problem_without_invariants_is_refused(tmp_path):
    from tableau_lab.experiments.scene import SceneError, load_scene
    p = tmp_path / "scene.json"
    p.write_text(json.dumps({"format": "tableau_lab/scene/1", "name": "ode", "problem": {"define": ODE},
                             "h": "1/10", "steps": 10, "plots": ["invariants"],
                             "runs": [{"method": str(METHODS / "gauss2.json")}]}))
    with pytest.raises(SceneError, match="no invariants to plot"):
        load_scene(p)


# -- item 11: a start the working precision cannot hold -----------------------------------------

@pytest.mark.parametrize("problem, q0, what", [("harmonic", "1e200", "H(y0)"), ("kepler", "1e200,0", "Jacobian")])
def test_start_out_of_range_fails_at_step_0(problem, q0, what, capsys):
    """``--q0 1e200``: H = q²/2 overflows float64 (5ea0488: "H nan", exit 0) — the run fails
    at step 0, naming what is not finite."""
    code = main(["run", "--method", str(METHODS / "gauss2.json"), "--problem", problem, "--h", "1/10",
                 "--steps", "10", "--q0", q0])
    err = capsys.readouterr().err
    assert code == 1 and "step 0" in err and what in err and "nan" not in err, err
