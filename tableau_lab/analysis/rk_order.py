r"""Classical and effective order of Runge–Kutta methods, elementary weights, simplifying
assumptions ([B16] ch. 3; [HNW93] II.2 and II.7; [HW96] IV.5; effective order: Butcher 1969,
[B21] Sec. 5.7, computed by :mod:`glm_order` with r = 1).

Φ(t) = bᵀΨ(t) with Ψ(τ) = 1 and Ψ([t₁…t_m]) = Π_k AΨ(t_k) (componentwise); the method has
classical order p when Φ(t) = 1/γ(t) for all |t| ≤ p.  The local error is
Σ_{|t|=p+1} h^{p+1}/σ(t) · (Φ(t) − 1/γ(t)) F(t)(y₀) + O(h^{p+2}), whose coefficients
(Φ(t) − 1/γ(t))/σ(t) are the principal error coefficients.

    B(p): Σᵢ bᵢcᵢ^{k−1} = 1/k,                     k ≤ p
    C(q): Σⱼ aᵢⱼcⱼ^{k−1} = cᵢ^k/k,                 k ≤ q, all i
    D(r): Σᵢ bᵢcᵢ^{k−1}aᵢⱼ = bⱼ(1 − cⱼ^k)/k,        k ≤ r, all j

The arithmetic runs in the method's number field at C speed (:class:`FastField`); the
5-stage Gauss method, whose nodes live in a degree-8 field, is pinned at order 10 through
all 1842 order-11 conditions in well under a second.

>>> from tableau_lab.exact.tableau_json import load
>>> r = rk_order(load("methods/gauss2.json"))
>>> r.order, r.B, r.C, r.D, r.stage_order
(4, 4, 2, 2, 2)
>>> print(r.weights[1][0], r.weights[1][2], r.weights[1][3])
[τ] 1/2 1/2
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import sympy as sp

from ..exact.conjugate import ANY
from ..exact.field import FastField, element, field_of, normal_form, power, to_dm
from ..exact.grammar import format_entry
from ..exact.methods import RungeKutta
from ..render.model import Document, Math, Paragraph, Plain, Table, Typeset
from .results import Result
from .tree_kinds import PLAIN, Tree
from .trees import bracket, density, latex, order as tree_order, symmetry, trees_of_order

__all__ = ["rk_order", "RKOrderResult", "simplifying_assumptions", "elementary_weights", "weight_function"]

#: trees of at most this order are listed in the LaTeX table (order 6 has 20 trees, 7 has 48)
LATEX_MAX_ORDER = 6
#: at order p + 1, every error coefficient is computed when there are at most this many trees; beyond,
#: the analysis stops at the first nonzero one (8-stage Gauss: 634 847 trees of order 17)
ERROR_TREES_BUDGET = 50_000


@dataclass(frozen=True, eq=False)      # Result.__eq__: equal to its order as an int
class RKOrderResult(Result):
    """Classical order with elementary weights, stage order, B/C/D and, when computed, the
    effective order (with the starting method's θ(t) when it exceeds the classical order)."""

    int_field = "order"          # int(result) is the order
    method: str
    order: int
    B: int
    C: int
    D: int
    stage_order: int
    capped: bool
    effective_order: int | None = None
    errors_partial: bool = False      # ERROR_TREES_BUDGET hit: only the first nonzero error coefficient
    embedded: RKOrderResult | None = None   # RKOrderResult of (A, b̂) for an embedded pair
    effective: Any = None             # GLMOrderResult when the effective order was computed
    _F: Any = field(default=None, repr=False, compare=False)      # the FastField of the weights
    _phi: tuple = field(default=(), repr=False, compare=False)   # ((tree, Φ fast), ...), |t| ≤ p + 1
    _bad: tuple = field(default=(), repr=False, compare=False)   # ((tree, Φ − 1/γ fast), ...) at p + 1

    @property
    def order_identity_start(self) -> int:
        """The classical order is the GLM order with the identity as starting method (θ ≡ 0)."""
        return self.order

    @cached_property
    def weights(self) -> tuple:
        """((bracket, LaTeX, Φ(t), 1/γ(t)), ...) for |t| ≤ p + 1, exact sympy values."""
        return tuple((bracket(t), latex(t), self._F.to_sympy(phi), sp.Rational(1, density(t)))
                     for t, phi in self._phi)

    @cached_property
    def conditions(self) -> tuple:
        """((|t|, bracket, LaTeX, Φ(t), 1/γ(t), Φ(t) − 1/γ(t)), ...) for every tree checked (|t| ≤ p + 1),
        the difference computed in the method's field (exact sympy values)."""
        return tuple((tree_order(t),) + w + (self._F.to_sympy(phi - self._F.rational(w[3])),)
                     for w, (t, phi) in zip(self.weights, self._phi, strict=False))

    @cached_property
    def residuals(self) -> dict:
        """bracket → Φ(t) − 1/γ(t) for the trees of order p + 1 where it is not zero."""
        return {bracket(t): self._F.to_sympy(v) for t, v in self._bad}

    @cached_property
    def error_coefficients(self) -> dict:
        """bracket → (Φ(t) − 1/γ(t))/σ(t): the principal error coefficients."""
        return {bracket(t): self._F.to_sympy(v) / symmetry(t) for t, v in self._bad}

    @cached_property
    def principal_error_norm(self):
        """A^(p+1) = ‖τ^(p+1)‖₂, the 2-norm of the principal error coefficients (Φ(t) − 1/γ(t))/σ(t)
        over the trees of order p + 1 ([HNW93] II.3; NodePy's principal_error_norm), exact; None
        when not every coefficient was computed (ERROR_TREES_BUDGET) or the order is capped."""
        if self.errors_partial or not self._bad:
            return None
        total: Any = sum(self._F.to_sympy(v) ** 2 / symmetry(t) ** 2 for t, v in self._bad)
        return sp.sqrt(total if total.is_Rational else normal_form(total))

    @property
    def consistency(self) -> str:
        """For order 0 (Σbᵢ ≠ 1): the failing order-1 condition with its exact residual, else ""."""
        if self.order or "τ" not in self.residuals:
            return ""
        r = self.residuals["τ"]
        generic = " (for generic parameter values)" if sp.sympify(r).free_symbols else ""
        return f"order-1 condition Σbᵢ = 1 fails{generic}: Σbᵢ − 1 = {format_entry(r)}"

    @property
    def _effective_gain(self) -> bool:
        """The effective order (with a starting method) exceeds the classical order."""
        return self.effective_order is not None and self.effective_order > self.order

    def _text(self) -> str:
        cap = " (at least: cap reached)" if self.capped else ""
        head = f"{self.method}: classical order {self.order}{cap}"
        if self.effective_order is not None:
            head += f", effective order {self.effective_order}"
        out = [head + f"; stage order {self.stage_order}; B({self.B}), C({self.C}), D({self.D})"]
        if self.consistency:
            out.append("  " + self.consistency)
        if self._bad:
            shown = list(self.error_coefficients.items())
            more = f" … ({len(shown)} trees)" if len(shown) > 8 else ""
            if self.errors_partial:
                more = (f" (the first nonzero one: the {len(trees_of_order(self.order + 1))} trees of order "
                        f"{self.order + 1} exceed the budget ERROR_TREES_BUDGET = {ERROR_TREES_BUDGET})")
            out.append(f"  principal error coefficients (order {self.order + 1}): "
                       + "; ".join(f"{t}: {format_entry(v)}" for t, v in shown[:8]) + more)
            if self.principal_error_norm is not None:
                out.append(f"  principal error norm ‖τ^({self.order + 1})‖₂ = {format_entry(self.principal_error_norm)}"
                           f" ≈ {sp.N(self.principal_error_norm, 6)}")
        if self.embedded is not None:
            e = self.embedded
            norm = "" if e.principal_error_norm is None else (
                f"; the error estimate's principal part ‖τ̂^({e.order + 1})‖₂ = {format_entry(e.principal_error_norm)}"
                f" ≈ {sp.N(e.principal_error_norm, 6)}")
            out.append(f"  embedded b̂: order {e.order}{norm}")
        if self.effective is not None and self._effective_gain:
            out.append("  starting method for the effective order (y0 ↦ B(ξ, y0)), θ(t) = ξ(t):")
            out.extend(f"    {t:10s} {format_entry(v)}" for t, v in self.effective.theta.items())
        return "\n".join(out)

    def to_json(self):
        def text(x):
            return str(format_entry(x))

        out = {"order": self.order, "order_identity_start": self.order, "stage_order": self.stage_order,
               "effective_order": self.effective_order, "B": self.B, "C": self.C, "D": self.D,
               "capped": self.capped, "error_coefficients_partial": self.errors_partial,
               "principal_error_norm": None if self.principal_error_norm is None else text(self.principal_error_norm),
               "embedded_order": None if self.embedded is None else self.embedded.order,
               "embedded_error_norm": (None if self.embedded is None or self.embedded.principal_error_norm is None
                                       else text(self.embedded.principal_error_norm)),
               "residuals": {k: text(v) for k, v in self.residuals.items()},
               "error_coefficients": {k: text(v) for k, v in self.error_coefficients.items()}}
        if self.effective is not None and self._effective_gain:
            eff = self.effective.to_json()
            out["starting_method"] = {t: v[0] for t, v in eff["starting_method"].items()}
            out["finishing_method"] = eff["finishing_method"]
        return out

    def display(self) -> Document:
        """Text: the orders, error coefficients and norms; typeset: the orders and the table of the
        elementary weights Φ(t) against 1/γ(t) for the trees to order LATEX_MAX_ORDER."""
        head, *lines = self._text().split("\n")
        rows = tuple((Math(tex), Math(sp.latex(phi)), Math(sp.latex(g)))
                     for (b, tex, phi, g), (t, _) in zip(self.weights, self._phi, strict=False)
                     if tree_order(t) <= LATEX_MAX_ORDER)
        hidden = sum(1 for t, _ in self._phi if tree_order(t) > LATEX_MAX_ORDER)
        eff = ("" if self.effective_order is None else f", effective order {self.effective_order}")
        note = [Paragraph("Trees of order ", Math(f">{LATEX_MAX_ORDER}"),
                          f": {hidden} more conditions, checked exactly, not listed.")] if hidden else []
        return Document(head, (Plain(*(Paragraph(x) for x in lines)), Typeset(
            Paragraph(f"Classical order {self.order}{eff}; stage order {self.stage_order}; simplifying assumptions ",
                      Math(f"B({self.B})"), ", ", Math(f"C({self.C})"), ", ", Math(f"D({self.D})"), "."),
            Table((Math("t"), Math(r"\Phi(t)"), Math(r"1/\gamma(t)")), rows, "lll"), *note)))

def simplifying_assumptions(m: RungeKutta, K=None) -> tuple[int, int, int]:
    """The largest p, q, r (capped at 2s+1, s+1, s+1) with B(p), C(q), D(r)."""
    if m.conjugate is not None:
        return _conjugate_assumptions(m.conjugate)
    K = K or field_of([m.A, m.b, m.c])
    F = FastField(K)
    s = m.s
    A = [[F.lift(x) for x in row] for row in to_dm(m.A, K).to_list()]
    b = [F.lift(element(K, x)) for x in m.b]
    c = [F.lift(element(K, x)) for x in m.c]

    def frac(k):                                 # 1/k in F
        return F.rational(sp.Rational(1, k))

    def dot(xs, ys):
        return sum((x * y for x, y in zip(xs, ys, strict=False)), F.zero)

    def pw(x, k):
        return power(F, x, k)

    def holds_B(k):
        return F.is_zero(dot(b, [pw(ci, k - 1) for ci in c]) - frac(k))

    def holds_C(k):
        ck = [pw(cj, k - 1) for cj in c]
        return all(F.is_zero(dot(A[i], ck) - c[i] ** k * frac(k)) for i in range(s))

    def holds_D(k):
        w = [bi * pw(ci, k - 1) for bi, ci in zip(b, c, strict=False)]
        return all(F.is_zero(dot(w, [A[i][j] for i in range(s)]) - b[j] * (F.one - c[j] ** k) * frac(k))
                   for j in range(s))

    return _largest(holds_B, 2 * s + 1), _largest(holds_C, s + 1), _largest(holds_D, s + 1)


def _stability_order(m, n: int) -> int:
    """The largest q ≤ n with R(z) = e^z + O(z^{q+1}): the power series of N/D (exact)."""
    from .stability import stability_function
    N, D, K = stability_function(m)
    Nc, Dc = ([K.to_sympy(c) for c in reversed(P.to_dense())] + [0] * (n + 2) for P in (N, D))   # z⁰ first
    R: list[sp.Expr] = []
    for k in range(n + 2):                       # R·D = N, D(0) = 1
        R.append(sp.expand((Nc[k] - sum(Dc[j] * R[k - j] for j in range(1, k + 1))) / Dc[0]))
        if sp.expand(R[k] - sp.Rational(1, sp.factorial(k))) != 0:
            return k - 1
    return n + 1


def _largest(test, cap):
    k = 0
    while k < cap and test(k + 1):
        k += 1
    return k


def _scaled(e, q):
    """q·e for an element e of ℚ[X]/(P)."""
    return e * e.alg.element([q])


def _conjugate_assumptions(alg) -> tuple[int, int, int]:
    """B, C, D in ℚ[X]/(P) (:mod:`~tableau_lab.exact.conjugate`): B(k): b̃(X^{k−1}) = 1/k;
    C(k): ÃX^{k−1} = X^k/k; D(k): b̃(X^{k−1}·Ãφ) = b̃(φ(1 − X^k))/k for φ = 1, X, …, X^{s−1}
    (Σᵢ bᵢcᵢ^{k−1}aᵢⱼ = bⱼ(1 − cⱼ^k)/k for all j, tested against a basis)."""
    s = alg.s
    one, _, A, b = alg.operators()
    x = A * one                                  # c = A·1 (the nodes X for a method with C(1))
    pw = [one]
    for _ in range(2 * s + 1):
        pw.append(pw[-1] * x)

    def rational(v):                             # an element of ℚ (p/q) as a sympy Rational
        return sp.Rational(int(v.p), int(v.q))

    def holds_B(k):
        return rational(b * pw[k - 1]) == sp.Rational(1, k)

    def holds_C(k):
        return alg.is_zero(A * pw[k - 1] - _scaled(pw[k], sp.Rational(1, k)))

    def holds_D(k):
        return all(rational(b * (pw[k - 1] * (A * pw[m])))
                   == (rational(b * pw[m]) - rational(b * pw[m + k])) * sp.Rational(1, k) for m in range(s))

    return _largest(holds_B, 2 * s + 1), _largest(holds_C, s + 1), _largest(holds_D, s + 1)


def elementary_weights(A: list, b: list, zero: Any, one: Any) -> Callable[[Tree], Any]:
    """t ↦ Φ(t) = bᵀΨ(t) for A, b given as lists of field elements (any arithmetic with +, *): the
    plain-tree case of the one recursion :meth:`~tableau_lab.analysis.tree_kinds.TreeKind.elementary_weights`."""
    return PLAIN.elementary_weights(A, b, zero, one)


def weight_function(m: RungeKutta):
    """(F, t ↦ Φ(t)): the elementary weights of ``m`` as elements of the FastField F, over ℚ by
    the conjugate form when the nodes are all the roots of one polynomial, else over the method's
    number field."""
    if m.conjugate is not None:                 # nodes = all roots of one polynomial: in ℚ
        F = FastField(sp.QQ)
        one, _, Aop, bfun = m.conjugate.operators()
        return F, elementary_weights([[Aop]], [bfun], ANY, one)
    K = field_of([m.A, m.b, m.c])
    F = FastField(K)
    A = [[F.lift(x) for x in row] for row in to_dm(m.A, K).to_list()]
    b = [F.lift(element(K, x)) for x in m.b]
    return F, elementary_weights(A, b, F.zero, F.one)


def rk_order(m: RungeKutta, max_order: int | None = None, effective: bool = True) -> RKOrderResult:
    """Classical order by elementary weights over the method's number field, pinned at p + 1
    (default cap: the bound 2s, or s for explicit methods), with the stage order, B, C, D and,
    unless ``effective=False``, the effective order (Butcher's algebraic theory with r = 1)."""
    if m.kind != "rk":
        raise TypeError(f"rk_order applies to Runge–Kutta methods, not {m.kind!r}")
    F, phi_of = weight_function(m)
    K = F.K
    bound = m.order_bound
    cap = max_order if max_order is not None else bound
    phis, p, bad, partial = [], 0, [], False
    for n in range(1, cap + 2):
        trees = trees_of_order(n)
        for t in trees:
            phi = phi_of(t)
            r = phi - F.rational(sp.Rational(1, density(t)))
            phis.append((t, phi))
            if not F.is_zero(r):
                bad.append((t, r))
                if len(trees) > ERROR_TREES_BUDGET:
                    partial = True
                    break
        if bad or n > cap:
            break
        p = n
    Bp, Cq, Dr = simplifying_assumptions(m, K)
    eff_order, eff = None, None
    if effective and m.conjugate is not None and p < bound:
        # the GLM solve of the effective order needs the field of all the nodes; but p ≤ effective
        # order ≤ the order of R(z) − e^z (on y′ = λy a starting method commutes with the step)
        effective = False
        eff_order = p if _stability_order(m, bound) == p else None
    if effective:
        if p >= bound:
            eff_order = p
        else:
            from .glm_order import glm_order
            eff = glm_order(m, max_order=cap)
            eff_order = eff.order
    pair = m.embedded()
    emb = rk_order(pair, max_order, effective=False) if pair is not None else None
    return RKOrderResult(method=m.name, order=p, B=Bp, C=Cq, D=Dr, stage_order=min(Cq, p), embedded=emb,
                         capped=not bad, effective_order=eff_order, effective=eff, errors_partial=partial,
                         _F=F, _phi=tuple(phis), _bad=tuple(bad))
