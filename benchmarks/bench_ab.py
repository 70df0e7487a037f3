"""Two checkouts side by side on the rows of ``tableau-lab bench``: is any row slower?

    python benchmarks/bench_ab.py OLD_CHECKOUT NEW_CHECKOUT [--rounds 3] [--reps 5] [--json FILE]

Each round runs every case once in each checkout (``tableau-lab bench --method … --json``, a
fresh process each, the checkout on PYTHONPATH, each checkout with its own compile cache under
a temporary folder, so the two never share a compiled loop), alternating which goes first, and
prints per case the minimum and the median over the rounds of the bench's own median µs/step,
and the new/old ratios.  Interference from other work only adds time, so on a shared machine
the ratio of the minima is the steadier; the medians show the scatter.  A benchmark, not a test.

Then the code the rows ran is compared: every loop module the two checkouts generated (their
compile caches), its provenance stamp and the problem modules' names (digests of their text) set
aside, and the limits' constants the generated modules import.  Identical text, constants and
numba give identical machine code, so a ratio away from 1 is the machine's, not the change's.
"""
from __future__ import annotations

import argparse
import collections
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

#: method, problem, h, precision: the rows of docs/speed.md's bench table
CASES = [("gauss2", "pendulum", "1/100", "float64"), ("gauss2", "kepler", "1/100", "float64"),
         ("gauss3", "pendulum", "1/100", "float64"), ("gauss3", "kepler", "1/100", "float64"),
         ("implicit_midpoint", "pendulum", "1/100", "float64"), ("implicit_midpoint", "kepler", "1/100", "float64"),
         ("rk4", "pendulum", "1/100", "float64"), ("rk4", "kepler", "1/100", "float64"),
         ("glm43", "pendulum", "1/100", "float64"), ("glm43", "kepler", "1/100", "float64"),
         ("example4_glm", "pendulum", "1/100", "float64"),
         ("gauss2", "fpu", "1/1000", "float64"), ("gauss2", "outer_solar_system", "10", "float64"),
         ("gauss2", "pendulum", "1/100", "dd"), ("gauss2", "kepler", "1/100", "dd")]


def bench_once(tree: Path, cache: Path, case: tuple, reps: int) -> float:
    """The bench's median µs/step of ``case`` in checkout ``tree`` (10⁵ steps; dd 2·10⁴)."""
    method, problem, h, precision = case
    steps = "20000" if precision == "dd" else "100000"
    env = dict(os.environ, PYTHONPATH=str(tree), TABLEAU_LAB_CACHE=str(cache))
    done = subprocess.run([sys.executable, "-m", "tableau_lab", "bench", "--method", f"methods/{method}.json",
                           "--problem", problem, "--h", h, "--precision", precision, "--steps", steps,
                           "--reps", str(reps), "--no-memory", "--json", "--out", str(cache / "out")],
                          cwd=tree, env=env, capture_output=True, text=True, check=True)
    return float(json.loads(done.stdout)["us_per_step"])


def generated(cache: Path) -> collections.Counter:
    """The texts of the loop and problem modules in a checkout's compile cache, each without its
    ``# sources`` stamp and with the problem modules' names (digests of their text) replaced."""
    out: collections.Counter = collections.Counter()
    for path in sorted((cache / "kernels").glob("tableau_lab_*.py")):
        text = "\n".join(line for line in path.read_text().splitlines() if not line.startswith("# sources"))
        out[re.sub(r"tableau_lab_problem_[0-9a-f]+", "tableau_lab_problem_X", text)] += 1
    return out


def constants(tree: Path) -> dict:
    """The constants of ``tableau_lab.numeric.limits`` in ``tree`` (what the loops import)."""
    code = ("import json, tableau_lab.numeric.limits as L; "
            "print(json.dumps({k: repr(v) for k, v in vars(L).items() if k.isupper()}))")
    done = subprocess.run([sys.executable, "-c", code], cwd=tree, env=dict(os.environ, PYTHONPATH=str(tree)),
                          capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def same_code(trees: dict, tmp: Path) -> None:
    """Print whether the two checkouts ran the same generated code with the same constants."""
    old, new = generated(tmp / "old"), generated(tmp / "new")
    print(f"\ngenerated modules: {sum(old.values())} old, {sum(new.values())} new, "
          f"{sum((old & new).values())} of the same text (stamp and problem-module names aside)")
    co, cn = constants(trees["old"]), constants(trees["new"])
    changed = sorted(k for k in co.keys() | cn.keys() if co.get(k) != cn.get(k))
    print("limits constants that differ: " + (", ".join(f"{k} ({co.get(k, '-')} → {cn.get(k, '-')})"
                                                        for k in changed) or "none"))
    texts = "\n".join((*old, *new))
    used = [k for k in changed if re.search(rf"\b{k}\b", texts)]
    print("of those, named in the generated code: " + (", ".join(used) or "none"))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--json", type=Path, help="also write the raw times here")
    args = ap.parse_args(argv)
    trees = {"old": args.old.resolve(), "new": args.new.resolve()}
    times: dict = {}
    with tempfile.TemporaryDirectory() as tmp:
        for rnd in range(args.rounds):
            for i, case in enumerate(CASES):
                for who in (("old", "new") if (rnd + i) % 2 == 0 else ("new", "old")):
                    us = bench_once(trees[who], Path(tmp) / who, case, args.reps)
                    times.setdefault(" ".join(case), {}).setdefault(who, []).append(us)
        if args.json:
            from tableau_lab.files import atomic_write_text
            atomic_write_text(args.json, json.dumps(times, indent=1))
        print("| case | old µs/step min / median | new µs/step min / median | new/old min | new/old median |")
        print("|---|---|---|---|---|")
        for key, t in times.items():
            o, n = t["old"], t["new"]
            print(f"| {key} | {min(o):.4f} / {statistics.median(o):.4f} | {min(n):.4f} / {statistics.median(n):.4f} "
                  f"| {min(n) / min(o):.3f} | {statistics.median(n) / statistics.median(o):.3f} |")
        same_code(trees, Path(tmp))
    return 0


if __name__ == "__main__":
    sys.exit(main())
