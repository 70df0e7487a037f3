"""A screenshot of docs/notebook.ipynb as a browser renders it with MathJax 3 (issue 19, item 3):
the stored notebook exported to HTML by nbconvert, MathJax from the local mathjax-full package
that ``benchmarks/mathjax_check.py`` installs (no network), rendered by headless Chromium.

    python benchmarks/notebook_screenshot.py [--out docs/notebook_mathjax.png]

Needs ``pip install nbconvert`` and a ``chromium`` (or ``chromium-browser``/``google-chrome``)
executable (``apt-get install chromium``).  A script, not a test."""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MATHJAX = (Path.home() / ".cache" / "tableau_lab" / "mathjax" / "node_modules" / "mathjax-full" / "es5"
           / "tex-chtml-full.js")
# MathJax 3 reads $…$ only when told (Jupyter's own setting); nbconvert's template configures MathJax 2
CONFIG = "<script>window.MathJax = {tex: {inlineMath: [['$', '$'], ['\\\\(', '\\\\)']]}};</script>"
SIZE = "1100,2600"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "docs" / "notebook_mathjax.png"))
    args = ap.parse_args(argv)
    browser = next((b for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b)), None)
    if browser is None or not MATHJAX.exists():
        print("needs chromium and the local MathJax (python benchmarks/mathjax_check.py installs it)", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, "-m", "jupyter", "nbconvert", "--to", "html",
                        str(ROOT / "docs" / "notebook.ipynb"), "--output-dir", tmp,
                        f"--HTMLExporter.mathjax_url=file://{MATHJAX}"], check=True, capture_output=True)
        html = Path(tmp) / "notebook.html"
        html.write_text(html.read_text().replace("<head>", "<head>" + CONFIG, 1))
        subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--allow-file-access-from-files",
                        "--virtual-time-budget=15000", f"--window-size={SIZE}", f"--screenshot={args.out}",
                        html.as_uri()], check=True, capture_output=True, timeout=120)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
