r"""Redraw figures from the data a run saved, without running anything again.

    tableau-lab replot PATH...

A figure is drawn from data that its command writes anyway; ``replot(PATH)`` draws it again
from them (in the current style: :mod:`~tableau_lab.experiments.figure_style`, PNG, PDF and
SVG), never integrating or computing a reference:

* a **scene folder** (``tableau-lab run``, and the scenes of ``tableau-lab suite``): ``meta.json``
  and ``data.npz`` (or their ``.incomplete`` pair) and the scene file named in ``meta.json``
  (read, not run: its plots, title, problem); the plots of the scene, the modified-energy figure
  when the run had one, and the suite's per-scene energy figure when the folder has one;
* a **work–precision folder** (``tableau-lab workprecision``): ``data.json``;
* a **convergence** or **round-off** data file (``tableau-lab convergence`` / ``roundoff``): the
  JSON written beside the figure (``NAME.json`` → ``NAME.png``);
* the **suite summary** (``SUITE_DIR/summary.json``): ``suite_energy`` and
  ``suite_time_to_failure``.

Any other folder is searched for these (its subfolders too).  Each folder's figures are written
as one set under its lock (:func:`tableau_lab.files.output_phase`), inside that folder only (a
name read from the data is one file name: :func:`tableau_lab.files.output_name`); the data files
are read, never written.  Every file read back is bounded (JSON: ``inputs.MAX_JSON_BYTES``;
``data.npz``: :func:`tableau_lab.files.load_npz`) and checked against the schema its writer
follows (:data:`SCHEMAS`) before anything is drawn: a damaged or edited file is a
:class:`ReplotError` naming the file and the key (exit 2), as is a path holding nothing to draw.
Figures for which nothing was saved to draw from (the benchmark scripts' figures,
whose curves their ``numbers.json`` does not keep) are left as they are and named by
:func:`main_replot`.
"""
from __future__ import annotations

import dataclasses
import sys
from functools import partial
from pathlib import Path
from types import SimpleNamespace

from ..errors import EXIT_INPUT, EXIT_OK, InputError
from ..files import load_npz, output_name, output_phase
from ..inputs import ListOf, MapOf, check_schema, printable, read_json

__all__ = ["replot", "ReplotError", "main_replot", "kind_of", "SCHEMAS", "MAX_SERIES", "MAX_POINTS"]

MAX_SERIES = 100         # series (methods, peers, runs, rows) of one saved figure's data that replot draws
MAX_POINTS = 10 ** 5     # points of one series (a convergence sweep, a round-off record)


class ReplotError(InputError):
    """A path that holds no saved output replot can draw from (the message names it and why)."""


_NUM, _NUMS = float, ListOf(float, MAX_POINTS)
_OPT = (float, type(None))
# what each writer saves and the drawing reads (workprecision.run_wp, runs.Convergence.to_json,
# cli._roundoff, suite.run_suite, scene.write_outputs)
SCHEMAS = {
    "workprecision": {"name": str, "title": str, "T": _NUM, "invariant": str, "reference_error_bound": _NUM,
                      "series": MapOf(ListOf(({"cpu": _NUM, "nfev": _NUM, "error": _NUM, "invariant_error": _NUM},
                                              {"failed": str}), MAX_POINTS), MAX_SERIES)},
    "convergence": ListOf({"method": str, "problem": str, "precision": str, "T": _NUM, "?order": (int, type(None)),
                           "h": _NUMS, "error": ListOf(_OPT, MAX_POINTS), "slope": _OPT}, MAX_SERIES, least=1),
    "roundoff": {"method": str, "problem": str, "h": (str, float), "n": _NUMS, "plain": _NUMS, "compensated": _NUMS,
                 "slope_plain": _NUM, "slope_compensated": _NUM},
    "suite": {"scenes": ListOf({"name": str}, MAX_SERIES, least=1),
              "rows": ListOf({"scene": str, "file": str, "projection": (list, bool, type(None)), "status": str,
                              "max_H_error": _OPT, "t_end": _NUM, "T": _OPT}, MAX_SERIES * MAX_SERIES)},
    "scene": {"scene": str, "name": str, "complete": bool,
              "runs": ListOf({"label": str, "status": str}, MAX_SERIES, least=1)},
}


def _read(path) -> object:
    """A saved data file (strict JSON, but our writers' Infinity and NaN allowed)."""
    return read_json(path, ReplotError, "saved data file", parse_constant=float)


def _checked(path, kind: str):
    """The saved data file ``path`` of ``kind``, checked against its writer's schema."""
    data = _read(path)
    check_schema(data, SCHEMAS[kind], path, ReplotError)
    return data


def _meta_file(folder: Path):
    for suffix in ("", ".incomplete"):
        if (folder / f"meta{suffix}.json").is_file() and (folder / f"data{suffix}.npz").is_file():
            return folder / f"meta{suffix}.json"
    return None


def kind_of(path) -> str | None:
    """What ``path`` is to replot: "scene", "workprecision" (folders), "convergence",
    "roundoff", "suite" (data files), or None."""
    path = Path(path)
    if path.is_dir():
        if _meta_file(path) is not None:
            return "scene"
        if (path / "data.json").is_file():
            data = _read(path / "data.json")
            if isinstance(data, dict) and isinstance(data.get("series"), dict) and "name" in data:
                return "workprecision"
        return None
    if path.suffix != ".json" or not path.is_file():
        return None
    data = _read(path)
    if isinstance(data, list) and data and all(isinstance(c, dict) and {"h", "error", "slope", "method"} <= set(c)
                                               for c in data):
        return "convergence"
    if isinstance(data, dict) and {"n", "plain", "compensated", "method", "problem", "h"} <= set(data):
        return "roundoff"
    if isinstance(data, dict) and isinstance(data.get("rows"), list) and isinstance(data.get("scenes"), list):
        return "suite"
    return None


def _named(path: Path) -> str | None:
    """What a path named on the command line is by its name alone, when its content does not say
    (a damaged file: its schema then names what is wrong)."""
    if path.is_dir():
        return "workprecision" if (path / "data.json").is_file() and not (path / "meta.json").exists() else None
    for prefix in ("convergence", "roundoff"):
        if path.name.startswith(prefix + "_") and path.suffix == ".json":
            return prefix
    return "suite" if path.name == "summary.json" else None


def replot(path) -> list:
    """Redraw the figures of ``path`` (module docstring) from its saved data; returns the PNG
    paths written (each with its PDF and SVG).  A folder that is not itself an output is
    searched; a file or folder named directly that holds nothing to draw from is a
    :class:`ReplotError`."""
    path = Path(path)
    if not path.exists():
        raise ReplotError(f"{printable(path)}: no such file or folder")
    kind = kind_of(path) or _named(path)
    if kind is not None:
        return _draw(kind, path)
    if path.is_dir():
        written = []
        for child in sorted(path.iterdir()):
            if child.name.startswith(".") or child.is_symlink():
                continue
            if child.is_dir():
                written += replot(child)
            elif child.suffix == ".json":
                try:
                    kind = kind_of(child)
                except ReplotError:             # a JSON file that is not saved data (searching, not named)
                    continue
                if kind is not None:
                    written += _draw(kind, child)
        return written
    raise ReplotError(f"{printable(path)}: not a saved output replot can draw from (a scene or work–precision "
                      "folder, a convergence or round-off JSON file, a suite's summary.json)")


def _draw(kind: str, path: Path) -> list:
    """``_DRAW[kind](path)``; a saved file that passed its schema and still does not draw (a
    cross-reference that does not hold: a row's scene not among the scenes, arrays of unequal
    length) is a :class:`ReplotError` naming the file, never an internal error."""
    try:
        return _DRAW[kind](path)
    except InputError:
        raise
    except (KeyError, IndexError, TypeError, ValueError, AttributeError, ZeroDivisionError) as exc:
        what = f"the key {exc.args[0]!r} is missing" if isinstance(exc, KeyError) and exc.args else \
            f"{type(exc).__name__}: {printable(str(exc))[:120]}"
        raise ReplotError(f"{printable(path)}: not the {kind} data its command writes ({what})") from None


def _scene_file(name: str, folder: Path) -> Path:
    """The scene file that ``meta.json`` names: as written (absolute, or relative to the working
    folder when the run was made), else relative to a folder above the output folder."""
    given = Path(name)
    candidates = [given] if given.is_absolute() else [given, *(a / given for a in folder.resolve().parents)]
    for c in candidates:
        if c.is_file():
            return c
    raise ReplotError(f"{printable(folder)}: the scene file {printable(name)} named in its metadata is not there")


def _scene(folder: Path) -> list:
    from .plots import draw
    from .scene import draw_modified_energy, load_scene
    meta_path = _meta_file(folder)
    meta = _checked(meta_path, "scene")
    suffix = "" if meta.get("complete") else ".incomplete"
    arrays = load_npz(folder / f"data{suffix}.npz", ReplotError)          # bounded, members checked first
    sc = load_scene(_scene_file(meta["scene"], folder))
    if sc.name != meta.get("name"):
        raise ReplotError(f"{printable(folder)}: its metadata names scene {meta.get('name')!r}, the scene file "
                          f"{printable(sc.path)} is {sc.name!r}")
    names = []
    with output_phase(folder):
        names += draw(sc, meta, arrays, folder)
        me = meta.get("modified_energy")
        if isinstance(me, dict) and any("modified_energy" in r for r in meta["runs"]):
            names.append(draw_modified_energy(dataclasses.replace(sc, modified_energy=me.get("terms", 2)), meta,
                                               arrays, folder, suffix))
        if (folder / f"{sc.name}_energy.png").exists():          # a scene of the hard-case suite
            from .figure_style import pyplot
            from .suite import draw_suite_energy
            runs = [({k.removeprefix(f"run{i}_"): v for k, v in arrays.items() if k.startswith(f"run{i}_")}, r, False)
                    for i, r in enumerate(meta["runs"]) if f"run{i}_t" in arrays]
            names.append(draw_suite_energy(pyplot(), sc, runs, folder))
    return [folder / n for n in names]


def _workprecision(folder: Path) -> list:
    from .plots import draw_workprecision
    data = _checked(folder / "data.json", "workprecision")
    target = folder / f"{output_name(data['name'], folder / 'data.json')}.png"     # one name, in this folder
    with output_phase(folder):
        draw_workprecision(data, target)
    return [target]


def _beside(kind: str, path: Path) -> list:
    """A convergence or round-off figure: NAME.png drawn beside its NAME.json."""
    from . import plots
    draw, title = {"convergence": (plots.draw_convergence, plots.convergence_title),
                   "roundoff": (plots.draw_roundoff, plots.roundoff_title)}[kind]
    data = _checked(path, kind)
    target = path.with_suffix(".png")
    with output_phase(path.parent):
        draw(data, target, title(data))
    return [target]


def _suite(path: Path) -> list:
    from .figure_style import pyplot
    from .suite import draw_suite_maps
    summary = _checked(path, "suite")
    scenes = [SimpleNamespace(name=s["name"]) for s in summary["scenes"]]
    with output_phase(path.parent):
        names = draw_suite_maps(pyplot(), summary["rows"], scenes, path.parent)
    return [path.parent / n for n in names]


_DRAW = {"scene": _scene, "workprecision": _workprecision, "convergence": partial(_beside, "convergence"),
         "roundoff": partial(_beside, "roundoff"), "suite": _suite}


def main_replot(args) -> int:
    """The CLI's ``replot`` command: redraw each PATH, print what was written and, for folders,
    the figures there that had nothing to be drawn from.  Exit 0: done; 2: a path could not be
    read or holds nothing to draw from."""
    from .figure_style import formats
    status = EXIT_OK
    for path in args.paths:
        try:
            written = replot(path)
        except InputError as exc:               # ReplotError, SceneError, … : the message names the file
            print(f"tableau-lab: error: {exc}", file=sys.stderr)
            status = EXIT_INPUT
            continue
        if not written:                          # the help's promise: exit 2 when nothing could be drawn
            print(f"tableau-lab: error: {printable(path)}: holds no saved output replot can draw from (scene or "
                  "work–precision folders, convergence or round-off JSON files, a suite's summary.json)",
                  file=sys.stderr)
            status = EXIT_INPUT
        for png in written:
            print(f"wrote {png} (and {', '.join(png.with_suffix(s).name for s in formats()[1:])})")
        if Path(path).is_dir():
            done = {Path(p).resolve() for p in written}
            for png in sorted(Path(path).rglob("*.png")):
                if png.resolve() not in done:
                    print(f"not redrawn (no saved data to draw it from): {png}")
    return status
