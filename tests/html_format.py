"""A toy output format, HTML with MathJax delimiters, written as one file against the document
model of tableau_lab.render: what a new format costs (tests/test_render.py renders every result
kind with it).  Text is escaped as each part is placed (html.escape), never afterwards."""
from html import escape

from tableau_lab.render.model import Code, Document, Formula, Math, Paragraph, Renderer, Strong, Table, Text


class HtmlRenderer(Renderer):
    face = "typeset"

    def render(self, doc: Document) -> str:
        head = "" if not doc.heading else f"<h3>{escape(doc.heading)}</h3>"
        return head + "".join(self.block(b) for b in self.shown(doc.blocks))

    def nested(self, doc: Document) -> str:
        return "<section>" + self.render(Document(None, doc.blocks, doc.math)) + "</section>"

    def paragraph(self, b: Paragraph) -> str:
        return f"<p>{self.inline(b.parts)}</p>"

    def text(self, p: Text, before: str, table: bool) -> str:
        return escape(p.text)

    def math(self, p: Math, before: str, table: bool) -> str:
        return rf"\({escape(p.latex)}\)"

    def code(self, p: Code, before: str, table: bool) -> str:
        return f"<code>{escape(p.text)}</code>"

    def strong(self, p: Strong, before: str, table: bool) -> str:
        return f"<b>{self.inline(p.parts, table)}</b>"

    def formula(self, b: Formula) -> str:
        return rf"<div>\[{escape(b.latex)}\]</div>"

    def table(self, b: Table) -> str:
        rows = "".join("<tr>" + "".join(f"<td>{self.inline(c)}</td>" for c in b.cells(r)) + "</tr>"
                       for r in (b.header, *b.rows))
        return f"<table>{rows}</table>"


def render(doc: Document) -> str:
    return HtmlRenderer().render(doc)
