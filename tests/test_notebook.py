"""docs/notebook.ipynb, executed (nbclient, kernel python3): no cell fails, every ``text/latex``
output is display math only (the checker of tests/test_displays.py), prose comes as Markdown,
the method cells show their tableaux, and the outputs stored in the file (what GitHub shows) are
the ones the code gives today; where node and mathjax-full are installed, MathJax 3 typesets
every formula without error (benchmarks/mathjax_check.py).

``python tests/test_notebook.py`` executes the notebook and stores it with its outputs, without
timestamps or kernel versions (regenerate it after a change of the displays)."""
import ast
import copy
import os
import re
import shutil
import sys
import time
from pathlib import Path

import nbformat
import pytest
from conftest import benchmark_script
from nbclient import NotebookClient
from test_displays import markdown_problems, math_problems, tableau_rows

NOTEBOOK = Path(__file__).resolve().parents[1] / "docs" / "notebook.ipynb"
SHOWN = ("text/markdown", "text/latex")        # what a MathJax frontend renders; text/plain is the repr


def execute(path: Path = NOTEBOOK):
    """The notebook executed in a fresh python3 kernel in its folder, its outputs without noise."""
    nb = nbformat.read(path, as_version=4)
    NotebookClient(nb, kernel_name="python3", timeout=120, record_timing=False,
                   resources={"metadata": {"path": str(path.parent)}}).execute()
    nb.metadata = {"kernelspec": {"name": "python3", "display_name": "Python 3", "language": "python"},
                   "language_info": {"name": "python"}}
    for cell in nb.cells:
        cell.metadata = {}
    return nb


@pytest.fixture(scope="module")
def executed():
    t0 = time.perf_counter()
    nb = execute()
    return nb, time.perf_counter() - t0


def _outputs(nb):
    return [(i, out) for i, cell in enumerate(nb.cells) if cell.cell_type == "code" for out in cell.outputs]


def test_notebook_runs_without_errors_within_a_minute(executed):
    nb, seconds = executed
    assert seconds < 60, f"the notebook took {seconds:.1f} s"
    errors = [(i, out.get("ename"), out.get("evalue")) for i, out in _outputs(nb) if out.output_type == "error"]
    assert not errors
    assert all(out.output_type != "stream" or out.name != "stderr" for _, out in _outputs(nb))
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert len(nb.cells) <= 12 and all(c.outputs for c in code)
    # each code cell follows a Markdown cell that says what it shows
    assert all(nb.cells[i - 1].cell_type == "markdown" for i, c in enumerate(nb.cells) if c.cell_type == "code")


def test_every_output_is_rendered_math_with_prose_as_markdown(executed):
    nb, _ = executed
    bundles = [out.data for _, out in _outputs(nb) if out.output_type in ("display_data", "execute_result")]
    assert len(bundles) >= 9
    for data in bundles:
        assert "text/markdown" in data, sorted(data)          # the frontends' choice: prose and math
        assert not markdown_problems(data["text/markdown"]), (markdown_problems(data["text/markdown"]),
                                                              data["text/markdown"][:300])
        if "text/latex" in data:
            assert not math_problems(data["text/latex"]), (math_problems(data["text/latex"]), data["text/latex"][:300])
    # the math-only results (the tableaux, the growth parameters) also come as text/latex
    assert sum("text/latex" in d for d in bundles) >= 3


def test_method_cells_show_their_tableaux(executed):
    nb, _ = executed
    heads = {}
    for _, out in _outputs(nb):
        md = out.get("data", {}).get("text/markdown", "")
        if md.startswith("### "):
            heads[md.split("\n", 1)[0]] = out.data
    assert set(heads) == {"### GLM43 (seed §3.2.3), repaired", "### Gauss–Legendre, 2 stages"}
    glm, gauss = heads["### GLM43 (seed §3.2.3), repaired"], heads["### Gauss–Legendre, 2 stages"]
    for mime in SHOWN:
        assert r"\begin{array}" in glm[mime] and tableau_rows(glm[mime]) == [4 + 3]     # s + r rows
        assert tableau_rows(gauss[mime]) == [2 + 1]                                     # s stages and b
    assert r"\sqrt{14595}" in glm["text/latex"] and r"\frac{\sqrt{3}}{6}" in gauss["text/latex"]


def test_proof_order_and_stability_are_shown(executed):
    nb, _ = executed
    md = "\n".join(out.data["text/markdown"] for _, out in _outputs(nb) if "text/markdown" in out.get("data", {}))
    assert md.count("The method is G-symplectic.") == 2
    assert r"$$DA + A^{\mathsf T}D - B^{\mathsf T}GB = \left(\begin{matrix}0 & 0 & 0 & 0\\" in md
    assert "| $t$ | $\\Phi(t)$ | $1/\\gamma(t)$ |" in md                  # Gauss: the order conditions, a table
    assert "controlled to first order (all μ = 0)" in md and r"\xi_{3}(t)" in md
    assert re.search(r"R\(z\) = \\frac\{z\^\{2\} \+ 6 z \+ 12\}\{z\^\{2\} - 6 z \+ 12\}", md)
    assert "The method is A-stable." in md and r"\operatorname{CRootOf}" in md


def tableau_lab_names(book) -> list[str]:
    """The tableau_lab names the code cells of ``book`` use, as written (``tl.load``, ``import
    tableau_lab as tl``, ``from tableau_lab.x import y``, …)."""
    names = []
    for cell in book.cells:
        if cell.cell_type != "code":
            continue
        for node in ast.walk(ast.parse(cell.source)):
            if isinstance(node, ast.Import):
                names += [f"import {a.name} as {a.asname}" for a in node.names if a.name.startswith("tableau_lab")]
            elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("tableau_lab"):
                names += [f"from {node.module} import {a.name}" for a in node.names]
            elif isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "tl":
                names.append(f"tl.{node.attr}")
    return names


def only_top_level(book) -> list[str]:
    """The uses of tableau_lab in ``book`` that are not ``import tableau_lab as tl`` and a public
    name at the package top (the must-show of issue 30)."""
    import tableau_lab as tl
    return [n for n in tableau_lab_names(book)
            if n != "import tableau_lab as tl" and not (n.startswith("tl.") and n[3:] in tl.__all__)]


def test_notebook_uses_only_top_level_names():
    book = nbformat.read(NOTEBOOK, as_version=4)
    assert "import tableau_lab as tl" in tableau_lab_names(book) and not only_top_level(book)
    bad = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(
        "import tableau_lab as tl\nfrom tableau_lab.analysis.order import order\ntl.exact.catalog")])
    assert only_top_level(bad) == ["from tableau_lab.analysis.order import order", "tl.exact"]


def test_stored_notebook_has_todays_outputs(executed):
    """The executed outputs stored in docs/notebook.ipynb are those of the code today (rerun
    ``python tests/test_notebook.py`` after changing a display)."""
    nb, _ = executed
    stored = nbformat.read(NOTEBOOK, as_version=4)

    def shown(book):
        return [{k: v for k, v in out.get("data", {}).items() if k in SHOWN} for _, out in _outputs(book)]
    assert shown(stored) == shown(nb)
    assert [c.source for c in stored.cells] == [c.source for c in nb.cells]
    assert all(not c.metadata for c in stored.cells) and set(stored.metadata) == {"kernelspec", "language_info"}


def test_mathjax_typesets_every_formula(executed):
    """benchmarks/mathjax_check.py: MathJax 3 in node typesets every formula of the executed
    notebook without a TeX error, and finds the errors of a broken output and of the old displays.
    Skipped where node or the npm package mathjax-full (installed by that script) is missing, but
    not in CI: .ci/run installs both and sets TABLEAU_LAB_REQUIRE_MATHJAX=1, and the test then fails."""
    check = benchmark_script("mathjax_check")
    modules = check.PREFIX / "node_modules"
    if shutil.which("node") is None or not (modules / "mathjax-full").exists():
        why = "MathJax not installed: run python benchmarks/mathjax_check.py --install once (node and npm)"
        if os.environ.get("TABLEAU_LAB_REQUIRE_MATHJAX") == "1":
            pytest.fail(why)
        pytest.skip(why)
    nb, _ = executed
    errors, control = check.check(nb, modules)
    assert len(check.formulas(nb)) > 100 and not errors and all(msg for _, msg in control), (errors, control)
    broken = copy.deepcopy(nb)
    broken.cells[1].outputs[0].data["text/markdown"] += r" and $\begin{tabular}{l} x \end{tabular}$"
    assert [msg for _, msg in check.check(broken, modules)[0]] == ["Unknown environment 'tabular'"]


if __name__ == "__main__":
    book = execute()
    nbformat.write(book, NOTEBOOK)
    print(f"{NOTEBOOK}: {len(book.cells)} cells executed and stored", file=sys.stderr)
