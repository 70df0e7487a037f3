r"""Benchmarks (``tableau-lab bench``): speed of the compiled loop against the fastest known way
to do the same job, a C loop of the same algorithm.

Not tests: nothing here asserts a time.  The standard set runs each case for 10⁵ steps with the
compiled float64 loop and with ``benchmarks/c_reference`` — the same algorithm (the stage
iteration on the q stages of a separable problem with the predicted start, or simplified
Newton; Kahan summation of the principal value) written in C99, the problem's functions printed
as C from its symbols, the method's shape as compile-time constants, ``gcc -O3 -march=native``,
called in this process through ctypes — timing the step loop alone in both, ``reps`` times
each, interleaved (ours, C, ours, C, …) so that the drift of a shared machine hits both alike.
It prints the median µs/step of each, their ratio
(ours/C: the figure to watch, as absolute times drift), the f-evaluations per step of each (for
separable problems: force evaluations, as Hairer's GNI codes count them), the goal of each row,
and Hairer's GNI_IRK2 (gfortran -O2) as measured for issue 14 on this machine class, for
orientation.  The C reference is a fixture of a source checkout; without it (or gcc) the ratios
are reported as unavailable.

The 32-digit rows compare the double-double loop with the plain mpmath loop (the same core run
in Python at ``mp:32``) per step, and check they agree.  The memory row runs ``tableau-lab run``
for 10⁷ steps recording 10³ samples and reports the peak resident memory of the command and of
its build child (``experiments/job.py``), and of the two together.  The one-time compile cost
(or disk-cache load) is reported separately, never inside a rate.
"""
from __future__ import annotations

import importlib.util
import json
import shutil
import statistics
import subprocess
import sys
from pathlib import Path

import sympy as sp

__all__ = ["bench_case", "step_sizes", "compare_case", "standard", "memory_probe"]

# (method, problem, h, goal: our µs/step over the C loop's); GNI_IRK2 for orientation: µs/step, f-evals/step
STANDARD = [("gauss2", "pendulum", "1/100", 1.0), ("gauss2", "kepler", "1/100", 1.0),
            ("gauss3", "pendulum", "1/100", 1.2), ("gauss3", "kepler", "1/100", 1.2),
            ("implicit_midpoint", "pendulum", "1/100", 1.2), ("implicit_midpoint", "kepler", "1/100", 1.2),
            ("rk4", "pendulum", "1/100", 1.2), ("rk4", "kepler", "1/100", 1.2),
            ("glm43", "pendulum", "1/100", 1.2), ("glm43", "kepler", "1/100", 1.2),
            ("example4_glm", "pendulum", "1/100", 1.2),       # on Kepler parasitism destroys it (step 577)
            ("gauss2", "fpu", "1/1000", 1.5), ("gauss2", "outer_solar_system", "10", 1.5)]
GNI = {("gauss2", "pendulum"): ("0.10–0.13", 4.73), ("gauss2", "kepler"): ("0.17–0.19", 5.44),
       ("gauss2", "fpu"): ("0.37", None), ("gauss2", "outer_solar_system"): ("1.35", None)}
ROOT = Path(__file__).resolve().parents[2]


def _setup(method, problem, precision):
    """(numeric method, compiled problem) at ``precision``."""
    from .runs import prepare_run
    prep = prepare_run(method, problem, precision)
    return prep.numeric, prep.compiled


def bench_case(method, problem, steps, h="1/100", precision="float64", reps=5, kernel="auto"):
    """One case: median seconds of ``reps`` runs → steps/s; compile (first call) seconds apart;
    nfev, stage-iteration sweeps, max invariant errors of the last run."""
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


def step_sizes(method, problem, steps, hs, precision="float64", reps=5, kernel="auto") -> dict:
    """The same case at several step sizes, timed interleaved (h₁, h₂, …, h₁, h₂, …, ``reps``
    rounds) in one process, so that the drift of a shared machine and the process's own layout
    hit every h alike: one :func:`bench_case`-style row per h and ``cost_ratios``, each h's
    median µs/step over the first h's, beside the ratio of their f-evaluations per step — the
    stage iteration's cost is judged by how closely the first follows the second."""
    from ..numeric.integrate import IntegrationError, integrate
    nm, cp = _setup(method, problem, precision)
    hs = [sp.Rational(h) for h in hs]
    rows = [bench_case(method, problem, steps, h=h, precision=precision, reps=1, kernel=kernel) for h in hs]
    failed = [r for r in rows if "failed" in r]
    if failed:
        return {"cases": rows, "failed": failed[0]["failed"]}
    times = [[] for _ in hs]
    try:
        for _ in range(reps):
            for k, h in enumerate(hs):
                times[k].append(integrate(nm, cp, cp.y0, h, steps, record_every=steps, kernel=kernel).seconds)
    except IntegrationError as exc:
        return {"cases": rows, "failed": str(exc)}
    for row, t in zip(rows, times, strict=False):
        med = statistics.median(t)
        row.update(seconds=med, steps_per_second=steps / med, us_per_step=med / steps * 1e6, reps=reps)
    first = rows[0]
    ratios = [{"h": r["h"], "us_per_step_over_first": r["us_per_step"] / first["us_per_step"],
               "nfev_per_step_over_first": r["nfev_per_step"] / first["nfev_per_step"]} for r in rows[1:]]
    return {"cases": rows, "cost_ratios": ratios}


def step_size_table(res: dict) -> str:
    """:func:`step_sizes` as text: one line per h, then each cost ratio beside its f-evaluation ratio."""
    if "failed" in res:
        return f"failed: {res['failed']}"
    rows = res["cases"]
    lines = [f"{rows[0]['method']} on {rows[0]['problem']}, {rows[0]['steps']} steps, {rows[0]['reps']} interleaved "
             f"rounds (median):"]
    lines += [f"  h = {r['h']}: {r['us_per_step']:.3f} µs/step, {r['nfev_per_step']:.2f} f-evals/step, "
              f"{r['newton_per_step']:.2f} sweeps/step, "
              f"max abs(ΔH) {r['max_invariant_error'].get('H', float('nan')):.1e}"
              for r in rows]
    lines += [f"  cost at h = {q['h']} over h = {rows[0]['h']}: {q['us_per_step_over_first']:.2f} "
              f"(f-evals {q['nfev_per_step_over_first']:.2f})" for q in res["cost_ratios"]]
    return "\n".join(lines)


def _c_reference():
    path = ROOT / "benchmarks" / "c_reference" / "c_reference.py"
    if not path.exists():
        return None
    spec = importlib.util.spec_from_file_location("tableau_lab_c_reference", path)
    mod = importlib.util.module_from_spec(spec)
    try:
        spec.loader.exec_module(mod)
        if shutil.which("gcc") is None:
            raise RuntimeError("gcc not found")
    except Exception as exc:            # no gcc, build failure: say so, do not stop the benchmark
        print(f"C reference unavailable: {exc}", file=sys.stderr)
        return None
    return mod


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


def compare_case(cref, method, problem, h, steps, reps) -> dict:
    """Ours against the C loop on one case, interleaved: median µs/step of each, the ratio,
    f-evaluations per step of each, max |H − H₀| of a run through ``integrate``."""
    path = ROOT / "methods" / f"{method}.json"
    user = bench_case(path, problem, steps, h=h, reps=1)
    if "failed" in user:
        return user
    ours, c = [], []
    for _ in range(reps):
        nb = cref.run_numba(path, problem, sp.Rational(h), steps, reps=1)
        cc = cref.run_c(path, problem, sp.Rational(h), steps, reps=1)
        ours.append(nb["us_per_step"])
        c.append(cc["us_per_step"])
    row = {k: user[k] for k in ("method", "problem", "steps", "h", "compile_seconds", "max_invariant_error")}
    mo, mc = statistics.median(ours), statistics.median(c)
    return {**row, "us_per_step": mo, "c_us_per_step": mc, "over_c": mo / mc, "nfev_per_step": nb["nfev"] / steps,
            "c_nfev_per_step": cc["nfev"] / steps, "sweeps_per_step": nb["sweeps"] / steps,
            "final_difference": float(abs(nb["final"] - cc["final"]).max())}


def llvm_case(cref, method, problem, h, steps, reps) -> dict | None:
    """The C loop compiled by gcc (the reference) and by clang (LLVM, the backend numba compiles
    our loop with), interleaved with ours: median µs/step of each.  None without clang (the
    ``ziglang`` wheel brings one: ``pip install ziglang``)."""
    path = ROOT / "methods" / f"{method}.json"
    try:
        cref.run_c(path, problem, sp.Rational(h), 10, reps=1, cc="clang")    # build, or fail here
    except RuntimeError as exc:
        print(f"clang build of the C loop unavailable: {str(exc).splitlines()[0]}", file=sys.stderr)
        return None
    times = {"ours": [], "gcc": [], "clang": []}
    for _ in range(reps):
        times["ours"].append(cref.run_numba(path, problem, sp.Rational(h), steps, reps=1)["us_per_step"])
        for cc in ("gcc", "clang"):
            times[cc].append(cref.run_c(path, problem, sp.Rational(h), steps, reps=1, cc=cc)["us_per_step"])
    med = {k: statistics.median(v) for k, v in times.items()}
    return {"method": method, "problem": problem, "h": h, "clang": cref._compiler("clang")[1],
            **{f"{k}_us_per_step": v for k, v in med.items()}}


def standard(steps=10 ** 5, reps=5, mp_steps=100, dd_steps=20000, memory=True, log=None) -> dict:
    """The standard set (see the module docstring) as a JSON-ready dict; ``log(line)`` after
    each row."""
    log = log or (lambda line: print(line, file=sys.stderr, flush=True))
    cref = _c_reference()
    rows = []
    for method, problem, h, goal in STANDARD:
        if cref is None:
            row = bench_case(ROOT / "methods" / f"{method}.json", problem, steps, h=h, reps=reps)
        else:
            row = compare_case(cref, method, problem, h, steps, reps)
        row["goal"] = goal
        if (method, problem) in GNI:
            row["gni_us_per_step"], row["gni_nfev_per_step"] = GNI[method, problem]
        rows.append(row)
        log(_row(row))
    llvm = []
    for method, problem, h, _ in STANDARD[:2] if cref is not None else ():
        row = llvm_case(cref, method, problem, h, steps, reps)
        if row is None:
            break
        llvm.append(row)
        log(f"LLVM, {method} {problem}: clang/gcc {row['clang_us_per_step'] / row['gcc_us_per_step']:.2f}, "
            f"ours/clang {row['ours_us_per_step'] / row['clang_us_per_step']:.2f}")
    high = []
    for problem in ("pendulum", "kepler"):
        path = ROOT / "methods" / "gauss2.json"
        dd = bench_case(path, problem, dd_steps, precision="dd", reps=reps)
        mp = bench_case(path, problem, mp_steps, precision="mp:32", reps=3, kernel="python")
        agree = _agreement(path, problem, mp_steps)
        high.append({"method": "gauss2", "problem": problem, "dd_us_per_step": dd["us_per_step"],
                     "mp32_us_per_step": mp["us_per_step"], "mp_over_dd": mp["us_per_step"] / dd["us_per_step"],
                     "dd_vs_mp32_difference": agree, "dd_compile_seconds": dd["compile_seconds"]})
        log(f"32 digits, {problem}: dd {dd['us_per_step']:.2f} µs/step, mp:32 {mp['us_per_step']:.0f} µs/step")
    out = {"float64": rows, "high_precision": high, "c_reference": cref is not None, "llvm_c": llvm}
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
        return float(max(abs(a - b) for a, b in zip(*finals, strict=False)))


_HEAD = ("| method | problem | h | µs/step | C µs/step | ours/C | goal | f-evals/step ours / C | GNI_IRK2 µs/step · "
         "f-evals | max abs(H−H₀) |")


def _row(r) -> str:
    if "failed" in r:
        return f"| {r['method']} | {r['problem']} | {r['h']} | failed: {r['failed'][:60]} |||||||"
    gni = f"{r['gni_us_per_step']} · {r['gni_nfev_per_step'] or '–'}" if "gni_us_per_step" in r else ""
    if "c_us_per_step" in r:
        c, ratio = f"{r['c_us_per_step']:.3f}", f"**{r['over_c']:.2f}**"
        nf = f"{r['nfev_per_step']:.2f} / {r['c_nfev_per_step']:.2f}"
    else:
        c, ratio, nf = "n/a", "n/a", f"{r['nfev_per_step']:.2f}"
    return (f"| {r['method']} | {r['problem']} | {r['h']} | {r['us_per_step']:.3f} | {c} | {ratio} | "
            f"≤ {r['goal']} | {nf} | {gni} | {r['max_invariant_error']['H']:.1e} |")


def table(res: dict) -> str:
    """The standard set as a Markdown table."""
    lines = [_HEAD, "|" + "---|" * 10] + [_row(r) for r in res["float64"]]
    cold = [r["compile_seconds"] for r in res["float64"] if r.get("compile_seconds") is not None]
    dd = [r["dd_compile_seconds"] for r in res["high_precision"] if r.get("dd_compile_seconds") is not None]
    if cold:
        lines += ["", f"Compile (first call; cold when the cache was empty): float64 {min(cold):.1f}–{max(cold):.1f} s "
                      f"per problem and run shape" + (f", double-double {min(dd):.1f}–{max(dd):.1f} s" if dd else "")
                  + "."]
    if res.get("llvm_c"):
        lines += ["", f"The same C loop compiled by LLVM ({res['llvm_c'][0]['clang']}; numba's backend), same flags, "
                      "interleaved:", "",
                  "| method | problem | ours µs/step | C (gcc) | C (clang) | clang/gcc | ours/clang |",
                  "|---|---|---|---|---|---|---|"]
        for r in res["llvm_c"]:
            lines.append(f"| {r['method']} | {r['problem']} | {r['ours_us_per_step']:.3f} | "
                         f"{r['gcc_us_per_step']:.3f} | "
                         f"{r['clang_us_per_step']:.3f} | {r['clang_us_per_step'] / r['gcc_us_per_step']:.2f} | "
                         f"{r['ours_us_per_step'] / r['clang_us_per_step']:.2f} |")
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
    from ..files import atomic_write_text, output_phase
    out = Path(out)
    with output_phase(out):                   # both or neither, under the folder's lock
        atomic_write_text(out / "bench.json", json.dumps(res, indent=1, default=float))
        atomic_write_text(out / "bench.md", "# tableau-lab bench\n\n" + table(res) + "\n")
    return out
