"""The step core (numeric/stepcore.py) compiled and in Python: the same algorithm, so the same
numbers to round-off and the same f-evaluation and sweep counts, for every method kind
(explicit, implicit with invertible or singular A, partitioned, GLM), with and without
projection; the stage iterations (simplified Newton, fixed point, the q stages alone) reach
the same stages; the predicted start pays; the failing step, the fallbacks and the switch to
Newton on a stiff problem; the double-double loop against mpmath at 32 digits."""
from pathlib import Path

import numpy as np
import pytest

from tableau_lab.exact.tableau_json import load
from tableau_lab.numeric import limits
from tableau_lab.numeric.codegen import compile_problem
from tableau_lab.numeric.export import to_numeric
from tableau_lab.numeric.integrate import component_masks, integrate
from tableau_lab.numeric.kernels import Pack, cache_dir, compiled_loop, run_shape

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
    assert slow.projection_iterations > 0
    assert abs(fast.projection_iterations - slow.projection_iterations) <= 0.02 * steps_
    assert max(fast.max_invariant_error().values()) <= 1e-14


def test_predicted_start_and_q_stage_iteration():
    """2-stage Gauss at h = 0.01 on the pendulum (q0 = 2.3) and Kepler (e = 0.6): the stage
    iteration on the q stages alone, started from the previous steps' forces extrapolated,
    needs fewer force evaluations per step than Hairer's GNI_IRK2 (4.73 and 5.44, measured with
    gfortran in issue 14), reaches the stages of simplified Newton to round-off, and keeps
    Gauss's quadratic invariant L to round-off; without the predicted start (every step from
    Ū) the iteration costs more."""
    nm = to_numeric(load(METHODS / "gauss2.json"))
    for problem, gni in (("pendulum", 4.73), ("kepler", 5.44)):
        cp = compile_problem(problem)
        invs = tuple(cp.problem.invariants)
        split = integrate(nm, cp, cp.y0, 0.01, 2000, invariants=invs)
        newton = integrate(nm, cp, cp.y0, 0.01, 2000, invariants=invs, solver="newton")
        restart = integrate(nm, cp, cp.y0, 0.01, 2000, predict=False)
        assert split.nfev / 2000 < gni and restart.nfev > 1.2 * split.nfev, (problem, split.nfev, restart.nfev)
        assert np.max(np.abs(split.final - newton.final)) < 1e-13
        if problem == "kepler":
            assert split.max_invariant_error()["L"] < 1e-14


def test_failing_step_names_step_and_time():
    """h = 20 on the pendulum: the stage iteration fails, the fallbacks (simplified Newton, full
    Newton, fixed point on the stage values) fail too, and the error names the step and time,
    compiled as in Python."""
    from tableau_lab.numeric.integrate import IntegrationError
    nm = to_numeric(load(METHODS / "gauss2.json"))
    cp = compile_problem("pendulum")
    msgs = []
    for kernel in ("compiled", "python"):
        with pytest.raises(IntegrationError) as exc:
            integrate(nm, cp, cp.y0, 20, 10, kernel=kernel)
        msgs.append(str(exc.value))
    assert all("step 3 (t = 60): the implicit stage equations did not converge" in m for m in msgs), msgs


def test_compiled_loop_cached_on_disk():
    mod = compiled_loop(compile_problem("pendulum").problem)
    assert Path(mod.__file__).parent == cache_dir() and Path(mod.__file__).exists()
    assert mod is compiled_loop(compile_problem("pendulum", parameters={"q0": 1}).problem)   # parameters are data


@pytest.mark.parametrize("name, problem, h, kw", [
    ("gauss2", "pendulum", 0.01, {}),                                   # SPLIT
    ("rk4", "kepler", 0.01, {"project": ("H", "L")}),                   # explicit, projected
    ("example4_glm", "pendulum", 0.01, {"solver": "newton"}),           # a GLM, simplified Newton
    ("gauss2", "fpu", 0.05, {"solver": "fixedpoint"}),                  # fails, switches to the NEWTON loop
    ("glm43", "kepler", 0.01, {}),                                      # zeros in A, B, U, V
    ("symplectic_euler", "kepler", 0.01, {}),                           # A_q, A_p with other zeros
])
def test_specialised_loop_equals_generic(monkeypatch, name, problem, h, kw):
    """The loop specialised to the run (s, r, d as constants, the stage iteration and the
    projection fixed: the other branches are not compiled) computes the same numbers bit for
    bit as the loop for any shape and run, with the same counts; a run that switches to Newton
    goes on in the Newton-specialised loop."""
    nm = to_numeric(load(METHODS / f"{name}.json"))
    cp = compile_problem(problem)
    runs = []
    for flag in ("0", "1"):
        monkeypatch.setenv("TABLEAU_LAB_SPECIALISE", flag)
        runs.append(integrate(nm, cp, cp.y0, h, 200, kernel="compiled", **kw))
    assert np.array_equal(runs[0].final, runs[1].final)
    assert (runs[0].nfev, runs[0].newton_iterations, runs[0].fallbacks) == (
        runs[1].nfev, runs[1].newton_iterations, runs[1].fallbacks)
    if problem == "fpu":
        assert runs[1].fallbacks >= limits.SWITCH_AFTER


def test_linked_loop_serves_every_problem(monkeypatch):
    """The linked loop (numeric/linked.py, issue 32: the problem's functions called through
    addresses in the run's data) is one compiled module for every problem and method shape of a
    stage iteration: Gauss 2 and GLM43 (s = 2, 4; r = 1, 3) on the pendulum and on Kepler run in
    the same module, and each run computes the same numbers bit for bit, with the same counts, as
    the loop for any shape that imports the problem's functions by name (TABLEAU_LAB_SPECIALISE=0).
    Fails on 017c8cd (no linked loop: TABLEAU_LAB_SPECIALISE=linked compiled one module per problem
    and shape)."""
    modules = set()
    for name, problem in (("gauss2", "pendulum"), ("glm43", "pendulum"), ("gauss2", "kepler"), ("glm43", "kepler")):
        nm, cp = to_numeric(load(METHODS / f"{name}.json")), compile_problem(problem)
        runs = []
        for flag in ("0", "linked"):
            monkeypatch.setenv("TABLEAU_LAB_SPECIALISE", flag)
            runs.append(integrate(nm, cp, cp.y0, 0.01, 200, kernel="compiled", solver="fixedpoint"))
        assert np.array_equal(runs[0].final, runs[1].final), (name, problem)
        assert (runs[0].nfev, runs[0].newton_iterations) == (runs[1].nfev, runs[1].newton_iterations)
        shape = run_shape(Pack(nm, cp, 0.01, component_masks(cp, len(cp.y0)), mode=limits.SPLIT))
        modules.add(compiled_loop(cp.problem, "f64", shape).__name__.split(":")[0])
    assert len(modules) == 1, modules


def test_linked_loop_rescues_with_the_jacobian(monkeypatch):
    """A linked fixed-point run has no Jacobian entry point (linked.slots_needed); when its
    iteration fails, drive links the Jacobian before the rescue step and the run goes on in the
    linked Newton loop: the same numbers bit for bit, and the same counts, as the loop for any shape."""
    nm, cp = to_numeric(load(METHODS / "gauss2.json")), compile_problem("fpu")
    runs = []
    for flag in ("0", "linked"):
        monkeypatch.setenv("TABLEAU_LAB_SPECIALISE", flag)
        runs.append(integrate(nm, cp, cp.y0, 0.05, 200, kernel="compiled", solver="fixedpoint"))
    assert np.array_equal(runs[0].final, runs[1].final)
    assert (runs[0].nfev, runs[0].newton_iterations, runs[0].fallbacks) == (
        runs[1].nfev, runs[1].newton_iterations, runs[1].fallbacks)
    assert runs[1].fallbacks >= limits.SWITCH_AFTER


@pytest.mark.parametrize("name", ["glm43", "symplectic_euler", "gauss2", "example4_glm", "sdirk34"])
def test_dense_matrices_are_the_exact_zeros(name):
    """kernels.dense_matrices (the matrices whose coefficients a specialised loop uses
    without a zero test) against the exact method: DENSE_X is 1 iff no entry of X is 0 in either
    class (A_q and A_p, B_q and B_p); the double-double arrays give the same flags."""
    import sympy as sp

    from tableau_lab.numeric.integrate import component_masks
    from tableau_lab.numeric.kernels import DENSE, Pack, dense_matrices
    m = load(METHODS / f"{name}.json")
    cp = compile_problem("kepler")
    masks = component_masks(cp, 4)
    got = [dense_matrices(Pack(to_numeric(m, prec), cp, 0.01, masks, mode=limits.SPLIT)) for prec in ("float64", "dd")]
    assert got[0] == got[1] and len(got[0]) == len(DENSE)
    if m.kind in ("rk", "prk"):               # one step: U = 1, V = [1], B = bᵀ; a PRK's second tableau is Â, b̂
        A2, b2 = (m.Ahat, m.bhat) if m.kind == "prk" else (m.A, m.b)
        exact = {"A": (m.A, A2), "B": (m.b.T, b2.T), "U": (sp.ones(m.s, 1),) * 2, "V": (sp.Matrix([[1]]),) * 2}
    else:
        g = m.as_glm()
        exact = {X: (getattr(g, X),) * 2 for X in "ABUV"}
    for k, X in enumerate("ABUV"):
        q, p = (sp.Matrix(M) for M in exact[X])
        assert got[0][k] == int(all(x != 0 for x in list(q) + list(p))), X


def test_loop_shape_names_the_run(monkeypatch):
    from tableau_lab.numeric.kernels import Shape, loop_shape
    monkeypatch.setenv("TABLEAU_LAB_SPECIALISE", "1")
    assert loop_shape(2, 1, 4, limits.SPLIT, False) == Shape(2, 1, 4, limits.SPLIT, 0)
    with pytest.raises(ValueError, match="FULL|mode 3"):
        loop_shape(2, 1, 4, limits.FULL)


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
        diff = max(abs(a - b) for a, b in zip(runs[0].final, runs[1].final, strict=False))
    assert diff < 1e-31 * steps, mpmath.nstr(diff, 3)
    # the same iteration; the tolerances differ (dd: u = 2^-104 ≈ 4.9e-32, mp:32: 1e-32), a sweep
    # in some steps
    assert abs(runs[0].nfev - runs[1].nfev) <= 0.15 * runs[1].nfev
    if project:
        assert max(runs[0].max_invariant_error().values()) < 1e-29


def test_stage_iteration_choice_and_switch_to_newton():
    """"auto": fixed point (on the q stages: all built-in problems are separable) where
    h·‖A‖∞·ρ(f′) is small, whatever the dimension; simplified Newton where fixed point does not
    contract (FPU with ω = 50 at h = 0.05).  Forced fixed point on that stiff case fails, and after
    SWITCH_AFTER failed steps the run goes on with Newton, to the same result; every iteration
    reaches the same stages (compiled = pure, fixed point = Newton) on a non-stiff problem."""
    from tableau_lab.numeric.integrate import stage_iteration
    nm = to_numeric(load(METHODS / "gauss2.json"))
    cp = compile_problem("kepler")
    solar, fpu = compile_problem("outer_solar_system"), compile_problem("fpu")
    assert stage_iteration("auto", nm, solar, solar.y0, 10, 36) == limits.SPLIT      # ρ(f′) ≈ 1e-3 per day
    assert stage_iteration("auto", nm, fpu, fpu.y0, 0.001, 12) == limits.SPLIT       # small: any dimension
    assert stage_iteration("auto", nm, fpu, fpu.y0, 0.05, 12) == limits.NEWTON       # h ω = 2.5: stiff
    assert stage_iteration("fixedpoint", nm, cp, cp.y0, 0.01, 4) == limits.SPLIT
    runs = {(k, s): integrate(nm, cp, cp.y0, 0.01, 300, kernel=k, solver=s)
            for k in ("compiled", "python") for s in ("fixedpoint", "newton")}
    fast, slow = runs["compiled", "fixedpoint"], runs["python", "fixedpoint"]
    assert np.max(np.abs(fast.final - slow.final)) < 1e-13 and abs(fast.nfev - slow.nfev) <= 0.01 * slow.nfev
    assert np.max(np.abs(fast.final - runs["compiled", "newton"].final)) < 1e-12
    forced = integrate(nm, fpu, fpu.y0, 0.05, 200, solver="fixedpoint", kernel="compiled")
    newton = integrate(nm, fpu, fpu.y0, 0.05, 200, solver="newton", kernel="compiled")
    assert forced.fallbacks >= limits.SWITCH_AFTER and newton.fallbacks == 0
    assert np.max(np.abs(forced.final - newton.final)) < 1e-10


def test_stage_iteration_chosen_by_cost():
    """Issue 29, item 12: the stage iteration is the cheaper by the cost model
    (limits.iteration_costs), not a threshold on κ = h·‖A‖∞·ρ(f′): fixed point on the q stages
    where it contracts fast enough — 3-stage Gauss on Kepler (e = 0.6) at h = 1/50 and 1/25,
    2-stage Gauss on the outer solar system at h = 100 days (5ea0488 chose Newton at κ ≥ 0.1, and
    its step cost 6× and 47× the smaller h's for the same f-evaluations) — and Newton where
    fixed point does not contract (FPU, ω = 50, h = 0.05: hω = 2.5).  The model's sweep count is
    an upper bound of the sweeps the chosen iteration makes, and that iteration converges without
    a fallback to the stages Newton finds."""
    from tableau_lab.numeric.integrate import stage_iteration
    g2, g3 = (to_numeric(load(METHODS / f"{m}.json")) for m in ("gauss2", "gauss3"))
    kepler, solar, fpu = compile_problem("kepler"), compile_problem("outer_solar_system"), compile_problem("fpu")
    for h in (0.01, 0.02, 0.04):
        assert stage_iteration("auto", g3, kepler, kepler.y0, h, 4) == limits.SPLIT, h
    assert stage_iteration("auto", g2, solar, solar.y0, 100, 36) == limits.SPLIT
    for nm in (g2, g3):
        assert stage_iteration("auto", nm, fpu, fpu.y0, 0.05, 12) == limits.NEWTON
    h, steps = 0.04, 2000
    kappa = g3.stage_scale(h) * float(np.max(np.abs(np.linalg.eigvals(kepler.jac(kepler.y0)))))
    auto = integrate(g3, kepler, kepler.y0, h, steps, kernel="compiled")
    newton = integrate(g3, kepler, kepler.y0, h, steps, kernel="compiled", solver="newton")
    assert auto.fallbacks == 0
    assert auto.newton_iterations / steps <= 1 + limits.START_GAP / np.log(1 / kappa ** 2)
    assert np.max(np.abs(auto.final - newton.final)) < 1e-11


def test_arrays_that_do_not_fit_the_compiled_shape_are_refused(monkeypatch):
    """stepcore.fits: a loop specialised to s = 3 given the arrays of a 2-stage method takes no
    step (status 5) and the driver raises; with its own shape the same run goes."""
    from tableau_lab.numeric.integrate import component_masks, start_values
    from tableau_lab.numeric.kernels import LoopState, Pack, drive, run_shape
    monkeypatch.setenv("TABLEAU_LAB_SPECIALISE", "1")
    nm, cp = to_numeric(load(METHODS / "gauss2.json")), compile_problem("pendulum")
    pk = Pack(nm, cp, 0.01, component_masks(cp, 2), mode=limits.SPLIT)
    Y = np.asarray(start_values(nm, cp, cp.y0, 0.01), dtype=float)
    wrong = compiled_loop(cp.problem, "f64", run_shape(pk)._replace(s=3))
    st = LoopState(wrong, pk, Y.copy(), 10, 10)
    assert wrong.run(*st.args(0, 10)) == 5 and st.stats[limits.S_DONE] == 0
    with pytest.raises(RuntimeError, match="do not fit"):
        drive(wrong, pk, Y.copy(), 10, 10, record=lambda n, y: None)
    assert drive(compiled_loop(cp.problem, "f64", run_shape(pk)), pk, Y.copy(), 10, 10,
                 record=lambda n, y: None).completed == 10
