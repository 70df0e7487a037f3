r"""Result objects shared by the analyses: each holds its data, serialises it to JSON (exact
values as strings in the tableau grammar) and builds one document, ``display()``, that the
rendering layer (:mod:`tableau_lab.render`) writes as text (``str``), LaTeX (``to_latex``) and,
in a notebook (Jupyter with MathJax), Markdown (``_repr_markdown_``: the heading in bold over the
typeset face) and display math (``_repr_latex_``: only when the typeset face is formulas and
nothing else, so that a frontend preferring LaTeX loses no sentence).

A result not yet moved onto the layer (the stability family, this round) writes ``__str__`` and
``to_latex`` itself; its notebook displays are its LaTeX translated (:func:`latex_markdown`:
display math as ``$$…$$``, inline math as ``$…$``, tables as Markdown tables, the few text-mode
commands it uses as Markdown; a class whose ``to_latex`` is a formula sets ``latex_math``).

A result made of others (``_parts``) shows them one after the other.

>>> from tableau_lab.exact.tableau_json import load
>>> from tableau_lab.analysis.parasitism import growth_parameters
>>> print(growth_parameters(load("methods/example4_glm.json"))._repr_latex_())
$$\begin{array}{c|c} \zeta & \mu \\ \hline -1 & 1 + \frac{2 \sqrt{3}}{3} \end{array}$$
>>> print(latex_markdown(r"Order $p = 4$, \textbf{not} 5: \[ \Phi(t) \ne 1/\gamma(t) \]"))
Order $p = 4$, **not** 5:
<BLANKLINE>
$$\Phi(t) \ne 1/\gamma(t)$$
"""
from __future__ import annotations

import dataclasses
import re
from typing import ClassVar

from ..exact.render import markdown_literal, matrix_latex, matrix_text
from ..render.displayed import Displayed
from ..render.markdown import code_span, display_body, gathered
from ..render.model import Document

__all__ = ["Result", "Combined", "matrix_text", "matrix_latex", "latex_markdown", "markdown_text"]


# ------------------------------------------------------------------ LaTeX fragments to Markdown

_SEGMENT = re.compile(                          # the math and the tables of a text-mode LaTeX fragment
    r"\\\[(?P<d1>.*?)\\\]|\$\$(?P<d2>.*?)\$\$"                                      # \[ … \], $$ … $$
    r"|\\begin\{(?P<env>align|gather)\*?\}(?P<d3>.*?)\\end\{(?P=env)\*?\}"              # align*, gather*
    r"|\\begin\{(?P<tab>tabular|longtable)\}\{[^}]*\}(?P<t>.*?)\\end\{(?P=tab)\}"       # tables
    r"|\\\((?P<i1>.*?)\\\)|(?<!\\)\$(?P<i2>.*?)(?<!\\)\$", re.S)                       # \( … \), $ … $
_RULES = re.compile(r"\\(?:hline|toprule|midrule|bottomrule)\b")
_PROSE = re.compile(                            # the LaTeX text mode the results' to_latex uses
    r"(?P<par>\\par\b\s*)|\\(?P<cmd>paragraph|textbf|emph|textit|texttt|text)\{(?P<arg>[^{}]*)\}"
    r"|\\(?P<named>textbackslash|textasciitilde|textasciicircum)\{\}|\\(?P<esc>[_$%&#{}])|(?P<nbsp>(?<!\\)~)")


def _display_body(mo) -> str | None:
    """The math of a display segment of ``_SEGMENT`` (None: inline math or a table)."""
    return next((mo[k] for k in ("d1", "d2", "d3") if mo[k] is not None), None)


_NAMED = {"textbackslash": "\\", "textasciitilde": "~", "textasciicircum": "^"}
_MARKUP = {"paragraph": "**", "textbf": "**", "emph": "*", "textit": "*", "text": ""}



def _untex(text: str) -> str:
    """LaTeX text mode's escapes (``\\_``, ``\\textbackslash{}``, …) as the characters they stand for."""
    return _PROSE.sub(lambda m: _NAMED[m["named"]] if m["named"] else m["esc"] if m["esc"] else m[0], text)


def markdown_text(text: str, line_start: bool = True) -> str:
    """LaTeX text mode (prose of a result's ``to_latex``) as Markdown, built piece by piece: each
    run of text made literal (:func:`..exact.render.markdown_literal`, lines kept), each escape
    (``\\_``, ``\\$``, ``\\textbackslash{}``) the literal character, ``\\textbf{…}`` and
    ``\\paragraph{…}`` bold, ``\\emph{…}`` italic, ``\\texttt{…}`` a code span, ``\\par`` a
    paragraph break, ``~`` a no-break space.  Nothing is escaped after it is built.  ``line_start``
    False: the text continues a line of the output (after inline math)."""
    out, pos = [], 0

    def run(chunk):
        return markdown_literal(chunk, lines=True, line_start=line_start if not pos else text[pos - 1] == "\n")
    for m in _PROSE.finditer(text):
        out.append(run(text[pos:m.start()]))
        pos = m.end()
        if m["par"] is not None:
            out.append("\n\n")
        elif m["cmd"] == "texttt":
            out.append(code_span(_untex(m["arg"])))
        elif m["cmd"]:
            out.append(_MARKUP[m["cmd"]] + markdown_text(m["arg"], False) + _MARKUP[m["cmd"]])
        elif m["nbsp"]:
            out.append("\u00a0")
        else:
            out.append(markdown_literal(_NAMED[m["named"]] if m["named"] else m["esc"]))
    out.append(run(text[pos:]))
    return "".join(out)


def _table(body: str) -> str:
    """A ``tabular`` body as a Markdown table, its first row the header; ``|`` in math as ``\\vert``."""
    rows = [[latex_markdown(c.strip(), table=True) for c in re.split(r"(?<!\\)&", r)]
            for r in re.split(r"\\\\", _RULES.sub("", body)) if r.strip()]
    if not rows:
        return ""
    lines = ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join([lines[0], "|" + " --- |" * len(rows[0])] + lines[1:])



def latex_markdown(tex: str, table: bool = False) -> str:
    """The LaTeX of a result (text mode with math, as ``to_latex`` makes it for the reports) as
    Markdown with MathJax math: ``$$…$$`` blocks, ``$…$`` inline, Markdown tables, prose escaped."""
    out, pos, inline_before = [], 0, False
    for mo in _SEGMENT.finditer(tex):
        out.append(markdown_text(tex[pos:mo.start()], not inline_before))       # after a display: a new line
        pos = mo.end()
        inline_before = mo["i1"] is not None or mo["i2"] is not None
        display, inline = _display_body(mo), (mo["i1"] if mo["i1"] is not None else mo["i2"])
        if display is not None:                  # on one line: no Markdown reads a row as a list item
            out.append("\n\n$$" + re.sub(r"\s*\n\s*", " ", display_body(display.strip())) + "$$\n\n")
        elif mo["t"] is not None:
            out.append(f"\n\n{_table(mo['t'])}\n\n")
        else:
            inline = inline.strip()
            out.append("$" + (inline.replace("|", r"\vert ") if table else inline) + "$")
    out.append(markdown_text(tex[pos:], not inline_before))
    text = re.sub(r"[ \t]*\n[ \t]*(\n[ \t]*)+", "\n\n", "".join(out))
    return text.strip().replace("\n", " ") if table else text.strip()


def _display_blocks(tex: str) -> list[str] | None:
    """The display-math blocks of ``tex`` when nothing but blank text lies between them."""
    blocks, pos = [], 0
    for mo in _SEGMENT.finditer(tex):
        body = _display_body(mo)
        if body is None or tex[pos:mo.start()].strip():
            return None
        blocks.append(display_body(body.strip()))
        pos = mo.end()
    return blocks if blocks and not tex[pos:].strip() else None


# ------------------------------------------------------------------ the results

def _compared(r) -> tuple:
    """The fields a dataclass compares (not caches set on the instance), or its whole __dict__."""
    if dataclasses.is_dataclass(r):
        return tuple(getattr(r, f.name) for f in dataclasses.fields(r) if f.compare)
    return tuple(sorted(vars(r).items()))


class Result(Displayed):
    """Base of the analyses' results.  A result moved onto the rendering layer implements
    ``display()`` (its :class:`~tableau_lab.render.model.Document`, built from its data) and
    ``to_json`` (its data); ``str``, ``to_latex``, ``dumps`` and the notebook displays are then
    the renderers' (:class:`~tableau_lab.render.displayed.Displayed`).  A result not yet moved
    (``display()`` None) implements ``__str__`` and ``to_latex`` itself, and its notebook
    displays are its LaTeX translated (:func:`latex_markdown`)."""

    latex_math = False     # not yet moved: True when to_latex() is one formula (math mode, no delimiters)
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

    def display(self) -> Document | None:
        """What the result shows, in every format (None: a result not yet moved onto the layer)."""
        return None

    def _parts(self) -> list | None:
        """The results this one is made of, shown one after the other; None: a single result."""
        return None

    def _display_math(self) -> str | None:
        """The whole result as one math formula (no delimiters), or None when it has prose."""
        parts = self._parts()
        if parts:
            bodies = [p._display_math() for p in parts]
            return None if None in bodies else gathered(bodies)
        if self.display() is not None:
            math = super()._repr_latex_()
            return None if math is None else math[2:-2]
        if self.latex_math:
            return display_body(self.to_latex().strip())
        blocks = _display_blocks(self.to_latex())
        return None if blocks is None else gathered(blocks)

    def _repr_latex_(self) -> str | None:
        """Jupyter: display math only, or None (then the Markdown is shown)."""
        math = self._display_math()
        return None if math is None else f"$${math}$$"

    def _repr_markdown_(self) -> str:
        """Jupyter: the heading in bold over the typeset face; the parts of a combined result one
        after the other; a result not yet moved: the first line of its text over its LaTeX translated."""
        parts = self._parts()
        if parts:
            return "\n\n".join(p._repr_markdown_() for p in parts)
        if self.display() is not None:
            return super()._repr_markdown_()
        head = str(self).split("\n", 1)[0].strip()
        body = latex_markdown(f"$${self.to_latex()}$$" if self.latex_math else self.to_latex())
        return ((f"**{markdown_literal(head)}**\n\n" if head else "") + body).strip()


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
