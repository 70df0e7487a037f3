"""The hard-case suite's tables in docs/stability.md (between <!-- suite-tables --> and
<!-- /suite-tables -->), from the suite's own summary (no runs):

    python -m tableau_lab suite                      # writes reports/suite/summary.json (about 11 min)
    python benchmarks/suite_tables.py --write docs/stability.md

Max |H − H₀| over each run, or "stopped"/"failed" with the time, per method and scene, without and
with projection."""
from __future__ import annotations

import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

from doc_blocks import cli  # noqa: E402

SUMMARY = ROOT / "reports" / "suite" / "summary.json"
BLOCK = "suite-tables"
SCENES = [("suite_pendulum_q23", "pendulum q₀ = 2.3"), ("suite_pendulum_separatrix", "pendulum q₀ = 3.13"),
          ("suite_kepler_e09", "Kepler e = 0.9"), ("suite_henon_heiles", "Hénon–Heiles"),
          ("suite_outer_solar_system", "outer solar system"), ("suite_fpu", "FPU ω = 50")]
SUPERSCRIPT = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")


def _time(t: float) -> str:
    if t >= 1e4:
        mant, exp = f"{t:.1e}".split("e")
        return f"{mant}·10{str(int(exp)).translate(SUPERSCRIPT)}"
    return f"{t:.2g}" if t < 10 else f"{t:.0f}"


def cell(row) -> str:
    if row["status"] != "completed":
        return f"**{row['status']}** t = {_time(row['t_end'])}"
    return f"{row['max_H_error']:.0e}"


def tables(summary: dict) -> str:
    rows = summary["rows"]
    methods = list(dict.fromkeys(r["file"] for r in rows))
    by = {(r["file"], r["scene"], bool(r["projection"])): r for r in rows}
    out = [f"The suite ran {summary['runs']} runs in {summary['wall_seconds']:.0f} s wall time with "
           f"{summary['workers']} workers (`reports/suite/summary.md` has every row: status, max |H − H₀|, "
           "largest parasitic component, measured against predicted log-growth, seconds). Max |H − H₀| over the "
           "run, or \"stopped\"/\"failed\" with the time:"]
    for projected, title in ((False, "Without projection:"), (True, "With projection:")):
        out += ["", title, "", "| method | " + " | ".join(h for _, h in SCENES) + " |",
                "|---|" + "---|" * len(SCENES)]
        for m in methods:
            out.append(f"| {m} | " + " | ".join(cell(by[m, sc, projected]) if (m, sc, projected) in by else "—"
                                                  for sc, _ in SCENES) + " |")
    return "\n".join(out)


def make() -> str:
    return tables(json.loads(SUMMARY.read_text()))


def main(argv=None) -> int:
    return cli(__doc__.splitlines()[0], BLOCK, make, argv)


if __name__ == "__main__":
    raise SystemExit(main())
