r"""Design search: the best member of an exact solution family, found numerically and certified
exactly (issue 18).

1. The family (:mod:`..analysis.family`) is evaluated in float64 at any point of its free
   parameters (one ``lambdify`` of its matrices); the objectives and constraints are those of
   :mod:`..numeric.objectives`.
2. A Sobol sample of the box (scipy.stats.qmc) ranks the starting points; Nelder–Mead refines the
   best of them on the penalised score (constraint violations weigh ``PENALTY``); distinct local
   optima are kept.
3. **Certify**: the optimum is snapped to exact values — rationals of growing height first, then,
   when the constraints are equations the rationals cannot meet (an order, μ = 0), the family is
   solved again with those constraints as exact requirements and the nearest real solution is
   taken — and the member is re-verified by the ordinary analyses (order, G-symplecticity, μ,
   the exact stability interval).  A member that cannot be certified is reported as such.

>>> from tableau_lab.analysis.family import families_of
>>> fam = families_of("methods/design/pn_family.json", ["g-symplectic"])[0]
>>> res = search(fam, maximize="imaginary-interval", constraints=("order=4",), box=(-3.0, 3.0), seed=1)
>>> [c.certified.name.split(" at ")[1] for c in res.candidates if c.certified]      # P and N
['u = 1 + 2*sqrt(3)/3', 'u = 1 - 2*sqrt(3)/3']
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np
import sympy as sp

from ..analysis.family import Family, FamilyError
from ..analysis.results import Result
from ..exact.grammar import format_entry
from ..numeric.objectives import YMAX, NumericGLM, growth, imaginary_interval, real_interval, series_defects

__all__ = ["search", "SearchResult", "Candidate", "OBJECTIVES", "CONSTRAINTS", "PENALTY", "SearchError"]

PENALTY = 1e3            # weight of a constraint violation in the score
FEASIBLE = 1e-9          # a numeric constraint holds below this
DENOMINATORS = (1, 2, 4, 10, 100, 1000, 10 ** 4, 10 ** 6)      # rational snapping, smallest height first


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
#: constraint name -> violation(g, p) (0 when it holds)
CONSTRAINTS = {
    "parasitism-free": lambda g, p: max((abs(m) for m in growth(g)), default=0.0),
    "order": lambda g, p: series_defects(g, p)[0],
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


@dataclass(frozen=True)
class SearchResult(Result):
    family: str
    free: tuple
    objective: str
    constraints: tuple
    candidates: tuple
    evaluations: int

    def __str__(self):
        lines = [f"{self.family}: {'maximise' if OBJECTIVES[self.objective][0] > 0 else 'minimise'} "
                 f"{self.objective} over {', '.join(map(str, self.free))}"
                 + (f" subject to {', '.join(self.constraints)}" if self.constraints else "")
                 + f" ({self.evaluations} evaluations)"]
        for i, c in enumerate(self.candidates, 1):
            pt = ", ".join(f"{s} = {v:.10g}" for s, v in zip(self.free, c.point))
            vals = ", ".join(f"{k} {'≥' if k.endswith('interval') and v >= YMAX else '='} {v:.6g}"
                             for k, v in c.values.items())
            lines.append(f"  {i}. {pt}: {vals}; violation {c.violation:.1e}")
            if c.certified is not None:
                lines.append("     certified: " + ", ".join(f"{k} = {format_entry(v)}" for k, v in c.exact.items()))
                lines += [f"       {k}: {_show(v)}" for k, v in c.verified.items()]
            elif c.note:
                lines.append(f"     not certified: {c.note}")
        return "\n".join(lines)

    def to_json(self):
        return {"family": self.family, "free": [str(s) for s in self.free], "objective": self.objective,
                "constraints": list(self.constraints), "evaluations": self.evaluations,
                "candidates": [{"point": list(c.point), "values": c.values, "violation": c.violation,
                                "certified": c.certified is not None,
                                "exact": {k: str(format_entry(v)) for k, v in c.exact.items()},
                                "verified": {k: str(v) for k, v in c.verified.items()}, "note": c.note}
                               for c in self.candidates]}

    def to_latex(self):
        return r"\text{" + self.family.replace("_", r"\_") + ": " + str(len(self.candidates)) + " candidates}"


def _show(v) -> str:
    """An exact value, with its decimal value when it is not rational."""
    if isinstance(v, tuple):
        return ", ".join(_show(x) for x in v) or "none"
    v = sp.sympify(v)
    if v.is_Rational or v in (sp.oo, -sp.oo) or not v.is_number:
        return str(v)
    return f"{v} ≈ {complex(sp.N(v, 15)).real:.10g}" if sp.N(v).is_real else str(v)


def _evaluator(family: Family):
    """point -> NumericGLM (None where the member is not a method, e.g. a singular I − zA)."""
    g = family.method.as_glm()
    syms = list(family.free)
    fns = [sp.lambdify(syms, M, "numpy") for M in (g.A, g.U, g.B, g.V)]

    def at(point):
        try:
            mats = [np.array(f(*point), dtype=float) for f in fns]
        except (ZeroDivisionError, FloatingPointError, ValueError):
            return None
        if not all(np.all(np.isfinite(M)) for M in mats):
            return None
        return NumericGLM(*mats)
    return at


def _score(g, objective, constraints, p):
    sense, value = OBJECTIVES[objective]
    with np.errstate(all="ignore"):
        try:
            v = value(g, p)
            viol = sum(CONSTRAINTS[c.split("=")[0]](g, p) for c in constraints)
        except (np.linalg.LinAlgError, ValueError, ZeroDivisionError):
            return None
    if not np.isfinite(v) or not np.isfinite(viol):
        return None
    return -sense * v + PENALTY * viol, v, viol


def search(family: Family, maximize: str | None = None, minimize: str | None = None, constraints=(),
           box=(-2.0, 2.0), samples: int = 256, starts: int = 8, seed: int = 0, certify: bool = True) -> SearchResult:
    """The best members of ``family`` for one objective under the constraints (see the module docstring)."""
    from scipy.optimize import minimize as nelder_mead
    from scipy.stats import qmc

    objective = maximize or minimize
    if objective not in OBJECTIVES or (maximize and minimize):
        raise SearchError(f"one objective, from {', '.join(OBJECTIVES)}; got {maximize or minimize!r}")
    if (maximize and OBJECTIVES[objective][0] < 0) or (minimize and OBJECTIVES[objective][0] > 0):
        raise SearchError(f"{objective} is {'minimised' if OBJECTIVES[objective][0] < 0 else 'maximised'}, not the other way")
    for c in constraints:
        if c.split("=")[0] not in CONSTRAINTS:
            raise SearchError(f"unknown constraint {c!r}: use {', '.join(CONSTRAINTS)}=P")
    if not family.free:
        raise SearchError(f"{family.name}: no free parameters to search")
    lo, hi = box
    if not lo < hi:
        raise SearchError(f"the box {box} is empty")
    p = _order_of(family, constraints) or 1
    at = _evaluator(family)
    dim = len(family.free)
    count = [0]

    def score(x):
        count[0] += 1
        g = at(x)
        out = None if g is None else _score(g, objective, constraints, p)
        return (np.inf, None, None) if out is None else out

    sampler = qmc.Sobol(dim, seed=seed)
    pts = qmc.scale(sampler.random(samples), [lo] * dim, [hi] * dim)
    scored = [(score(x), tuple(x)) for x in pts]
    by_score = sorted(scored, key=lambda t: t[0][0])[:starts]
    # and the most nearly feasible points, so that feasible optima with a worse objective are found too
    by_violation = sorted((t for t in scored if t[0][2] is not None), key=lambda t: t[0][2])[:starts]
    optima = []
    for (s0, _, _), x0 in by_score + by_violation:
        if not np.isfinite(s0):
            continue
        res = nelder_mead(lambda x: score(x)[0], np.array(x0), method="Nelder-Mead", bounds=[(lo, hi)] * dim,
                          options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 2000})
        x = tuple(float(v) for v in res.x)
        sc, v, viol = score(x)
        if v is None or any(np.allclose(x, o.point, atol=1e-6) for o in optima):
            continue
        optima.append(Candidate(x, {objective: float(v)}, float(viol)))
    optima.sort(key=lambda c: (c.violation > FEASIBLE, -OBJECTIVES[objective][0] * c.values[objective]))
    if certify:
        for c in optima:
            if c.violation <= 1e-6:
                _certify(family, c, constraints, p)
    return SearchResult(family.name, tuple(family.free), objective, tuple(constraints), tuple(optima), count[0])


def _verify(m, constraints, p) -> dict | str:
    """The exact properties of a member, or why it fails a constraint."""
    from ..analysis.order import order
    from ..analysis.parasitism import growth_parameters
    from ..analysis.stability import stability
    out = {}
    if p > 1 or any(c.startswith("order") for c in constraints):
        o = order(m, max_order=p + 1).order
        if o < p:
            return f"order {o} < {p}"
        out["order"] = o
    if m.kind == "glm":
        mus = [x.mu for x in growth_parameters(m).items]
        if "parasitism-free" in constraints and any(sp.simplify(mu) != 0 for mu in mus):
            return "μ ≠ 0"
        out["mu"] = tuple(mus)
    st = stability(m)
    out["imaginary interval"] = st.bounded_radius
    return out


def _certify(family: Family, c: Candidate, constraints, p):
    names = [str(s) for s in family.free]
    for den in DENOMINATORS:
        exact = {n: sp.Rational(Fraction(v).limit_denominator(den)) for n, v in zip(names, c.point)}
        try:
            m = family.member(exact)
        except FamilyError:
            continue
        ver = _verify(m, constraints, p)
        if isinstance(ver, dict):
            c.certified, c.exact, c.verified = m, exact, ver
            return
    if not constraints:
        c.note = "no rational member near the optimum is a method of the family (a branch condition vanishes there?)"
        return
    # the constraints are equations the rationals cannot meet: solve them exactly on the family
    from ..analysis.design import solve
    reqs = [x for x in constraints]
    try:
        res = solve(family.method, reqs)
    except (ValueError, FamilyError) as exc:
        c.note = f"the constraints could not be solved exactly on the family: {exc}"
        return
    best, dist = None, np.inf
    for sol in res.solutions:
        if not sol.real or sol.free or sol.method is None:
            continue
        vals = {str(k): v for k, v in sol.parameters.items()}
        try:
            pt = [complex(sp.N(vals[n], 30)) for n in names]
        except (KeyError, TypeError):
            continue
        d = float(np.linalg.norm(np.array([z.real for z in pt]) - np.array(c.point)))
        if d < dist:
            best, dist = {n: vals[n] for n in names}, d
    if best is None:
        c.note = f"no exact member meets {', '.join(constraints)} near the optimum"
        return
    m = family.member(best)
    ver = _verify(m, constraints, p)
    if isinstance(ver, str):
        c.note = ver
        return
    c.certified, c.exact, c.verified = m, best, ver

