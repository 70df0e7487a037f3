r"""Result objects shared by the analyses: each holds its data, serialises it to JSON (exact
values as strings in the tableau grammar) and builds one document, ``display()``, that the
rendering layer (:mod:`tableau_lab.render`) writes as text (``str``), LaTeX (``to_latex``) and,
in a notebook (Jupyter with MathJax), Markdown (``_repr_markdown_``: the heading in bold over the
typeset face) and display math (``_repr_latex_``: only when the typeset face is formulas and
nothing else, so that a frontend preferring LaTeX loses no sentence).  No result writes a format
itself, and nothing here edits a finished string.

A result made of others (``_parts``: :class:`Combined`, the stability report) shows them one
after the other; in a notebook each with its heading.

>>> from tableau_lab.exact.tableau_json import load
>>> from tableau_lab.analysis.parasitism import growth_parameters
>>> print(growth_parameters(load("methods/example4_glm.json"))._repr_latex_())
$$\begin{array}{c|c} \zeta & \mu \\ \hline -1 & 1 + \frac{2 \sqrt{3}}{3} \end{array}$$
"""
from __future__ import annotations

import dataclasses
from typing import ClassVar

from ..exact.render import matrix_latex, matrix_text
from ..render.displayed import Displayed
from ..render.model import Document

__all__ = ["Result", "Combined", "matrix_text", "matrix_latex"]


# ------------------------------------------------------------------ the results

def _compared(r) -> tuple:
    """The fields a dataclass compares (not caches set on the instance), or its whole __dict__."""
    if dataclasses.is_dataclass(r):
        return tuple(getattr(r, f.name) for f in dataclasses.fields(r) if f.compare)
    return tuple(sorted(vars(r).items()))


class Result(Displayed):
    """Base of the analyses' results.  A result implements ``display()`` (its
    :class:`~tableau_lab.render.model.Document`, built from its data) and ``to_json`` (its data);
    ``str``, ``to_latex``, ``dumps`` and the notebook displays are the renderers'
    (:class:`~tableau_lab.render.displayed.Displayed`)."""

    int_field: ClassVar[str | None] = None   # the field int(result) gives ("order" for the order analyses), or None

    def __int__(self) -> int:
        """``int(tl.order(m))`` is the order: the field :attr:`int_field` of a result that has one."""
        if self.int_field is None:
            raise TypeError(f"a {type(self).__name__} has no integer value")
        return int(getattr(self, self.int_field))

    def __index__(self) -> int:
        return self.__int__()

    def __eq__(self, other):
        """A result with an integer value equals that integer (``tl.order(m) == 6``, as NodePy's
        ``rk.order()``); results of one class compare field by field.  The classes with an
        :attr:`int_field` are dataclasses with ``eq=False``, so that this is their equality."""
        if self.int_field is not None and isinstance(other, int) and not isinstance(other, bool):
            return int(self) == other
        if type(other) is not type(self):
            return NotImplemented
        return _compared(self) == _compared(other)

    def __hash__(self):
        return hash(int(self)) if self.int_field is not None else object.__hash__(self)

    def _parts(self) -> list | None:
        """The results this one is made of, shown one after the other (its display nests theirs, and
        its Markdown is theirs, each with its heading in bold); None: a single result."""
        return None

    def _repr_markdown_(self) -> str:
        """Jupyter: the heading in bold over the typeset face; the parts of a combined result one
        after the other, each with its heading."""
        parts = self._parts()
        if parts:
            return "\n\n".join(p._repr_markdown_() for p in parts)
        return super()._repr_markdown_()


class Combined(Result):
    """Several results of one method shown together: text one after the other, JSON merged
    (each later part under its ``key``), LaTeX and the notebook displays one after the other."""

    def __init__(self, parts: tuple, keys: tuple = ()):
        self.parts, self.keys = tuple(parts), tuple(keys) or tuple(f"part{i}" for i in range(len(parts)))

    def display(self) -> Document:
        """The parts' displays one after the other (each with its heading in text)."""
        return Document(None, tuple(p.display() for p in self.parts))

    def _parts(self) -> list:
        return list(self.parts)

    def to_json(self) -> dict:
        out = dict(self.parts[0].to_json())
        for k, p in zip(self.keys[1:], self.parts[1:], strict=False):
            out[k] = p.to_json()
        return out
