"""The JSON tableau format: read, validate, write (documented in docs/tableau-format.md).

>>> m = loads('{"name": "implicit midpoint", "kind": "rk", "A": [["1/2"]], "b": [1]}')
>>> m.c.T
Matrix([[1/2]])
>>> loads(dumps(m)) == m
True
>>> loads('{"name": "x", "kind": "rk", "A": [[0.5]], "b": [1]}', source="m.json")  # doctest: +NORMALIZE_WHITESPACE
Traceback (most recent call last):
...
tableau_lab.exact.tableau_json.TableauError: m.json: entry A row 1, column 1: 0.5 is a floating-point number,
and the entries of an exact tableau are exact: write it as a string such as "1/2" or "sqrt(2)/2", or declare the
file decimal with the top-level key "numbers": "decimal" (its decimals are then read as balls)

A decimal tableau (``"numbers": "decimal"``) is read by :func:`from_dict_any` / :func:`load_any` as a
:class:`~tableau_lab.exact.balls.BallMethod`; its decimals are balls, its exact entries stay exact:

>>> d = loads_any('{"name": "x", "kind": "rk", "numbers": "decimal", "A": [[0.5]], "b": [1]}')
>>> d.entry("A", 1, 1).center, d.entry("A", 1, 1).radius, d.entry("b", 1).exact
(1/2, 1/20, 1)
"""
from __future__ import annotations

import json
import os
import re
from collections.abc import Iterable
from typing import Any

import sympy as sp

from ..errors import InputError
from ..files import atomic_write_text, path_exists
from ..inputs import parse_json, printable, read_json
from .balls import HALF_UNIT, BallError, BallMethod, Coefficient, Rounding, coefficient, radius_of
from .grammar import LIMITS, NAME, RESERVED, EntryError, format_entry, parameter, parse_entry
from .library import FamilyError, family, is_family, library_path
from .methods import GeneralLinearMethod, Method, MethodError, PartitionedRungeKutta, RungeKutta
from .names import did_you_mean

__all__ = ["TableauError", "load", "loads", "dumps", "save", "to_dict", "KINDS", "CLAIMS", "MAX_BYTES", "load_any",
           "loads_any", "from_dict_any", "DECIMAL_KEY", "MAX_DIGITS"]

MAX_BYTES = 1 << 20

#: kind → (class, required entries, optional entries), each entry's shape "matrix" or "vector"
KINDS: dict[str, tuple[type[Method], dict[str, str], dict[str, str]]] = {
    "rk": (RungeKutta, {"A": "matrix", "b": "vector"}, {"c": "vector", "bhat": "vector"}),   # bhat: embedded weights
    "prk": (PartitionedRungeKutta, {"A": "matrix", "b": "vector", "Ahat": "matrix", "bhat": "vector"},
            {"c": "vector", "chat": "vector"}),
    "glm": (GeneralLinearMethod, {"A": "matrix", "U": "matrix", "B": "matrix", "V": "matrix"}, {"c": "vector"}),
}

#: Claims a tableau may make, with the JSON type each takes and the kinds it applies to.
CLAIMS: dict[str, tuple[type, tuple[str, ...]]] = {
    "symplectic": (bool, ("rk", "prk")),
    "g_symplectic": (bool, ("rk", "glm")),
    "order": (int, ("rk", "prk", "glm")),
    "stage_order": (int, ("rk", "glm")),
    "effective_order": (int, ("rk",)),
    "identity_start_order": (int, ("glm",)),      # the GLM order with θ ≡ 0 (identity first starting component)
    "parasitism_free": (bool, ("glm",)),
    "embedded_order": (int, ("rk",)),             # the order of the embedded weights bhat
    "ssp_coefficient": (str, ("rk",)),            # an entry (exact, or decimal in a decimal file), or an integer
}

#: the top-level keys that describe a decimal file's numbers (docs/tableau-format.md): its rounding, and "numbers"
DECIMAL_ROUNDING = ("radius", "digits")
DECIMAL_KEYS = frozenset({"numbers", *DECIMAL_ROUNDING})
META = {"format", "name", "kind", "source", "notes", "claims", "constants", "provenance"} | DECIMAL_KEYS
#: the top-level key and value that make a tableau decimal (docs/tableau-format.md)
DECIMAL_KEY = '"numbers": "decimal"'
#: the largest "digits" a decimal file may state (the precision budget of exact/balls.py)
MAX_DIGITS = 2000
PROVENANCE = {"repository": str, "commit": str, "file": str, "line": int}
MATRICES = {k for _, req, opt in KINDS.values() for k, shape in {**req, **opt}.items() if shape == "matrix"}
MAX_CONSTANTS = 64          # named numbers in one file
#: a file's "constants": the name's symbol → its exact value
Constants = dict[sp.Symbol, sp.Expr]


class TableauError(InputError):
    """A tableau file that cannot be read: names the file and the entry."""

    def __init__(self, source: str, message: str, entry: str | None = None) -> None:
        self.source, self.entry, self.message = source, entry, message
        where = f"{source}: " + (f"entry {entry}: " if entry else "")
        super().__init__(where + message)


class _Refused:
    """A JSON value kept as text to be refused, with a message naming its entry."""

    def __init__(self, text: str) -> None:
        self.text = text

    def __repr__(self) -> str:
        return self.text

    def message(self) -> str:  # pragma: no cover - overridden
        raise NotImplementedError


class _Float(_Refused):
    def message(self) -> str:
        return (f"{self.text} is a floating-point number, and the entries of an exact tableau are exact: "
                f'write it as a string such as "{_hint(self.text)}" or "sqrt(2)/2", or declare the file decimal '
                f"with the top-level key {DECIMAL_KEY} (its decimals are then read as balls)")


class _Constant(_Refused):
    def message(self) -> str:
        return f"{self.text} is not a number a tableau can hold"


class _BigInt(_Refused):
    def message(self) -> str:
        return f"integer with {len(self.text.lstrip('-'))} digits is too long (limit {LIMITS['integer_digits']})"


def _int(text: str) -> int | _BigInt:
    return _BigInt(text) if len(text) > LIMITS["integer_digits"] + 1 else int(text)


def entry_name(parts: Iterable[str | int]) -> str:
    """A tableau's one-based name of the JSON entry at ``parts`` (as in every tableau message):
    ``("A", 0, 1)`` → ``A row 1, column 2``, ``("b", 2)`` → ``b[3]``, ``("claims", "order")`` →
    ``claims.order``.

    >>> entry_name(("A", 0, 1)), entry_name(("b", 2)), entry_name(("claims", "order"))
    ('A row 1, column 2', 'b[3]', 'claims.order')
    """
    parts = list(parts)
    head: str
    if len(parts) >= 3 and isinstance(parts[1], int) and isinstance(parts[2], int) and parts[0] in MATRICES:
        head, rest = f"{parts[0]} row {parts[1] + 1}, column {parts[2] + 1}", parts[3:]
    else:
        head, rest = "", parts
    for p in rest:
        head += f"[{p + 1}]" if isinstance(p, int) else (f".{p}" if head else str(p))
    return printable(head) or "(top level)"


#: the JSON reader's hooks (:func:`tableau_lab.inputs.parse_json`): floats, NaN and long integers kept to be refused
_HOOKS: dict[str, Any] = {"parse_float": _Float, "parse_int": _int, "parse_constant": _Constant, "name": entry_name}


def _entry(value: Any, source: str, where: str, consts: Constants | None = None) -> sp.Expr:
    if isinstance(value, _Refused):
        raise TableauError(source, value.message(), where)
    if value is None:
        raise TableauError(source, "null is not a number", where)
    try:
        e = parse_entry(value)
    except EntryError as exc:
        hint = (f"; or declare the file decimal with the top-level key {DECIMAL_KEY} (its decimals are then read "
                "as balls)") if isinstance(value, str) and _HAS_DECIMAL.search(value) else ""
        raise TableauError(source, str(exc) + hint, where) from None
    return e.xreplace(consts) if consts and e.free_symbols else e


_HAS_DECIMAL = re.compile(r"[0-9]\.|\.[0-9]|[0-9][eE][+-]?[0-9]")


def _constants(value: Any, source: str) -> Constants:
    """The "constants" object: name → an exact number (an entry without parameters), usable by
    name in every entry of the file (the nodes of an 8-stage Gauss method, SDIRK34's γ)."""
    if not isinstance(value, dict):
        raise TableauError(source, 'constants must be an object such as {"gamma": "1/2 + cos(pi/18)/sqrt(3)"}',
                           "constants")
    if len(value) > MAX_CONSTANTS:
        raise TableauError(source, f"{len(value)} constants: more than the limit of {MAX_CONSTANTS}", "constants")
    out: Constants = {}
    for name, text in value.items():
        where = f"constants.{name}"
        if not NAME.match(name) or len(name) > 31 or name in RESERVED:
            raise TableauError(source, f"{name!r} is not a constant name (a letter, then letters, digits, _; "
                                       f"not {', '.join(sorted(RESERVED))})", where)
        v = _entry(text, source, where)
        if v.free_symbols:
            raise TableauError(source, f"a constant must be a number, but {name} = {v} has names in it", where)
        out[parameter(name)] = v
    return out


_SMALL_DECIMAL = re.compile(r"-?[0-9]{0,20}(?:\.[0-9]{0,20})?(?:[eE][+-]?[0-9]{1,2})?")


def _hint(text: str) -> str:
    """The exact value a JSON float denotes, as a hint: "0.5" → "1/2"; "1/2" where that value
    would be long (1e99999999 has 10⁸ digits: never built).

    >>> _hint("0.25"), _hint("1e99999999"), _hint("2.5e-3")
    ('1/4', '1/2', '1/400')
    """
    if not _SMALL_DECIMAL.fullmatch(text):
        return "1/2"
    try:
        return str(sp.Rational(text))
    except (TypeError, ValueError):
        return "1/2"


#: reads one entry: (value, its one-based name) → the entry
Reader = Any


def _exact_reader(source: str, consts: Constants | None = None) -> Reader:
    return lambda x, where: _entry(x, source, where, consts)


def _rows(value: Any, source: str, key: str, read: Reader) -> list[list[Any]]:
    """A matrix's rows of entries, each read by ``read`` (named one-based: "A row 2, column 1")."""
    if not isinstance(value, list) or not value:
        raise TableauError(source, f"{key} must be a non-empty list of rows (a list of lists)", key)
    rows = []
    for i, row in enumerate(value, 1):
        if not isinstance(row, list):
            raise TableauError(source, f"row {i} of {key} is not a list", f"{key} row {i}")
        if len(row) != len(value[0]):
            raise TableauError(source, f"{key} is ragged: row {i} has {len(row)} entries, row 1 has {len(value[0])}",
                               f"{key} row {i}")
        if not row:
            raise TableauError(source, f"row {i} of {key} is empty", f"{key} row {i}")
        rows.append([read(x, f"{key} row {i}, column {j}") for j, x in enumerate(row, 1)])
    return rows


def _items(value: Any, source: str, key: str, read: Reader) -> list[Any]:
    """A vector's entries, each read by ``read`` (named one-based: "b[3]")."""
    if not isinstance(value, list) or not value:
        raise TableauError(source, f"{key} must be a non-empty list of entries", key)
    out = []
    for i, x in enumerate(value, 1):
        if isinstance(x, list):
            raise TableauError(source, f"{key} must be a flat list, but entry {i} is a list", f"{key}[{i}]")
        out.append(read(x, f"{key}[{i}]"))
    return out


def _matrix(value: Any, source: str, key: str, consts: Constants | None = None) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(_rows(value, source, key, _exact_reader(source, consts)))


def _vector(value: Any, source: str, key: str, consts: Constants | None = None) -> sp.ImmutableMatrix:
    return sp.ImmutableMatrix(_items(value, source, key, _exact_reader(source, consts)))


def _claims(value: Any, kind: str, source: str, read: Reader | None = None) -> dict[str, Any]:
    """The claims, checked; an entry claim (the SSP coefficient) read by ``read`` (default: exact,
    kept as written)."""
    if not isinstance(value, dict):
        raise TableauError(source, "claims must be an object such as {\"g_symplectic\": true}", "claims")
    out = dict(value)
    for k, v in value.items():
        if k not in CLAIMS:
            raise TableauError(source, f"unknown claim {k!r} (known: {', '.join(sorted(CLAIMS))})", f"claims.{k}")
        typ, kinds = CLAIMS[k]
        if kind not in kinds:
            raise TableauError(source, f"claim {k!r} does not apply to kind {kind!r}", f"claims.{k}")
        if k == "ssp_coefficient" and not isinstance(v, bool) and isinstance(v, (str, int, _Refused)):
            entry = (read or _exact_reader(source))(v, f"claims.{k}")
            if not read and entry.free_symbols:
                raise TableauError(source, f"the claimed SSP coefficient {v} must be a number", f"claims.{k}")
            out[k] = entry if read else v
        elif type(v) is not typ:
            raise TableauError(source, f"claim {k!r} must be a {typ.__name__}, got {v!r}", f"claims.{k}")
    return out


def _provenance(value: Any, source: str) -> tuple[tuple[str, Any], ...]:
    """The "provenance" object of extracted data: repository "owner/name", commit (40 hex digits), file and
    line (one-based), checked."""
    if not isinstance(value, dict):
        raise TableauError(source, 'provenance must be an object such as {"repository": "owner/name", "commit": '
                                   '"<40 hex>", "file": "path", "line": 12}', "provenance")
    for k, v in value.items():
        typ = PROVENANCE.get(k)
        if typ is None:
            raise TableauError(source, f"unknown provenance key {k!r} (known: {', '.join(PROVENANCE)})",
                               f"provenance.{k}")
        if type(v) is not typ or (isinstance(v, str) and not 0 < len(v) <= 400) or (isinstance(v, int) and v < 1):
            what = "a positive integer" if typ is int else "a non-empty string of at most 400 characters"
            raise TableauError(source, f"provenance {k} must be {what}", f"provenance.{k}")
    for k in ("repository", "commit", "file"):
        if k not in value:
            raise TableauError(source, f"provenance needs {k!r}", f"provenance.{k}")
    if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.-]*/[A-Za-z0-9][A-Za-z0-9_.-]*", value["repository"]):
        raise TableauError(source, "provenance repository must be owner/name", "provenance.repository")
    if not re.fullmatch(r"[0-9a-f]{40}", value["commit"]):
        raise TableauError(source, "provenance commit must be the 40 hexadecimal digits of a commit",
                           "provenance.commit")
    return tuple(sorted(value.items()))


def from_dict(data: Any, source: str = "<tableau>") -> Method:
    """Build a method from the parsed JSON object of a tableau file."""
    if not isinstance(data, dict):
        raise TableauError(source, "the file must hold one JSON object {\"name\": ..., \"kind\": ..., ...}")
    kind = data.get("kind")
    if not isinstance(kind, str) or kind not in KINDS:
        raise TableauError(source, f"unknown or missing kind {kind!r}: use one of {', '.join(KINDS)}", "kind")
    if _numbers(data, source) == "decimal":
        raise TableauError(source, f"a decimal tableau ({DECIMAL_KEY}) is analysed in ball arithmetic by "
                                   "`tableau-lab verify FILE` or tl.verify(tl.load(FILE)); this needs exact entries",
                           "numbers")
    for key in DECIMAL_ROUNDING:
        if key in data:
            raise TableauError(source, f"{key!r} belongs to a decimal tableau ({DECIMAL_KEY})", key)
    cls, required, optional = KINDS[kind]
    name, notes = _checked_top(data, kind, source)
    readers = {"matrix": _matrix, "vector": _vector}
    consts = _constants(data["constants"], source) if "constants" in data else None
    parts = {}
    for key, shape in list(required.items()) + list(optional.items()):
        if key in data:
            parts[key] = readers[shape](data[key], source, key, consts)
    claims = _claims(data.get("claims", {}), kind, source)
    provenance = _provenance(data["provenance"], source) if "provenance" in data else ()
    try:
        return cls(**parts, name=name, source=data.get("source", ""), notes=tuple(notes),
                   claims=tuple(sorted(claims.items())), provenance=provenance)
    except MethodError as exc:
        raise TableauError(source, str(exc)) from None


def _numbers(data: dict[str, Any], source: str) -> str:
    numbers = data.get("numbers", "exact")
    if numbers not in ("exact", "decimal"):
        raise TableauError(source, f'numbers must be "exact" (the default) or "decimal", not {str(numbers)[:40]!r}',
                           "numbers")
    return str(numbers)


def _checked_top(data: dict[str, Any], kind: str, source: str) -> tuple[str, list[str]]:
    """The keys, the metadata and the size budget (before any entry is read): (name, notes)."""
    _, required, _ = KINDS[kind]
    _check_keys(data, kind, source)
    name, notes = _metadata(data, source)
    for key in required:
        if isinstance(data[key], list) and len(data[key]) > MAX_SIZE:
            raise TableauError(source, f"{len(data[key])} rows: beyond the size budget MAX_SIZE = {MAX_SIZE} stages "
                                       "or values of the exact analyses (tableau_json.py)", key)
    return name, notes


def from_dict_any(data: Any, source: str = "<tableau>") -> Method | BallMethod:
    """:func:`from_dict` for an exact tableau; a decimal one (``"numbers": "decimal"``) as a
    :class:`~tableau_lab.exact.balls.BallMethod`: decimal entries as balls (docs/tableau-format.md),
    exact entries kept exact; every error names the file and the one-based entry."""
    if not isinstance(data, dict) or _numbers(data, source) != "decimal":
        return from_dict(data, source)
    kind = data.get("kind")
    if kind not in ("rk", "prk"):
        raise TableauError(source, f'a decimal tableau is of kind "rk" or "prk", not {str(kind)[:40]!r}', "kind")
    _, required, optional = KINDS[kind]
    name, notes = _checked_top(data, kind, source)
    if "constants" in data:
        raise TableauError(source, "a decimal tableau has no named constants: write each entry", "constants")
    rounding = _rounding(data, source)

    def read(x: Any, where: str) -> Coefficient:
        return _ball_entry(x, source, where, rounding)
    parts: dict[str, Any] = {}
    for key, shape in list(required.items()) + list(optional.items()):
        if key in data:
            rows = (_rows if shape == "matrix" else _items)(data[key], source, key, read)
            parts[key] = tuple(tuple(r) if isinstance(r, list) else r for r in rows)
    claims = _claims(data.get("claims", {}), kind, source, read)
    provenance = _provenance(data["provenance"], source) if "provenance" in data else ()
    try:
        return BallMethod(name=name, kind=kind, **parts, rounding=rounding, source=data.get("source", ""),
                          notes=tuple(notes), claims=tuple(sorted(claims.items())), provenance=provenance)
    except BallError as exc:
        raise TableauError(source, str(exc), exc.entry) from None


def _rounding(data: dict[str, Any], source: str) -> Rounding:
    """The file's "radius" or "digits" (not both), or half a unit in the last digit."""
    if "radius" in data and "digits" in data:
        raise TableauError(source, 'give "radius" or "digits", not both', "digits")
    if "radius" in data:
        r = data["radius"]
        try:
            return Rounding("radius", radius_of(r.text if isinstance(r, _Float) else r))
        except BallError as exc:
            raise TableauError(source, str(exc), "radius") from None
    if "digits" in data:
        d = data["digits"]
        if type(d) is not int or not 1 <= d <= MAX_DIGITS:
            raise TableauError(source, f"digits must be an integer from 1 to {MAX_DIGITS} (the significant digits "
                                       "every decimal entry is correctly rounded to)", "digits")
        return Rounding("digits", d)
    return HALF_UNIT


def _ball_entry(value: Any, source: str, where: str, rounding: Rounding) -> Coefficient:
    """One entry of a decimal tableau: a decimal (string or JSON number, its text kept) as a ball, an
    exact entry of the grammar kept exact."""
    if isinstance(value, _Float):
        value = value.text
    elif isinstance(value, _Refused):
        raise TableauError(source, value.message(), where)
    elif isinstance(value, int) and not isinstance(value, bool):
        value = str(value)
    if not isinstance(value, str):
        raise TableauError(source, f"{'null' if value is None else type(value).__name__} is not a number: an "
                                   'entry is a decimal ("0.0815892447", "-1.2e-3") or an exact entry ("1/3")', where)
    try:
        return coefficient(value, rounding)
    except (EntryError, BallError) as exc:
        raise TableauError(source, str(exc), where) from None


def _check_keys(data: dict[str, Any], kind: str, source: str) -> None:
    """Every key known for the kind (or a user's 'x-' key), every required one present."""
    _, required, optional = KINDS[kind]
    for key in data:
        if key not in META and key not in required and key not in optional and not key.startswith("x-"):
            raise TableauError(source, f"unknown key {key!r} for kind {kind!r} (allowed: "
                                       f"{', '.join(list(required) + list(optional) + sorted(META))}; "
                                       "prefix your own keys with 'x-')", key)
    for key in required:
        if key not in data:
            raise TableauError(source, f"kind {kind!r} needs {key!r}", key)


def _metadata(data: dict[str, Any], source: str) -> tuple[str, list[str]]:
    """(name, notes) checked, with the source and the format."""
    name = data.get("name")
    if not isinstance(name, str) or not name.strip():
        raise TableauError(source, "name must be a non-empty string", "name")
    if "source" in data and not isinstance(data["source"], str):
        raise TableauError(source, "source must be a string", "source")
    notes = data.get("notes", [])
    if isinstance(notes, str):
        notes = [notes]
    if not isinstance(notes, list) or not all(isinstance(n, str) for n in notes):
        raise TableauError(source, "notes must be a string or a list of strings", "notes")
    if "format" in data and data["format"] != FORMAT:
        raise TableauError(source, f"format {data['format']!r} is not understood (this is {FORMAT!r})", "format")
    return name, notes


FORMAT = "tableau_lab/1"
MAX_SIZE = 40        # stages, values of a tableau file: exact algebra on a dense 60-stage tableau runs for hours in
                     # FLINT calls that no time budget can interrupt (the families stop at 8 stages, 30 steps)


def _error(source: str, reason: str, entry: str | None) -> TableauError:
    return TableauError(source, reason, entry)


def parse(text: str | bytes, source: str = "<tableau>") -> Any:
    """The JSON object of a tableau text, read by the strict reader of :mod:`~tableau_lab.inputs`
    with the tableau's size limit; floats, NaN and long integers are kept to be refused by entry
    (entries are not parsed yet: :func:`from_dict` does that)."""
    if not isinstance(text, (str, bytes)):
        raise TableauError(str(source), f"a tableau text is a str or bytes (the JSON text), not {type(text).__name__}: "
                                        "load(path) reads a file, from_dict(obj) takes a parsed object")
    return parse_json(text, source, _error, "tableau", max_bytes=MAX_BYTES, **_HOOKS)


def loads(text: str | bytes, source: str = "<tableau>") -> Method:
    """Parse the text of a tableau file."""
    return from_dict(parse(text, source), source)


def read(path: str | os.PathLike[str]) -> Any:
    """The JSON object of a tableau file (see :func:`parse`); only a regular file is read."""
    return read_json(path, _error, "tableau", max_bytes=MAX_BYTES, **_HOOKS)


def load(path: str | os.PathLike[str], **size: int) -> Method:
    """Read a tableau file; errors name the file and the entry.  A name that is not a file is
    a shipped method (``load("gauss2")``) or a generated family (``load("bdf:5")``,
    ``load("gauss", s=3)``): :mod:`library`; a name close to one of those is answered with
    "did you mean" (:mod:`names`)."""
    m: Method = _load(path, from_dict, **size)
    return m


def load_any(path: str | os.PathLike[str], **size: int) -> Method | BallMethod:
    """:func:`load`, reading a decimal tableau too (:func:`from_dict_any`)."""
    m: Method | BallMethod = _load(path, from_dict_any, **size)
    return m


def loads_any(text: str | bytes, source: str = "<tableau>") -> Method | BallMethod:
    """:func:`loads`, reading a decimal tableau too (:func:`from_dict_any`)."""
    return from_dict_any(parse(text, source), source)


def _load(path: str | os.PathLike[str], build: Any, **size: int) -> Any:
    if size or (not path_exists(path) and is_family(path)):
        try:
            return family(str(path), **size)
        except FamilyError as exc:
            raise TableauError(str(path), str(exc).split(": ", 1)[-1]) from None
    shipped = None if path_exists(path) else library_path(path)
    if shipped is not None:
        return build(read(shipped), str(path))      # a shipped method by name
    if not path_exists(path) and did_you_mean(path):
        raise TableauError(str(path), "no such file, shipped method or family" + did_you_mean(path)
                           + " (tableau-lab list shows them all)")
    return build(read(path), str(path))


def entries(value: Any, source: str, key: str) -> sp.ImmutableMatrix:
    """Parse one matrix (list of rows) or vector of entries with the safe grammar."""
    reader = _matrix if isinstance(value, list) and value and isinstance(value[0], list) else _vector
    return reader(value, source, key)


def to_dict(m: Method) -> dict[str, Any]:
    """The JSON object of a method (entries written in the grammar)."""
    out: dict[str, Any] = {"format": FORMAT, "name": m.name, "kind": m.kind}
    if m.source:
        out["source"] = m.source
    names: dict[sp.Expr, sp.Symbol] = {}
    if isinstance(m, RungeKutta) and m.conjugate is not None and any(isinstance(x, sp.RootOf) for x in m.c):
        # nodes that are roots of polynomials: named once (c1, c2, …), the entries polynomials in them
        names = {x: parameter(f"c{i}") for i, x in enumerate(m.c, 1) if isinstance(x, sp.RootOf)}
        out["constants"] = {str(v): format_entry(k) for k, v in names.items()}
    for key, M in m.matrices().items():
        if M is None:
            continue
        M = M.xreplace(names) if names else M
        if key in ("b", "c", "bhat", "chat"):
            out[key] = [format_entry(x) for x in M]
        else:
            out[key] = [[format_entry(x) for x in M.row(i)] for i in range(M.rows)]
    if m.notes:
        out["notes"] = list(m.notes)
    if m.claims:
        out["claims"] = dict(m.claims)
    if m.provenance:
        out["provenance"] = dict(m.provenance)
    return out


def dumps(m: Method) -> str:
    """Tableau text: one matrix row per line."""
    d = to_dict(m)
    lines = []
    for k, v in d.items():
        if isinstance(v, list) and v and isinstance(v[0], list):
            rows = ",\n    ".join(json.dumps(r, ensure_ascii=False) for r in v)
            lines.append(f'  {json.dumps(k)}: [\n    {rows}\n  ]')
        else:
            lines.append(f"  {json.dumps(k)}: {json.dumps(v, ensure_ascii=False)}")
    return "{\n" + ",\n".join(lines) + "\n}\n"


SAVED_BY = ("Solved by tableau-lab solve", "Found by tableau-lab design",     # the note --save writes
            "Reconstructed by tableau-lab reconstruct")


def saved_by_tableau_lab(path: str | os.PathLike[str]) -> bool:
    """Whether the file at ``path`` is a tableau that ``solve --save``, ``design --save`` or
    ``reconstruct --save`` wrote
    (a note starting with one of :data:`SAVED_BY`): only such a file is replaced by ``--save``."""
    try:
        data = read_json(path, _error, "tableau", max_bytes=MAX_BYTES, input=False, **_HOOKS)    # our own output
    except TableauError:
        return False
    notes = data.get("notes") if isinstance(data, dict) else None
    return isinstance(notes, list) and any(isinstance(n, str) and n.startswith(SAVED_BY) for n in notes)


def save(m: Method, path: str | os.PathLike[str]) -> None:
    """Write a tableau file atomically (no half-written file on failure)."""
    atomic_write_text(path, dumps(m))
