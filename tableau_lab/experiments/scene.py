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

Paths are relative to the scene file; a method that is no file there is a library name
(``"gauss2"``) or a family with its size (``"gauss:3"``, ``"bdf:4"``) (:func:`method_file`).
Numbers are exact strings ("1/100", "0.03") or integers.  Every key is read by its entry of the
tables in :mod:`~tableau_lab.experiments.scene_keys` (docs/scenes.md is generated from them).
``tableau-lab run SCENE...`` writes ``reports/<name>/data.npz`` (times, invariant errors, states,
the parasitic component of GLM inputs) with ``meta.json`` beside it (scene,
method names, problem, h, precision, tableau-lab version, whether each run completed) and
``<name>_<plot>.png``.  A run stopped by an error or by Ctrl-C keeps its records, marked
``"completed": false``; files are written atomically (no half-written file).  Only what is asked
for is computed: no invariant gradients without projection, no states unless a plot needs them.

``"monitor": "1e-3"`` (an exact positive number) bounds the parasitic components of GLM input
vectors (:mod:`~tableau_lab.numeric.integrate`, checked at the records): a run that exceeds it
stops with status ``"stopped"`` and its message names ζ, the value, the bound and μ.  A stopped
run is a result, not a failure (the scene stays complete).

A run that goes to its end with an invariant error or a parasitic component of relative size
``limits.DEGRADED`` (1e-2) or more (:meth:`~tableau_lab.numeric.integrate.Run.degraded`) has the
status ``"degraded"`` and the reason as its message; the scene stays complete, the figures say
so (a label, the title, and phase plots draw such runs in a panel of their own), and ``run``
exits 4.  For every GLM with eigenvalues
ζ ≠ 1 of V on the unit circle the data hold ``run<i>_parasitic_<j>`` (the component of the j-th
ζ at the records) and, when μ ≠ 0, ``run<i>_predicted_<j>`` (∫ max Re eig(μ f′) dt); meta.json
lists the ζ, μ and the largest component per run.

``"modified_energy": {"terms": 2}`` (Hamiltonian problems; terms an integer 1 to 3, default 2)
adds ``<name>_modified_energy.png``: per run, |H(y_n) − H₀| beside |H̃(y_n) − H̃₀|, H̃ the
method's modified energy to its ``terms`` lowest nonzero corrections at the scene's h
(:mod:`~tableau_lab.experiments.modified_energy`), both evaluated in float64 at the recorded
states (for a GLM z_n = wᵀy^[n], or its finished output when the finishing method is not the
identity: meta.json says which).  A run whose method has no modified energy (RK4, explicit Euler)
shows |H − H₀| alone with the reason.  The data hold ``run<i>_modified_H`` and
``run<i>_modified_Htilde``; meta.json per run the powers, the corrections, the maxima and their
ratio (or the reason).
"""
from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import sympy as sp

from .. import __version__
from ..budget import DEFAULT_SECONDS, computing, time_limit
from ..files import atomic_write, atomic_write_text
from ..inputs import printable
from .progress import StepBar
from .scene_keys import (
    FORMAT,
    KEYS,
    MAX_MODIFIED_TERMS,
    MODIFIED_ENERGY_KEYS,
    MODIFIED_ENERGY_SCHEMA,
    PLOT_SCHEMA,
    PLOTS,
    RUN_KEYS,
    RUN_SCHEMA,
    SCHEMA,
    Field,
    Key,
    SceneError,
    method_file,
    method_label,
    read_object,
    read_scene,
    scene_doc,
)

__all__ = ["SceneError", "load_scene", "run_scene", "run_one", "write_outputs", "Scene", "method_file", "method_label",
           "scene_doc", "draw_modified_energy", "SCHEMA", "RUN_SCHEMA", "PLOT_SCHEMA", "MODIFIED_ENERGY_SCHEMA", "Key",
           "FORMAT", "PLOTS", "MAX_MODIFIED_TERMS", "KEYS", "RUN_KEYS", "MODIFIED_ENERGY_KEYS"]


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
    modified_energy: int | None = None   # terms of H̃ to plot beside H (None: no modified-energy plot)


def load_scene(path, timeout: float | None = DEFAULT_SECONDS) -> Scene:
    """Read and validate a scene file: every key read by its entry of :data:`SCHEMA` (type,
    range, default; the runs by :data:`RUN_SCHEMA`), the problem built (within the time budget
    ``timeout``, as the exact commands': a user-defined problem can be costly), the method files
    read as JSON (nothing run).  Messages name the file and the key
    (:func:`~tableau_lab.experiments.scene_keys.read_object`)."""
    path = Path(path)
    data = read_scene(path)
    got = read_object(SCHEMA, data, Field(path, timeout=timeout))
    runs = tuple({"method": run["method"], "as_written": raw["method"], **run}
                 for run, raw in zip(got["runs"], data["runs"], strict=True))
    return Scene(path, got["name"], got["title"], got["seed"], got["problem"], got["h"], got["steps"], runs,
                 got["record_every"], tuple(got["plots"]), data, got["monitor"], got["modified_energy"])


def run_one(sc: Scene, i: int, progress: bool = False, timeout: float | None = DEFAULT_SECONDS):
    """Run ``sc.runs[i]``; returns (arrays without the ``run<i>_`` prefix, its meta entry,
    interrupted).  A run stopped by an error, the monitor or Ctrl-C keeps its records.  The
    exact stage (the method read and rounded, the problem's code generated) runs within the
    time budget ``timeout`` (BudgetError), the run itself within the scene's step budget."""
    from ..exact.tableau_json import load
    from ..numeric.export import to_numeric
    from ..numeric.integrate import IntegrationError, ParasiticBoundExceeded, integrate
    from .runs import compiled, generate

    r = sc.runs[i]
    want_states = any(p in ("orbit", "state") for p in sc.plots) or sc.modified_energy is not None
    with time_limit(timeout), computing(f"{sc.path}: runs[{i + 1}] ({printable(r['label'])})"):
        m = load(r["method"])
        nm = to_numeric(m, r["precision"])
        cp = compiled(sc.problem, r["precision"])
        generate(cp, nm, tuple(sc.problem.invariants), r["project"])
    status, message, interrupted = "completed", "", False
    try:
        with StepBar(sc.steps, f"{sc.name}: {r['label']}", show=bool(progress)) as tick:
            run = integrate(nm, cp, cp.y0, sc.h, sc.steps, start=r["start"], project=r["project"],
                            invariants=tuple(sc.problem.invariants), record_every=sc.record_every,
                            record_states=want_states, problem_name=sc.problem.name, progress=tick,
                            monitor=sc.monitor, kernel="cost")
    except (IntegrationError, KeyboardInterrupt) as exc:
        run = getattr(exc, "partial", None)
        status = ("interrupted" if isinstance(exc, KeyboardInterrupt)
                  else "stopped" if isinstance(exc, ParasiticBoundExceeded) else "failed")
        message = str(exc) or "interrupted by the user"
        interrupted = isinstance(exc, KeyboardInterrupt)
        if run is None:
            raise
    degraded = run.degraded() if status == "completed" else ""
    if degraded:
        status, message = "degraded", f"degraded: {degraded}"
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
            "seconds": round(run.seconds, 3), "loop": run.loop, "loop_why": run.loop_why,
            "compile_seconds": round(run.compile_seconds, 3), "max_invariant_error": run.max_invariant_error(),
            **({"parasitic_modes": modes} if modes else {})}
    if sc.modified_energy is not None and not interrupted:
        meta["modified_energy"] = _modified_energy(sc, m, nm, r, arrays)
    return arrays, meta, interrupted


_MODIFIED: dict = {}        # (method, problem key, h, terms) -> (corrections, H, H̃) or the reason


def _modified_energy(sc: Scene, m, nm, r, arrays) -> dict:
    """H and H̃ at the run's recorded states (into ``arrays`` as ``modified_H``, ``modified_Htilde``)
    and the meta entry; a method without a modified energy gets H alone and the reason."""
    from .modified_energy import energy_errors, modified_energy_expression, problem_hamiltonian
    key = (m, sc.problem.key, sc.h, sc.modified_energy)       # the method's value: no second read of its file
    if key not in _MODIFIED:
        try:
            _MODIFIED[key] = modified_energy_expression(m, sc.problem, sc.h, sc.modified_energy)
        except ValueError as exc:                  # no H̃ (RK4), or not within the series' orders
            _MODIFIED[key] = printable(str(exc)) or "no modified energy"
        except Exception as exc:                   # an optional plot never stops the scene
            _MODIFIED[key] = printable(f"H̃ not computed ({type(exc).__name__}: {exc})")
    found = _MODIFIED[key]
    states = arrays.get("y", np.zeros((0, sc.problem.dimension)))
    finished = nm.r > 1 and r["start"] == "exact" and any(v != 0 for v in nm.finishing.values())
    where = ("the GLM's finished output (its H̃ is conserved at z_n = wᵀy^[n], not there)" if finished
             else "z_n = wᵀy^[n]" if nm.r > 1 else "y_n")
    if isinstance(found, str):
        (eH,) = energy_errors(sc.problem, [problem_hamiltonian(sc.problem)[0]], states)
        arrays["modified_H"] = eH
        return {"terms": sc.modified_energy, "none": found, "evaluated_at": where,
                "max_abs_H_error": float(np.max(np.abs(eH), initial=0.0))}
    corr, H, Ht = found
    try:
        eH, eT = energy_errors(sc.problem, [H, Ht], states)
    except Exception as exc:                       # e.g. a derivative numpy cannot evaluate
        eH, = energy_errors(sc.problem, [H], states)
        arrays["modified_H"] = eH
        return {"terms": sc.modified_energy, "none": printable(f"H̃ not evaluated ({type(exc).__name__}: {exc})"),
                "evaluated_at": where, "max_abs_H_error": float(np.max(np.abs(eH), initial=0.0))}
    arrays["modified_H"], arrays["modified_Htilde"] = eH, eT
    mH, mT = float(np.max(np.abs(eH), initial=0.0)), float(np.max(np.abs(eT), initial=0.0))
    return {"terms": sc.modified_energy, "powers": [k for k, _ in corr],
            "corrections": {f"h^{k}": str(e) for k, e in corr}, "evaluated_at": where,
            "max_abs_H_error": mH, "max_abs_Htilde_error": mT, "ratio": mH / mT if mT > 0 else None}


def write_outputs(sc: Scene, results, out, also=None) -> dict:
    """Data, metadata and plots of a scene under ``out`` from ``run_one``'s results in run
    order (``None``, or a shorter list, for runs that did not run: listed as ``"not run"``).
    One write phase (:mod:`tableau_lab.files`): the folder's lock held (a concurrent run of the
    same scene writes before or after, never in between), Ctrl-C held until the set is written,
    every file staged and moved into place together; then, still under the lock, the previous
    run's files that this set does not replace are removed (missing ones tolerated).
    A full disk (:class:`~tableau_lab.files.OutputError`) leaves the previous set as it was.
    ``also(out)``: more files drawn in the same phase (their names, kept).  Returns the
    metadata (with ``"plots"``)."""
    from ..files import (
        OutputRefused,
        confined,
        deferred_interrupt,
        guard_output,
        output_lock,
        output_set,
        remove_stale_temps,
    )
    from .plots import draw
    out = Path(out)
    results = list(results) + [None] * (len(sc.runs) - len(results))
    arrays = {f"run{i}_{k}": v for i, res in enumerate(results) if res is not None for k, v in res[0].items()}
    meta_runs = [res[1] if res is not None else _not_run(sc, i) for i, res in enumerate(results)]
    meta = {"scene": str(sc.path), "name": sc.name, "title": sc.title, "seed": sc.seed, "problem": sc.problem.name,
            "parameters": {k: str(v) for k, v in sc.problem.parameters.items()}, "h": str(sc.h), "steps": sc.steps,
            "record_every": sc.record_every, "tableau_lab": __version__,
            **({"monitor": sc.monitor} if sc.monitor is not None else {}),
            **({"modified_energy": {"terms": sc.modified_energy}} if sc.modified_energy is not None else {}),
            "complete": all(r["status"] in ("completed", "degraded", "stopped") for r in meta_runs),
            "runs": meta_runs}
    suffix = "" if meta["complete"] else ".incomplete"
    with confined(out), output_lock(out), deferred_interrupt():
        remove_stale_temps(out)
        with output_set():
            written = [f"data{suffix}.npz", f"meta{suffix}.json"]
            atomic_write(out / written[0], lambda tmp: np.savez_compressed(tmp, **arrays), suffix=".npz")
            atomic_write_text(out / written[1], json.dumps(meta, indent=1, ensure_ascii=False))
            plots = draw(sc, meta, arrays, out) if any(res is not None for res in results) else []
            if sc.modified_energy is not None and any(res is not None for res in results):
                plots.append(draw_modified_energy(sc, meta, arrays, out, suffix))
            extra = list(also(out)) if also is not None else []
        # the set is in place: a previous run's files must not contradict it
        from .figure_style import siblings
        keep = set(written) | {f.name for name in plots + extra
                               for f in (siblings(out / name) if name.endswith(".png") else [out / name])}
        for name in _scene_files(out, sc.name):
            if name not in keep:
                try:
                    guard_output(out / name)        # never an input, never anything but a regular file
                    (out / name).unlink()
                except (FileNotFoundError, OutputRefused):
                    pass                    # removed by a concurrent writer that does not lock; an input
    meta["plots"] = plots + extra
    return meta


def draw_modified_energy(sc: Scene, meta, arrays, out: Path, suffix: str) -> str:
    """``<name>_modified_energy<suffix>.png`` in ``out``: a panel per run, |H − H₀| beside |H̃ − H̃₀|,
    from a scene's metadata and data arrays (:func:`write_outputs` after the runs, ``tableau-lab
    replot`` from the saved files: experiments/replot.py).  Returns the file name."""
    from .modified_energy import plot_energy_panels
    panels = []
    for i, r in enumerate(meta["runs"]):
        me, t = r.get("modified_energy"), arrays.get(f"run{i}_t")
        if me is None or t is None:
            panels.append({"t": [], "err_H": [], "title": r["label"], "note": f"run {r['status']}"})
            continue
        if "none" in me:
            panels.append({"t": t, "err_H": arrays[f"run{i}_modified_H"], "note": me["none"],
                           "title": f"{r['label']}: no modified energy"})
            continue
        ratio = f"ratio of maxima {me['ratio']:.3g}" if me["ratio"] is not None else "H̃ exactly conserved"
        panels.append({"t": t, "err_H": arrays[f"run{i}_modified_H"], "err_Ht": arrays[f"run{i}_modified_Htilde"],
                       "powers": me["powers"], "title": f"{r['label']} ({ratio})"})
    name = f"{sc.name}_modified_energy{suffix}.png"
    title = sc.title + ("" if meta["complete"] else " (incomplete)")
    lowest = "its lowest nonzero correction" if sc.modified_energy == 1 else \
        f"its {sc.modified_energy} lowest nonzero corrections"
    plot_energy_panels(panels, out / name, f"{title}\nH̃ = H + {lowest} (the method's modified energy at h = {sc.h})")
    return name


def guard_scene_outputs(sc: Scene, out) -> None:
    """Before any run: refuse (:class:`~tableau_lab.files.OutputRefused`, naming both paths) when
    a file the scene's write phase may replace or remove in ``out`` (its data, metadata, figures:
    :func:`_scene_files`) is one of its inputs (the scene file, a method file) or not a regular
    file."""
    from ..files import refuse_outputs
    out = Path(out)
    inputs = [sc.path] + [r["method"] for r in sc.runs if isinstance(r.get("method"), Path)]   # a family has no file
    names = {"data.npz", "meta.json", "data.incomplete.npz", "meta.incomplete.json"} | set(_scene_files(out, sc.name))
    refuse_outputs([out / n for n in sorted(names)], inputs)


def _scene_files(out: Path, name: str) -> list:
    """The files of a scene's output set in ``out``: data*.npz, meta*.json, and its figures
    <name>_* in every format of the figure style."""
    from .figure_style import FORMATS
    try:
        names = [p.name for p in out.iterdir()]
    except OSError:
        return []
    return [f for f in names if (f.startswith("data") and f.endswith(".npz"))
            or (f.startswith("meta") and f.endswith(".json")) or (f.startswith(f"{name}_") and f.endswith(FORMATS))]


def _not_run(sc: Scene, i: int) -> dict:
    """The meta entry of a run that did not run (the scene was interrupted before it)."""
    r = sc.runs[i]
    return {"label": r["label"], "method": None, "file": r["as_written"], "precision": r["precision"],
            "start": r["start"], "projection": list(r["project"]), "status": "not run",
            "message": "not run: the scene was interrupted before this run", "completed_steps": 0, "t_end": 0.0,
            "nfev": 0, "newton_iterations": 0, "projection_iterations": 0, "seconds": 0.0,
            "max_invariant_error": {}}


def run_scene(path, out_root="reports", progress: bool | None = None, timeout: float | None = DEFAULT_SECONDS) -> dict:
    """Run every run of a scene, write data, metadata and plots; returns the metadata.  Ctrl-C
    (``KeyboardInterrupt``) stops the runs; the runs that finished and the records of the one
    interrupted are written as an incomplete set (the others listed as ``"not run"``), then
    ``KeyboardInterrupt`` is raised again.  Interrupted before any run produced records, the
    folder is left as it was."""
    sc = load_scene(path, timeout)
    guard_scene_outputs(sc, Path(out_root) / sc.name)      # before any run
    show = sys.stderr.isatty() if progress is None else progress
    results = [None] * len(sc.runs)
    interrupted = False
    try:
        for i in range(len(sc.runs)):
            results[i] = run_one(sc, i, show, timeout)
            if results[i][2]:
                interrupted = True
                break
    except KeyboardInterrupt:
        interrupted = True
    if interrupted and all(res is None for res in results):
        raise KeyboardInterrupt
    meta = write_outputs(sc, results, Path(out_root) / sc.name)
    if interrupted:
        raise KeyboardInterrupt
    return meta
