r"""Linear stability of a tableau with free parameters, over the parameters' field.

A designer with a family (entries in ℚ(a, b, …), possibly with radicals) wants the stability
function of the whole family, not a refusal.  Over K = ℚ(params) — a field of rational functions,
so every identity below holds for all parameter values where the denominators do not vanish —
these are computed exactly, with the same code as for numbers (``DomainMatrix`` determinants
over K[w, z]):

* P(w, z) = det[[I − zA, −U], [−zB, wI − V]] (:func:`stability.characteristic_polynomial`);
* RK methods: R(z) = N(z)/D(z) and E(y) = |D(iy)|² − |N(iy)|², the polynomial whose
  nonnegativity on the real line is A-stability's axis condition ([HW96] IV.3);
* RK methods: the order of R as an approximation of e^z (R(z) − e^z = O(z^{p̂+1}) for every
  parameter value: the first Taylor coefficient of N − D·e^z that is not identically 0), and
  R(∞) = lim R(z) (as a function of the parameters, when deg N ≤ deg D);
* GLMs: det(wI − V), and zero-stability decided exactly when V has no parameter.

What needs numbers: A-stability, the imaginary-axis interval Y*, the real interval β, the SSP
coefficient, the internal amplification, algebraic stability, the A(α) angle and the parasitic
growth parameters are sign and root-location questions whose answers change with the
parameters (semi-algebraic sets in parameter space); give the parameters values
(``tableau-lab solve``, or write them into the tableau) to decide them.

>>> import sympy as sp
>>> from tableau_lab.exact.methods import RungeKutta
>>> a = sp.Symbol("a")
>>> m = RungeKutta.from_lists([[0, 0], [a, 0]], [1 - 1/(2*a), 1/(2*a)], name="explicit 2-stage")
>>> r = parametric_stability(m)
>>> r.stability_function, r.order_of_r
(z**2/2 + z + 1, 2)
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..exact.methods import Method
from ..render.model import Block, Document, Formula, Math, Paragraph, Plain, Typeset
from .results import Result
from .zero_stability import ZeroStabilityResult, zero_stability

__all__ = ["parametric_stability", "ParametricStability", "NEEDS_NUMBERS"]

NEEDS_NUMBERS = ("A-stability", "imaginary-axis interval Y*", "real-axis interval β", "SSP coefficient",
                 "internal amplification", "algebraic stability", "A(α) angle", "parasitic growth parameters")

_Z, _Y = sp.symbols("z y")


@dataclass(frozen=True)
class ParametricStability(Result):
    """The stability analyses that hold over the parameters' field (module docstring)."""

    method: str
    kind: str
    parameters: tuple                # the free parameters (sympy symbols)
    field: str                       # K, e.g. QQ(a)
    polynomial: sp.Expr              # P(w, z) (x = hω for partitioned methods)
    variable: str = "z"
    stability_function: sp.Expr | None = None     # RK: R(z)
    e_polynomial: sp.Expr | None = None           # RK: E(y)
    order_of_r: int | None = None                 # RK: R(z) = e^z + O(z^(p+1)) identically
    r_at_infinity: sp.Expr | None = None          # RK: lim R(z) as z → ∞ (None: R unbounded)
    v_polynomial: sp.Expr | None = None           # GLM: det(wI − V)
    zero: ZeroStabilityResult | None = None       # GLM with V free of parameters: zero-stability
    needs_numbers: tuple = NEEDS_NUMBERS

    def _lines(self) -> list[str]:
        """The plain face, a line each."""
        names = ", ".join(str(p) for p in self.parameters)
        lines = [f"linear stability over {self.field} (free parameters {names}; every formula holds for all "
                 "parameter values where its denominators do not vanish):",
                 f"  P(w, {self.variable}) = {self.polynomial}"]
        if self.stability_function is not None:
            assert self.order_of_r is not None, "set with the stability function (RK)"
            lines += [f"  R(z) = {self.stability_function}",
                      f"  E(y) = |D(iy)|² − |N(iy)|² = {self.e_polynomial}",
                      f"  R(z) − e^z = O(z^{self.order_of_r + 1}) for every parameter value (order {self.order_of_r})",
                      "  R(∞) = " + ("∞ (deg N > deg D)" if self.r_at_infinity is None else f"{self.r_at_infinity}")]
        if self.v_polynomial is not None:
            lines.append(f"  det(wI − V) = {self.v_polynomial}")
        if self.zero is not None:
            lines.append("  " + str(self.zero).replace("\n", "\n  "))
        lines.append("needs numbers for the parameters (decided per value; give them values, e.g. with "
                     "`tableau-lab solve`): " + ", ".join(self.needs_numbers))
        return lines

    def to_json(self):
        return {"parametric": True, "parameters": [str(p) for p in self.parameters], "field": self.field,
                "characteristic_polynomial": str(self.polynomial), "variable": self.variable,
                "stability_function": None if self.stability_function is None else str(self.stability_function),
                "E_polynomial": None if self.e_polynomial is None else str(self.e_polynomial),
                "order_of_stability_function": self.order_of_r,
                "R_at_infinity": None if self.r_at_infinity is None else str(self.r_at_infinity),
                "V_polynomial": None if self.v_polynomial is None else str(self.v_polynomial),
                "zero_stable": None if self.zero is None else self.zero.holds,
                "needs_numbers": list(self.needs_numbers)}

    def display(self) -> Document:
        """The plain face: the lines above; the typeset face: P(w, z) (R(z) and E(y) for RK) over the
        parameters' field, and what needs numbers."""
        typeset: list[Block] = [
            Paragraph("Free parameters ", Math(", ".join(sp.latex(p) for p in self.parameters)), "; over ",
                      Math(self.field), ":"),
            Formula(f"P(w,{self.variable}) = {sp.latex(self.polynomial)}")]
        if self.stability_function is not None:
            typeset.append(Formula(f"R(z) = {sp.latex(self.stability_function)}, "
                                   f"\\qquad E(y) = {sp.latex(self.e_polynomial)}"))
        typeset.append(Paragraph("Needs numbers: " + ", ".join(self.needs_numbers) + "."))
        head, *lines = self._lines()
        return Document(head, (Plain(*map(Paragraph, lines)), Typeset(*typeset)))


def _order_of_r(N, D) -> int:
    """The largest p with N − D·e^z = O(z^(p+1)) identically in the parameters (D(0) = 1)."""
    n = max(sp.degree(N, _Z), sp.degree(D, _Z)) + 2
    series = sp.expand(sp.series(sp.exp(_Z), _Z, 0, 2 * n + 2).removeO())
    diff = sp.Poly(sp.expand(N - D * series), _Z)
    for k in range(2 * n + 2):
        if sp.cancel(diff.coeff_monomial(_Z ** k)) != 0:
            return k - 1
    return 2 * n + 1


def parametric_stability(m: Method) -> ParametricStability:
    """Stability of a method with free parameters over their field (module docstring)."""
    from .stability import Z, characteristic_polynomial, e_polynomial, stability_function
    P, K = characteristic_polynomial(m, parametric=True)
    variable = "x" if m.kind == "prk" else "z"
    common = dict(method=m.name, kind=m.kind, parameters=tuple(m.parameters), field=str(K),
                  polynomial=sp.factor_terms(P.as_expr()), variable=variable)
    if m.kind == "rk":
        Np, Dp, KR = stability_function(m)
        E = e_polynomial(Np, Dp, KR)
        N, D = sp.cancel(Np.as_expr()), sp.cancel(Dp.as_expr())
        R = sp.cancel(N / D)
        dn, dd = sp.degree(sp.numer(sp.together(R)), Z), sp.degree(sp.denom(sp.together(R)), Z)
        at_inf = None if dn > dd else (sp.Integer(0) if dn < dd else sp.cancel(
            sp.Poly(sp.numer(sp.together(R)), Z).LC() / sp.Poly(sp.denom(sp.together(R)), Z).LC()))
        return ParametricStability(**common, stability_function=R, e_polynomial=sp.factor_terms(E.as_expr()),
                                   order_of_r=_order_of_r(N, D), r_at_infinity=at_inf)
    if m.kind == "glm":
        w = sp.Symbol("w")
        V = sp.Matrix(m.as_glm().V)
        zero = None
        if not V.free_symbols:
            zero = zero_stability(m)
        return ParametricStability(**common, v_polynomial=sp.factor((w * sp.eye(V.rows) - V).det()), zero=zero)
    return ParametricStability(**common)
