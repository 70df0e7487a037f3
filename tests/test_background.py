"""A run that starts in the pure loop and goes on compiled once a background compile is done
(numeric/background.py, kernels.drive's switch): the switch itself changes no number (a switch
to the same loop is bit for bit the run without one, records and counters included), a switch to
the compiled loop agrees with the pure run to round-off as tests/test_kernels.py holds the two
loops, and the compile happens in a child process, announced once per problem."""
from pathlib import Path

import numpy as np
import pytest

from tableau_lab.exact.tableau_json import load
from tableau_lab.numeric import background, kernels, limits
from tableau_lab.numeric.codegen import compile_problem
from tableau_lab.numeric.export import to_numeric
from tableau_lab.numeric.integrate import integrate

METHODS = Path(__file__).parent.parent / "methods"


def _glm_on_kepler():
    nm, cp = to_numeric(load(METHODS / "glm43.json")), compile_problem("kepler")
    return nm, cp, tuple(cp.problem.invariants)


def test_switch_to_the_same_loop_changes_nothing(monkeypatch):
    """drive's switch between chunks, to another pure loop: the records re-allocated for the
    longer chunks, the counters carried: every number equal to the run without a switch."""
    nm, cp, inv = _glm_on_kepler()
    plain = integrate(nm, cp, cp.y0, 0.01, 700, kernel="python", invariants=inv, record_every=7)
    asked = []

    def drive(loop, pk, Y, steps, every, **kw):
        def switch():
            asked.append(len(asked))
            return kernels.pure_loop(cp, "float64") if len(asked) == 2 else None
        return original(loop, pk, Y, steps, every, **dict(kw, switch=switch))
    original = kernels.drive
    monkeypatch.setattr(kernels, "drive", drive)
    switched = integrate(nm, cp, cp.y0, 0.01, 700, kernel="python", invariants=inv, record_every=7)
    assert len(asked) == 2                         # asked after each pure chunk until it switched
    assert switched.switched_at == 2 * 256 and switched.loop == "python, then compiled"
    assert np.array_equal(switched.final, plain.final)
    assert switched.times == plain.times and switched.invariant_errors == plain.invariant_errors
    assert (switched.nfev, switched.newton_iterations) == (plain.nfev, plain.newton_iterations)
    assert switched.tracked == plain.tracked


def test_background_compile_then_switch(monkeypatch, capsys):
    """kernel="cost" on a loop not compiled yet: the run starts in Python, a child compiles the
    loop (the pendulum's, which tests/test_kernels.py compiles too: one compile for both), the
    run switches at the next chunk boundary once it is done, and agrees with the pure run."""
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "auto")
    monkeypatch.setenv("TABLEAU_LAB_BACKGROUND", "1")
    monkeypatch.setattr(background, "worth", lambda seconds: True)
    monkeypatch.setattr(kernels, "compile_state", lambda *a, disk=True, **k: "cold" if disk else None)
    monkeypatch.setattr(kernels, "linked_state", lambda shape: "cold")    # no shared loop built either
    monkeypatch.setattr(limits, "NUMBA_START_SECONDS", 0.0)    # as if numba were imported: a load costs 0.5 s
    monkeypatch.setattr(background, "_ALL", {})   # as in a fresh process
    monkeypatch.setattr(background, "_TOLD", set())
    nm, cp = to_numeric(load(METHODS / "gauss2.json")), compile_problem("pendulum")
    steps, inv = 6000, tuple(cp.problem.invariants)   # predicted above a cache load in Python
    started = []
    real_start = background.start

    def start(*args, **kw):
        c = real_start(*args, **kw)
        started.append(c)
        assert background.wait_all(timeout=300)  # the compile done before the run's first chunk ends
        return c
    monkeypatch.setattr(background, "start", start)
    run = integrate(nm, cp, cp.y0, 0.01, steps, kernel="cost", invariants=inv, record_every=100)
    pure = integrate(nm, cp, cp.y0, 0.01, steps, kernel="python", invariants=inv, record_every=100)
    assert len(started) == 1 and started[0].ok, "the background compile failed"
    assert run.loop == "python, then compiled" and run.switched_at == 256
    assert "background" in run.loop_why
    assert np.max(np.abs(run.final - pure.final)) <= 1e-13 * steps
    assert abs(run.nfev - pure.nfev) <= 0.01 * pure.nfev and run.times == pure.times
    err = capsys.readouterr().err
    assert err.count("in the background (one-off, cached in") == 1 and "pendulum" in err
    background.announce(cp.problem, "f64")        # once per problem and arithmetic in a process
    assert capsys.readouterr().err == ""


def test_cost_rule_takes_the_shared_loop_when_built(monkeypatch):
    """kernel="cost", the specialised loop not compiled but the linked loop shared by every problem
    built (kernels.linked_state): the run goes on the linked loop (its record says so), not in
    Python and not through a compile; with the shared loop not built either, a background compile."""
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "auto")
    monkeypatch.setenv("TABLEAU_LAB_SPECIALISE", "1")
    nm, cp, inv = _glm_on_kepler()
    monkeypatch.setattr(kernels, "compile_state", lambda *a, disk=True, **k: "cold" if disk else None)
    monkeypatch.setattr(kernels, "linked_state", lambda shape: "cached")
    asked = []

    def linked_loop(problem, shape):                # the decision only: the loop itself is test_kernels.py's
        asked.append(shape)
        return kernels.pure_loop(cp, "float64")
    monkeypatch.setattr(kernels, "linked_loop", linked_loop)
    run = integrate(nm, cp, cp.y0, 0.01, 3000, kernel="cost", invariants=inv)
    assert run.loop == "linked" and "shared by every problem" in run.loop_why
    assert len(asked) == 1 and (asked[0].s, asked[0].r, asked[0].d) == (4, 3, 4)
    monkeypatch.setattr(kernels, "linked_state", lambda shape: "cold")
    monkeypatch.setattr(background, "possible", lambda: False)
    short = integrate(nm, cp, cp.y0, 0.01, 300, kernel="cost", invariants=inv)
    assert short.loop == "python"                  # the cost rule: 300 steps in Python, cheaper than a compile


def test_missing_shared_loop_builds_in_the_background(monkeypatch, tmp_path, capsys):
    """kernel="cost" on a fresh installation: neither the loop specialised to the run nor the loop
    shared by every problem for its stage iteration is built.  The run starts in Python while a
    child builds THAT shared loop (RK4: explicit, no projection, the cheapest) into the shared
    folder; the run goes on it at the next chunk boundary, with the pure run's numbers (the two
    loops execute the same stepcore: bit for bit here, same f-evaluations), the build announced
    once; the next run of any problem of that stage iteration takes the built loop at once."""
    pytest.importorskip("numba")
    for name, value in (("KERNEL", "auto"), ("BACKGROUND", "1"), ("SPECIALISE", "1"), ("SHARED_CACHE", str(tmp_path))):
        monkeypatch.setenv(f"TABLEAU_LAB_{name}", value)
    monkeypatch.setattr(background, "worth", lambda seconds: True)
    monkeypatch.setattr(kernels, "compile_state", lambda *a, disk=True, **k: "cold" if disk else None)
    monkeypatch.setattr(limits, "NUMBA_START_SECONDS", 0.0)
    for name, fresh in (("_ALL", {}), ("_TOLD", set())):          # as in a fresh process
        monkeypatch.setattr(background, name, fresh)
    for name in ("_COMPILE", "_BY_KEY"):                          # no shared loop loaded by another test
        monkeypatch.setattr(kernels, name, {})
    nm, cp = to_numeric(load(METHODS / "rk4.json")), compile_problem("pendulum")
    steps, inv = 15000, tuple(cp.problem.invariants)      # predicted longer in Python than a cache load
    started = []
    real_start = background.start_shared

    def start_shared(*args, **kw):
        c = real_start(*args, **kw)
        started.append(c)
        assert background.wait_all(timeout=120)  # built before the run's first chunk ends
        return c
    monkeypatch.setattr(background, "start_shared", start_shared)
    run = integrate(nm, cp, cp.y0, 0.01, steps, kernel="cost", invariants=inv, record_every=100)
    assert len(started) == 1 and started[0].ok, "the background build failed"
    assert started[0].files[3].startswith(str(tmp_path))            # the shared folder, not the problems' cache
    assert any(tmp_path.glob("__pycache__/tableau_lab_kernel_*.run-*.nbi"))
    assert run.loop == "python, then linked" and run.switched_at == 256, (run.loop, run.switched_at)
    assert "shared by every problem" in run.loop_why
    pure = integrate(nm, cp, cp.y0, 0.01, steps, kernel="python", invariants=inv, record_every=100)
    assert np.max(np.abs(run.final - pure.final)) <= 1e-13 * steps
    assert run.nfev == pure.nfev and run.times == pure.times
    err = capsys.readouterr().err
    assert err.count("building the step loop shared by every problem (float64, any shape, explicit") == 1
    again = integrate(nm, cp, cp.y0, 0.01, steps, kernel="cost", invariants=inv, record_every=100)
    assert again.loop == "linked" and len(started) == 1
    assert np.array_equal(again.final, run.final)


def test_switch_moves_only_to_a_better_loop(monkeypatch):
    """switch_when_ready over (compile, loop) choices, the best first (the specialised loop, then the
    shared one): it hands over the shared loop once built, then the specialised one once compiled,
    each once; a failed compile is passed over; never back to a worse loop."""
    monkeypatch.setattr(background, "_ALL", {})

    class Fake:
        def __init__(self):
            self.ok = None

        def poll(self):
            return self.ok
    special, shared = Fake(), Fake()
    switch = background.switch_when_ready((special, lambda: "specialised"), (shared, lambda: "linked"))
    assert switch() is None
    shared.ok = True
    assert switch() == "linked" and switch() is None
    special.ok = True
    assert switch() == "specialised" and switch() is None
    failed = Fake()
    failed.ok = False
    switch = background.switch_when_ready((failed, lambda: "specialised"), (shared, lambda: "linked"))
    assert switch() == "linked" and switch() is None


def test_cost_rule_prices_projection(monkeypatch):
    """The Python loop's predicted time counts the projection (limits.PYTHON_PROJECTION_FACTOR):
    explicit Euler projected onto the pendulum's energy costs about three times its step
    unprojected (docs/speed.md), and the cost rule's prediction for such a run is within a factor
    two of the run's measured CPU time (before: a third of it, so long projected runs stayed in
    Python)."""
    import re
    import time
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "auto")
    monkeypatch.setattr(kernels, "compile_state", lambda *a, disk=True, **k: "cold" if disk else None)
    monkeypatch.setattr(kernels, "linked_state", lambda shape: "cold")
    monkeypatch.setattr(background, "possible", lambda: False)
    nm, cp = to_numeric(load(METHODS / "explicit_euler.json")), compile_problem("pendulum")
    steps = 20000
    t = time.process_time()
    run = integrate(nm, cp, cp.y0, 0.01, steps, kernel="cost", project=("H",))
    cpu = time.process_time() - t
    assert run.loop == "python"
    predicted = float(re.search(r"predicted at ([0-9.e+-]+) s", run.loop_why).group(1))
    assert 0.5 * cpu <= predicted <= 2 * cpu, (predicted, cpu)


def test_long_linked_run_moves_to_its_specialised_loop(monkeypatch):
    """A run on the built linked loop long enough to repay its specialised loop's compile
    (limits.specialised_repays) has that compiled in the background and moves to it between
    chunks (record 'linked, then compiled'); a shorter one asks for no compile.  The loops here
    are stand-ins (the pure loop), so the move must change no number."""
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "auto")
    monkeypatch.setenv("TABLEAU_LAB_SPECIALISE", "1")
    nm, cp, inv = _glm_on_kepler()
    monkeypatch.setattr(kernels, "compile_state", lambda *a, disk=True, **k: "cold" if disk else None)
    monkeypatch.setattr(kernels, "linked_state", lambda shape: "cached")
    monkeypatch.setattr(kernels, "linked_loop", lambda problem, shape: kernels.pure_loop(cp, "float64"))
    monkeypatch.setattr(kernels, "compiled_loop", lambda problem, kind, shape: kernels.pure_loop(cp, "float64"))
    monkeypatch.setattr(background, "possible", lambda: True)
    monkeypatch.setattr(limits, "NUMBA_START_SECONDS", 0.0)    # as if numba were imported: a load costs 0.5 s
    asked = []

    class Done:
        ok = True

        def poll(self):
            return True

    def start(problem, kind, shape, args):
        asked.append(shape)
        return Done()
    monkeypatch.setattr(background, "start", start)
    plain = integrate(nm, cp, cp.y0, 0.01, 2000, kernel="python", invariants=inv, record_every=7)
    short = integrate(nm, cp, cp.y0, 0.01, 2000, kernel="cost", invariants=inv, record_every=7)
    assert short.loop == "linked" and asked == []
    monkeypatch.setattr(limits, "specialised_repays", lambda seconds: True)
    long = integrate(nm, cp, cp.y0, 0.01, 2000, kernel="cost", invariants=inv, record_every=7)
    assert len(asked) == 1 and long.loop == "linked, then compiled" and long.switched_at == 256
    assert np.array_equal(long.final, plain.final) and long.invariant_errors == plain.invariant_errors
