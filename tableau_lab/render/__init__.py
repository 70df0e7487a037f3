r"""The one rendering layer: a result says *what* it shows as a small document (:mod:`.model`),
and one renderer per format says *how*: :mod:`.text` (what ``print`` and the CLI show),
:mod:`.latex` (LaTeX text mode with math), :mod:`.markdown` (Jupyter's Markdown with MathJax
math, and the display math of ``_repr_latex_``) and :mod:`.json` (the result's data, exact
values as strings in the tableau grammar).  A new output format is one new file: a subclass of
:class:`.model.Renderer` with one method per node of the model.

The design:

* A result builds its document from its data with ONE method, ``display()``; its ``__str__``,
  ``to_latex``, ``dumps``, ``_repr_markdown_`` and ``_repr_latex_`` are the renderers' (the
  mixin :class:`.displayed.Displayed`, base of :class:`tableau_lab.analysis.results.Result`).
* The document is made of escaped *parts*: :class:`.model.Text` (plain text — a method's name, a
  message — made literal by each renderer as it places the part: ``latex_text``, CommonMark
  escapes), :class:`.model.Math` (a formula written by the program from exact values, in LaTeX
  and optionally in the tableau grammar for text), :class:`.model.Code`, :class:`.model.Strong`,
  :class:`.model.Lead`; blocks :class:`.model.Paragraph`, :class:`.model.Formula` (display
  math), :class:`.model.Table` and a nested :class:`.model.Document` (a result shown inside
  another).  No renderer edits a finished string: escaping happens when a part is placed.
* Exact values are written by the one printer, :mod:`tableau_lab.exact.render` (``exact_sum``,
  ``format_entry``, ``sympy.latex``, :func:`~tableau_lab.exact.render.matrix_text`).
* Two *faces*: the plain face (terse lines for a terminal, aligned matrices) and the typeset
  face (sentences with math, tables).  A block is shown by every format unless wrapped in
  :class:`.model.Plain` (text only) or :class:`.model.Typeset` (LaTeX, Markdown and any other
  typesetting format); a result's :class:`.model.Document` ``heading`` is its first plain line,
  which Markdown shows in bold and LaTeX leaves to the report around it.

The floor: this package sits at the bottom beside ``exact/render.py`` and imports only from
``tableau_lab.exact``; the analyses (``analysis/results.py``) import it, never the reverse.

>>> from tableau_lab.render import Document, Paragraph, Text, Math, Formula, text, latex, markdown
>>> doc = Document("a*b_[c]: order 2", (Paragraph(Text("Order "), Math("p = 2", "p = 2"), Text(" of a*b_[c].")),
...                                       Formula(r"\Phi(t) = 1/\gamma(t)")))
>>> print(text.render(doc))
a*b_[c]: order 2
Order p = 2 of a*b_[c].
>>> print(latex.render(doc))
Order $p = 2$ of a*b\_[c].
\[ \Phi(t) = 1/\gamma(t) \]
>>> print(markdown.render(doc))
**a\*b\_\[c\]: order 2**
<BLANKLINE>
Order $p = 2$ of a\*b\_\[c\].
<BLANKLINE>
$$\Phi(t) = 1/\gamma(t)$$
"""
from .model import Break, Code, Document, Formula, Lead, Math, Paragraph, Plain, Renderer, Strong, Table, Text, Typeset

__all__ = ["Break", "Code", "Document", "Formula", "Lead", "Math", "Paragraph", "Plain", "Renderer", "Strong", "Table",
           "Text", "Typeset"]
