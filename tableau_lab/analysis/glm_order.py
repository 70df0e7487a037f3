r"""Order of a general linear method relative to a starting method, exactly.

Butcher's algebraic theory ([B16] Sec. 53; [B21] ch. 6; Butcher & Imran, BIT 55 (2015)):
a GLM M has order p relative to a starting method S (y^[0]_i = B(ξ_i, y₀), ξ(∅) = u)
when M∘S = S∘E + O(h^{p+1}).  Tree by tree, with the stage series η and its
derivative ηD ((ηD)(τ) = 1, (ηD)([t₁…t_m]) = Π η(t_k)):

    η(t) = A (ηD)(t) + U ξ(t),        (I − V) ξ(t) = Q(t) := B (ηD)(t) − [(ξ·E)(t) − ξ(t)].

The order-|t| equation is solvable iff wᵀQ(t) = 0 (w the left eigenvector of V for 1,
wᵀu = 1); then ξ(t) = ξ₀(t) + θ(t)u with wᵀξ₀(t) = 0 and θ(t) = wᵀξ(t) free.  The θ(s),
|s| = k − 1, enter the order-k conditions linearly with the method-independent matrix
L_k[t, s] = [t = [s]] − #{leaves of t whose removal leaves s}; L_2 = 0 (θ(τ) is a time
shift and never matters) and L_k has full column rank for k ≥ 3 (checked up to k = 9 in
the tests), so the θ's are forced order by order and the sequential exact solve below
gives the **highest achievable order**.  Forcing θ ≡ 0 gives the order with the identity
as first starting component; for an RK method the two are its effective and classical orders.

The **stage order** q is Butcher's ([B16] Sec. 53; Butcher, Appl. Numer. Math. 11 (1993) for
DIMSIMs): the largest q <= p with stages accurate to O(h^{q+1}), η(t) = c^|t|/γ(t) for |t| <= q,
relative to a starting method that realises the order p.  The order fixes θ(s) for |s| < p; θ(t),
|t| = p, first enters at order p + 1 and is chosen for the stages (a DIMSIM, the leapfrog and
Nordsieck Adams methods get q = p), and the printed starting method is that one.  An RK method
whose classical order is the order keeps the identity start (θ ≡ 0): its classical stage order.

>>> from tableau_lab.exact.tableau_json import load
>>> res = glm_order(load("methods/example4_glm.json"))
>>> res.order, res.order_identity_start
(4, 4)
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import sympy as sp
from sympy.polys.matrices import DomainMatrix

from ..exact.field import element, field_of, solve_linear, to_dm
from ..exact.grammar import format_entry
from ..exact.methods import Method, RungeKutta, preconsistency
from ..render.model import Document, Formula, Paragraph, Plain, Typeset
from .bseries import flow_cuts, inverse_coefficients
from .results import Result
from .tree_kinds import Coefficients, Tree
from .trees import bracket, bracket_tex, density, leaf_removals, order, trees_of_order

__all__ = ["glm_order", "GLMOrderResult", "OrderSolver", "theta_matrix", "order_conditions", "condition_residuals"]

@lru_cache(maxsize=None)
def theta_matrix(k: int) -> tuple:
    """L_k: coefficient of θ(s) (|s| = k−1) in the order-k condition of tree t."""
    return tuple(tuple((1 if t == (s,) else 0) - leaf_removals(t).count(s) for s in trees_of_order(k - 1))
                 for t in trees_of_order(k))


# ----------------------------------------------------------------- the solve

@dataclass(frozen=True, eq=False)      # Result.__eq__: equal to its order as an int
class GLMOrderResult(Result):
    """Order of a GLM (or an RK method as a GLM) with its starting and finishing methods."""

    int_field = "order"          # int(result) is the order
    method: str
    order: int                   # highest achievable (θ free)
    order_identity_start: int    # θ ≡ 0
    stage_order: int
    u: tuple
    w: tuple
    starting: dict               # bracket -> (ξ_1(t), ..., ξ_r(t)) exact, |t| <= order
    theta: dict                  # bracket -> θ(t)
    finishing: dict              # bracket -> α⁻¹(t): F(y) = B(α⁻¹, wᵀy)
    errors: dict                 # bracket -> nonzero residual of the order-(p+1) condition
    errors_identity_start: dict
    max_order: int = 0
    capped: bool = False         # order reached max_order: it may be higher
    _exact: dict = field(default_factory=dict, repr=False, compare=False)   # ``starting`` in the field

    @property
    def starting_exact(self) -> dict:
        """``starting`` as elements of the method's number field when the solve kept them (the
        sympy form of an entry in a large field need not convert back), else ``starting``."""
        return self._exact or self.starting

    def _text(self) -> str:
        cap = " (at least: cap reached)" if self.capped else ""
        lines = [f"{self.method}: order {self.order}{cap} with a suitable starting method; "
                 f"{self.order_identity_start} with θ ≡ 0; stage order {self.stage_order}"]
        lines.append("  starting method ξ(t) (y^[0]_i = B(ξ_i, y0); it realises the order and the stage order):")
        for t, xi in self.starting.items():
            lines.append(f"    {t:10s} " + ", ".join(str(format_entry(x)) for x in xi))
        if self.errors:
            lines.append(f"  error terms at order {self.order + 1}: "
                         + "; ".join(f"{t}: {format_entry(v)}" for t, v in self.errors.items()))
        return "\n".join(lines)

    def to_json(self):
        def text(x):
            return str(format_entry(x))

        return {
            "order": self.order, "order_identity_start": self.order_identity_start,
            "stage_order": self.stage_order, "capped": self.capped,
            "u": [text(x) for x in self.u], "w": [text(x) for x in self.w],
            "starting_method": {t: [text(x) for x in xi] for t, xi in self.starting.items()},
            "theta": {t: text(x) for t, x in self.theta.items()},
            "finishing_method": {t: text(x) for t, x in self.finishing.items()},
            "error_terms": {t: text(x) for t, x in self.errors.items()},
            "error_terms_identity_start": {t: text(x) for t, x in self.errors_identity_start.items()},
        }

    def display(self) -> Document:
        """Text: the orders, the starting method, the error terms; typeset: the order and ξ(t)."""
        head, *lines = self._text().split("\n")
        rows = [f"{bracket_tex(t)} & " + " & ".join(sp.latex(x) for x in xi) + r" \\"
                for t, xi in self.starting.items()]
        r = len(self.u)
        array = (r"\begin{array}{c|" + "c" * r + "} t & " + " & ".join(f"\\xi_{{{i + 1}}}(t)" for i in range(r))
                 + r" \\ \hline " + "\n".join(rows) + r" \end{array}")
        return Document(head, (Plain(*(Paragraph(x) for x in lines)), Typeset(
            Paragraph(f"Order {self.order} relative to the starting method"), Formula(array))))


class OrderSolver:
    """The exact data of Butcher's sequential solve of a GLM's order conditions over its field K
    ([B16] Sec. 53, the module docstring): the matrices A, U, B, V as ``DomainMatrix``, the
    preconsistency vector u (Vu = u, Uu = 𝟙), the left eigenvector w (wᵀV = wᵀ, wᵀu = 1), a left
    inverse ``Pinv`` of [I − V; wᵀ] (ξ(t) without principal part), and the tree-by-tree defect
    Q(t) and the sequential :meth:`run`; :func:`glm_order` and
    ``method_series.method_series`` (the underlying one-step method) use it.

    >>> from sympy import QQ
    >>> from tableau_lab.exact.library import family
    >>> S = OrderSolver(family("bdf:2").as_glm(), QQ)
    >>> [str(x) for x in S.u], [str(x) for x in S.w]
    (['1', '1'], ['3/2', '-1/2'])
    """

    def __init__(self, g, K):
        self.K = K
        self.s, self.r = g.s, g.r
        self.A, self.U, self.B, self.V = (to_dm(X, K) for X in (g.A, g.U, g.B, g.V))
        u = preconsistency(g.U, g.V)
        if u is None:
            raise ValueError(f"{g.name}: not preconsistent (no u with Vu = u, Uu = 1): order 0")
        r = self.r
        M = to_dm(sp.Matrix.vstack(g.V.T - sp.eye(r), u.T), K)
        if M.rank() < r:
            raise ValueError(f"{g.name}: 1 is not a simple eigenvalue of V; the order theory here needs it")
        self.u = [element(K, x) for x in u]
        w = solve_linear(M, [0] * r + [1])
        if w is None:                      # not reached: rank r above makes the system consistent
            raise ValueError(f"{g.name}: no left eigenvector w of V with wᵀu = 1; the order theory here needs it")
        self.w = w
        # (I − V) x = q with wᵀx = 0: the particular solution without principal part.
        # P has full column rank r: invert r independent rows once (x = Pinv·[q; 0] when wᵀq = 0).
        self.P = to_dm(sp.Matrix.vstack(sp.eye(r) - g.V, sp.Matrix([[K.to_sympy(x) for x in self.w]])), K)
        rows = list(self.P.transpose().rref()[1])
        sub = DomainMatrix([self.P.to_list()[i] for i in rows], (r, r), K).inv().to_list()
        self.Pinv = [[sum((sub[i][j] for j, ri in enumerate(rows) if ri == k), K.zero) for k in range(r + 1)]
                     for i in range(r)]
        self.c = [element(K, x) for x in g.c]
        self._rat = {}

    def rational(self, q):
        if q not in self._rat:
            self._rat[q] = self.K.convert(q)
        return self._rat[q]

    # vectors are plain lists of field elements
    def mat(self, M, v):
        K = self.K
        rows = M.to_list()
        return [sum((a * x for a, x in zip(row, v, strict=False)), K.zero) for row in rows]

    def mat_rows(self, rows, v):
        return [sum((a * x for a, x in zip(row, v, strict=False)), self.K.zero) for row in rows]

    def dot_w(self, v):
        return sum((a * b for a, b in zip(self.w, v, strict=False)), self.K.zero)

    def defect(self, t, eta, xi, etaD, nonzero):
        """Q(t) = B(ηD)(t) − [(ξ·E)(t) − ξ(t)] from η of the subtrees of t and ξ of its trunks
        (those in ``nonzero``; ξ[None] = u); (ηD)(t) is stored in ``etaD``."""
        d = [self.K.one] * self.s
        for c in t:
            d = [x * y for x, y in zip(d, eta[c], strict=False)]
        etaD[t] = d
        q = self.mat(self.B, d)
        e = self.rational(sp.Rational(1, density(t)))
        q = [a - b * e for a, b in zip(q, xi[None], strict=False)]
        for trunk, coef in flow_cuts(t):
            if trunk in nonzero:
                cf = self.rational(coef)
                q = [a - cf * b for a, b in zip(q, xi[trunk], strict=False)]
        return q

    def run(self, max_order, free_theta, theta_tau, collect=None):
        """The sequential solve.  With ``collect`` (a list), the order conditions up to
        ``max_order`` are appended to it as (label, residual) instead of stopping at the first
        failure; θ is then the least-squares-free left-inverse solution, exact wherever the
        conditions hold (the design module solves them)."""
        K = self.K
        xi: Coefficients = {None: list(self.u)}          # None is the empty tree
        eta: Coefficients = {}
        etaD: Coefficients = {}
        theta: Coefficients = {}
        p, errors = 0, {}
        nonzero: set[Tree] = set()         # trees whose ξ(t) is not the zero vector
        for k in range(1, max_order + (1 if collect is not None else 2)):
            Tk = trees_of_order(k)

            def Q(t):
                return self.defect(t, eta, xi, etaD, nonzero)

            res = [self.dot_w(Q(t)) for t in Tk]
            if k >= 3 and free_theta:
                prev = trees_of_order(k - 1)
                L = DomainMatrix([[K.convert(x) for x in row] for row in theta_matrix(k)], (len(Tk), len(prev)), K)
                sol = (left_inverse(L, [-x for x in res]) if collect is not None
                       else solve_linear(L, [-x for x in res]))
                if sol is None:
                    errors = _pivot_residuals(L, res, Tk, K)
                    break
                for s_, th in zip(prev, sol, strict=False):
                    theta[s_] = th
                    xi[s_] = [a + th * b for a, b in zip(xi[s_], self.u, strict=False)]
                    eta[s_] = [a + th for a in eta[s_]]
                    if not K.is_zero(th):
                        nonzero.add(s_)
                res = [self.dot_w(Q(t)) for t in Tk]
            if collect is not None:
                collect.extend((f"order {k}, tree {bracket(t)}", x)
                               for t, x in zip(Tk, res, strict=False) if not K.is_zero(x))
                res = []
            bad = {bracket(t): K.to_sympy(x) for t, x in zip(Tk, res, strict=False) if not K.is_zero(x)}
            if bad:
                errors = bad
                break
            if k > max_order:
                break
            p = k
            for t in Tk:
                qt = Q(t)
                x = self.mat_rows(self.Pinv, qt + [K.zero])
                if t == () and theta_tau is not None:
                    x = [a + theta_tau * b for a, b in zip(x, self.u, strict=False)]
                    theta[t] = theta_tau
                xi[t] = x
                if any(not K.is_zero(v) for v in x):
                    nonzero.add(t)
                eta[t] = [a + b for a, b in zip(self.mat(self.A, etaD[t]), self.mat(self.U, x), strict=False)]
        return p, xi, eta, theta, errors


def left_inverse(L, rhs):
    """x with L x = rhs on the independent rows of L (L of full column rank)."""
    rows = L.to_list()
    chosen = list(L.transpose().rref()[1])
    sub = DomainMatrix([rows[i] for i in chosen], (len(chosen), L.shape[1]), L.domain)
    return solve_linear(sub, [rhs[i] for i in chosen])


def _pivot_residuals(L, res, Tk, K):
    """θ chosen to satisfy a maximal independent set of the conditions (first trees first);
    the residuals of the others are the intrinsic error terms."""
    rows = L.to_list()
    th = left_inverse(L, [-x for x in res])    # θ from the first maximal set of independent rows
    out = {}
    for i, t in enumerate(Tk):
        v = res[i] + sum((a * b for a, b in zip(rows[i], th, strict=False)), K.zero)
        if not K.is_zero(v):
            out[bracket(t)] = K.to_sympy(v)
    return out


def _stage_order(solver, p, xi, eta, theta, free_top) -> int:
    """The stage order q <= p: the stages accurate to O(h^{q+1}), η(t) = c^|t|/γ(t) for |t| <= q
    ([B16] Sec. 53 with the starting method y^[0] = B(ξ, y₀) realising order p).

    The order-p conditions fix θ(s) (ξ(s) = ξ₀(s) + θ(s)u) for |s| < p (θ(τ) by the abscissae c)
    but leave θ(t), |t| = p, free: it first enters at order p + 1.  Adding θ(t)u to ξ(t) adds
    θ(t)·Uu = θ(t)·1 to η(t), so with ``free_top`` stage order p holds when every
    c^p/γ(t) − η(t) is a constant vector, and that constant becomes θ(t) in ``xi``, ``eta`` and
    ``theta`` (updated in place): the starting method returned realises both p and q.  Without
    ``free_top`` (an RK method with its identity start) θ stays 0: the classical stage order."""
    K = solver.K
    q = 0
    for k in range(1, p + 1):
        gaps = {t: [ci ** k * K.convert(sp.Rational(1, density(t))) - e
                    for e, ci in zip(eta[t], solver.c, strict=False)]
                for t in trees_of_order(k)}
        if all(all(K.is_zero(g) for g in d) for d in gaps.values()):
            q = k
            continue
        if k == p and free_top and all(all(K.is_zero(g - d[0]) for g in d) for d in gaps.values()):
            for t, d in gaps.items():
                if not K.is_zero(d[0]):
                    theta[t] = theta.get(t, K.zero) + d[0]
                    xi[t] = [a + d[0] * b for a, b in zip(xi[t], solver.u, strict=False)]
                    eta[t] = [a + d[0] for a in eta[t]]
            q = k
        break
    return q


def glm_order(m: Method, max_order: int = 8) -> GLMOrderResult:
    """The order of ``m`` (a GLM, or an RK method as a GLM) relative to the best starting
    method, the order with θ ≡ 0, the stage order, the starting method ξ(t) for |t| <= p,
    the finishing method and the error terms at order p + 1."""
    g = m.as_glm()
    K = field_of([g.A, g.U, g.B, g.V, g.c])
    solver = OrderSolver(g, K)
    # θ(τ): the uniform shift that makes the stage abscissae equal to the method's c
    ones = [K.one] * g.s
    x0 = solve_linear(solver.P, [a - b for a, b in zip(solver.mat(solver.B, ones), solver.u, strict=False)] + [K.zero])
    c0 = [a + b for a, b in zip(solver.mat(solver.A, ones), solver.mat(solver.U, x0 or [K.zero] * g.r), strict=False)]
    shift = solver.c[0] - c0[0] if x0 is not None else K.zero
    p0, xi0, eta0, theta0, errors0 = solver.run(max_order, False, shift)
    bound = m.order_bound if isinstance(m, RungeKutta) else None
    if bound is not None and p0 >= bound:
        # For RK methods the order with any starting method is at most the order of the
        # stability function R(z) (on y' = λy the starting method is a scalar factor that
        # commutes): ≤ 2s, and ≤ s for explicit methods.  The classical order reaches it.
        p, xi, eta, theta, errors = p0, xi0, eta0, theta0, errors0
    else:
        p, xi, eta, theta, errors = solver.run(max_order, True, shift)
    # θ at order p is free unless the identity start is the RK convention or order p + 1 was not
    # refuted (capped: the order-(p+1) solve has fixed it)
    free_top = not (bound is not None and p0 >= bound) and bool(errors)
    q = _stage_order(solver, p, xi, eta, theta, free_top)
    alpha = {t: solver.dot_w(xi[t]) for t in xi if t is not None}
    beta = inverse_coefficients(alpha, p)
    lift = K.to_sympy
    return GLMOrderResult(
        method=m.name, order=p, order_identity_start=p0, stage_order=q,
        u=tuple(lift(x) for x in solver.u), w=tuple(lift(x) for x in solver.w),
        starting={bracket(t): tuple(lift(x) for x in xi[t]) for k in range(1, p + 1) for t in trees_of_order(k)},
        _exact={bracket(t): tuple(xi[t]) for k in range(1, p + 1) for t in trees_of_order(k)},
        theta={bracket(t): lift(v) for t, v in theta.items() if order(t) <= p},
        finishing={bracket(t): lift(v) for t, v in beta.items() if t is not None},
        errors=errors, errors_identity_start=errors0, max_order=max_order, capped=not errors)


def order_conditions(m: Method, max_order: int, K, free_theta: bool = True) -> list:
    """The order conditions of ``m`` through ``max_order`` as (label, element of K) pairs, with
    the principal parts θ free (eliminated) or ≡ 0; K holds the method's free parameters.
    All vanish exactly when the method has that order (for the parameter values)."""
    g = m.as_glm()
    solver = OrderSolver(g, K)
    out: list = []
    solver.run(max_order, free_theta, None, collect=out)
    return out


def condition_residuals(m: Method, starting: dict, upto: int) -> tuple[dict, bool | None]:
    """The order conditions evaluated with a given starting method, tree by tree for |t| ≤ upto.

    ``starting``: bracket → ξ(t) (r exact entries, sympy or of the method's field, as
    ``GLMOrderResult.starting`` or ``.starting_exact``); ξ(∅) = u.  The
    stage condition η(t) = A(ηD)(t) + Uξ(t) defines η; the value for t is the residual of the
    output condition, R(t) = B(ηD)(t) + Vξ(t) − (ξE)(t) (r exact sympy entries).  For a tree whose
    ξ(t) is not given (they must all be of the last order) the value is the scalar wᵀR(t), which
    does not depend on ξ(t) (wᵀ(V − I) = 0): the output condition is solvable for ξ(t) iff it is 0.

    Returns (bracket → value, repairable): ``repairable`` says, when scalars were returned and not
    all are zero, whether a change θ(s) of the principal parts of the last given order
    (ξ(s) ↦ ξ(s) + θ(s)u, which changes no condition of lower order) can make them all zero —
    L_k θ = −wᵀR solvable — and is None otherwise."""
    g = m.as_glm()
    K = field_of([g.A, g.U, g.B, g.V, g.c])
    solver = OrderSolver(g, K)
    xi: Coefficients = {None: list(solver.u)}
    eta: Coefficients = {}
    etaD: Coefficients = {}
    nonzero: set[Tree] = set()
    out: dict[str, Any] = {}
    missing: list[tuple[Tree, Any]] = []     # (tree, wᵀR(t)) of the trees whose ξ(t) is not given
    for k in range(1, upto + 1):
        for t in trees_of_order(k):
            q = solver.defect(t, eta, xi, etaD, nonzero)
            if bracket(t) not in starting:
                missing.append((t, solver.dot_w(q)))
                continue
            x = [v if isinstance(v, K.dtype) else element(K, v) for v in starting[bracket(t)]]
            xi[t] = x
            if any(not K.is_zero(v) for v in x):
                nonzero.add(t)
            eta[t] = [a + b for a, b in zip(solver.mat(solver.A, etaD[t]), solver.mat(solver.U, x), strict=False)]
            Vx = solver.mat(solver.V, x)
            out[bracket(t)] = tuple(K.to_sympy(a - b + c) for a, b, c in zip(q, x, Vx, strict=False))
        if missing:
            break
    repairable = None
    if missing and any(not K.is_zero(v) for _, v in missing):
        k = order(missing[0][0])
        res = [v for _, v in missing]
        L = theta_matrix(k) if k >= 2 else ()
        Ldm = DomainMatrix([[K.convert(x) for x in row] for row in L], (len(L), len(L[0])), K) if L else None
        repairable = bool(L) and solve_linear(Ldm, [-v for v in res]) is not None
    out.update((bracket(t), K.to_sympy(v)) for t, v in missing)
    return out, repairable
