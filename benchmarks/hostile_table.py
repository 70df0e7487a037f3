"""The table of docs/reliability.md: every case of tests/hostile_cases.py through the command
line (``tableau_lab.cli.main``, in this process, each in its own folder as working directory),
counted per surface and category: refused with the expected exit code, tracebacks (a raw one or
an internal error), hangs (longer than the case's budget + 5 s), executions (a file the
injection cases would create appears anywhere), files left beside the input on refusal; the
slowest case.

    python benchmarks/hostile_table.py [--write docs/reliability.md]
"""
from __future__ import annotations

import argparse
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from hostile_cases import CASES, SLACK, run_case  # noqa: E402

from tableau_lab.cli import main  # noqa: E402

BEGIN, END = "<!-- hostile table: begin -->", "<!-- hostile table: end -->"


def row(case) -> dict:
    r = run_case(case, main)
    return {"id": case.id, "surface": case.surface, "category": case.category, "ok": r["code"] == case.exit,
            "refused": r["code"] == 2, "traceback": "Traceback" in r["err"] or "internal error" in r["err"],
            "hang": r["seconds"] > r["budget"] + SLACK, "executed": r["executed"], "left": len(r["added"]),
            "seconds": r["seconds"]}


def table(rows) -> str:
    groups = defaultdict(list)
    for r in rows:
        groups[r["surface"], r["category"]].append(r)
    lines = ["| surface | category | cases | refused, exit 2 | as expected | tracebacks | hangs | executions | "
             "files left |", "|---|---|---|---|---|---|---|---|---|"]
    for (s, c), rs in sorted(groups.items()):
        lines.append(f"| {s} | {c} | {len(rs)} | {sum(r['refused'] for r in rs)} | {sum(r['ok'] for r in rs)} | "
                     f"{sum(r['traceback'] for r in rs)} | {sum(r['hang'] for r in rs)} | "
                     f"{sum(r['executed'] for r in rs)} | {sum(r['left'] for r in rs)} |")
    tot = {k: sum(r[k] for r in rows) for k in ("refused", "ok", "traceback", "hang", "executed", "left")}
    lines.append(f"| **all** | | **{len(rows)}** | {tot['refused']} | {tot['ok']} | {tot['traceback']} | {tot['hang']} "
                 f"| {tot['executed']} | {tot['left']} |")
    slow = max(rows, key=lambda r: r["seconds"])
    lines += ["", f"Slowest case: `{slow['id']}`, {slow['seconds']:.1f} s (the budget cases run with `--timeout 3`)."]
    return "\n".join(lines)


def main_table(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--write", metavar="DOC", help="replace the table between the markers of DOC")
    args = ap.parse_args(argv)
    rows = [row(c) for c in CASES]
    out = table(rows)
    print(out)
    bad = [r["id"] for r in rows if not r["ok"] or r["traceback"] or r["hang"] or r["executed"] or r["left"]]
    if bad:
        print("not as expected: " + ", ".join(bad), file=sys.stderr)
    if args.write:
        doc = Path(args.write)
        text = doc.read_text()
        i, j = text.index(BEGIN) + len(BEGIN), text.index(END)
        doc.write_text(text[:i] + "\n" + out + "\n" + text[j:])
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main_table())
