r"""Benchmarks (``tableau-lab bench``): speed of the compiled loops beside their references.

Not tests: nothing here asserts a time.  The standard set runs each method × problem for 10⁵
steps (h = 0.01) with the compiled float64 loop (Example 4 on the pendulum only: parasitism
destroys its Kepler run), median of 5 runs side by side in one process, and prints steps/s, f-evaluations and Newton iterations per step, and two ratios
measured in the same process:

* ``numba/C``: against the hand-written C loop of the same algorithm compiled with
  ``gcc -O2`` (the fixture ``benchmarks/c_reference`` of a source checkout; absent from an
  installed package, then reported as unavailable);
* ``scipy/ours``: scipy's DOP853 (rtol 1e-10, f compiled by numba as ours) over the same
  time span, against ours — with both max |H − H₀| beside the ratio, as the two runs do not
  reach the same accuracy.

The 32-digit rows compare the double-double loop with the plain mpmath loop (our pure loop at
``mp:32``) per step, and check they agree.  The memory row runs ``tableau-lab run`` for 10⁷
steps recording 10³ samples and reports the peak resident memory of the command and of its
build child (``experiments/job.py``), and of the two together.  The one-time compile cost
(or disk-cache load) is reported separately, never inside a rate.
"""
from __future__ import annotations

import importlib.util
import json
import statistics
import subprocess
import sys
from pathlib import Path

import sympy as sp

__all__ = ["bench_case", "standard", "memory_probe"]

STANDARD_METHODS = ("implicit_midpoint", "gauss2", "rk4", "example4_glm")
STANDARD_PROBLEMS = ("pendulum", "kepler")
ROOT = Path(__file__).resolve().parents[2]


def _setup(method, problem, precision):
    """(numeric method, compiled problem) at ``precision``."""
    from .runs import _setup as setup
    _, _, cp, nm = setup(method, problem, precision, None)
    return nm, cp


def bench_case(method, problem, steps, h="1/100", precision="float64", reps=5, kernel="auto"):
    """One case: median seconds of ``reps`` runs → steps/s; compile (first call) seconds apart;
    nfev, Newton iterations, max invariant errors of the last run."""
    from ..numeric.integrate import IntegrationError, integrate
    nm, cp = _setup(method, problem, precision)
    h = sp.Rational(h)
    invs = tuple(cp.problem.invariants)
    first = integrate(nm, cp, cp.y0, h, 1, invariants=invs, kernel=kernel)   # compile or load the cache
    times, run, failed = [], None, None
    try:
        for _ in range(reps):                  # timed runs compute only the steps (as the C loop)
            times.append(integrate(nm, cp, cp.y0, h, steps, record_every=steps, kernel=kernel).seconds)
        run = integrate(nm, cp, cp.y0, h, steps, invariants=invs, record_every=steps, kernel=kernel)
    except IntegrationError as exc:
        failed = str(exc)
    out = {"method": Path(str(method)).stem, "problem": problem, "precision": precision, "steps": steps,
           "h": str(h), "compile_seconds": round(first.compile_seconds, 3)}
    if failed:
        return {**out, "failed": failed}
    med = statistics.median(times)
    return {**out, "seconds": med, "steps_per_second": steps / med, "us_per_step": med / steps * 1e6,
            "nfev": run.nfev, "nfev_per_step": run.nfev / steps, "newton_per_step": run.newton_iterations / steps,
            "max_invariant_error": run.max_invariant_error()}


def _c_reference():
    path = ROOT / "benchmarks" / "c_reference" / "c_reference.py"
    if not path.exists():
        return None
    spec = importlib.util.spec_from_file_location("tableau_lab_c_reference", path)
    mod = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(mod)
        mod.build()
    except Exception as exc:            # no gcc, build failure: say so, do not stop the benchmark
        print(f"C reference unavailable: {exc}", file=sys.stderr)
        return None
    return mod


def _scipy_seconds(problem, T, reps=3):
    """Median seconds of DOP853 (rtol 1e-10, atol 1e-10) over [0, T], and its max |H − H₀|."""
    from .workprecision import peer_point
    from ..numeric.problems import get_problem
    pts = [peer_point("DOP853", get_problem(problem), T, 1e-10, 1.0, "H") for _ in range(reps)]
    return statistics.median(p["cpu"] for p in pts), pts[-1]["invariant_error"]


def _status_kb(pid: int) -> dict:
    """VmRSS and VmHWM (kB) of a live process; {} once it is gone."""
    try:
        lines = Path(f"/proc/{pid}/status").read_text().splitlines()
    except OSError:
        return {}
    return {ln.split(":")[0]: int(ln.split()[1]) for ln in lines if ln.startswith(("VmRSS:", "VmHWM:"))}


def _descendants(pid: int) -> list:
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        for task in Path(f"/proc/{p}/task").glob("*/children"):
            try:
                kids = [int(x) for x in task.read_text().split()]
            except OSError:
                continue
            out += kids
            todo += kids
    return out


def memory_probe(method="gauss2", problem="kepler", steps=10 ** 7, precision="float64", interval=0.02) -> dict:
    """Peak resident memory (MB) of ``tableau-lab run --method … --steps 10⁷`` (compiled float64,
    10³ records), as a user starts it: the command's own peak (VmHWM of its process image), the
    peak of its build child (experiments/job.py), and the peak of their sum sampled every
    ``interval`` s — the figure that counts when runs share a machine.  Linux (/proc) only."""
    import os
    import time
    if not Path("/proc/self/status").exists():
        return {"method": method, "problem": problem, "steps": steps, "unavailable": "needs /proc (Linux)"}
    env = {k: v for k, v in os.environ.items() if k != "TABLEAU_LAB_KERNEL"}
    cmd = [sys.executable, "-m", "tableau_lab", "run", "--method", str(ROOT / "methods" / f"{method}.json"),
           "--problem", problem, "--h", "0.01", "--steps", str(steps), "--precision", precision, "--json"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    own, child, total = 0, 0, 0
    while proc.poll() is None:
        kids = _descendants(proc.pid)
        st = [_status_kb(proc.pid)] + [_status_kb(k) for k in kids]
        own = max(own, st[0].get("VmHWM", 0))
        child = max([child] + [x.get("VmHWM", 0) for x in st[1:]])
        total = max(total, sum(x.get("VmRSS", 0) for x in st))
        time.sleep(interval)
    out, err = proc.communicate()
    if proc.returncode:
        raise RuntimeError(f"memory probe: {' '.join(cmd)} failed: {err.strip()}")
    res = json.loads(out)
    return {"method": method, "problem": problem, "steps": steps, "precision": precision, "records": res["records"],
            "peak_rss_mb": round(own / 1024, 1), "build_child_peak_rss_mb": round(child / 1024, 1),
            "peak_tree_rss_mb": round(total / 1024, 1), "seconds": res["seconds"]}


def standard(steps=10 ** 5, reps=5, mp_steps=100, dd_steps=20000, memory=True) -> dict:
    """The standard set (see the module docstring) as a JSON-ready dict."""
    methods = {m: ROOT / "methods" / f"{m}.json" for m in STANDARD_METHODS}
    cref = _c_reference()
    rows = []
    for problem in STANDARD_PROBLEMS:
        for m, path in methods.items():
            if m == "example4_glm" and problem == "kepler":
                continue          # destroyed by parasitism within 600 steps (docs/seed_figures.md)
            row = bench_case(path, problem, steps, reps=reps)
            if "failed" not in row:
                if cref is not None:
                    c = cref.run_c(path, problem, 0.01, steps, reps=reps)
                    row["c_us_per_step"] = c["us_per_step"]
                    row["numba_over_c"] = row["us_per_step"] / c["us_per_step"]
                sec, err = _scipy_seconds(problem, steps / 100)
                row["scipy_dop853_seconds"] = sec
                row["scipy_over_ours"] = sec / row["seconds"]
                row["scipy_max_H_error"] = err
            rows.append(row)
    high = []
    for problem in STANDARD_PROBLEMS:
        dd = bench_case(methods["gauss2"], problem, dd_steps, precision="dd", reps=reps)
        mp = bench_case(methods["gauss2"], problem, mp_steps, precision="mp:32", reps=3, kernel="python")
        agree = _agreement(methods["gauss2"], problem, mp_steps)
        high.append({"method": "gauss2", "problem": problem, "dd_us_per_step": dd["us_per_step"],
                     "mp32_us_per_step": mp["us_per_step"], "mp_over_dd": mp["us_per_step"] / dd["us_per_step"],
                     "dd_vs_mp32_difference": agree, "dd_compile_seconds": dd["compile_seconds"]})
    out = {"float64": rows, "high_precision": high, "c_reference": cref is not None}
    if memory:
        out["memory"] = memory_probe()
    return out


def _agreement(method, problem, steps) -> float:
    import mpmath
    from ..numeric.integrate import integrate
    finals = []
    for prec in ("dd", "mp:32"):
        nm, cp = _setup(method, problem, prec)
        finals.append(integrate(nm, cp, cp.y0, sp.Rational(1, 100), steps, record_every=steps).final)
    with mpmath.workdps(40):
        return float(max(abs(a - b) for a, b in zip(*finals)))


def table(res: dict) -> str:
    """The standard set as a Markdown table."""
    lines = ["| method | problem | steps | µs/step | steps/s | nfev/step | Newton/step | numba/C | scipy DOP853/ours "
             "| max abs(H−H₀) ours / DOP853 |", "|" + "---|" * 10]
    for r in res["float64"]:
        if "failed" in r:
            lines.append(f"| {r['method']} | {r['problem']} | {r['steps']} | failed: {r['failed'][:60]} |||||||")
            continue
        c = f"{r['numba_over_c']:.2f}" if "numba_over_c" in r else "n/a"
        lines.append(f"| {r['method']} | {r['problem']} | {r['steps']} | {r['us_per_step']:.3f} | "
                     f"{r['steps_per_second']:.3g} | {r['nfev_per_step']:.2f} | {r['newton_per_step']:.2f} | {c} | "
                     f"{r['scipy_over_ours']:.1f} | {r['max_invariant_error']['H']:.1e} / {r['scipy_max_H_error']:.1e} |")
    lines += ["", "| 32 digits | problem | dd µs/step | mp:32 µs/step | mpmath/dd | dd − mp:32 after 100 steps |",
              "|---|---|---|---|---|---|"]
    for r in res["high_precision"]:
        lines.append(f"| {r['method']} | {r['problem']} | {r['dd_us_per_step']:.2f} | {r['mp32_us_per_step']:.0f} | "
                     f"{r['mp_over_dd']:.0f} | {r['dd_vs_mp32_difference']:.1e} |")
    if "memory" in res:
        m = res["memory"]
        lines += ["", f"Memory: `tableau-lab run`, {m['steps']:.0e} steps of {m['method']} on {m['problem']} with "
                      f"{m['records']} records: peak resident {m['peak_rss_mb']} MB (its build child "
                      f"{m['build_child_peak_rss_mb']} MB, before the run; the two together at most "
                      f"{m['peak_tree_rss_mb']} MB) in {m['seconds']} s."]
    return "\n".join(lines)


def save(res: dict, out="reports/bench") -> Path:
    from ..files import atomic_write_text
    out = Path(out)
    atomic_write_text(out / "bench.json", json.dumps(res, indent=1, default=float))
    atomic_write_text(out / "bench.md", "# tableau-lab bench\n\n" + table(res) + "\n")
    return out
