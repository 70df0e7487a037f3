r"""Parasitic growth parameters of a GLM ([BHHN14] Butcher, Habib, Hill & Norton, SIAM J.
Numer. Anal. 52 (2014) 2440–2465; [B21] ch. 7).

M(z) = V + zBU + O(z²).  For each simple eigenvalue ζ ≠ 1 of V on the unit circle, with right
and left eigenvectors x, y (y x = 1), the perturbed eigenvalue is ζ(1 + μz + O(z²)) with

    μ = ζ⁻¹ · y B U x.

The parasitic component then behaves like ζⁿ v(t) with v′ = μ f′(y(t)) v: it grows where
μ f′ has eigenvalues with positive real part.  μ = 0 for every such ζ: parasitism is
controlled to first order.  Computed exactly (ζ, x, y in a number field containing i); the
entries of A, U, B may be free parameters (μ is then a polynomial in them), V may not.

For a run: :func:`predicted_growth` is the growth rate of each component at a state, the
largest real part of the eigenvalues of μ·f′(y) (per unit time; times h per step), and
:func:`numeric_modes` gives ζ, μ and the left eigenvector y (y x = 1) as complex numbers for the
integrator's monitor, which measures the component y·y^[n] at its records.

>>> from tableau_lab.exact.tableau_json import load
>>> [str(p.mu) for p in growth_parameters(load("methods/example4_glm.json")).items]
['1 + 2*sqrt(3)/3']

(By hand: V = diag(1, −1), x = y = e₂, so μ = (−1)⁻¹ (BU)₂₂ = −(½·u₁₂ − ½·u₂₂) with
u₁₂ = −u₂₂ = −(1 + 2√3/3).)  On the pendulum at q = 2.3, f′ = [[0, 1], [−cos q, 0]] has the
real eigenvalues ±√(−cos 2.3), so the component grows at μ√(−cos 2.3) ≈ 1.76 per unit time:

>>> import math
>>> rates = predicted_growth(load("methods/example4_glm.json"), [[0, 1], [-math.cos(2.3), 0]])
>>> {z: round(v, 3) for z, v in rates.items()}
{'-1': 1.759}
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..exact.field import field_of, normal_form
from ..exact.grammar import format_entry
from ..exact.methods import Method
from ..exact.real_roots import unit_circle_eigenvalues as _unit_circle_eigenvalues
from ..render.model import Document, Formula, Paragraph, Plain, Typeset
from .growth import NumericMode, growth_rate
from .results import Result

__all__ = ["growth_parameters", "parasitism", "ParasitismResult", "Parasitic", "NumericMode", "numeric_modes",
           "growth_rate", "predicted_growth"]


@dataclass(frozen=True)
class Parasitic:
    zeta: sp.Expr     # eigenvalue of V on the unit circle, ζ ≠ 1
    mu: sp.Expr       # growth parameter ζ⁻¹ y B U x (y x = 1)
    left: tuple = ()  # the left eigenvector y (y V = ζ y), normalised by y x = 1
    right: tuple = ()  # the right eigenvector x (V x = ζ x)


@dataclass(frozen=True)
class ParasitismResult(Result):
    method: str
    items: tuple
    note: str = ""

    @property
    def free(self) -> bool:
        """True when every growth parameter is exactly zero."""
        return all(p.mu == 0 for p in self.items)

    def _lines(self) -> list[str]:
        """The plain face, a line each."""
        if not self.items:
            return [f"parasitism: none (V has no eigenvalue ≠ 1 on the unit circle){self.note}"]
        lines = ["parasitism: " + ("controlled to first order (all μ = 0)" if self.free
                                   else "growth parameters are not all zero")]
        lines += [f"  ζ = {_show(p.zeta)}: μ = {_show(p.mu)}" for p in self.items]
        return lines

    def to_json(self):
        return {"parasitism_free": self.free,
                "parasitism": [{"zeta": _show(p.zeta), "mu": _show(p.mu)} for p in self.items]}

    def display(self) -> Document:
        """The plain face: the lines above; the typeset face: the (ζ, μ) array, one formula."""
        rows = " \\\\ ".join(f"{sp.latex(p.zeta)} & {sp.latex(p.mu)}" for p in self.items)
        head, *lines = self._lines()
        return Document(head, (Plain(*map(Paragraph, lines)), Typeset(Formula(
            r"\begin{array}{c|c} \zeta & \mu \\ \hline " + rows + r" \end{array}"))), math=True)


def _show(x):
    x = sp.sympify(x)
    if x.has(sp.I):
        return str(x)
    return str(format_entry(x))


def growth_parameters(m: Method) -> ParasitismResult:
    """The parasitic growth parameters μ = ζ⁻¹ y B U x of each simple eigenvalue ζ ≠ 1 of V with
    |ζ| = 1 (x, y its right and left eigenvectors, y x = 1), exact ([BHHN14] Butcher, Habib, Hill
    & Norton, SIAM J. Numer. Anal. 52 (2014), Sec. 4; the module docstring).  ``tl.parasitism``;
    ``.free`` is true when every μ = 0 (parasitism controlled to first order).

    >>> import tableau_lab as tl
    >>> r = tl.parasitism(tl.load("example4_glm"))
    >>> [(str(p.zeta), str(p.mu)) for p in r.items], r.free     # by hand: the module docstring
    ([('-1', '1 + 2*sqrt(3)/3')], False)
    >>> tl.parasitism(tl.load("glm43")).free                      # the seed's GLM43 (§3.2.3): μ = 0
    True
    """
    g = m.as_glm()
    V, B, U = sp.Matrix(g.V), sp.Matrix(g.B), sp.Matrix(g.U)
    if V.free_symbols:
        raise ValueError(f"{m.name}: V has free parameters; growth parameters need a numeric V")
    raw = []
    for zeta, mult in _unit_circle_eigenvalues(V):
        right = (V - zeta * sp.eye(V.rows)).nullspace()
        if mult > 1 or len(right) > 1:
            raise ValueError(f"{m.name}: eigenvalue {zeta} of V is not simple; growth parameters need simple ones")
        x = right[0]
        left = (V.T - zeta * sp.eye(V.rows)).nullspace()
        y = left[0].T
        yx = sp.expand((y * x)[0])
        mu = sp.expand((y * B * U * x)[0] / (zeta * yx))
        raw.append((zeta, mu, [v / yx for v in y], list(x)))
    # one field for every quantity (a field per expression costs a primitive element each)
    everything = [e for zeta, mu, y, x in raw for e in (zeta, mu, *y, *x)]
    K = None if any(sp.sympify(e).free_symbols for e in everything) else field_of(everything)
    items = tuple(Parasitic(zeta=normal_form(zeta, K), mu=_normal(mu, K), left=tuple(_normal(v, K) for v in y),
                            right=tuple(_normal(v, K) for v in x)) for zeta, mu, y, x in raw)
    return ParasitismResult(method=m.name, items=items)


#: the public name (``tl.parasitism``, ``m.parasitism()``) of :func:`growth_parameters`
parasitism = growth_parameters


def numeric_modes(m: Method) -> tuple:
    """The modes of :func:`growth_parameters` (exact μ, left eigenvector) rounded to complex
    float64; empty when V has no eigenvalue ζ ≠ 1 on the unit circle (RK methods)."""
    return tuple(NumericMode(_show(p.zeta), complex(sp.N(p.zeta, 20)), complex(sp.N(p.mu, 20)),
                             np.array([complex(sp.N(v, 20)) for v in p.left]))
                 for p in growth_parameters(m).items)


def predicted_growth(method, jacobian_at_state) -> dict:
    """ζ (as printed) → the predicted growth rate of that parasitic component at a problem state
    with Jacobian f′(y) = ``jacobian_at_state``: max Re eig(μ f′(y)) per unit time ([BHHN14];
    multiply by h for the rate per step).  ``method``: a Method, or its numeric modes."""
    modes = numeric_modes(method) if isinstance(method, Method) else method
    return {md.label: growth_rate(md.mu, jacobian_at_state) for md in modes}


def _normal(e, K=None):
    """Normal form of an exact (possibly complex, possibly parametric) expression, in K if given."""
    e = sp.sympify(e)
    if e.free_symbols:
        re, im = (sp.expand(part) for part in sp.expand_complex(e).as_real_imag())
        return normal_form(re) + sp.I * normal_form(im)
    return normal_form(e, K)
