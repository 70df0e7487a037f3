"""Numeric code generated from a problem's symbols: numpy (float64) or mpmath (any precision).

Only what is asked for is generated: f at compile time, the Jacobian, an invariant's gradient
or the m-th derivative of f the first time they are used.  Parameters enter the generated
functions as arguments, converted from their exact values (float64: correctly rounded;
mpmath: at the working precision, never through a float).  Generated code is shared by all
compiled instances of a problem; compiled instances are cached per (problem with its
parameter values, backend, dps).

>>> from tableau_lab.numeric.problems import get_problem
>>> c = compile_problem(get_problem("harmonic"), "mpmath", dps=25)
>>> c.f(c.y0)
array([mpf('0.0'), mpf('-1.0')], dtype=object)
>>> F = c.elementary_differentials(3)([1, 2])
>>> [list(F[t]) for t in [(), ((),), ((), ())]]       # f, f'f, f''(f, f)
[[mpf('2.0'), mpf('-1.0')], [mpf('-1.0'), mpf('-2.0')], [mpf('0.0'), mpf('0.0')]]
"""
from __future__ import annotations

import contextlib
import functools
import hashlib
import json
from pathlib import Path

import mpmath
import sympy as sp

from ..files import atomic_write_text, path_exists
from ..inputs import read_json
from .arith import arith
from .frozen import function_from_text, generated_text
from .problem_functions import ProblemFunctions
from .problems import Problem, ProblemError, exact_value, get_problem

__all__ = ["compile_problem", "CompiledProblem", "reference", "extrapolation"]

_CODE: dict = {}       # (problem.key, backend, what) -> generated function
_COMPILED: dict = {}   # (problem.key, backend, dps) -> CompiledProblem
_REFERENCES: dict = {}  # (problem.key, t, dps, method) -> state


def compile_problem(problem, backend: str = "numpy", dps: int | None = None,
                    parameters: dict | None = None) -> "CompiledProblem":
    """f, jac, invariant, gradient and elementary differentials of ``problem`` (a Problem or a
    built-in's name) for ``backend`` ("numpy" or "mpmath"; ``dps`` defaults to mpmath's current
    precision), with ``parameters`` (name -> value, read exactly) replacing the problem's own."""
    if backend not in ("numpy", "mpmath"):
        raise ProblemError(f"backend must be 'numpy' or 'mpmath', not {backend!r}")
    problem = get_problem(problem, **(parameters or {}))
    dps = None if backend == "numpy" else int(dps or mpmath.mp.dps)
    key = (problem.key, backend, dps)
    if key not in _COMPILED:
        _COMPILED[key] = CompiledProblem(problem, backend, dps)
    return _COMPILED[key]


class CompiledProblem(ProblemFunctions):
    """The functions of :class:`~.problem_functions.ProblemFunctions`, generated from the
    problem's symbols: f at construction, the rest on first use."""

    def __init__(self, problem, backend, dps):
        self.problem, self.backend, self.dps = problem, backend, dps
        self.constants = [self._number(v) for v in problem.parameters.values()]
        self.y0 = self._vector([self._number(v) for v in problem.initial_state()])
        self._functions: dict = {}          # what -> generated function: the loops look up by ``what`` alone
        self._code("f")

    def _number(self, x):
        return arith("float64" if self.backend == "numpy" else f"mp:{self.dps}").number(x)

    def _code(self, what):
        fn = self._functions.get(what)
        if fn is None:                      # the problem's key (sympy objects) is hashed once per ``what``
            key = (self.problem.key, self.backend, what)
            if key not in _CODE:
                path = self._stored(what)
                _CODE[key] = _load_code(path) or _store_code(path, self._generate(what))
            fn = self._functions[what] = _CODE[key]
        return fn

    def _generate(self, what):
        exprs, extra = self._expressions(what)
        args = [list(self.problem.state), list(self.problem.parameter_symbols.values()), *extra]
        return sp.lambdify(args, exprs, modules=self.backend, cse=True)

    def _stored(self, what) -> Path:
        """The file of ``what``'s generated code in the cache (:func:`code_dir`): named by a digest
        of what the code is made from — the state, parameter symbols (with their assumptions),
        f and the invariants, the backend and ``what`` — and of the code that makes it (this
        file, sympy's version); parameter and initial values are arguments, not part of it."""
        digest = hashlib.sha256(f"{_STAMP}\n{self._made_of}\n{self.backend}\n{what!r}".encode()).hexdigest()[:32]
        from .kernels import code_dir
        return code_dir() / f"{digest}.json"

    @functools.cached_property
    def _made_of(self) -> str:
        """What the problem's generated code is made from, as text (:meth:`_stored`): once per
        problem, a large f's srepr takes a while."""
        P = self.problem
        return sp.srepr((tuple(P.state), tuple(P.parameter_symbols.values()), tuple(P.f_expr),
                         tuple(P.invariants.items())))

    def _expressions(self, what):
        """The expressions of ``what`` (see ``ProblemFunctions``) and the extra vector arguments."""
        P = self.problem
        if what == "f":
            return list(P.f_expr), []
        if what == "jac":
            return sp.Matrix(P.f_expr).jacobian(P.state).tolist(), []
        kind, arg = what
        if kind == "invariant":
            return P.invariants[arg], []
        if kind == "gradient":
            return [sp.diff(P.invariants[arg], s) for s in P.state], []
        # the m-th derivative: ∂ᵐ/∂s₁…∂s_m f(y + s₁u₁ + … + s_m u_m) at s = 0
        us = [[sp.Dummy(f"u{k}_{j}", real=True) for j in range(P.dimension)] for k in range(arg)]
        ss = [sp.Dummy(f"s{k}", real=True) for k in range(arg)]
        shift = {y: y + sum(s * u[j] for s, u in zip(ss, us, strict=False)) for j, y in enumerate(P.state)}
        out = []
        for g in P.f_expr:
            g = g.xreplace(shift)
            for s in ss:
                g = sp.diff(g, s).xreplace({s: 0})
            out.append(g)
        return out, us


# -- generated code kept on the disk ------------------------------------------------------------

_STAMP = hashlib.sha256(Path(__file__).read_bytes() + sp.__version__.encode()).hexdigest()[:16]


def _load_code(path: Path):
    """The generated function stored at ``path`` (:func:`.frozen.generated_text`'s source and
    homes, JSON), or None where there is none or it cannot be read (then it is generated again)."""
    if not path_exists(path):
        return None
    try:
        stored = read_json(path, ProblemError, "generated-code cache file", input=False)
        return function_from_text(stored["source"], stored["homes"], f"<generated {path.stem}>")
    except (ProblemError, KeyError, TypeError, ValueError, SyntaxError, ImportError, AttributeError):
        return None


def _store_code(path: Path, fn):
    """``fn`` (generated by lambdify), its text written to ``path`` unless the cache folder cannot
    be written (the run goes on without it)."""
    source, homes = generated_text(fn)
    with contextlib.suppress(OSError):
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(path, json.dumps({"source": source, "homes": homes}))
    return fn


# -- high-precision reference integration --------------------------------------------------------

def _gbs_step(f, y, fy, H, k):
    """One step of the Gragg-Bulirsch-Stoer method: the midpoint rule with n = 2, 4, …, 2k
    substeps extrapolated to order 2k (Aitken-Neville in h²); returns (T_kk, T_kk − T_k,k−1)."""
    prev = []
    for j in range(1, k + 1):
        n = 2 * j
        h = H / n
        z0, z1 = y, y + fy * h              # array * mpf: mpf * array is slow
        for _ in range(n - 1):
            z0, z1 = z1, z0 + f(z1) * (2 * h)
        row = [z1]
        for i in range(1, j):
            row.append(row[i - 1] + (row[i - 1] - prev[i - 1]) / ((mpmath.mpf(n) / (n - 2 * i)) ** 2 - 1))
        prev = row
    return prev[-1], prev[-1] - prev[-2]


def _integrate(f, y, t, tol, k):
    s, H = mpmath.mpf(0), min(abs(t), mpmath.mpf(1) / 10) * mpmath.sign(t)
    for _ in range(100000):
        if s == t:
            return y
        last = abs(H) >= abs(t - s)
        if last:
            H = t - s
        ynew, diff = _gbs_step(f, y, f(y), H, k)
        floor = max(abs(v) for v in y) * mpmath.mpf(10) ** -6 + mpmath.eps
        err = max(abs(d) / (abs(v) + floor) for d, v in zip(diff, y, strict=False)) / tol
        if not mpmath.isfinite(err):
            raise ProblemError(f"reference integration failed: non-finite values at t = {mpmath.nstr(s, 8)}")
        if err <= 1:
            s, y = t if last else s + H, ynew
        H *= min(4, max(mpmath.mpf(1) / 5, mpmath.mpf(9) / 10 * err ** (-mpmath.mpf(1) / (2 * k - 1))))
    raise ProblemError(f"reference integration needs more than 100000 steps (stopped at t = {mpmath.nstr(s, 8)})")


def extrapolation(problem: Problem, t, dps: int, k: int | None = None):
    """The state at time t by the GBS extrapolation method (order 2k, by default k = dps/3 + 4
    between 8 and 30, i.e. order 28 at 32 digits; adaptive steps) at
    dps + 20 digits, run with local tolerances 10^-(dps+4) and 10^-(dps+8); the two results
    must agree to 10^-dps (relative to the size of the state), else ProblemError."""
    wp, k = dps + 20, k or max(8, min(30, dps // 3 + 4))
    c = compile_problem(problem, "mpmath", dps=wp)
    with mpmath.workdps(wp):
        t = c._number(t)
        coarse = _integrate(c.f, c.y0, t, mpmath.mpf(10) ** -(dps + 4), k)
        fine = _integrate(c.f, c.y0, t, mpmath.mpf(10) ** -(dps + 8), k)
        size = max(1, max(abs(v) for v in fine))
        gap = max(abs(a - b) for a, b in zip(coarse, fine, strict=False)) / size
        if gap > mpmath.mpf(10) ** -dps:
            raise ProblemError(f"reference solution of {problem.name!r} at t = {t}: two tolerances disagree "
                               f"by {mpmath.nstr(gap, 3)} (relative), more than 1e-{dps}")
        return fine


def reference(problem: Problem, t, dps: int = 32, method: str = "auto") -> tuple:
    """The solution at time t to ``dps`` digits, as a tuple of mpmath numbers.

    ``method``: "exact" (the problem's closed form: harmonic oscillator, unperturbed Kepler
    through Kepler's equation), "integrate" (``extrapolation``: GBS at dps + 20 digits, two
    tolerances that must agree to 10^-dps relative), or "auto" (exact where available).
    Results are cached in memory.

    >>> from tableau_lab.numeric.problems import get_problem
    >>> x = reference(get_problem("harmonic"), 1, dps=20)
    >>> mpmath.nstr(x[0], 15), mpmath.nstr(x[1], 15)
    ('0.54030230586814', '-0.841470984807897')
    """
    t = exact_value(t, "reference time")
    if method not in ("auto", "exact", "integrate"):
        raise ProblemError(f"method must be 'auto', 'exact' or 'integrate', not {method!r}")
    key = (problem.key, t, int(dps), method)
    if key not in _REFERENCES:
        state = None
        if method != "integrate" and problem.reference is not None:
            state = problem.reference(problem, t, dps)
        if state is None and method == "exact":
            raise ProblemError(f"problem {problem.name!r} has no exact solution for these initial values")
        if state is None:
            state = extrapolation(problem, t, dps)
        with mpmath.workdps(dps):
            _REFERENCES[key] = tuple(mpmath.mpf(str(sp.N(v, dps + 10))) if isinstance(v, sp.Basic)
                                     else +mpmath.mpf(v) for v in state)
    return _REFERENCES[key]
