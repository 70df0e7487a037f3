"""Typeset every formula of the executed notebook docs/notebook.ipynb with a real MathJax 3 (the
TeX input of JupyterLab 4's MathJax, in node, no browser) and report each TeX error.

    python benchmarks/mathjax_check.py [NOTEBOOK] [--execute]
    python benchmarks/mathjax_check.py --install      (only install MathJax: .ci/run does, before the tests)

The formulas are those a MathJax frontend typesets: every ``text/latex`` output, the ``$$…$$`` and
``$…$`` math of every ``text/markdown`` output and of the Markdown cells.  MathJax runs with all
its TeX packages except ``noerrors`` and ``noundefined``, and every TeX error (an undefined macro,
an unknown environment such as ``tabular``, a misplaced ``&``) is raised, not drawn in red.  As a
control, the displays as they were before issue 19 (``"$" + to_latex() + "$"``) are typeset too and
must fail, so a run that finds no error in the notebook has shown that it can find one.

MathJax is the npm package ``mathjax-full`` 3, installed on first use with npm into
``$TABLEAU_LAB_MATHJAX`` (default ``~/.cache/tableau_lab/mathjax``).  Exit status 0: no error in
the notebook and every control failed; 1: errors; 2: node or npm missing (nothing checked).
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = ROOT / "docs" / "notebook.ipynb"
PREFIX = Path(os.environ.get("TABLEAU_LAB_MATHJAX", Path.home() / ".cache" / "tableau_lab" / "mathjax"))

# TeX to MathML for each [tex, display] of stdin; prints the error message (or null) of each
TYPESET = r"""
const {mathjax} = require('mathjax-full/js/mathjax.js');
const {TeX} = require('mathjax-full/js/input/tex.js');
const {SVG} = require('mathjax-full/js/output/svg.js');
const {liteAdaptor} = require('mathjax-full/js/adaptors/liteAdaptor.js');
const {RegisterHTMLHandler} = require('mathjax-full/js/handlers/html.js');
const {AllPackages} = require('mathjax-full/js/input/tex/AllPackages.js');
RegisterHTMLHandler(liteAdaptor());
const tex = new TeX({packages: AllPackages.filter(p => p !== 'noerrors' && p !== 'noundefined'),
                     formatError: (jax, err) => { throw err; }});
const doc = mathjax.document('', {InputJax: tex, OutputJax: new SVG({fontCache: 'none'})});
const items = JSON.parse(require('fs').readFileSync(0, 'utf8'));
console.log(JSON.stringify(items.map(([t, display]) => {
  try { doc.convert(t, {display}); return null; } catch (e) { return String(e.message || e); }
})));
"""

# math in Markdown as JupyterLab's removeMath finds it: $$…$$ (display) and $…$ (inline), not \$
_MARKDOWN_MATH = re.compile(r"(?<!\\)\$\$(.+?)(?<!\\)\$\$|(?<![\\$])\$(.+?)(?<!\\)\$", re.S)


def markdown_math(md: str) -> list[tuple[str, bool]]:
    """(tex, display) of each formula of a Markdown text."""
    return [(m[1], True) if m[1] is not None else (m[2], False) for m in _MARKDOWN_MATH.finditer(md)]


def formulas(nb) -> list[tuple[str, str, bool]]:
    """(where, tex, display) of every formula a MathJax frontend typesets in the notebook."""
    out = []
    for i, cell in enumerate(nb["cells"], 1):
        if cell["cell_type"] == "markdown":
            out += [(f"cell {i} (Markdown)", t, d) for t, d in markdown_math(_text(cell["source"]))]
            continue
        for k, output in enumerate(cell.get("outputs", []), 1):
            data = output.get("data", {})
            where = f"cell {i}, output {k}"
            if "text/latex" in data:
                latex = _text(data["text/latex"]).strip()
                inner = latex[2:-2] if latex.startswith("$$") and latex.endswith("$$") else latex
                out.append((where + " text/latex", inner, True))
            if "text/markdown" in data:
                out += [(where + " text/markdown", t, d) for t, d in markdown_math(_text(data["text/markdown"]))]
    return out


def _text(source) -> str:
    return "".join(source) if isinstance(source, list) else source


def ensure_mathjax(prefix: Path = PREFIX) -> Path | None:
    """The node_modules folder with mathjax-full (installed with npm when missing), or None."""
    modules = prefix / "node_modules"
    if (modules / "mathjax-full" / "package.json").exists():
        return modules
    npm = shutil.which("npm")
    if npm is None or shutil.which("node") is None:
        return None
    prefix.mkdir(parents=True, exist_ok=True)
    subprocess.run([npm, "install", "--prefix", str(prefix), "--no-audit", "--no-fund", "--silent", "mathjax-full@3"],
                   check=True, timeout=600)
    return modules


def typeset_errors(items: list[tuple[str, bool]], modules: Path) -> list[str | None]:
    """MathJax's error message for each (tex, display), None where it typesets."""
    p = subprocess.run(["node", "-e", TYPESET], input=json.dumps(items), capture_output=True, text=True,
                       env={**os.environ, "NODE_PATH": str(modules)}, timeout=300)
    if p.returncode != 0:
        raise RuntimeError(f"node failed: {p.stderr[-800:]}")
    return json.loads(p.stdout)


def old_displays() -> list[tuple[str, str, bool]]:
    """The control: results as ``Result._repr_latex_`` showed them before issue 19."""
    from tableau_lab.analysis.order import order
    from tableau_lab.analysis.symplectic import g_symplectic
    from tableau_lab.exact.library import library_path
    from tableau_lab.exact.tableau_json import load
    rk4, glm = load(library_path("rk4")), load(library_path("glm43"))
    return [(f"old {what}", r.to_latex(), False) for what, r in
            (("order(rk4)", order(rk4)), ("g_symplectic(glm43)", g_symplectic(glm)), ("order(glm43)", order(glm)))]


def check(nb, modules: Path) -> tuple[list, list]:
    """(errors in the notebook, MathJax's verdict on each control): lists of (where, message),
    the message None for a control that typesets (which it must not)."""
    found, control = formulas(nb), old_displays()
    verdicts = typeset_errors([(t, d) for _, t, d in found + control], modules)
    errors = [(w, e) for (w, _, _), e in zip(found, verdicts, strict=False) if e is not None]
    return errors, [(w, e) for (w, _, _), e in zip(control, verdicts[len(found):], strict=False)]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("notebook", nargs="?", default=str(NOTEBOOK))
    ap.add_argument("--execute", action="store_true", help="execute the notebook first (nbclient, kernel python3)")
    ap.add_argument("--install", action="store_true", help="install MathJax (npm) if missing and stop (.ci/run)")
    args = ap.parse_args(argv)
    modules = ensure_mathjax()
    if modules is None:
        print("node or npm is not installed: nothing checked", file=sys.stderr)
        return 2
    if args.install:
        print(f"MathJax in {modules}")
        return 0
    import nbformat
    nb = nbformat.read(args.notebook, as_version=4)
    if args.execute:
        from nbclient import NotebookClient
        NotebookClient(nb, kernel_name="python3", timeout=120,
                       resources={"metadata": {"path": str(Path(args.notebook).resolve().parent)}}).execute()
    errors, control = check(nb, modules)
    version = json.loads((modules / "mathjax-full" / "package.json").read_text())["version"]
    print(f"{args.notebook}: {len(formulas(nb))} formulas typeset with MathJax {version}: {len(errors)} errors")
    for where, msg in errors:
        print(f"  {where}: {msg}")
    print("control, the displays before issue 19 (each must fail):")
    for where, msg in control:
        print(f"  {where}: {msg or 'NO ERROR: the check cannot see errors'}")
    return 1 if errors or None in (msg for _, msg in control) else 0


if __name__ == "__main__":
    sys.exit(main())
