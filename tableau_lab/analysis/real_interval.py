r"""The real-axis stability interval [−β, 0] of a Runge–Kutta method, exactly.

β = sup{b ≥ 0 : |R(x)| ≤ 1 for all x ∈ [−b, 0]} with R = N/D the stability function
([HW96] IV.2; NodePy's ``real_stability_interval``).  On the real line |R| ≤ 1 is
D² − N² ≥ 0 with D ≠ 0; the negative real roots of D² − N² and of D (exact: rational or
``CRootOf``) cut (−∞, 0) into intervals of constant sign, tested at a rational point from 0
leftwards: β is the first cut beyond which the test fails, ∞ when none does (over a number
field the cuts come from the norms, and the signs are certified).

>>> from tableau_lab.exact.tableau_json import load
>>> r = real_stability_interval(load("rk4"))
>>> str(r.beta), round(float(r.beta), 9)
('-2*CRootOf(x**3 + 2*x**2 + 3*x + 3, 0)', 2.785293563)
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..exact.grammar import format_entry
from ..exact.methods import Method
from ..render.model import Document, Math, Paragraph, Typeset
from .results import Result

__all__ = ["real_stability_interval", "RealIntervalResult"]

_X = sp.Dummy("x")          # not a name that a CRootOf in the coefficients may use


@dataclass(frozen=True)
class RealIntervalResult(Result):
    method: str
    beta: sp.Expr | None    # exact (sympy number or oo); None when not computed
    reason: str = ""

    def _line(self) -> str:
        """The plain face, one line."""
        if self.beta is None:
            return f"real-axis interval: not computed ({self.reason})"
        if self.beta == sp.oo:
            return "real-axis interval: |R(x)| ≤ 1 on the whole negative axis"
        approx = "" if self.beta.is_Rational else f" ≈ {sp.N(self.beta, 10)}"
        return f"real-axis interval: [−β, 0] with β = {format_entry(self.beta)}{approx}"

    def to_json(self):
        exact = None if self.beta is None else ("oo" if self.beta == sp.oo else str(format_entry(self.beta)))
        return {"real_interval": exact, "real_interval_float": None if self.beta is None else float(self.beta),
                "real_interval_reason": self.reason}

    def display(self) -> Document:
        """The plain face: the line above; the typeset face: β in a sentence."""
        if self.beta is None:
            return Document(self._line(), (Typeset(Paragraph(f"Real-axis interval not computed ({self.reason}).")),))
        return Document(self._line(), (Typeset(Paragraph("Real-axis stability interval ", Math(r"[-\beta, 0]"), ", ",
                                                         Math(r"\beta = " + sp.latex(self.beta)), ".")),))


def real_stability_interval(m: Method) -> RealIntervalResult:
    """β of an RK method (module docstring).  When R has coefficients in a number field K
    (SDIRK34: ℚ(cos π/18)) the cuts are the negative real roots of the norms of D² − N² and D
    (ℚ-polynomials whose roots include theirs) and each sign at a rational probe is certified in K."""
    if m.kind != "rk":
        return RealIntervalResult(m.name, None, f"computed here for Runge–Kutta methods, not {m.kind}")
    from ..exact.real_roots import last_good_cut, sign_at
    from .stability import stability_function
    N, D, K = stability_function(m)
    n = sp.Poly.from_list(N.to_dense() if N else [K.zero], _X, domain=K)      # the ring's coefficients, as they are
    d = sp.Poly.from_list(D.to_dense(), _X, domain=K)
    g = d ** 2 - n ** 2

    def sgn(p, x):
        return sign_at(p, x, K)

    def fails(x):
        return sgn(d, x) == 0 or sgn(g, x) < 0

    cuts = set()
    for p in (g, d):
        if p.degree() > 0:
            q = p if K.is_QQ else p.norm()
            cuts |= {r for r in sp.Poly(q.as_expr(), _X).real_roots() if r < 0}
    end, _ = last_good_cut(sp.Integer(0), sorted(cuts, key=lambda r: -sp.N(r, 50)), fails, -1)   # from 0 leftwards
    return RealIntervalResult(m.name, sp.oo if end is None else -end)
