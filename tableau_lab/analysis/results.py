"""Result objects shared by the analyses: each prints itself, serialises to JSON
(exact values as strings in the tableau grammar) and renders to LaTeX."""
from __future__ import annotations

import json

import sympy as sp

from ..exact.grammar import format_matrix

__all__ = ["Result", "matrix_text", "matrix_latex"]


def matrix_text(M, indent: str = "    ") -> str:
    """A small exact matrix as aligned text rows."""
    rows = format_matrix(sp.Matrix(M))
    if rows and not isinstance(rows[0], list):
        rows = [[x] for x in rows]
    width = max((len(x) for r in rows for x in r), default=1)
    return "\n".join(indent + "[ " + "  ".join(x.rjust(width) for x in r) + " ]" for r in rows)


def matrix_latex(M) -> str:
    return sp.latex(sp.Matrix(M), mat_delim="(", mat_str="matrix")


class Result:
    """Base: subclasses implement ``to_json`` (a dict), ``__str__`` and ``to_latex``."""

    def to_json(self) -> dict:  # pragma: no cover - overridden
        raise NotImplementedError

    def dumps(self) -> str:
        return json.dumps(self.to_json(), ensure_ascii=False)

    def to_latex(self) -> str:  # pragma: no cover - overridden
        raise NotImplementedError

    def _repr_latex_(self) -> str:
        return "$" + self.to_latex() + "$"
