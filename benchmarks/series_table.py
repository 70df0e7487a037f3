"""The structure of every method of methods/ as a B-series (the underlying one-step method for
GLMs), exactly, and the time of a 5-stage modified equation to order 8:

    python benchmarks/series_table.py --write docs/bseries.md

rewrites the part of docs/bseries.md between the markers <!-- series-table --> and
<!-- /series-table --> (without --write: prints it)."""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from doc_blocks import write_block  # noqa: E402

from tableau_lab.analysis.method_series import method_series  # noqa: E402
from tableau_lab.analysis.modified import modified_equation  # noqa: E402
from tableau_lab.analysis.series_structure import structure  # noqa: E402
from tableau_lab.exact.tableau_json import load  # noqa: E402

ORDER = 9
BLOCK = "series-table"


def table() -> str:
    def cell(n):
        return f"≥ {n}" if n >= ORDER else str(n)
    m5 = load(ROOT / "methods" / "butcher_effective5.json")      # first: cold caches (tree partitions)
    t0 = time.perf_counter()
    me = modified_equation(m5, 8)
    dt5 = time.perf_counter() - t0
    rows = ["| method | kind | order | symplectic | conjugate-symplectic | symmetric | energy-preserving | time |",
            "|---|---|---|---|---|---|---|---|"]
    skipped = []
    for path in sorted((ROOT / "methods").glob("*.json")):
        m = load(path)
        if m.kind == "prk" or m.parameters:
            why = "a partitioned method: P-series" if m.kind == "prk" else "free parameters"
            skipped.append(f"`{path.name}` ({why})")
            continue
        t0 = time.perf_counter()
        try:
            s = structure(method_series(m, ORDER).phi)
        except ValueError as exc:
            skipped.append(f"`{path.name}` ({exc})")
            continue
        dt = time.perf_counter() - t0
        rows.append(f"| `{path.name}` | {m.kind} | {s.order} | {cell(s.symplectic)} | {cell(s.conjugate_symplectic)} | "
                    f"{cell(s.symmetric)} | {cell(s.energy_preserving)} | {dt:.2f} s |")
    out = [f"Every tree up to order {ORDER} (\"≥ {ORDER}\": holds to the budget). Not in the table: "
           + ", ".join(skipped) + ".", "", *rows, "",
           f"Modified equation of `{m5.name}` ({m5.s} stages) to order 8 ({len(me.field.items())} trees): "
           f"{dt5:.2f} s in a fresh process (the tree partitions are computed, then cached)."]
    return "\n".join(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", metavar="MD", help="the markdown file to update between the markers")
    args = ap.parse_args()
    text = table()
    if not args.write:
        print(text)
        return 0
    path = Path(args.write)
    write_block(path, BLOCK, text)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
