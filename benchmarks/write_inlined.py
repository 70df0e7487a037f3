"""Write the pure loop's inlined texts shipped with the package (``tableau_lab/numeric/inlined``):

    python benchmarks/write_inlined.py

The pure (Python) loop runs stepcore's functions with their one-line operations written in place
(``tableau_lab/numeric/inliner.py``); the rewritten text depends only on the package's source, so
it is made here, once, for the loops a run builds — float64 with a problem's generated code, and
mpmath — rather than by every fresh installation (about 0.2 s of a first short run).  Texts of an
older source are removed.  ``tests/test_inliner.py`` fails while a shipped text is missing or
differs from what the inliner makes now.
"""
from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["TABLEAU_LAB_CACHE"] = tmp
        from tableau_lab.files import atomic_copy
        from tableau_lab.numeric import inliner, kernels
        from tableau_lab.numeric.codegen import compile_problem
        shipped = inliner.SHIPPED
        inliner.SHIPPED = Path(tmp) / "none"                 # make every text, whatever ships now
        for backend, dps in (("numpy", None), ("mpmath", 30)):
            prob = compile_problem("pendulum", backend, dps)
            kernels.pure_loop(prob, "float64" if backend == "numpy" else "mp")
        made = sorted(kernels.code_dir().glob("inlined_*.txt"))
        shipped.mkdir(exist_ok=True)
        for old in shipped.glob("inlined_*.txt"):
            if old.name not in {p.name for p in made}:
                old.unlink()
                print(f"removed {old.name}")
        for path in made:
            atomic_copy(path, shipped / path.name)         # no half-written text in the package
            print(f"wrote {shipped / path.name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
