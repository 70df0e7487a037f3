r"""Scenes: a JSON file describing an experiment → runs → data files and plots under reports/.

A scene names a problem, one or more runs (method file, projection, precision, start), the step
size and the number of steps (or the final time), what to record and how often, and the plots::

    {"format": "tableau_lab/scene/1", "name": "fig3_01_euler_pendulum",
     "title": "Explicit Euler on the pendulum, (p0, q0) = (1, 0)", "seed": "Figure 3.1",
     "problem": {"name": "pendulum", "set": {"q0": "0", "p0": "1"}},
     "h": "1/100", "steps": 10000,
     "runs": [{"method": "../../methods/explicit_euler.json", "label": "explicit Euler"},
              {"method": "../../methods/explicit_euler.json", "project": ["H"], "label": "with projection"}],
     "record_every": 10, "plots": ["invariants", "orbit"]}

Paths are relative to the scene file.  Numbers are exact strings ("1/100", "0.03") or
integers.  ``tableau-lab run SCENE...`` writes ``reports/<name>/data.npz`` (times, invariant
errors, states, the parasitic component of GLM inputs) with ``meta.json`` beside it (scene,
method names, problem, h, precision, tableau-lab version, whether each run completed) and
``<name>_<plot>.png``.  A run stopped by an error or by Ctrl-C keeps its records, marked
``"completed": false``; files are written atomically (no half-written file).  Only what is asked
for is computed: no invariant gradients without projection, no states unless a plot needs them.

``"monitor": "1e-3"`` (an exact positive number) bounds the parasitic components of GLM input
vectors (:mod:`~tableau_lab.numeric.integrate`, checked at the records): a run that exceeds it
stops with status ``"stopped"`` and its message names ζ, the value, the bound and μ.  A stopped
run is a result, not a failure (the scene stays complete).  For every GLM with eigenvalues
ζ ≠ 1 of V on the unit circle the data hold ``run<i>_parasitic_<j>`` (the component of the j-th
ζ at the records) and, when μ ≠ 0, ``run<i>_predicted_<j>`` (∫ max Re eig(μ f′) dt); meta.json
lists the ζ, μ and the largest component per run.
"""
from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import sympy as sp

from .. import __version__
from ..files import atomic_write, atomic_write_text

__all__ = ["SceneError", "load_scene", "run_scene", "run_one", "write_outputs", "Scene"]

FORMAT = "tableau_lab/scene/1"
PLOTS = ("invariants", "orbit", "parasitic", "state")
KEYS = {"format", "name", "title", "seed", "notes", "problem", "h", "steps", "T", "runs", "record_every",
        "plots", "precision", "start", "monitor"}
RUN_KEYS = {"method", "project", "precision", "start", "label"}


class SceneError(ValueError):
    """A scene that cannot be run: the message names the file and the key."""


@dataclass(frozen=True)
class Scene:
    path: Path
    name: str
    title: str
    seed: str
    problem: object
    h: sp.Rational
    steps: int
    runs: tuple           # dicts: method (Path), project, precision, start, label
    record_every: int
    plots: tuple
    raw: dict
    monitor: float | None = None     # bound on the parasitic components (None: recorded, not bounded)


def _exact(v, where, path):
    from ..exact.grammar import EntryError, parse_number
    if isinstance(v, bool) or not isinstance(v, (int, str)):
        raise SceneError(f"{path}: {where}: write numbers as integers or exact strings such as \"1/100\", not {v!r}")
    try:
        return parse_number(str(v))
    except EntryError as exc:
        raise SceneError(f"{path}: {where}: {exc}") from None


def _read_json(path):
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise SceneError(f"{path}: cannot read: {exc.strerror}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise SceneError(f"{path}: not valid JSON: {exc}") from None
    if not isinstance(data, dict):
        raise SceneError(f"{path}: a scene is one JSON object")
    return data


def _problem(prob, path):
    """The problem of a scene: a name, {"name": ..., "set": {...}} or {"define": {...}}."""
    from ..numeric.problems import ProblemError, get_problem, problem_from_dict
    try:
        if isinstance(prob, str):
            problem = get_problem(prob)
        elif isinstance(prob, dict) and "define" in prob:
            problem = problem_from_dict(prob["define"])
        elif isinstance(prob, dict) and isinstance(prob.get("name"), str):
            sets = prob.get("set", {})
            if not isinstance(sets, dict):
                raise SceneError(f"{path}: problem.set must be an object such as {{\"e\": \"0.6\"}}")
            over = {}
            for k, v in sets.items():
                over[k] = tuple(_exact(x, f"problem.set.{k}", path) for x in v) if isinstance(v, list) else \
                    _exact(v, f"problem.set.{k}", path)
            problem = get_problem(prob["name"], **over)
        else:
            raise SceneError(f"{path}: problem must be a name, {{\"name\": ..., \"set\": {{...}}}} or {{\"define\": {{...}}}}")
    except ProblemError as exc:
        raise SceneError(f"{path}: problem: {exc}") from None
    return problem


def load_scene(path) -> Scene:
    """Read and validate a scene file (problem built, methods found; nothing run)."""
    path = Path(path)
    data = _read_json(path)
    unknown = set(data) - KEYS
    if unknown:
        raise SceneError(f"{path}: unknown keys {sorted(unknown)} (allowed: {sorted(KEYS)})")
    if data.get("format", FORMAT) != FORMAT:
        raise SceneError(f"{path}: format {data.get('format')!r} is not {FORMAT!r}")
    name = data.get("name")
    if not isinstance(name, str) or not name or not all(c.isalnum() or c in "-_." for c in name):
        raise SceneError(f"{path}: name must be a non-empty file-name-safe string (letters, digits, - _ .)")
    problem = _problem(data.get("problem"), path)
    h = _exact(data.get("h"), "h", path) if "h" in data else None
    if h is None or not h > 0:
        raise SceneError(f"{path}: h must be a positive exact number, got {data.get('h')!r}")
    if ("steps" in data) == ("T" in data):
        raise SceneError(f"{path}: give exactly one of steps and T")
    if "steps" in data:
        steps = data["steps"]
        if not isinstance(steps, int) or isinstance(steps, bool) or not 1 <= steps <= 10 ** 9:
            raise SceneError(f"{path}: steps must be an integer between 1 and 10^9")
    else:
        T = _exact(data["T"], "T", path)
        steps = T / h
        if not (steps.is_Integer and steps > 0):
            raise SceneError(f"{path}: T / h = {steps} is not a positive whole number of steps")
        steps = int(steps)
    runs = data.get("runs")
    if not isinstance(runs, list) or not runs:
        raise SceneError(f"{path}: runs must be a non-empty list of {{\"method\": FILE, ...}}")
    out_runs = []
    for i, r in enumerate(runs):
        where = f"runs[{i}]"
        if not isinstance(r, dict) or "method" not in r or set(r) - RUN_KEYS:
            raise SceneError(f"{path}: {where} must be an object with method and optional {sorted(RUN_KEYS - {'method'})}")
        mpath = (path.parent / r["method"]).resolve()
        if not mpath.exists():
            raise SceneError(f"{path}: {where}.method: no file {r['method']} (relative to the scene file)")
        project = r.get("project", [])
        bad = [k for k in project if k not in problem.invariants]
        if bad:
            raise SceneError(f"{path}: {where}.project: {bad} are not invariants of {problem.name} "
                             f"({', '.join(problem.invariants)})")
        prec = r.get("precision", data.get("precision", "float64"))
        from ..numeric.arith import arith
        try:
            arith(prec)
        except ValueError as exc:
            raise SceneError(f"{path}: {where}.precision: {exc}") from None
        start = r.get("start", data.get("start", "exact"))
        if start not in ("exact", "naive"):
            raise SceneError(f"{path}: {where}.start must be exact or naive")
        out_runs.append({"method": mpath, "as_written": r["method"], "project": tuple(project), "precision": prec, "start": start,
                         "label": r.get("label") or mpath.stem + (f" + projection onto {', '.join(project)}" if project else "")})
    every = data.get("record_every", max(1, steps // 1000))
    if not isinstance(every, int) or every < 1:
        raise SceneError(f"{path}: record_every must be a positive integer")
    plots = tuple(data.get("plots", ["invariants"]))
    bad = [p for p in plots if p not in PLOTS]
    if bad:
        raise SceneError(f"{path}: unknown plots {bad} (known: {', '.join(PLOTS)})")
    monitor = None
    if "monitor" in data:
        bound = _exact(data["monitor"], "monitor", path)
        if not bound > 0:
            raise SceneError(f"{path}: monitor must be a positive bound such as \"1e-3\", got {data['monitor']!r}")
        monitor = float(bound)
    return Scene(path, name, data.get("title", name), data.get("seed", ""), problem, h, steps, tuple(out_runs),
                 every, plots, data, monitor)


def run_one(sc: Scene, i: int, progress: bool = False):
    """Run ``sc.runs[i]``; returns (arrays without the ``run<i>_`` prefix, its meta entry,
    interrupted).  A run stopped by an error, the monitor or Ctrl-C keeps its records."""
    from ..exact.tableau_json import load
    from ..numeric.export import to_numeric
    from ..numeric.integrate import IntegrationError, ParasiticBoundExceeded, integrate
    from .runs import compiled

    r = sc.runs[i]
    want_states = any(p in ("orbit", "state") for p in sc.plots)
    m = load(r["method"])
    nm = to_numeric(m, r["precision"])
    cp = compiled(sc.problem, r["precision"])
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=sc.steps, desc=f"{sc.name}: {r['label']}", unit="step", leave=False)
    last = [0]

    def tick(n):
        if bar is not None:
            bar.update(n - last[0])
            last[0] = n
    status, message, interrupted = "completed", "", False
    try:
        run = integrate(nm, cp, cp.y0, sc.h, sc.steps, start=r["start"], project=r["project"],
                        invariants=tuple(sc.problem.invariants), record_every=sc.record_every,
                        record_states=want_states, problem_name=sc.problem.name, progress=tick, monitor=sc.monitor)
    except (IntegrationError, KeyboardInterrupt) as exc:
        run = getattr(exc, "partial", None)
        status = ("interrupted" if isinstance(exc, KeyboardInterrupt)
                  else "stopped" if isinstance(exc, ParasiticBoundExceeded) else "failed")
        message = str(exc) or "interrupted by the user"
        interrupted = isinstance(exc, KeyboardInterrupt)
        if run is None:
            raise
    finally:
        if bar is not None:
            bar.close()
    arrays = {"t": np.array(run.times)}
    for k, v in run.invariant_errors.items():
        arrays[k] = np.array([float(x) for x in v])
    if want_states and run.values:
        arrays["y"] = np.array([nm.arith.to_float(v) for v in run.values])
    if run.parasitic:
        arrays["parasitic"] = np.array(run.parasitic)
    modes = []
    for j, (zeta, comp) in enumerate(run.parasitic_components.items()):
        arrays[f"parasitic_{j}"] = np.array(comp)
        if zeta in run.predicted_growth:
            arrays[f"predicted_{j}"] = np.array(run.predicted_growth[zeta])
        mu = run.growth_parameters[zeta]
        modes.append({"zeta": zeta, "mu": f"{mu.real:.12g}" if mu.imag == 0 else f"{mu:.12g}",
                      "max": max(comp, default=0.0)})
    meta = {"label": r["label"], "method": m.name, "file": r["as_written"], "precision": r["precision"],
            "start": run.start, "projection": list(r["project"]), "status": status, "message": message,
            "completed_steps": run.completed, "t_end": float(run.completed * sc.h), "nfev": run.nfev,
            "newton_iterations": run.newton_iterations, "projection_iterations": run.projection_iterations,
            "seconds": round(run.seconds, 3), "max_invariant_error": run.max_invariant_error(),
            **({"parasitic_modes": modes} if modes else {})}
    return arrays, meta, interrupted


def write_outputs(sc: Scene, results, out) -> dict:
    """Data, metadata and plots of a scene from ``run_one``'s results (in run order) under
    ``out``; stale files of an earlier run are removed.  Returns the metadata."""
    from .plots import draw
    out = Path(out)
    arrays = {f"run{i}_{k}": v for i, (a, _, _) in enumerate(results) for k, v in a.items()}
    meta_runs = [m for _, m, _ in results]
    meta = {"scene": str(sc.path), "name": sc.name, "title": sc.title, "seed": sc.seed, "problem": sc.problem.name,
            "parameters": {k: str(v) for k, v in sc.problem.parameters.items()}, "h": str(sc.h), "steps": sc.steps,
            "record_every": sc.record_every, "tableau_lab": __version__,
            **({"monitor": sc.monitor} if sc.monitor is not None else {}),
            "complete": all(r["status"] in ("completed", "stopped") for r in meta_runs) and len(meta_runs) == len(sc.runs),
            "runs": meta_runs}
    suffix = "" if meta["complete"] else ".incomplete"
    for stale in list(out.glob("data*.npz")) + list(out.glob("meta*.json")) + list(out.glob(f"{sc.name}_*.png")):
        stale.unlink()                      # a previous run's files must not contradict this one's
    atomic_write(out / f"data{suffix}.npz", lambda tmp: np.savez_compressed(tmp, **arrays), suffix=".npz")
    atomic_write_text(out / f"meta{suffix}.json", json.dumps(meta, indent=1, ensure_ascii=False))
    meta["plots"] = draw(sc, meta, arrays, out) if meta_runs else []
    return meta


def run_scene(path, out_root="reports", progress: bool | None = None) -> dict:
    """Run every run of a scene, write data, metadata and plots; returns the metadata."""
    sc = load_scene(path)
    show = sys.stderr.isatty() if progress is None else progress
    results = []
    for i in range(len(sc.runs)):
        results.append(run_one(sc, i, show))
        if results[-1][2]:
            break
    meta = write_outputs(sc, results, Path(out_root) / sc.name)
    if results[-1][2]:
        raise KeyboardInterrupt
    return meta
