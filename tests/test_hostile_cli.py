"""The hostile-input corpus (tests/hostile_cases.py) through the command line, in process: every
case ends with its exit code (2: refused), a message naming the file, entry or option, no
traceback, within its time budget, and nothing written (the case's folder holds only its input
files afterwards; the working directory is the case's folder)."""
import os
import sys
import time

import pytest

sys.path.insert(0, os.path.dirname(__file__))
from hostile_cases import CASES, SLACK, run_case

from tableau_lab.cli import main


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_hostile_case(case):
    r = run_case(case, main)
    err = r["err"]
    assert r["code"] == case.exit, f"exit {r['code']}, expected {case.exit}: {err[-500:]}"
    assert "Traceback" not in err and "internal error" not in err, err[-1000:]
    assert case.fragment.lower() in err.lower(), err[-500:]
    assert r["seconds"] < r["budget"] + SLACK, f"{r['seconds']:.1f} s"
    assert not r["added"] and not r["executed"], f"files written on refusal: {r['added']}"


def test_corpus_size():
    """Issue 16 asks for at least 200 hostile cases in tests/ (with tests/test_hostile_scenes.py)."""
    assert len(CASES) >= 150 and len({c.id for c in CASES}) == len(CASES)


def _stuck(args):
    """A computation the alarm cannot stop (as a long call into FLINT: SIGALRM blocked)."""
    import signal
    signal.pthread_sigmask(signal.SIG_BLOCK, [signal.SIGALRM])
    time.sleep(60)
    return 0


def test_hard_deadline_kills_an_uninterruptible_computation(capsys):
    """As the program (cli.main without argv), an exact command runs in a child that is killed
    HARD_GRACE s after its budget: exit 2, the budget named, within budget + grace + 1 s."""
    import argparse

    from tableau_lab import cli
    args = argparse.Namespace(command="verify", files=["m.json"], timeout=1.0, max_field_degree=64, debug=False,
                              run=_stuck)
    t0 = time.perf_counter()
    code = cli.run_with_hard_deadline(args)
    seconds = time.perf_counter() - t0
    err = capsys.readouterr().err
    assert code == 2 and "time budget of 1 s exceeded" in err and "verify of m.json" in err, err
    assert 1 + cli.HARD_GRACE - 0.5 < seconds < 1 + cli.HARD_GRACE + 1.5


def test_hard_deadline_passes_the_exit_code():
    import argparse

    from tableau_lab import cli
    args = argparse.Namespace(command="verify", files=["m.json"], timeout=30.0, max_field_degree=64, debug=False,
                              run=lambda a: 1)
    assert cli.run_with_hard_deadline(args) == 1


def test_sigterm_stops_like_ctrl_c(tmp_path):
    """SIGTERM to the program: exit 143, one line, no traceback (errors.Terminated)."""
    import signal
    import subprocess
    p = subprocess.Popen([sys.executable, "-m", "tableau_lab", "run", "--method", "gauss2", "--problem", "pendulum",
                          "--h", "1/100", "--steps", "100000000", "--precision", "mp:15"],
                         cwd=tmp_path, stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    time.sleep(4)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 143 and "terminated" in err and "Traceback" not in err, err[-500:]
