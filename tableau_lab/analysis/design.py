r"""Method design: the free parameters of a tableau solved for required properties.

A tableau may hold named unknowns anywhere (``"b2"``, ``"-u22"``, ``"(1-b2)/2"``).  Each
requirement becomes polynomial equations in them (numerators of exact rational functions
over the tableau's number field):

* ``order=P``: RK: Φ(t) = 1/γ(t) for |t| ≤ P (elementary weights); partitioned RK: the
  bicoloured-tree conditions; GLM: the order conditions relative to the best starting method
  (θ eliminated order by order, see :mod:`glm_order`);
* ``identity-start-order=P`` (GLM): the same with θ ≡ 0, i.e. the identity as first starting
  component ([B16] Sec. 53; for RK methods it is ``order=P``);
* ``effective-order=P`` (RK): the GLM conditions with r = 1 (a free starting method);
* ``stage-order=Q`` (RK): C(Q), Σⱼ aᵢⱼcⱼ^{k−1} = cᵢ^k/k;
* ``symplectic`` (RK, PRK): diag(b)A + Aᵀdiag(b) − bbᵀ = 0 ([HLW06] VI.4);
* ``g-symplectic``: VᵀGV = G, DU = BᵀGV, DA + AᵀD = BᵀGB with the entries of G and D as
  further unknowns, det(G)·z = 1 (Rabinowitsch: G nonsingular), and the scale fixed by a
  complete case split on the first nonzero entry of G (set to 1, those before it to 0);
* ``parasitism-free``: Re μ = Im μ = 0 for every parasitic growth parameter ([BHHN14]);
* ``symmetric``: RK: aᵢⱼ + a_{s+1−i,s+1−j} = bⱼ, bᵢ = b_{s+1−i} ([HLW06] V.2); GLM: the adjoint
  equals the method up to stage reversal and a diagonal sign involution L of the inputs
  (:mod:`symmetry`; one branch per L, V numeric);
* user equations ``LHS = RHS`` in the safe entry grammar;
* always, unless an order is required: consistency (the order-1 conditions, e.g. Σbᵢ = 1),
  without which a "method" approximates nothing.

The system is split into components and parametrised by :mod:`exact.polysystem` (Gröbner
bases, factor splitting, back-substitution in radicals).  Every solution is then rebuilt as a
method and **re-verified** through the ordinary analyses (``rk_symplectic``, ``g_symplectic``,
``order``, ``growth_parameters``); one that fails is never returned.  A solution with free
parameters left is verified generically (over the field of rational functions in them) and
holds wherever its branch conditions (listed) do not vanish.

>>> from tableau_lab.exact.tableau_json import loads
>>> res = solve_text('{"name": "2-stage", "kind": "rk", "A": [["a11", "a12"], ["a21", "a22"]],'
...                  ' "b": ["b1", "b2"]}', ["order=4"])
>>> res.status, len(res.solutions)
('solved', 2)
>>> sorted(str(s.parameters["a12"]) for s in res.solutions)
['1/4 + sqrt(3)/6', '1/4 - sqrt(3)/6']
"""
from __future__ import annotations

import re
import time
from dataclasses import dataclass, field
from typing import Any

import sympy as sp

from ..errors import InputError
from ..exact.field import is_zero, normal_form, power
from ..exact.grammar import EntryError, format_entry, parse_entry
from ..exact.methods import GeneralLinearMethod, Method, MethodError, PartitionedRungeKutta, RungeKutta, glm_parts
from ..exact.polysystem import PolynomialSystem, SystemError_
from ..exact.tableau_json import entries, from_dict, parse, read, to_dict
from ..render.model import Block, Break, Document, Lead, Math, Paragraph, Plain, Typeset
from .results import Result
from .trees import bracket, density, order as tree_order, trees_up_to

__all__ = ["solve", "solve_file", "solve_text", "method_from_design", "parse_requirements", "Requirement",
           "DesignResult", "Solution", "DesignError"]

CLASSICAL_ORDERS = ("order", "identity-start-order")      # imply consistency (the order-1 conditions)
ORDER_KEYWORDS = CLASSICAL_ORDERS + ("effective-order", "stage-order")     # take a value =P
KEYWORDS = ("g-symplectic", "symplectic") + ORDER_KEYWORDS + ("parasitism-free", "symmetric")


class DesignError(InputError):
    """A requirement that cannot be posed for this tableau (message says why)."""


@dataclass(frozen=True)
class Requirement:
    name: str                 # one of KEYWORDS or "equation"
    value: object = None      # P for order, Q for stage-order, (lhs, rhs) for an equation
    text: str = ""

    def __str__(self):
        return self.text or self.name


def parse_requirements(items) -> tuple[Requirement, ...]:
    """``["g-symplectic", "order=4", "a11 = b1/2"]`` (items may also be comma-separated)."""
    out = []
    for item in items:
        if isinstance(item, Requirement):
            out.append(item)
            continue
        for part in (p.strip() for p in str(item).split(",")):
            if not part:
                continue
            key, _, val = part.partition("=")
            key = key.strip().lower()
            if key in ORDER_KEYWORDS:
                try:
                    if not val.strip().isascii():         # int() would read other scripts' digits
                        raise ValueError(val)
                    n = int(val)
                except ValueError:
                    raise DesignError(f"requirement {part!r}: {key} needs a positive integer, e.g. {key}=4") from None
                if not 1 <= n <= 12:
                    raise DesignError(f"requirement {part!r}: {key} must be between 1 and 12")
                out.append(Requirement(key, n, f"{key}={n}"))
            elif key in KEYWORDS and not val:
                out.append(Requirement(key, None, key))
            elif "=" in part:
                lhs, rhs = part.split("=", 1)
                try:
                    out.append(Requirement("equation", (parse_entry(lhs.strip()), parse_entry(rhs.strip())), part))
                except EntryError as exc:
                    raise DesignError(f"equation {part!r}: {exc}") from None
            else:
                raise DesignError(f"unknown requirement {part!r}: use {', '.join(KEYWORDS)} "
                                  "(order=P, stage-order=Q) or an equation LHS = RHS")
    if not out:
        raise DesignError("no requirement given")
    return tuple(out)


@dataclass(frozen=True)
class Solution:
    label: str
    parameters: dict          # unknown's name -> exact value (in the free ones)
    free: tuple
    conditions: tuple         # expressions that must not vanish
    auxiliary: dict           # "G", "D" -> exact matrices (g-symplectic)
    method: Method | None
    verified: dict            # requirement text -> bool (re-verified by the analyses)
    real: bool = True
    implicit: dict = field(default_factory=dict)

    def to_json(self):
        def text(x):                             # sympy's form for complex values (no grammar form)
            return str(x) if sp.sympify(x).has(sp.I) else str(format_entry(x))

        out = {"label": self.label,
               "parameters": {k: text(v) for k, v in self.parameters.items()},
               "free": [str(x) for x in self.free],
               "conditions": [f"{text(c)} != 0" for c in self.conditions],
               "real": self.real, "verified": dict(self.verified),
               "method": None if self.method is None else to_dict(self.method)}
        if self.auxiliary:
            out["auxiliary"] = {k: [[text(x) for x in M.row(i)] for i in range(M.rows)]
                                for k, M in self.auxiliary.items()}
        if self.implicit:
            out["implicit"] = {str(k): f"root of {v}" for k, v in self.implicit.items()}
        return out


@dataclass(frozen=True)
class DesignResult(Result):
    name: str
    requirements: tuple
    unknowns: tuple
    status: str                # "solved" | "no solution" | "no real solution" | "not in radicals"
    solutions: tuple
    obstruction: tuple = ()    # ((label, equation), ...): a minimal inconsistent subset
    rejected: tuple = ()       # solutions found but not verified, or complex, or implicit
    equations: int = 0
    seconds: float = 0.0

    def _text(self) -> str:
        req = ", ".join(map(str, self.requirements))
        lines = [f"{self.name}: solve for {', '.join(map(str, self.unknowns))} with {req}",
                 f"status: {self.status} ({self.equations} equations, {self.seconds:.2f} s)"]
        for i, sol in enumerate(self.solutions, 1):
            free = f"; free: {', '.join(map(str, sol.free))}" if sol.free else ""
            lines.append(f"solution {i}: {sol.label}{free}")
            lines += [f"    {k} = {format_entry(v)}" for k, v in sol.parameters.items()]
            for k, M in sol.auxiliary.items():
                lines.append(f"    {k} = {_inline(M)}")
            lines += [f"    provided {format_entry(c)} ≠ 0" for c in sol.conditions]
            verdicts = ", ".join(f"{k} {'yes' if v else 'NO'}" for k, v in sol.verified.items())
            lines.append("    re-verified: " + verdicts)
        if self.obstruction:
            lines.append("obstruction (a minimal inconsistent set of the equations):")
            lines += [f"    {lab}: {format_entry(e)} = 0" for lab, e in self.obstruction]
        for sol in self.rejected:
            why = "complex" if not sol.real else ("not in radicals" if sol.implicit else "failed re-verification")
            lines.append(f"not returned ({why}): {sol.label}: "
                         + ", ".join(f"{k} = {v}" for k, v in list(sol.parameters.items())[:6]))
        return "\n".join(lines)

    def to_json(self):
        return {"status": self.status, "requirements": [str(r) for r in self.requirements],
                "unknowns": [str(u) for u in self.unknowns], "equations": self.equations,
                "solutions": [s.to_json() for s in self.solutions],
                "obstruction": [{"condition": lab, "equation": f"{format_entry(e)} = 0"}
                                for lab, e in self.obstruction],
                "rejected": [s.to_json() for s in self.rejected], "seconds": round(self.seconds, 3)}

    def display(self) -> Document:
        """Text: the system, status, solutions and obstruction; typeset: the requirements, the status
        and each solution's values."""
        head, *lines = self._text().split("\n")
        out: list[Block] = [Paragraph(Lead(self.name), f" Requirements: {', '.join(map(str, self.requirements))}; "
                         f"status: {self.status}.")]
        for i, sol in enumerate(self.solutions, 1):
            eqs = ", ".join(f"{sp.latex(k)} = {sp.latex(v)}" for k, v in sol.parameters.items())
            out += [Break(), Paragraph(f"Solution {i} ({sol.label}): ", Math(eqs), ".")]
        return Document(head, (Plain(*(Paragraph(x) for x in lines)), Typeset(*out)))


def _inline(M):
    return "[" + "; ".join(", ".join(str(format_entry(x)) for x in M.row(i)) for i in range(M.rows)) + "]"


# ------------------------------------------------------------------ equations

def _unknown_order(m: Method, extra=()) -> list:
    """Unknowns in lex order, largest first: the ``extra`` ones (abscissae to eliminate), then
    the tableau's in reading order (A row by row, U, B, V, b, ...), so that the last entries
    read are the ones left free in a family."""
    seen = []
    for M in m.matrices().values():
        if M is None:
            continue
        for x in M:
            for s in sorted(sp.sympify(x).free_symbols, key=lambda s: s.name):
                if s not in seen:
                    seen.append(s)
    return [s for s in extra if s not in seen] + seen


def _rk_weights(A, b, n, F, const):
    """Φ(t) − 1/γ(t) for |t| ≤ n over the fraction field F (elementary weights)."""
    from .rk_order import elementary_weights
    phi = elementary_weights(A, b, F.zero, F.one)
    return [(f"order {tree_order(t)}, tree {bracket(t)}", phi(t) - const(sp.Rational(1, density(t))))
            for t in trees_up_to(n)]


def _symplectic_rk(A, b, F, hat=None):
    s = len(b)
    bh, Ah = (b, A) if hat is None else hat
    out = []
    for i in range(s):
        for j in range(i if hat is None else 0, s):
            out.append((f"symplectic M[{i + 1},{j + 1}]", b[i] * Ah[i][j] + bh[j] * A[j][i] - b[i] * bh[j]))
    return out


class _Problem:
    """The tableau as elements of K(unknowns) and the labelled equations of the requirements."""

    def __init__(self, m: Method, reqs, extra_eqs=(), extra_unknowns=()):
        self.m, self.reqs = m, reqs
        self.params = _unknown_order(m, extra_unknowns)
        self.aux: list = []
        self.branches: list[list[tuple[str, Any]]] = [[]]   # the extra equations of each branch (symmetric: one per L)
        consts = [x for M in m.matrices().values() if M is not None for x in M]
        consts += [s for _, s in extra_eqs]
        for r in reqs:
            if r.name == "equation":
                stray = sorted(str(x) for x in (r.value[0] - r.value[1]).free_symbols if x not in self.params)
                if stray:
                    import difflib
                    hint = difflib.get_close_matches(stray[0].replace("_", "-"), KEYWORDS, n=1)
                    raise DesignError(f"equation {r.text!r} names {', '.join(stray)}, not an unknown of the tableau "
                                      f"(unknowns: {', '.join(map(str, self.params)) or 'none'})"
                                      + (f"; did you mean the condition {hint[0]!r}?" if hint else ""))
                consts += list(r.value)
        if any(r.name == "g-symplectic" for r in reqs):
            self._g_unknowns()
        try:
            self.sys = PolynomialSystem(self.aux + self.params, _radicals(consts))
        except SystemError_ as exc:
            raise DesignError(str(exc)) from None
        self.labelled = [(lab, self.sys.frac(e)) for lab, e in extra_eqs]
        if not any(r.name in CLASSICAL_ORDERS for r in reqs):     # a method must at least be consistent
            self.labelled += [(f"consistency ({lab})", e) for lab, e in self._order(1)]
        for r in reqs:
            self.labelled += self._equations(r)

    # unknowns for G (symmetric) and D (diagonal), det inverse z
    def _glm(self):
        """(A, U, B, V), unvalidated: unknowns may break consistency until they are solved for."""
        try:
            return glm_parts(self.m)
        except ValueError:
            raise DesignError("g-symplectic applies to RK methods and GLMs; for a partitioned RK method "
                              "use symplectic") from None

    def _g_unknowns(self):
        A, U, B, V = self._glm()
        r, s = V.rows, A.rows
        self.G = sp.Matrix(r, r, lambda i, j: sp.Symbol(f"G{min(i, j) + 1}{max(i, j) + 1}", real=True))
        self.D = sp.diag(*[sp.Symbol(f"D{i + 1}", real=True) for i in range(s)])
        self.z = sp.Symbol("z_det", real=True)
        gs = [self.G[i, j] for i in range(r) for j in range(i, r)]
        self.aux = [self.z] + gs + [self.D[i, i] for i in range(s)]
        # first nonzero entry of G (in reading order) is 1, those before it are 0
        self.branches = [[(f"normalisation {gs[k]} = 1", gs[k] - 1)] + [(f"normalisation {x} = 0", x) for x in gs[:k]]
                           for k in range(len(gs))]

    def _mat(self, M):
        return [[self.sys.frac(x) for x in M.row(i)] for i in range(M.rows)]

    def _vec(self, v):
        return [self.sys.frac(x) for x in v]

    def _equations(self, r):
        """The labelled equations of the requirement ``r`` (one builder per requirement name)."""
        build = self._BUILDERS.get(r.name)
        if build is None:
            raise DesignError(f"requirement {r} is not implemented")  # pragma: no cover
        return build(self, r)

    def _equation(self, r):
        return [(f"equation {r.text}", self.sys.frac(r.value[0] - r.value[1]))]

    def _symplectic(self, r):
        m, F = self.m, self.sys.F
        if isinstance(m, RungeKutta):
            return _symplectic_rk(self._mat(m.A), self._vec(m.b), F)
        if isinstance(m, PartitionedRungeKutta):
            A, b, Ah, bh = self._mat(m.A), self._vec(m.b), self._mat(m.Ahat), self._vec(m.bhat)
            return (_symplectic_rk(A, b, F, hat=(bh, Ah))
                    + [(f"b = bhat, stage {i + 1}", x - y) for i, (x, y) in enumerate(zip(b, bh, strict=False))])
        raise DesignError("symplectic applies to RK and partitioned RK methods; for a GLM use g-symplectic")

    def _symmetric(self, r):
        m = self.m
        if isinstance(m, PartitionedRungeKutta):
            raise DesignError("symmetric is implemented for RK methods and GLMs, not partitioned methods")
        from .symmetry import symmetry_conditions
        try:
            cands = symmetry_conditions(m)
        except ValueError as exc:
            raise DesignError(f"symmetric: {exc}") from None
        if len(cands) == 1:                    # RK (r = 1): L = 1, plain equations
            return [(f"symmetric, condition {k + 1}", self.sys.frac(e)) for k, e in enumerate(cands[0][1]) if e != 0]
        # one branch per involution L: the union of their solutions
        self.branches = [gb + [(f"symmetric, L = diag({', '.join(str(L[i, i]) for i in range(L.rows))}),"
                                f" condition {k + 1}", e) for k, e in enumerate(conds) if e != 0]
                         for gb in self.branches for L, conds in cands]
        return []

    def _stage_order(self, r):
        m, F = self.m, self.sys.F
        if not isinstance(m, RungeKutta):
            raise DesignError("stage-order is implemented for RK methods (C(q))")
        A, c = self._mat(m.A), self._vec(m.c)
        return [(f"C({k}) stage {i + 1}",
                 sum((a * power(F, cj, k - 1) for a, cj in zip(A[i], c, strict=False)), F.zero)
                 - c[i] ** k * self.sys.frac(sp.Rational(1, k))) for k in range(1, r.value + 1) for i in range(m.s)]

    def _effective_order(self, r):
        if self.m.kind != "rk":
            raise DesignError("effective-order applies to RK methods; a GLM's order=P is already relative "
                              "to the best starting method")
        return self._order(r.value, glm=True)

    def _parasitism_free(self, r):
        from .parasitism import growth_parameters
        try:
            res = growth_parameters(self.m)
        except ValueError as exc:
            raise DesignError(str(exc)) from None
        out = []
        for p in res.items:
            re, im = sp.expand_complex(sp.expand(p.mu)).as_real_imag()
            out += [(f"parasitism Re μ(ζ = {p.zeta})", self.sys.frac(sp.expand(re))),
                    (f"parasitism Im μ(ζ = {p.zeta})", self.sys.frac(sp.expand(im)))]
        return out

    def _g_symplectic(self, r):
        A, U, B, V = self._glm()
        G, D = self.G, self.D
        out = []
        for name, M in (("VᵀGV − G", V.T * G * V - G), ("DU − BᵀGV", D * U - B.T * G * V),
                        ("DA + AᵀD − BᵀGB", D * A + A.T * D - B.T * G * B)):
            sym = name != "DU − BᵀGV"
            out += [(f"{name} [{i + 1},{j + 1}]", self.sys.frac(sp.expand(M[i, j])))
                    for i in range(M.rows) for j in range(i if sym else 0, M.cols)]
        out.append(("G nonsingular: det(G)·z = 1", self.sys.frac(sp.expand(G.det() * self.z - 1))))
        return out

    _BUILDERS = {
        "equation": _equation,
        "symplectic": _symplectic,
        "symmetric": _symmetric,
        "stage-order": _stage_order,
        "order": lambda self, r: self._order(r.value),
        "identity-start-order": lambda self, r: self._order(r.value, free_theta=False),
        "effective-order": _effective_order,
        "parasitism-free": _parasitism_free,
        "g-symplectic": _g_symplectic,
    }

    def _order(self, P, glm=False, free_theta=True):
        m, F = self.m, self.sys.F
        if isinstance(m, RungeKutta) and not glm:
            return _rk_weights(self._mat(m.A), self._vec(m.b), P, F, self.sys.frac)
        if isinstance(m, PartitionedRungeKutta):
            from .prk_order import order_conditions as prk_conditions
            return [(lab, self.sys.frac(e)) for lab, e in prk_conditions(m, P)]
        from .glm_order import order_conditions
        K = self.sys.K.frac_field(*self.params) if self.params else self.sys.K
        return [(lab, self.sys.frac(K.to_sympy(x))) for lab, x in order_conditions(m, P, K, free_theta)]


def _radicals(exprs):
    """The radicals (and numbers) in the expressions, parameters set aside."""
    out = []
    for e in exprs:
        e = sp.sympify(e)
        out += [p for p in e.atoms(sp.Pow) if p.exp.is_Rational and not p.exp.is_Integer and not p.free_symbols]
    return out or [sp.Integer(0)]


# ------------------------------------------------------------------ solving

def _label(m: Method, sol: dict, free) -> str:
    """'irreducible', or the stages that never reach the output (DJ-reducible: b_j = 0 and no
    stage that reaches the output uses stage j) for RK methods."""
    if not isinstance(m, RungeKutta):
        return "component"
    s = m.s

    def nonzero(e):                              # a value with free unknowns counts as nonzero
        return sp.sympify(e).subs(sol) != 0

    used = {i for i in range(s) if nonzero(m.b[i])}
    grew = True
    while grew:
        new = {j for i in used for j in range(s) if nonzero(m.A[i, j])} - used
        grew = bool(new)
        used |= new
    idle = [j + 1 for j in range(s) if j not in used]
    if idle:
        return "reducible: " + ", ".join(f"stage {j} does not reach the output" for j in idle)
    return "irreducible"


def _rebuild(m: Method, values: dict) -> Method:
    def sub(M):
        if M is None:
            return None
        M = M.subs(values)
        if M.has(sp.nan, sp.zoo, sp.oo, -sp.oo):      # the values make a denominator of the tableau vanish
            raise ValueError("the solution makes a denominator of the tableau vanish")
        return sp.ImmutableMatrix(M.applyfunc(normal_form))
    meta: dict[str, Any] = dict(name=m.name + " (solved)", source=m.source, notes=m.notes)
    if isinstance(m, RungeKutta):
        return RungeKutta(A=sub(m.A), b=sub(m.b), **meta)
    if isinstance(m, PartitionedRungeKutta):
        return PartitionedRungeKutta(A=sub(m.A), b=sub(m.b), Ahat=sub(m.Ahat), bhat=sub(m.bhat), **meta)
    if not isinstance(m, GeneralLinearMethod):
        raise TypeError(f"{m.name}: a method of kind {m.kind!r} cannot be rebuilt")
    return GeneralLinearMethod(A=sub(m.A), U=sub(m.U), B=sub(m.B), V=sub(m.V), **meta)


def _verify(meth: Method, reqs, values) -> dict:
    """Each requirement checked on the rebuilt method by the ordinary analyses (one order
    analysis for all order requirements; the effective order only when one asks for it)."""
    from .order import order
    from .parasitism import growth_parameters
    from .rk_order import rk_order
    from .symmetry import symmetric
    from .symplectic import g_symplectic, rk_symplectic
    orders = [r.value for r in reqs if r.name in ORDER_KEYWORDS]
    o = None
    if orders:
        if isinstance(meth, RungeKutta):
            o = rk_order(meth, max(orders), effective=any(r.name == "effective-order" for r in reqs))
        else:
            o = order(meth, max_order=max(orders))
    checks = {
        "symplectic": lambda r: rk_symplectic(meth).holds,
        "g-symplectic": lambda r: g_symplectic(meth).holds,
        "parasitism-free": lambda r: growth_parameters(meth).free,
        "symmetric": lambda r: symmetric(meth).holds,
        "equation": lambda r: is_zero(sp.sympify(r.value[0] - r.value[1]).subs(values)),
    }
    if o is not None:                  # the order requirements (ORDER_KEYWORDS), from the one order analysis
        checks.update({
            "order": lambda r: o.order >= r.value,
            "identity-start-order": lambda r: getattr(o, "order_identity_start", o.order) >= r.value,  # PRK: classical
            "effective-order": lambda r: o.effective_order >= r.value,
            "stage-order": lambda r: o.stage_order >= r.value,
        })
    return {str(r): checks[r.name](r) for r in reqs}


def solve(m: Method, requirements, extra_equations=(), extra_unknowns=()) -> DesignResult:
    """All solution families of the requirements for the unknowns of ``m`` (names such as
    ``a21``, ``b2`` in its entries), each re-verified by the analyses: ``tl.solve``, ``tableau-lab
    solve``.  Requirements (docs/design.md): ``order=p``, ``symplectic``, ``g-symplectic``,
    ``stage-order=q``, ``parasitism-free``, ``symmetric``, equations; the polynomial system is
    solved exactly (Gröbner bases, :mod:`tableau_lab.exact.polysystem`).  Reference: the order
    conditions of [B16] Butcher, *Numerical Methods for ODEs*, 3rd ed., ch. 3 (the family of
    explicit 2-stage methods of order 2 below is [B16] Sec. 31's b₂a₂₁ = 1/2, b₁ + b₂ = 1).

    ``m`` is a method or a design tableau file (whose unknown abscissae are dropped, as
    ``tableau-lab solve`` reads it: :func:`solve_file`).

    >>> import tableau_lab as tl
    >>> r = tl.solve(tl.load("methods/design/erk2_general.json"), ["order=2"])
    >>> r.status, {k: str(v) for k, v in r.solutions[0].parameters.items()}
    ('solved', {'a21': '1/(2*b2)', 'b1': '1 - b2'})
    """
    if not isinstance(m, Method):
        if extra_equations or extra_unknowns:
            raise TypeError("solve(path, ...): extra equations go with a method object")
        return solve_file(m, requirements)
    t0 = time.perf_counter()
    reqs = parse_requirements(requirements)
    prob = _Problem(m, reqs, extra_equations, extra_unknowns)
    sysm = prob.sys
    if not prob.params:
        raise DesignError(f"{m.name}: the tableau has no unknowns to solve for (write names such as \"b2\" "
                          "in the entries); use `tableau-lab verify` to check a method")
    base = [(lab, f.numer) for lab, f in prob.labelled]
    solutions: list[Solution] = []
    rejected: list[Solution] = []
    cores, n_eq = [], len(base)
    queue: list[tuple[list[Any], int, str, list[Any] | None]] = []     # (component, depth, note, parent)
    for branch in prob.branches:
        labelled = base + [(lab, sysm.poly(e)) for lab, e in branch]
        comps = sysm.components([p for _, p in labelled])
        if not comps:
            cores.append(sysm.core([(lab, p) for lab, p in labelled if p]))
        queue += [(comp, 0, "", None) for comp in comps]
    params = set(prob.params)
    covered: list[tuple[list[Any], list[Any]]] = []     # (component, condition polynomials) of the families found
    while queue:
        comp, depth, note, parent = queue.pop(0)
        if parent is not None and any(
                other is not parent and sysm._contains(other, comp)
                and all(sysm.poly(c).rem(comp) for c in conds) for other, conds in covered):
            continue      # a special case that another family already covers
        for br in sysm.explicit_parametrisation(comp, list(reversed(prob.params)))[1]:
            conds = _conditions(br.conditions, params)
            covered.append((comp, conds))
            sol, verdict = _judged(m, prob, reqs, br, conds, note)
            (solutions if verdict == "accepted" else rejected).append(sol)
            if verdict == "no method":
                continue      # its special cases are not searched
            # the generic formulas exclude the zeros of their branch conditions: solve those too
            if depth < 2:
                exprs = [g.as_expr() for g in comp]
                for c in conds:
                    queue += [(sub, depth + 1, f"special case {format_entry(c)} = 0 of: ", comp)
                              for sub in sysm.components([sysm.poly(e) for e in exprs] + [sysm.poly(c)])]
    solutions = _dedupe(solutions)
    status = _status(solutions, rejected)
    core = cores[0] if cores and not solutions and not rejected else ()
    obstruction = tuple((lab, sysm.expr(p)) for lab, p in core)
    return DesignResult(name=m.name, requirements=reqs, unknowns=tuple(prob.params), status=status,
                        solutions=tuple(solutions), obstruction=obstruction, rejected=tuple(rejected),
                        equations=n_eq, seconds=time.perf_counter() - t0)


def _judged(m: Method, prob, reqs, br, conds, note) -> tuple:
    """(solution, verdict): a branch of the parametrisation as a :class:`Solution`, rebuilt as a
    method and re-verified when it is real and explicit — "accepted" when every requirement holds,
    else "rejected"; "no method" for a solution that is no method (a zero denominator, say), with
    the reason in its label."""
    symvals = {p: br.values[p] for p in prob.params if p in br.values}
    sol = _solution(m, prob, br, symvals, conds, note)
    if not sol.real or sol.implicit:
        return sol, "rejected"
    try:
        meth = _rebuild(m, symvals)
        ver = _verify(meth, reqs, symvals)
    except (MethodError, ValueError) as exc:  # a solution that is no method (e.g. a zero denominator)
        return Solution(**{**sol.__dict__, "label": f"{sol.label}: {exc}"}), "no method"
    return (Solution(**{**sol.__dict__, "method": meth, "verified": ver}),
            "accepted" if all(ver.values()) else "rejected")


def _status(solutions, rejected) -> str:
    """The design's outcome in words."""
    if solutions:
        return "solved"
    if any(not s.real for s in rejected):
        return "no real solution"
    if rejected:
        return "not in radicals"
    return "no solution"


def _conditions(conds, params) -> list:
    """The distinct non-constant factors (over QQ) of the numerators of the branch conditions
    that involve only tableau unknowns."""
    out = []
    for c in conds:
        if not c.free_symbols or not c.free_symbols <= params:
            continue
        num = sp.numer(sp.together(c))
        for f, _ in sp.factor_list(num)[1]:
            f = sp.expand(f / sp.Poly(f, *sorted(f.free_symbols, key=str)).LC())
            if f.free_symbols and f not in out:
                out.append(f)
    return out


def _solution(m, prob, br, symvals, conds, note) -> Solution:
    aux = {"G": prob.G.subs(br.values), "D": prob.D.subs(br.values)} if prob.aux else {}
    return Solution(label=note + _label(m, symvals, br.free), parameters={p.name: v for p, v in symvals.items()},
                    free=tuple(x for x in br.free if x in prob.params), conditions=tuple(conds),
                    auxiliary=aux, method=None, verified={}, real=br.real, implicit=br.implicit)


def _dedupe(sols):
    out, seen = [], set()
    for s in sols:
        key = (tuple(sorted((str(k), str(v)) for k, v in s.parameters.items())), s.free)
        if key not in seen:
            seen.add(key)
            out.append(s)
    return out


def method_from_design(data: dict, source: str):
    """(method, extra equations) from the parsed JSON ``data`` of a design tableau read from
    ``source``: when c or A holds unknowns, c is dropped (c = A·1 is derived) and its entries
    become the equations cᵢ = Σⱼ aᵢⱼ, labelled for the design report; claims are dropped (they
    are what the design will establish).  One reader for ``solve_text``, ``solve_file`` and
    ``family.tableau_family``.

    >>> m, extra = method_from_design({"name": "heun", "kind": "rk", "A": [["0", "0"], ["a", "0"]],
    ...                                "b": ["1/2", "1/2"], "c": ["0", "1"]}, "<example>")
    >>> m.c.T, extra
    (Matrix([[0, a]]), [('c1 = row sum of A', 0), ('c2 = row sum of A', 1 - a)])
    """
    extra = []
    if data.get("kind") in ("rk", "prk") and "c" in data:
        c = entries(data["c"], source, "c")
        A = entries(data["A"], source, "A")
        if any(sp.sympify(x).free_symbols for x in list(c) + list(A)):
            data = {k: v for k, v in data.items() if k != "c"}
            extra = [(f"c{i + 1} = row sum of A", c[i] - sum(A.row(i))) for i in range(A.rows)]
    data = {k: v for k, v in data.items() if k != "claims"}
    return from_dict(data, source), extra


def solve_text(text: str, requirements, source: str = "<tableau>") -> DesignResult:
    m, extra = method_from_design(parse(text, source), source)
    return solve(m, requirements, extra, _symbols(extra))


def solve_file(path, requirements) -> DesignResult:
    m, extra = method_from_design(read(path), str(path))
    return solve(m, requirements, extra, _symbols(extra))


def _symbols(extra):
    out = []
    for _, e in extra:
        out += sorted(sp.sympify(e).free_symbols, key=lambda s: s.name)
    return out



# ------------------------------------------------------------------ repair of misprinted tableaux

@dataclass(frozen=True)
class RepairResult(Result):
    """Suspect entries of a printed tableau solved for the requirements: each changed entry with
    its printed and its correct value; with ``located``, the single entries whose replacement by
    an unknown makes the requirements solvable."""

    name: str
    suspects: tuple            # entry names, e.g. "A[2,1]"
    printed: dict              # entry -> printed value
    design: DesignResult | None
    located: tuple = ()        # entries that alone restore solvability (locate mode)
    tried: int = 0
    skipped: tuple = ()        # entries whose generic replacement leaves no preconsistent method

    def _text(self) -> str:
        lines = [f"{self.name}: repair"]
        if self.tried:
            lines.append(f"located: of {self.tried} entries tried one at a time, the requirements become solvable "
                         f"when {('one of ' + ', '.join(self.located)) if self.located else 'none'} is an unknown"
                         + (f" (not tried: {', '.join(self.skipped)}: no preconsistent method for generic values)"
                            if self.skipped else ""))
        if self.design is None:
            return "\n".join(lines)
        lines.append(f"suspects {', '.join(self.suspects)}: {self.design.status}")
        for i, sol in enumerate(self.design.solutions, 1):
            lines.append(f"repair {i}" + (f" (free: {', '.join(map(str, sol.free))})" if sol.free else "") + ":")
            changed = self.changes(i)
            for e in self.suspects:
                lines.append(f"    {e}: printed {format_entry(self.printed[e])}"
                             + (f"  →  {format_entry(changed[e][1])}" if e in changed else "  (correct)"))
            for k, M in sol.auxiliary.items():
                lines.append(f"    {k} = {_inline(M)}")
            verdicts = ", ".join(f"{k} {'yes' if v else 'NO'}" for k, v in sol.verified.items())
            lines.append("    re-verified: " + verdicts)
        if self.design.obstruction:
            lines.append("obstruction: " + "; ".join(lab for lab, _ in self.design.obstruction))
        return "\n".join(lines)

    def changes(self, k: int = 1) -> dict:
        """entry -> (printed, correct) for the entries that repair k changes."""
        if self.design is None:
            raise ValueError(f"{self.name}: no repair was solved (located: {', '.join(self.located) or 'none'}); "
                             "name the suspect entry to repair")
        sol = self.design.solutions[k - 1]
        out = {}
        for e in self.suspects:
            new = sol.parameters.get(_var(e).name, _var(e))
            if sp.sympify(new).free_symbols or not is_zero(new - self.printed[e]):
                out[e] = (self.printed[e], new)
        return out

    def to_json(self):
        out = {"suspects": list(self.suspects), "located": list(self.located), "tried": self.tried,
               "printed": {e: str(format_entry(v)) for e, v in self.printed.items()}}
        if self.design is not None:
            out.update(self.design.to_json())
            out["changes"] = [{e: {"printed": str(format_entry(a)), "correct": str(format_entry(b))}
                               for e, (a, b) in self.changes(k).items()}
                              for k in range(1, len(self.design.solutions) + 1)]
        return out

    def display(self) -> Document:
        """Text: the located entries and each repair; typeset: the design's display."""
        head, *lines = self._text().split("\n")
        return Document(head, (Plain(*(Paragraph(x) for x in lines)),
                               Typeset(*([] if self.design is None else [self.design.display()]))))


_ENTRY = re.compile(r"^\s*([A-Za-z]+)\s*\[\s*([0-9]{1,6})\s*(?:,|\]\s*\[)\s*([0-9]{1,6})\s*\]\s*$"
                    r"|^\s*([A-Za-z]+)\s*\[\s*([0-9]{1,6})\s*\]\s*$")      # ASCII indices of at most 6 digits


def _var(entry: str) -> sp.Symbol:
    return sp.Symbol("x_" + "".join(ch for ch in entry if ch.isalnum()), real=True)


def _entry_spec(m: Method, text: str):
    """'A[2,1]' (or A[2][1], b[3]) → (matrix key, row, col), 0-based, checked against m."""
    mt = _ENTRY.match(text)
    if not mt:
        raise DesignError(f"suspect entry {text!r}: write it as A[2,1] (1-based row, column) or b[2]")
    key, i, j = (mt.group(1), int(mt.group(2)), int(mt.group(3))) if mt.group(1) else (mt.group(4), int(mt.group(5)), 1)
    mats = {k: v for k, v in m.matrices().items() if v is not None and k != "c"}
    if key not in mats:
        raise DesignError(f"suspect entry {text!r}: {key} is not a matrix of this {m.kind} tableau "
                          f"({', '.join(mats)})")
    M = mats[key]
    if not (1 <= i <= M.rows and 1 <= j <= M.cols):
        raise DesignError(f"suspect entry {text!r}: {key} is {M.rows}x{M.cols}")
    return key, i - 1, j - 1


def _with_unknowns(m: Method, specs: dict) -> Method:
    mats = {k: sp.Matrix(v) for k, v in m.matrices().items() if v is not None and k != "c"}
    for name, (key, i, j) in specs.items():
        mats[key][i, j] = _var(name)
    cls = type(m)
    return cls(**{k: sp.ImmutableMatrix(v) for k, v in mats.items()}, name=m.name, source=m.source, notes=m.notes)


def _canonical(text: str, m: Method) -> str:
    key, i, j = _entry_spec(m, text)
    return f"{key}[{i + 1}]" if key in ("b", "bhat") else f"{key}[{i + 1},{j + 1}]"


def solvable(m: Method, requirements) -> bool:
    """Whether the requirements have any (complex) solution for the unknowns of m: one Gröbner
    basis per normalisation branch, no parametrisation."""
    prob = _Problem(m, parse_requirements(requirements))
    base = [f.numer for _, f in prob.labelled]
    return any(prob.sys.consistent(base + [prob.sys.poly(e) for _, e in br]) for br in prob.branches)


def repair(m: Method, requirements, suspects=(), locate: bool = False, within=None) -> RepairResult:
    """Replace the ``suspects`` (e.g. ["A[2,1]", "U[2,2]"]) of a numeric tableau by unknowns and
    solve for the requirements.  With ``locate``, first try every single entry (of the matrices
    ``within``, default all but V and c) as the unknown, beside the suspects, and report those
    that make the requirements solvable; without suspects, a single located entry is repaired.

    >>> from tableau_lab.exact.tableau_json import load
    >>> r = repair(load("methods/glm43_printed.json"), ["g-symplectic"], locate=True, within=["A"])
    >>> r.located
    ('A[1,2]', 'A[2,1]')
    >>> r = repair(load("methods/glm43_printed.json"), ["g-symplectic"], ["A[2,1]"])
    >>> {e: [str(v) for v in pair] for e, pair in r.changes().items()}
    {'A[2,1]': ['-11/127', '-11/172']}
    """
    if m.parameters:
        raise DesignError(f"{m.name}: repair takes a numeric tableau (this one has unknowns "
                          f"{', '.join(map(str, m.parameters))}: use solve)")
    reqs = parse_requirements(requirements)
    printed = {}
    located: tuple[str, ...] = ()
    tried, skipped = 0, []
    if locate:
        mats = {k: M for k, M in m.matrices().items() if M is not None and k != "c"}
        bad = [k for k in within or () if k not in mats]
        if bad:
            raise DesignError(f"--within {', '.join(bad)}: not a matrix of this tableau ({', '.join(mats)})")
        keys = [k for k in mats if k in within] if within else [k for k in mats if k != "V"]
        cands = [f"{k}[{i + 1},{j + 1}]" for k in keys for i in range(mats[k].rows) for j in range(mats[k].cols)]
        base = {_canonical(s, m) for s in suspects}
        found = []
        for c in cands:
            cc = _canonical(c, m)
            if cc in base:
                continue
            specs = {e: _entry_spec(m, e) for e in sorted(base | {cc})}
            try:
                trial = _with_unknowns(m, specs)
            except MethodError:          # no preconsistency vector for generic values: not tried
                skipped.append(cc)
                continue
            tried += 1
            if solvable(trial, reqs):
                found.append(cc)
        located = tuple(found)
        if not suspects and len(found) != 1:
            return RepairResult(m.name, (), {}, None, located, tried, tuple(skipped))
        if not suspects:
            suspects = found
    if not suspects:
        raise DesignError("name the suspect entries (e.g. A[2,1]) or ask to locate them")
    specs = {}
    for s in suspects:
        c = _canonical(s, m)
        specs[c] = _entry_spec(m, c)
        key, i, j = specs[c]
        M = m.matrices()[key]
        assert M is not None, "_entry_spec names a matrix of the tableau"
        printed[c] = M[i, j]
    design = solve(_with_unknowns(m, specs), reqs)
    return RepairResult(m.name, tuple(specs), printed, design, located, tried, tuple(skipped))


__all__ += ["repair", "RepairResult", "solvable"]
