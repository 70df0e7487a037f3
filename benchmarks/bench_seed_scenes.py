"""The 17 seed scenes (``reports/scenes/*.json``) from an empty compile cache and again warm:
issue 32's bound is cold ≤ 1.5× warm.

    python benchmarks/bench_seed_scenes.py [--tree CHECKOUT] [--rounds N] [--shared DIR | --fresh-shared]

One ``tableau-lab run reports/scenes/*.json --out DIR`` with a fresh, empty ``TABLEAU_LAB_CACHE``
("cold"), then the same command on the cache it left ("warm"); wall seconds of each and their
ratio, and the CPU seconds (user + system) of the command's process tree (its background
compiles included, except one still running when the command ends: it dies unwaited) with the
load average before and after — the machine's other work shows in the wall time, less in the
CPU time; the command's own process's CPU seconds (the scenes' work, no background compile)
are given apart.  The loops shared by every problem (``tableau-lab warm-up``) live apart from that
cache: ``--shared DIR`` uses (and, if empty, first builds with ``tableau-lab warm-up``, timed
apart) the shared loops in DIR; ``--fresh-shared`` gives the cold run an empty shared folder too
— an installation's very first run (the runs build the ones they need in the background).
``--tree``: the checkout on PYTHONPATH (default this one; an older checkout has no shared
loops).  A benchmark, not a test.
"""
from __future__ import annotations

import argparse
import glob
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


# ``tableau-lab`` (python -m tableau_lab) adding the CPU seconds of its own processes — itself and
# the child it forks to run the command (cli.run_with_hard_deadline, which leaves by os._exit) —
# at their exits to $BENCH_SELF_CPU, one line each; the background compiles' processes are not in it
_RUN = ("import atexit, os, resource, runpy\n"
        "def own():\n"
        "    with open(os.environ['BENCH_SELF_CPU'], 'a') as f:\n"
        "        f.write(repr(sum(resource.getrusage(resource.RUSAGE_SELF)[:2])) + '\\n')\n"
        "exit_now = os._exit\n"
        "def leave(code):\n"
        "    own()\n"
        "    exit_now(code)\n"
        "os._exit = leave\n"
        "atexit.register(own)\n"
        "runpy.run_module('tableau_lab', run_name='__main__')\n")


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def timed(cmd: list, env: dict, cwd: Path) -> tuple:
    """(wall seconds, CPU seconds of its process tree, of its own process, load averages before
    and after) of ``cmd`` (its output discarded; exit 4, a degraded run, is the seed's own)."""
    own = Path(env["BENCH_SELF_CPU"])
    own.unlink(missing_ok=True)
    load, cpu, t = os.getloadavg()[0], _children_cpu(), time.perf_counter()
    done = subprocess.run(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode not in (0, 4):
        sys.exit(f"{' '.join(cmd[:4])} …: exit {done.returncode}\n{done.stderr[-2000:]}")
    wall, tree = time.perf_counter() - t, _children_cpu() - cpu
    mine = sum(float(x) for x in own.read_text().split()) if own.exists() else tree
    return wall, tree, mine, (load, os.getloadavg()[0])


def _said(what: str, measured: tuple) -> str:
    wall, cpu, own, (before, after) = measured
    return (f"{what} {wall:.1f} s wall, {cpu:.1f} s CPU ({own:.1f} s the command's own process, "
            f"{cpu - own:.1f} s its children) (load {before:.1f} → {after:.1f})")


def one_round(tree: Path, files: list, args) -> tuple:
    """(cold, warm) :func:`timed` of the scenes on a fresh cache (and shared folder, as asked)."""
    scenes = tree / "reports" / "scenes"
    with tempfile.TemporaryDirectory(prefix="tableau_lab_bench_scenes_") as tmp:
        env = dict(os.environ, PYTHONPATH=str(tree), TABLEAU_LAB_CACHE=str(Path(tmp) / "cache"),
                   BENCH_SELF_CPU=str(Path(tmp) / "self_cpu"))
        cmd = [sys.executable, "-c", _RUN, "run", *files, "--out"]
        if args.shared or args.fresh_shared:
            env["TABLEAU_LAB_SHARED_CACHE"] = args.shared or str(Path(tmp) / "shared")
        if args.shared and not any(Path(args.shared).glob("*.py")):
            built = timed([sys.executable, "-c", _RUN, "warm-up"], env, scenes)
            print(_said("warm-up (the shared loops, once):", built))
        cold = timed(cmd + [str(Path(tmp) / "out1")], env, scenes)
        warm = timed(cmd + [str(Path(tmp) / "out2")], env, scenes)
    return cold, warm


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tree", default=str(ROOT))
    ap.add_argument("--rounds", type=int, default=1, help="cold-then-warm rounds (medians printed)")
    group = ap.add_mutually_exclusive_group()
    group.add_argument("--shared", help="the shared loops' folder (built first if empty)")
    group.add_argument("--fresh-shared", action="store_true", help="an empty shared folder for the cold run")
    args = ap.parse_args(argv)
    from tableau_lab.numeric.kernels import shared_dir
    tree = Path(args.tree).resolve()
    files = sorted(Path(p).name for p in glob.glob(str(tree / "reports" / "scenes" / "*.json")))
    shared = ("built" if args.shared else "empty (a fresh installation)" if args.fresh_shared
              else f"the default ({shared_dir()})")
    print(f"{len(files)} seed scenes, {tree}, shared loops {shared}:", flush=True)
    rounds = []
    for k in range(args.rounds):
        cold, warm = one_round(tree, files, args)
        rounds.append((cold, warm))
        print(f" round {k + 1}:\n  {_said('cold', cold)}\n  {_said('warm', warm)}", flush=True)
        print(f"  cold/warm {cold[0] / warm[0]:.2f} wall, {cold[1] / warm[1]:.2f} CPU, "
              f"{cold[2] / warm[2]:.2f} the command's own CPU (issue 32: ≤ 1.5)", flush=True)
    if args.rounds > 1:
        med = [[statistics.median(r[i][j] for r in rounds) for j in range(3)] for i in range(2)]
        print(f" medians: cold {med[0][0]:.1f} s wall, {med[0][1]:.1f} s CPU ({med[0][2]:.1f} own); warm "
              f"{med[1][0]:.1f} s wall, {med[1][1]:.1f} s CPU ({med[1][2]:.1f} own); cold/warm "
              f"{med[0][0] / med[1][0]:.2f} wall, {med[0][1] / med[1][1]:.2f} CPU")
    return 0


if __name__ == "__main__":
    sys.exit(main())
