"""A compiled problem as data: the generated code of the functions one run needs, as text.

:func:`freeze` takes a :class:`~.codegen.CompiledProblem` (built from the problem's symbols)
and keeps the source of f and of what the run asks for (the Jacobian, invariants, gradients,
derivatives f⁽ᵐ⁾ up to an order), the names of the generated globals it calls, the
parameter values, y0 and the files of its compiled loops.  A :class:`FrozenProblem` pickles
and evaluates the same code in a process that never imports sympy (``experiments/job.py``), so
the numbers are those of the compiled problem, bit for bit.

>>> from tableau_lab.numeric.codegen import compile_problem
>>> import pickle
>>> cp = compile_problem("kepler")
>>> fp = pickle.loads(pickle.dumps(freeze(cp, invariants=("H",), jac=True)))
>>> bool(fp.invariant("H", cp.y0) == cp.invariant("H", cp.y0)), bool((fp.jac(cp.y0) == cp.jac(cp.y0)).all())
(True, True)
>>> fp.gradient("H", cp.y0)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
tableau_lab.numeric.problem_functions.ProblemError: problem 'kepler': ('gradient', 'H') was not frozen with it ...
"""
from __future__ import annotations

import builtins
import hashlib
import importlib
import inspect
import linecache
from dataclasses import dataclass, field

from .problem_functions import ProblemError, ProblemFunctions

__all__ = ["ProblemInfo", "FrozenProblem", "freeze", "generated_text", "function_from_text"]

_HOMES = ("numpy", "mpmath", "math", "builtins")   # where generated code's globals may come from


@dataclass(frozen=True)
class ProblemInfo:
    """What a run reads of a problem besides its functions (no symbols)."""
    name: str
    kind: str                  # "hamiltonian" or "general"
    q: tuple                   # names of the q components (Hamiltonian problems)
    invariants: tuple          # names
    dimension: int
    key: str                   # a digest of the problem with its parameter values
    kernel_files: dict = field(default_factory=dict)   # kind -> kernels.write_problem_module's (name, path)
    separable: bool = False    # H = T(p) + V(q): the stage iteration on the q stages alone
    operations: int = 0        # of one f-evaluation: the stage-iteration cost model's price of f (Problem.operations)


class FrozenProblem(ProblemFunctions):
    """The functions of :class:`~.problem_functions.ProblemFunctions` from frozen source text."""

    def __init__(self, problem: ProblemInfo, backend: str, dps, constants, y0, codes: dict):
        self.problem, self.backend, self.dps = problem, backend, dps
        self.constants, self.y0, self.codes = list(constants), y0, dict(codes)
        self._functions = {}

    def _code(self, what):
        if what not in self._functions:
            if what not in self.codes:
                hint = {"jac": "jac=True", "invariant": "invariants=...", "gradient": "gradients=...",
                        "derivative": "derivatives=..."}[what if isinstance(what, str) else what[0]]
                raise ProblemError(f"problem {self.problem.name!r}: {what!r} was not frozen with it "
                                   f"(freeze(..., {hint}))")
            source, homes = self.codes[what]
            self._functions[what] = function_from_text(source, homes, f"<frozen {self.problem.name} {what}>")
        return self._functions[what]


def function_from_text(source: str, homes: dict, label: str):
    """The generated function of :func:`generated_text`'s (source, homes), compiled again: its
    globals taken from the modules ``homes`` names (name -> (module, attribute)); its text kept
    under ``label`` for ``inspect.getsource`` (as lambdify keeps it), so it can be frozen again."""
    ns = {name: getattr(importlib.import_module(mod), attr) for name, (mod, attr) in homes.items()}
    linecache.cache[label] = (len(source), None, source.splitlines(True), label)
    exec(compile(source, label, "exec"), ns)
    return ns["_lambdifygenerated"]


def _names(code) -> set:
    out = set(code.co_names)
    for c in code.co_consts:
        if inspect.iscode(c):
            out |= _names(c)
    return out


def _home(name, obj) -> tuple:
    """(module, attribute) holding ``obj``: generated code calls numpy/mpmath/math functions."""
    for mod in _HOMES:
        m = importlib.import_module(mod)
        if getattr(m, name, None) is obj:
            return mod, name
    for mod in _HOMES:
        for attr, v in vars(importlib.import_module(mod)).items():
            if v is obj:
                return mod, attr
    raise ProblemError(f"generated code calls {name!r}, which is not a numpy, mpmath or math function")


def generated_text(fn) -> tuple:
    """(source, homes) of a function lambdify generated: its text and where each global it calls
    comes from (name -> (module, attribute)), for :func:`function_from_text`."""
    g = fn.__globals__
    homes = {n: _home(n, g[n]) for n in sorted(_names(fn.__code__)) if n in g and not hasattr(builtins, n)}
    return inspect.getsource(fn), homes


def freeze(cp, *, invariants=(), gradients=(), jac=False, derivatives: int = 0, kernels=()) -> FrozenProblem:
    """The functions of ``cp`` (a CompiledProblem) that a run needs, as a picklable
    :class:`FrozenProblem`: f always; the Jacobian if ``jac``; the named invariants and
    gradients; f⁽ᵐ⁾ for 1 ≤ m < ``derivatives`` (the elementary differentials up to that order);
    the problem modules of the compiled loops of ``kernels`` ("f64", "dd") written to the cache
    and named (the loops themselves need no sympy: the job writes those it runs)."""
    P = cp.problem
    wanted = ["f"] + (["jac"] if jac else []) + [("invariant", k) for k in invariants]
    wanted += [("gradient", k) for k in gradients] + [("derivative", m) for m in range(1, derivatives)]
    for k in tuple(invariants) + tuple(gradients):
        cp._known_invariant(k)
    codes = {w: generated_text(cp._code(w)) for w in wanted}
    files = {}
    if kernels:
        from .kernels import write_problem_module
        files = {kind: write_problem_module(P, kind) for kind in kernels}
    info = ProblemInfo(P.name, P.kind, tuple(str(x) for x in getattr(P, "q", ()) or ()), tuple(P.invariants),
                       P.dimension, hashlib.sha256(repr((P.key, cp.backend, cp.dps)).encode()).hexdigest()[:20],
                       files, P.separable, P.operations)
    return FrozenProblem(info, cp.backend, cp.dps, cp.constants, cp.y0, codes)
