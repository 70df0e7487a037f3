"""The faces of a thing shown through the layer: a class that implements ``display()`` (a
:class:`~.model.Document` built from its data) and ``to_json()`` (its data) gets ``str``,
``to_latex``, ``dumps`` and the notebook displays from the renderers, and writes none itself.

>>> from tableau_lab.render.model import Document, Paragraph, Typeset, Math
>>> class Answer(Displayed):
...     def display(self):
...         return Document("answer: 42", (Typeset(Paragraph("The answer is ", Math("42"), ".")),))
...     def to_json(self):
...         return {"answer": 42}
>>> a = Answer()
>>> print(a, a.to_latex(), a.dumps(), a._repr_markdown_(), a._repr_latex_(), sep="\\n")
answer: 42
The answer is $42$.
{"answer": 42}
**answer: 42**
<BLANKLINE>
The answer is $42$.
None
"""
from __future__ import annotations

from typing import Any

from . import json as json_format, latex as latex_format, markdown as markdown_format, text as text_format
from .model import Document

__all__ = ["Displayed"]


class Displayed:
    """Mixin: ``str``, ``to_latex``, ``dumps``, ``_repr_markdown_`` and ``_repr_latex_`` as the
    renderers of ``self.display()`` (and ``self.to_json()``)."""

    def display(self) -> Document | None:  # pragma: no cover - implemented by each class
        """The document shown (None: the subclass writes its faces itself)."""
        raise NotImplementedError

    def _document(self) -> Document:
        doc = self.display()
        if doc is None:
            raise TypeError(f"a {type(self).__name__} has no display(): it writes its own faces")
        return doc

    def to_json(self) -> dict[str, Any]:  # pragma: no cover - implemented by each class
        raise NotImplementedError

    def __str__(self) -> str:
        return text_format.render(self._document())

    def to_latex(self) -> str:
        """LaTeX text mode (a formula, math mode, when the display is one formula)."""
        return latex_format.render(self._document())

    def dumps(self) -> str:
        """The data as one line of JSON."""
        return json_format.render(self.to_json())

    def _repr_markdown_(self) -> str:
        """Jupyter: the heading in bold over the typeset face."""
        return markdown_format.render(self._document())

    def _repr_latex_(self) -> str | None:
        """Jupyter: display math only, or None when the display has prose (the Markdown is shown)."""
        return markdown_format.display_math(self._document())
