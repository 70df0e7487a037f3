r"""The user's own problem from Python: ``integrate(method, f, y0, t_span, h)`` and ``problem(H=...)``.

``f`` is one of

* a Python callable ``f(t, y) -> array`` (the convention of ``scipy.integrate.solve_ivp``).  It is
  first *traced* (:mod:`~tableau_lab.experiments.tracing`): called once with symbols, and if it
  is made of arithmetic and the problem grammar's functions (``np.sin``, ``np.exp``, ``np.sqrt``
  …) the expressions it returns — checked against the callable at (t₀, y₀) and at seeded
  perturbations — become the problem, as a sympy f would (below): the compiled loop or the
  Python loop, chosen by predicted cost, the exact f′, a GLM's exact starting values.  Callable
  invariants I(y) are traced with it; a function already compiled by numba is traced through its
  Python source (``py_func``).  A callable that is not traceable (``math.sin``, a branch
  on a value, hidden state) runs as Python in the Python step loop, with f′ by central
  differences (the stage equations are solved to the same tolerance; only the Newton
  iteration's rate depends on f′) and a GLM started naively (y^[0] = u y₀: no elementary
  differentials of a callable), which :attr:`Solution.start` says; the time is carried as one
  more state component (t′ = 1, integrated exactly by every consistent method), so f may
  depend on t.  (numba's ``njit`` of such a callable was dropped: it cost a compile of 0.5–3.5 s
  and bought nothing for RK4 and about 10 % of a Gauss 2 step in the Python loop,
  ``benchmarks/loop_choice.py``, docs/speed.md.)  :attr:`Solution.loop`,
  :attr:`Solution.why` and a one-line notice say which, and why;
* a sympy expression, list or Matrix in the state symbols ``variables`` (and optionally the time
  symbol ``time``, or a free symbol named ``t``), or
* a :class:`~tableau_lab.numeric.problems.Problem` — :func:`problem`'s result or a built-in
  problem (its name, ``"pendulum"``, or :func:`~tableau_lab.numeric.problems.get_problem`'s
  result).

The last two are problems with symbols: f′, the invariants, the GLM starting values and the
compiled step loop (numba, float64 and double-double) are generated from them exactly as for
the command line's runs (:mod:`~tableau_lab.experiments.runs`).

*The time grid.*  Forward in time (t₁ > t₀).  ``h`` is the largest step: the run takes
n = ⌈(t₁ − t₀)/h⌉ equal steps of (t₁ − t₀)/n (a ratio within 1e-9 of a whole number counts as
that number), so it ends on t₁ exactly, one step size throughout (a GLM's input vector is valid
for one h only; the global error keeps its expansion in one h).  :attr:`Solution.h` is the step
used.  ``t_span`` and ``h`` are read exactly where they are exact (``sympy.pi``, ``"1/100"``,
integers; a float as the decimal it prints as), and the step is rounded once at the working precision.

>>> import numpy as np
>>> from tableau_lab.exact.tableau_json import load
>>> sol = integrate(load("gauss2"), lambda t, y: np.array([y[1], -y[0]]), [1, 0], (0, 1), h=0.1, notice=False)
>>> sol.steps, float(sol.times[-1]), bool(abs(sol.final[0] - np.cos(1)) < 1e-6)
(10, 1.0, True)
>>> sol.loop, sol.why.split(";")[0]
('Python', 'f traced to expressions')
>>> import math
>>> integrate(load("gauss2"), lambda t, y: [y[1], -math.sin(y[0])], [1, 0], (0, 1), h=0.1, notice=False).why[:33]
'f not traceable (f(t, y) needs a '
>>> P = problem(H="p^2/2 - cos(q)", q0=["1/2"], p0=[0])
>>> sol = integrate(load("gauss2"), P, None, (0, 10), h="1/10", kernel="python", notice=False)
>>> bool(abs(sol.invariant_errors["H"]).max() < 1e-6), sol.names
(True, ('q', 'p'))

References: [HNW93] E. Hairer, S. P. Nørsett, G. Wanner, Solving Ordinary Differential Equations I,
2nd ed., Springer 1993, II.1 (fixed-step Runge–Kutta runs, the order measured on log–log data);
[B16] J. C. Butcher, Numerical Methods for Ordinary Differential Equations, 3rd ed., Wiley 2016,
ch. 5 (GLMs with their starting methods).
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np
import sympy as sp

from ..budget import DEFAULT_SECONDS, computing, time_limit
from ..errors import InputError
from ..exact.catalog import load_with_numbers
from ..numeric.problems import LABEL_LENGTH, MAX_ENTRIES, Problem, ProblemError, exact_value, get_problem, valid_name

__all__ = ["integrate", "problem", "Solution", "step_grid"]

#: a ratio (t₁ − t₀)/h this close (relative) to a whole number is that number of steps
WHOLE = 1e-9
#: records kept by default (every step up to this many; a longer run records every k-th step)
RECORDS = 100_000


# -- problems ------------------------------------------------------------------------------------

def _names(value, key, default, label) -> tuple:
    """Coordinate names from a string ("q"), a list of strings or sympy symbols."""
    if value is None:
        value = default
    items = [value] if isinstance(value, (str, sp.Symbol)) else value
    if not isinstance(items, (list, tuple)) or not 0 < len(items) <= MAX_ENTRIES:
        raise ProblemError(f"problem {label!r}, entry {key!r}: a name or a list of 1 to {MAX_ENTRIES} names is needed")
    out = []
    for i, n in enumerate(items):
        n = n.name if isinstance(n, sp.Symbol) else n
        if not valid_name(n):
            raise ProblemError(f"problem {label!r}, entry '{key}[{i + 1}]': {n!r} is not a valid name (a letter, "
                               "then letters, digits, _; not a function or constant name)")
        out.append(n)
    return tuple(out)


def _coordinates(H) -> tuple:
    """The coordinate and momentum names H uses when none are given: q1, q2, … and p1, p2, …
    (or q and p) in the order of their numbers; ("q",), ("p",) when it uses none.

    >>> _coordinates("(p1^2 + p2^2)/2 - 1/sqrt(q1^2 + q2^2)")
    (('q1', 'q2'), ('p1', 'p2'))
    """
    import re
    text = H if isinstance(H, str) else " ".join(str(s) for s in getattr(H, "free_symbols", ()))
    found = set(re.findall(r"(?<![A-Za-z0-9_])([qp][0-9]*)(?![A-Za-z0-9_])", text))
    qs = sorted((n for n in found if n[0] == "q"), key=lambda n: (len(n), n))
    ps = sorted((n for n in found if n[0] == "p"), key=lambda n: (len(n), n))
    return (tuple(qs) or ("q",)), (tuple(ps) or ("p",))


def _reader(label, names: dict):
    """The reader of one entry: text through the safe grammar (never eval), a sympy expression
    with its free symbols matched to ``names`` by name and its floats read as the decimals they
    print as, or a number (read exactly)."""
    def read(key, v, allowed=names):
        where = f"problem {label!r}, entry {key!r}"
        if isinstance(v, sp.Basic) and not v.is_Number:
            if not isinstance(v, sp.Expr):
                raise ProblemError(f"{where}: {type(v).__name__} is not an expression")
            extra = sorted(str(s) for s in v.free_symbols if str(s) not in allowed)
            if extra:
                raise ProblemError(f"{where}: uses undeclared names {extra} (declared: {', '.join(allowed) or 'none'})")
            floats = {x: exact_value(float(x), where) for x in v.atoms(sp.Float)}     # 0.1 is 1/10, as in text
            return v.xreplace({**{s: allowed[str(s)] for s in v.free_symbols}, **floats})
        return exact_value(v.item() if isinstance(v, np.generic) else v, where, allowed)
    return read


def _values(v, key, n, read, label):
    """Initial values: 0 when not given; each read exactly (parameters may appear)."""
    if v is None:
        return (0,) * n
    items = list(v) if isinstance(v, (list, tuple, np.ndarray, sp.MatrixBase)) else [v]
    if len(items) != n:
        raise ProblemError(f"problem {label!r}, entry {key!r}: {n} values needed, got {len(items)}")
    return tuple(read(f"{key}[{i + 1}]", x) for i, x in enumerate(items))


def problem(H=None, *, f=None, q=None, p=None, y=None, q0=None, p0=None, y0=None, invariants=None,
            parameters=None, angles=(), name: str = "user") -> Problem:
    """A problem of the user's: a Hamiltonian ``H`` in coordinates ``q`` and momenta ``p`` (by
    default the names q1, q2, … and p1, p2, … that H uses, or q and p; f = (∂H/∂p, −∂H/∂q)), or a
    right-hand side ``f`` (a list) in the variables ``y``.
    Expressions are text read by the project's safe grammar (:mod:`~tableau_lab.numeric.expressions`:
    numbers, declared names, + − * / ^ and sqrt, exp, log, sin, cos, …; never eval) or sympy
    expressions (their symbols matched to the declared names by name).  ``invariants`` and
    ``parameters`` are dicts name → expression / value; initial values (``q0``, ``p0``, ``y0``)
    default to 0 and are read exactly (0.1 is 1/10).  The result runs in :func:`integrate` and in
    the command line's machinery (it is a :class:`~tableau_lab.numeric.problems.Problem`).
    A Hamiltonian's field is f = J⁻¹∇H ([HLW06] I.1, VI.2).

    >>> P = problem(H="p**2/2 - cos(q)")
    >>> P.f_expr, P.kind
    ((p, -sin(q)), 'hamiltonian')
    >>> x, v = sp.symbols("x v")
    >>> problem(f=[v, -x - v / 10], y=[x, v], invariants={"E": "v^2/2 + x^2/2"}, y0=[1, 0]).f_expr
    (v, -v/10 - x)
    >>> problem(H="p^2/2 + k*q^2/2", parameters={"k": 4}).parameters
    {'k': 4}
    >>> problem(H="(p1^2 + p2^2)/2 - 1/sqrt(q1^2 + q2^2)", q0=[1, 0], p0=[0, 1]).state
    (q1, q2, p1, p2)
    >>> problem(H="p^2/2 - cos(r)")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    tableau_lab...ProblemError: problem 'user', entry 'H': unknown name 'r' (at position 13 of ...); known names: q, p
    >>> problem(H="__import__('os').system('ls')")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    tableau_lab...ProblemError: problem 'user', entry 'H': names must start with a letter, not '_' (at position 1...)
    """
    if not isinstance(name, str) or not 0 < len(name) <= LABEL_LENGTH:
        raise ProblemError(f"problem(): name must be a string of 1 to {LABEL_LENGTH} characters")
    label = name
    if (H is None) == (f is None):
        raise ProblemError(f"problem {label!r}: give H (a Hamiltonian) or f (a right-hand side), one of them")
    params = parameters or {}
    if not isinstance(params, dict) or len(params) > MAX_ENTRIES or not all(valid_name(k) for k in params):
        raise ProblemError(f"problem {label!r}, entry 'parameters': a dict of at most {MAX_ENTRIES} valid names "
                           "→ values is needed")
    invs = invariants or {}
    if not isinstance(invs, dict) or len(invs) > MAX_ENTRIES or not all(valid_name(k) for k in invs):
        raise ProblemError(f"problem {label!r}, entry 'invariants': a dict of at most {MAX_ENTRIES} valid names "
                           "→ expressions is needed")
    if H is not None:
        if f is not None or y is not None or y0 is not None:
            raise ProblemError(f"problem {label!r}: a Hamiltonian problem takes q, p, q0, p0, not y, f, y0")
        guess_q, guess_p = _coordinates(H)
        qn, pn = _names(q, "q", guess_q, label), _names(p, "p", guess_p, label)
        state = qn + pn
    else:
        if q is not None or p is not None or q0 is not None or p0 is not None:
            raise ProblemError(f"problem {label!r}: a problem given by f takes y, y0, not q, p, q0, p0")
        rhs = list(f) if isinstance(f, (list, tuple, sp.MatrixBase)) else [f]
        state = _names(y, "y", [f"y{i + 1}" for i in range(len(rhs))] if len(rhs) > 1 else "y", label)
    if len(set(state) | set(params)) != len(state) + len(params):
        raise ProblemError(f"problem {label!r}: state names and parameters must be distinct: "
                           f"{', '.join(state + tuple(params))}")
    symbols = {n: sp.Symbol(n, real=True) for n in (*state, *params)}
    read = _reader(label, symbols)
    par = {k: read(f"parameters.{k}", v, {}) for k, v in params.items()}
    body = dict(invariants={k: read(f"invariants.{k}", e) for k, e in invs.items()}, parameters=par,
                source="user-defined (problem())")
    pvals = {k: symbols[k] for k in params}

    def initial(key, v):
        return read(key, v, pvals)
    if H is not None:
        d = len(qn)
        if len(pn) != d:
            raise ProblemError(f"problem {label!r}: q and p must have the same length ({d} and {len(pn)})")
        body.update(q=tuple(symbols[n] for n in qn), p=tuple(symbols[n] for n in pn), hamiltonian=read("H", H),
                    q0=_values(q0, "q0", d, initial, label), p0=_values(p0, "p0", d, initial, label),
                    angles=tuple(angles))
        kind, given = "hamiltonian", q0 is not None or p0 is not None
    else:
        if len(rhs) != len(state):
            raise ProblemError(f"problem {label!r}: f has {len(rhs)} entries for {len(state)} variables")
        body.update(y=tuple(symbols[n] for n in state), rhs=tuple(read(f"f[{i + 1}]", e) for i, e in enumerate(rhs)),
                    y0=_values(y0, "y0", len(state), initial, label))
        kind, given = "general", y0 is not None
    P = Problem(label, kind, **body)
    if given:
        P.check_initial_state()
    return P


def _symbolic_problem(f, variables, time_symbol, y0, invariants, t0) -> Problem:
    """A sympy right-hand side as a general Problem; a time dependence becomes one more
    component (t′ = 1) started at t₀."""
    rhs = list(f) if isinstance(f, (list, tuple, sp.MatrixBase)) else [f]
    if variables is None:
        free = sorted(set().union(*(sp.sympify(e).free_symbols for e in rhs)) - {time_symbol}, key=str)
        free = [s for s in free if not (time_symbol is None and s.name == "t")]
        if len(free) != len(rhs):
            raise InputError(f"integrate: f is a sympy expression: give variables=(the state symbols, in order); "
                             f"its symbols are {', '.join(map(str, free)) or 'none'}")
        variables = free
    variables = list(variables) if isinstance(variables, (list, tuple)) else [variables]
    if not all(isinstance(s, sp.Symbol) for s in variables) or len(variables) != len(rhs):
        raise InputError(f"integrate: variables must be {len(rhs)} sympy symbols (one per entry of f)")
    names = [s.name for s in variables]
    tname = time_symbol.name if time_symbol is not None else "t"
    used = set().union(*(sp.sympify(e).free_symbols for e in rhs)) | set().union(
        *(sp.sympify(e).free_symbols for e in (invariants or {}).values() if isinstance(e, sp.Basic)))
    timed = any(s.name == tname for s in used) and tname not in names
    extra = [1] if timed else []
    return problem(f=rhs + extra, y=names + [tname] * len(extra), y0=list(y0) + [t0] * len(extra),
                   invariants=invariants, name="f")


# -- a Python callable -----------------------------------------------------------------------

class _Callable:
    """A Python f(t, y) as the loop's problem: the state z = (y, t), f(z) = (f(t, y), 1); f′ by
    central differences; invariants I(y) from callables.  ``problem`` is the light description
    the loop asks of it (no symbols: the pure loop runs)."""

    backend = "python"

    def __init__(self, fn, d, invariants, a):
        self.fn, self.d, self.a, self.calls = fn, d, a, 0
        self.invariants = dict(invariants or {})
        for k, inv in self.invariants.items():
            if not callable(inv):
                raise InputError(f"integrate: invariants[{k!r}]: with a callable f, an invariant is a callable I(y)")

        class _P:                          # what the loop and integrate read of a problem
            name, kind, q, separable, operations = "f", "general", (), False, 0
        _P.invariants = self.invariants
        self.problem = _P

    def f(self, z):
        self.calls += 1
        d, a = self.d, self.a
        v = np.asarray(self.fn(z[d], z[:d]), dtype=a.dtype).reshape(-1)
        if v.shape != (d,):
            raise InputError(f"integrate: f(t, y) returned {v.shape[0]} values for a state of dimension {d}")
        out = np.empty(d + 1, dtype=a.dtype)
        out[:d], out[d] = v, a.number(1)
        return out

    def _step(self, x):
        """The central difference's step: eps^(1/3) relative ([HNW93] II.4's choice for f′)."""
        return self.a.loop_tolerances()[0] ** (1 / 3) * max(1, abs(x))     # an mpf at mp:DIGITS (no underflow)

    def jac(self, z):
        n = len(z)
        J = self.a.zeros(n, n)
        for j in range(n):
            e = self._step(z[j])
            zp, zm = z.copy(), z.copy()
            zp[j], zm[j] = z[j] + e, z[j] - e
            J[:, j] = (self.f(zp) - self.f(zm)) / (2 * e)
        return J

    def invariant(self, name, z):
        return self.invariants[name](z[:self.d])

    def gradient(self, name, z):
        g = self.a.zeros(len(z))
        for j in range(self.d):
            e = self._step(z[j])
            zp, zm = z.copy(), z.copy()
            zp[j], zm[j] = z[j] + e, z[j] - e
            g[j] = (self.invariant(name, zp) - self.invariant(name, zm)) / (2 * e)
        return g


def _first_call(f, a, y0, t0) -> tuple:
    """(y₀, t₀) in the arithmetic ``a``, after f(t₀, y₀) ran there and returned one value per
    component (else InputError)."""
    with a.context():
        y = np.array([a.number(v) for v in y0], dtype=a.dtype)
        tt = a.number(t0)
        try:
            first = f(tt, y.copy())
        except Exception as exc:                 # the user's f failing at the start is bad input
            raise InputError(f"integrate: f(t0, y0) raised {type(exc).__name__}"
                             f"{'' if a.dtype is float else ' in ' + a.name}: {str(exc)[:200]}") from exc
    d = len(y)
    if np.shape(first) not in ((d,), (d, 1), (1, d)):
        raise InputError(f"integrate: f(t0, y0) returned shape {np.shape(first)} for a state of dimension {d}")
    return y, tt


def _traced(fn, d: int, invariants, y0, t0) -> tuple:
    """(the Problem a callable f traces to, "") or (None, why not): f (a numba function's
    ``py_func``) and each invariant I(y) traced (:func:`~.tracing.trace_callable`), the problem
    built as for a sympy f, and its generated float64 code checked against the callables
    themselves (:func:`~.tracing.agrees`)."""
    from ..numeric.codegen import compile_problem
    from .tracing import agrees, symbols, trace_callable
    exprs, why = trace_callable(getattr(fn, "py_func", fn), d)     # a numba function: its Python source
    if exprs is None:
        return None, why
    invs = {}
    for k, inv in (invariants or {}).items():
        if not callable(inv):
            raise InputError(f"integrate: invariants[{k!r}]: with a callable f, an invariant is a callable I(y)")
        e, why = trace_callable(inv, d, timed=False)
        if e is None:
            return None, f"invariant {k}: {why.replace('f(t, y)', 'I(y)')}"
        invs[k] = e[0]
    t, ys = symbols(d)
    try:
        P = _symbolic_problem(list(exprs), list(ys), t, y0, invs, t0)
    except InputError as exc:
        return None, f"the traced problem is refused: {exc}"
    cf = compile_problem(P, "numpy")
    timed = P.dimension > d

    def z(t, y):
        return np.concatenate([y, [t]]) if timed else y
    yf, tf = np.array([float(v) for v in y0]), float(t0)
    why = agrees(lambda t, y: cf.f(z(t, y))[:d], fn, tf, yf)
    for k, inv in (invariants or {}).items():
        bad = agrees(lambda t, y, k=k: [cf.invariant(k, z(t, y))], lambda t, y, inv=inv: [inv(y)], tf, yf)
        why = why or (bad and f"invariant {k}: {bad.replace(' with f ', ' with I ')}")
    return (None, why) if why else (P, "")


# -- the run -------------------------------------------------------------------------------------

def _exact(v, what):
    if isinstance(v, str):
        from ..exact.grammar import EntryError, parse_number
        try:
            return parse_number(v)
        except EntryError as exc:
            raise InputError(f"integrate: {what}: {exc}") from None
    try:
        if isinstance(v, (np.floating, np.integer)):
            v = v.item()
        if isinstance(v, sp.Basic) and not v.free_symbols and v.is_real:
            return v
        if isinstance(v, (int, float, Fraction)) and not isinstance(v, bool):
            return exact_value(v, what)
    except InputError:
        pass
    raise InputError(f"integrate: {what}: {str(v)[:40]!r} is not a finite real number")


def step_grid(t_span, h) -> tuple:
    """(t₀, t₁, n, step) exactly: n = ⌈(t₁ − t₀)/h⌉ equal steps (a ratio within :data:`WHOLE`
    of a whole number counts as it), step = (t₁ − t₀)/n ≤ h.

    >>> step_grid((0, 1), "1/10")
    (0, 1, 10, 1/10)
    >>> step_grid((0, 2 * sp.pi), 0.01)[2:]
    (629, 2*pi/629)
    >>> step_grid((1, 0), 0.1)
    Traceback (most recent call last):
    ...
    tableau_lab.errors.InputError: integrate: t_span = (1, 0): t1 must be greater than t0
    """
    from ..inputs import MAX_STEPS
    if not isinstance(t_span, (tuple, list)) or len(t_span) != 2:
        raise InputError(f"integrate: t_span must be (t0, t1), not {str(t_span)[:40]}")
    t0, t1 = (_exact(v, f"t_span[{i + 1}]") for i, v in enumerate(t_span))
    hh = _exact(h, "h")
    if not bool(t1 > t0):
        raise InputError(f"integrate: t_span = ({t0}, {t1}): t1 must be greater than t0")
    if not bool(hh > 0):
        raise InputError(f"integrate: h = {hh}: the step size must be positive")
    ratio = (t1 - t0) / hh
    x = float(ratio)
    if not x <= MAX_STEPS:
        raise InputError(f"integrate: (t1 - t0)/h = {x:.3g} steps is more than the limit of {MAX_STEPS} (MAX_STEPS)")
    n = int(ratio) if ratio.is_Integer else (round(x) if abs(x - round(x)) <= WHOLE * x else math.ceil(x))
    n = max(n, 1)
    return t0, t1, n, (t1 - t0) / n


@dataclass
class Solution:
    """A run of :func:`integrate`: ``times`` (n+1 records), ``states`` (records × dimension, float64;
    the working precision's values in ``run.values``), ``invariants`` and ``invariant_errors``
    (name → array of I(y) and I(y) − I(y₀) at the records), ``nfev`` (evaluations of f by the
    steps; an untraced callable's calls in all, finite differences included, in ``f_calls``,
    None when f was traced), ``steps``, ``h`` (the step used: module docstring), ``loop``
    ("compiled with numba" or "Python") and ``why`` (whether a callable was traced, and why
    this loop: :func:`~tableau_lab.numeric.limits.choose_loop`), ``seconds`` (the steps) and
    ``compile_seconds`` (numba's first call of a compiled loop: a compile, or a load from its disk
    cache), ``start`` (a GLM's starting values: "exact" or "naive"), ``run`` (the integrator's
    :class:`~tableau_lab.numeric.integrate.Run`).
    ``plot(ax=None, what="states" | "phase" | "invariants")`` draws it on matplotlib axes.

    >>> from tableau_lab.exact.tableau_json import load
    >>> sol = integrate(load("gauss2"), problem(H="p^2/2 + q^2/2", q0=[1]), None, (0, 1), "1/10",
    ...                 kernel="python", notice=False)
    >>> sol.steps, sol.loop, bool(abs(sol.invariant_errors["H"]).max() < 1e-14)   # [HLW06] IV.2: H is kept
    (10, 'Python', True)
    """
    method: str
    problem: str
    precision: str
    names: tuple
    times: np.ndarray
    states: np.ndarray
    invariants: dict
    invariant_errors: dict
    nfev: int
    steps: int
    h: float
    loop: str
    why: str
    start: str
    seconds: float
    compile_seconds: float = 0.0
    f_calls: int | None = None
    run: object = field(default=None, repr=False)

    @property
    def final(self) -> np.ndarray:
        """The state at t₁ (float64)."""
        return self.states[-1]

    def __str__(self):
        err = ", ".join(f"max |{k} − {k}(y0)| = {float(np.max(np.abs(v), initial=0.0)):.3g}"
                        for k, v in self.invariant_errors.items())
        return (f"{self.method} on {self.problem}: {self.steps} steps of h = {self.h:.6g} to t = {self.times[-1]:.6g} "
                f"in {self.precision}, {self.nfev} f-evaluations, {self.seconds:.3g} s; loop: {self.loop} "
                f"({self.why}); final state {np.array2string(self.final, precision=10)}" + (f"; {err}" if err else ""))

    def plot(self, ax=None, what: str = "states"):
        """The states against t (``what="states"``), the phase plane of the first two components
        (``"phase"``) or |I − I(y₀)| on a log scale (``"invariants"``), on ``ax`` (a new figure
        when None); returns the matplotlib Axes."""
        if ax is None:
            import matplotlib.pyplot as plt
            _, ax = plt.subplots()
        if what == "states":
            for i, n in enumerate(self.names):
                ax.plot(self.times, self.states[:, i], label=n)
            ax.set_xlabel("t")
            ax.legend()
        elif what == "phase":
            if self.states.shape[1] < 2:
                raise ValueError("plot(what='phase'): the state has one component")
            ax.plot(self.states[:, 0], self.states[:, 1])
            ax.set_xlabel(self.names[0])
            ax.set_ylabel(self.names[1])
        elif what == "invariants":
            if not self.invariant_errors:
                raise ValueError("plot(what='invariants'): the run tracked no invariants")
            for k, v in self.invariant_errors.items():
                ax.semilogy(self.times, np.maximum(np.abs(v), 1e-300), label=f"|{k} − {k}(y0)|")
            ax.set_xlabel("t")
            ax.legend()
        else:
            raise ValueError(f"plot: what must be 'states', 'phase' or 'invariants', not {what!r}")
        ax.set_title(f"{self.method}, h = {self.h:.4g}")
        return ax


def _symbolic(f, y0, variables, time_symbol, invariants, t0) -> tuple:
    """(the Problem integrate runs, the number of its state components shown) for f a Problem,
    a built-in problem's name or a sympy right-hand side."""
    if isinstance(f, Problem) or isinstance(f, str):
        P = get_problem(f)
        if y0 is not None:
            vals = list(np.asarray(y0, dtype=object).reshape(-1))
            if len(vals) != P.dimension:
                raise InputError(f"integrate: y0 has {len(vals)} values for the {P.dimension} of {P.name}")
            k = len(P.q)
            P = P.with_values(q0=vals[:k], p0=vals[k:]) if P.kind == "hamiltonian" else P.with_values(y0=vals)
        else:
            P.check_initial_state()
        if invariants:
            raise InputError("integrate: a Problem brings its own invariants: declare them in problem(...)")
        keep = P.dimension
    elif isinstance(f, (sp.Basic, list, tuple, sp.MatrixBase)):
        if y0 is None:
            raise InputError("integrate: y0 is needed with a sympy f")
        start = list(np.asarray(y0, dtype=object).reshape(-1))
        P = _symbolic_problem(f, variables, time_symbol, start, invariants, t0)
        keep = len(f) if isinstance(f, (list, tuple, sp.MatrixBase)) else 1
    else:
        raise InputError(f"integrate: f must be a callable f(t, y), a sympy expression or list, or a Problem, "
                         f"not {type(f).__name__}")
    return P, keep


def integrate(method, f, y0, t_span, h, *, variables=None, time=None, invariants=None, precision: str = "float64",
              project=(), start: str = "exact", kernel: str = "auto", trace: bool | None = None,
              record_every: int | None = None, notice: bool = True,
              timeout: float | None = DEFAULT_SECONDS) -> Solution:
    """Integrate y′ = f(t, y), y(t₀) = y0 over ``t_span`` = (t₀, t₁) with the method ``method`` (a method
    object, or a file, library or family name) and steps of at most ``h`` (module docstring: the
    grid, and what ``f`` may be). ``y0`` may be None for a Problem (its own initial values).
    ``invariants``: name → I(y) (callables for a callable f; expressions for a sympy f; a Problem
    brings its own) are recorded, and ``project`` (names) projects onto them. ``precision``:
    "float64", "dd" (problems with symbols) or "mp:DIGITS". ``kernel``: "auto", "compiled" or
    "python" (problems with symbols, and a traced callable: the step loop; "auto" the one predicted
    to finish first, :func:`~tableau_lab.numeric.limits.choose_loop`); ``trace``: False runs a callable
    as Python without tracing it, True requires the trace (InputError when it fails).
    ``notice``: print the one-line notice of which loop ran (and why) to stderr. ``timeout``: the
    budget in seconds (BudgetError; None for none) of the exact stage —
    the method rounded, a symbolic problem's code generated — as the commands' exact work; the
    steps are bounded by ``inputs.MAX_STEPS``. Records every step (every ``record_every``-th; by
    default so that at most :data:`RECORDS` are kept).  The methods: [HNW93] II (Runge–Kutta),
    [B16] ch. 5 (general linear methods and their starting methods).

    >>> from tableau_lab.exact.tableau_json import load
    >>> x, v = sp.symbols("x v")
    >>> sol = integrate(load("rk4"), [v, -x], [1, 0], (0, sp.pi), "1/20", variables=[x, v],
    ...                 kernel="python", notice=False)
    >>> sol.steps, round(float(sol.final[0]), 6), sol.h == float(sp.pi / 63)
    (63, -1.0, True)
    """
    from ..numeric.arith import arith
    from ..numeric.export import to_numeric
    from ..numeric.integrate import integrate as run_steps
    from .runs import compiled, generate, step_count

    m = load_with_numbers(method, "a run")
    try:
        a = arith(precision)
    except ValueError as exc:
        raise InputError(f"integrate: {exc}") from None
    t0, t1, n, hx = step_grid(t_span, h)
    step_count(n, "integrate: (t1 - t0)/h")
    _check_options(start, record_every, project)
    with time_limit(timeout, "timeout=SECONDS"), computing(f"{m.name} in {precision}"):
        nm = to_numeric(m, precision)
    every = min(record_every or max(1, n // RECORDS), n)
    f_calls, traced, label, cp = None, 0, None, None
    if callable(f) and not isinstance(f, (sp.Basic, Problem)):
        label = getattr(f, "__name__", "f")
        P, traced, python = _callable_f(f, y0, invariants, trace, precision, a, t0, project, timeout)
        if P is not None:
            f, y0, variables, time, invariants = P, None, None, None, None
        else:
            cp, z0, names, keep, loop_why = python
    if cp is None:
        with time_limit(timeout, "timeout=SECONDS"), computing("the problem's code"):
            P, keep = _symbolic(f, y0, variables, time, invariants, t0)
            keep = traced or keep
            P.check_projection(project)
            cp = compiled(P, precision)
            generate(cp, nm, tuple(P.invariants), tuple(project))
        z0, names, label = cp.y0, tuple(str(s) for s in P.state[:keep]), label or P.name
    run_start = "naive" if isinstance(cp, _Callable) else start
    with a.context():
        hnum = a.number(hx)
    run = run_steps(nm, cp, z0, hnum, n, start=run_start, project=tuple(project),
                    invariants=tuple(cp.problem.invariants),
                    record_every=every, record_states=True, problem_name=label,
                    kernel="cost" if kernel == "auto" else kernel)
    if isinstance(cp, _Callable):
        f_calls = cp.calls
        loop, why = "Python", loop_why
    else:
        words = {"python": "Python", "compiled": "compiled with numba",
                 "linked": "compiled with numba (the loop shared by every problem)"}
        loop = ", then ".join(words.get(part, part) for part in run.loop.split(", then "))
        if run.switched_at is not None:
            loop += f" after step {run.switched_at}"
        why = _loop_why(run, traced)
    if nm.r > 1 and run_start == "naive" and nm.starting and isinstance(cp, _Callable):
        why += "; a GLM with a callable f starts naively (y^[0] = u y0): its order may drop to the naive start's"
    states = np.array([a.to_float(v)[:keep] for v in run.values])
    with a.context():
        I0 = {k: cp.invariant(k, z0) for k in run.invariant_errors}
    errors = {k: np.array([float(x) for x in v]) for k, v in run.invariant_errors.items()}
    values = {k: float(I0[k]) + errors[k] for k in errors}
    sol = Solution(m.name, label, precision, names, np.array(run.times) + float(t0), states, values, errors,
                   run.nfev, n, float(hnum), loop, why, run.start, run.seconds, run.compile_seconds, f_calls, run)
    if notice:
        print(f"tableau-lab: {m.name}, {n} steps: {loop} ({why})", file=sys.stderr)
    return sol


def _check_options(start, record_every, project) -> None:
    """integrate's start, record_every and project, checked before any work."""
    from .runs import step_count
    if start not in ("exact", "naive"):
        raise InputError(f"integrate: start must be 'exact' or 'naive', not {start!r}")
    if record_every is not None:
        step_count(record_every, "integrate: record_every")
    if isinstance(project, str) or not all(isinstance(k, str) for k in project):
        raise InputError(f"integrate: project must be a list of invariant names, not {str(project)[:40]!r}")


def _callable_f(f, y0, invariants, trace, precision, a, t0, project, timeout) -> tuple:
    """A Python callable ``f``: traced to expressions, (problem, dimension, None); or run as Python
    in the Python step loop, (None, 0, (problem wrapper, z0, names, kept components, why))."""
    if y0 is None:
        raise InputError("integrate: y0 is needed with a callable f")
    if trace not in (None, True, False):
        raise InputError(f"integrate: trace must be None, True or False, not {trace!r}")
    exact0 = [_exact(v, f"y0[{i + 1}]") for i, v in enumerate(np.asarray(y0, dtype=object).reshape(-1))]
    from ..numeric.arith import arith
    y, tt = _first_call(f, arith("float64"), exact0, t0)      # the trace is checked in float64
    d = len(y)
    with time_limit(timeout, "timeout=SECONDS"), computing("the trace of f"):
        P, why = (None, "trace=False") if trace is False else _traced(f, d, invariants, exact0, t0)
    if P is not None:
        return P, d, None
    if trace:
        raise InputError(f"integrate: trace=True, but f is not traceable: {why}")
    if precision == "dd":
        raise InputError(f"integrate: precision dd runs compiled loops generated from a problem's symbols; "
                         f"f is not traceable ({why}): a Python callable runs in float64 or mp:DIGITS")
    if a.dtype is not float:
        y, tt = _first_call(f, a, exact0, t0)           # the callable's own numbers: mpmath's
    cp = _Callable(f, d, invariants, a)
    unknown = [k for k in project if k not in cp.invariants]
    if unknown:
        raise InputError(f"integrate: project: {', '.join(unknown)} not among the invariants given "
                         f"({', '.join(cp.invariants) or 'none'})")
    names = tuple(f"y{i + 1}" for i in range(d)) if d > 1 else ("y",)
    z0 = np.concatenate([y, np.array([tt], dtype=a.dtype)])
    return None, 0, (cp, z0, names, d, f"f not traceable ({why}): a Python callable runs in the Python step loop")


def _loop_why(run, traced) -> str:
    """Why a problem's run took the loop it took (integrate's notice; ``Run.loop_why``)."""
    return f"f traced to expressions; {run.loop_why}" if traced else run.loop_why
