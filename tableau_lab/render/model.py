"""The document model of the rendering layer (see the package docstring): inline parts, blocks,
faces, and :class:`Renderer`, the walk every format shares.

Inline parts: :class:`Text`, :class:`Math`, :class:`Code`, :class:`Strong`, :class:`Lead`.
Blocks: :class:`Paragraph`, :class:`Formula`, :class:`Table`, :class:`Break`, a nested :class:`Document`, and
the face filters :class:`Plain` and :class:`Typeset`.  A plain ``str`` among the parts of a
paragraph is :class:`Text`.

>>> Paragraph("x = ", Math("x", "x")).parts
(Text(text='x = '), Math(latex='x', text='x'))
"""
from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Union

__all__ = ["Text", "Math", "Code", "Strong", "Lead", "Paragraph", "Formula", "Table", "Break", "Plain", "Typeset",
           "Document", "Renderer", "Part", "Block"]


# ------------------------------------------------------------------ inline parts

@dataclass(frozen=True)
class Text:
    """Plain text (user text too: a method's name, a message): every character literal in every
    format, escaped by the renderer when the part is placed."""
    text: str


@dataclass(frozen=True)
class Math:
    """A formula the program wrote from exact values: ``latex`` in math mode (no delimiters), and
    ``text`` the same formula for a terminal (the tableau grammar, Unicode); None: text shows the
    LaTeX."""
    latex: str
    text: str | None = None


@dataclass(frozen=True)
class Code:
    """Literal program text (an option, a key): monospace where the format has it."""
    text: str


def _parts(parts: Iterable[str | Part]) -> tuple[Part, ...]:
    return tuple(Text(p) if isinstance(p, str) else p for p in parts)


@dataclass(frozen=True, init=False)
class Strong:
    """Inline parts in bold (text: as they are)."""
    parts: tuple[Part, ...]

    def __init__(self, *parts: str | Part) -> None:
        object.__setattr__(self, "parts", _parts(parts))


@dataclass(frozen=True, init=False)
class Lead:
    """A run-in heading that opens a paragraph (LaTeX ``\\paragraph``, Markdown bold)."""
    parts: tuple[Part, ...]

    def __init__(self, *parts: str | Part) -> None:
        object.__setattr__(self, "parts", _parts(parts))


Part = Union[Text, Math, Code, Strong, Lead]


# ------------------------------------------------------------------ blocks

@dataclass(frozen=True, init=False)
class Paragraph:
    """A run of inline parts (``str`` items are :class:`Text`)."""
    parts: tuple[Part, ...]

    def __init__(self, *parts: str | Part) -> None:
        object.__setattr__(self, "parts", _parts(parts))


@dataclass(frozen=True)
class Formula:
    """Display math: ``latex`` in math mode (rows may be separated by ``\\\\``), ``text`` the same
    for a terminal (None: the plain face does not show it)."""
    latex: str
    text: str | None = None


@dataclass(frozen=True)
class Table:
    """A table: ``header`` a tuple of cells, ``rows`` tuples of cells, a cell a tuple of inline
    parts (or one part, or a ``str``: :class:`Text`); ``columns`` the LaTeX column spec."""
    header: tuple[Cell, ...]
    rows: tuple[tuple[Cell, ...], ...]
    columns: str = ""

    def cells(self, row: tuple[Cell, ...]) -> list[tuple[Part, ...]]:
        """The cells of ``row`` each as a tuple of parts."""
        return [_parts((c,)) if isinstance(c, (str, Text, Math, Code, Strong, Lead)) else _parts(c) for c in row]


@dataclass(frozen=True)
class Break:
    """A paragraph break.  Consecutive blocks without one run on as one paragraph (sentences,
    display formulas, a table), as in LaTeX; a result shown inside another stands apart anyway."""


@dataclass(frozen=True, init=False)
class Plain:
    """Blocks of the plain face only (the text format)."""
    blocks: tuple[Block, ...]

    def __init__(self, *blocks: Block) -> None:
        object.__setattr__(self, "blocks", tuple(blocks))


@dataclass(frozen=True, init=False)
class Typeset:
    """Blocks of the typeset face only (LaTeX, Markdown, any typesetting format)."""
    blocks: tuple[Block, ...]

    def __init__(self, *blocks: Block) -> None:
        object.__setattr__(self, "blocks", tuple(blocks))


@dataclass(frozen=True)
class Document:
    """A result's display: ``heading`` its first plain line (or None), ``blocks`` the rest;
    ``math``: the typeset face is one formula and nothing else (LaTeX gives it without
    delimiters, as the reports embed it; a notebook shows it as display math)."""
    heading: str | None
    blocks: tuple[Block, ...] = field(default=())
    math: bool = False


Block = Union[Paragraph, Formula, Table, Break, Plain, Typeset, Document]
Cell = Union[str, Part, tuple[Union[str, Part], ...]]


# ------------------------------------------------------------------ the walk

class Renderer:
    """One output format: ``face`` ("plain" or "typeset") picks the blocks it shows, the methods
    write each node; :meth:`render` walks a document.  A new format writes :meth:`render` and
    the node methods (``before``: what the run of parts has written so far; ``table``: inside a
    table cell)."""

    face = "typeset"

    def render(self, doc: Document) -> str:  # pragma: no cover - overridden
        raise NotImplementedError

    def shown(self, blocks: Sequence[Block]) -> list[Block]:
        """The blocks of this renderer's face, :class:`Plain`/:class:`Typeset` unwrapped."""
        out: list[Block] = []
        for b in blocks:
            if isinstance(b, (Plain, Typeset)):
                if isinstance(b, Plain) == (self.face == "plain"):
                    out += self.shown(b.blocks)
            else:
                out.append(b)
        return out

    def block(self, b: Block) -> str:
        """One block (not a face filter), dispatched on its kind."""
        if isinstance(b, Paragraph):
            return self.paragraph(b)
        if isinstance(b, Formula):
            return self.formula(b)
        if isinstance(b, Table):
            return self.table(b)
        if isinstance(b, Document):
            return self.nested(b)
        if isinstance(b, Break):
            return ""
        raise TypeError(f"not a block of the document model: {b!r}")

    def inline(self, parts: Iterable[Part], table: bool = False) -> str:
        """Inline parts, dispatched on their kind (``table``: they fill a table cell)."""
        out: list[str] = []
        for p in parts:
            before = "".join(out)
            if isinstance(p, Text):
                out.append(self.text(p, before, table))
            elif isinstance(p, Math):
                out.append(self.math(p, before, table))
            elif isinstance(p, Code):
                out.append(self.code(p, before, table))
            elif isinstance(p, Strong):
                out.append(self.strong(p, before, table))
            elif isinstance(p, Lead):
                out.append(self.lead(p, before, table))
            else:
                raise TypeError(f"not an inline part of the document model: {p!r}")
        return "".join(out)

    def paragraph(self, b: Paragraph) -> str:
        return self.inline(b.parts)

    def nested(self, doc: Document) -> str:
        """A result shown inside another: its blocks of this face (not its heading)."""
        return self.render(Document(None, doc.blocks, doc.math))

    def text(self, p: Text, before: str, table: bool) -> str:  # pragma: no cover - overridden
        raise NotImplementedError

    def math(self, p: Math, before: str, table: bool) -> str:  # pragma: no cover - overridden
        raise NotImplementedError

    def code(self, p: Code, before: str, table: bool) -> str:  # pragma: no cover - overridden
        raise NotImplementedError

    def strong(self, p: Strong, before: str, table: bool) -> str:  # pragma: no cover - overridden
        raise NotImplementedError

    def lead(self, p: Lead, before: str, table: bool) -> str:
        """A run-in heading: bold unless the format has its own."""
        return self.strong(Strong(*p.parts), before, table)

    def formula(self, b: Formula) -> str:  # pragma: no cover - overridden
        raise NotImplementedError

    def table(self, b: Table) -> str:  # pragma: no cover - overridden
        raise NotImplementedError
