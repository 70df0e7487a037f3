r"""Modified equations and modifying integrators of a method, exactly ([HLW06] IX.1, IX.9;
Chartier, Hairer & Vilmart, *Found. Comput. Math.* 10 (2010)).

The numerical solution of y′ = f(y) by a method with B-series Φ is, formally, the exact flow of

    ỹ′ = f̃(ỹ) = Σ_t h^{|t|−1} b(t)/σ(t) F(t)(ỹ),        b ⋆ E = Φ,

and the method applied to y′ = Σ_t h^{|t|−1} c(t)/σ(t) F(t)(y), c ⋆ Φ = E, reproduces the exact
flow of y′ = f (the *modifying integrator*).  For a GLM, Φ is its underlying one-step method
(:mod:`method_series`).  The terms are listed by powers of h with coefficients b(t)/σ(t).

>>> from tableau_lab.exact.tableau_json import load
>>> print(modified_equation(load("methods/explicit_euler.json"), 3))
explicit Euler: modified equation, trees to order 3
  ỹ′ = f
     + h   ( -1/2 f'f )
     + h^2 ( 1/12 f''(f, f) + 1/3 f'f'f )
>>> modified_equation(load("methods/implicit_midpoint.json"), 5).terms[1:3]   # h²(−1/24 f″(f,f) + 1/12 f′f′f)
((2, '[τ²]', -1/24), (2, '[[τ]]', 1/12))
"""
from __future__ import annotations

from dataclasses import dataclass

from ..budget import MODIFIED_ORDER, computing
from ..exact.grammar import format_entry
from ..exact.methods import Method
from ..exact.render import LATEX, TEXT, exact_sum
from ..render.model import Document, Formula, Paragraph, Plain, Typeset
from .bseries import BSeries, modified_field, modifying_field
from .method_series import method_series
from .results import Result

__all__ = ["modified_equation", "ModifiedEquation", "MODIFIED_MAX_ORDER"]

#: the largest tree order of a modified equation from the command line (budget.MODIFIED_ORDER)
MODIFIED_MAX_ORDER = MODIFIED_ORDER


@dataclass(frozen=True)
class ModifiedEquation(Result):
    """The field f̃ (``kind`` "modified") or the modifying field (``kind`` "modifying") of a method,
    as h-power, tree, coefficient b(t)/σ(t)."""

    method: str
    kind: str
    max_order: int
    field: BSeries
    method_kind: str

    @property
    def terms(self) -> tuple:
        """((power of h, bracket, b(t)/σ(t)), ...) for the nonzero terms, by order."""
        k = self.field.kind
        return tuple((k.order(t) - 1, k.bracket(t), v / k.symmetry(t)) for t, v in self.field.items() if v != 0)

    def expression(self, f, y, h=None):
        """The modified field f̃(y) = Σ_t h^{|t|−1} b(t)/σ(t) F(t)(y) for the field ``f``: sympy
        expressions in the symbols ``y`` (a scalar f and y, or tuples), exact, up to the order of
        the series; ``h`` a symbol (default ``h``).  Plain B-series only (an RK method or a GLM).

        >>> import tableau_lab as tl, sympy as sp
        >>> y = sp.Symbol("y")
        >>> tl.modified_equation(tl.load("explicit_euler"), 4).expression(y**2, y)   # [HLW06] §IX.1: y′ = y²
        -8*h**3*y**5/3 + 3*h**2*y**4/2 - h*y**3 + y**2
        """
        import sympy as sp

        from .modified_hamiltonian import elementary_differential
        k = self.field.kind
        if k.coloured:
            raise TypeError(f"{self.method}: the P-series of a partitioned method has two fields; "
                            "expression() evaluates plain B-series")
        scalar = not isinstance(y, (tuple, list))
        ys, fs = ((y,), (f,)) if scalar else (tuple(y), tuple(f))
        h = sp.Symbol("h") if h is None else h
        total = [sp.Integer(0)] * len(ys)
        cache: dict = {}
        for t, v in self.field.items():
            if t is None or v == 0:
                continue
            F = elementary_differential(t, ys, fs, cache)
            c = v / k.symmetry(t) * h ** (k.order(t) - 1)
            total = [a + c * b for a, b in zip(total, F, strict=False)]
        total = [sp.expand(x) for x in total]
        return total[0] if scalar else tuple(total)

    def display(self) -> Document:
        """The series by powers of h: text lines ỹ′ = … + h( … ) + …; typeset one formula f̃ = …."""
        head, *lines = self._lines()
        return Document(head, (Plain(*(Paragraph(x) for x in lines)), Typeset(Formula(self._latex()))), math=True)

    def _lines(self) -> list[str]:
        what = "modified equation" if self.kind == "modified" else "modifying integrator (the field to integrate)"
        lhs = "ỹ′ =" if self.kind == "modified" else "y′ ="
        lines = [f"{self.method}: {what}, trees to order {self.max_order}"]
        if self.method_kind == "glm":
            lines[0] += " (underlying one-step method)"
        k = self.field.kind
        if k.coloured:
            lhs = "(q̃′, p̃′) =" if self.kind == "modified" else "(q′, p′) ="
            lines[0] += " (P-series: q′ = f(q, p), p′ = g(q, p); f-terms go to q̃′, g-terms to p̃′)"
        by_power = self._by_power(TEXT)
        lines.append(f"  {lhs} {by_power.pop(0, '0')}")
        for n, body in sorted(by_power.items()):
            lines.append(f"     + {('h' if n == 1 else 'h^' + str(n)).ljust(4)}( {body} )")
        return lines

    def _by_power(self, notation) -> dict:
        """power of h -> the sum of its terms b(t)/σ(t) F(t), printed in ``notation``."""
        k, tex = self.field.kind, notation is LATEX
        pairs: dict = {}
        for t, v in self.field.items():
            if v != 0:
                pairs.setdefault(k.order(t) - 1, []).append((v / k.symmetry(t), k.differential(t, tex=tex)))
        return {n: exact_sum(p, notation) for n, p in pairs.items()}

    def to_json(self):
        k = self.field.kind
        return {"method": self.method, "kind": self.kind, "max_order": self.max_order, "trees": k.name,
                "terms": [{"h_power": k.order(t) - 1, "tree": k.bracket(t),
                           "coefficient": str(format_entry(v / k.symmetry(t))), "differential": k.differential(t)}
                          for t, v in self.field.items() if v != 0],
                "series": self.field.to_json()}

    def _latex(self) -> str:
        by_power = self._by_power(LATEX)
        parts = [body if n == 0 else rf"{'h' if n == 1 else f'h^{{{n}}}'}\left({body}\right)"
                 for n, body in sorted(by_power.items())]
        lhs = r"\tilde f" if self.kind == "modified" else r"f_h"
        return f"{lhs} = " + r" \\ &\quad + ".join(parts) if parts else f"{lhs} = 0"


def modified_equation(m: Method, max_order: int, kind: str = "modified") -> ModifiedEquation:
    """The modified equation (``kind="modified"``) or the modifying integrator (``"modifying"``)
    of ``m`` with every tree of order ≤ ``max_order`` (terms up to h^(max_order − 1)):
    ``tl.modified_equation(m, n)``, ``m.modified_equation(n)``, ``tableau-lab modified``.  The
    field is f̃ = Σ_t h^{|t|−1} b(t)/σ(t) F(t) with b ⋆ E = Φ ([HLW06] Hairer, Lubich & Wanner,
    *Geometric Numerical Integration*, 2nd ed., §IX.1 and §IX.9, Thm 9.3; the modifying
    integrator: Chartier, Hairer & Vilmart, Found. Comput. Math. 10 (2010)).  ``terms`` lists
    (power of h, tree, coefficient); ``expression(f, y)`` evaluates the field for a given f.

    >>> import tableau_lab as tl
    >>> print(tl.modified_equation(tl.load("explicit_euler"), 3))     # [HLW06] IX.1, Example 1.1
    explicit Euler: modified equation, trees to order 3
      ỹ′ = f
         + h   ( -1/2 f'f )
         + h^2 ( 1/12 f''(f, f) + 1/3 f'f'f )
    """
    if kind not in ("modified", "modifying"):
        raise ValueError(f"kind must be 'modified' or 'modifying', not {kind!r}")
    with computing(f"{kind} equation of {m.name} to order {max_order}"):
        phi = method_series(m, max_order).phi
        field = modified_field(phi) if kind == "modified" else modifying_field(phi)
    return ModifiedEquation(m.name, kind, max_order, field, m.kind)
