"""Issue 14, item 8: the one step core computes what the three loops it replaced computed.

``tests/data/finals_1977dd2.json`` holds the final states and max |H − H₀| of every method of
methods/ on every built-in problem after 10⁵ steps, computed by the previous version (commit
1977dd2: the float64 loop kept as a string) with ``benchmarks/regression/finals.py`` run with
that commit on PYTHONPATH.  The new core reaches the stages by other iterations (fixed point on
the q stages, a predicted start, other stopping rules), so its rounding errors differ:

* explicit methods: the same numbers, bit for bit;
* where the two versions differ by more than 1e-12 (relative), both are measured against the
  same method run in double-double (about 32 digits; ``tests/data/finals_dd.json``, by
  ``finals.py tests/data/finals_dd.json --precision dd --cases benchmarks/regression/dd_cases.json``):
  the new loop must be about as close to it as the old one was —
  its own rounding error, not a change of the method — and it is closer in most cases;
* elsewhere the two agree to 1e-12; where the problem is chaotic (Hénon–Heiles) or the method
  parasitic (Example 4 on the pendulum), round-off decides the final state after 10⁵ steps and
  only the energy errors are compared, to two digits where they are above round-off;
* where the old run broke down (parasitism), the new one breaks down too;
* the explicit GLMs whose starting method changed since (leapfrog and AB2 as GLMs: issue 29, item 6,
  the order-p part of the start is now the one that realises the stage order) are measured against
  the double-double run of the same method and start only (measured: 5e-12 on the pendulum, 6e-11
  on Kepler, relative, after 10⁵ steps; their finals moved by 4e-3 and 1.3 on Kepler's orbit phase).
"""
import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from tableau_lab.experiments.runs import prepare_run
from tableau_lab.numeric.integrate import IntegrationError, integrate

ROOT = Path(__file__).parent.parent
OLD = json.loads((Path(__file__).parent / "data" / "finals_1977dd2.json").read_text())
DD = json.loads((Path(__file__).parent / "data" / "finals_dd.json").read_text())
CHAOTIC = {"henon_heiles", "example4_glm pendulum"}
STEP = {"harmonic": "1/100", "pendulum": "1/100", "kepler": "1/100", "kepler_unperturbed": "1/100",
        "henon_heiles": "1/100", "fpu": "1/1000", "outer_solar_system": "10"}
METHODS = sorted({key.split()[0] for key in OLD})      # the methods the previous loops ran
CASES = [(m, p) for m in METHODS for p in ("pendulum", "kepler")]
CASES += [(m, p) for m in ("gauss2", "gauss3", "glm43")
          for p in ("harmonic", "kepler_unperturbed", "henon_heiles", "fpu")]
# the outer solar system once: even its entry points for the linked loop take seconds (30 coordinates)
CASES += [("gauss3", "outer_solar_system")]
STEPS = 10 ** 5
NEW_START = {"leapfrog", "adams_bashforth2"}           # starting method changed after 1977dd2 (issue 29, item 6)


@pytest.fixture(autouse=True)
def _linked(monkeypatch):
    """The compiled loop shared by every problem (numeric/linked.py): bit for bit the loop for any
    shape and the specialised ones (tests/test_kernels.py), and a new problem costs only its entry
    points (about a second each) instead of a loop module (25-75 s for the outer solar system)."""
    monkeypatch.setenv("TABLEAU_LAB_SPECIALISE", "linked")


def _run(method, problem):
    _, _, cp, nm = prepare_run(str(ROOT / "methods" / f"{method}.json"), problem, "float64", None)
    run = integrate(nm, cp, cp.y0, sp.Rational(STEP[problem]), STEPS, invariants=("H",), record_every=STEPS,
                    kernel="compiled")
    return np.array([float(x) for x in run.final]), run.max_invariant_error()["H"], nm.explicit


@pytest.mark.parametrize("method, problem", CASES)
def test_same_finals_as_the_previous_loops(method, problem):
    key = f"{method} {problem}"
    old = OLD[key]
    try:
        new, H, explicit = _run(method, problem)
    except IntegrationError as exc:
        assert "failed" in old, f"the new loop fails where the old did not: {exc}"
        return
    if "failed" in old:             # the old run broke down (parasitism): the new one is destroyed too
        assert not np.all(np.isfinite(new)) or H > 1, (old["failed"], H)
        return
    if method in NEW_START:         # the previous finals came from another start: the same start in dd
        exact = np.array([float(x) for x in DD[key]["final"]])
        assert np.max(np.abs(new - exact)) / np.max(np.abs(exact)) <= 1e-10
        assert abs(H - DD[key]["H"]) <= 1e-6 * DD[key]["H"], (H, DD[key]["H"])
        return
    ref, Hold = np.array(old["final"]), old["H"]
    if not np.all(np.isfinite(ref)):
        assert not np.all(np.isfinite(new))
        return
    scale = np.max(np.abs(ref))
    rel = np.max(np.abs(new - ref)) / scale
    if explicit:
        assert rel == 0
    elif key in DD:
        exact = np.array([float(x) for x in DD[key]["final"]])
        new_err, old_err = (np.max(np.abs(y - exact)) / scale for y in (new, ref))
        assert new_err <= max(5 * old_err, 5e-12), (new_err, old_err)
    elif not (problem in CHAOTIC or key in CHAOTIC):
        assert rel <= 1e-12, rel
    if max(H, Hold) > 1e-12:
        assert abs(H - Hold) <= 0.05 * max(H, Hold), (H, Hold)
