"""The notebook cell of issue 32: five methods on three problems, 10⁴ steps each, from a fresh
Python process (a new notebook kernel), with an empty compiled-loop cache ("cold") and with the
cache that the cold cell left ("warm"), in interleaved rounds; prints the median wall seconds of
the cell, their ratio (the issue's bound: cold < 3× warm) and how many times the compile notice
was shown per problem (the bound: once).

The cell is timed from ``import tableau_lab`` to its last result; after the clock stops, the cold
process waits for its background compiles (numeric/background.py) so that the warm rounds find
every loop the cell wants in the cache.  A benchmark, not a test: the machine's load moves it.

    python benchmarks/bench_notebook.py [--rounds 3] [--fresh-shared] [--json]
"""
from __future__ import annotations

import argparse
import json
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_startup import installation_env

ROOT = Path(__file__).resolve().parents[1]
METHODS = ("gauss2", "glm43", "rk4", "stormer_verlet", "implicit_midpoint")
PROBLEMS = ("pendulum", "kepler", "henon_heiles")
STEPS = 10_000
H = "1/100"

CELL = f"""
import time
t0 = time.perf_counter()
import tableau_lab as tl
loops = []
for problem in {PROBLEMS!r}:
    for method in {METHODS!r}:
        sol = tl.integrate(method, problem, None, (0, {STEPS} * {H}), "{H}", notice=False)
        loops.append(sol.loop)
seconds = time.perf_counter() - t0
from tableau_lab.numeric import background
background.wait_all()
import json, sys
print(json.dumps({{"seconds": seconds, "loops": loops}}))
"""


def cell(cache: str, shared: str | None = None) -> dict:
    """Run the cell in a fresh process on the compiled-loop cache ``cache`` (and the shared loops'
    folder ``shared``; None: the installation's): its seconds, the loop each run took, and the
    compile notices it printed per problem."""
    env = installation_env(TABLEAU_LAB_CACHE=cache, PYTHONPATH=str(ROOT))
    if shared is not None:
        env["TABLEAU_LAB_SHARED_CACHE"] = shared
    done = subprocess.run([sys.executable, "-c", CELL], env=env, capture_output=True, text=True, check=True)
    out = json.loads(done.stdout.strip().splitlines()[-1])
    notices = [line for line in done.stderr.splitlines() if "compiling" in line]
    out["notices"] = {p: sum(bool(re.search(rf"\b{p}\b", line)) for line in notices) for p in PROBLEMS}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--fresh-shared", action="store_true",
                    help="a fresh installation: an empty shared-loop folder for each cold cell (its warm cell "
                         "keeps what the cold one built), not the installation's")
    args = ap.parse_args(argv)
    cold, warm = [], []
    with tempfile.TemporaryDirectory(prefix="tableau_lab_bench_notebook_") as tmp:
        for k in range(args.rounds):
            cache = str(Path(tmp) / f"cache{k}")
            shared = str(Path(tmp) / f"shared{k}") if args.fresh_shared else None
            cold.append(cell(cache, shared))
            warm.append(cell(cache, shared))
    c = statistics.median(r["seconds"] for r in cold)
    w = statistics.median(r["seconds"] for r in warm)
    res = {"cell": f"{len(METHODS)} methods × {len(PROBLEMS)} problems × {STEPS} steps",
           "cold_seconds": round(c, 2), "warm_seconds": round(w, 2), "cold_over_warm": round(c / w, 2),
           "notices_per_problem_cold": cold[0]["notices"], "notices_per_problem_warm": warm[0]["notices"],
           "loops_cold": cold[0]["loops"], "loops_warm": warm[0]["loops"], "rounds": args.rounds,
           "shared": "fresh" if args.fresh_shared else "installation's"}
    if args.json:
        print(json.dumps(res, ensure_ascii=False))
    else:
        print(f"{res['cell']}, median of {args.rounds} interleaved rounds, shared loops: {res['shared']}:")
        print(f"  cold {c:.2f} s, warm {w:.2f} s: cold/warm {c / w:.2f} (issue 32: < 3)")
        print(f"  compile notices per problem, cold: {res['notices_per_problem_cold']}, "
              f"warm: {res['notices_per_problem_warm']}")
        print(f"  loops cold: {', '.join(res['loops_cold'])}")
        print(f"  loops warm: {', '.join(res['loops_warm'])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
