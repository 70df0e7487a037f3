"""The table of docs/reliability.md: every case of tests/hostile_cases.py through the command
line (``tableau_lab.cli.main``, each in a forked child process of its own, with its own folder as
working directory), counted per surface and category: refused with the expected exit code,
tracebacks (a raw one or an internal error), hangs (longer than the case's budget + 5 s),
executions (a file the injection cases would create appears anywhere), files left beside the
input on refusal, and the largest peak resident memory of a case (the child's ``ru_maxrss``, which
counts the pages it shares with this process: an upper bound; at most ``PEAK_MB``); the slowest
case.

    python benchmarks/hostile_table.py [--write docs/reliability.md]
"""
from __future__ import annotations

import argparse
import os
import pickle
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from hostile_cases import CASES, SLACK, run_case  # noqa: E402

from tableau_lab.cli import main  # noqa: E402

BEGIN, END = "<!-- hostile table: begin -->", "<!-- hostile table: end -->"
PEAK_MB = 1024           # the largest peak memory a hostile case may reach (issue 29: under 1 GB)


def _row(case) -> dict:
    r = run_case(case, main)
    return {"id": case.id, "surface": case.surface, "category": case.category, "ok": r["code"] == case.exit,
            "refused": r["code"] == 2, "traceback": "Traceback" in r["err"] or "internal error" in r["err"],
            "hang": r["seconds"] > r["budget"] + SLACK, "executed": r["executed"], "left": len(r["added"]),
            "seconds": r["seconds"]}


def row(case) -> dict:
    """:func:`_row` in a forked child: its result through a pipe, its peak memory from ``wait4``."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:                                        # the child: one case, then exit without clean-up
        os.close(read)
        try:
            out = _row(case)
        except BaseException as exc:                    # reported as a traceback row
            out = {"id": case.id, "surface": case.surface, "category": case.category, "ok": False, "refused": False,
                   "traceback": True, "hang": False, "executed": False, "left": 0, "seconds": 0.0,
                   "error": repr(exc)[:200]}
        with os.fdopen(write, "wb") as f:
            pickle.dump(out, f)
        os._exit(0)
    os.close(write)
    with os.fdopen(read, "rb") as f:
        data = f.read()
    _, _, usage = os.wait4(pid, 0)
    out = pickle.loads(data) if data else {"id": case.id, "surface": case.surface, "category": case.category,
                                           "ok": False, "refused": False, "traceback": True, "hang": False,
                                           "executed": False, "left": 0, "seconds": 0.0}
    out["peak_mb"] = usage.ru_maxrss / 1024             # kilobytes on Linux
    return out


def table(rows) -> str:
    groups = defaultdict(list)
    for r in rows:
        groups[r["surface"], r["category"]].append(r)
    lines = ["| surface | category | cases | refused, exit 2 | as expected | tracebacks | hangs | executions | "
             "files left | peak MB |", "|---|---|---|---|---|---|---|---|---|---|"]
    for (s, c), rs in sorted(groups.items()):
        lines.append(f"| {s} | {c} | {len(rs)} | {sum(r['refused'] for r in rs)} | {sum(r['ok'] for r in rs)} | "
                     f"{sum(r['traceback'] for r in rs)} | {sum(r['hang'] for r in rs)} | "
                     f"{sum(r['executed'] for r in rs)} | {sum(r['left'] for r in rs)} | "
                     f"{max(r['peak_mb'] for r in rs):.0f} |")
    tot = {k: sum(r[k] for r in rows) for k in ("refused", "ok", "traceback", "hang", "executed", "left")}
    lines.append(f"| **all** | | **{len(rows)}** | {tot['refused']} | {tot['ok']} | {tot['traceback']} | {tot['hang']} "
                 f"| {tot['executed']} | {tot['left']} | {max(r['peak_mb'] for r in rows):.0f} |")
    slow, big = max(rows, key=lambda r: r["seconds"]), max(rows, key=lambda r: r["peak_mb"])
    lines += ["", f"Slowest case: `{slow['id']}`, {slow['seconds']:.1f} s (the budget cases run with `--timeout 3`); "
              f"largest peak memory: `{big['id']}`, {big['peak_mb']:.0f} MB (limit {PEAK_MB} MB; the child's peak "
              "counts the pages it shares with the table's process)."]
    return "\n".join(lines)


def main_table(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--write", metavar="DOC", help="replace the table between the markers of DOC")
    args = ap.parse_args(argv)
    rows = [row(c) for c in CASES]
    out = table(rows)
    print(out)
    bad = [r["id"] for r in rows
           if not r["ok"] or r["traceback"] or r["hang"] or r["executed"] or r["left"] or r["peak_mb"] > PEAK_MB]
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
