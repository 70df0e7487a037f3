r"""The B-series of a method: Runge–Kutta methods and the **underlying one-step method** of a
general linear method ([HLW06] XV.2; Kirchgraber, *Numer. Math.* 48 (1986); [B21] ch. 6).

A GLM M (stages Y = hA f(Y) + U y^[n−1], y^[n] = hB f(Y) + V y^[n−1]) whose matrix V has 1 as a
simple eigenvalue has, as formal B-series, a starting method S (y^[n]_i = B(ξ_i, y), ξ(∅) = u)
and a one-step map Φ with

    M ∘ S = S ∘ Φ,        wᵀ ξ(t) = 0 for t ≠ ∅  (wᵀ y^[n] = y_n exactly),

w the left eigenvector of V for 1 (wᵀu = 1).  Tree by tree, with η the stage series and η′ its
derivative (η′(τ) = 1, η′([t₁…t_m]) = Π η(t_k)):

    Q(t) = B η′(t) − Σ_{root-keeping cuts ≠ t} Π Φ(pruned) ξ(trunk),
    Φ(t) = wᵀ Q(t),   (I − V) ξ(t) = Q(t) − u Φ(t),   η(t) = A η′(t) + U ξ(t).

Other normalisations of S give Φ conjugate to this one by a near-identity B-series, so the
properties that do not depend on coordinates (order, symmetry up to conjugacy, conjugate
symplecticity) are those of any of them.  For a Runge–Kutta method (r = 1, V = 1) ξ vanishes and
Φ(t) = bᵀη′(t), the elementary weights; a partitioned method has the P-series
Φ(t) = b_{col(t)}ᵀΨ(t) over bicoloured trees (:func:`prk_order.weight_function`).

>>> from tableau_lab.exact.tableau_json import load
>>> from tableau_lab.analysis.bseries import series_order
>>> ex4 = method_series(load("methods/example4_glm.json"), 6)
>>> series_order(ex4.phi), ex4.phi["[τ²]"]
(4, 1/3)
>>> gauss = method_series(load("methods/gauss2.json"), 5).phi
>>> series_order(gauss), gauss["[τ⁴]"]
(4, 7/36)
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..exact.field import FastField, field_of
from ..exact.grammar import format_entry
from ..exact.methods import Method, PartitionedRungeKutta, RungeKutta
from ..render.model import Document, Formula, Paragraph, Plain, Typeset
from .bseries import BSeries, check_series_order, kept_cuts
from .glm_order import OrderSolver
from .prk_order import weight_function as prk_weights
from .results import Result
from .rk_order import weight_function
from .tree_kinds import BICOLOURED, Coefficients
from .trees import bracket, density, symmetry, trees_of_order, trees_up_to

__all__ = ["method_series", "MethodSeries", "error_terms"]


@dataclass(frozen=True)
class MethodSeries(Result):
    """Φ (the method's B-series, for a GLM that of its underlying one-step method) and, for a GLM,
    the starting method ξ_i(t) with wᵀξ(t) = 0 (empty for a Runge–Kutta method)."""

    method: str
    kind: str
    phi: BSeries
    starting: dict               # tree -> tuple of exact values (empty for r = 1)
    u: tuple
    w: tuple

    def _text(self) -> str:
        head = (f"{self.method}: B-series of the underlying one-step method" if self.kind == "glm"
                else f"{self.method}: B-series")
        lines = [head + f" to order {self.phi.max_order}"]
        for t, v in self.phi.items():
            xi = ""
            if self.starting:
                xi = "    ξ = (" + ", ".join(str(format_entry(x)) for x in self.starting[t]) + ")"
            lines.append(f"  {self.phi.kind.bracket(t):12s} {format_entry(v)}{xi}")
        return "\n".join(lines)

    def to_json(self):
        def text(x):
            return str(format_entry(x))

        return {"method": self.method, "kind": self.kind, "max_order": self.phi.max_order,
                "phi": self.phi.to_json(), "u": [text(x) for x in self.u], "w": [text(x) for x in self.w],
                "starting_method": {bracket(t): [text(x) for x in xi] for t, xi in self.starting.items()}}

    def display(self) -> Document:
        """Text: Φ(t) (and ξ(t)) tree by tree; typeset: one formula, the (t, Φ(t)) array."""
        head, *lines = self._text().split("\n")
        rows = [f"{self.phi.kind.tex(t)} & {sp.latex(v)}" + r" \\" for t, v in self.phi.items()]
        array = r"\begin{array}{c|c} t & \Phi(t) \\ \hline " + "\n".join(rows) + r" \end{array}"
        return Document(head, (Plain(*(Paragraph(x) for x in lines)), Typeset(Formula(array))), math=True)


def glm_series(A, U, B, u, w, Pinv, max_order: int, zero, one) -> tuple:
    """(Φ, ξ) of the module docstring for a GLM given as row lists in any arithmetic with +, −, *
    (field elements here; floats in :mod:`..numeric.objectives`): u and w the right and left
    eigenvectors of V for 1 (wᵀu = 1), ``Pinv`` the r × (r+1) solver of (I − V)x = q, wᵀx = 0."""
    def mat(rows, v):
        out = []
        for row in rows:
            acc = zero
            for a, x in zip(row, v, strict=False):
                acc = acc + a * x
            out.append(acc)
        return out
    s = len(A)
    xi: Coefficients = {None: list(u)}
    phi: Coefficients = {None: one}
    eta: Coefficients = {}
    for t in trees_up_to(max_order):
        d = [one] * s
        for c in t:
            d = [x * y for x, y in zip(d, eta[c], strict=False)]
        q = mat(B, d)
        for trunk, coef in kept_cuts(t, lambda c: phi[c], one).items():
            if trunk != t:
                q = [a - coef * b for a, b in zip(q, xi[trunk], strict=False)]
        ph = mat([w], q)[0]
        phi[t] = ph
        x = mat(Pinv, [a - ph * b for a, b in zip(q, u, strict=False)] + [zero])
        xi[t] = x
        eta[t] = [a + b for a, b in zip(mat(A, d), mat(U, x), strict=False)]
    return phi, xi


def error_terms(phi: dict, n: int) -> list:
    """The principal error terms (Φ(t) − 1/γ(t))/σ(t) over the trees of order n, in the arithmetic of
    ``phi`` (exact or float: written with integers only); their 2-norm is the error norm the design
    search optimises ([HLW06] III.1; [B16] Sec. 31)."""
    return [(phi[t] * density(t) - 1) / (density(t) * symmetry(t)) for t in trees_of_order(n)]


def method_series(m: Method, max_order: int) -> MethodSeries:
    """The exact B-series of ``m`` to ``max_order`` (see the module docstring)."""
    check_series_order(max_order, f"the B-series of {m.name}")
    if isinstance(m, PartitionedRungeKutta):        # a P-series over bicoloured trees
        K = field_of([m.A, m.b, m.Ahat, m.bhat])
        F, phi_of = FastField(K), prk_weights(m, K)
        values: Coefficients = {t: F.lift(phi_of(t)) for t in BICOLOURED.trees_up_to(max_order)}
        values[None] = F.one
        return MethodSeries(m.name, "prk", BSeries(F, values, max_order, m.name, BICOLOURED), {}, (1,), (1,))
    if isinstance(m, RungeKutta):
        F, phi_of = weight_function(m)
        values = {t: phi_of(t) for t in trees_up_to(max_order)}
        values[None] = F.one
        return MethodSeries(m.name, "rk", BSeries(F, values, max_order, m.name), {}, (1,), (1,))
    g = m.as_glm()
    K = field_of([g.A, g.U, g.B, g.V])
    S = OrderSolver(g, K)
    phi, xi = glm_series(S.A.to_list(), S.U.to_list(), S.B.to_list(), S.u, S.w, S.Pinv, max_order,
                         K.zero, K.one)
    F = FastField(K)
    series = BSeries(F, {t: F.lift(v) for t, v in phi.items()}, max_order, m.name)
    lift = K.to_sympy
    starting = {t: tuple(lift(v) for v in xi[t]) for t in trees_up_to(max_order)}
    return MethodSeries(m.name, "glm", series, starting,
                        tuple(lift(x) for x in S.u), tuple(lift(x) for x in S.w))
