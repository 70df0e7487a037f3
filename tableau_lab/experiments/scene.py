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
(``"gauss2"``) or a family with its size (``"gauss:3"``, ``"bdf:4"``) (:func:`method_file`).  Numbers are exact strings ("1/100", "0.03") or
integers.  ``tableau-lab run SCENE...`` writes ``reports/<name>/data.npz`` (times, invariant
errors, states, the parasitic component of GLM inputs) with ``meta.json`` beside it (scene,
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
import math
import re
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import sympy as sp

from .. import __version__
from ..budget import DEFAULT_SECONDS, computing, time_limit
from ..errors import InputError
from ..files import atomic_write, atomic_write_text
from ..inputs import MAX_STEPS, NAME_LENGTH, SAFE_NAME, printable, read_json
from .progress import StepBar

__all__ = ["SceneError", "load_scene", "run_scene", "run_one", "write_outputs", "Scene", "method_file", "method_label",
           "scene_doc", "draw_modified_energy", "SCHEMA", "RUN_SCHEMA", "PLOT_SCHEMA", "Key"]

FORMAT = "tableau_lab/scene/1"
MAX_MODIFIED_TERMS = 3      # nonzero corrections of H̃ (each costs a tree order or two of exact algebra)
STARTS = ("exact", "naive")
NAME = SAFE_NAME                     # the output folder's name (inputs.py)
PRECISION = re.compile(r"float64|dd|mp:[0-9]{1,5}")
MAX_RUNS = 100              # runs of one scene
MAX_LIST = 1000             # entries of problem.set and of one value there
MAX_TEXT = 1000             # characters of a title, seed, label or method path
MAX_NOTES = 20000           # characters of the notes


@dataclass(frozen=True)
class Key:
    """One key of the scene format: its name, what it takes, its default ("required" when it has
    none) and what it does.  The tables below are the one schema: the validator's sets of
    allowed keys come from them, and docs/scenes.md's block is generated from them
    (:func:`scene_doc`)."""
    name: str
    takes: str
    default: str
    what: str


REQUIRED = "required"
#: the keys of a scene file
SCHEMA = (
    Key("format", f'"{FORMAT}"', f'"{FORMAT}"', "the format tag"),
    Key("name", f"1 to {NAME_LENGTH} ASCII letters, digits, `-`, `_`, `.`, starting with a letter or digit",
        REQUIRED, "names the output folder `reports/<name>/` and the figures `<name>_<plot>.png`"),
    Key("title", f"a string (at most {MAX_TEXT} characters)", "the name", "the figures' title"),
    Key("seed", f"a string (at most {MAX_TEXT} characters)", '""', "where the experiment comes from "
        '(e.g. "Figure 3.1"), kept in meta.json'),
    Key("notes", f"a string or a list of strings (at most {MAX_NOTES} characters)", '""',
        "free text for the reader; not used by the runs"),
    Key("problem", 'a built-in problem\'s name, `{"name": ..., "set": {...}}` (parameters or initial values '
        'replaced, exact numbers) or `{"define": {...}}` (a problem of your own, below)', REQUIRED,
        "the problem every run integrates"),
    Key("h", 'an exact positive number: an integer or a string such as "1/100" or "1e-3"', REQUIRED,
        "the step size"),
    Key("steps", f"an integer from 1 to {MAX_STEPS}", "give exactly one of steps and T", "the number of steps"),
    Key("T", "an exact positive number with T/h a whole number", "give exactly one of steps and T",
        "the final time"),
    Key("runs", f"a list of 1 to {MAX_RUNS} run objects (below)", REQUIRED, "the runs, one method each"),
    Key("record_every", "an integer from 1 to steps", "max(1, steps // 1000)",
        "the records' stride (time, invariant errors, states, parasitic components)"),
    Key("plots", "a list of distinct plot names (below)", '["invariants"] (["state"] for a problem without '
        'invariants)', "the figures drawn"),
    Key("precision", "float64, dd or mp:DIGITS (5 ≤ DIGITS ≤ 10000)", "float64",
        "the runs' working precision (a run may set its own)"),
    Key("start", ", ".join(STARTS), "exact", "GLM starting values: the starting method's series, or u·y0 "
        "(a run may set its own)"),
    Key("monitor", 'an exact positive number such as "1e-3"', "none (recorded, not bounded)",
        "a bound on the parasitic components of GLM inputs: a run exceeding it stops, status \"stopped\""),
    Key("modified_energy", f'`{{"terms": N}}`, N from 1 to {MAX_MODIFIED_TERMS} (default 2)',
        "none", "adds `<name>_modified_energy.png`: |H − H₀| beside |H̃ − H̃₀| (Hamiltonian problems)"),
)
#: the keys of one entry of "runs"
RUN_SCHEMA = (
    Key("method", f"a tableau file (relative to the scene file), a library name such as \"gauss2\" or a "
        f"family with its size such as \"gauss:3\" (at most {MAX_TEXT} characters)", REQUIRED, "the method"),
    Key("project", "a list of distinct invariant names of the problem", "[]",
        "projection onto these invariants after every step"),
    Key("precision", "as the scene's", "the scene's", "this run's working precision"),
    Key("start", "as the scene's", "the scene's", "this run's GLM starting values"),
    Key("label", f"a string (at most {MAX_TEXT} characters)", "the method's file stem or name "
        "(+ the projection)", "the run's name in the figures and meta.json"),
)
#: the keys of "modified_energy"
MODIFIED_ENERGY_SCHEMA = (
    Key("terms", f"an integer from 1 to {MAX_MODIFIED_TERMS}", "2", "the lowest nonzero corrections of H̃ kept"),
)
#: the plots a scene can ask for
PLOT_SCHEMA = {
    "invariants": "I(y_n) − I(y0) against t, one panel per invariant of the problem",
    "orbit": "the orbit (q1, q2) of a Hamiltonian problem with two or more coordinates; otherwise as \"state\"",
    "parasitic": "GLMs: the parasitic components of the input vector (and their predicted growth) against t",
    "state": "the phase plot (first coordinate, its momentum), or the first two variables; one variable "
             "against t",
}
PLOTS = tuple(PLOT_SCHEMA)
KEYS = frozenset(k.name for k in SCHEMA)
RUN_KEYS = frozenset(k.name for k in RUN_SCHEMA)
MODIFIED_ENERGY_KEYS = frozenset(k.name for k in MODIFIED_ENERGY_SCHEMA)


def scene_doc() -> str:
    """The scene format as Markdown, generated from the schema (:data:`SCHEMA`, :data:`RUN_SCHEMA`,
    :data:`MODIFIED_ENERGY_SCHEMA`, :data:`PLOT_SCHEMA` and the user-problem keys
    :data:`~tableau_lab.numeric.problems.DEFINE_KEYS`): docs/scenes.md's block
    (``python benchmarks/scene_doc.py --write docs/scenes.md``; a test checks it is current).

    >>> print(scene_doc().splitlines()[2])
    | key | takes | default | what it does |
    """
    from ..numeric.expressions import FUNCTIONS
    from ..numeric.problems import DEFINE_KEYS

    def cell(text):
        return str(text).replace("|", "\\|")

    def table(keys):
        rows = ["| key | takes | default | what it does |", "| --- | --- | --- | --- |"]
        rows += [f"| `{k.name}` | {cell(k.takes)} | {cell(k.default)} | {cell(k.what)} |" for k in keys]
        return rows

    out = ["### Keys of a scene file", ""] + table(SCHEMA)
    out += ["", "### Keys of a run (an entry of `runs`)", ""] + table(RUN_SCHEMA)
    out += ["", "### Keys of `modified_energy`", ""] + table(MODIFIED_ENERGY_SCHEMA)
    out += ["", "### Plots (the names `plots` takes)", "", "| plot | what it draws |", "| --- | --- |"]
    out += [f"| `{k}` | {cell(v)} |" for k, v in PLOT_SCHEMA.items()]
    from ..numeric.problems import PROBLEMS
    out += ["", '### Built-in problems (`"problem": NAME` or `{"name": NAME, "set": {...}}`)', "",
            "| name | kind | what `set` may replace |", "| --- | --- | --- |"]
    for name, P in PROBLEMS.items():
        settable = [*P.parameters, *(("q0", "p0") if P.kind == "hamiltonian" else ("y0",))]
        out.append(f"| `{name}` | {P.kind} | {', '.join(f'`{k}`' for k in settable)} |")
    out += ["", '### A problem of your own: `"problem": {"define": {...}}`', "",
            "A Hamiltonian problem has `H`; any other is given by `f`. Every expression and number is text read by "
            "the safe grammar (never evaluated as code): exact decimals (`0.005` is 1/200), integers, + − * / ^ "
            "(`-2^2` is −4), parentheses, the declared names and the functions "
            + ", ".join(f"`{f}`" for f in FUNCTIONS) + ".", "",
            "| key | kind | required | takes | what it is |", "| --- | --- | --- | --- | --- |"]
    out += [f"| `{k}` | {' and '.join(kinds)} | {'yes' if required else 'no'} | {cell(takes)} | {cell(what)} |"
            for k, (kinds, required, takes, what) in DEFINE_KEYS.items()]
    return "\n".join(out)


class SceneError(InputError):
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
    modified_energy: int | None = None   # terms of H̃ to plot beside H (None: no modified-energy plot)


def scene_number(v, where, path):
    """An exact number from an integer or an ASCII string ("1/100", "1e-3", "sqrt(2)/2")."""
    from ..exact.grammar import EntryError, parse_number
    if isinstance(v, bool) or not isinstance(v, (int, str)):
        raise SceneError(f"{printable(path)}: {where}: write numbers as integers or exact strings such as \"1/100\", "
                         f"not {shown(v)}")
    if isinstance(v, str) and not v.isascii():
        raise SceneError(f"{printable(path)}: {where}: {shown(v)}: a number is written with ASCII digits only")
    try:
        return parse_number(str(v))
    except EntryError as exc:
        raise SceneError(f"{printable(path)}: {where}: {exc}") from None


def shown(v, width=60) -> str:
    """A JSON value, shortened, for a message."""
    try:
        text = printable(json.dumps(v))
    except (TypeError, ValueError):
        text = printable(repr(v))
    return text if len(text) <= width else text[:width - 3] + "..."


def _positive(v) -> bool:
    try:
        return bool(v > 0)
    except TypeError:                       # not a real number
        return False


def float64_number(v, where, src) -> float:
    """``v`` in float64, refused if it rounds to 0 or overflows."""
    try:
        x = float(v)
    except (TypeError, ValueError, OverflowError):
        x = math.inf
    if x == 0 or not math.isfinite(x):
        raise SceneError(f"{src}: {where}: rounds to {x} in float64 (the working precision of times and records); "
                         f"use a value between {sys.float_info.min:.3g} and {sys.float_info.max:.3g}")
    return x


def read_scene(path):
    """The JSON object of a scene file, read strictly (:func:`tableau_lab.inputs.read_json`)."""
    data = read_json(path, SceneError, "scene file")
    if not isinstance(data, dict):
        raise SceneError(f"{printable(path)}: a scene is one JSON object")
    return data


def scene_problem(prob, path):
    """The problem of a scene: a name, {"name": ..., "set": {...}} or {"define": {...}}."""
    from ..numeric.problems import ProblemError, get_problem, problem_from_dict
    src = printable(path)
    shape = f"{src}: problem must be a name, {{\"name\": ..., \"set\": {{...}}}} or {{\"define\": {{...}}}}"
    try:
        if isinstance(prob, str):
            problem = get_problem(prob)
        elif isinstance(prob, dict) and "define" in prob:
            if set(prob) != {"define"} or not isinstance(prob["define"], dict):
                raise SceneError(shape + ": \"define\" is an object, alone")
            problem = problem_from_dict(prob["define"])
        elif isinstance(prob, dict) and isinstance(prob.get("name"), str):
            if set(prob) - {"name", "set"}:
                raise SceneError(f"{shape}: unknown keys {sorted(set(prob) - {'name', 'set'})}")
            sets = prob.get("set", {})
            if not isinstance(sets, dict) or len(sets) > MAX_LIST:
                raise SceneError(f"{src}: problem.set must be an object such as {{\"e\": \"0.6\"}}")
            over = {}
            for k, v in sets.items():
                where = f"problem.set.{k}"
                if isinstance(v, list) and not 0 < len(v) <= MAX_LIST:
                    raise SceneError(f"{src}: {where}: a list of 1 to {MAX_LIST} exact numbers is needed")
                over[k] = tuple(scene_number(x, f"{where}[{i}]", path) for i, x in enumerate(v, 1)) if isinstance(v, list) \
                    else scene_number(v, where, path)
            problem = get_problem(prob["name"], **over)
        else:
            raise SceneError(shape)
    except ProblemError as exc:
        raise SceneError(f"{src}: problem: {printable(exc)}") from None
    return problem


def method_file(scene, name, where):
    """The method a scene names: a file relative to the scene file (resolved, a Path); else a
    shipped method by name ("gauss2": its library file, a Path); else a family with its size
    ("gauss:3", "bdf:4": the name itself, a str, checked by building it).  SceneError naming
    ``where`` when it is none of them.

    >>> method_file("reports/scenes/x.json", "gauss2", "runs[1].method").name
    'gauss2.json'
    >>> method_file("reports/scenes/x.json", "bdf:4", "runs[1].method")
    'bdf:4'
    >>> method_file("reports/scenes/x.json", "gauss:9", "runs[1].method")
    Traceback (most recent call last):
    ...
    tableau_lab.experiments.scene.SceneError: reports/scenes/x.json: runs[1].method: gauss:9: the number of stages must be an integer 1 … 8, not 9
    """
    from ..exact.library import FamilyError, family, is_family, library_path
    try:
        found = (Path(scene).parent / name).resolve()
        if found.exists():
            return found
    except (OSError, RuntimeError, ValueError):
        pass
    if library_path(name) is not None:
        return library_path(name)
    if is_family(name):
        try:
            family(name)
        except FamilyError as exc:
            raise SceneError(f"{printable(scene)}: {where}: {printable(exc)}") from None
        return name
    raise SceneError(f"{printable(scene)}: {where}: no file {printable(name)} (relative to the scene file), "
                     "library method or family (tableau-lab list)")


def method_label(method) -> str:
    """The default label of a method :func:`method_file` gave: a file's stem, a family's name."""
    return method.stem if isinstance(method, Path) else str(method)


def scene_text(d, key, where, src, default="", limit=MAX_TEXT) -> str:
    """A string value (at most ``limit`` characters); ``notes`` may be a list of strings."""
    v = d.get(key, default)
    parts = v if key == "notes" and isinstance(v, list) else [v]
    if not all(isinstance(x, str) for x in parts) or sum(len(x) for x in parts) > limit:
        raise SceneError(f"{src}: {where}: a string of at most {limit} characters is needed, not {shown(v)}")
    return v


def _choice(d, key, where, src, default, allowed):
    v = d.get(key, default)
    if not isinstance(v, str) or v not in allowed:
        raise SceneError(f"{src}: {where}: {shown(v)} is not one of {', '.join(allowed)}")
    return v


def _precision(d, where, src, default):
    """float64, dd or mp:DIGITS (ASCII digits, within arith's range)."""
    from ..numeric.arith import arith
    prec = d.get("precision", default)
    ok = isinstance(prec, str) and PRECISION.fullmatch(prec)
    try:
        if ok:
            arith(prec)
    except ValueError:
        ok = False
    if not ok:
        raise SceneError(f"{src}: {where}: {shown(prec)} is not a precision: use float64, dd or mp:DIGITS with "
                         f"5 <= DIGITS <= 10000 (e.g. mp:32)")
    return prec


def _count(v, where, src, low, high):
    if isinstance(v, bool) or not isinstance(v, int) or not low <= v <= high:
        raise SceneError(f"{src}: {where} must be an integer between {low} and {high}, not {shown(v)}")
    return v


def load_scene(path, timeout: float | None = DEFAULT_SECONDS) -> Scene:
    """Read and validate a scene file: every key's type and range, the problem built (within
    the time budget ``timeout``, as the exact commands': a user-defined problem can be costly),
    the method files read as JSON (nothing run).  Messages name the file and the key."""
    from ..exact.tableau_json import TableauError, read
    from ..numeric.problems import ProblemError
    path = Path(path)
    src = printable(path)
    data = read_scene(path)
    unknown = set(data) - KEYS
    if unknown:
        raise SceneError(f"{src}: unknown keys {sorted(unknown)} (allowed: {sorted(KEYS)})")
    if data.get("format", FORMAT) != FORMAT:
        raise SceneError(f"{src}: format: {shown(data.get('format'))} is not {FORMAT!r}")
    name = data.get("name")
    if not isinstance(name, str) or not NAME.fullmatch(name):
        raise SceneError(f"{src}: name: {shown(name)} is not a file-name-safe name: 1 to {NAME_LENGTH} ASCII letters, "
                         f"digits, - _ . starting with a letter or digit (it names the output folder)")
    title = scene_text(data, "title", "title", src, name)
    seed = scene_text(data, "seed", "seed", src)
    scene_text(data, "notes", "notes", src, limit=MAX_NOTES)
    if "h" not in data:
        raise SceneError(f"{src}: h: missing; give the step size as an exact number such as \"1/100\"")
    h = scene_number(data["h"], "h", path)
    if not _positive(h):
        raise SceneError(f"{src}: h must be a positive exact number, got {shown(data['h'])}")
    float64_number(h, "h", src)
    if ("steps" in data) == ("T" in data):
        raise SceneError(f"{src}: give exactly one of steps and T")
    if "steps" in data:
        steps = _count(data["steps"], "steps", src, 1, MAX_STEPS)
    else:
        T = scene_number(data["T"], "T", path)
        if not _positive(T):
            raise SceneError(f"{src}: T must be a positive exact number, got {shown(data['T'])}")
        n = T / h
        if not n.is_Integer:
            raise SceneError(f"{src}: T: T / h = {shown(data['T'])} / {shown(data['h'])} is not a whole number of steps")
        if n > MAX_STEPS:
            raise SceneError(f"{src}: T: T / h = {shown(data['T'])} / {shown(data['h'])} is more than the limit "
                             f"of {MAX_STEPS} steps (MAX_STEPS)")
        steps = int(n)
    every = _count(data.get("record_every", max(1, steps // 1000)), "record_every", src, 1, steps)
    plots = data.get("plots", ["invariants"])
    if not isinstance(plots, list) or not all(isinstance(p, str) for p in plots) or len(set(plots)) != len(plots):
        raise SceneError(f"{src}: plots: a list of distinct names ({', '.join(PLOTS)}) is needed, not {shown(plots)}")
    bad = [p for p in plots if p not in PLOTS]
    if bad:
        raise SceneError(f"{src}: plots: unknown plots {[printable(p) for p in bad]} (known: {', '.join(PLOTS)})")
    monitor = None
    if "monitor" in data:
        bound = scene_number(data["monitor"], "monitor", path)
        if not _positive(bound):
            raise SceneError(f"{src}: monitor must be a positive bound such as \"1e-3\", got {shown(data['monitor'])}")
        monitor = float64_number(bound, "monitor", src)
    modified = None
    if "modified_energy" in data:
        me = data["modified_energy"]
        if not isinstance(me, dict):
            raise SceneError(f"{src}: modified_energy must be an object such as {{\"terms\": 2}}, not {shown(me)}")
        extra = sorted(set(me) - MODIFIED_ENERGY_KEYS)
        if extra:
            raise SceneError(f"{src}: modified_energy: unknown keys {[printable(k) for k in extra]} "
                             f"(allowed: {sorted(MODIFIED_ENERGY_KEYS)})")
        modified = _count(me.get("terms", 2), "modified_energy.terms", src, 1, MAX_MODIFIED_TERMS)
    precision = _precision(data, "precision", src, "float64")
    start = _choice(data, "start", "start", src, "exact", STARTS)
    runs = data.get("runs")
    if not isinstance(runs, list) or not 0 < len(runs) <= MAX_RUNS:
        raise SceneError(f"{src}: runs must be a non-empty list of at most {MAX_RUNS} "
                         f"{{\"method\": FILE, ...}}, not {shown(runs)}")
    for i, r in enumerate(runs):
        where = f"runs[{i + 1}]"
        if not isinstance(r, dict) or "method" not in r:
            raise SceneError(f"{src}: {where} must be an object with method and optional {sorted(RUN_KEYS - {'method'})}")
        if set(r) - RUN_KEYS:
            raise SceneError(f"{src}: {where}: unknown keys {sorted(set(r) - RUN_KEYS)} (allowed: {sorted(RUN_KEYS)})")
        if not isinstance(r["method"], str) or not 0 < len(r["method"]) <= MAX_TEXT:
            raise SceneError(f"{src}: {where}.method: a file name (a string) is needed, not {shown(r['method'])}")
        project = r.get("project", [])
        if not isinstance(project, list) or not all(isinstance(k, str) for k in project) \
                or len(set(project)) != len(project):
            raise SceneError(f"{src}: {where}.project: a list of distinct invariant names is needed, not {shown(project)}")
        _precision(r, f"{where}.precision", src, precision)
        _choice(r, "start", f"{where}.start", src, start, STARTS)
        scene_text(r, "label", f"{where}.label", src)
    with time_limit(timeout), computing(f"the problem of {src}"):
        problem = scene_problem(data.get("problem"), path)
    if modified is not None and problem.kind != "hamiltonian":
        raise SceneError(f"{src}: modified_energy: the problem {printable(problem.name)} is not Hamiltonian "
                         f"(a modified energy needs H(q, p))")
    if "plots" not in data and not problem.invariants:
        plots = ["state"]                          # nothing to draw against time but the state
    if "invariants" in plots and not problem.invariants:
        raise SceneError(f"{src}: plots: the problem {printable(problem.name)} has no invariants to plot "
                         f"(declare some under problem.define.invariants, or drop \"invariants\")")
    out_runs, read_methods = [], {}
    for i, r in enumerate(runs):
        where = f"runs[{i + 1}]"
        mpath = method_file(path, r["method"], f"{where}.method")
        if mpath not in read_methods and isinstance(mpath, Path):
            try:
                read_methods[mpath] = read(mpath)          # a regular file of strict JSON, or refused now
            except TableauError as exc:
                raise SceneError(f"{src}: {where}.method: {exc}") from None
        project = r.get("project", [])
        bad = [k for k in project if k not in problem.invariants]
        if bad:
            raise SceneError(f"{src}: {where}.project: {[printable(k) for k in bad]} are not invariants of "
                             f"{problem.name} ({', '.join(problem.invariants)})")
        try:
            problem.check_projection(project)
        except ProblemError as exc:
            raise SceneError(f"{src}: {where}.project: {printable(exc)}") from None
        out_runs.append({"method": mpath, "as_written": r["method"], "project": tuple(project),
                         "precision": r.get("precision", precision), "start": r.get("start", start),
                         "label": r.get("label") or method_label(mpath) + (f" + projection onto {', '.join(project)}"
                                                                  if project else "")})
    return Scene(path, name, title, seed, problem, h, steps, tuple(out_runs), every, tuple(plots), data, monitor,
                 modified)


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
                            monitor=sc.monitor)
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
            "seconds": round(run.seconds, 3), "max_invariant_error": run.max_invariant_error(),
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
        except Exception as exc:                   # noqa: BLE001 - an optional plot never stops the scene
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
    except Exception as exc:                       # noqa: BLE001 - e.g. a derivative numpy cannot evaluate
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
