"""The problems registry: generated f, Jacobian, invariants and elementary differentials against
independent facts (finite differences, hand formulas, Lie derivatives, exact solutions)."""
import functools
import math
from math import factorial

import mpmath
import numpy as np
import pytest
import sympy as sp

from tableau_lab.analysis.trees import TAU, density, from_children, order, symmetry, trees_of_order
from tableau_lab.numeric.codegen import compile_problem, reference
from tableau_lab.numeric.problems import PROBLEMS, ProblemError, get_problem, problem_from_dict

HAMILTONIAN = [name for name, p in PROBLEMS.items() if p.kind == "hamiltonian"]


def random_state(problem, seed=1):
    """The initial state, each component moved by up to 10 % (zero components by up to 10 % of
    the largest one), so that no component is 0."""
    y0 = compile_problem(problem).y0
    rng = np.random.default_rng(seed)
    scale = np.where(y0 != 0, np.abs(y0), max(1.0, np.abs(y0).max()))
    if problem.name == "outer_solar_system":     # keep zero components of momentum tiny, as the others
        scale = np.where(y0 != 0, np.abs(y0), 1e-3 * np.abs(y0[y0 != 0]).min())
    return y0 + 0.1 * scale * rng.uniform(-1, 1, y0.size)


def central_differences(fun, y, rel=1e-6):
    """Columns ∂fun/∂y_j by central differences with steps relative to |y_j| (floats or mpf)."""
    cols = []
    for j in range(len(y)):
        h = rel * max(abs(y[j]), 1e-30)
        up, down = list(y), list(y)
        up[j] += h
        down[j] -= h
        cols.append([float(v) for v in np.atleast_1d((np.asarray(fun(up)) - np.asarray(fun(down))) / (2 * h))])
    return np.array(cols).T.squeeze()


@pytest.mark.parametrize("name", HAMILTONIAN)
def test_f_is_the_hamiltonian_vector_field(name):
    problem = PROBLEMS[name]
    c = compile_problem(problem)
    y = random_state(problem)
    cm = compile_problem(problem, "mpmath", dps=40)    # differences of H at 40 digits: no round-off
    with mpmath.workdps(40):
        grad = central_differences(lambda v: cm.invariant("H", v), [mpmath.mpf(float(v)) for v in y], 1e-8)
    d = problem.dimension // 2
    expected = np.concatenate([grad[d:], -grad[:d]])                     # (∂H/∂p, −∂H/∂q)
    f = c.f(y)
    np.testing.assert_allclose(f, expected, rtol=1e-10, atol=1e-10 * np.abs(f).min())
    np.testing.assert_allclose(c.gradient("H", y), np.concatenate([-f[d:], f[:d]]), rtol=1e-12, atol=0)


@pytest.mark.parametrize("name", list(PROBLEMS))
def test_numpy_and_mpmath_agree(name):
    problem = PROBLEMS[name]
    y = random_state(problem, seed=2)
    cn, cm = compile_problem(problem), compile_problem(problem, "mpmath", dps=30)
    with mpmath.workdps(30):
        ym = [mpmath.mpf(float(v)) for v in y]         # the same point, exactly
        fm = np.array([float(v) for v in cm.f(ym)])
        for inv in problem.invariants:
            assert cm.invariant(inv, ym) == pytest.approx(cn.invariant(inv, y), rel=1e-13, abs=1e-300)
    fn = cn.f(y)
    assert np.abs(fn - fm).max() <= 1e-13 * np.abs(fm).max()
    nonzero = np.abs(fm) > 1e-6 * np.abs(fm).max()
    np.testing.assert_allclose(fn[nonzero], fm[nonzero], rtol=1e-13)
    assert mpmath.mp.dps == 15                          # the working precision is left alone


def test_perturbed_kepler_force_and_invariants():
    c = compile_problem(get_problem("kepler"))
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, p = rng.uniform(-2, 2, 2), rng.uniform(-1, 1, 2)
        r = math.hypot(*q)
        f = c.f(np.concatenate([q, p]))
        np.testing.assert_allclose(f[:2], p, rtol=1e-15)
        np.testing.assert_allclose(f[2:], -q / r**3 - 0.0075 * q / r**5, rtol=1e-13)
    for e in (0.6, 0.9, "1/3"):
        problem = get_problem("kepler", e=e)
        c = compile_problem(problem)
        ev = float(sp.Rational(str(e)))
        H = (1 + ev) / (2 * (1 - ev)) - 1 / (1 - ev) - 0.005 / (2 * (1 - ev) ** 3)
        assert c.invariant("H", c.y0) == pytest.approx(H, rel=1e-14)
        assert c.invariant("L", c.y0) == pytest.approx(math.sqrt(1 - ev**2), rel=1e-14)
    assert get_problem("kepler", e=0.9).parameters["e"] == sp.Rational(9, 10)   # read exactly


@pytest.mark.parametrize("name", ["pendulum", "kepler", "henon_heiles", "fpu"])
def test_jacobian_and_gradients_match_finite_differences(name):
    problem = PROBLEMS[name]
    c = compile_problem(problem)
    y = random_state(problem, seed=4)
    J = c.jac(y)
    assert np.abs(J - central_differences(c.f, y)).max() <= 1e-6 * np.abs(J).max()
    for inv in problem.invariants:
        g = central_differences(functools.partial(c.invariant, inv), y)
        assert np.abs(c.gradient(inv, y) - g).max() <= 1e-6 * max(np.abs(g).max(), 1e-12)
    cm = compile_problem(problem, "mpmath", dps=30)
    Jm = cm.jac([mpmath.mpf(float(v)) for v in y])
    assert np.abs(np.array(Jm.tolist(), dtype=float) - J).max() <= 1e-13 * np.abs(J).max()


def tall(n):
    t = TAU
    for _ in range(n - 1):
        t = from_children([t])
    return t


def test_elementary_differentials_of_a_linear_problem():
    """y' = Ly: F(t) = L^|t| y for the tall tree, 0 as soon as a vertex has two children."""
    L = np.array([[0.0, 1.0], [-1.0, 0.0]])
    y = np.array([0.3, -1.7])
    for backend in ("numpy", "mpmath"):
        F = compile_problem(get_problem("harmonic"), backend, dps=25).elementary_differentials(5)(y)
        assert len(F) == 1 + 1 + 2 + 4 + 9
        for t, v in F.items():
            expected = np.linalg.matrix_power(L, order(t)) @ y if t == tall(order(t)) else np.zeros(2)
            np.testing.assert_allclose(np.array(v, dtype=float), expected, atol=1e-15)


def test_elementary_differentials_of_y_squared():
    """f = y²: f' = 2y, f'' = 2, f''' = 0; hand values at y = 3/2 and the Taylor series of the
    exact solution y/(1 − ty) (coefficient y^(n+1) of tⁿ = Σ_{|t|=n} F(t)/(σ(t)γ(t)))."""
    problem = problem_from_dict({"name": "square", "y": ["y"], "f": ["y^2"], "y0": ["3/2"]})
    y = 1.5
    hand = {TAU: y**2, ((),): 2 * y * y**2, ((), ()): 2 * y**4, (((),),): 4 * y**4,
            ((), (), ()): 0.0, ((), ((),)): 4 * y**5, (((), ()),): 4 * y**5, ((((),),),): 8 * y**5}
    for backend in ("numpy", "mpmath"):
        F = compile_problem(problem, backend, dps=30).elementary_differentials(4)([y])
        for t, v in hand.items():
            assert float(F[t][0]) == pytest.approx(v, rel=1e-14, abs=1e-300)
        for n in range(1, 5):
            total = sum(float(F[t][0]) / (symmetry(t) * density(t)) for t in trees_of_order(n))
            assert total == pytest.approx(y ** (n + 1), rel=1e-14)


@pytest.mark.parametrize("name", ["kepler", "henon_heiles"])
def test_elementary_differentials_sum_to_the_taylor_coefficients(name):
    """Σ_{|t|=n} F(t)(y)/(σ(t)γ(t)) = y⁽ⁿ⁾/n!, with y⁽ⁿ⁾ from repeated Lie derivatives
    g ↦ g'·f computed here with sympy's jacobian."""
    problem = PROBLEMS[name]
    state = sp.Matrix(problem.state)
    subs = {s: problem.parameters[k] for k, s in problem.parameter_symbols.items()}
    f = sp.Matrix(problem.f_expr).xreplace(subs)
    values = [sp.Rational(7, 10), sp.Rational(-3, 10), sp.Rational(1, 5), sp.Rational(9, 10)]
    point = dict(zip(problem.state, values, strict=False))
    y = np.array([float(point[s]) for s in problem.state])
    F = compile_problem(problem).elementary_differentials(4)(y)
    g = f
    for n in range(1, 5):
        expected = np.array([float(v) for v in g.xreplace(point)]) / factorial(n)
        total = sum(F[t] / (symmetry(t) * density(t)) for t in trees_of_order(n))
        np.testing.assert_allclose(total, expected, rtol=1e-12)
        g = g.jacobian(state) * f


def test_reference_solutions():
    harmonic = get_problem("harmonic", q0="1/3", p0="-2")
    exact, integrated = (reference(harmonic, 10, 32, method=m) for m in ("exact", "integrate"))
    with mpmath.workdps(32):
        assert abs(exact[0] - (mpmath.cos(10) / 3 - 2 * mpmath.sin(10))) < 1e-30
        assert max(abs(a - b) for a, b in zip(exact, integrated, strict=False)) < 1e-25
    kepler0 = get_problem("kepler_unperturbed")
    exact, integrated = (reference(kepler0, 10, 32, method=m) for m in ("exact", "integrate"))
    with mpmath.workdps(32):
        assert max(abs(a - b) for a, b in zip(exact, integrated, strict=False)) < 1e-20
        period = reference(kepler0, 2 * sp.pi, 32)                    # a = 1: period 2π
        y0 = compile_problem(kepler0, "mpmath", dps=32).y0
        assert max(abs(a - b) for a, b in zip(period, y0, strict=False)) < 1e-28
    assert reference(kepler0, 10, 32) is reference(kepler0, 10, 32)   # cached


@pytest.mark.parametrize("name, invariants", [("pendulum", ["H"]), ("kepler", ["H", "L"])])
def test_reference_conserves_the_invariants(name, invariants):
    problem = get_problem(name)
    y = reference(problem, 10, 32)
    c = compile_problem(problem, "mpmath", dps=40)
    for inv in invariants:
        assert abs(c.invariant(inv, y) - c.invariant(inv, c.y0)) < 1e-25


def test_fpu_is_the_books_chain_of_springs():
    """[HLW06] (I.5.1): H = ½Σy_i² + ω²/4 Σ(x_{2i} − x_{2i−1})² + Σ_{i=0}^{m}(x_{2i+1} − x_{2i})⁴,
    x₀ = x_{2m+1} = 0, in the variables x0_i = (x_{2i} + x_{2i−1})/√2, x1_i = (x_{2i} − x_{2i−1})/√2."""
    problem = get_problem("fpu")
    w = sp.Symbol("omega", real=True)
    x = [0] + [sp.Symbol(f"x{i}", real=True) for i in range(1, 7)] + [0]
    yv = [sp.Symbol(f"y{i}", real=True) for i in range(1, 7)]
    H = (sum(v**2 for v in yv) / 2 + w**2 / 4 * sum((x[2 * i] - x[2 * i - 1])**2 for i in range(1, 4))
         + sum((x[2 * i + 1] - x[2 * i])**4 for i in range(0, 4)))
    s2 = sp.sqrt(2)
    to_new = {}
    for i in range(1, 4):
        x0, x1, y0, y1 = (sp.Symbol(f"{v}_{i}", real=True) for v in ("x0", "x1", "y0", "y1"))
        to_new.update({x[2 * i - 1]: (x0 - x1) / s2, x[2 * i]: (x0 + x1) / s2,
                       yv[2 * i - 2]: (y0 - y1) / s2, yv[2 * i - 1]: (y0 + y1) / s2})
    assert sp.expand(H.xreplace(to_new) - problem.hamiltonian) == 0
    c = compile_problem(problem)
    assert c.invariant("I", c.y0) == 1.0 and c.invariant("I1", c.y0) == 1.0   # (1 + ω²/ω²)/2
    assert problem.parameters["omega"] == 50


def test_outer_solar_system_data():
    problem = get_problem("outer_solar_system")
    c = compile_problem(problem)
    velocity = c.f(c.y0)[:18].reshape(6, 3)                          # dq/dt = p/m = v at t = 0
    np.testing.assert_allclose(velocity[1], [0.00565429, -0.00412490, -0.00190589], rtol=1e-15)
    np.testing.assert_allclose(velocity[5], [0.00276725, -0.00170702, -0.00136504], rtol=1e-15)
    assert problem.parameters["m_pluto"] == sp.Rational(1, 130000000)
    assert problem.parameters["G"] == sp.Rational(295912208286, 10**15)
    assert c.invariant("H", c.y0) < 0
    assert set(problem.invariants) == {"H", "Lx", "Ly", "Lz"}


def test_problem_from_dict_matches_the_builtin_kepler():
    d = {"name": "my kepler", "q": ["q1", "q2"], "p": ["p1", "p2"],
         "H": "(p1^2 + p2^2)/2 - 1/sqrt(q1^2 + q2^2) - 0.005/(2*(q1**2 + q2**2)^(3/2))",
         "invariants": {"L": "q1*p2 - q2*p1"}, "parameters": {"e": "0.6"},
         "q0": ["1 - e", 0], "p0": [0, "sqrt((1 + e)/(1 - e))"], "source": "test"}
    mine, builtin = compile_problem(problem_from_dict(d)), compile_problem(get_problem("kepler"))
    y = np.array([0.7, -0.2, 0.3, 1.1])
    np.testing.assert_allclose(mine.f(y), builtin.f(y), rtol=1e-15)
    np.testing.assert_array_equal(mine.y0, builtin.y0)
    assert mine.invariant("L", y) == builtin.invariant("L", y)


HOSTILE = ["__import__('os')", "a.b", "lambda x: 1", "2**2**2**2**2**2", "x" * 5000, "q1 + z",
           "exec(q1)", "q1; q2", "'q1'", "(" * 80 + "q1" + ")" * 80, "q1^q2", "1e99999", "q1[0]"]


@pytest.mark.parametrize("text", HOSTILE)
@pytest.mark.parametrize("key", ["H", "invariants", "q0"])
def test_hostile_expressions_are_refused_naming_the_entry(text, key):
    d = {"name": "user", "q": ["q1"], "p": ["q2"], "H": "q2^2/2 + q1^2/2", "q0": [1], "p0": [0]}
    if key == "invariants":
        d["invariants"] = {"K": text}
    else:
        d[key] = text if key == "H" else [text]
    with pytest.raises(ProblemError) as err:
        problem_from_dict(d)
    entry = {"H": "'H'", "invariants": "'invariants.K'", "q0": "'q0[1]'"}[key]
    assert f"problem 'user', entry {entry}" in str(err.value)


@pytest.mark.parametrize("call, fragment", [
    (lambda: get_problem("kepler3"), "unknown problem 'kepler3'; known problems: fpu, harmonic, henon_heiles"),
    (lambda: get_problem("kepler", eccentricity=0.5), "no parameter or initial value 'eccentricity'; known: delta, e"),
    (lambda: get_problem("kepler", e=1), "p0[2] = zoo is not a finite real number"),
    (lambda: get_problem("kepler", e=1.5), "is not a finite real number"),
    (lambda: get_problem("kepler", e=float("nan")), "not a finite number"),
    (lambda: get_problem("kepler", e=True), "True is not a number"),
    (lambda: get_problem("kepler", e="e"), "unknown name 'e'"),
    (lambda: get_problem("kepler", q0=[0, 0]), "H is not finite at the initial value"),
    (lambda: get_problem("pendulum", q0=[1, 2]), "1 values needed, got 2"),
    (lambda: compile_problem(get_problem("harmonic")).invariant("L", [1, 0]), "has no invariant 'L'; known: H"),
    (lambda: compile_problem(get_problem("harmonic"), "float32"), "backend must be"),
    (lambda: compile_problem(get_problem("kepler"), parameters={"d": 1}), "no parameter or initial value 'd'"),
    (lambda: compile_problem("kepler", parameters={"e": "1"}), "p0[2] = zoo is not a finite real number"),
    (lambda: problem_from_dict({"name": "x", "y": ["y"], "f": ["y"], "y0": [1], "eval": 1}),
     "entry 'eval': unknown key"),
    (lambda: problem_from_dict({"name": "x", "y": ["__y"], "f": ["1"], "y0": [1]}), "'__y' is not a valid name"),
    (lambda: problem_from_dict({"name": "x", "y": ["sqrt"], "f": ["1"], "y0": [1]}), "'sqrt' is not a valid name"),
    (lambda: problem_from_dict({"name": "x", "y": ["y"], "f": ["y", "y"], "y0": [1]}), "y, f and y0 of one length"),
    (lambda: problem_from_dict({"name": "x", "y": ["y"], "f": ["foo(y)"], "y0": [1]}), "unknown function 'foo'"),
    (lambda: problem_from_dict({"name": "x", "y": ["y"], "f": ["y"], "y0": ["y"]}), "entry 'y0[1]': unknown name 'y'"),
    (lambda: problem_from_dict({"name": "x", "y": ["y"], "f": ["1/y"], "y0": [0]}),
     "f[1] is not finite at the initial value"),
    (lambda: reference(get_problem("kepler"), 1, method="exact"), "no exact solution"),
])
def test_bad_input_is_refused(call, fragment):
    with pytest.raises(ProblemError) as err:
        call()
    assert fragment in str(err.value)


def test_compilation_is_cached_and_parameters_override():
    kepler = get_problem("kepler")
    assert compile_problem(kepler) is compile_problem(get_problem("kepler"))
    c = compile_problem(kepler, parameters={"e": "0.9"})
    np.testing.assert_allclose(c.y0, [0.1, 0, 0, math.sqrt(19)], rtol=1e-15)
    assert compile_problem(kepler).y0[0] == 0.4


def test_generated_code_is_kept_on_the_disk(tmp_path, monkeypatch):
    """A problem's generated code is written to the cache once and read back by a later process
    (here: the in-memory caches emptied), which generates none — no sympy derivative, no lambdify:
    most of a short pure run's preparation (issue 32) — and computes the same numbers bit for bit.
    Parameter values are arguments, not part of the code; a damaged file is generated again; code
    read back freezes as generated code does (the run process of experiments/job.py)."""
    import pickle

    from tableau_lab.numeric import codegen
    from tableau_lab.numeric.frozen import freeze

    def forget():
        monkeypatch.setattr(codegen, "_CODE", {})
        monkeypatch.setattr(codegen, "_COMPILED", {})
    monkeypatch.setenv("TABLEAU_LAB_CACHE", str(tmp_path))
    forget()
    first = compile_problem("kepler")
    y = first.y0 + 0.25
    F1, J1 = first.elementary_differentials(3)(y), first.jac(y)
    files = sorted((tmp_path / "codes").iterdir())
    assert len(files) == 4                                 # f, f′, f″, f‴ (elementary differentials of order 3)
    forget()
    monkeypatch.setattr(codegen.CompiledProblem, "_expressions",
                        lambda self, what: pytest.fail(f"{what!r} generated again"))
    again = compile_problem("kepler", parameters={"e": "0.9"})
    other = compile_problem("kepler")
    assert again is not first and other is not first and again.constants != other.constants
    F2 = other.elementary_differentials(3)(y)
    assert all((F1[t] == F2[t]).all() for t in F1) and (other.jac(y) == J1).all()
    frozen = pickle.loads(pickle.dumps(freeze(other, jac=True, derivatives=3)))
    assert (frozen.jac(y) == J1).all() and (frozen.derivative(2)(y, y, y) == other.derivative(2)(y, y, y)).all()
    for file in files:                                     # damaged: generated again, in place
        file.write_text('{"source": "def f(:", "homes": {}}')
    forget()
    monkeypatch.undo()
    monkeypatch.setenv("TABLEAU_LAB_CACHE", str(tmp_path))
    forget()
    fresh = compile_problem("kepler")
    F3 = fresh.elementary_differentials(3)(y)
    assert all((F1[t] == F3[t]).all() for t in F1) and (fresh.jac(y) == J1).all()
    assert sorted((tmp_path / "codes").iterdir()) == files and all("def f(:" not in f.read_text() for f in files)
