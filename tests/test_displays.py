"""Notebook displays (issue 19, item 3): ``_repr_latex_`` is display math only, or None where a
result has prose; ``_repr_markdown_`` carries prose and tables with MathJax math; methods show
their tableau.  The checkers below are also used on the executed notebook (test_notebook.py),
and are themselves tested on the strings the displays used to produce."""
import re
from pathlib import Path

import pytest
import sympy as sp

from tableau_lab.analysis.results import Combined
from tableau_lab.exact.library import family, library_path
from tableau_lab.exact.methods import RungeKutta
from tableau_lab.exact.render import markdown_literal
from tableau_lab.exact.tableau_json import load, loads, loads_any

PKG = Path(__file__).resolve().parents[1] / "tableau_lab"

# ------------------------------------------------------------------ the checkers

_TEXT_MODE = re.compile(r"\\(?:textbf|textit|texttt|emph|paragraph|section|subsection|par|noindent|small|hfill)\b"
                        r"|\\text\{[^{}]*\s[^{}]*\}|\\begin\{(?:tabular|longtable|align\*?|equation\*?|gather\*?)\}"
                        r"|\\[\[\]()]|(?<!\\)\$")
_PROSE = re.compile(r"\b[A-Za-z]{2,}\s+[A-Za-z]{2,}\s+[A-Za-z]{2,}\b")     # three words in a row


def math_problems(tex: str) -> list[str]:
    """What keeps ``tex`` (a ``text/latex`` output) from being display math only: ``$$…$$`` or an
    environment; no delimiters inside, no text mode (``\\text{…}`` phrases, ``\\textbf``,
    ``tabular``, ``\\par``), no prose; braces, environments and ``\\left``/``\\right`` balanced."""
    tex = tex.strip()
    if tex.startswith("$$") and tex.endswith("$$") and len(tex) > 4:
        body = tex[2:-2]
    elif re.fullmatch(r"\\begin\{(\w+\*?)\}.*\\end\{\1\}", tex, re.S):
        body = tex
    else:
        return [f"not display math: starts {tex[:12]!r}, ends {tex[-12:]!r}"]
    out = [f"text mode or a delimiter inside: {m.group()!r}" for m in _TEXT_MODE.finditer(body)]
    words = _PROSE.search(re.sub(r"\\[A-Za-z]+", " ", body))
    if words:
        out.append(f"prose: {words.group()!r}")
    if re.search(r"\n\s*\n", body):
        out.append("a blank line (a paragraph) inside math")
    depth = 0
    for ch in re.sub(r"\\\\|\\[{}]", "", body):          # a line break \\, then \{ and \}
        depth += {"{": 1, "}": -1}.get(ch, 0)
        if depth < 0:
            break
    if depth:
        out.append("unbalanced braces")
    stack = []
    for kind, env in re.findall(r"\\(begin|end)\{([^{}]*)\}", body):
        if kind == "begin":
            stack.append(env)
        elif not stack or stack.pop() != env:
            out.append(f"\\end{{{env}}} without its \\begin")
            break
    if stack:
        out.append(f"\\begin{{{stack[-1]}}} not closed")
    if len(re.findall(r"\\left\b", body)) != len(re.findall(r"\\right\b", body)):
        out.append("\\left and \\right unbalanced")
    return out


_MD_MATH = re.compile(r"\$\$(.+?)\$\$|(?<![\\$])\$([^$]+?)(?<!\\)\$", re.S)


def markdown_problems(md: str) -> list[str]:
    """Markdown for MathJax: each ``$$…$$`` and ``$…$`` passes :func:`math_problems`, and the
    prose between has no LaTeX left (commands, ``\\[`` delimiters, environments)."""
    out = []
    for m in _MD_MATH.finditer(md):
        out += [f"in {m.group()[:40]!r}: {p}" for p in math_problems(f"$${m[1] or m[2]}$$")]
    prose = _MD_MATH.sub(" ", md)
    out += [f"LaTeX in prose: {m.group()!r}" for m in re.finditer(r"\\[A-Za-z]+|\$", prose)]
    return out


def tableau_rows(tex: str) -> list[int]:
    """The number of rows of each ``array`` in ``tex``."""
    return [len(re.findall(r"\\\\", body)) + 1 for body in re.findall(r"\\begin\{array\}\{[^{}]*\}(.*?)\\end\{array\}",
                                                                      tex, re.S)]


def test_the_checkers_reject_what_the_displays_used_to_produce():
    from tableau_lab.analysis.order import order
    from tableau_lab.analysis.symplectic import rk_symplectic
    rk4 = load(library_path("rk4"))
    old = [f"${order(rk4).to_latex()}$", f"${rk_symplectic(rk4).to_latex()}$"]     # Result._repr_latex_ until now
    assert all(math_problems(t) for t in old)
    assert any("tabular" in p for p in math_problems(old[0]))
    bad = [r"$$\[ x \]$$", r"$$\text{The method is not symplectic}$$", "$$The method is symplectic.$$",
           r"$$\begin{array}{c} 1$$", r"$$\left( x$$", r"$$x} + {y$$", "$$a\n\nb$$", "$x$", r"$$\textbf{G}$$",
           r"$$x$ and $y$$", r"\begin{aligned} a \end{gathered}"]
    assert all(math_problems(t) for t in bad), [t for t in bad if not math_problems(t)]
    good = ["$$x^2$$", r"\begin{aligned}a &= b \\ &\quad + c\end{aligned}", r"$$\mathtt{\text{a21}} = 1$$",
            r"$$\left[\begin{array}{c|c} 1 & 2 \\ \hline 3 & 4 \end{array}\right]$$"]
    assert not [t for t in good if math_problems(t)]
    assert markdown_problems(r"Order $4$, \textbf{not} 5")
    assert markdown_problems(r"$$\begin{tabular}{l} x \end{tabular}$$")
    assert markdown_problems(r"see \[ \frac{1}{2} \]") and not markdown_problems(r"**a\_b** $x_1$ \| \[1,2\]")
    assert tableau_rows(r"\begin{array}{c|c} a & b \\ c & d \\ \hline & e \end{array}") == [3]


# ------------------------------------------------------------------ every result class

def _results() -> list:
    """One (or a few) of each Result subclass, built cheaply (the whole list in about a second)."""
    from tableau_lab.analysis.bseries import modified_field
    from tableau_lab.analysis.design import RepairResult, solve_text
    from tableau_lab.analysis.method_series import method_series
    from tableau_lab.analysis.modified import modified_equation
    from tableau_lab.analysis.modified_hamiltonian import modified_hamiltonian
    from tableau_lab.analysis.order import order
    from tableau_lab.analysis.parasitism import growth_parameters
    from tableau_lab.analysis.series_structure import structure
    from tableau_lab.analysis.stability_report import stability_report
    from tableau_lab.analysis.symmetry import symmetric
    from tableau_lab.analysis.symplectic import g_symplectic, rk_symplectic
    from tableau_lab.analysis.verify import verify
    from tableau_lab.experiments.design_search import SearchResult
    m = {k: load(library_path(k)) for k in ("rk4", "gauss2", "example4_glm", "glm43", "glm43_printed",
                                             "stormer_verlet", "implicit_midpoint")}
    design = solve_text('{"name": "e_2", "kind": "rk", "A": [[0, 0], ["a21", 0]], "b": ["b1", "b2"]}',
                        ["order=2", "b1 = b2"])
    reports = [stability_report(m[k]) for k in ("gauss2", "example4_glm", "stormer_verlet")] + [
        stability_report(family("bdf:3"))]
    parts = [p for r in reports for p in r._parts()]
    out = [g_symplectic(m["glm43"]), g_symplectic(m["glm43_printed"]), rk_symplectic(m["gauss2"]),
           rk_symplectic(m["stormer_verlet"]), order(m["rk4"]), order(m["example4_glm"]), order(m["stormer_verlet"]),
           growth_parameters(m["example4_glm"]), growth_parameters(m["gauss2"]), *reports, *parts,
           verify(m["example4_glm"]), method_series(m["example4_glm"], 3), modified_equation(m["rk4"], 5),
           modified_hamiltonian(modified_field(method_series(m["implicit_midpoint"], 5).phi)),
           structure(method_series(m["gauss2"], 4).phi), structure(method_series(m["stormer_verlet"], 3).phi),
           symmetric(m["example4_glm"]), symmetric(m["rk4"]), design,
           RepairResult(name="e_2", suspects=("A[2,1]",), printed={"A[2,1]": sp.Integer(2)}, design=design),
           RepairResult(name="e_2", suspects=(), printed={}, design=None),
           SearchResult(family="rk_2<x>", free=(sp.Symbol("c2"),), objectives=("imaginary-interval",),
                        constraints=("order=2",), candidates=(), evaluations=0)]
    from tableau_lab.analysis.catalog import list_methods
    from tableau_lab.analysis.front import modified_hamiltonian as method_hamiltonian, stability_function
    q, p = sp.symbols("q p")
    out += [list_methods(), stability_function(m["gauss2"]), stability_function(m["rk4"]),
            method_hamiltonian(m["implicit_midpoint"], p ** 2 / 2 - sp.cos(q), 3)]
    parametric = stability_report(loads('{"name": "sdirk_g", "kind": "rk", "A": [["g", 0], ["1 - 2*g", "g"]], '
                                        '"b": ["1/2", "1/2"]}'))
    import flint

    from tableau_lab.analysis.error_constant import error_constant
    certified = verify(loads_any('{"name": "Heun_[3]*", "kind": "rk", "numbers": "decimal", "A": [[0, 0], [1, 0]], '
                                 '"b": ["0.500", "0.499"], "claims": {"order": 2}}'))
    from tableau_lab.analysis.reconstruct import reconstruct
    with flint.ctx.workprec(128):
        third = flint.arb("[0.33333333333333333333 +/- 5e-21]")
    rebuilt = reconstruct({"name": "Heun 3", "kind": "rk", "A": [[0, 0, 0], [third, 0, 0], [0, "2/3", 0]],
                           "b": ["1/4", 0, "3/4"]})
    return out + [certified, parametric, error_constant(family("bdf:3")), rebuilt,
                  Combined((out[7], out[-14]), ("parasitism", "series")), Combined((out[0], out[7]))]


@pytest.fixture(scope="module")
def results():
    return _results()


def test_every_result_class_is_displayed(results):
    """Each subclass of Result in the package (found in the source) is among the results tested."""
    declared = {name for p in PKG.rglob("*.py") for name in re.findall(r"^class (\w+)\(Result\)", p.read_text(), re.M)}
    assert declared and declared <= {type(r).__name__ for r in results}, declared - {type(r).__name__ for r in results}


def test_markdown_and_latex_of_every_result(results):
    for r in results:
        md, tex = r._repr_markdown_(), r._repr_latex_()
        assert isinstance(md, str) and md.strip(), type(r).__name__
        assert not markdown_problems(md), (type(r).__name__, markdown_problems(md), md[:400])
        assert tex is None or not math_problems(tex), (type(r).__name__, math_problems(tex), tex[:400])
        head = str(r).split("\n", 1)[0].strip()
        assert not head or md.startswith(f"**{markdown_literal(head)}**"), (type(r).__name__, md[:100])


def test_latex_is_offered_exactly_for_the_results_that_are_all_math(results):
    kinds = {}
    for r in results:
        kinds.setdefault(type(r).__name__, set()).add(r._repr_latex_() is not None)
    assert {k for k, v in kinds.items() if v == {True}} == {"ParasitismResult", "MethodSeries", "ModifiedEquation",
                                                            "ModifiedHamiltonian", "StabilityFunction",
                                                            "MethodHamiltonian"}
    assert kinds["Combined"] == {True, False}            # all-math parts: gathered; a part with prose: None
    assert all(kinds[k] == {False} for k in ("RKOrderResult", "GSymplecticResult", "StabilityReport", "StabilityResult",
                                             "GLMOrderResult", "DesignResult", "SearchResult", "VerifyResult",
                                             "CertifiedResult"))


def test_rk_order_conditions_become_a_markdown_table():
    from tableau_lab.analysis.order import order
    md = order(load(library_path("rk4")))._repr_markdown_()
    rows = [line for line in md.splitlines() if line.startswith("| ")]
    assert rows[0] == r"| $t$ | $\Phi(t)$ | $1/\gamma(t)$ |" and len(rows) == 2 + 17       # the 17 trees to order 5
    assert r"| $[[[[\tau]]]]$ | $0$ | $\frac{1}{120}$ |" in rows
    assert "simplifying assumptions $B(4)$, $C(1)$, $D(1)$." in md and "tabular" not in md


def test_combined_shows_its_parts(results):
    both = results[-2]
    assert both._repr_latex_().startswith(r"$$\begin{gathered}") and not math_problems(both._repr_latex_())
    assert both._repr_markdown_() == "\n\n".join(p._repr_markdown_() for p in both.parts)


# ------------------------------------------------------------------ methods

@pytest.mark.parametrize("name, rows", [("rk4", [5]), ("gauss2", [3]), ("stormer_verlet", [3, 3]),
                                        ("example4_glm", [4]), ("glm43", [7])])
def test_methods_show_their_tableau(name, rows):
    m = load(library_path(name))
    tex, md = m._repr_latex_(), m._repr_markdown_()
    assert not math_problems(tex) and not markdown_problems(md), (math_problems(tex), markdown_problems(md))
    assert tableau_rows(tex) == rows and tableau_rows(md) == rows
    assert md.startswith(f"### {m.name}\n\n") and md.endswith(tex)
    assert (r"\begin{bmatrix} A & U \\ B & V \end{bmatrix}" in tex) == (m.kind == "glm")
    if m.kind == "glm":
        assert r"\qquad c = (" in tex and f"r = {m.r} values" in md


def test_method_entries_are_exact_and_the_name_is_escaped():
    m = RungeKutta.from_lists([[0, 0], [sp.sqrt(2) / 3, 0]], [1 - sp.Rational(1, 7), sp.Rational(1, 7)],
                              name="a*b_[c] <x>")
    assert m._repr_latex_() == (r"$$\begin{array}{c|cc} 0 & 0 & 0 \\ \frac{\sqrt{2}}{3} & \frac{\sqrt{2}}{3} & 0 "
                                r"\\ \hline & \frac{6}{7} & \frac{1}{7} \end{array}$$")
    assert m._repr_markdown_().startswith(r"### a\*b\_\[c\] \<x\>" + "\n\nRunge–Kutta method, s = 2 stages\n\n")


def test_the_report_typesets_the_same_tableau():
    """report/latex.py's tableau is ``Method.tableau_latex`` with its named constants: the text
    the PDF had before the function moved, byte for byte."""
    from tableau_lab.proofs.latex import _Constants, _tableau
    ex4 = _tableau(load(library_path("example4_glm")), _Constants())
    assert ex4 == (r"\[ \begin{bmatrix} A & U \\ B & V \end{bmatrix} = \left[\begin{array}{cc|cc} "
                   r"\frac{\sqrt{3}}{6} + \frac{1}{2} & 0 & 1 & - \frac{2 \sqrt{3}}{3} - 1 \\ - \frac{\sqrt{3}}{3} & "
                   r"\frac{\sqrt{3}}{6} + \frac{1}{2} & 1 & 1 + \frac{2 \sqrt{3}}{3} \\ \hline \frac{1}{2} & "
                   r"\frac{1}{2} & 1 & 0 \\ \frac{1}{2} & - \frac{1}{2} & 0 & -1 \end{array}\right] \]" + "\n"
                   r"with stage abscissae $c = (\frac{\sqrt{3}}{6} + \frac{1}{2},\ \frac{1}{2} - \frac{\sqrt{3}}{6})$.")
    C = _Constants()
    assert _tableau(load(library_path("stormer_verlet")), C) == (
        r"\[ \begin{array}{c|cc} 0 & 0 & 0 \\ 1 & \frac{1}{2} & \frac{1}{2} \\ \hline & \frac{1}{2} & \frac{1}{2} "
        r"\end{array} \qquad \begin{array}{c|cc} \frac{1}{2} & \frac{1}{2} & 0 \\ \frac{1}{2} & \frac{1}{2} & 0 \\ "
        r"\hline & \frac{1}{2} & \frac{1}{2} \end{array} \]")


# ------------------------------------------------------------------ hostile names (issue 29, item 11)

HOSTILE_NAMES = [r"\\<img src=x onerror=alert(1)//>", "\\<img src=x onerror=alert(1)//>", "<script>alert(1)</script>",
                 "$x$", "$$x$$", r"\(x\)", r"\[x\]", r"\begin{align}x\end{align}", "`code`", "``x``", "a ` b",
                 "[link](javascript:alert(1))", "![i](x)", "a\nb", "a\n\n<img src=x onerror=1>", "&lt;img src=x&gt;",
                 "&#36;x&#36;", "&#60;img src=x&#62;", "**b** _i_", "- item", "1. item", "# h", "> q", "a|b", "~~s~~",
                 "\\", "\\$x\\$", "x\\", "<!-- c -->", "\u001b[2J\u0000", r"{\textbf{x}}", r"\textbackslash{}",
                 "50% & #1 ~ ^", "<http://x>", "\\\\(x\\\\)"]


class _Html:
    """The tags and attributes of rendered HTML, and its text outside <code> (what MathJax reads)."""

    def __init__(self, html: str):
        from html.parser import HTMLParser
        self.tags, self.attrs, self.text, self.h3 = [], [], [], []
        depth = {"code": 0, "h3": 0}
        me = self

        class P(HTMLParser):
            def handle_starttag(self, tag, attrs):
                me.tags.append(tag)
                me.attrs += attrs
                if tag in depth:
                    depth[tag] += 1

            def handle_endtag(self, tag):
                if tag in depth:
                    depth[tag] -= 1

            def handle_data(self, data):
                if not depth["code"]:
                    me.text.append(data)
                if depth["h3"]:
                    me.h3.append(data)
        P(convert_charrefs=True).feed(html)


def mathjax_delimiters(text: str) -> list:
    r"""What MathJax (Jupyter: ``$``, ``$$``, ``\(``, ``\[``, environments, ``processEscapes``)
    would take for math delimiters in ``text``, left to right; ``\\`` and ``\$`` are its escapes."""
    return [m[0] for m in re.finditer(r"\\\\|\\\$|\$\$?|\\[(\[)\]]|\\begin\{", text) if m[0] not in ("\\\\", "\\$")]


def _unescape_mathjax(text: str) -> str:
    return re.sub(r"\\([\\$])", r"\1", text)


def _hostile_displays(name: str) -> list:
    from tableau_lab.analysis.design import DesignResult, RepairResult
    from tableau_lab.analysis.modified import modified_equation
    from tableau_lab.experiments.design_search import SearchResult
    m = RungeKutta.from_lists([[0, 0], [sp.Rational(1, 2), 0]], [0, 1], name=name)
    return [m, modified_equation(m, 2), RepairResult(name=name, suspects=(), printed={}, design=None),
            DesignResult(name=name, requirements=(name,), unknowns=(), status="solved", solutions=()),
            SearchResult(family=name, free=(sp.Symbol("c2"),), objectives=("imaginary-interval",),
                         constraints=(), candidates=(), evaluations=0)]


def test_hostile_names_render_as_text_under_commonmark():
    """A method name is text in every notebook display: rendered by a CommonMark renderer
    (markdown-it-py, with GFM tables and strikethrough) it makes no tag of its own, no attribute,
    no math delimiter MathJax would read (compared with the same display of a plain name), and
    reads back as the name itself.  On 5ea0488 ``\\\\<img …>`` rendered a live <img>, and ``$x$``
    reached MathJax as math."""
    from markdown_it import MarkdownIt
    md = MarkdownIt("commonmark").enable(["table", "strikethrough"])
    plain = [_Html(md.render(d._repr_markdown_())) for d in _hostile_displays("plain")]
    for name in HOSTILE_NAMES:
        for d, ref in zip(_hostile_displays(name), plain, strict=False):
            source = d._repr_markdown_()
            html = _Html(md.render(source))
            what = (name, type(d).__name__, source[:200])
            assert sorted(set(html.tags)) == sorted(set(ref.tags)) and html.attrs == ref.attrs == [], what
            assert mathjax_delimiters("".join(html.text)) == mathjax_delimiters("".join(ref.text)), what
            if isinstance(d, RungeKutta) and name.isprintable():
                assert _unescape_mathjax("".join(html.h3)) == name, what


def test_latex_text_of_a_name_is_literal():
    """The report's and the displays' LaTeX text mode: every special character of a name escaped."""
    from tableau_lab.exact.render import latex_text
    for name in HOSTILE_NAMES:
        tex = latex_text(name)
        rest = re.sub(r"\\(?:textbackslash|textasciitilde|textasciicircum)\{\}|\\[$%&#_{}]", "", tex)
        assert not set(rest) & set("\\$%&#_{}~^") and rest.isprintable(), (name, tex)
