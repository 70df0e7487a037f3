r"""The problems registry: test problems written symbolically, compiled on demand.

A problem is a Hamiltonian H(q, p) or a general right-hand side f(y), with exact parameters
and initial values; f, its Jacobian, its invariants, their gradients and its elementary
differentials are generated from the symbols for numpy (float64) and for mpmath (any
precision) by ``compile_problem`` (``codegen.py``).  The state is y = (q₁..q_d, p₁..p_d)
and f(y) = (∂H/∂p, −∂H/∂q).

>>> kepler = get_problem("kepler", e="1/2")
>>> kepler.state, kepler.initial_state()
((q1, q2, p1, p2), (1/2, 0, 0, sqrt(3)))
>>> kepler.f_expr[2], kepler.parameters["delta"]         # force -q/r^3 - 0.0075 q/r^5
(-3*delta*q1/(2*(q1**2 + q2**2)**(5/2)) - q1/(q1**2 + q2**2)**(3/2), 1/200)
>>> from tableau_lab.numeric.codegen import compile_problem
>>> c = compile_problem(kepler)
>>> c.f([1.0, 0.0, 0.0, 1.0])[2], c.invariant("L", c.y0) == 3 ** 0.5 / 2
(np.float64(-1.0075), True)
>>> get_problem("kepler", e=2)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
tableau_lab.numeric.problem_functions.ProblemError: problem 'kepler': the initial value p0[2] = sqrt(3)*I is not a ...
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from fractions import Fraction
from functools import cached_property
from typing import Callable

import mpmath
import sympy as sp

from ..exact.grammar import NUMBER_NAMES
from .expressions import FUNCTIONS, NAME, ExpressionError, exact_number, parse_expression
from .problem_functions import ProblemError

__all__ = ["ProblemError", "Problem", "PROBLEMS", "get_problem", "problem_from_dict", "exact_value", "valid_name",
           "DEFINE_KEYS", "LABEL_LENGTH", "MAX_ENTRIES"]


def _symbols(names: str) -> tuple:
    return tuple(sp.Symbol(n, real=True) for n in names.split())


def exact_value(value, where: str, names=None) -> sp.Expr:
    """``expressions.exact_number`` with errors as ProblemError naming ``where``."""
    try:
        return exact_number(value, names)
    except ExpressionError as exc:
        raise ProblemError(f"{where}: {exc}") from None


def _exact(v, what):
    if isinstance(v, sp.Basic):
        return v
    if isinstance(v, (int, Fraction)) and not isinstance(v, bool):
        return sp.Rational(v)
    raise ProblemError(f"{what}: {v!r} is not an exact value (use a sympy number or an integer)")


@dataclass(frozen=True, eq=False)
class Problem:
    """A symbolic problem; see the module docstring. Equal problems have equal ``key``."""
    name: str
    kind: str                                  # "hamiltonian" or "general"
    q: tuple = ()
    p: tuple = ()
    y: tuple = ()
    hamiltonian: sp.Expr | None = None
    rhs: tuple = ()
    invariants: dict = field(default_factory=dict)
    parameters: dict = field(default_factory=dict)
    q0: tuple = ()
    p0: tuple = ()
    y0: tuple = ()
    source: str = ""
    reference: Callable | None = None          # (problem, t, dps) -> state, or None if it does not apply
    notes: str = ""
    angles: tuple = ()                         # names of q variables that are angles (H 2π-periodic in them)

    def __post_init__(self):
        def fail(msg):
            return ProblemError(f"problem {self.name!r}: {msg}")
        if self.kind == "hamiltonian":
            ok = len(self.q) == len(self.p) == len(self.q0) == len(self.p0) > 0 and self.hamiltonian is not None
            object.__setattr__(self, "invariants", {"H": self.hamiltonian, **self.invariants})
        else:
            ok = self.kind == "general" and len(self.y) == len(self.rhs) == len(self.y0) > 0
        other = (self.y, self.rhs, self.y0) if self.kind == "hamiltonian" else (self.q, self.p, self.q0, self.p0)
        if not ok or any(other):
            raise fail("kind 'hamiltonian' needs H and q, p, q0, p0 of one length; kind 'general' needs y, f "
                       "and y0 of one length")
        for name in ("q", "p", "y", "rhs", "q0", "p0", "y0"):
            object.__setattr__(self, name, tuple(_exact(v, f"{self.name}.{name}") for v in getattr(self, name)))
        object.__setattr__(self, "parameters", {k: _exact(v, f"{self.name}.{k}") for k, v in self.parameters.items()})
        names = [str(s) for s in self.state] + list(self.parameters)
        if len(set(names)) != len(names) or not all(isinstance(s, sp.Symbol) for s in self.state):
            raise fail(f"state variables and parameters must be distinct symbols: {names}")
        params = set(self.parameter_symbols.values())
        for what, e in [*self.invariants.items(), *(("f", e) for e in self.rhs),
                        *(("initial value", e) for e in self.initial_values)]:
            extra = e.free_symbols - params - (set(self.state) if what != "initial value" else set())
            if extra:
                raise fail(f"{what} uses undeclared names {sorted(map(str, extra))}")
        for k, v in self.parameters.items():
            if v.free_symbols or not (v.is_real and v.is_finite):
                raise fail(f"parameter {k} = {v} is not a finite real number")
        if not set(self.angles) <= {str(s) for s in self.q}:
            raise fail(f"angles {list(self.angles)}: each must be one of the q variables "
                       f"{', '.join(map(str, self.q)) or '(none: not a Hamiltonian problem)'}")

    @property
    def state(self) -> tuple:
        return self.q + self.p if self.kind == "hamiltonian" else self.y

    @property
    def initial_values(self) -> tuple:
        return self.q0 + self.p0 if self.kind == "hamiltonian" else self.y0

    @property
    def dimension(self) -> int:
        return len(self.state)

    @property
    def parameter_symbols(self) -> dict:
        return {k: sp.Symbol(k, real=True) for k in self.parameters}

    @cached_property
    def f_expr(self) -> tuple:
        if self.kind == "general":
            return self.rhs
        H = self.hamiltonian
        return tuple(sp.diff(H, s) for s in self.p) + tuple(-sp.diff(H, s) for s in self.q)

    @cached_property
    def operations(self) -> int:
        """Arithmetic operations of one evaluation of f, counted on its expression trees (an
        n-ary sum or product is n − 1, a function call one; no common subexpressions taken
        out): the stage-iteration cost model's price of f (:func:`limits.iteration_costs`).

        >>> get_problem("pendulum").operations           # (p, -sin(q))
        2
        """
        return sum(max(len(e.args) - 1, 1) for expr in self.f_expr for e in sp.preorder_traversal(expr) if e.args)

    @cached_property
    def separable(self) -> bool:
        """H = T(p) + V(q): the q-rate reads p only and the p-rate q only (the stage equations
        can then be iterated on the q stages alone, :mod:`stepcore`)."""
        if self.kind != "hamiltonian":
            return False
        k = len(self.q)
        return (all(not (e.free_symbols & set(self.q)) for e in self.f_expr[:k])
                and all(not (e.free_symbols & set(self.p)) for e in self.f_expr[k:]))

    @cached_property
    def key(self) -> tuple:
        """What defines the problem (its code, parameter values and initial values)."""
        return (self.name, self.kind, self.state, self.rhs, tuple(self.invariants.items()),
                tuple(self.parameters.items()), self.initial_values)

    def __eq__(self, other):
        return isinstance(other, Problem) and self.key == other.key

    def __hash__(self):
        return hash(self.key)

    def check_projection(self, names) -> tuple:
        """The invariants a run projects onto, checked: each one of the problem's, and none
        constant (its gradient is zero: there is no level set to project onto, and Newton on
        the multiplier would "fail" with residual 0).

        >>> get_problem("kepler").check_projection(["H", "L"])
        ('H', 'L')
        >>> problem_from_dict({"name": "c", "y": ["x"], "f": ["-x"], "y0": [1], "invariants": {"C": "2"}}
        ...                   ).check_projection(["C"])  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        tableau_lab.numeric.problem_functions.ProblemError: problem 'c': projection onto C: C = 2 is constant ...
        """
        names = tuple(names)
        unknown = [k for k in names if k not in self.invariants]
        if unknown:
            raise ProblemError(f"problem {self.name!r}: projection onto {', '.join(map(str, unknown))}: not invariants "
                               f"of it (its invariants: {', '.join(self.invariants) or 'none'})")
        for k in names:
            if not (self.invariants[k].free_symbols & set(self.state)):
                raise ProblemError(f"problem {self.name!r}: projection onto {k}: {k} = {self.invariants[k]} "
                                   "is constant "
                                   f"(it does not depend on {', '.join(map(str, self.state))}): every state lies on "
                                   "its level set, there is nothing to project onto; leave it out of the projection")
        return names

    def initial_state(self, parameters=None) -> tuple:
        """The exact initial state, parameters substituted."""
        values = {**self.parameters, **(parameters or {})}
        subs = {s: values[k] for k, s in self.parameter_symbols.items()}
        return tuple(sp.sympify(v).xreplace(subs) for v in self.initial_values)

    def with_values(self, **overrides) -> "Problem":
        """A copy with parameters (``e=0.9``, ``e="9/10"``) or initial values (``q0=[0]``,
        ``p0=["1"]``, ``y0=...``) replaced; values are read exactly (0.9 is 9/10)."""
        known = set(self.parameters) | ({"q0", "p0"} if self.kind == "hamiltonian" else {"y0"})
        changes, params = {}, dict(self.parameters)
        for key, value in overrides.items():
            where = f"problem {self.name!r}, {key}"
            if key not in known:
                raise ProblemError(f"problem {self.name!r} has no parameter or initial value {key!r}; "
                                   f"known: {', '.join(sorted(known))}")
            if key in ("q0", "p0", "y0"):
                vals = list(value) if isinstance(value, (list, tuple)) else [value]
                if len(vals) != len(getattr(self, key)):
                    raise ProblemError(f"{where}: {len(getattr(self, key))} values needed, got {len(vals)}")
                changes[key] = tuple(exact_value(v, where, self.parameter_symbols) for v in vals)
            else:
                params[key] = exact_value(value, where)
        new = replace(self, parameters=params, **changes)
        new.check_initial_state()
        return new

    def check_initial_state(self):
        """Raise ProblemError if the initial state or an invariant there is not finite and real."""
        y0 = self.initial_state()
        labels = [f"{n}[{i + 1}]" for n in (("q0", "p0") if self.kind == "hamiltonian" else ("y0",))
                  for i in range(len(getattr(self, n)))]
        for label, v in zip(labels, y0, strict=False):
            if v.has(sp.zoo, sp.nan, sp.oo, -sp.oo) or not v.is_real:
                raise ProblemError(f"problem {self.name!r}: the initial value {label} = {v} "
                                   "is not a finite real number")
        subs = {**dict(zip(self.state, y0, strict=False)),
                **{s: self.parameters[k] for k, s in self.parameter_symbols.items()}}
        for name, e in [*self.invariants.items(), *((f"f[{i + 1}]", e) for i, e in enumerate(self.f_expr))]:
            value = e.evalf(20, subs=subs)
            if not (value.is_real and value.is_finite):
                raise ProblemError(f"problem {self.name!r}: {name} is not finite at the initial value")


# -- built-in problems ------------------------------------------------------------------------

HLW06 = "[HLW06] E. Hairer, C. Lubich, G. Wanner, Geometric Numerical Integration, 2nd ed., Springer 2006"
_R = sp.Rational


def _harmonic_exact(problem, t, dps):
    q0, p0 = problem.initial_state()
    return q0 * sp.cos(t) + p0 * sp.sin(t), p0 * sp.cos(t) - q0 * sp.sin(t)


def _kepler_exact(problem, t, dps):
    """Unperturbed Kepler from pericentre (a = 1, mean motion 1): E − e sin E = t,
    q = (cos E − e, √(1−e²) sin E), p = (−sin E, √(1−e²) cos E)/(1 − e cos E)."""
    if (problem.q0, problem.p0) != (PROBLEMS["kepler_unperturbed"].q0, PROBLEMS["kepler_unperturbed"].p0):
        return None
    with mpmath.workdps(dps + 20):
        e, t = (mpmath.mpf(x.p) / x.q if x.is_Rational else mpmath.mpf(str(sp.N(x, dps + 30)))
                for x in (problem.parameters["e"], t))
        k = mpmath.floor(t / (2 * mpmath.pi))
        m = t - 2 * k * mpmath.pi          # |E − m| = |e sin E| < 1
        E = mpmath.findroot(lambda E: E - e * mpmath.sin(E) - m, (m - 1, m + 1), solver="illinois")
        c, s, b = mpmath.cos(E), mpmath.sin(E), mpmath.sqrt(1 - e * e)
        return c - e, b * s, -s / (1 - e * c), b * c / (1 - e * c)


def _kepler(name, delta):
    q1, q2, p1, p2, e, d = _symbols("q1 q2 p1 p2 e delta")
    r = sp.sqrt(q1**2 + q2**2)
    return Problem(
        name, "hamiltonian", q=(q1, q2), p=(p1, p2),
        hamiltonian=(p1**2 + p2**2) / 2 - 1 / r - (d / (2 * r**3) if delta else 0),
        invariants={"L": q1 * p2 - q2 * p1}, parameters={"e": _R(3, 5), **({"delta": delta} if delta else {})},
        q0=(1 - e, 0), p0=(0, sp.sqrt((1 + e) / (1 - e))), reference=None if delta else _kepler_exact,
        source=f"{HLW06}, I.2 and IV.4 (perturbed Kepler, delta = 0.005: force -q/r^3 - 0.0075 q/r^5)"
        if delta else f"{HLW06}, I.2.2 (Kepler problem, exact solution by Kepler's equation)")


def _fpu(m=3):
    x0, x1, y0, y1 = (_symbols(" ".join(f"{v}_{i}" for i in range(1, m + 1))) for v in ("x0", "x1", "y0", "y1"))
    w, = _symbols("omega")
    osc = {f"I{j + 1}": (y1[j]**2 + w**2 * x1[j]**2) / 2 for j in range(m)}
    soft = ((x0[0] - x1[0])**4 + sum((x0[i + 1] - x1[i + 1] - x0[i] - x1[i])**4 for i in range(m - 1))
            + (x0[-1] + x1[-1])**4)
    H = sum(v**2 for v in y0 + y1) / 2 + w**2 / 2 * sum(v**2 for v in x1) + soft / 4
    zeros = [0] * (m - 1)
    return Problem(
        "fpu", "hamiltonian", q=x0 + x1, p=y0 + y1, hamiltonian=H,
        invariants={**osc, "I": sum(osc.values())}, parameters={"omega": 50},
        q0=(1, *zeros, 1 / w, *zeros), p0=(1, *zeros, 1, *zeros),
        source=f"{HLW06}, I.5.1 (Fermi-Pasta-Ulam, m = 3, omega = 50, the book's initial values)",
        notes="I = I1 + I2 + I3 (oscillatory energy) is an adiabatic invariant: conserved up to O(1/omega), "
              "not exactly.")


_BODIES = ["sun", "jupiter", "saturn", "uranus", "neptune", "pluto"]
_SOLAR = {  # [HLW06] Table I.2.1: mass, initial position, initial velocity (AU, days, solar masses)
    "sun": ("1.00000597682", "0 0 0", "0 0 0"),
    "jupiter": ("0.000954786104043", "-3.5023653 -3.8169847 -1.5507963", "0.00565429 -0.00412490 -0.00190589"),
    "saturn": ("0.000285583733151", "9.0755314 -3.0458353 -1.6483708", "0.00168318 0.00483525 0.00192462"),
    "uranus": ("0.0000437273164546", "8.3101420 -16.2901086 -7.2521278", "0.00354178 0.00137102 0.00055029"),
    "neptune": ("0.0000517759138449", "11.4707666 -25.7294829 -10.8169456", "0.00288930 0.00114527 0.00039677"),
    "pluto": ("1/1.3e8", "-15.5387357 -25.2225594 -3.1902382", "0.00276725 -0.00170702 -0.00136504"),
}


def _outer_solar_system():
    q = [_symbols(f"x_{b} y_{b} z_{b}") for b in _BODIES]
    p = [_symbols(f"px_{b} py_{b} pz_{b}") for b in _BODIES]
    m = _symbols(" ".join(f"m_{b}" for b in _BODIES))
    G, = _symbols("G")
    kinetic = sum(sum(c**2 for c in p[i]) / (2 * m[i]) for i in range(6))
    potential = sum(m[i] * m[j] / sp.sqrt(sum((a - b)**2 for a, b in zip(q[i], q[j], strict=False)))
                    for i in range(6) for j in range(i + 1, 6))
    L = [sum(q[i][a] * p[i][b] - q[i][b] * p[i][a] for i in range(6)) for a, b in ((1, 2), (2, 0), (0, 1))]

    def numbers(text):                           # the space-separated numbers of a table row
        return [parse_expression(v) for v in text.split()]

    return Problem(
        "outer_solar_system", "hamiltonian", q=sum(q, ()), p=sum(p, ()), hamiltonian=kinetic - G * potential,
        invariants=dict(zip(("Lx", "Ly", "Lz"), L, strict=False)),
        parameters={"G": parse_expression("2.95912208286e-4"),
                    **{f"m_{b}": parse_expression(_SOLAR[b][0]) for b in _BODIES}},
        q0=tuple(v for b in _BODIES for v in numbers(_SOLAR[b][1])),
        p0=tuple(mi * v for b, mi in zip(_BODIES, m, strict=False) for v in numbers(_SOLAR[b][2])),
        source=f"{HLW06}, I.2.4 and Table I.2.1 (outer solar system; p = m v)")


def _builtin():
    q, p = _symbols("q p")
    (q1, q2), (p1, p2) = _symbols("q1 q2"), _symbols("p1 p2")
    yield Problem("harmonic", "hamiltonian", q=(q,), p=(p,), hamiltonian=(p**2 + q**2) / 2, q0=(1,), p0=(0,),
                  reference=_harmonic_exact, source="harmonic oscillator; exact solution q = cos t, p = -sin t")
    yield Problem("pendulum", "hamiltonian", q=(q,), p=(p,), hamiltonian=p**2 / 2 - sp.cos(q),
                  q0=(_R(23, 10),), p0=(0,), angles=("q",),
                  source=f"{HLW06}, I.1 (mathematical pendulum); the seed's q0 = 2.3, p0 = 0",
                  notes="the seed's second case (p0, q0) = (1, 0): get_problem('pendulum', q0=0, p0=1)")
    yield _kepler("kepler", _R(1, 200))
    yield _kepler("kepler_unperturbed", 0)
    yield Problem("henon_heiles", "hamiltonian", q=(q1, q2), p=(p1, p2),
                  hamiltonian=(p1**2 + p2**2 + q1**2 + q2**2) / 2 + q1**2 * q2 - q2**3 / 3,
                  q0=(0, 0), p0=(_R(1, 2), _R(1, 4)),
                  source=f"{HLW06}, I.3 (Hénon-Heiles). Initial value ours: H = 5/32, between the book's "
                         "levels 1/8 and 1/6, in the chaotic sea (finite-time Lyapunov exponent about 0.13)")
    yield _fpu()
    yield _outer_solar_system()


PROBLEMS: dict[str, Problem] = {p.name: p for p in _builtin()}


def get_problem(name, **overrides) -> Problem:
    """A built-in problem by name (or a Problem), with parameters or initial values replaced.

    >>> get_problem("pendulum", q0=0, p0=1).initial_state()       # the seed's second case
    (0, 1)
    >>> get_problem("kepler", ee=1)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    tableau_lab.numeric.problem_functions.ProblemError: problem 'kepler' has no parameter or initial value 'ee'; ...
    """
    if isinstance(name, Problem):
        problem = name
    elif name in PROBLEMS:
        problem = PROBLEMS[name]
    else:
        raise ProblemError(f"unknown problem {name!r}; known problems: {', '.join(sorted(PROBLEMS))}")
    return problem.with_values(**overrides) if overrides else problem


LABEL_LENGTH = 100          # characters of a user problem's name
MAX_ENTRIES = 200           # variables, parameters, invariants, initial values of a user problem (each)
_H, _G = ("hamiltonian",), ("general",)
#: the keys of a user problem (a scene's ``"define"``): key -> (the kinds that take it, required,
#: what it takes, what it is); problem_from_dict's allowed and required keys come from here, and
#: docs/scenes.md's table is generated from it (experiments/scene.py, scene_doc)
DEFINE_KEYS = {
    "name": (_H + _G, True, f"a string of 1 to {LABEL_LENGTH} characters", "the problem's name"),
    "q": (_H, True, "a list of names", "the coordinates"),
    "p": (_H, True, "a list of names, as many as q", "the momenta"),
    "H": (_H, True, "an expression in q, p and the parameters", "the Hamiltonian; f = (∂H/∂p, −∂H/∂q)"),
    "q0": (_H, True, "a list of exact numbers (expressions in the parameters)", "the initial coordinates"),
    "p0": (_H, True, "a list of exact numbers (expressions in the parameters)", "the initial momenta"),
    "angles": (_H, False, "a list of names among q", "the coordinates that are angles (wrapped in phase plots)"),
    "y": (_G, True, "a list of names", "the variables"),
    "f": (_G, True, "a list of expressions in y and the parameters, one per variable", "the right-hand side"),
    "y0": (_G, True, "a list of exact numbers (expressions in the parameters)", "the initial values"),
    "invariants": (_H + _G, False, "an object name → expression", "quantities recorded (and projected on); H is "
                   "one already"),
    "parameters": (_H + _G, False, "an object name → exact number", "named constants of the expressions"),
    "source": (_H + _G, False, "a string", "where the problem comes from"),
    "notes": (_H + _G, False, "a string", "free text"),
}
_KEYS = {kind: tuple(k for k, (kinds, required, *_) in DEFINE_KEYS.items()
                     if required and kind in kinds and k != "name")
         for kind in ("hamiltonian", "general")}
# names a user problem cannot declare (any case): they read as numbers or constants
NOT_NAMES = NUMBER_NAMES | {"pi"}


def valid_name(n) -> bool:
    """A name a user problem can declare (a state variable, parameter or invariant): a letter,
    then letters, digits, _; not a function of the grammar, nor a number or constant name.

    >>> valid_name("q1"), valid_name("sin"), valid_name("Pi"), valid_name("_x")
    (True, False, False, False)
    """
    return isinstance(n, str) and bool(NAME.match(n)) and n not in FUNCTIONS and n.lower() not in NOT_NAMES


def _label_and_kind(d) -> tuple:
    """(name, "hamiltonian" or "general") of a problem entry whose keys are those of its kind
    (:data:`DEFINE_KEYS`), else the error naming the key."""
    label = d.get("name") if isinstance(d, dict) else None
    if not isinstance(label, str) or not 0 < len(label) <= LABEL_LENGTH:
        raise ProblemError(f"a problem is an object with a 'name' (a string of at most {LABEL_LENGTH} characters)")
    kind = "hamiltonian" if "H" in d else "general"
    allowed = tuple(k for k, (kinds, *_) in DEFINE_KEYS.items() if kind in kinds)
    for key in [k for k in d if k not in allowed] + [k for k in _KEYS[kind] if k not in d]:
        raise ProblemError(f"problem {label!r}, entry {key!r}: {'missing' if key in allowed else 'unknown key'}; "
                           f"a {kind} problem has the keys {', '.join(allowed)}")
    return label, kind


def problem_from_dict(d: dict) -> Problem:
    """A user-defined problem from a scene file's entry; every text is read by the safe parser
    of ``expressions.py`` (numbers, declared names, + − * / ^, whitelisted functions).

    >>> problem_from_dict({"name": "osc", "q": ["x"], "p": ["v"], "H": "v^2/2 + k*x^2/2",
    ...                    "parameters": {"k": "4"}, "q0": ["1"], "p0": [0]}).f_expr
    (v, -k*x)
    >>> problem_from_dict({"name": "bad", "y": ["y"], "f": ["y.real"], "y0": [1]})  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    tableau_lab.numeric.problem_functions.ProblemError: problem 'bad', entry 'f[1]': unexpected character '.' ...
    """
    label, kind = _label_and_kind(d)

    def fail(key, msg):
        return ProblemError(f"problem {label!r}, entry {key!r}: {msg}")

    def read(key, value, names):
        return exact_value(value, f"problem {label!r}, entry {key!r}", names)

    def items(key, mapping=False):
        v = d.get(key, {})
        if not isinstance(v, dict if mapping else list) or len(v) > MAX_ENTRIES or not (v or mapping):
            raise fail(key, f"{'an object' if mapping else 'a non-empty list'} of at most {MAX_ENTRIES} entries "
                            "is needed")
        return v

    def declare(key, names):
        for i, n in enumerate(names):
            if not valid_name(n):
                raise fail(key if isinstance(names, dict) else f"{key}[{i + 1}]", f"{n!r} is not a valid name")
        return _symbols(" ".join(names))

    psyms = dict(zip(items("parameters", True), declare("parameters", items("parameters", True)), strict=False))
    for k in items("invariants", True):
        if not NAME.match(k) or k.lower() in NOT_NAMES:
            raise fail(f"invariants.{k}", f"{k!r} is not a valid invariant name (a letter, then letters, digits, _)")
    state = declare("q", items("q")) + declare("p", items("p")) if kind == "hamiltonian" else declare("y", items("y"))
    names = {str(s): s for s in state} | psyms
    if len(names) != len(state) + len(psyms) or (kind == "hamiltonian" and len(d["q"]) != len(d["p"])):
        raise ProblemError(f"problem {label!r}: names must be distinct, and q and p of the same length")
    if not isinstance(d.get("source", ""), str) or not isinstance(d.get("notes", ""), str):
        raise ProblemError(f"problem {label!r}: 'source' and 'notes' must be strings")
    initial = ("q0", "p0") if kind == "hamiltonian" else ("y0",)
    body = {k: tuple(read(f"{k}[{i + 1}]", v, psyms) for i, v in enumerate(items(k))) for k in initial}
    if kind == "hamiltonian":
        body.update(q=state[:len(d["q"])], p=state[len(d["q"]):], hamiltonian=read("H", d["H"], names))
    else:
        body.update(y=state, rhs=tuple(read(f"f[{i + 1}]", v, names) for i, v in enumerate(items("f"))))
    angles = d.get("angles", [])
    if not isinstance(angles, list) or not all(isinstance(a, str) for a in angles):
        raise fail("angles", "a list of q names (the variables that are angles, wrapped in phase plots) is needed")
    problem = Problem(label, kind, **body, source=d.get("source", "user-defined"), notes=d.get("notes", ""),
                      angles=tuple(angles),
                      invariants={k: read(f"invariants.{k}", v, names) for k, v in items("invariants", True).items()},
                      parameters={k: read(f"parameters.{k}", v, {}) for k, v in items("parameters", True).items()})
    problem.check_initial_state()
    return problem
