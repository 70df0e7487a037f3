r"""Work–precision diagrams: error against cost for our methods and for scipy's adaptive peers.

A work–precision scene (JSON) names a problem, a time span [0, T], the methods with the step
counts to sweep, and the peers (``scipy.integrate.solve_ivp`` with DOP853 / RK45 over a range
of tolerances)::

    {"format": "tableau_lab/workprecision/1", "name": "wp_kepler",
     "problem": {"name": "kepler", "set": {"e": "0.6"}}, "T": 1000,
     "methods": [{"method": "../../methods/gauss2.json", "steps": [20000, 40000, 80000]}],
     "peers": [{"method": "DOP853", "rtol": ["1e-6", "1e-8", "1e-10"]}]}

Every point is one independent run (through :mod:`executor`: a process pool, or a Dask
cluster): CPU time of the run (``time.process_time``, compile excluded: each worker compiles
or loads the kernel before timing), f-evaluations, the error at T against a reference
(max-norm of the state difference) and max |H − H₀| over the run (our runs: at 1000 records
and the end; peers: at every accepted step).  The reference at T is computed once, by our
double-double kernel (about 32 digits) with 3-stage Gauss at two step sizes whose
difference bounds its error (reported).  ``tableau-lab workprecision SCENE`` writes
``data.json``, ``summary.md`` and ``<name>.png`` under ``reports/workprecision/<name>/``.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..budget import DEFAULT_SECONDS
from ..files import atomic_write_text, output_phase
from .compiled_peer import PEER as COMPILED_PEER, dop853_point, max_invariant_error
from .scene_keys import PEERS, WP_FORMAT, WP_SCHEMA

__all__ = ["load_wp_scene", "run_wp", "WPScene", "peer_point", "method_point", "speedup", "summary_table", "versus",
           "cheapest", "FORMAT", "PEERS"]

FORMAT = WP_FORMAT
LEVELS = (1e-6, 1e-8, 1e-10, 1e-12)   # energy-error thresholds of the summary: the cheapest run reaching each


@dataclass(frozen=True)
class WPScene:
    path: Path
    name: str
    title: str
    problem: object
    T: object
    methods: tuple       # (path, [steps...], label)
    peers: tuple         # (name, [rtol...], atol_factor)
    invariant: str


def load_wp_scene(path, timeout: float | None = DEFAULT_SECONDS) -> WPScene:
    """Read and validate a work–precision scene: every key read by its entry of
    :data:`~tableau_lab.experiments.scene_keys.WP_SCHEMA` (the methods' and peers' by
    ``WP_METHOD_SCHEMA``, ``WP_PEER_SCHEMA``): the problem built within the time budget
    ``timeout`` (as the exact commands'), every sweep within the step budget of a run scene
    (``inputs.MAX_STEPS`` per run, the reference's runs included), peers among :data:`PEERS`.
    Messages name the file and the entry (one-based: ``methods[1].steps[2]``)."""
    from ..inputs import MAX_STEPS, printable
    from .scene_keys import Field, SceneError, read_object, read_scene, shown
    path = Path(path)
    data = read_scene(path)
    got = read_object(WP_SCHEMA, data, Field(path, timeout=timeout))
    longest = max(reference_steps(got["T"]))
    if longest > MAX_STEPS:
        raise SceneError(f"{printable(path)}: T = {shown(data['T'])}: the reference solution would take {longest:.3g} "
                         f"steps, more than the limit of {MAX_STEPS} steps of a run (MAX_STEPS); T ≤ "
                         f"{MAX_STEPS // (2 * REFERENCE_STEPS_PER_UNIT)} is within it")
    if not got["methods"] and not got["peers"]:
        raise SceneError(f"{printable(path)}: nothing to run (no methods, no peers)")
    return WPScene(path, got["name"], got["title"], got["problem"], got["T"],
                   tuple((m["method"], m["steps"], m["label"]) for m in got["methods"]),
                   tuple((p["method"], p["rtol"], p["atol_factor"]) for p in got["peers"]), got["invariant"])


REFERENCE_STEPS_PER_UNIT = 500       # steps of the reference run per unit of T (at least REFERENCE_MIN_STEPS)
REFERENCE_MIN_STEPS = 2000


def reference_steps(T, steps=None) -> tuple:
    """The step counts (n, 2n) of the two reference runs over [0, T] (:func:`reference_state`)."""
    n = steps or max(REFERENCE_MIN_STEPS, int(float(T) * REFERENCE_STEPS_PER_UNIT))
    return n, 2 * n


# -- one point each (module-level: they run in worker processes) ---------------------------------

def method_point(method_path, problem, T, steps, invariant):
    """One run of our method, compiled float64: CPU seconds, nfev, final state, max |I − I₀|."""
    import sympy as sp

    from ..numeric.integrate import IntegrationError, integrate
    from .runs import prepare_run
    _, _, cp, nm = prepare_run(method_path, problem, "float64", None)
    h = sp.Rational(T) / steps
    integrate(nm, cp, cp.y0, h, 1)                       # compile / load the kernel, not timed
    t0 = time.process_time()
    try:
        run = integrate(nm, cp, cp.y0, h, steps, invariants=(invariant,), record_every=steps)
    except IntegrationError as exc:
        return {"steps": steps, "failed": str(exc)}
    cpu = time.process_time() - t0
    return {"steps": steps, "cpu": cpu, "nfev": run.nfev, "final": [float(x) for x in run.final],
            "invariant_error": run.max_invariant_error()[invariant]}


def cheapest(points, key: str, level: float):
    """The smallest ``key`` (cpu, nfev) among the points whose max |I − I₀| is ≤ level; None if none."""
    ok = [p[key] for p in points if key in p and p.get("invariant_error") is not None and p["invariant_error"] <= level]
    return min(ok) if ok else None


def peer_point(peer, problem, T, rtol, atol_factor, invariant):
    """One scipy solve_ivp run (f compiled by numba as for our runs, called through a thin
    Python wrapper as scipy requires): CPU seconds, nfev, final state, max |I − I₀| over the
    accepted steps."""
    from scipy.integrate import solve_ivp

    from ..numeric.codegen import compile_problem
    from ..numeric.kernels import compiled_loop
    cp = compile_problem(problem)
    mod = compiled_loop(cp.problem)           # its f_ and inv_ (numba compiles only what is called)
    c = np.array([float(v) for v in cp.constants])
    y0 = np.array(cp.y0, dtype=float)
    d = len(y0)

    def fun(t, y):
        out = np.empty((1, d))
        mod.f_(y, c, out, 0)
        return out[0]
    fun(0.0, y0)                                           # compile / load, not timed
    t0 = time.process_time()
    sol = solve_ivp(fun, (0.0, float(T)), y0, method=peer, rtol=rtol, atol=rtol * atol_factor)
    cpu = time.process_time() - t0
    if not sol.success:
        return {"rtol": rtol, "failed": sol.message}
    err = max_invariant_error(mod, invariant, c, y0, sol.y.T)
    return {"rtol": rtol, "cpu": cpu, "nfev": int(sol.nfev), "final": sol.y[:, -1].tolist(),
            "invariant_error": float(err), "steps": int(sol.t.size - 1)}


def reference_state(problem, T, steps=None):
    """The state at T to about 30 digits: 3-stage Gauss (order 6) in double-double at n and 2n
    steps; returns (state as floats, the difference of the two runs: a bound on its error)."""
    import sympy as sp

    from ..exact.families import gauss
    from ..numeric.integrate import integrate
    from .runs import prepare_run
    _, _, cp, nm = prepare_run(gauss(3), problem, "dd", None)
    runs = [integrate(nm, cp, cp.y0, sp.Rational(T) / k, k).final for k in reference_steps(T, steps)]
    gap = max(abs(float(a - b)) for a, b in zip(*runs, strict=False))
    return np.array([float(x) for x in runs[1]]), gap


def output_paths(out: Path, name: str) -> dict:
    """What :func:`run_wp` writes into ``out`` for a scene named ``name``: ``data`` (data.json),
    ``figure`` (the PNG; its other formats are siblings), ``summary`` (summary.md)."""
    return {"data": out / "data.json", "figure": out / f"{name}.png", "summary": out / "summary.md"}


def run_wp(scene: WPScene, out_root="reports/workprecision", scheduler=None, workers=None):
    """All points of a work–precision scene (independent runs through the executor), the
    reference, then ``data.json`` and the PNG.  Returns the data dict."""
    from ..files import refuse_outputs
    from .executor import executor
    from .figure_style import siblings
    paths = output_paths(Path(out_root) / scene.name, scene.name)     # before any run: no output over an input
    refuse_outputs([paths["data"], paths["summary"], *siblings(paths["figure"])],
                   [scene.path] + [p for p, _, _ in scene.methods if isinstance(p, Path)])
    ref, gap = reference_state(scene.problem, scene.T)
    tasks = [(method_point, (str(p), scene.problem, scene.T, n, scene.invariant), label)
             for p, steps, label in scene.methods for n in steps]
    tasks += [(dop853_point, (scene.problem, scene.T, rtol, af, scene.invariant), peer) if peer == COMPILED_PEER
              else (peer_point, (peer, scene.problem, scene.T, rtol, af, scene.invariant), peer)
              for peer, rtols, af in scene.peers for rtol in rtols]
    with executor(scheduler=scheduler, workers=workers) as ex:
        results = ex.map(_call, [(fn, args) for fn, args, _ in tasks])
    series: dict = {}
    for (_, _, label), res in zip(tasks, results, strict=False):
        if "final" in res:
            res["error"] = float(np.max(np.abs(np.array(res.pop("final")) - ref)))
        series.setdefault(label, []).append(res)
    data = {"name": scene.name, "title": scene.title, "problem": scene.problem.name, "T": float(scene.T),
            "invariant": scene.invariant, "reference_error_bound": gap, "series": series}
    data["speedup"] = speedup(data)
    from .plots import draw_workprecision
    with output_phase(Path(out_root) / scene.name):     # the three together, under the folder's lock
        atomic_write_text(paths["data"], json.dumps(data, indent=1))
        draw_workprecision(data, paths["figure"])
        atomic_write_text(paths["summary"], f"# {data['title']}\n\n{summary_table(data)}\n")
    return data


def _call(task):
    fn, args = task
    return fn(*args)


def speedup(data, levels=LEVELS):
    """For each invariant-error level: the cheapest CPU time of each series reaching it, our best
    series, and each peer's time over our best's (``peer_over_best``; None where one of the two
    never reaches the level; ``DOP853_over_best`` is scipy's DOP853's)."""
    out = {}
    for lv in levels:
        best = {label: cheapest(pts, "cpu", lv) for label, pts in data["series"].items()}
        ours = {k: v for k, v in best.items() if k not in PEERS and v is not None}
        top = min(ours, key=ours.get) if ours else None
        ratios = {k: (v / ours[top] if top and v else None) for k, v in best.items() if k in PEERS}
        out[f"{lv:g}"] = {"cpu": best, "best": top, "peer_over_best": ratios,
                          "DOP853_over_best": ratios.get("DOP853")}
    return out


def summary_table(data, levels=LEVELS) -> str:
    """Markdown: per series, its sweep and the cheapest CPU time reaching each invariant-error
    level, then DOP853's time over our best's."""
    inv = data["invariant"]
    head = " / ".join(f"{lv:g}" for lv in levels)
    rows = [f"| method | sweep | cheapest CPU s with max abs({inv} − {inv}₀) ≤ {head} |", "|---|---|---|"]
    cheapest = speedup(data, levels)
    for label, pts in data["series"].items():
        key = "rtol" if label in PEERS else "steps"
        best = [cheapest[f"{lv:g}"]["cpu"][label] for lv in levels]
        best = " / ".join("—" if b is None else f"{b:.3f}" for b in best)
        rows.append(f"| {label} | {key} {pts[0][key]:g} … {pts[-1][key]:g} | {best} |")
    sp_ = data.get("speedup") or cheapest
    rows.append("")
    rows += [f"- max abs({inv} − {inv}₀) ≤ {lv}: " + versus(v) for lv, v in sp_.items()]
    return "\n".join(rows)


def versus(v) -> str:
    """One level of :func:`speedup` in words: each peer's CPU time over our best's."""
    if v["best"] is None:
        return "none of our methods reaches it"
    ratios = v.get("peer_over_best") or {"DOP853": v.get("DOP853_over_best")}
    said = [f"{k} needs {r:.2g}× the CPU time of our best ({v['best']})" for k, r in ratios.items() if r]
    return "; ".join(said) if said else f"no peer reaches it (our best: {v['best']})"
