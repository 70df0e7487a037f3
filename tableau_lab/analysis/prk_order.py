r"""Order of partitioned Runge–Kutta methods from bicoloured trees ([HLW06] III.2.1).

A bicoloured tree is (colour, children) with colour 0 for the first partition (A, b)
and 1 for the second (Â, b̂).  The elementary weight is Φ(t) = b_{col(root)}ᵀ Ψ(t) with
Ψ(t) = Π_children (A_{col(child)} Ψ(child)) (componentwise), and the method has order p
when Φ(t) = 1/γ(t) for every bicoloured tree with |t| ≤ p.

>>> from tableau_lab.exact.tableau_json import load
>>> prk_order(load("methods/stormer_verlet.json")).order
2
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import sympy as sp

from ..exact.field import element, field_of, to_dm
from ..exact.grammar import format_entry
from ..exact.methods import PartitionedRungeKutta
from ..render.model import Document, Paragraph, Plain, Typeset
from .results import Result
from .tree_kinds import BICOLOURED, Tree, bicoloured_trees, density

__all__ = ["prk_order", "PRKOrderResult", "bicoloured_trees", "weight_function", "condition_table"]


@dataclass(frozen=True, eq=False)      # Result.__eq__: equal to its order as an int
class PRKOrderResult(Result):
    int_field = "order"          # int(result) is the order
    method: str
    order: int
    errors: dict          # label -> Φ(t) − 1/γ(t) at order p + 1 (nonzero ones)
    max_order: int

    def _text(self) -> str:
        out = f"{self.method}: order {self.order} (bicoloured trees; ● first partition, ○ second)"
        if self.errors:
            out += f"\n  error terms at order {self.order + 1}: " + "; ".join(
                f"{k}: {format_entry(v)}" for k, v in self.errors.items())
        return out

    def to_json(self):
        return {"order": self.order, "error_terms": {k: str(format_entry(v)) for k, v in self.errors.items()}}

    def display(self) -> Document:
        head, *lines = self._text().split("\n")
        return Document(head, (Plain(*(Paragraph(x) for x in lines)),
                               Typeset(Paragraph(f"The partitioned method has order {self.order}."))))


def weight_function(m: PartitionedRungeKutta, K: Any) -> Callable[[Tree], Any]:
    """t ↦ Φ(t) over K for the bicoloured trees of :mod:`tree_kinds`: Φ(t) = b_{col(t)}ᵀΨ(t),
    Ψ(t) = Π over the children c of A_{col(c)}Ψ(c) (componentwise), by the one recursion
    :meth:`~tableau_lab.analysis.tree_kinds.TreeKind.elementary_weights`."""
    As = (to_dm(m.A, K).to_list(), to_dm(m.Ahat, K).to_list())
    bs = ([element(K, x) for x in m.b], [element(K, x) for x in m.bhat])
    return BICOLOURED.elementary_weights(As, bs, K.zero, K.one)


def _residuals(m: PartitionedRungeKutta, K):
    """Per order n, the list of (tree, Φ(t) − 1/γ(t)) over K (a generator, order by order)."""
    phi = weight_function(m, K)
    n = 0
    while True:
        n += 1
        yield [(t, phi(t) - K.convert(sp.Rational(1, density(t)))) for t in bicoloured_trees(n)]


def order_conditions(m: PartitionedRungeKutta, max_order: int) -> list:
    """(label, Φ(t) − 1/γ(t)) as exact sympy expressions for every bicoloured tree of order
    ≤ max_order (the free parameters stay symbolic)."""
    K = field_of([m.A, m.b, m.Ahat, m.bhat])
    out = []
    for n, level in zip(range(1, max_order + 1), _residuals(m, K), strict=False):
        out += [(f"order {n}, tree {BICOLOURED.bracket(t)}", K.to_sympy(r)) for t, r in level]
    return out


def condition_table(m: PartitionedRungeKutta, max_order: int) -> list:
    """(order, label, Φ(t), 1/γ(t), Φ(t) − 1/γ(t)) for every bicoloured tree of order ≤ max_order,
    computed over the method's field (exact sympy values)."""
    K = field_of([m.A, m.b, m.Ahat, m.bhat])
    phi = weight_function(m, K)
    return [(n, BICOLOURED.bracket(t), K.to_sympy(phi(t)), sp.Rational(1, density(t)),
             K.to_sympy(phi(t) - K.convert(sp.Rational(1, density(t)))))
            for n in range(1, max_order + 1) for t in bicoloured_trees(n)]


def prk_order(m: PartitionedRungeKutta, max_order: int = 6) -> PRKOrderResult:
    """Classical order of a partitioned RK method, exactly, pinned at p + 1."""
    K = field_of([m.A, m.b, m.Ahat, m.bhat])
    p = 0
    errors = {}
    for n, level in zip(range(1, max_order + 2), _residuals(m, K), strict=False):
        bad = {BICOLOURED.bracket(t): K.to_sympy(r) for t, r in level if not K.is_zero(r)}
        if bad:
            errors = bad
            break
        if n > max_order:
            break
        p = n
    return PRKOrderResult(m.name, p, errors, max_order)
