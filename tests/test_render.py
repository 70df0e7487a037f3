"""The rendering layer (issue 31, item 2): results return data and one document each
(``display()``); text, LaTeX, Markdown and JSON come from one renderer per format; a new format
is one file (tests/html_format.py renders every result kind); user text is escaped per part,
in each format, when the part is placed."""
import ast
import json
import re
from html.parser import HTMLParser
from pathlib import Path

import html_format
import pytest
import sympy as sp
from test_displays import _results

from tableau_lab.analysis.results import Result
from tableau_lab.exact.render import latex_text, markdown_literal
from tableau_lab.render import latex, markdown, text
from tableau_lab.render.model import Document

PKG = Path(__file__).resolve().parents[1] / "tableau_lab"
# the modules whose results render through the layer: every module that declares a result (the
# stability family moved last)
MOVED = sorted(str(p.relative_to(PKG)) for p in PKG.rglob("*.py")
               if re.search(r"^class \w+\((?:\w+, )*Result\b", p.read_text(), re.M))
FACES = ("__str__", "to_latex", "_repr_markdown_", "_repr_latex_")


@pytest.fixture(scope="module")
def results():
    return _results()


def test_moved_results_render_only_through_the_layer():
    """No result class of the moved modules writes a format itself: each has ``display()`` and
    none of ``__str__``/``to_latex``/``_repr_markdown_``/``_repr_latex_`` (on 66067b6 all did; the
    stability family and ``Combined`` until they moved)."""
    assert {"analysis/stability.py", "analysis/stability_report.py", "analysis/a_alpha.py", "analysis/results.py",
            "analysis/zero_stability.py", "analysis/ssp.py", "experiments/design_search.py"} <= set(MOVED), MOVED
    own, missing = [], []
    for rel in MOVED:
        for node in ast.parse((PKG / rel).read_text()).body:
            if isinstance(node, ast.ClassDef) and any(getattr(b, "id", None) == "Result" for b in node.bases):
                names = {f.name for f in node.body if isinstance(f, ast.FunctionDef)}
                own += [f"{rel}:{node.name}.{n}" for n in sorted(names & set(FACES))]
                missing += [] if "display" in names else [f"{rel}:{node.name}"]
    assert not own and not missing, (own, missing)


def test_the_layer_sits_on_the_exact_core():
    """tableau_lab/render imports nothing of the package but tableau_lab.exact (and itself)."""
    for p in (PKG / "render").glob("*.py"):
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level:
                assert node.level == 1 or node.module.startswith("exact"), (p.name, node.module)
            if isinstance(node, ast.ImportFrom) and not node.level and node.module:
                assert not node.module.startswith("tableau_lab") or node.module.startswith(
                    ("tableau_lab.exact", "tableau_lab.render")), (p.name, node.module)


class _Tags(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tags = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)


def test_a_new_format_is_one_file(results):
    """The toy HTML format of tests/html_format.py renders every kind of moved result; its
    sentences and formulas are those of the other typeset formats (the same document)."""
    moved = results
    kinds = {type(r).__name__ for r in moved}
    assert {"VerifyResult", "RKOrderResult", "GLMOrderResult", "GSymplecticResult", "RKSymplecticResult",
            "ModifiedEquation", "ModifiedHamiltonian", "MethodSeries", "SeriesStructure", "PSeriesStructure",
            "SymmetryResult", "DesignResult", "RepairResult", "SearchResult", "MethodList", "StabilityFunction",
            "MethodHamiltonian", "ErrorConstantResult", "StabilityResult", "StabilityReport", "AAlphaResult",
            "AlgebraicStabilityResult", "InternalStabilityResult", "ParametricStability", "ParasitismResult",
            "RealIntervalResult", "SSPResult", "ZeroStabilityResult", "Combined"} <= kinds
    for r in moved:
        doc = r.display()
        page = html_format.render(doc)
        tags = _Tags()
        tags.feed(page)
        assert set(tags.tags) <= {"h3", "p", "div", "table", "tr", "td", "b", "code", "section"}, type(r).__name__
        formulas = re.findall(r"\\\((.*?)\\\)|\\\[(.*?)\\\]", page, re.S)
        tex = r.to_latex()
        for inline, display in formulas:                  # every formula is one the LaTeX format wrote
            from html import unescape
            assert unescape(inline or display) in tex, (type(r).__name__, inline or display)
        assert formulas or not re.search(r"\$|\\\[", tex), type(r).__name__


NAME = r"a*b_[c] $x$ \(y\) <img src=q> 50% & #1 ~ ^ {z} `k` |p|"


def _named(name: str) -> list:
    """Results whose displays carry ``name`` as user text (a method's name, a family)."""
    from tableau_lab.analysis.design import DesignResult, RepairResult
    from tableau_lab.analysis.symmetry import SymmetryResult
    from tableau_lab.experiments.design_search import SearchResult
    design = DesignResult(name=name, requirements=(name, "order=2"), unknowns=(sp.Symbol("b1"),), status="solved",
                          solutions=())
    return [design, RepairResult(name=name, suspects=(), printed={}, design=design),
            SearchResult(family=name, free=(sp.Symbol("c2"),), objectives=("imaginary-interval",), constraints=(),
                         candidates=(), evaluations=0),
            SymmetryResult(name, False, None, note=name)]


def _strings(data) -> set:
    """Every string value in JSON data."""
    if isinstance(data, dict):
        return set().union(*map(_strings, data.values()))
    if isinstance(data, list):
        return set().union(*map(_strings, data))
    return {data} if isinstance(data, str) else set()


def test_user_text_is_escaped_per_part_in_each_format():
    """A name full of Markdown, LaTeX and HTML metacharacters is placed in each format as that
    format's literal of it and nowhere raw: the output is the one for a plain name with the
    plain name replaced by the literal (on 66067b6 the design's notebook Markdown carried a raw
    ``\\paragraph{…}`` for such a name: the regex over the finished LaTeX missed it)."""
    plain = "PLAIN"
    for shown, ref in zip(_named(NAME), _named(plain), strict=True):
        what = type(shown).__name__
        assert str(shown) == str(ref).replace(plain, NAME), what
        assert shown.to_latex() == ref.to_latex().replace(plain, latex_text(NAME)), what
        md, md_ref = shown._repr_markdown_(), ref._repr_markdown_()
        assert md == md_ref.replace(plain, markdown_literal(NAME, line_start=False)), (what, md)
        assert NAME in _strings(json.loads(shown.dumps())) or what == "RepairResult", what
        assert html_format.render(shown.display()).count("&lt;img") == html_format.render(ref.display()).count(
            plain), what


def test_each_renderer_writes_every_node():
    """text, latex, markdown (and the toy HTML) implement each inline part and block kind."""
    nodes = {"text", "math", "code", "strong", "lead", "formula", "table", "render"}
    for module in (text, latex, markdown, html_format):
        cls = next(v for v in vars(module).values() if isinstance(v, type) and v.__module__ == module.__name__)
        assert all(callable(getattr(cls, n, None)) for n in nodes), module.__name__


def test_a_result_is_shown_only_through_its_display():
    """No fallback guesses a result's faces from its LaTeX any more (the regex translation of
    finished LaTeX to Markdown is gone): a result without ``display()`` has no faces."""
    class Bare(Result):
        def to_json(self):
            return {}
    for face in (str, Result.to_latex, Result._repr_markdown_, Result._repr_latex_):
        with pytest.raises(NotImplementedError):
            face(Bare())
    assert Bare().dumps() == "{}"


def test_a_math_document_is_one_formula_in_latex_and_display_math_in_a_notebook(results):
    from tableau_lab.analysis.front import StabilityFunction
    r = next(r for r in results if isinstance(r, StabilityFunction))
    doc = r.display()
    assert isinstance(doc, Document) and doc.math
    assert latex.render(doc) == r.to_latex() and not r.to_latex().startswith("\\[")
    assert r._repr_latex_() == f"$${r.to_latex()}$$" == markdown.display_math(doc)
    assert str(r) == text.render(doc) == doc.heading


FAMILY = {"StabilityResult", "StabilityReport", "AAlphaResult", "AlgebraicStabilityResult", "InternalStabilityResult",
          "ParametricStability", "ParasitismResult", "RealIntervalResult", "SSPResult", "ZeroStabilityResult"}
_MATH = re.compile(r"\\\[.*?\\\]|(?<!\\)\$.*?(?<!\\)\$", re.S)
_ESCAPED = re.compile(r"\\[_{}$%&#]|\\text(?:backslash|asciitilde|asciicircum)\{\}")


def test_the_stability_family_writes_text_mode_latex_with_its_math_delimited(results):
    """The LaTeX of every stability-family result is text mode: outside ``\\[ … \\]`` and ``$…$``
    no math markup and no bare brace is left (on 98a80bf a GLM's stability report carried the
    parasitism array bare in text mode, a LaTeX error, and an algebraic-stability reason its
    braces raw, which LaTeX drops: "rows {1}")."""
    shown = [r for r in results if type(r).__name__ in FAMILY]
    assert FAMILY == {type(r).__name__ for r in shown}
    for r in shown:
        if type(r).__name__ == "ParasitismResult":     # one formula (the (ζ, μ) array): math mode by contract
            assert r.to_latex().startswith(r"\begin{array}") and f"\\[ {r.to_latex()} \\]" in " ".join(
                p.to_latex() for p in results if type(p).__name__ == "StabilityReport")
            continue
        prose = _ESCAPED.sub("", _MATH.sub("", r.to_latex()))
        assert not re.search(r"[_^{}$]|\\begin|\\end|\\frac", prose), (type(r).__name__, prose)
