r"""Internal stability of a Runge–Kutta method: how much errors made in the stages are amplified.

A perturbation δⱼ of stage j (round-off, an inexact stage solve) reaches the step's result on
y′ = λy as Qⱼ(z)δⱼ with the internal stability functions

    Qⱼ(z) = z bᵀ(I − zA)⁻¹eⱼ,        z = hλ

(Verwer, Hundsdorfer & Sommeijer 1990; Ketcheson, Loczi & Parsani, SIAM J. Matrix Anal. Appl. 35
(2014); NodePy's ``internal_stability_polynomials``).  They are computed exactly, and their
largest modulus on the real stability interval [−β, 0] is found exactly where the Qⱼ have
rational coefficients (NodePy's ``maximum_internal_amplification`` takes the maximum over the
whole complex stability region instead: a different, numerical quantity): |Qⱼ| attains its
maximum on the interval at an end or at a real root of Qⱼ′, all exact; the amplification is max
over j.

>>> from tableau_lab.exact.tableau_json import load
>>> r = internal_stability(load("rk4"))
>>> r.functions[0]
z**4/24 + z**3/12 + z**2/6 + z/6
>>> round(float(r.amplification), 6)
1.535784
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..exact.grammar import format_entry
from ..exact.methods import Method, RungeKutta
from ..render.model import Document, Math, Paragraph, Typeset
from .results import Result

__all__ = ["internal_stability", "InternalStabilityResult"]

_Z = sp.Symbol("z")


@dataclass(frozen=True)
class InternalStabilityResult(Result):
    method: str
    functions: tuple          # Qⱼ(z), exact rational functions (polynomials for explicit methods)
    interval: sp.Expr | None          # β of the real interval the maximum is taken on (oo: not bounded)
    amplification: sp.Expr | None     # max_j max_{x ∈ [−β, 0]} |Qⱼ(x)|, exact; None when not computed
    reason: str = ""

    def _line(self) -> str:
        """The plain face, one line."""
        head = "internal stability: Qⱼ(z) = z bᵀ(I − zA)⁻¹eⱼ"
        if self.amplification is None:
            return f"{head}; the largest |Qⱼ| on the real interval: not computed ({self.reason})"
        v = self.amplification
        approx = "" if v.is_Rational else f" ≈ {sp.N(v, 8)}"
        return f"{head}; max |Qⱼ(x)| on [−β, 0], β = {format_entry(self.interval)}: {format_entry(v)}{approx}"

    def to_json(self):
        return {"internal_stability_functions": [str(q) for q in self.functions],
                "internal_amplification": None if self.amplification is None else str(format_entry(self.amplification)),
                "internal_amplification_float": None if self.amplification is None else float(self.amplification),
                "internal_reason": self.reason}

    def display(self) -> Document:
        """The plain face: the line above; the typeset face: the Qⱼ and their largest modulus."""
        rows = ", ".join(f"Q_{{{j + 1}}} = {sp.latex(q)}" for j, q in enumerate(self.functions))
        tail = (() if self.amplification is None
                else ("; ", Math(f"\\max|Q_j| = {sp.latex(self.amplification)}"), " on ", Math(r"[-\beta, 0]")))
        return Document(self._line(), (Typeset(Paragraph("Internal stability functions ", Math(rows), *tail, ".")),))


def _functions(m: RungeKutta) -> tuple:
    """Qⱼ = z·(bᵀ adj(I − zA))ⱼ / det(I − zA) in lowest terms, from the adjugate and determinant of
    I − zA over K[z] (a ``DomainMatrix``: 0.2 s for NodePy's 17-stage DC(4), where sympy's symbolic
    ``Matrix.adjugate`` took minutes)."""
    from sympy.polys.matrices import DomainMatrix

    from ..exact.field import field_of, to_dm
    K = field_of([m.A, m.b])
    R = K[str(_Z)]
    z, s = R.gens[0], m.s
    A, b = to_dm(sp.Matrix(m.A), K).to_list(), to_dm(sp.Matrix(m.b).T, K).to_list()[0]
    M = DomainMatrix([[(R.one if i == j else R.zero) - z * R(A[i][j]) for j in range(s)] for i in range(s)], (s, s), R)
    adj, det = M.adj_det()
    row = (DomainMatrix([[R(x) for x in b]], (1, s), R) * adj).to_list()[0]
    out = []
    for q in row:
        g = (z * q).gcd(det)                      # in lowest terms first: sympy's cancel is then cheap
        out.append(sp.cancel((z * q).exquo(g).as_expr() / det.exquo(g).as_expr()))
    return tuple(out)


def internal_stability(m: Method) -> InternalStabilityResult:
    """Qⱼ(z) and their largest modulus on the real stability interval (module docstring)."""
    if not isinstance(m, RungeKutta):
        return InternalStabilityResult(m.name, (), None, None, f"defined here for Runge–Kutta methods, not {m.kind}")
    from .real_interval import real_stability_interval
    Q = _functions(m)
    beta = real_stability_interval(m).beta
    if beta is None:
        return InternalStabilityResult(m.name, Q, None, None, "the real interval is not computed")
    if beta == sp.oo:
        return InternalStabilityResult(m.name, Q, beta, None, "the real interval is unbounded")
    if not all(c.is_Rational for q in Q for c in sp.Poly(sp.numer(q) * sp.denom(q), _Z).coeffs()):
        return InternalStabilityResult(m.name, Q, beta, None, "Qⱼ have irrational coefficients")
    best = sp.Integer(0)
    for q in Q:
        num, den = sp.fraction(sp.together(q))
        deriv = sp.Poly(sp.expand(sp.diff(num, _Z) * den - num * sp.diff(den, _Z)), _Z)
        points = [-beta, sp.Integer(0)]
        if deriv.degree() > 0:
            points += [r for r in deriv.real_roots() if -beta < r < 0]
        for x in points:
            v = sp.Abs(q.subs(_Z, x))
            if sp.N(v - best, 60) > 0:
                best = v
    return InternalStabilityResult(m.name, Q, beta, best)
