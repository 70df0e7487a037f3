r"""Symmetry of RK methods and GLMs ([HLW06] V.1–V.2; Butcher, Hill & Norton, "Symmetric general
linear methods", BIT 56 (2016)).

The adjoint of a GLM (A, U, B, V) is the method that undoes a step with h → −h:

    A* = UV⁻¹B − A,   U* = UV⁻¹,   B* = V⁻¹B,   V* = V⁻¹.

The method is symmetric when its adjoint is itself up to reversing the stages (P, the
anti-diagonal permutation) and an involution L of the input values:
A* = PAP, U* = PUL, B* = LBP, V* = LVL.  For an RK method (r = 1, L = 1) this is
aᵢⱼ + a_{s+1−i,s+1−j} = bⱼ, bᵢ = b_{s+1−i} ([HLW06] Thm V.2.3).  Here L ranges over the
diagonal sign matrices with L₁₁ = 1 (the principal value is kept): a restriction, said in the
result.

>>> from tableau_lab.exact.tableau_json import load
>>> [symmetric(load(f"methods/{n}.json")).holds for n in ("gauss2", "rk4", "example4_glm")]
[True, False, True]
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import sympy as sp

from ..exact.field import is_zero
from ..exact.methods import Method, glm_parts
from ..exact.render import matrix_latex, matrix_text
from ..render.model import Document, Math, Paragraph, Plain, Typeset
from .results import Result

__all__ = ["symmetric", "SymmetryResult", "symmetry_conditions"]


@dataclass(frozen=True)
class SymmetryResult(Result):
    method: str
    holds: bool
    L: sp.Matrix | None
    note: str = ""

    def display(self) -> Document:
        if not self.holds:
            return Document("symmetric: no" + (f" ({self.note})" if self.note else ""),
                            (Typeset(Paragraph("The method is not symmetric.")),))
        shown = self.L is not None and self.L.rows > 1
        with_l = () if self.L is None else (" with ", Math(f"L = {matrix_latex(self.L)}"))
        return Document("symmetric: yes" + (", L =" if shown else ""),
                        (Plain(*([Paragraph(matrix_text(self.L))] if shown else [])),
                         Typeset(Paragraph("The method is symmetric", *with_l, "."))))

    def to_json(self):
        return {"holds": self.holds, "L": None if self.L is None else [[str(x) for x in self.L.row(i)]
                                                                        for i in range(self.L.rows)], "note": self.note}


def symmetry_conditions(m: Method) -> list[tuple[sp.Matrix, list]]:
    """For each candidate involution L, the entries (exact expressions) that must vanish.
    For an RK method (L = 1) they are aᵢⱼ + a_{s+1−i,s+1−j} − bⱼ and bᵢ − b_{s+1−i}."""
    A, U, B, V = glm_parts(m)
    s, r = A.rows, V.rows
    if V.free_symbols:
        raise ValueError("symmetry needs a numeric V (V⁻¹ is formed)")
    if V.det() == 0:
        raise ValueError("V is singular: the method has no adjoint of this form")
    Vi = V.inv()
    P = sp.Matrix(s, s, lambda i, j: 1 if i + j == s - 1 else 0)
    out = []
    for signs in itertools.product([1, -1], repeat=r - 1):
        L = sp.diag(1, *signs)
        conds = [U * Vi * B - A - P * A * P, U * Vi - P * U * L, Vi * B - L * B * P, Vi - L * V * L]
        out.append((L, [sp.expand(x) for M in conds for x in M]))
    return out


def symmetric(m: Method) -> SymmetryResult:
    """Whether m is symmetric (for some diagonal sign involution L when r > 1)."""
    try:
        cands = symmetry_conditions(m)
    except ValueError as exc:
        return SymmetryResult(m.name, False, None, str(exc))
    for L, conds in cands:
        if all(is_zero(x) for x in conds):
            return SymmetryResult(m.name, True, L)
    return SymmetryResult(m.name, False, None, "no diagonal sign involution L works" if m.kind == "glm" else "")
