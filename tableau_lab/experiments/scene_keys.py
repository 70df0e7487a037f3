"""The keys of the scene formats, as one declarative table read by one loop.

Each JSON object of a scene file (the scene, an entry of ``runs``, ``modified_energy``) and of a
work–precision scene (the scene, an entry of ``methods``, of ``peers``) has a table of
:class:`Key`: its name, what it takes, its default, what it does (docs/scenes.md's block is
generated from these texts: :func:`scene_doc`), and how it is read: ``read`` checks and
converts a given value, ``value`` gives the default when the key is absent (or marks it
required).  :func:`read_object` is the one loop: unknown keys refused, each key read in table
order (a key may use those above it, and the enclosing object's), every message naming the
file and the key with one-based entries (``runs[2].precision``).

>>> [k.name for k in MODIFIED_ENERGY_SCHEMA]
['terms']
>>> read_object(MODIFIED_ENERGY_SCHEMA, {}, Field("s.json", "modified_energy"))
{'terms': 2}
>>> read_object(MODIFIED_ENERGY_SCHEMA, {"terms": 4}, Field("s.json", "modified_energy"))
Traceback (most recent call last):
...
tableau_lab.experiments.scene_keys.SceneError: s.json: modified_energy.terms must be an integer between 1 and 3, not 4
"""
from __future__ import annotations

import json
import math
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import InputError
from ..inputs import MAX_STEPS, NAME_LENGTH, SAFE_NAME, printable, read_json
from .compiled_peer import PEER as COMPILED_PEER

__all__ = ["Key", "Field", "read_object", "SceneError", "SCHEMA", "RUN_SCHEMA", "MODIFIED_ENERGY_SCHEMA",
           "PLOT_SCHEMA", "WP_SCHEMA", "WP_METHOD_SCHEMA", "WP_PEER_SCHEMA", "scene_doc", "scene_number", "shown",
           "float64_number", "read_scene", "scene_problem", "method_file", "method_label"]

FORMAT = "tableau_lab/scene/1"
WP_FORMAT = "tableau_lab/workprecision/1"
MAX_MODIFIED_TERMS = 3      # nonzero corrections of H̃ (each costs a tree order or two of exact algebra)
STARTS = ("exact", "naive")
NAME = SAFE_NAME                     # the output folder's name (inputs.py)
PRECISION = re.compile(r"float64|dd|mp:[0-9]{1,5}")
MAX_RUNS = 100              # runs of one scene; methods and peers of a work–precision scene
MAX_LIST = 1000             # entries of problem.set and of one value there
MAX_TEXT = 1000             # characters of a title, seed, label or method path
MAX_NOTES = 20000           # characters of the notes
MAX_SWEEP = 100             # step counts of one method, tolerances of one peer (work–precision)
PEERS = ("DOP853", "RK45", "RK23", "Radau", COMPILED_PEER)   # scipy's solve_ivp methods, and DOP853 compiled
# (experiments/compiled_peer.py: numbalsoda, f through a C function pointer: the fair CPU peer)


class SceneError(InputError):
    """A scene that cannot be run: the message names the file and the key."""


REQUIRED = "required"
_REQUIRED = object()            # Key.value of a key without a default


@dataclass(frozen=True)
class Field:
    """Where a value is read: the scene file, the key's place (``"runs[1].label"``, ``""`` for
    the top object), the keys of its object read so far (``got``), the raw object, the enclosing
    object's values (``outer``: a run's scene) and the time budget of the problem's build."""
    path: object
    where: str = ""
    got: dict = field(default_factory=dict)
    raw: dict = field(default_factory=dict)
    outer: dict = field(default_factory=dict)
    timeout: float | None = None

    @property
    def src(self) -> str:
        return printable(self.path)

    def at(self, key: str) -> Field:
        """The field of ``key`` of this object."""
        return replace(self, where=f"{self.where}.{key}" if self.where else key)

    def inside(self, where: str, outer: dict) -> Field:
        """The field of a nested object at ``where`` whose enclosing values are ``outer``."""
        return replace(self, where=where, got={}, raw={}, outer=outer)

    def fail(self, message: str, sep: str = ": "):
        """SceneError ``file: where: message`` (``sep`` " " for ``where must be …``)."""
        raise SceneError(f"{self.src}: {self.where}{sep}{message}" if self.where else f"{self.src}: {message}")


@dataclass(frozen=True)
class Key:
    """One key of a scene format: its name, what it takes, its default ("required" when it has
    none) and what it does (the documentation's texts); ``read(value, field)`` checks and
    converts a given value; ``value`` is its value when absent: a constant, ``_REQUIRED``, or
    ``value(field)`` computed from the keys above it."""
    name: str
    takes: str
    default: str
    what: str
    read: Callable = lambda v, f: v
    value: object = _REQUIRED


def read_object(keys, obj, where: Field) -> dict:
    """The one reader of a scene object: ``obj`` must be a JSON object whose keys are among
    ``keys``; each key, in table order, read by its ``read`` or given its default.  Returns the
    values by key name."""
    names = [k.name for k in keys]
    if not isinstance(obj, dict):
        where.fail(f"must be an object with keys {', '.join(names)}, not {shown(obj)}", " ")
    unknown = sorted(set(obj) - set(names))
    if unknown:
        where.fail(f"unknown keys {[printable(k) for k in unknown]} (allowed: {sorted(names)})")
    got: dict = {}
    for k in keys:
        f = replace(where.at(k.name), got=got, raw=obj)
        if k.name in obj:
            got[k.name] = k.read(obj[k.name], f)
        elif k.value is _REQUIRED:
            f.fail(f"missing (required: {k.takes})")
        else:
            got[k.name] = k.value(f) if callable(k.value) else k.value
    return got


# -- readers of values -------------------------------------------------------------------------

def shown(v, width=60) -> str:
    """A JSON value, shortened, for a message."""
    try:
        text = printable(json.dumps(v))
    except (TypeError, ValueError):
        text = printable(repr(v))
    return text if len(text) <= width else text[:width - 3] + "..."


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


def _positive(v) -> bool:
    try:
        return bool(v.is_real and v > 0)
    except (TypeError, AttributeError):      # not a real number
        return False


def positive_number(v, f: Field, what: str = "exact number"):
    """An exact positive number that float64 holds (a step size, a bound)."""
    x = scene_number(v, f.where, f.path)
    if not _positive(x):
        f.fail(f"must be a positive {what}, got {shown(v)}", " ")
    float64_number(x, f.where, f.src)
    return x


def count(low, high=None) -> Callable:
    """A reader of an integer in [low, high] (``high(field)`` when it depends on other keys)."""
    def read(v, f: Field) -> int:
        top = high(f) if callable(high) else high
        if isinstance(v, bool) or not isinstance(v, int) or not low <= v <= top:
            f.fail(f"must be an integer between {low} and {top}, not {shown(v)}", " ")
        return v
    return read


def text(limit=MAX_TEXT, many=False) -> Callable:
    """A reader of a string of at most ``limit`` characters (``many``: or a list of strings)."""
    def read(v, f: Field) -> str:
        parts = v if many and isinstance(v, list) else [v]
        if not all(isinstance(x, str) for x in parts) or sum(len(x) for x in parts) > limit:
            f.fail(f"a string of at most {limit} characters is needed, not {shown(v)}")
        return v
    return read


def choice(allowed) -> Callable:
    """A reader of one of the strings ``allowed``."""
    def read(v, f: Field) -> str:
        if not isinstance(v, str) or v not in allowed:
            f.fail(f"{shown(v)} is not one of {', '.join(allowed)}")
        return v
    return read


def precision(v, f: Field) -> str:
    """float64, dd or mp:DIGITS (ASCII digits, within arith's range)."""
    from ..numeric.arith import arith
    ok = isinstance(v, str) and PRECISION.fullmatch(v)
    try:
        if ok:
            arith(v)
    except ValueError:
        ok = False
    if not ok:
        f.fail(f"{shown(v)} is not a precision: use float64, dd or mp:DIGITS with 5 <= DIGITS <= 10000 (e.g. mp:32)")
    return v


def distinct_names(what: str) -> Callable:
    """A reader of a list of distinct strings."""
    def read(v, f: Field) -> list:
        if not isinstance(v, list) or not all(isinstance(k, str) for k in v) or len(set(v)) != len(v):
            f.fail(f"a list of distinct {what} is needed, not {shown(v)}")
        return v
    return read


def objects(keys, most: int, what: str, least: int = 0) -> Callable:
    """A reader of a list of ``least`` to ``most`` objects, each read by :func:`read_object`
    with ``keys`` (``where[1]``, ``where[2]``, …)."""
    def read(v, f: Field) -> tuple:
        if not isinstance(v, list) or not least <= len(v) <= most:
            f.fail(f"must be a {'non-empty ' if least else ''}list of at most {most} {what}, not {shown(v)}", " ")
        return tuple(read_object(keys, x, f.inside(f"{f.where}[{i}]", f.got)) for i, x in enumerate(v, 1))
    return read


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
            return get_problem(prob)
        if isinstance(prob, dict) and "define" in prob:
            if set(prob) != {"define"} or not isinstance(prob["define"], dict):
                raise SceneError(shape + ": \"define\" is an object, alone")
            return problem_from_dict(prob["define"])
        if isinstance(prob, dict) and isinstance(prob.get("name"), str):
            if set(prob) - {"name", "set"}:
                raise SceneError(f"{shape}: unknown keys {sorted(set(prob) - {'name', 'set'})}")
            return get_problem(prob["name"], **_problem_set(prob.get("set", {}), path))
        raise SceneError(shape)
    except ProblemError as exc:
        raise SceneError(f"{src}: problem: {printable(exc)}") from None


def _problem_set(sets, path) -> dict:
    """The exact values of ``problem.set``: a number, or a list of them, per name."""
    src = printable(path)
    if not isinstance(sets, dict) or len(sets) > MAX_LIST:
        raise SceneError(f"{src}: problem.set must be an object such as {{\"e\": \"0.6\"}}")
    over = {}
    for k, v in sets.items():
        where = f"problem.set.{k}"
        if isinstance(v, list) and not 0 < len(v) <= MAX_LIST:
            raise SceneError(f"{src}: {where}: a list of 1 to {MAX_LIST} exact numbers is needed")
        over[k] = (tuple(scene_number(x, f"{where}[{i}]", path) for i, x in enumerate(v, 1)) if isinstance(v, list)
                   else scene_number(v, where, path))
    return over


def problem(v, f: Field):
    """The problem, built within the time budget of the exact commands (a user-defined problem
    can be costly)."""
    from ..budget import computing, time_limit
    with time_limit(f.timeout), computing(f"the problem of {f.src}"):
        return scene_problem(v, f.path)


def method_file(scene, name, where):
    """The method a scene names: a file relative to the scene file (resolved, a Path); else a
    shipped method by name ("gauss2": its library file, a Path); else a family with its size
    ("gauss:3", "bdf:4": the name itself, a str, checked by building it).  SceneError naming
    ``where`` when it is none of them.

    >>> method_file("reports/scenes/x.json", "gauss2", "runs[1].method").name
    'gauss2.json'
    >>> method_file("reports/scenes/x.json", "bdf:4", "runs[1].method")
    'bdf:4'
    >>> method_file("reports/scenes/x.json", "gauss:9", "runs[1].method")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    tableau_lab...SceneError: reports/scenes/x.json: runs[1].method: gauss:9: the number of stages must be ... not 9
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


def method(v, f: Field):
    """A method: :func:`method_file`'s; a file is read as strict JSON now (refused before any run)."""
    from ..exact.tableau_json import TableauError, read
    if not isinstance(v, str) or not 0 < len(v) <= MAX_TEXT:
        f.fail(f"a file name (a string) is needed, not {shown(v)}")
    found = method_file(f.path, v, f.where)
    if isinstance(found, Path):
        try:
            read(found)
        except TableauError as exc:
            f.fail(str(exc))
    return found


# -- a scene file ----------------------------------------------------------------------------

def _name(v, f: Field) -> str:
    if not isinstance(v, str) or not NAME.fullmatch(v):
        f.fail(f"{shown(v)} is not a file-name-safe name: 1 to {NAME_LENGTH} ASCII letters, digits, - _ . starting "
               "with a letter or digit (it names the output folder)")
    return v


def _format(tag: str) -> Callable:
    def read(v, f: Field) -> str:
        if v != tag:
            f.fail(f"{shown(v)} is not {tag!r}")
        return v
    return read


def _final_time(v, f: Field):
    """T, given instead of steps."""
    if "steps" in f.raw:
        f.fail("give exactly one of steps and T")
    T = scene_number(v, "T", f.path)
    if not _positive(T):
        f.fail(f"must be a positive exact number, got {shown(v)}", " ")
    return T


def _steps_of_T(f: Field) -> int:
    """steps not given: the whole number of steps T/h (within MAX_STEPS), refused naming T."""
    T, at_T = f.got["T"], replace(f, where="T")
    if T is None:
        f.fail("give exactly one of steps and T")
    n = T / f.got["h"]
    ratio = f"T / h = {shown(f.raw['T'])} / {shown(f.raw['h'])}"
    if not n.is_Integer:
        at_T.fail(f"{ratio} is not a whole number of steps")
    if n > MAX_STEPS:
        at_T.fail(f"{ratio} is more than the limit of {MAX_STEPS} steps (MAX_STEPS)")
    return int(n)


def _plots(v, f: Field) -> list:
    plots = PLOTS if v is None else v
    if not isinstance(plots, list) or not all(isinstance(p, str) for p in plots) or len(set(plots)) != len(plots):
        f.fail(f"a list of distinct names ({', '.join(PLOTS)}) is needed, not {shown(plots)}")
    bad = [p for p in plots if p not in PLOTS]
    if bad:
        f.fail(f"unknown plots {[printable(p) for p in bad]} (known: {', '.join(PLOTS)})")
    invariants = f.got["problem"].invariants
    if "invariants" in plots and not invariants:
        f.fail(f"the problem {printable(f.got['problem'].name)} has no invariants to plot (declare some under "
               "problem.define.invariants, or drop \"invariants\")")
    return plots


def _modified_energy(v, f: Field) -> int:
    if not isinstance(v, dict):
        f.fail(f"must be an object such as {{\"terms\": 2}}, not {shown(v)}", " ")
    terms = read_object(MODIFIED_ENERGY_SCHEMA, v, f.inside(f.where, f.got))["terms"]
    if f.got["problem"].kind != "hamiltonian":
        f.fail(f"the problem {printable(f.got['problem'].name)} is not Hamiltonian (a modified energy needs H(q, p))")
    return terms


def _project(v, f: Field) -> tuple:
    from ..numeric.problems import ProblemError
    project = distinct_names("invariant names")(v, f)
    prob = f.outer["problem"]
    bad = [k for k in project if k not in prob.invariants]
    if bad:
        f.fail(f"{[printable(k) for k in bad]} are not invariants of {prob.name} ({', '.join(prob.invariants)})")
    try:
        prob.check_projection(project)
    except ProblemError as exc:
        f.fail(printable(exc))
    return tuple(project)


def _run_label(f: Field) -> str:
    project = f.got["project"]
    return method_label(f.got["method"]) + (f" + projection onto {', '.join(project)}" if project else "")


#: the plots a scene can ask for
PLOT_SCHEMA = {
    "invariants": "I(y_n) − I(y0) against t, one panel per invariant of the problem",
    "orbit": "the orbit (q1, q2) of a Hamiltonian problem with two or more coordinates; otherwise as \"state\"",
    "parasitic": "GLMs: the parasitic components of the input vector (and their predicted growth) against t",
    "state": "the phase plot (first coordinate, its momentum), or the first two variables; one variable "
             "against t",
}
PLOTS = tuple(PLOT_SCHEMA)
#: the keys of "modified_energy"
MODIFIED_ENERGY_SCHEMA = (
    Key("terms", f"an integer from 1 to {MAX_MODIFIED_TERMS}", "2", "the lowest nonzero corrections of H̃ kept",
        count(1, MAX_MODIFIED_TERMS), 2),
)
#: the keys of one entry of "runs" (read after the scene's keys: ``outer`` is the scene)
RUN_SCHEMA = (
    Key("method", f"a tableau file (relative to the scene file), a library name such as \"gauss2\" or a "
        f"family with its size such as \"gauss:3\" (at most {MAX_TEXT} characters)", REQUIRED, "the method",
        method),
    Key("project", "a list of distinct invariant names of the problem", "[]",
        "projection onto these invariants after every step", _project, ()),
    Key("precision", "as the scene's", "the scene's", "this run's working precision", precision,
        lambda f: f.outer["precision"]),
    Key("start", "as the scene's", "the scene's", "this run's GLM starting values", choice(STARTS),
        lambda f: f.outer["start"]),
    Key("label", f"a string (at most {MAX_TEXT} characters)", "the method's file stem or name "
        "(+ the projection)", "the run's name in the figures and meta.json", lambda v, f: text()(v, f) or _run_label(f),
        _run_label),
)
#: the keys of a scene file, in the order they are read
SCHEMA = (
    Key("format", f'"{FORMAT}"', f'"{FORMAT}"', "the format tag", _format(FORMAT), FORMAT),
    Key("name", f"1 to {NAME_LENGTH} ASCII letters, digits, `-`, `_`, `.`, starting with a letter or digit",
        REQUIRED, "names the output folder `reports/<name>/` and the figures `<name>_<plot>.png`", _name),
    Key("title", f"a string (at most {MAX_TEXT} characters)", "the name", "the figures' title", text(),
        lambda f: f.got["name"]),
    Key("seed", f"a string (at most {MAX_TEXT} characters)", '""', "where the experiment comes from "
        '(e.g. "Figure 3.1"), kept in meta.json', text(), ""),
    Key("notes", f"a string or a list of strings (at most {MAX_NOTES} characters)", '""',
        "free text for the reader; not used by the runs", text(MAX_NOTES, many=True), ""),
    Key("h", 'an exact positive number: an integer or a string such as "1/100" or "1e-3"', REQUIRED,
        "the step size", positive_number),
    Key("T", "an exact positive number with T/h a whole number", "give exactly one of steps and T",
        "the final time", _final_time, None),
    Key("steps", f"an integer from 1 to {MAX_STEPS}", "give exactly one of steps and T", "the number of steps",
        count(1, MAX_STEPS), _steps_of_T),
    Key("record_every", "an integer from 1 to steps", "max(1, steps // 1000)",
        "the records' stride (time, invariant errors, states, parasitic components)",
        count(1, lambda f: f.got["steps"]), lambda f: max(1, f.got["steps"] // 1000)),
    Key("precision", "float64, dd or mp:DIGITS (5 ≤ DIGITS ≤ 10000)", "float64",
        "the runs' working precision (a run may set its own)", precision, "float64"),
    Key("start", ", ".join(STARTS), "exact", "GLM starting values: the starting method's series, or u·y0 "
        "(a run may set its own)", choice(STARTS), "exact"),
    Key("monitor", 'an exact positive number such as "1e-3"', "none (recorded, not bounded)",
        "a bound on the parasitic components of GLM inputs: a run exceeding it stops, status \"stopped\"",
        lambda v, f: float(positive_number(v, f, 'bound such as "1e-3"')), None),
    Key("problem", 'a built-in problem\'s name, `{"name": ..., "set": {...}}` (parameters or initial values '
        'replaced, exact numbers) or `{"define": {...}}` (a problem of your own, below)', REQUIRED,
        "the problem every run integrates", problem),
    Key("modified_energy", f'`{{"terms": N}}`, N from 1 to {MAX_MODIFIED_TERMS} (default 2)',
        "none", "adds `<name>_modified_energy.png`: |H − H₀| beside |H̃ − H̃₀| (Hamiltonian problems)",
        _modified_energy, None),
    Key("plots", "a list of distinct plot names (below)", '["invariants"] (["state"] for a problem without '
        'invariants)', "the figures drawn", _plots,
        lambda f: ["invariants"] if f.got["problem"].invariants else ["state"]),
    Key("runs", f"a list of 1 to {MAX_RUNS} run objects", REQUIRED, "the runs, one method each",
        objects(RUN_SCHEMA, MAX_RUNS, '{"method": FILE, ...}', least=1)),
)

KEYS = frozenset(k.name for k in SCHEMA)
RUN_KEYS = frozenset(k.name for k in RUN_SCHEMA)
MODIFIED_ENERGY_KEYS = frozenset(k.name for k in MODIFIED_ENERGY_SCHEMA)


# -- a work–precision scene --------------------------------------------------------------------

def _sweep(read_one, what: str) -> Callable:
    """A reader of a list of 1 to MAX_SWEEP values, each by ``read_one(value, field)``."""
    def read(v, f: Field) -> tuple:
        if not isinstance(v, list) or not 0 < len(v) <= MAX_SWEEP:
            f.fail(f"must be a list of 1 to {MAX_SWEEP} {what}, not {shown(v)}", " ")
        return tuple(read_one(x, replace(f, where=f"{f.where}[{j}]")) for j, x in enumerate(v, 1))
    return read


def _wp_steps(n, f: Field) -> int:
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_STEPS:
        f.fail(f"must be an integer between 1 and {MAX_STEPS} (MAX_STEPS, the step budget of a run), not {shown(n)}",
               " ")
    float64_number(f.outer["T"] / n, f"{f.where}: the step size T/n", f.src)
    return n


def tolerance(v, f: Field):
    """A tolerance: an exact string or integer as every scene number, or a JSON float (the
    decimal it is written as)."""
    return scene_number(repr(v) if isinstance(v, float) else v, f.where, f.path)


def _rtol(v, f: Field) -> float:
    x = tolerance(v, f)
    if not (x.is_real and 0 < x < 1):
        f.fail(f"must be a number in (0, 1), not {shown(v)}", " ")
    return float64_number(x, f.where, f.src)


def _atol_factor(v, f: Field) -> float:
    x = tolerance(v, f)
    if not (x.is_real and x > 0):
        f.fail(f"must be a positive number, not {shown(v)}", " ")
    return float64_number(x, f.where, f.src)


def _peer(v, f: Field) -> str:
    if v not in PEERS:
        f.fail(f"must be one of {', '.join(PEERS)} (the known peers), not {shown(v)}", " ")
    return v


def _wp_T(v, f: Field):
    T = scene_number(v, "T", f.path)
    if not _positive(T):
        f.fail(f"must be positive, not {shown(v)}", " ")
    float64_number(T, "T", f.src)
    return T


def _invariant(v, f: Field) -> str:
    prob = f.got["problem"]
    if not isinstance(v, str) or v not in prob.invariants:
        f.fail(f"{shown(v)} unknown for {printable(prob.name)} ({', '.join(prob.invariants) or 'it has none'})",
               " ")
    return v


#: the keys of an entry of "methods" of a work–precision scene
WP_METHOD_SCHEMA = (
    replace(RUN_SCHEMA[0], what="the method, compiled"),
    Key("steps", f"a list of 1 to {MAX_SWEEP} integers from 1 to {MAX_STEPS}", REQUIRED,
        "the step counts over [0, T], one point each", _sweep(_wp_steps, "step counts")),
    Key("label", f"a string (at most {MAX_TEXT} characters)", "the method's file stem or name",
        "the series' name in the figure", lambda v, f: text()(v, f) or method_label(f.got["method"]),
        lambda f: method_label(f.got["method"])),
)
#: the keys of an entry of "peers" of a work–precision scene
WP_PEER_SCHEMA = (
    Key("method", ", ".join(PEERS), REQUIRED, "scipy's solve_ivp method, or DOP853 compiled", _peer),
    Key("rtol", f'a list of 1 to {MAX_SWEEP} numbers in (0, 1) such as "1e-8"', REQUIRED,
        "the relative tolerances, one point each", _sweep(_rtol, 'numbers in (0, 1) such as "1e-8"')),
    Key("atol_factor", "a positive number", "1", "atol = atol_factor · rtol", _atol_factor, 1.0),
)
#: the keys of a work–precision scene file, in the order they are read
WP_SCHEMA = (
    Key("format", f'"{WP_FORMAT}"', REQUIRED, "the format tag", _format(WP_FORMAT)),
    replace(SCHEMA[1], what="names the output folder `reports/workprecision/<name>/` and the figure `<name>.png`"),
    SCHEMA[2],
    SCHEMA[4],
    Key("T", "an exact positive number (at most the reference run's step budget)", REQUIRED,
        "the final time: every point is the error at T", _wp_T),
    Key("problem", "as a scene's", REQUIRED, "the problem", problem),
    Key("invariant", "an invariant's name of the problem", '"H"',
        "the invariant whose error max |I − I₀| every point reports",
        _invariant, lambda f: _invariant("H", f)),
    Key("methods", f"a list of at most {MAX_RUNS} method objects", "[]", "our methods, compiled",
        objects(WP_METHOD_SCHEMA, MAX_RUNS, "objects"), ()),
    Key("peers", f"a list of at most {MAX_RUNS} peer objects", "[]", "the adaptive peers",
        objects(WP_PEER_SCHEMA, MAX_RUNS, "objects"), ()),
)

WP_KEYS = frozenset(k.name for k in WP_SCHEMA + WP_METHOD_SCHEMA + WP_PEER_SCHEMA)


def scene_doc() -> str:
    """The scene formats as Markdown, generated from the tables (:data:`SCHEMA`, :data:`RUN_SCHEMA`,
    :data:`MODIFIED_ENERGY_SCHEMA`, :data:`PLOT_SCHEMA`, the work–precision :data:`WP_SCHEMA`,
    :data:`WP_METHOD_SCHEMA`, :data:`WP_PEER_SCHEMA`, and the user-problem keys
    :data:`~tableau_lab.numeric.problems.DEFINE_KEYS`): docs/scenes.md's block
    (``python benchmarks/scene_doc.py --write docs/scenes.md``; a test checks it is current).

    >>> print(scene_doc().splitlines()[2])
    | key | takes | default | what it does |
    """
    from ..numeric.expressions import FUNCTIONS
    from ..numeric.problems import DEFINE_KEYS, PROBLEMS

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
    out += ["", "### Keys of a work–precision scene (`tableau-lab workprecision SCENE`)", ""] + table(WP_SCHEMA)
    out += ["", "### Keys of a method (an entry of `methods`)", ""] + table(WP_METHOD_SCHEMA)
    out += ["", "### Keys of a peer (an entry of `peers`)", ""] + table(WP_PEER_SCHEMA)
    return "\n".join(out)
