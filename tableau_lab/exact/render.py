r"""The one printer of exact values for people: sums of exact coefficients times terms in text
(the tableau grammar), LaTeX and — through LaTeX — Markdown, and plain text made literal for
Markdown and LaTeX.  Every face (the results' text, JSON and LaTeX, the PDF report, notebook
displays) prints through these functions; nothing edits a finished string.

A sum Σ cᵢ Tᵢ (exact cᵢ, a rendered term Tᵢ such as an elementary differential) is printed
term by term: the sign of each coefficient is taken once (``could_extract_minus_sign``), a
magnitude 1 is elided, and a magnitude whose printed form is itself a sum is one parenthesised
factor, so that the text re-parses to the exact value:

>>> import sympy as sp
>>> c = sp.Rational(1, 45) + sp.sqrt(3) / 72
>>> exact_sum([(-sp.Rational(1, 2), "f'f"), (c, "f''(f, f)"), (-c, "f'f'f"), (-1, "g"), (1, "f")])
"-1/2 f'f + (1/45 + sqrt(3)/72) f''(f, f) - (1/45 + sqrt(3)/72) f'f'f - g + f"
>>> exact_sum([(c, r"f''(f, f)"), (-2, "f'f")], LATEX)
"\\left(\\frac{1}{45} + \\frac{\\sqrt{3}}{72}\\right)\\, f''(f, f) - 2\\, f'f"
>>> exact_sum([(sp.Rational(-3, 2), None), (c, None), (-c, None)])   # constant terms: no 1 elided
'-3/2 + 1/45 + sqrt(3)/72 - (1/45 + sqrt(3)/72)'
>>> exact_sum([])
'0'

Plain text (a method's name, a message) in Markdown and in LaTeX text mode, every character
literal (CommonMark backslash escapes; the backslash and ``$`` escaped once more for MathJax,
whose ``processEscapes`` reads ``\\`` and ``\$``; control characters shown as escapes):

>>> print(markdown_literal(r"\\<img src=x> $a$ *b*"))
\\\\\\\\\<img src=x\> \\\$a\\\$ \*b\*
>>> print(latex_text("a_b $x$ 50% \\"))
a\_b \$x\$ 50\% \textbackslash{}
"""
from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from typing import Any, NamedTuple

import sympy as sp
from sympy.printing.latex import LatexPrinter

from .grammar import format_entry, format_matrix, real_root_index

__all__ = ["Notation", "TEXT", "LATEX", "entry_latex", "signed_term", "exact_sum", "is_sum", "matrix_text",
           "matrix_latex", "markdown_literal", "latex_text"]


class Notation(NamedTuple):
    """How a sum is written: ``number`` writes an exact value, ``times`` stands between a
    coefficient and its term, ``left``/``right`` enclose a coefficient that is a sum, ``minus``
    leads a sum whose first term is negative."""
    number: Callable[[Any], str]
    times: str
    left: str
    right: str
    minus: str

    def using(self, number: Callable[[Any], str]) -> "Notation":
        """The same notation with another writer of values (the report's named constants)."""
        return self._replace(number=number)


class _LatexPrinter(LatexPrinter):  # type: ignore[misc]  # sympy ships no types: LatexPrinter is Any
    """sympy's LaTeX printer, with a real root written as the grammar writes it, ``root(P, k)`` with
    k counted from 1 (sympy's own LaTeX, ``CRootOf(P, k − 1)``, counts from 0 and is no entry)."""

    def _print_ComplexRootOf(self, r: sp.Expr) -> str:
        if not r.is_real:                              # no root(P, k) for it: sympy's own form
            return str(super()._print_ComplexRootOf(r))
        P = sp.Poly(r.poly.as_expr().subs(r.poly.gen, _X), _X, domain=sp.QQ)
        return rf"\operatorname{{root}}\left({self._print(P.as_expr())}, {real_root_index(r, P)}\right)"


_X = sp.Symbol("x")


def entry_latex(e: Any) -> str:
    r"""An exact value in LaTeX (sympy's, with ``root(P, k)`` as the grammar writes it).

    >>> from tableau_lab.exact.grammar import parse_entry
    >>> entry_latex(parse_entry("1 - 4*root(24*x**3 - 36*x**2 + 12*x - 1, 3)"))
    '1 - 4 \\operatorname{root}\\left(24 x^{3} - 36 x^{2} + 12 x - 1, 3\\right)'
    >>> entry_latex(sp.CRootOf(sp.Symbol("x") ** 3 - 2, 1))        # not real: sympy's form
    '\\operatorname{CRootOf} {\\left(x^{3} - 2, 1\\right)}'
    """
    return str(_LatexPrinter().doprint(sp.sympify(e, strict=True)))      # strict: text is never evaluated


TEXT = Notation(lambda e: str(format_entry(e)), " ", "(", ")", "-")
LATEX = Notation(entry_latex, r"\, ", r"\left(", r"\right)", "- ")

_OPEN, _CLOSE = "([{", ")]}"


def is_sum(text: str) -> bool:
    """``text`` (an exact value as printed) has a + or − outside every bracket: written before
    a term it must be parenthesised.

    >>> is_sum("sqrt(3)/72 + 1/45"), is_sum(r"\\frac{1 + \\sqrt{2}}{2}"), is_sum("-2"), is_sum("2*x**(-1)")
    (True, False, True, False)
    """
    depth = 0
    for i, ch in enumerate(text):
        if ch in _OPEN:
            depth += 1
        elif ch in _CLOSE:
            depth -= 1
        elif ch in "+-" and depth == 0 and text[:i].rstrip()[-1:] not in ("^", "*"):
            return True
    return False


def signed_term(c: Any, term: str | None, notation: Notation = TEXT) -> tuple[bool, str]:
    """(negative, body): the term c·``term`` as its sign and the rest — the magnitude elided when
    it is 1 (unless there is no term), parenthesised when it prints as a sum (without a term: when
    a minus sign stands before it)."""
    c = sp.sympify(c)
    negative = bool(c.could_extract_minus_sign())
    mag = -c if negative else c
    if term is not None and mag == 1:
        return negative, term
    text = notation.number(mag)
    if is_sum(text) and (term is not None or negative):
        text = f"{notation.left}{text}{notation.right}"
    return negative, text if term is None else f"{text}{notation.times}{term}"


def exact_sum(pairs: Iterable[tuple[Any, str | None]], notation: Notation = TEXT, per_row: int | None = None,
              newline: str = "", most: int | None = None, more: str = r"\dots") -> str:
    """Σ c·term for ``pairs`` of (exact coefficient, rendered term or None), zero terms dropped;
    "0" when none is left.  ``per_row`` terms per row, rows joined by ``newline`` (LaTeX
    ``\\\\ &\\qquad``); ``most``: at most this many terms, then ``+ more``."""
    terms = [signed_term(c, t, notation) for c, t in pairs if sp.sympify(c) != 0]
    if not terms:
        return "0"
    cut = most is not None and len(terms) > most
    terms = terms[:most] if cut else terms
    out = []
    for i, (negative, body) in enumerate(terms):
        if i == 0:
            out.append(notation.minus + body if negative else body)
            continue
        sep = f" {newline} " if per_row and i % per_row == 0 and newline else " "
        out.append(f"{sep}{'-' if negative else '+'} {body}")
    if cut:
        out.append(f" + {more}")
    return "".join(out)


def matrix_text(M: Any, indent: str = "    ") -> str:
    """A small exact matrix as aligned text rows, entries in the tableau grammar.

    >>> print(matrix_text([[1, sp.Rational(-1, 2)], [sp.sqrt(3), 0]]))
        [       1     -1/2 ]
        [ sqrt(3)        0 ]
    """
    flat = format_matrix(sp.Matrix(M))
    rows = [x if isinstance(x, list) else [x] for x in flat]
    width = max((len(x) for r in rows for x in r), default=1)
    return "\n".join(indent + "[ " + "  ".join(x.rjust(width) for x in r) + " ]" for r in rows)


def matrix_latex(M: Any) -> str:
    r"""A small exact matrix in LaTeX math, ``\begin{pmatrix}``-like: ``\left(\begin{matrix}…``."""
    return str(sp.latex(sp.Matrix(M), mat_delim="(", mat_str="matrix"))


# ------------------------------------------------------------------ plain text, literally

_ALWAYS = frozenset("\\`*_[]<>&~|#$")      # markup anywhere in a line (CommonMark, GFM tables and strikethrough)
_LINE_START = re.compile(r"^([ \t]*)(?:(\d{1,9})([.)])|([-+=>.)]))", re.M)  # list items, headings, quotes


def _visible(ch: str) -> str:
    """A control character as the escape a reader recognises (\\n, \\t, \\x1b, …)."""
    return {"\n": r"\n", "\t": r"\t", "\r": r"\r"}.get(ch) or repr(ch)[1:-1]


def markdown_literal(text: str, line_start: bool = True) -> str:
    """Plain text as Markdown that renders as exactly that text, with nothing live: the characters
    that are markup anywhere (``\\ ` * _ [ ] < > & ~ | # $``) backslash-escaped (CommonMark),
    the backslash and ``$`` once more so that the HTML holds ``\\\\`` and ``\\$``, MathJax's
    literal backslash and dollar (``processEscapes``); what would open a block at the start of a
    line (``-``, ``+``, ``1.``, ``>``, …) escaped there.  Control characters are shown as their
    escapes, newlines too; ``line_start`` False: the text continues a line (its first character is
    not at a line start)."""
    out = []
    for ch in str(text):
        if not (ch.isprintable() or ch == " "):
            out.append(markdown_literal(_visible(ch)))
        elif ch == "\\":
            out.append(r"\\\\")
        elif ch == "$":
            out.append(r"\\\$")
        else:
            out.append("\\" + ch if ch in _ALWAYS else ch)
    return _LINE_START.sub(lambda m: m[0] if m.start() == 0 and not line_start else
                           m[1] + (f"{m[2]}\\{m[3]}" if m[2] else "\\" + m[4]), "".join(out))


_LATEX_TEXT = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
               "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}"}


def latex_text(text: str) -> str:
    """Plain text in LaTeX text mode, every character literal (control characters as escapes)."""
    return "".join(_LATEX_TEXT.get(ch, ch) if ch.isprintable() or ch == " " else latex_text(_visible(ch))
                   for ch in str(text))
