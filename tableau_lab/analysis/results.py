"""Result objects shared by the analyses: each prints itself, serialises to JSON
(exact values as strings in the tableau grammar) and renders to LaTeX."""
from __future__ import annotations

import json

import sympy as sp

from ..exact.grammar import format_matrix

__all__ = ["Result", "Combined", "matrix_text", "matrix_latex"]


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


class Combined(Result):
    """Several results of one method shown together: text one after the other, JSON merged
    (each later part under its ``key``), LaTeX one after the other."""

    def __init__(self, parts: tuple, keys: tuple = ()):
        self.parts, self.keys = tuple(parts), tuple(keys) or tuple(f"part{i}" for i in range(len(parts)))

    def __str__(self):
        return "\n".join(str(p) for p in self.parts)

    def to_json(self) -> dict:
        out = dict(self.parts[0].to_json())
        for k, p in zip(self.keys[1:], self.parts[1:]):
            out[k] = p.to_json()
        return out

    def to_latex(self) -> str:
        return "\n\n".join(p.to_latex() for p in self.parts)
