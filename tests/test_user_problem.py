"""The user's own problem from Python (issue 30, item 2): ``integrate`` and ``problem`` against
independent facts — the exact solutions of the harmonic oscillator and of non-Hamiltonian ODEs
with closed-form solutions, a measured convergence slope (least squares on log–log data above
round-off), float64 against mpmath at 30 digits (their difference is round-off alone), and bad
input refused naming the entry.  One test pays numba's compile of a user callable (the
must-show); the others run the Python loop."""
import math
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp

from tableau_lab.errors import InputError
from tableau_lab.exact.tableau_json import load
from tableau_lab.experiments.runs import fit_order, quick_run
from tableau_lab.experiments.user import Solution, integrate, problem, step_grid
from tableau_lab.numeric.problems import ProblemError

METHODS = Path(__file__).parent.parent / "methods"


def oscillator(t, y):
    return np.array([y[1], -y[0]])


def test_must_show_gauss2_returns_to_the_start_after_one_period():
    """The issue's must-show: Gauss 2 (methods/gauss2.json), a Python f for the harmonic
    oscillator, h = 0.01 over (0, 2π): back at (1, 0) within 1e-6 (exact solution: (cos t, −sin t))."""
    sol = integrate(load(METHODS / "gauss2.json"), oscillator, [1, 0], (0, 2 * np.pi), h=0.01)
    assert isinstance(sol, Solution)
    assert np.max(np.abs(sol.final - [1.0, 0.0])) < 1e-6
    # the grid: 629 equal steps of 2π/629 ≤ 0.01, ending on 2π exactly
    assert sol.steps == 629 and sol.h == pytest.approx(2 * np.pi / 629, rel=1e-15) and sol.h <= 0.01
    assert sol.times[0] == 0 and sol.times[-1] == pytest.approx(2 * np.pi, rel=1e-15)
    assert sol.states.shape == (630, 2) and sol.nfev > 2 * 629
    # every record on the exact solution (global error O(h^4): 1e-10 here)
    exact = np.column_stack([np.cos(sol.times), -np.sin(sol.times)])
    assert np.max(np.abs(sol.states - exact)) < 1e-8
    # traced to (y2, -y1), a 629-step run: the Python loop (a compile would not pay), said so
    assert sol.loop == "Python" and sol.why.startswith("f traced to expressions") and sol.start == "identity"


def test_non_hamiltonian_user_ode_converges_at_order_4():
    """y1' = y1 cos t (y1 = exp(sin t)), y2' = -y2^2 (y2 = 1/(1+t)): a time-dependent, dissipative
    Python f; Gauss 2's global error at t = 2 falls with slope 4 (least squares on the log–log
    points above round-off, runs.fit_order)."""
    def f(t, y):
        return np.array([y[0] * np.cos(t), -y[1] ** 2])

    exact = np.array([np.exp(np.sin(2.0)), 1 / 3])
    hs, errs = [], []
    for n in (8, 16, 32, 64):
        sol = integrate(load("gauss2"), f, [1, 1], (0, 2), h=sp.Rational(2, n), notice=False)
        assert sol.steps == n
        hs.append(sol.h)
        errs.append(float(np.max(np.abs(sol.final - exact))))
    slope = fit_order(hs, errs, 2.2e-16)
    assert slope is not None and abs(slope - 4) < 0.2, (hs, errs, slope)


def test_sympy_right_hand_side_with_time():
    """y' = -2 t y, y(0) = 1: y = exp(-t^2); f given as a sympy expression in y and t (the time
    carried as a state component, not shown in the states)."""
    y, t = sp.symbols("y t")
    sol = integrate(load("gauss2"), -2 * t * y, [1], (0, 1), "1/20", variables=[y], kernel="python", notice=False)
    assert sol.names == ("y",) and sol.states.shape == (21, 1)
    assert abs(sol.final[0] - np.exp(-1)) < 1e-6
    assert np.max(np.abs(sol.states[:, 0] - np.exp(-sol.times ** 2))) < 1e-6


def test_float64_and_mpmath_differ_by_round_off_only():
    """The pendulum from problem(H=...) with Gauss 2 at h = 1/10 to t = 5: float64 against 30 digits
    of mpmath (the same method error) agree to round-off; the 30-digit run against the
    high-precision reference solution shows the method's error, O(h^4), not round-off."""
    from tableau_lab.numeric.codegen import reference
    P = problem(H="p^2/2 - cos(q)", q0=["1/2"], p0=[0])
    lo = integrate(load("gauss2"), P, None, (0, 5), "1/10", kernel="python", notice=False)
    hi = integrate(load("gauss2"), P, None, (0, 5), "1/10", precision="mp:30", notice=False)
    assert hi.loop == "Python" and "mp:30" in hi.why
    assert np.max(np.abs(lo.states - hi.states)) < 1e-13
    ref = np.array([float(v) for v in reference(P, 5, 30)])
    err = np.max(np.abs(hi.final - ref))
    assert 1e-9 < err < 1e-5
    assert np.max(np.abs(hi.invariant_errors["H"])) < 1e-6     # Gauss: H bounded, no drift


def test_problem_runs_in_the_existing_machinery(monkeypatch):
    """A problem(...) is a Problem: the command line's quick_run takes it as it is (the Python
    loop here: no cold compile in the suite).  Exact: q = cos 2t, p = -2 sin 2t."""
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "python")
    P = problem(H="p^2/2 + k*q^2/2", parameters={"k": 4}, q0=[1], p0=[0])
    r = quick_run(METHODS / "gauss2.json", P, h="1/100", steps=100)
    assert abs(r["final"]["q"][0] - np.cos(2)) < 1e-8 and abs(r["final"]["p"][0] + 2 * np.sin(2)) < 1e-8
    assert r["max_invariant_error"]["H"] < 1e-13


def test_glm_runs_with_its_starting_method_and_naively_with_a_callable():
    """Example 4 (a GLM): on a problem with symbols its exact starting method is used; with a
    callable it starts naively and says so.  Both follow the oscillator's exact solution."""
    x, v = sp.symbols("x v")
    sym = integrate(load("example4_glm"), [v, -x], [1, 0], (0, 1), "1/50", variables=[x, v], kernel="python",
                    notice=False)
    call = integrate(load("example4_glm"), oscillator, [1, 0], (0, 1), "1/50", trace=False, notice=False)
    assert sym.start == "exact" and call.start == "naive" and "naively" in call.why
    for sol in (sym, call):
        assert np.max(np.abs(sol.final - [np.cos(1), -np.sin(1)])) < 1e-5


@pytest.mark.parametrize("trace", [None, False])
def test_callable_invariants_and_projection(trace):
    """An invariant given as a callable is recorded; projecting onto it holds it to round-off
    (explicit Euler alone drifts: |y|^2 grows by (1 + h^2)^n) — traced with f, and as Python."""
    E = {"E": lambda y: y[0] ** 2 + y[1] ** 2}
    free = integrate(load("explicit_euler"), oscillator, [1, 0], (0, 1), "1/100", invariants=E, trace=trace,
                     notice=False)
    assert free.why.startswith("f traced" if trace is None else "f not traceable (trace=False)")
    assert free.invariant_errors["E"][-1] == pytest.approx((1 + 1e-4) ** 100 - 1, rel=1e-9)
    held = integrate(load("explicit_euler"), oscillator, [1, 0], (0, 1), "1/100", invariants=E, project=["E"],
                     trace=trace, notice=False)
    assert np.max(np.abs(held.invariant_errors["E"])) < 1e-13
    assert held.invariants["E"][0] == 1.0


def test_mp_precision_with_a_callable():
    """A callable in mpmath at 30 digits: the oscillator's period with RK4 at h = 1/1000 to
    t = 1 agrees with the exact solution to O(h^4)·t ≈ 1e-14, beyond float64's reach."""
    with mpmath.workdps(30):
        sol = integrate(load("rk4"), lambda t, y: np.array([y[1], -y[0]], dtype=object), [1, 0], (0, 1),
                        "1/1000", precision="mp:30", notice=False)
        final = sol.run.final
        err = max(abs(final[0] - mpmath.cos(1)), abs(final[1] + mpmath.sin(1)))
    assert 1e-17 < err < 1e-13 and sol.why.startswith("f traced to expressions")


def test_mp_precision_with_a_traced_numpy_callable():
    """np.sin of an mpf array raises TypeError (mpf has no .sin method), so this pendulum could not run at 30
    digits as Python; traced, it is the sympy pendulum: the same 30-digit states."""
    q, p = sp.symbols("q p")
    with mpmath.workdps(30):
        call = integrate(load("rk4"), pendulum, ["1/2", 0], (0, 1), "1/20", precision="mp:30", notice=False)
        expr = integrate(load("rk4"), [p, -sp.sin(q)], ["1/2", 0], (0, 1), "1/20", variables=[q, p],
                         precision="mp:30", notice=False)
        assert all(a == b for u, v in zip(call.run.values, expr.run.values, strict=False)
                   for a, b in zip(u, v, strict=False))
    with pytest.raises(InputError, match="raised TypeError in mp:30"):
        integrate(load("rk4"), pendulum, ["1/2", 0], (0, 1), "1/20", precision="mp:30", trace=False, notice=False)


def test_plot_returns_axes():
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.axes import Axes
    sol = integrate(load("gauss2"), oscillator, [1, 0], (0, 1), "1/10", invariants={"E": lambda y: y @ y},
                    notice=False)
    for what in ("states", "phase", "invariants"):
        assert isinstance(sol.plot(what=what), Axes)
    with pytest.raises(ValueError, match="states"):
        sol.plot(what="orbit")


def test_step_grid():
    assert step_grid((0, 1), "1/3")[2:] == (3, sp.Rational(1, 3))
    assert step_grid((0, 1), 0.1)[2] == 10                 # 1/0.1 is 10 (0.1 read as 1/10)
    assert step_grid((0, 1), 0.3)[2:] == (4, sp.Rational(1, 4))
    for bad, msg in [(((0, 1), 0), "positive"), (((0, 1), "x"), "h"), (((2, 1), 1), "greater"),
                     ((0, 1), "t_span"), (((0, 1), 1e-300), "MAX_STEPS")]:
        with pytest.raises(InputError, match=msg):
            step_grid(*bad)


@pytest.mark.parametrize("kwargs, entry", [
    (dict(H="p^2/2 - cos(x)"), "entry 'H': unknown name 'x'"),
    (dict(H="p^2/2", q=["q", "sin"]), "entry 'q[2]'"),
    (dict(H="p^2/2", q=["a", "b"], p=["c"]), "same length"),
    (dict(H="p^2/2", q0=[1, 2]), "entry 'q0': 1 values needed"),
    (dict(H="p^2/2", p0=["1/0"]), "entry 'p0[1]'"),
    (dict(f=["y", "z"], y=["y"]), "2 entries for 1 variables"),
    (dict(f=["y"], invariants={"I": "y.real"}), "entry 'invariants.I'"),
    (dict(H="p^2/2", invariants={"I": sp.Symbol("w")}), "entry 'invariants.I': uses undeclared names ['w']"),
    (dict(H="exec('1')"), "entry 'H'"),
    (dict(), "give H"),
    (dict(H="p^2/2", y=["y"]), "takes q, p"),
    (dict(H="-1/q", q0=[0]), "not finite at the initial value"),
])
def test_problem_refuses_bad_input_naming_the_entry(kwargs, entry):
    with pytest.raises(ProblemError, match=entry.replace("(", r"\(").replace("[", r"\[").replace("]", r"\]")):
        problem(**kwargs)


def test_integrate_refuses_bad_input():
    with pytest.raises(InputError, match="y0 is needed"):
        integrate(load("rk4"), oscillator, None, (0, 1), 0.1)
    with pytest.raises(InputError, match=r"dd .* not traceable \(f\(t, y\) needs a number"):
        integrate(load("rk4"), lambda t, y: [y[1], -math.sin(y[0])], [1, 0], (0, 1), 0.1, precision="dd")
    with pytest.raises(InputError, match="trace=True, but f is not traceable"):
        integrate(load("rk4"), lambda t, y: [y[1], -math.sin(y[0])], [1, 0], (0, 1), 0.1, trace=True)
    with pytest.raises(InputError, match=r"f\(t0, y0\) raised ZeroDivisionError"):
        integrate(load("rk4"), lambda t, y: 1 / 0, [1, 0], (0, 1), 0.1)
    with pytest.raises(InputError, match=r"returned shape \(3,\)"):
        integrate(load("rk4"), lambda t, y: np.zeros(3), [1, 0], (0, 1), 0.1)
    with pytest.raises(InputError, match="variables"):
        integrate(load("rk4"), [sp.Symbol("a") * sp.Symbol("b")], [1], (0, 1), 0.1)
    with pytest.raises(InputError, match="f must be"):
        integrate(load("rk4"), 3, [1], (0, 1), 0.1)


def test_float64_dd_and_mpmath_on_a_builtin_problem():
    """The pendulum (a built-in problem by name) with Gauss 2, h = 1/100 to t = 10, in the three
    precisions: double-double agrees with 32-digit mpmath to ~1e-30 (both far below the method
    error), float64 to round-off (~1e-15).  The dd loop is the one tests/test_job.py compiles."""
    runs = {p: integrate(load("gauss2"), "pendulum", None, (0, 10), "1/100", precision=p, notice=False)
            for p in ("float64", "dd", "mp:32")}
    assert runs["dd"].loop == "compiled with numba" and runs["mp:32"].loop == "Python"
    with mpmath.workdps(40):
        ref = runs["mp:32"].run.final
        dd = max(abs(mpmath.mpf(a) - b) for a, b in zip(runs["dd"].run.final, ref, strict=False))
        f64 = max(abs(mpmath.mpf(float(a)) - b) for a, b in zip(runs["float64"].run.final, ref, strict=False))
    assert dd < 1e-27 and 1e-18 < f64 < 1e-12


def test_integrate_refuses_bad_run_options():
    with pytest.raises(InputError, match="project: Q not among"):
        integrate(load("rk4"), oscillator, [1, 0], (0, 1), 0.1, project=["Q"], trace=False)
    with pytest.raises(InputError, match="projection onto Q: not invariants"):
        integrate(load("rk4"), oscillator, [1, 0], (0, 1), 0.1, project=["Q"])
    with pytest.raises(InputError, match="record_every"):
        integrate(load("rk4"), oscillator, [1, 0], (0, 1), 0.1, record_every=0)
    with pytest.raises(ProblemError, match="projection onto Q"):
        integrate(load("rk4"), "harmonic", None, (0, 1), 0.1, project=["Q"])
    with pytest.raises(InputError, match="precision"):
        integrate(load("rk4"), oscillator, [1, 0], (0, 1), 0.1, precision="quad")


def test_time_starts_at_t0():
    """y' = cos t from t0 = 1: y(t) = y0 + sin t - sin 1; the callable sees the true t (the time
    carried as a state component from t0), and the records are at t0 + k h."""
    sol = integrate(load("rk4"), lambda t, y: np.array([np.cos(t)]), [2], (1, 3), "1/50", notice=False)
    assert sol.times[0] == 1 and sol.times[-1] == pytest.approx(3, rel=1e-15) and sol.steps == 100
    assert np.max(np.abs(sol.states[:, 0] - (2 + np.sin(sol.times) - np.sin(1)))) < 1e-9


def test_the_exact_stage_has_a_time_budget():
    """A symbolic problem whose code takes long to generate stops at the budget with a
    BudgetError naming the work and how to raise it (a Jacobian of a 60-term product)."""
    from tableau_lab.budget import BudgetError
    ys = sp.symbols("a0:60")
    f = [sp.prod([sp.sin(y + k) for k, y in enumerate(ys)]) + ys[i] for i in range(60)]
    with pytest.raises(BudgetError, match="timeout=SECONDS"):
        integrate(load("gauss2"), f, [0] * 60, (0, 1), "1/10", variables=list(ys), timeout=0.5, notice=False)


def test_sympy_entries_are_read_exactly():
    """Floats inside a sympy expression are read as the decimals they print as (0.1 is 1/10, as
    in text): no float enters the symbolic problem; numpy numbers are numbers."""
    q, p = sp.symbols("q p")
    P = problem(H=p**2 / 2 + 0.1 * q**2, q0=[np.float64(0.5)], p0=[0])
    assert P.hamiltonian == P.p[0] ** 2 / 2 + sp.Rational(1, 10) * P.q[0] ** 2
    assert not P.hamiltonian.atoms(sp.Float) and P.q0 == (sp.Rational(1, 2),)


# -- a callable traced to expressions (issue 30, item 2: "compiled when it can be, run in Python when
#    it cannot, said which") -----------------------------------------------------------------------

def pendulum(t, y):
    return np.array([y[1], -np.sin(y[0])])


def test_traced_callable_is_the_sympy_problem_bit_for_bit():
    """The pendulum as a Python callable (np.sin) and as sympy expressions: the callable traces
    to the same ODE, so Gauss 2 (implicit: the exact Jacobian) and the GLM of Example 4 (its
    exact starting method, which a callable run as Python cannot have) give the same states on
    the same loop, bit for bit; and the states follow an independent high-precision reference
    of the pendulum to the methods' accuracy."""
    from tableau_lab.numeric.codegen import reference
    q, p = sp.symbols("q p")
    for name in ("gauss2", "example4_glm"):
        call = integrate(load(name), pendulum, ["1/2", 0], (0, 2), "1/50", kernel="python", notice=False)
        expr = integrate(load(name), [p, -sp.sin(q)], ["1/2", 0], (0, 2), "1/50", variables=[q, p],
                         kernel="python", notice=False)
        assert call.why.startswith("f traced to expressions") and call.start == expr.start
        assert np.array_equal(call.states, expr.states) and call.nfev == expr.nfev
        assert call.f_calls is None                   # the callable is not called by the steps
    ref = np.array([float(v) for v in reference(problem(H="p^2/2 - cos(q)", q0=["1/2"], p0=[0]), 2, 30)])
    assert np.max(np.abs(call.final - ref)) < 1e-5 and expr.start == "exact"


def test_a_general_problem_compiles_in_the_loop_for_any_shape(monkeypatch):
    """A problem that is not H = T(p) + V(q) (a damped oscillator) on the compiled loop for any
    shape (TABLEAU_LAB_SPECIALISE=0, the suite's setting; the shape-generic loop of issue 32):
    it failed to compile (numba: ``fq_`` not defined in the q-stage iteration it never runs);
    now it runs and equals the Python loop, the same algorithm, to round-off."""
    monkeypatch.setenv("TABLEAU_LAB_SPECIALISE", "0")
    x, v = sp.symbols("x v")
    runs = [integrate(load("gauss2"), [v, -x - v / 10], [1, 0], (0, 1), "1/10", variables=[x, v], kernel=k,
                      notice=False) for k in ("compiled", "python")]
    assert runs[0].loop == "compiled with numba" and runs[1].loop == "Python"
    assert np.max(np.abs(runs[0].states - runs[1].states)) < 1e-14


@pytest.mark.parametrize("f, reason", [
    (lambda t, y: np.array([y[1], -math.sin(y[0])]), "needs a number where it has a symbol"),
    (lambda t, y: np.array([y[1], -np.sin(y[0]) if y[0] > -3 else 0.0]), "branches on a value (y1 > -3"),
    (lambda t, y: np.array([y[1], -np.sin(np.fmod(y[0], 2 * np.pi))]),
     "numpy's fmod, which is outside the problem grammar"),
])
def test_untraceable_callable_runs_in_python_and_says_why(f, reason, capsys):
    """The pendulum written with math.sin of a symbol, a branch on a value, a function outside
    the grammar: the callable runs as Python and the notice says why; the states agree with the
    sympy pendulum's (the generated code, another code path) to round-off."""
    q, p = sp.symbols("q p")
    sol = integrate(load("rk4"), f, ["1/2", 0], (0, 1), "1/100")
    assert sol.loop == "Python" and sol.why.startswith("f not traceable (") and reason in sol.why
    assert sol.f_calls >= sol.nfev > 0 and sol.start == "identity"
    assert reason in capsys.readouterr().err
    ref = integrate(load("rk4"), [p, -sp.sin(q)], ["1/2", 0], (0, 1), "1/100", variables=[q, p], notice=False)
    assert np.max(np.abs(sol.states - ref.states)) < 1e-14


def test_a_trace_that_disagrees_with_the_callable_is_discarded():
    """A callable with a hidden call counter (its trace records the constant of one call) and
    one with randomness: their traces disagree with the callables at the check points and are
    discarded; the callables run as Python."""
    calls = [0]

    def counted(t, y):
        calls[0] += 1
        return np.array([y[1], -y[0] * (1 + 1e-6 * calls[0])])

    rng = np.random.default_rng(1)

    def noisy(t, y):
        return np.array([y[1], -y[0] + 1e-9 * rng.standard_normal()])

    for f in (counted, noisy):
        sol = integrate(load("rk4"), f, [1, 0], (0, "1/10"), "1/100", notice=False)
        assert sol.loop == "Python" and "disagree" in sol.why and sol.f_calls >= sol.nfev
    with pytest.raises(InputError, match="trace=True, but f is not traceable: the traced expressions disagree"):
        integrate(load("rk4"), counted, [1, 0], (0, 1), "1/100", trace=True, notice=False)


def test_the_loop_follows_the_predicted_cost(monkeypatch):
    """kernel="auto": the Python loop when the predicted Python time (limits.python_step_seconds ×
    steps) is less than what the compiled loop must pay first, the compiled loop when more
    (limits.choose_loop) — no timings asserted: the rule's inputs and its choice.  The long run
    uses the built-in pendulum, whose compiled loop the suite compiles anyway (test_kernels)."""
    from tableau_lab.numeric import limits
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "auto")             # the suite's default is the Python loop
    step = limits.python_step_seconds(2, 1, 2, explicit=False)
    cold = limits.COMPILE_COLD_SECONDS
    assert not limits.choose_loop(100, step, "cold")[0] and not limits.choose_loop(100, step, "cached")[0]
    assert limits.choose_loop(math.ceil(1.01 * cold / step), step, "cold")[0]
    assert limits.choose_loop(1, step, "loaded")[0]
    short = integrate(load("gauss2"), pendulum, [1, 0], (0, 1), "1/100", notice=False)
    assert short.loop == "Python" and "the Python loop: 100 steps predicted" in short.why
    n = math.ceil(1.01 * cold / step)                             # more than even a cold compile costs
    long = integrate(load("gauss2"), "pendulum", None, (0, n / 100), "1/100", record_every=n, notice=False)
    assert long.steps == n and long.loop == "compiled with numba" and f"the compiled loop: {n} steps" in long.why
    again = integrate(load("gauss2"), "pendulum", None, (0, 1), "1/100", notice=False)     # its loop is loaded now
    assert again.loop == "compiled with numba" and "already compiled in this process" in again.why


def test_the_rule_looks_at_the_disk_cache_only_when_it_matters(monkeypatch, tmp_path):
    """RK4, 14 000 steps: 0.62 s predicted in Python, between a load from the cache and a compile,
    so the rule looks at numba's cache — an empty folder here: a compile would not pay, the
    Python loop runs, and looking wrote nothing.  100 steps need no look (less than any load)."""
    from tableau_lab.numeric import kernels
    monkeypatch.setenv("TABLEAU_LAB_KERNEL", "auto")
    monkeypatch.setenv("TABLEAU_LAB_CACHE", str(tmp_path))
    looked = []
    real = kernels.compile_state
    monkeypatch.setattr(kernels, "compile_state", lambda *a, **k: looked.append(k.get("disk", True)) or real(*a, **k))
    sol = integrate(load("rk4"), pendulum, ["1/2", 0], (0, 140), "1/100", notice=False)
    assert sol.loop == "Python" and "14000 steps predicted at 0.62 s in Python, less than the compile" in sol.why
    assert looked == [False, True] and not list(tmp_path.rglob("*.py"))
    looked.clear()
    sol = integrate(load("rk4"), pendulum, ["1/2", 0], (0, 1), "1/100", notice=False)
    assert sol.loop == "Python" and "less than loading the cached compiled loop" in sol.why and looked == [False]
    with pytest.raises(ValueError, match="kernel must be"):
        integrate(load("gauss2"), "pendulum", None, (0, 1), "1/100", kernel="fast", notice=False)


def test_callable_invariants_are_traced_with_f_or_the_whole_runs_as_python():
    """An invariant I(y) traced with f is the problem's invariant (its exact gradient projects:
    explicit Euler held on the circle to round-off); one that is not traceable (math.hypot)
    sends f and it to the Python loop, saying which invariant."""
    E = {"E": lambda y: y[0] ** 2 + y[1] ** 2}
    sol = integrate(load("explicit_euler"), oscillator, [1, 0], (0, 1), "1/100", invariants=E, project=["E"],
                    notice=False)
    assert sol.why.startswith("f traced") and sol.f_calls is None
    assert np.max(np.abs(sol.invariant_errors["E"])) < 1e-13
    bad = {"E": lambda y: math.hypot(y[0], y[1]) ** 2}
    sol = integrate(load("explicit_euler"), oscillator, [1, 0], (0, 1), "1/100", invariants=bad, notice=False)
    assert sol.why.startswith("f not traceable (invariant E: I(y) needs a number") and sol.f_calls >= sol.nfev
    assert sol.invariant_errors["E"][-1] == pytest.approx((1 + 1e-4) ** 100 - 1, rel=1e-9)


def test_a_numba_function_is_traced_through_its_python_source():
    """numba's functions keep their Python source as ``py_func``; it is traced (a Dispatcher
    itself cannot take symbols) and checked against the function as called.  A stand-in with
    the same attribute, so that no numba compile is paid."""
    class Dispatcher:
        py_func = staticmethod(pendulum)

        def __call__(self, t, y):
            return pendulum(t, np.asarray(y, dtype=float))
    q, p = sp.symbols("q p")
    sol = integrate(load("gauss2"), Dispatcher(), ["1/2", 0], (0, 1), "1/20", kernel="python", notice=False)
    ref = integrate(load("gauss2"), [p, -sp.sin(q)], ["1/2", 0], (0, 1), "1/20", variables=[q, p], kernel="python",
                    notice=False)
    assert sol.why.startswith("f traced") and np.array_equal(sol.states, ref.states)
