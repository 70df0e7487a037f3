"""A first run against a warm one and against ``verify``: the start-up of a quick run.

    python benchmarks/bench_startup.py [--rounds 5] [--steps 1000] [--tree CHECKOUT ...] [--json FILE]

Per case (2-stage Gauss on the pendulum, GLM43 on Kepler; ``tableau-lab run --method
methods/FILE.json --problem NAME --h 0.01 --steps 1000 --json``) three commands, each a fresh
process, wall time measured around it: the run with an EMPTY compile cache (a fresh
``TABLEAU_LAB_CACHE`` folder each round), the same run warm (the cache kept from the previous
round; round 0 fills it) and ``tableau-lab verify methods/gauss2.json``.  The rounds interleave
every command (the machine may be shared: a slow spell spreads over all of them) and the
medians are printed with the ratios issue 32 sets targets for: cold/warm ≤ 1.5, warm/verify ≤ 2.
Each run's record says which loop ran and what it compiled (``loop``, ``compile_seconds``).
``--tree``: the checkout put on PYTHONPATH (default: this one); given twice or more, the
checkouts take turns inside every round (before/after on the same machine state), each with its
own caches.  Python's bytecode cache (``__pycache__``) is kept, as an installation has it
(pip compiles it; a shell with ``PYTHONDONTWRITEBYTECODE`` set recompiles every module of every
command, about 0.1 s, and is not what a user meets).  A benchmark, not a test.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
#: method file stem, problem: the cases of issue 32
CASES = [("gauss2", "pendulum"), ("glm43", "kepler")]
TARGETS = {"cold/warm": 1.5, "warm/verify": 2.0}


def installation_env(**extra: str) -> dict:
    """This process's environment as a user's installation runs a command, with ``extra`` set:
    with its bytecode cache (pip compiles it; ``PYTHONDONTWRITEBYTECODE``, which a shell may set,
    removed).  The one environment of the timing scripts (bench_startup, bench_notebook, latency)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env.update(extra)
    return env


def timed(cmd: list, tree: Path, cache: Path) -> tuple:
    """(wall seconds, the command's JSON output or None) of one fresh process."""
    env = installation_env(PYTHONPATH=str(tree), TABLEAU_LAB_CACHE=str(cache))
    env.pop("TABLEAU_LAB_KERNEL", None)          # the kernel the package chooses
    t0 = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "tableau_lab", *cmd], cwd=tree, env=env, capture_output=True,
                          text=True, check=True)
    wall = time.perf_counter() - t0
    try:
        return wall, json.loads(done.stdout)
    except ValueError:
        return wall, None


def run_cmd(method: str, problem: str, steps: int) -> list:
    return ["run", "--method", f"methods/{method}.json", "--problem", problem, "--h", "0.01", "--steps", str(steps),
            "--json"]


def one_round(tree: Path, tmp: Path, rnd: int, steps: int, times: dict, records: dict) -> None:
    """Every command once in ``tree``, its caches under ``tmp``; round 0 only fills the warm
    cache (not counted)."""
    warm = tmp / "warm"
    for method, problem in CASES:
        label = f"{method} {problem}"
        for which in (("cold", "warm") if rnd % 2 == 0 else ("warm", "cold")):
            cache = tmp / f"cold{rnd}_{method}" if which == "cold" else warm
            wall, rec = timed(run_cmd(method, problem, steps), tree, cache)
            if rnd:
                times.setdefault(f"{label} {which}", []).append(wall)
                records.setdefault(f"{label} {which}", []).append(rec)
    wall, _ = timed(["verify", "methods/gauss2.json"], tree, warm)
    if rnd:
        times.setdefault("verify gauss2", []).append(wall)


def rounds(trees: list, n: int, steps: int, log=print) -> dict:
    """Per checkout, the wall times per command over ``n`` interleaved rounds, {label: [seconds
    …]}, and the records of the runs, {label: [record …]}."""
    res: dict = {str(tree): {"times": {}, "records": {}} for tree in trees}
    with tempfile.TemporaryDirectory(prefix="bench_startup_") as tmp:
        for rnd in range(n + 1):
            for tree in (trees if rnd % 2 == 0 else trees[::-1]):
                r = res[str(tree)]
                one_round(tree, Path(tmp) / f"tree{trees.index(tree)}", rnd, steps, r["times"], r["records"])
                if rnd:
                    log(f"round {rnd}/{n} {tree}: " + ", ".join(f"{k} {v[-1]:.2f} s" for k, v in r["times"].items()))
    return res


def summary(res: dict) -> dict:
    """Medians and the ratios per case (``res``: one checkout's times and records)."""
    med = {k: statistics.median(v) for k, v in res["times"].items()}
    cases = {}
    for method, problem in CASES:
        label = f"{method} {problem}"
        cold, warm = med[f"{label} cold"], med[f"{label} warm"]
        last = res["records"][f"{label} warm"][-1] or {}
        first = res["records"][f"{label} cold"][-1] or {}
        cases[label] = {"cold": cold, "warm": warm, "verify": med["verify gauss2"], "cold/warm": cold / warm,
                        "warm/verify": warm / med["verify gauss2"], "loop cold": first.get("loop", "?"),
                        "loop warm": last.get("loop", "?"),
                        "compile_seconds cold": first.get("compile_seconds", "?")}
    return cases


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--tree", type=Path, action="append", help="a checkout to measure (PYTHONPATH); "
                    "default this one; repeat to interleave several")
    ap.add_argument("--json", type=Path, help="also write the raw times and the summary here")
    args = ap.parse_args(argv)
    trees = [t.resolve() for t in (args.tree or [ROOT])]
    load = [os.getloadavg()[0]]
    res = rounds(trees, args.rounds, args.steps)
    load.append(os.getloadavg()[0])
    out = {}
    for tree in trees:
        cases = out[str(tree)] = summary(res[str(tree)])
        print(f"median wall seconds over {args.rounds} interleaved rounds, {args.steps} steps, h = 0.01 ({tree})")
        print(f"{'case':<18}{'cold':>8}{'warm':>8}{'verify':>8}{'cold/warm':>11}{'warm/verify':>13}"
              "  loop (cold, warm)")
        for label, c in cases.items():
            print(f"{label:<18}{c['cold']:>8.2f}{c['warm']:>8.2f}{c['verify']:>8.2f}{c['cold/warm']:>11.2f}"
                  f"{c['warm/verify']:>13.2f}  {c['loop cold']}, {c['loop warm']}")
    print("targets (issue 32): " + ", ".join(f"{k} ≤ {v}" for k, v in TARGETS.items())
          + f"; load average {load[0]:.1f} at the start, {load[1]:.1f} at the end")
    if args.json:
        from tableau_lab.files import atomic_write_text
        atomic_write_text(args.json, json.dumps({"rounds": args.rounds, "steps": args.steps, "load": load, "raw": res,
                                                 "summary": out}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
