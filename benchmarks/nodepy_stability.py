"""``tableau-lab stability`` over NodePy's exact methods and LMMs (docs/nodepy.md's set,
``nodepy_set.stability_methods``): each method written as a tableau file and analysed by the
command as a user runs it, one process per method; its exit status, CPU time (user + system of the
child, from ``os.wait4``: the machine is shared, so wall time says little) and wall time.

    python benchmarks/nodepy_stability.py --run [--only NAME ...]   # measure, save reports/nodepy/stability.json
    python benchmarks/nodepy_stability.py --write docs/nodepy.md    # the block, from the saved file
    python benchmarks/nodepy_stability.py                            # print the block

The issue-29 criterion: no exit 3 (an internal error), no method over ``LIMIT`` seconds.
"""
from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path[:0] = [str(ROOT), str(HERE)]
from doc_blocks import write_block  # noqa: E402

SAVED = ROOT / "reports" / "nodepy" / "stability.json"
LIMIT = 120.0           # seconds of CPU per method (issue 29)
CPU_CAP = 2 * LIMIT     # RLIMIT_CPU of each run: a method past it is stopped (SIGXCPU) and recorded
KILL = 900.0            # wall seconds after which a run is stopped (recorded as a hang)
# --timeout 0: the command's own budget is wall time, which a shared machine inflates (CPU_CAP bounds
# the run instead); --entry-limit: RK59[2R]S has a 102-digit abscissa (the default limit is 100
# digits, and the command says how to raise it)
OPTIONS = ["--timeout", "0", "--entry-limit", "integer_digits=400"]
BLOCK = "nodepy-stability"


def run_one(path: Path) -> dict:
    """Exit status, CPU and wall seconds of ``tableau-lab stability PATH`` in a child process."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    t0 = time.perf_counter()
    import resource

    def cap():
        resource.setrlimit(resource.RLIMIT_CPU, (int(CPU_CAP), int(CPU_CAP) + 5))
    proc = subprocess.Popen([sys.executable, "-m", "tableau_lab", "stability", *OPTIONS, str(path)], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True,
                            preexec_fn=cap)
    hung = False
    while True:
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            break
        if time.perf_counter() - t0 > KILL:
            os.killpg(proc.pid, signal.SIGKILL)
            hung = True
        time.sleep(0.05)
    wall = time.perf_counter() - t0
    err = proc.stderr.read().decode(errors="replace").strip().splitlines()
    proc.stderr.close()
    return {"exit": None if hung else os.waitstatus_to_exitcode(status), "cpu": usage.ru_utime + usage.ru_stime,
            "wall": wall, "stderr": err[-1][:300] if err else ""}


def measure(only=()) -> dict:
    from nodepy_set import stability_methods

    from tableau_lab.exact.interop import from_nodepy
    from tableau_lab.exact.methods import MethodError
    from tableau_lab.exact.tableau_json import save
    from tableau_lab.files import atomic_write_text
    methods, skipped = stability_methods()
    old = json.loads(SAVED.read_text()) if only and SAVED.exists() else {"rows": []}
    rows = {r["name"]: r for r in old["rows"]}
    with tempfile.TemporaryDirectory() as tmp:
        for k, (name, obj) in enumerate(methods):
            if only and name not in only:
                continue
            try:
                m = from_nodepy(obj)
            except MethodError as exc:                 # floating-point coefficients, an empty tableau
                skipped.append((name, str(exc)[:160]))
                continue
            path = Path(tmp) / f"m{k}.json"
            save(m, path)
            lmm = hasattr(obj, "alpha") and not hasattr(obj, "A")
            r = {"name": name, "kind": "lmm" if lmm else m.kind, "stages": m.s,
                 "steps": len(obj.alpha) - 1 if lmm else None, **run_one(path)}
            rows[name] = r
            print(f"{name}: exit {r['exit']}, {r['cpu']:.1f} s CPU, {r['wall']:.1f} s wall",
                  file=sys.stderr, flush=True)
    from importlib.metadata import version
    order = [n for n, _ in methods]
    data = {"nodepy": version("nodepy"), "limit": LIMIT, "cpus": os.cpu_count(),
            "rows": sorted(rows.values(), key=lambda r: order.index(r["name"]) if r["name"] in order else 1e9),
            "skipped": sorted(set(n for n, _ in skipped))}
    SAVED.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(SAVED, json.dumps(data, indent=1) + "\n")
    return data


def make(data=None) -> str:
    """The docs block from the saved run."""
    data = data or json.loads(SAVED.read_text())
    rows = data["rows"]
    rk = [r for r in rows if r["kind"] == "rk"]
    lmm = [r for r in rows if r["kind"] == "lmm"]
    codes = {}
    for r in rows:
        codes[r["exit"]] = codes.get(r["exit"], 0) + 1
    over = [r for r in rows if r["cpu"] > data["limit"] or r["exit"] is None]

    def size(r):
        return f"{r['steps']} steps" if r.get("steps") else f"{r['stages']} stages"
    slow = sorted(rows, key=lambda r: -r["cpu"])[:8]
    lines = [f"NodePy {data['nodepy']}: `tableau-lab stability` on {len(rows)} exact methods "
             f"({len(rk)} Runge–Kutta, {len(lmm)} linear multistep), one process each:",
             "",
             "* exit status: " + ", ".join(f"{'killed' if c is None else c}: {n}" for c, n in
                                           sorted(codes.items(), key=lambda kv: (kv[0] is None, kv[0] or 0))),
             f"* over {data['limit']:.0f} s of CPU: {len(over)}" + (" (" + ", ".join(r["name"] for r in over) + ")"
                                                                      if over else ""),
             f"* total {sum(r['cpu'] for r in rows):.0f} s of CPU; the slowest (CPU seconds, user + system of "
             "the child; wall time on the shared machine is not a measure):",
             "",
             "| method | size | exit | CPU s |", "|---|---|---|---|"]
    lines += [f"| {r['name']} | {size(r)} | {r['exit']} | {r['cpu']:.1f} |" for r in slow]
    lines += ["", f"Skipped (floating-point coefficients, an empty tableau, or a size NodePy does not build): "
              f"{', '.join(data['skipped'])}."]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--run", action="store_true", help="measure and save reports/nodepy/stability.json")
    ap.add_argument("--only", nargs="*", default=(), metavar="NAME", help="with --run: these methods only")
    ap.add_argument("--write", metavar="MD", help="rewrite the block in MD from the saved run")
    args = ap.parse_args(argv)
    data = measure(set(args.only)) if args.run else None
    text = make(data)
    print(text)
    if args.write:
        write_block(args.write, BLOCK, text)
    bad = [r for r in (data or json.loads(SAVED.read_text()))["rows"] if r["exit"] in (3, None)]
    return 1 if args.run and bad else 0


if __name__ == "__main__":
    sys.exit(main())
