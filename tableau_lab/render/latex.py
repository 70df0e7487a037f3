r"""The LaTeX format: the typeset face of a document in LaTeX text mode (what ``to_latex`` gives
and the reports embed): plain text made literal as it is placed (:func:`latex_text`), inline
math in ``$…$``, display math in ``\[ … \]``, tables as ``tabular``; blocks one a line (one
paragraph), a :class:`~.model.Break` and a result shown inside another set off by a blank
line.  The heading is the report's business: not shown.
A document that is one formula (``math``) is that formula, without delimiters.

>>> from tableau_lab.render.model import Document, Paragraph, Table, Math, Code
>>> print(render(Document("h", (Paragraph("50% of a_b: ", Math(r"\frac{1}{2}"), " ", Code("x_y")),
...                             Table(("$t$",), (("~",),), "l"), Paragraph("after")))))
50\% of a\_b: $\frac{1}{2}$ \texttt{x\_y}
\begin{tabular}{l}
\$t\$ \\ \hline
\textasciitilde{} \\
\end{tabular}
\par after
"""
from __future__ import annotations

from ..exact.render import latex_text
from .model import Break, Cell, Code, Document, Formula, Lead, Math, Paragraph, Renderer, Strong, Table, Text

__all__ = ["LatexRenderer", "render"]


class LatexRenderer(Renderer):
    face = "typeset"

    def render(self, doc: Document) -> str:
        blocks = self.shown(doc.blocks)
        if doc.math:
            (formula,) = blocks
            assert isinstance(formula, Formula), formula
            return formula.latex
        out, prev, parted = [], None, False
        for b in blocks:
            if isinstance(b, Break):
                parted = prev is not None
                continue
            if prev is not None:
                out.append("\n\n" if parted or isinstance(b, Document) or isinstance(prev, Document) else "\n")
            if isinstance(b, Paragraph) and isinstance(prev, Table):
                out.append("\\par ")                   # text after a tabular is a new paragraph
            out.append(self.block(b))
            prev, parted = b, False
        return "".join(out)

    def nested(self, doc: Document) -> str:
        body = self.render(Document(None, doc.blocks, doc.math))
        return f"\\[ {body} \\]" if doc.math else body

    def text(self, p: Text, before: str, table: bool) -> str:
        return latex_text(p.text)

    def math(self, p: Math, before: str, table: bool) -> str:
        return f"${p.latex}$"

    def code(self, p: Code, before: str, table: bool) -> str:
        return f"\\texttt{{{latex_text(p.text)}}}"

    def strong(self, p: Strong, before: str, table: bool) -> str:
        return f"\\textbf{{{self.inline(p.parts, table)}}}"

    def lead(self, p: Lead, before: str, table: bool) -> str:
        return f"\\paragraph{{{self.inline(p.parts, table)}}}"

    def formula(self, b: Formula) -> str:
        return f"\\[ {b.latex} \\]"

    def table(self, b: Table) -> str:
        def row(r: tuple[Cell, ...]) -> str:
            return " & ".join(self.inline(c, True) for c in b.cells(r))
        return (f"\\begin{{tabular}}{{{b.columns or 'l' * len(b.header)}}}\n{row(b.header)} \\\\ \\hline\n"
                + "".join(f"{row(r)} \\\\\n" for r in b.rows) + "\\end{tabular}")


def render(doc: Document) -> str:
    """``doc`` in LaTeX text mode (or one formula, math mode, when ``doc.math``)."""
    return LatexRenderer().render(doc)
