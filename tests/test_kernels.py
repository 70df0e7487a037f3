"""The compiled float64 loop against the pure-Python loop: the same algorithm, so the same
numbers to round-off and the same f-evaluation and Newton counts, for every method kind
(explicit, implicit with invertible or singular A, partitioned, GLM), with and without
projection; and the extrapolated stage start pays (fewer f-evaluations than a restart)."""
import dataclasses
from pathlib import Path

import numpy as np
import pytest

from tableau_lab.exact.tableau_json import load
from tableau_lab.numeric.codegen import compile_problem
from tableau_lab.numeric.export import to_numeric
from tableau_lab.numeric.integrate import integrate
from tableau_lab.numeric.kernels import cache_dir, kernel_module

METHODS = Path(__file__).parent.parent / "methods"
CASES = ["gauss2", "rk4", "implicit_midpoint", "example4_glm", "stormer_verlet", "symplectic_euler",
         "lobatto_iiia3", "radau_iia3", "leapfrog"]


@pytest.mark.parametrize("problem", ["pendulum", "kepler"])
@pytest.mark.parametrize("name", CASES)
def test_compiled_equals_pure(name, problem):
    nm = to_numeric(load(METHODS / f"{name}.json"))
    cp = compile_problem(problem)
    steps = 300
    fast = integrate(nm, cp, cp.y0, 0.01, steps, kernel="compiled", invariants=tuple(cp.problem.invariants),
                     record_every=50)
    slow = integrate(nm, cp, cp.y0, 0.01, steps, kernel="python", invariants=tuple(cp.problem.invariants),
                     record_every=50)
    assert fast.completed == slow.completed == steps
    assert np.max(np.abs(fast.final - slow.final)) <= 1e-13 * steps
    assert abs(fast.nfev - slow.nfev) <= 0.01 * slow.nfev and abs(fast.newton_iterations - slow.newton_iterations) <= 2
    assert fast.times == slow.times
    for k in fast.invariant_errors:
        assert np.allclose(fast.invariant_errors[k], slow.invariant_errors[k], rtol=0, atol=1e-13 * steps)


@pytest.mark.parametrize("project", [("H",), ("H", "L")])
def test_compiled_projection_equals_pure(project):
    nm = to_numeric(load(METHODS / "rk4.json"))
    cp = compile_problem("kepler")
    steps_ = 400
    fast = integrate(nm, cp, cp.y0, 0.01, steps_, kernel="compiled", project=project, invariants=project)
    slow = integrate(nm, cp, cp.y0, 0.01, steps_, kernel="python", project=project, invariants=project)
    assert np.max(np.abs(fast.final - slow.final)) <= 1e-12
    assert slow.projection_iterations > 0 and abs(fast.projection_iterations - slow.projection_iterations) <= 0.02 * steps_
    assert max(fast.max_invariant_error().values()) <= 1e-14


def test_extrapolated_start_saves_f_evaluations():
    """GNI's start (the previous stage derivatives extrapolated): 2-stage Gauss at h = 0.01 needs
    about 5 f-evaluations per step on the pendulum (q0 = 2.3) and Kepler (e = 0.6), fewer than
    starting every step from Ū (Z = 0) with the same stopping test."""
    nm = to_numeric(load(METHODS / "gauss2.json"))
    restart = dataclasses.replace(nm, E=None)
    for problem in ("pendulum", "kepler"):
        cp = compile_problem(problem)
        with_e = integrate(nm, cp, cp.y0, 0.01, 2000).nfev / 2000
        without = integrate(restart, cp, cp.y0, 0.01, 2000).nfev / 2000
        assert with_e <= 6.5 and without > with_e, (problem, with_e, without)


def test_failing_step_handed_back_to_the_pure_path():
    """h = 20 on the pendulum: simplified Newton fails; the pure path (full Newton, fixed point)
    redoes the step and the error names the step and time, as without the compiled loop."""
    from tableau_lab.numeric.integrate import IntegrationError
    nm = to_numeric(load(METHODS / "gauss2.json"))
    cp = compile_problem("pendulum")
    msgs = []
    for kernel in ("compiled", "python"):
        with pytest.raises(IntegrationError) as exc:
            integrate(nm, cp, cp.y0, 20, 10, kernel=kernel)
        msgs.append(str(exc.value))
    assert all("step 3 (t = 60): the implicit stage equations did not converge" in m for m in msgs)


def test_kernel_source_cached_on_disk():
    mod = kernel_module(compile_problem("pendulum").problem)
    assert Path(mod.__file__).parent == cache_dir() and Path(mod.__file__).exists()
    assert mod is kernel_module(compile_problem("pendulum", parameters={"q0": 1}).problem)   # parameters are data


@pytest.mark.parametrize("name, problem, project", [("gauss2", "pendulum", ()), ("example4_glm", "pendulum", ()),
                                                      ("rk4", "kepler", ("H", "L")), ("stormer_verlet", "kepler", ())])
def test_double_double_agrees_with_mpmath_32(name, problem, project):
    """The compiled double-double loop against the pure loop in mpmath at 32 digits: the same
    algorithm, agreeing to the dd round-off (u² = 2^-106 ≈ 1e-32, times the steps)."""
    import mpmath
    import sympy as sp
    cp = compile_problem(problem, "mpmath", dps=32)
    steps = 200
    runs = [integrate(to_numeric(load(METHODS / f"{name}.json"), prec), cp, cp.y0, sp.Rational(1, 100), steps,
                      project=project, invariants=project, record_every=100) for prec in ("dd", "mp:32")]
    with mpmath.workdps(40):
        diff = max(abs(a - b) for a, b in zip(runs[0].final, runs[1].final))
    assert diff < 1e-31 * steps, mpmath.nstr(diff, 3)
    assert abs(runs[0].nfev - runs[1].nfev) <= 0.05 * runs[1].nfev
    if project:
        assert max(runs[0].max_invariant_error().values()) < 1e-29


def test_fixed_point_stage_iteration():
    """solver="fixedpoint" (Newton with M = I): compiled and pure loops agree and count the same
    f-evaluations; on a non-stiff problem it reaches the same stages as simplified Newton (to
    round-off); "auto" picks it only for many components and a small h·ρ(f')."""
    from tableau_lab.numeric.integrate import _fixed_point
    nm = to_numeric(load(METHODS / "gauss2.json"))
    cp = compile_problem("kepler")
    runs = {(k, s): integrate(nm, cp, cp.y0, 0.01, 300, kernel=k, solver=s)
            for k in ("compiled", "python") for s in ("fixedpoint", "newton")}
    fast, slow = runs["compiled", "fixedpoint"], runs["python", "fixedpoint"]
    assert np.max(np.abs(fast.final - slow.final)) < 1e-12 and abs(fast.nfev - slow.nfev) <= 0.01 * slow.nfev
    assert np.max(np.abs(fast.final - runs["compiled", "newton"].final)) < 1e-12
    assert fast.nfev > runs["compiled", "newton"].nfev          # more sweeps, but no Jacobian and no LU
    solar, fpu = compile_problem("outer_solar_system"), compile_problem("fpu")
    assert _fixed_point("auto", nm, solar, solar.y0, 10, 36)            # ρ(f') ≈ 1e-3 per day, d = 36
    assert not _fixed_point("auto", nm, fpu, fpu.y0, 0.001, 12)         # s·d = 24: Newton
    assert not _fixed_point("auto", nm, cp, cp.y0, 0.01, 4)
