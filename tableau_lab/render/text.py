"""The text format: what ``print(result)`` and the CLI show — the plain face of a document, its
heading on the first line, one block a line (or several), exact values in the tableau grammar
(the parts carry them so), tables as aligned columns.  Text needs no escaping.

>>> from tableau_lab.render.model import Document, Table, Typeset, Paragraph
>>> print(render(Document("library", (Table(("name", "order"), (("rk4", "4"), ("gauss:3", "6"))),
...                                   Typeset(Paragraph("not in text"))))))
library
name     order
-------  -----
rk4      4
gauss:3  6
"""
from __future__ import annotations

from .model import Break, Code, Document, Formula, Math, Renderer, Strong, Table, Text

__all__ = ["TextRenderer", "render"]


class TextRenderer(Renderer):
    face = "plain"

    def render(self, doc: Document) -> str:
        lines = [] if doc.heading is None else [doc.heading]
        lines += [self.block(b) for b in self.shown(doc.blocks)
                  if not (isinstance(b, Formula) and b.text is None or isinstance(b, Break))]
        return "\n".join(lines)

    def nested(self, doc: Document) -> str:
        return self.render(doc)          # in text a result inside another shows itself whole

    def text(self, p: Text, before: str, table: bool) -> str:
        return p.text

    def math(self, p: Math, before: str, table: bool) -> str:
        return p.latex if p.text is None else p.text

    def code(self, p: Code, before: str, table: bool) -> str:
        return p.text

    def strong(self, p: Strong, before: str, table: bool) -> str:
        return self.inline(p.parts, table)

    def formula(self, b: Formula) -> str:
        return b.latex if b.text is None else b.text

    def table(self, b: Table) -> str:
        rows = [[self.inline(c, True) for c in b.cells(r)] for r in (b.header, *b.rows)]
        widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]

        def line(row: list[str]) -> str:
            return "  ".join(x.ljust(w) for x, w in zip(row, widths, strict=True)).rstrip()
        return "\n".join([line(rows[0]), line(["-" * w for w in widths])] + [line(r) for r in rows[1:]])


def render(doc: Document) -> str:
    """``doc`` as text."""
    return TextRenderer().render(doc)
