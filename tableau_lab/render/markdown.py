r"""The Markdown format (Jupyter: CommonMark with GFM tables, MathJax math) and the display math
that ``_repr_latex_`` offers: the typeset face of a document, its heading in bold.  Each part is
made Markdown as it is placed — plain text literal (:func:`markdown_literal`: CommonMark escapes,
the backslash and ``$`` once more for MathJax), code as a code span, math as ``$…$`` and
``$$…$$`` on one line (no Markdown reads a row of a formula as a list item) — and nothing is
escaped after it is built.

>>> from tableau_lab.render.model import Document, Paragraph, Table, Math, Code, Lead
>>> print(render(Document("<b>x</b>", (Paragraph(Lead("a_b"), " 2*3 < 4, ", Code("x`y"), " ", Math("y")),
...                                    Table(("$t$", Math(r"\Phi(t)")), ((Math(r"|x|"), "- 1"),))))))
**\<b\>x\</b\>**
<BLANKLINE>
**a\_b** 2\*3 \< 4, ``x`y`` $y$
<BLANKLINE>
| \\\$t\\\$ | $\Phi(t)$ |
| --- | --- |
| $\vert x\vert $ | \- 1 |
>>> print(display_math(Document(None, (Formula(r"a \\ [b]"), Formula(r"\begin{array}{c} 1 \\ 2 \end{array}")))))
$$\begin{gathered}\begin{aligned}a \\{} [b]\end{aligned} \\ \begin{array}{c} 1 \\ 2 \end{array}\end{gathered}$$
"""
from __future__ import annotations

import re

from ..exact.render import markdown_literal
from .model import Block, Break, Cell, Code, Document, Formula, Math, Paragraph, Renderer, Strong, Table, Text

__all__ = ["MarkdownRenderer", "render", "display_math", "display_body", "gathered", "code_span"]


def code_span(text: str) -> str:
    """``text`` as a CommonMark code span (literal: no escapes, no HTML; MathJax skips <code>):
    the fence one backtick longer than any run of backticks in it."""
    fence = "`" * (max((len(r) for r in re.findall("`+", text)), default=0) + 1)
    pad = " " if text.startswith("`") or text.endswith("`") or not text.strip() else ""
    return f"{fence}{pad}{text}{pad}{fence}"


def display_body(math: str) -> str:
    """A formula as one display block: rows (``\\\\`` outside any environment) go into
    ``aligned``, which MathJax accepts inside ``$$``, where ``align*`` is not allowed; a row
    that begins with ``[`` (a tree such as ``[\\tau]``) is kept from being read as the
    ``\\\\[dimen]`` argument of the line break before it (a MathJax and LaTeX error)."""
    math = re.sub(r"\\\\(\s*)\[", r"\\\\{}\1[", math)
    flat = math
    while (shorter := re.sub(r"\\begin\{([^{}]*)\}(?:(?!\\begin\{).)*?\\end\{\1\}", "", flat, flags=re.S)) != flat:
        flat = shorter
    return rf"\begin{{aligned}}{math}\end{{aligned}}" if "\\\\" in flat else math


def gathered(bodies: list[str]) -> str:
    """Several display formulas as one, centred one below the other."""
    return bodies[0] if len(bodies) == 1 else r"\begin{gathered}" + r" \\ ".join(bodies) + r"\end{gathered}"


def _one_line(math: str) -> str:
    return "$$" + re.sub(r"\s*\n\s*", " ", display_body(math.strip())) + "$$"


class MarkdownRenderer(Renderer):
    face = "typeset"

    def render(self, doc: Document) -> str:
        head = (doc.heading or "").strip()
        return ((f"**{markdown_literal(head)}**\n\n" if head else "") + self.body(doc)).strip()

    def body(self, doc: Document) -> str:
        blocks = self.shown(doc.blocks)
        if doc.math:
            return "\n\n".join(_one_line(b.latex) for b in blocks if isinstance(b, Formula))
        out: list[str] = []
        prev: Block | None = None
        for b in blocks:
            text = self.block(b).strip()
            if text:                   # consecutive paragraphs are one: a line break
                out += ["\n" if isinstance(b, Paragraph) and isinstance(prev, Paragraph) else "\n\n", text]
            prev = None if isinstance(b, Break) else b if text else prev
        return "".join(out[1:])

    def nested(self, doc: Document) -> str:
        return self.body(doc)

    def text(self, p: Text, before: str, table: bool) -> str:
        return markdown_literal(p.text, line_start=not before or before.endswith("\n"))   # a newline shown: \n

    def math(self, p: Math, before: str, table: bool) -> str:
        body = p.latex.strip()
        return "$" + (body.replace("|", r"\vert ") if table else body) + "$"

    def code(self, p: Code, before: str, table: bool) -> str:
        return code_span(p.text)

    def strong(self, p: Strong, before: str, table: bool) -> str:
        return "**" + self.inline(p.parts, table) + "**"

    def formula(self, b: Formula) -> str:
        return _one_line(b.latex)

    def table(self, b: Table) -> str:
        def row(r: tuple[Cell, ...]) -> str:
            return "| " + " | ".join(self.inline(c, True).strip() for c in b.cells(r)) + " |"
        return "\n".join([row(b.header), "|" + " --- |" * len(b.header)] + [row(r) for r in b.rows])


def render(doc: Document) -> str:
    """``doc`` as Markdown for a notebook: its heading in bold, then its typeset face."""
    return MarkdownRenderer().render(doc)


def display_math(doc: Document) -> str | None:
    """``doc`` as display math only (``$$…$$``: MathJax typesets the whole output as math), when
    its typeset face is formulas and nothing else; None when it has prose (a frontend that
    prefers LaTeX must then not lose a sentence)."""
    bodies = _formulas(doc)
    return None if bodies is None else f"$${gathered(bodies)}$$"


def _formulas(doc: Document) -> list[str] | None:
    out: list[str] = []
    for b in MarkdownRenderer().shown(doc.blocks):
        if isinstance(b, Formula):
            out.append(display_body(b.latex.strip()))
        elif isinstance(b, Document) and (inner := _formulas(b)) is not None:
            out.append(gathered(inner))
        else:
            return None
    return out or None
