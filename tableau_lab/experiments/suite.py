r"""The hard-case suite (issue 8, item 6): scenes whose runs go through one executor, one table.

    tableau-lab suite [SUITE_DIR] [--steps N] [--workers N] [--scheduler ADDR] [--only NAMES] [--json]

``SUITE_DIR`` (default ``reports/suite``) holds ``scenes/*.json``: one scene per hard case, each
listing every symplectic and G-symplectic method with and without projection and a parasitism
``monitor`` bound.  Every run (method × problem × projection) is one independent task of
:func:`~tableau_lab.experiments.executor.executor` (a local process pool, in-process, or a Dask
cluster), the most expensive scenes first.  Each scene's data, metadata and plots are written
as ``tableau-lab run`` writes them, under ``OUT/<scene>/``; then ``OUT/summary.json``,
``OUT/summary.md`` (the table and the claims), ``OUT/suite_energy.png`` (max |H − H₀| per run)
and ``OUT/suite_time_to_failure.png`` (how far each run got).  A scene is written as soon as its
last run finishes (while the others run); after Ctrl-C the scenes with finished runs are written
as incomplete sets (the others listed as not run), the summary is not rewritten, and the
command ends with ``KeyboardInterrupt`` (exit 130).  Every file is written atomically under the
folder's lock (:mod:`tableau_lab.files`).  ``--steps N`` gives every scene N
steps with as many records as before (the reduced suite of the tests uses 10³).

For the runs whose method has a growth parameter μ ≠ 0 the table compares the measured
log-growth of the parasitic component, log(c(t₁)/c(t₀)) from the first nonzero record t₀ to
the first record where c ≥ 10⁻² (or the end), with the prediction ∫_{t₀}^{t₁} max Re eig(μ f′(y)) dt
([BHHN14]; :func:`~tableau_lab.analysis.parasitism.predicted_growth`).  The claims checked:
Example 4 has μ ≠ 0 and on the pendulum at q₀ = 2.3 its component grows as predicted (ratio
within a factor 10) and the monitor stops it; GLM43 (all μ = 0) completes the same run with its
components below the bound.
"""
from __future__ import annotations

import dataclasses
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from ..files import atomic_write_text, output_phase
from .executor import executor
from .scene import SceneError, load_scene, run_one, write_outputs

__all__ = ["run_suite", "suite_task", "growth_check", "format_table", "load_suite", "draw_suite_energy",
           "draw_suite_maps"]

CEILING = 1e-2          # the measured growth window ends where the component reaches this size
SUMMARY_FILES = ("summary.json", "summary.md")   # what run_suite writes into OUT beside the scenes' folders
# relative cost of a step (for the order of the tasks: the longest first)
_COST = {"outer_solar_system": 200.0, "fpu": 6.0, "kepler": 1.5, "henon_heiles": 1.0, "pendulum": 1.0}


def load_suite(suite_dir, steps: int | None = None, only=None) -> list:
    """The suite's scenes (``SUITE_DIR/scenes/*.json``, by name), with ``steps`` replacing each
    scene's step count (records as many as before) and ``only`` a set of scene names."""
    files = sorted(Path(suite_dir, "scenes").glob("*.json"))
    if not files:
        raise SceneError(f"{suite_dir}: no scene files under {Path(suite_dir, 'scenes')}")
    scenes = [_with_steps(load_scene(f), steps) for f in files]
    if only:
        unknown = set(only) - {sc.name for sc in scenes}
        if unknown:
            raise SceneError(f"{suite_dir}: no scenes {sorted(unknown)} (known: {', '.join(sc.name for sc in scenes)})")
        scenes = [sc for sc in scenes if sc.name in only]
    return scenes


def _with_steps(sc, steps):
    if steps is None:
        return sc
    if steps < 1:
        raise SceneError(f"--steps {steps}: at least one step")
    records = max(1, sc.steps // sc.record_every)
    return dataclasses.replace(sc, steps=int(steps), record_every=max(1, int(steps) // records))


def suite_task(item):
    """One run of the suite: item = (scene file, run index, steps or None) → ``run_one``'s
    (arrays, meta, interrupted).  Module level, so that it pickles for the process pool."""
    path, i, steps = item
    return run_one(_with_steps(load_scene(path), steps), i)


def growth_check(t, c, predicted, ceiling: float = CEILING):
    """Measured against predicted log-growth of one parasitic component over [t₀, t₁] (see the
    module docstring); None without a nonzero record after the start."""
    c, predicted = np.asarray(c, dtype=float), np.asarray(predicted, dtype=float)
    nonzero = np.flatnonzero(c > 0)
    if len(nonzero) < 2:
        return None
    k0 = int(nonzero[0])
    above = np.flatnonzero(c[k0:] >= ceiling)
    k1 = k0 + int(above[0]) if len(above) else len(c) - 1
    if k1 == k0 or not math.isfinite(c[k1]):
        return None
    measured, pred = float(np.log(c[k1] / c[k0])), float(predicted[k1] - predicted[k0])
    ratio = measured / pred if pred > 0 else None
    return {"t0": float(t[k0]), "t1": float(t[k1]), "measured": measured, "predicted": pred,
            "ratio": ratio, "agree": ratio is not None and 0.1 <= ratio <= 10}


def _row(sc, meta, arrays) -> dict:
    modes = meta.get("parasitic_modes", [])
    growth = None
    for j, _ in enumerate(modes):
        if f"predicted_{j}" in arrays:
            growth = growth_check(arrays["t"], arrays[f"parasitic_{j}"], arrays[f"predicted_{j}"])
            break
    errs = meta["max_invariant_error"]
    return {"scene": sc.name, "problem": sc.problem.name, "method": meta["method"], "label": meta["label"],
            "file": Path(meta["file"]).stem, "projection": meta["projection"], "status": meta["status"],
            "t_end": meta["t_end"], "T": float(sc.steps * sc.h), "steps": meta["completed_steps"],
            "max_H_error": errs.get("H"), "max_invariant_error": errs,
            "max_parasitic": max((m["max"] for m in modes), default=None),
            "mu": [m["mu"] for m in modes], "zeta": [m["zeta"] for m in modes], "growth": growth,
            "seconds": meta["seconds"], "message": meta["message"]}


def _claims(rows, monitor_of) -> list:
    """The issue's claims, on the rows that exist (pendulum at q₀ = 2.3, no projection)."""
    def find(stem):
        return next((r for r in rows if r["file"] == stem and not r["projection"] and r["problem"] == "pendulum"
                     and r["scene"].endswith("q23")), None)
    out = []
    ex4, g43 = find("example4_glm"), find("glm43")
    if ex4 is not None:
        mu = [complex(m) for m in ex4["mu"]]
        out.append({"claim": "Example 4 GLM has a nonzero parasitic growth parameter",
                    "holds": any(abs(m) > 1e-12 for m in mu), "detail": f"μ = {', '.join(ex4['mu'])}"})
        g = ex4["growth"]
        out.append({"claim": "Example 4 on the pendulum, q0 = 2.3: the parasitic component grows as predicted "
                             "(measured / predicted log-growth within a factor 10)",
                    "holds": bool(g and g["agree"] and g["measured"] > 1),
                    "detail": "no growth window" if not g else
                    f"t = {g['t0']:g}..{g['t1']:g}: measured {g['measured']:.3g}, predicted {g['predicted']:.3g}"})
        if monitor_of.get(ex4["scene"]) is not None and ex4["T"] > 60:
            out.append({"claim": "the monitor stops Example 4 on the pendulum, q0 = 2.3",
                        "holds": ex4["status"] == "stopped", "detail": f"{ex4['status']} at t = {ex4['t_end']:g}"})
    if g43 is not None:
        bound = monitor_of.get(g43["scene"])
        out.append({"claim": "GLM43 (all μ = 0) does not blow up on the same run",
                    "holds": g43["status"] == "completed" and (g43["max_H_error"] or 0) < 1e-3
                    and (bound is None or (g43["max_parasitic"] or 0) <= bound),
                    "detail": f"{g43['status']}, max |H - H0| = {g43['max_H_error']:.2e}, "
                              f"max component {g43['max_parasitic']:.2e}"})
    free = [r for r in rows if r["mu"] and all(complex(m) == 0 for m in r["mu"])]
    if free:
        bad = [r for r in free if r["status"] != "completed"
               or (r["max_parasitic"] or 0) > (monitor_of.get(r["scene"]) or float("inf"))]
        worst = max(free, key=lambda r: r["max_parasitic"] or 0)
        out.append({"claim": "every parasitism-free GLM (all μ = 0) completes every scene, with and without "
                             "projection, its parasitic components below the monitor bound",
                    "holds": not bad,
                    "detail": (f"{len(free)} runs of {', '.join(sorted({r['file'] for r in free}))}; largest "
                               f"component {worst['max_parasitic'] or 0:.2e} ({worst['file']}, {worst['problem']})")
                    if not bad else "; ".join(f"{r['file']} on {r['scene']}: {r['status']}" for r in bad)})
    return out


def _status(r) -> str:
    return "completed" if r["status"] == "completed" else f"{r['status']} at t = {r['t_end']:.6g}"


def _num(x) -> str:
    return "—" if x is None else f"{x:.2e}"


def format_table(rows) -> str:
    """The summary table in Markdown: one line per run."""
    lines = ["| problem | method | projection | status | max \\|H − H₀\\| | max parasitic | log-growth "
             "measured / predicted | seconds |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        g = r["growth"]
        growth = "—" if not g else f"{g['measured']:.3g} / {g['predicted']:.3g}"
        lines.append(f"| {r['scene'].removeprefix('suite_')} | {r['file']} | {', '.join(r['projection']) or '—'} | "
                     f"{_status(r)} | {_num(r['max_H_error'])} | {_num(r['max_parasitic'])} | {growth} | "
                     f"{r['seconds']:.1f} |")
    return "\n".join(lines)


def _markdown(summary) -> str:
    claims = "\n".join(f"- {'holds' if c['holds'] else 'FAILS'}: {c['claim']} ({c['detail']})"
                       for c in summary["claims"])
    scenes = "\n".join(f"- `{s['name']}`: {s['title']}; h = {s['h']}, {s['steps']} steps, monitor bound "
                       f"{s['monitor']}" for s in summary["scenes"])
    return (f"# Hard-case suite\n\nWall time {summary['wall_seconds']:.0f} s with {summary['workers']} workers "
            f"({summary['runs']} runs; tableau-lab {summary['tableau_lab']}).\n\n{scenes}\n\n"
            f"{format_table(summary['rows'])}\n\nStatus \"stopped\": the parasitism monitor's bound was exceeded "
            "(checked at the records); \"failed\": the integrator could not continue. Log-growth: natural log of the "
            "parasitic component from its first nonzero record to where it reaches 1e-2 (or the end), against "
            "∫ max Re eig(μ f′(y)) dt over the same span.\n\n## Claims\n\n" + claims + "\n")


def run_suite(suite_dir="reports/suite", out=None, steps=None, scheduler=None, workers=None, only=None,
              progress=None) -> dict:
    """Run the suite (module docstring); returns the summary (also written to OUT)."""
    from .. import __version__
    from .figure_style import pyplot
    scenes = load_suite(suite_dir, steps, only)
    out = Path(out or suite_dir)
    from ..files import refuse_outputs
    from .scene import guard_scene_outputs
    for sc in scenes:                # before any run: no output over an input
        guard_scene_outputs(sc, out / sc.name)
    refuse_outputs([out / name for name in SUMMARY_FILES], [sc.path for sc in scenes])
    items = [(str(sc.path), i, steps) for sc in scenes for i in range(len(sc.runs))]
    cost = {sc.path: _COST.get(sc.problem.name, 1.0) * sc.steps for sc in scenes}
    order = sorted(range(len(items)), key=lambda k: -cost[Path(items[k][0])])
    t0 = time.perf_counter()
    results, metas = {}, {}

    def write(sc):                   # a scene's data and plots, the energy plot in the same set
        res = [results.get((str(sc.path), i, steps)) for i in range(len(sc.runs))]
        metas[sc.name] = write_outputs(sc, res, out / sc.name, also=lambda folder: [
            draw_suite_energy(pyplot(), sc, [r for r in res if r is not None], folder)])

    def finished(k, res):
        results[items[order[k]]] = res
        sc = next(sc for sc in scenes if str(sc.path) == items[order[k]][0])
        if all((str(sc.path), i, steps) in results for i in range(len(sc.runs))):
            write(sc)
        if res[2]:                   # a run in this process, stopped by Ctrl-C
            raise KeyboardInterrupt

    try:
        with executor(scheduler, workers, progress=progress) as ex:
            ex.map(suite_task, [items[k] for k in order], desc="suite",
                   describe=lambda it: f"{Path(it[0]).stem} run {it[1]}", on_result=finished)
            n_workers = ex.workers
    except KeyboardInterrupt:        # the scenes with finished runs, as incomplete sets
        for sc in scenes:
            if sc.name not in metas and any((str(sc.path), i, steps) in results for i in range(len(sc.runs))):
                write(sc)
        raise
    wall = time.perf_counter() - t0
    rows, scene_info = [], []
    for sc in scenes:
        res = [results[(str(sc.path), i, steps)] for i in range(len(sc.runs))]
        meta = metas[sc.name]
        rows += [_row(sc, m, a) for a, m, _ in res]
        scene_info.append({"name": sc.name, "title": sc.title, "problem": sc.problem.name, "h": str(sc.h),
                           "steps": sc.steps, "monitor": sc.monitor, "plots": meta["plots"]})
    summary = {"tableau_lab": __version__, "wall_seconds": round(wall, 1), "workers": n_workers, "runs": len(rows),
               "steps": steps, "scenes": scene_info, "rows": rows,
               "claims": _claims(rows, {sc.name: sc.monitor for sc in scenes})}
    with output_phase(out):          # the summary's files: one set, under the folder's lock
        summary_json, summary_md = (out / name for name in SUMMARY_FILES)
        atomic_write_text(summary_json, json.dumps(summary, indent=1, ensure_ascii=False))
        atomic_write_text(summary_md, _markdown(summary))
        summary["plots"] = draw_suite_maps(pyplot(), rows, scenes, out)
    return summary


def draw_suite_energy(plt, sc, results, out) -> str:
    """|H − H₀| against t (log–log), one panel per method: without projection solid, with
    projection dashed; a run that stopped or failed ends in a cross; a panel whose two curves
    coincide says so in its title.  ``results``: ``run_one``'s triples (arrays, meta entry,
    interrupted).  Returns the file name, ``<scene>_energy.png`` in ``out``; the suite draws it
    after its runs, ``tableau-lab replot`` again from the saved data (experiments/replot.py)."""
    from . import figure_style as style
    stems = list(dict.fromkeys(Path(m["file"]).stem for _, m, _ in results))
    cols = min(style.GRID_COLUMNS, len(stems))
    rows = -(-len(stems) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(style.PRINT_WIDTH, style.SMALL_PANEL_HEIGHT * rows + 0.9),
                             squeeze=False, sharex=True, sharey=True)
    kinds = {False: ("without projection", {**style.series_style(0), "linestyle": "-"}),
             True: ("with projection", {**style.series_style(1), "linestyle": "--"})}
    for ax, stem in zip(axes.flat, stems, strict=False):
        for arrays, meta, _ in results:
            if Path(meta["file"]).stem != stem or "H" not in arrays or len(arrays["t"]) < 2:
                continue
            t, e = arrays["t"][1:], np.maximum(np.abs(arrays["H"][1:]), 1e-17)
            label, s = kinds[bool(meta["projection"])]
            ax.loglog(t, e, lw=0.7, label=label, **s)
            if meta["status"] != "completed":
                ax.plot(t[-1:], e[-1:], color=s["color"], marker="x", linestyle="None", ms=7, mew=1.5)
        same = style.mark_coinciding(ax, relabel=False)
        note = "" if not same else " (the two coincide)" if same[0][2] == 1 else " (the two mostly coincide)"
        ax.set_title(style.plain(stem) + note, fontsize=style.SMALL_FONT)
    for ax in axes.flat[len(stems):]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel(style.invariant_error("H"))
    for ax in axes[-1, :]:
        ax.set_xlabel(style.T_LABEL)
    style.legend(axes[0, 0], "below", notes=False, ncols=3,
                 entries=[*kinds.values(), ("stopped or failed", {"color": "0.3", "marker": "x", "linestyle": "None"})])
    style.title(fig, style.plain(sc.title))
    name = f"{sc.name}_energy.png"
    style.save(fig, out / name)
    return name


def draw_suite_maps(plt, rows, scenes, out) -> list:
    """Two heat maps, methods × problems (without | with projection, one above the other): log10
    max |H − H₀|, and the fraction of the span each run got through (stopped and failed runs
    marked), from the summary's rows; ``scenes`` give the columns (their ``name``).  Returns the
    file names written in ``out``; drawn by the suite and by ``tableau-lab replot`` from
    summary.json (experiments/replot.py)."""
    from . import figure_style as style
    names = [sc.name for sc in scenes]
    methods = list(dict.fromkeys(r["file"] for r in rows))
    files = []
    for kind in ("energy", "time_to_failure"):
        fig, axes = plt.subplots(2, 1, figsize=(style.PRINT_WIDTH, 1.6 + 0.5 * len(methods)), squeeze=False,
                                 sharex=True)
        for row, proj in enumerate((False, True)):
            ax = axes[row, 0]
            M = np.full((len(methods), len(names)), np.nan)
            for r in rows:
                if bool(r["projection"]) != proj:
                    continue
                i, j = methods.index(r["file"]), names.index(r["scene"])
                if kind == "energy":
                    M[i, j] = np.log10(max(r["max_H_error"], 1e-17)) if r["max_H_error"] is not None else np.nan
                    text = "" if r["max_H_error"] is None else f"{r['max_H_error']:.0e}" + (
                        "" if r["status"] == "completed" else f" {r['status'][0]}")
                else:
                    M[i, j] = r["t_end"] / r["T"] if r["T"] else np.nan
                    text = "" if r["status"] == "completed" else f"{r['status'][0]} {r['t_end']:.3g}"
                if not np.isfinite(M[i, j]):
                    continue
                dark = M[i, j] > -6 if kind == "energy" else M[i, j] < 0.25
                ax.text(j, i, text, ha="center", va="center", fontsize=style.SMALL_FONT - 1,
                        color="white" if dark else "black")
            im = ax.imshow(M, aspect="auto", cmap="viridis_r" if kind == "energy" else "RdYlGn",
                           vmin=(-16 if kind == "energy" else 0), vmax=1)
            ax.grid(False)
            ax.set_xticks(range(len(names)), [n.removeprefix("suite_") for n in names], rotation=20, ha="right")
            ax.set_yticks(range(len(methods)), [style.plain(m) for m in methods])
            ax.set_title("with projection" if proj else "without projection")
        fig.colorbar(im, ax=axes[:, 0].tolist(), shrink=0.8,
                     label=r"$\log_{10}\,\max|H(y_n)-H(y_0)|$ (s, f: until stopped, failed)" if kind == "energy"
                     else "t reached / T (s: stopped, f: failed)")
        name = f"suite_{kind}.png"
        style.save(fig, out / name)
        files.append(name)
    return files


def main_suite(args) -> int:
    """The CLI's ``suite`` command: prints the table (or the summary as JSON); exit 0 when every
    claim holds, 1 when one fails, 2 on bad input."""
    from .executor import SchedulerError
    only = {x.strip() for x in args.only.split(",") if x.strip()} if args.only else None
    try:
        summary = run_suite(args.suite_dir, out=args.out, steps=args.steps, scheduler=args.scheduler,
                            workers=args.workers, only=only)
    except (SceneError, SchedulerError, ValueError) as exc:
        print(f"tableau-lab: error: {exc}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(summary, ensure_ascii=False))
    else:
        print(format_table(summary["rows"]))
        for c in summary["claims"]:
            print(f"{'holds' if c['holds'] else 'FAILS'}: {c['claim']} ({c['detail']})")
        print(f"wall time {summary['wall_seconds']:.1f} s, {summary['workers']} workers; "
              f"wrote {Path(args.out or args.suite_dir) / 'summary.md'}")
    return 0 if all(c["holds"] for c in summary["claims"]) else 1
