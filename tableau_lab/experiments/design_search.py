r"""Design search: the best member of an exact solution family, found numerically and certified
exactly (issue 18).

1. The family (:mod:`..analysis.family`) is evaluated in float64 at any point of its free
   parameters (one ``lambdify`` of its matrices); the objectives and constraints are those of
   :mod:`..numeric.objectives`.
2. A Sobol sample of the box (scipy.stats.qmc) ranks the starting points; Nelder–Mead refines the
   best of them on the penalised score (constraint violations weigh ``PENALTY``); distinct local
   optima are kept.
3. **Certify**: the optimum is snapped to exact values — the rationals of smallest height within the
   objective tolerance first (:mod:`..exact.rationals`, one parameter at a time), then,
   when the constraints are equations the rationals cannot meet (an order, μ = 0), the family is
   solved again with those constraints as exact requirements and the nearest real solution is
   taken; on families with more than EXACT_FREE parameters, the parameters the constraints leave
   free are snapped and the determined ones solved exactly (a partial snap) — and the member is
   re-verified by the ordinary analyses (order, G-symplecticity, μ, the exact stability interval).
   A member that cannot be certified is reported as such; one that several optima certify to is
   reported once; an optimum that a face of the box keeps within tolerance is flagged box-bound.

>>> from tableau_lab.analysis.family import families_of
>>> fam = families_of("methods/design/pn_family.json", ["g-symplectic"])[0]
>>> res = search(fam, maximize="imaginary-interval", constraints=("order=4",), box=(-3.0, 3.0), seed=1)
>>> [c.certified.name.split(" at ")[1] for c in res.candidates if c.certified]      # P and N
['u = 1 + 2*sqrt(3)/3', 'u = 1 - 2*sqrt(3)/3']
"""
from __future__ import annotations

import hashlib
import json
import re
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

import numpy as np
import sympy as sp

from ..analysis.family import Family, FamilyError, families_of
from ..analysis.results import Result
from ..analysis.trees import trees_of_order
from ..exact.grammar import format_entry
from ..exact.rationals import by_height, height
from ..files import atomic_write_text
from ..numeric.objectives import (
    YMAX,
    NumericGLM,
    growth,
    imaginary_interval,
    order_residuals,
    real_interval,
    series_defects,
)
from ..render.model import Document, Paragraph, Plain, Typeset

__all__ = ["design", "search", "SearchResult", "Candidate", "OBJECTIVES", "CONSTRAINTS", "PENALTY", "SearchError",
           "check_constraints", "is_checkpoint"]

PENALTY = 1e3            # weight of a constraint violation in the score
MAX_CERTIFIED = 8        # candidates certified per search (each costs exact analyses)
FRONT_POINTS = 12        # a Pareto front is thinned to at most this many members
# certification solves the constraints exactly on families with at most this many free parameters
EXACT_FREE = 3
ORDER_PROBE = 8          # the family's generic order is probed up to this order
FEASIBLE = 1e-9          # a numeric constraint holds below this
DENOMINATORS = (1, 2, 4, 10, 100, 1000, 10 ** 4, 10 ** 6)      # a partial snap's rationals, smallest height first
SNAP_TOLERANCE = 1e-6    # a snapped member must keep the objective values to this (relative) tolerance
SNAP_HEIGHT = 10 ** 6    # a rational snap takes no rational of larger height (max |numerator|, denominator)
SNAP_ATTEMPTS = 8        # rationals tried per parameter (smallest height first) before the snap gives up
FIRST_STEP = 1e-10       # the tolerance interval of a parameter is probed from this (relative) step outwards
INTERVAL_PRECISION = 1e-6  # ... and its ends bisected to this fraction of its half-width
FACE_PROBES = 8          # an optimum is box-bound when these points up to a face all keep the tolerance
PARTIAL_TOLERANCE = 1e-3  # a partly snapped member (the rest solved exactly) may lose this much (relative)
PARTIAL_ATTEMPTS = 3     # exact solves tried per candidate after a partial snap
RANK_TOLERANCE = 1e-6    # singular values of the constraint Jacobian below this (relative) do not count


class SearchError(FamilyError):
    """A search request that cannot run (unknown objective, empty box, …)."""


def _order_of(family: Family, constraints) -> int | None:
    for c in tuple(constraints) + tuple(family.requirements):
        m = re.fullmatch(r"order=(\d+)", str(c).replace(" ", ""))
        if m:
            return int(m.group(1))
    return None


#: objective name -> (sense: +1 maximise / −1 minimise, value(g, p))
OBJECTIVES = {
    "imaginary-interval": (+1, lambda g, p: imaginary_interval(g)),
    "real-interval": (+1, lambda g, p: real_interval(g)),
    "error-norm": (-1, lambda g, p: series_defects(g, p)[1]),
    "mu": (-1, lambda g, p: max((abs(m) for m in growth(g)), default=0.0)),
}
#: constraint name -> its residual vector at a member (all zero when it holds)
CONSTRAINTS = {
    "parasitism-free": lambda g, p: np.array([v for m in growth(g) for v in (m.real, m.imag)]),
    "order": lambda g, p: order_residuals(g, p),
    "explicit-first-stage": lambda g, p: np.array([g.A[0, 0]]),
}


@dataclass
class Candidate:
    point: tuple                      # free parameter values (floats)
    values: dict                      # objective -> value
    violation: float
    certified: object = None          # the exact Method when certified
    exact: dict = field(default_factory=dict)     # parameter -> exact value
    verified: dict = field(default_factory=dict)  # property -> exact result
    note: str = ""
    box_bound: tuple = ()             # (parameter, face) for each box face within tolerance of the optimum
    repeats: int = 0                  # other local optima that certified to exactly this member

    @property
    def height(self) -> int | None:
        """The largest height max(|p|, q) of the exact parameters when they are all rational p/q."""
        vals = [sp.sympify(v) for v in self.exact.values()]
        return max(height(v) for v in vals) if vals and all(v.is_Rational for v in vals) else None


@dataclass(frozen=True)
class SearchResult(Result):
    family: str
    free: tuple
    objectives: tuple             # one name, or two: then ``candidates`` is the Pareto front
    constraints: tuple
    candidates: tuple
    evaluations: int

    def _goal(self) -> str:
        parts = [f"{'maximise' if OBJECTIVES[o][0] > 0 else 'minimise'} {o}" for o in self.objectives]
        return " and ".join(parts) if len(parts) == 1 else "the Pareto front of " + " and ".join(parts)

    def _text(self) -> str:
        lines = [f"{self.family}: {self._goal()} over {', '.join(map(str, self.free))}"
                 + (f" subject to {', '.join(self.constraints)}" if self.constraints else "")
                 + f" ({self.evaluations} evaluations)"]
        for i, c in enumerate(self.candidates, 1):
            pt = ", ".join(f"{s} = {v:.10g}" for s, v in zip(self.free, c.point, strict=False))
            vals = ", ".join(f"{k} {'≥' if k.endswith('interval') and v >= YMAX else '='} {v:.6g}"
                             for k, v in c.values.items())
            lines.append(f"  {i}. {pt}: {vals}; violation {c.violation:.1e}")
            if c.box_bound:
                lines.append("     box-bound: " + ", ".join(f"{s} = {f:g}" for s, f in c.box_bound)
                             + " (a face of --box keeps the objective within tolerance: the optimum may lie "
                               "beyond it; widen --box)")
            if c.repeats:
                lines.append(f"     also the certified member of {c.repeats} other local "
                             f"optim{'um' if c.repeats == 1 else 'a'}")
            if c.certified is not None:
                h = c.height
                lines.append("     certified: " + ", ".join(f"{k} = {format_entry(v)}" for k, v in c.exact.items())
                             + ("" if h is None else f" (height {h})"))
                lines += [f"       {k}: {_show(v)}" for k, v in c.verified.items()]
            elif c.note:
                lines.append(f"     not certified: {c.note}")
        return "\n".join(lines)

    def to_json(self):
        return {"family": self.family, "free": [str(s) for s in self.free], "objectives": list(self.objectives),
                "constraints": list(self.constraints), "evaluations": self.evaluations,
                "candidates": [{"point": list(c.point), "values": c.values, "violation": c.violation,
                                "certified": c.certified is not None,
                                "exact": {k: str(format_entry(v)) for k, v in c.exact.items()},
                                "verified": {k: str(v) for k, v in c.verified.items()}, "note": c.note,
                                "height": c.height, "repeats": c.repeats,
                                "box_bound": [{"parameter": str(s), "face": f} for s, f in c.box_bound]}
                               for c in self.candidates]}

    def display(self) -> Document:
        """Text: the goal and each candidate; typeset: the number of candidates."""
        head, *lines = self._text().split("\n")
        return Document(head, (Plain(*(Paragraph(x) for x in lines)),
                               Typeset(Paragraph(self.family, f": {len(self.candidates)} candidates."))))


def _show(v) -> str:
    """An exact value, with its decimal value when it is not rational."""
    if isinstance(v, tuple):
        return ", ".join(_show(x) for x in v) or "none"
    v = sp.sympify(v)
    if v.is_Rational or v in (sp.oo, -sp.oo) or not v.is_number:
        return str(v)
    return f"{v} ≈ {complex(sp.N(v, 15)).real:.10g}" if sp.N(v).is_real else str(v)


@dataclass(frozen=True)
class _Task:
    """What a worker needs to score members: picklable (the family's exact matrices travel; each
    process lambdifies them once)."""

    family: Family
    objectives: tuple             # names; with two, ``weight`` mixes them (a Pareto scalarisation)
    constraints: tuple
    p: int
    box: tuple
    scales: tuple = (1.0, 1.0)
    key: str = ""                 # names the family's evaluator in each process (computed once)

    def at(self, x):
        return _evaluator(self.family, self.key)(tuple(x))

    def values(self, x):
        """(objective values, violation) at x, or None where the member is not usable."""
        g = self.at(x)
        if g is None:
            return None
        with np.errstate(all="ignore"):
            try:
                vals = tuple(float(OBJECTIVES[o][1](g, self.p)) for o in self.objectives)
                viol = float(np.max(np.abs(self._residuals(g)), initial=0.0))
            except (np.linalg.LinAlgError, ValueError, ZeroDivisionError):
                return None
        if not all(np.isfinite(vals)) or not np.isfinite(viol):
            return None
        return vals, viol

    def _residuals(self, g) -> np.ndarray:
        parts = [CONSTRAINTS[c.split("=")[0]](g, self.p) for c in self.constraints]
        return np.concatenate(parts) if parts else np.zeros(0)

    def residuals(self, x, size: int) -> np.ndarray:
        """The constraints' residual vector at x (``size`` entries; large where x is unusable)."""
        g = self.at(x)
        with np.errstate(all="ignore"):
            try:
                r = None if g is None else self._residuals(g)
            except (np.linalg.LinAlgError, ValueError, ZeroDivisionError):
                r = None
        if r is None or len(r) != size or not np.all(np.isfinite(r)):
            return np.full(size, 1e6)
        return r

    def mix(self, vals, weight=1.0) -> float:
        """The objectives to minimise, scaled and weighted (weight, 1 − weight)."""
        return sum(-OBJECTIVES[o][0] * v / s * w
                   for o, v, s, w in zip(self.objectives, vals, self.scales, (weight, 1.0 - weight), strict=False))

    def rank(self, out, weight=1.0) -> float:
        """The penalised score of (values, violation) as :meth:`values` gives them."""
        return np.inf if out is None else self.mix(out[0], weight) + PENALTY * out[1]

    def score(self, x, weight=1.0) -> float:
        return self.rank(self.values(x), weight)


_EVALUATORS: dict = {}


def _evaluator(family: Family, key: str):
    """point -> NumericGLM (None where the member is not a method, e.g. a singular I − zA); one
    ``lambdify`` per family and process, found by ``key`` (:func:`_key`)."""
    if key in _EVALUATORS:
        return _EVALUATORS[key]
    g = family.method.as_glm()
    syms = list(family.free)
    fns = [sp.lambdify(syms, M, "numpy") for M in (g.A, g.U, g.B, g.V)]

    def at(point):
        try:
            with np.errstate(all="ignore"):
                mats = [np.array(f(*point), dtype=float) for f in fns]
        except (ZeroDivisionError, FloatingPointError, ValueError):
            return None
        if not all(np.all(np.isfinite(M)) for M in mats):
            return None
        return NumericGLM(*mats)
    _EVALUATORS[key] = at
    return at


def _evaluate(item):
    """A chunk of sample points → [(values, violation) or None] (a module-level task)."""
    task, points = item
    return [task.values(x) for x in points]


def _refine(item):
    """A local search from x0 → (point, (values, violation) or None, evaluations).  Without
    constraints: Nelder–Mead within the box on the (weighted) score.  With constraints: first onto
    the constraint set (least squares on the residual vector, within the box), then along it
    (SLSQP with the residuals as equality constraints) for the weighted objectives."""
    from scipy.optimize import least_squares, minimize
    task, x0, weight = item
    calls = [0]
    lo, hi = task.box
    bounds = [(lo, hi)] * len(x0)

    def f(x):
        calls[0] += 1
        return task.score(x, weight)
    if not task.constraints:
        res = minimize(f, np.array(x0), method="Nelder-Mead", bounds=bounds,
                       options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 2000})
        x = tuple(float(v) for v in res.x)
        return x, task.values(x), calls[0]
    first = task.values(x0)
    if first is None:
        return tuple(x0), None, 1
    size = len(task._residuals(task.at(x0)))
    proj = least_squares(lambda x: task.residuals(x, size), np.array(x0), bounds=(lo, hi), xtol=1e-15, ftol=1e-15,
                         gtol=1e-15, max_nfev=200 * len(x0))
    calls[0] += proj.nfev
    x = tuple(float(v) for v in proj.x)
    out = task.values(x)
    if out is None or out[1] > FEASIBLE or len(x0) <= 1:
        return x, out, calls[0]

    def objective(z):
        calls[0] += 1
        v = task.values(z)
        return 1e6 if v is None else task.mix(v[0], weight)
    try:
        with np.errstate(all="ignore"):
            # SLSQP needs independent equations: the residuals' independent combinations at x
            W = _independent(_jacobian(task, x, size))[0]
            res = minimize(objective, np.array(x), method="SLSQP", bounds=bounds,
                           constraints=[{"type": "eq", "fun": lambda z: W.T @ task.residuals(z, size)}],
                           options={"maxiter": 200, "ftol": 1e-12})
        y = tuple(float(v) for v in res.x)
        better = task.values(y)
        if better is not None and better[1] <= FEASIBLE and objective(y) <= objective(x):
            x, out = y, better
    except (ValueError, np.linalg.LinAlgError):
        pass                                # SLSQP gave up: the projected point stands
    return x, out, calls[0]


def _key(family: Family) -> str:
    """A name for the family's exact matrices and free parameters (the evaluators' cache key)."""
    text = json.dumps([family.name, str(family.method.matrices()), [str(x) for x in family.free]])
    return hashlib.sha256(text.encode()).hexdigest()


def _generic_order(family: Family, key: str, pts) -> int:
    """The order every probed member reaches (the residuals of the order conditions below 1e-9 at
    three sample points): the order the error norm is taken at when no order is required."""
    at = _evaluator(family, key)
    sizes = np.cumsum([len(trees_of_order(n)) for n in range(1, ORDER_PROBE + 1)])
    orders = []
    for x in pts[:3]:
        g = at(x)
        if g is None:
            continue
        with np.errstate(all="ignore"):
            bad = np.flatnonzero(~(np.abs(order_residuals(g, ORDER_PROBE)) < FEASIBLE))
        orders.append(ORDER_PROBE if not len(bad) else int(np.searchsorted(sizes, bad[0], side="right")))
    return max(1, min(orders, default=1))


def check_constraints(constraints) -> tuple:
    """The constraints as the search uses them (``order=P`` with P as ``solve`` takes it, the others
    without a value), or SearchError naming the first that is not one.

    >>> check_constraints(["order=4", "parasitism-free"])
    ('order=4', 'parasitism-free')
    >>> check_constraints(["order=-3"])
    Traceback (most recent call last):
    ...
    tableau_lab.experiments.design_search.SearchError: constraint 'order=-3': order must be between 1 and 12
    """
    from ..analysis.design import DesignError, parse_requirements
    out = []
    for c in constraints:
        text = str(c)
        name, eq, value = (x.strip() for x in text.partition("="))
        if name not in CONSTRAINTS:
            raise SearchError(f"unknown constraint {text!r}: use {', '.join(CONSTRAINTS)} (order=P)")
        if name == "order":
            try:
                req, = parse_requirements([f"order={value}"])
            except DesignError as exc:
                raise SearchError(f"constraint {text!r}: {str(exc).split(': ', 1)[-1]}") from None
            out.append(f"order={req.value}")
        elif eq:
            raise SearchError(f"constraint {text!r}: {name} takes no value")
        else:
            out.append(name)
    return tuple(out)


def _names(v) -> tuple:
    """One objective name, a sequence of names, or None, as a tuple of names."""
    return (v,) if isinstance(v, str) else tuple(v or ())


def _objectives(maximize, minimize) -> tuple:
    """The objective names (each a name, a sequence of names, or None), checked."""
    maximize, minimize = _names(maximize), _names(minimize)
    names = maximize + minimize
    if not 1 <= len(names) <= 2:
        raise SearchError(f"one objective, or two for a Pareto front, from {', '.join(OBJECTIVES)}; got {names}")
    for n in names:
        if n not in OBJECTIVES:
            raise SearchError(f"unknown objective {n!r}: use {', '.join(OBJECTIVES)}")
    for n in maximize:
        if OBJECTIVES[n][0] < 0:
            raise SearchError(f"{n} is minimised, not the other way")
    for n in minimize:
        if OBJECTIVES[n][0] > 0:
            raise SearchError(f"{n} is maximised, not the other way")
    return names


def _dominates(a, b, senses) -> bool:
    better = [s * x >= s * y for s, x, y in zip(senses, a, b, strict=False)]
    strictly = [s * x > s * y for s, x, y in zip(senses, a, b, strict=False)]
    return all(better) and any(strictly)


def is_checkpoint(path) -> bool:
    """Whether the file at ``path`` is a design checkpoint (read bounded: at most
    :data:`~tableau_lab.files.MAX_CHECKPOINT_BYTES`): an object with exactly the keys ``key``,
    ``sample`` and ``refine`` that :class:`_Checkpoint` writes.  Only such a file is replaced by
    ``--checkpoint``; any other is refused, never overwritten."""
    try:
        data = _read_checkpoint(path)
    except ValueError:
        return False
    return (isinstance(data, dict) and set(data) == {"key", "sample", "refine"} and isinstance(data["key"], str)
            and isinstance(data["sample"], dict) and isinstance(data["refine"], dict))


def _read_checkpoint(path):
    from ..files import MAX_CHECKPOINT_BYTES
    from ..inputs import read_json
    return read_json(path, SearchError, "design checkpoint", max_bytes=MAX_CHECKPOINT_BYTES, input=False,
                     parse_constant=float)          # our own file read back (NaN / Infinity as json.dumps wrote them)


def _number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _scores(v, k: int) -> bool:
    """A sample value as the search writes it: None, or [[k objective values], violation]."""
    return v is None or (isinstance(v, list) and len(v) == 2 and isinstance(v[0], list) and len(v[0]) == k
                         and all(map(_number, v[0])) and _number(v[1]))


def _refined(v, k: int, dim: int) -> bool:
    """A local search's value: [point (dim numbers), scores or None, evaluations]."""
    return (isinstance(v, list) and len(v) == 3 and isinstance(v[0], list) and len(v[0]) == dim
            and all(map(_number, v[0])) and _scores(v[1], k) and isinstance(v[2], int) and not isinstance(v[2], bool)
            and v[2] >= 0)


class _Checkpoint:
    """The finished tasks of a search, kept in a JSON file (rewritten atomically as tasks finish) so
    that a rerun of the same request continues where the last one stopped; another request's
    checkpoint is ignored and replaced.  The file is guarded before any work
    (:func:`tableau_lab.files.guard_output`): a file that is not a checkpoint, an input, a device
    or a folder is refused, never replaced; a checkpoint of this request whose entries are not
    what the search wrote (edited, damaged) is refused naming the file and the entry."""

    def __init__(self, path, key: str, objectives: int = 1, dim: int = 1):
        self.path = None if path is None else Path(path)
        self.data = {"key": key, "sample": {}, "refine": {}}
        if self.path is None:
            return
        from ..files import guard_output, path_exists
        from ..inputs import printable
        guard_output(self.path, mine=is_checkpoint, what="--checkpoint")
        if not path_exists(self.path):
            return
        old = _read_checkpoint(self.path)
        if old.get("key") != key:
            return                                  # another request's checkpoint: started afresh, replaced
        for stage, ok in (("sample", lambda v: _scores(v, objectives)),
                          ("refine", lambda v: _refined(v, objectives, dim))):
            for item, value in old[stage].items():
                if not ok(value):
                    raise SearchError(f"{printable(self.path)}: {stage}[{printable(json.dumps(item))[:80]}]: "
                                      "not a value this search writes (the checkpoint was edited or damaged); "
                                      "remove the file to start afresh")
            self.data[stage] = dict(old[stage])

    def has(self, stage: str, item) -> bool:
        return repr(item) in self.data[stage]

    def get(self, stage: str, item):
        return self.data[stage][repr(item)]

    def put(self, stage: str, pairs):
        for item, value in pairs:
            self.data[stage][repr(item)] = value
        if self.path is not None:
            atomic_write_text(self.path, json.dumps(self.data))


def _tuples(v):
    """JSON lists back to the tuples the search uses."""
    return tuple(_tuples(x) for x in v) if isinstance(v, list) else v


def design(tableau, require, maximize=None, minimize=None, constraints=(), box=(-2.0, 2.0), **options) -> list:
    r"""The best certified members of the solution families of ``require`` for the unknowns of the
    design tableau ``tableau`` (a file, docs/design.md): ``tl.design``, ``tableau-lab design``.
    Each family with free parameters is searched (:func:`search`: a Sobol sample, Nelder–Mead,
    then an exact certificate; ``options``: samples, starts, seed, workers, scheduler, checkpoint)
    for ``maximize``/``minimize`` (:data:`OBJECTIVES`) under ``constraints``; returns one
    :class:`SearchResult` per family.  Reference: [BHHN14] Butcher, Habib, Hill & Norton, SIAM J.
    Numer. Anal. 52 (2014) for the P and N methods found below.

    >>> import tableau_lab as tl
    >>> [res] = tl.design("methods/design/pn_family.json", ["g-symplectic"], maximize="imaginary-interval",
    ...                   constraints=("order=4",), box=(-3.0, 3.0), seed=1, samples=32, starts=2)
    >>> sorted(c.certified.name.split(" at ")[1] for c in res.candidates if c.certified)    # P and N of [BHHN14]
    ['u = 1 + 2*sqrt(3)/3', 'u = 1 - 2*sqrt(3)/3']
    """
    fams = [f for f in families_of(tableau, list(require)) if f.free]
    if not fams:
        raise FamilyError(f"{tableau}: no family with free parameters for {', '.join(map(str, require))}")
    return [search(f, maximize=maximize, minimize=minimize, constraints=constraints, box=box, **options) for f in fams]


def search(family: Family, maximize=None, minimize=None, constraints=(), box=(-2.0, 2.0), samples: int = 256,
           starts: int = 8, seed: int = 0, certify: bool = True, scheduler=None, workers: int | None = 1,
           weights: int = 9, progress=None, checkpoint=None) -> SearchResult:
    """The best members of ``family`` under the constraints (see the module docstring): one objective,
    or a Pareto front of two.  ``maximize``/``minimize`` take a name or a tuple of names; the sample
    and the local searches run through :func:`executor.executor` (``scheduler``: None for a process
    pool of ``workers``, "serial", or a Dask address), with the same results everywhere.
    ``checkpoint``: a file that keeps the finished tasks, so that an interrupted search resumes."""
    from scipy.stats import qmc

    from .executor import executor
    names = _objectives(maximize, minimize)
    constraints = check_constraints(constraints)
    if not family.free:
        raise SearchError(f"{family.name}: no free parameters to search")
    lo, hi = box
    if not lo < hi:
        raise SearchError(f"the box {box} is empty")
    dim = len(family.free)
    pts = [tuple(float(v) for v in x) for x in
           qmc.scale(qmc.Sobol(dim, seed=seed).random(samples), [lo] * dim, [hi] * dim)]
    key = _key(family)
    p = _order_of(family, constraints) or _generic_order(family, key, pts)
    task = _Task(family, names, tuple(constraints), p, (float(lo), float(hi)), key=key)
    request = json.dumps([key, names,
                          list(constraints), [lo, hi], samples, starts, seed, weights, p])
    cp = _Checkpoint(checkpoint, hashlib.sha256(request.encode()).hexdigest(), len(names), dim)
    with executor(scheduler, workers, progress=progress) as ex:
        n = max(1, ex.workers)
        todo = [x for x in pts if not cp.has("sample", x)]
        chunks = [todo[i::n] for i in range(n) if todo[i::n]]
        ex.map(_evaluate, [(task, c) for c in chunks], desc="sample",
               on_result=lambda i, out: cp.put("sample", zip(chunks[i], out, strict=False)))
        found = dict(sorted((x, _tuples(cp.get("sample", x))) for x in pts if cp.get("sample", x) is not None))
        count = len(pts)
        if len(names) == 2:                 # scale each objective by its spread over the sample
            spread = [np.ptp([o[0][k] for o in found.values()]) or 1.0 for k in range(2)]
            task = _Task(family, names, tuple(constraints), p, task.box, tuple(spread), key)
        jobs = []
        per = starts if len(names) == 1 else max(1, starts // 4)
        for w in (np.linspace(0, 1, weights) if len(names) == 2 else [1.0]):
            ranked = sorted(found, key=lambda x: task.rank(found[x], w))[:per]
            # and the most nearly feasible points, so that feasible optima with a worse objective are found too
            feasible = sorted(found, key=lambda x: found[x][1])[:per] if constraints else []
            jobs += [(task, x, float(w)) for x in dict.fromkeys(ranked + feasible)]
        keys = [(x, w) for _, x, w in jobs]
        todo = [j for j, k in zip(jobs, keys, strict=False) if not cp.has("refine", k)]
        ex.map(_refine, todo, desc="local searches",
               on_result=lambda i, out: cp.put("refine", [((todo[i][1], todo[i][2]), out)]))
        refined = [_tuples(cp.get("refine", k)) for k in keys]
    optima = []
    for x, out, calls in refined:
        count += calls
        if out is None or any(np.allclose(x, o.point, atol=1e-6) for o in optima):
            continue
        optima.append(Candidate(x, dict(zip(names, out[0], strict=False)), out[1]))
    senses = [OBJECTIVES[o][0] for o in names]
    if len(names) == 2:                     # the front: feasible points no other feasible point dominates
        pool = [c for c in optima if c.violation <= FEASIBLE] + [
            Candidate(x, dict(zip(names, o[0], strict=False)), o[1]) for x, o in found.items() if o[1] <= FEASIBLE]
        optima = [c for c in pool if not any(_dominates(tuple(d.values.values()), tuple(c.values.values()), senses)
                                             for d in pool)]
        uniq = {}                           # one member per distinct pair of objective values
        for c in sorted(optima, key=lambda c: (-senses[0] * c.values[names[0]], c.point)):
            uniq.setdefault(tuple(float(f"{v:.9g}") for v in c.values.values()), c)
        optima = list(uniq.values())
        if len(optima) > FRONT_POINTS:      # thinned evenly along the front
            keep = np.unique(np.linspace(0, len(optima) - 1, FRONT_POINTS).round().astype(int))
            optima = [optima[i] for i in keep]
    else:
        optima.sort(key=lambda c: (c.violation > FEASIBLE, -senses[0] * c.values[names[0]]))
    for c in optima:
        c.box_bound = _box_bound(task, c)
    if certify:
        done = []
        for c in optima[:MAX_CERTIFIED]:
            if c.violation <= 1e-6:
                _certify(family, c, constraints, p, key, done, task.box)
                if c.certified is not None:
                    done.append(c)
        optima = _distinct(optima)
    return SearchResult(family.name, tuple(family.free), names, tuple(constraints), tuple(optima), count)


def _verify(m, constraints, p) -> dict | str:
    """The exact properties of a member, or why it fails a constraint."""
    from ..analysis.method_series import error_terms, method_series
    from ..analysis.order import order
    from ..analysis.parasitism import growth_parameters
    from ..analysis.stability import stability
    from ..exact.field import is_zero, normal_form
    out = {}
    if p > 1 or any(c.startswith("order") for c in constraints):
        o = order(m, max_order=p + 1)
        if any(c.startswith("order") for c in constraints) and o.order_identity_start < p:
            return f"order {o.order_identity_start} < {p} with the identity as principal starting component"
        out["order"] = o.order
        out["order with θ ≡ 0"] = o.order_identity_start
    if "explicit-first-stage" in constraints and not is_zero(m.as_glm().A[0, 0]):
        return "a11 ≠ 0"
    out["error norm"] = sp.sqrt(normal_form(sum(e ** 2 for e in error_terms(method_series(m, p + 1).phi, p + 1))))
    if m.kind == "glm":
        from ..analysis.symplectic import g_symplectic
        out["G-symplectic"] = g_symplectic(m).holds
        mus = [x.mu for x in growth_parameters(m).items]
        if "parasitism-free" in constraints and not all(is_zero(mu) for mu in mus):
            return "μ ≠ 0"
        out["mu"] = tuple(mus)
    st = stability(m)
    out["imaginary interval"] = st.bounded_radius
    return out


def _keeps(task, c: Candidate, point, share: float = 1.0) -> bool:
    """The member at ``point`` keeps the candidate's objective values within ``share`` of SNAP_TOLERANCE
    (relative) and its constraints (violation at most the candidate's, or FEASIBLE)."""
    out = task.values(tuple(point))
    return out is not None and out[1] <= max(FEASIBLE, c.violation) and all(
        abs(v - c.values[o]) <= share * SNAP_TOLERANCE * max(1.0, abs(c.values[o]))
        for o, v in zip(task.objectives, out[0], strict=False))


def _tolerance_interval(ok, x: float, lo: float, hi: float) -> tuple:
    """(a, b), lo ≤ a ≤ x ≤ b ≤ hi: how far the parameter goes from x each way with ``ok`` holding
    (steps growing fourfold from FIRST_STEP, then bisection of the last one to INTERVAL_PRECISION)."""
    ends = []
    for face in (lo, hi):
        good, step, bad = x, FIRST_STEP * max(1.0, abs(x)), None
        while good != face:
            t = x + step if face > x else x - step
            t = min(t, face) if face > x else max(t, face)
            if not ok(t):
                bad = t
                break
            good, step = t, 4 * step
        while bad is not None and abs(bad - good) > INTERVAL_PRECISION * max(abs(good - x), 1e-300):
            mid = (good + bad) / 2
            if mid in (good, bad):
                break
            good, bad = (mid, bad) if ok(mid) else (good, mid)
        ends.append(good)
    return tuple(ends)


def _box_bound(task, c: Candidate) -> tuple:
    """(parameter, face) for each face of the box that the optimum reaches within tolerance: the
    points from it to the face (FACE_PROBES of them, the face first) all keep its objective values
    and constraints (:func:`_keeps`) — so the search cannot tell that the optimum is not beyond."""
    out = []
    for i, s in enumerate(task.family.free):
        for face in task.box:
            def at(t, i=i):
                x = list(c.point)
                x[i] = t
                return x
            probes = [c.point[i] + (face - c.point[i]) * k / FACE_PROBES for k in range(FACE_PROBES, 0, -1)]
            if all(_keeps(task, c, at(t)) for t in probes):
                out.append((s, face))
    return tuple(out)


def _same(a: dict, b: dict) -> bool:
    """Two members' exact parameters are equal (exact zero test of each difference)."""
    from ..exact.field import is_zero
    return a.keys() == b.keys() and all(is_zero(sp.sympify(a[k]) - sp.sympify(b[k])) for k in a)


def _distinct(optima: list) -> list:
    """The candidates with each certified member once: a later one that certified to exactly the same
    member is dropped and counted in the first one's ``repeats``."""
    kept = []
    for c in optima:
        twin = c.certified is not None and next((d for d in kept if d.certified is not None
                                                 and _same(d.exact, c.exact)), None)
        if twin:
            twin.repeats += 1
        else:
            kept.append(c)
    return kept


def _snap(task, c: Candidate, box) -> dict | None:
    """The candidate's point as rationals of small height that keep its objectives within
    SNAP_TOLERANCE, or None when none of height ≤ SNAP_HEIGHT is found: the parameters are snapped in
    turn (every order for up to EXACT_FREE parameters, else two), and the snap of the smallest
    largest height (then sum of heights) is kept."""
    from itertools import permutations
    n = len(c.point)
    orders = list(permutations(range(n))) if n <= EXACT_FREE else [tuple(range(n)), tuple(reversed(range(n)))]
    snaps = [s for s in (_snap_in_order(task, c, box, o) for o in orders) if s is not None]
    if not snaps:
        return None
    best = min(snaps, key=lambda e: (max(map(height, e.values())), sum(map(height, e.values()))))
    return {str(s): best[str(s)] for s in task.family.free}


def _snap_in_order(task, c: Candidate, box, order) -> dict | None:
    """The parameters snapped in ``order``: the k-th of n may use k/n of the tolerance, and takes the
    rational of smallest height (ties: nearest) that keeps it, from the interval around its value
    where that holds (:func:`_tolerance_interval`, within ``box``); SNAP_ATTEMPTS tries each."""
    x = list(c.point)
    exact = {}
    n = len(x)
    for k, i in enumerate(order):
        share = (k + 1) / n

        def ok(t, i=i, share=share):
            y = list(x)
            y[i] = float(t)
            return _keeps(task, c, y, share)
        a, b = _tolerance_interval(ok, x[i], max(box[0], -1e300), min(box[1], 1e300))
        for j, r in enumerate(by_height(Fraction(a), Fraction(b), near=x[i])):
            if j >= SNAP_ATTEMPTS or height(r) > SNAP_HEIGHT:
                return None
            if ok(r):
                x[i], exact[str(task.family.free[i])] = float(r), sp.Rational(r.numerator, r.denominator)
                break
        else:
            return None
    return exact


def _certify(family: Family, c: Candidate, constraints, p, key: str, done=(), box=(-np.inf, np.inf)):
    """Certify ``c`` (see the module docstring); a snap equal to the member of an already certified
    candidate in ``done`` takes its verified claims without computing them again."""
    names = [str(s) for s in family.free]
    task = _Task(family, tuple(c.values), tuple(constraints), p, (-np.inf, np.inf), key=key)
    exact = _snap(task, c, box)
    if exact is not None:
        twin = next((d for d in done if _same(d.exact, exact)), None)
        if twin is not None:
            c.certified, c.exact, c.verified = twin.certified, exact, twin.verified
            return
        try:
            m = family.member(exact)
        except FamilyError:
            m = None
        ver = None if m is None else _verify(m, constraints, p)
        if isinstance(ver, dict):
            c.certified, c.exact, c.verified = m, exact, ver
            return
    if not constraints:
        c.note = (f"no rational of height ≤ {SNAP_HEIGHT} keeps the objective within {SNAP_TOLERANCE:g} "
                  "(the optimum may be where an exact condition holds: require it with --constrain)")
        return
    if len(family.free) > EXACT_FREE:
        if _certify_partial(family, c, constraints, p, key):
            return
        c.note = (f"the constraints are equations on {len(family.free)} free parameters; the exact solve is "
                  f"attempted for at most EXACT_FREE = {EXACT_FREE}, and no partial snap (rationals for the "
                  "parameters the constraints leave free, the rest solved exactly) was certified")
        return
    # the constraints are equations the rationals cannot meet: solve them exactly on the family
    try:
        best = _nearest_solution(family.method, constraints, names, c.point)
    except (ValueError, FamilyError) as exc:
        c.note = f"the constraints could not be solved exactly on the family: {exc}"
        return
    if best is None:
        c.note = f"no exact member meets {', '.join(constraints)} near the optimum"
        return
    twin = next((d for d in done if _same(d.exact, best)), None)
    if twin is not None:
        c.certified, c.exact, c.verified = twin.certified, best, twin.verified
        return
    m = family.member(best)
    ver = _verify(m, constraints, p)
    if isinstance(ver, str):
        c.note = ver
        return
    c.certified, c.exact, c.verified = m, best, ver


def _requirements(method, constraints) -> list:
    """The exact requirements of ``design.solve`` that the numeric constraints stand for."""
    from ..analysis.design import Requirement
    out = []
    for k in constraints:
        if k.startswith("order=") and method.kind == "glm":       # numerically: the order with θ ≡ 0
            out.append(k.replace("order=", "identity-start-order="))
        elif k == "explicit-first-stage":
            out.append(Requirement("equation", (method.as_glm().A[0, 0], sp.S.Zero), "a11 = 0"))
        else:
            out.append(k)
    return out


def _nearest_solution(method, constraints, names, point) -> dict | None:
    """The real exact solution of the constraints for the unknowns ``names`` of ``method`` nearest to
    ``point`` (name → exact value), or None."""
    from ..analysis.design import solve
    res = solve(method, _requirements(method, constraints))
    best, dist = None, np.inf
    for sol in res.solutions:
        if not sol.real or sol.free or sol.method is None:
            continue
        vals = {str(k): v for k, v in sol.parameters.items()}
        try:
            pt = [complex(sp.N(vals[n], 30)) for n in names]
        except (KeyError, TypeError):
            continue
        d = float(np.linalg.norm(np.array([z.real for z in pt]) - np.array(point)))
        if d < dist:
            best, dist = {n: vals[n] for n in names}, d
    return best


def _jacobian(task, x0, size: int) -> np.ndarray:
    """The constraint residuals' Jacobian at x0 by forward differences."""
    x0 = np.asarray(x0, dtype=float)
    r0 = task.residuals(tuple(x0), size)
    cols = []
    for i in range(len(x0)):
        step = 1e-7 * max(1.0, abs(x0[i]))
        x = x0.copy()
        x[i] += step
        cols.append((task.residuals(tuple(x), size) - r0) / step)
    return np.array(cols).T


def _independent(J) -> tuple:
    """(U, σ₁): the leading left singular vectors of J (those above RANK_TOLERANCE·σ₁), the independent
    combinations of redundant residuals (the order conditions of a family are many equations of low
    rank), and J's largest singular value."""
    if J.size == 0:
        return np.zeros((J.shape[0], 0)), 0.0
    Uf, sv, _ = np.linalg.svd(J, full_matrices=False)
    k = int(np.sum(sv > RANK_TOLERANCE * sv[0])) if sv[0] > 0 else 0
    return Uf[:, :k], float(sv[0])


def _determined(task, point, prefer_snapped=()) -> list:
    """Choices of the parameters (indices) the constraints determine near ``point``, best first: as many
    as the rank of the constraint Jacobian (finite differences), each choice with a well-conditioned
    square block of it.  Choices that leave the ``prefer_snapped`` parameters (those in the family's
    denominators: solving for them makes the exact system rational, much harder) to the snap come
    first, then by the block's smallest singular value."""
    from itertools import combinations
    x0 = np.array(point, dtype=float)
    J = _jacobian(task, x0, len(task._residuals(task.at(tuple(x0)))))
    U, top = _independent(J)                       # the constraints' k independent directions
    k = U.shape[1]
    if not 0 < k < len(x0):
        return []
    choices = []
    for sub in combinations(range(len(x0)), k):
        smallest = np.linalg.svd(U.T @ J[:, sub], compute_uv=False)[-1]
        if smallest > RANK_TOLERANCE * top:
            choices.append((sum(i in prefer_snapped for i in sub), -smallest, list(sub)))
    return [c for _, _, c in sorted(choices)]


def _certify_partial(family: Family, c: Candidate, constraints, p, key: str) -> bool:
    """Snap the parameters the constraints leave free to small rationals, solve the constraints
    exactly for the others (``design.solve`` on the partly snapped tableau: few unknowns, seconds),
    and verify the member.  The numeric member after the snap (the determined parameters re-solved
    by least squares) must keep the objectives within PARTIAL_TOLERANCE before an exact solve is tried."""
    from dataclasses import replace as dc_replace

    from scipy.optimize import least_squares
    names = [str(s) for s in family.free]
    task = _Task(family, tuple(c.values), tuple(constraints), p, (-np.inf, np.inf), key=key)
    in_denominators = {str(v) for cond in family.conditions for v in sp.sympify(cond).free_symbols}
    choices = _determined(task, c.point, [i for i, n in enumerate(names) if n in in_denominators])
    if not choices:
        return False
    solved = choices[0]
    snapped = [i for i in range(len(names)) if i not in solved]
    size = len(task._residuals(task.at(c.point)))
    tried, seen = 0, set()
    for den in DENOMINATORS:
        fixed = {i: sp.Rational(Fraction(c.point[i]).limit_denominator(den)) for i in snapped}
        if tuple(fixed.values()) in seen:
            continue
        seen.add(tuple(fixed.values()))

        def full(z, fixed=fixed):
            x = list(c.point)
            for i, v in fixed.items():
                x[i] = float(v)
            for i, v in zip(solved, z, strict=False):
                x[i] = v
            return tuple(x)
        fit = least_squares(lambda z: task.residuals(full(z), size), [c.point[i] for i in solved], xtol=1e-15,
                            ftol=1e-15, gtol=1e-15, max_nfev=200 * len(solved))
        out = task.values(full(fit.x))
        if out is None or out[1] > FEASIBLE or not all(
                abs(v - c.values[o]) <= PARTIAL_TOLERANCE * max(1.0, abs(c.values[o]))
                for o, v in zip(task.objectives, out[0], strict=False)):
            continue
        tried += 1
        sub = {family.free[i]: v for i, v in fixed.items()}
        m = family.method
        partial = dc_replace(m, **{k: M.applyfunc(lambda e, sub=sub: sp.cancel(e.xreplace(sub)))
                                   for k, M in m.matrices().items() if isinstance(M, sp.MatrixBase)})
        try:
            best = _nearest_solution(partial, constraints, [names[i] for i in solved],
                                     [fit.x[k] for k in range(len(solved))])
        except (ValueError, FamilyError):
            best = None
        if best is not None:
            exact = {**{names[i]: v for i, v in fixed.items()}, **best}
            try:
                member = family.member(exact)
            except FamilyError:
                member = None
            ver = None if member is None else _verify(member, constraints, p)
            if isinstance(ver, dict):
                c.certified, c.exact, c.verified = member, {n: exact[n] for n in names}, ver
                c.note = (f"{', '.join(names[i] for i in snapped)} snapped to rationals, "
                          f"{', '.join(names[i] for i in solved)} solved exactly")
                return True
        if tried >= PARTIAL_ATTEMPTS:
            break
    return False
