"""Issue 19, item 4: long runs and slow compiles show progress on a terminal, and nothing
elsewhere; the bar writes to the process's own stderr (the CLI's stderr wrapper escapes control
characters) and escapes the description, which may come from a file."""
import sys
import time
from types import SimpleNamespace

from tableau_lab.experiments import progress
from tableau_lab.numeric import kernels, limits


def test_step_bar_draws_on_a_terminal_only(capfd):
    with progress.StepBar(100, "quiet", show=False) as tick:
        tick(50)
    assert capfd.readouterr().err == ""
    with progress.StepBar(100, "shown", show=True) as tick:
        tick(50)
        tick(100)
    err = capfd.readouterr().err
    assert "shown" in err and "/100" in err and "step" in err          # tqdm throttles the updates


def test_bar_escapes_a_hostile_description(capfd):
    with progress.StepBar(10, "GLM\x1b[2J\x1b]0;owned\x07", show=True) as tick:
        tick(10)
    err = capfd.readouterr().err
    assert "\x1b[2J" not in err and "\x1b]0;" not in err and "GLM" in err


def test_slow_compile_is_announced_on_a_terminal(capfd, monkeypatch):
    """A compile whose state is not known beforehand (a loop without a file): announced late, on
    a terminal only (the known cold compile: tests/test_latency.py)."""
    monkeypatch.setattr(limits, "COMPILE_NOTICE_SECONDS", 0.01)
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    unknown = SimpleNamespace(__name__="loop_without_a_file")
    with kernels._compile_notice(unknown):
        time.sleep(0.2)
    err = capfd.readouterr().err
    assert "compiling the step loop" in err and "compiled in" in err
    monkeypatch.setattr(sys.stderr, "isatty", lambda: False, raising=False)
    with kernels._compile_notice(unknown):
        time.sleep(0.05)
    assert capfd.readouterr().err == ""


def test_quick_run_shows_a_bar_from_the_threshold(capfd, monkeypatch):
    from tableau_lab.experiments.runs import quick_run
    monkeypatch.setattr(progress, "QUICK_RUN_BAR_STEPS", 50)
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    import sympy as sp
    quick_run("methods/gauss2.json", "harmonic", sp.Rational(1, 10), 40)
    assert "step" not in capfd.readouterr().err
    out = quick_run("methods/gauss2.json", "harmonic", sp.Rational(1, 10), 60)
    assert "/60" in capfd.readouterr().err and out["steps"] == 60
