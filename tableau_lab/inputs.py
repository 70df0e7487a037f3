"""The one strict JSON reader of every JSON input (tableaux, scenes, the problems in them).

:func:`read_json` refuses, with the caller's error class and a message naming the file and the
entry (a JSON path such as ``runs[1].method``: list positions one-based, as every entry name of
the project): anything but a regular file (FIFOs, directories,
devices, sockets: at once, without reading), files over ``MAX_JSON_BYTES``, text that is not
strict UTF-8, duplicate keys at any depth, the literals ``NaN``, ``Infinity`` and ``-Infinity``,
nesting deeper than ``MAX_JSON_DEPTH`` (checked before parsing: no RecursionError), integers
over ``MAX_JSON_INT_DIGITS`` digits, and strings, keys included, holding lone surrogates, control
characters (tab, newline and carriage return aside) or bidirectional overrides.  Nothing is
evaluated.

>>> parse_json('{"a": {"b": 1, "b": 2}}', "s.json", ValueError)
Traceback (most recent call last):
...
ValueError: s.json: a.b: duplicate key 'b'
>>> parse_json('{"runs": [{"method": "\\\\ud800"}]}', "s.json", ValueError)
Traceback (most recent call last):
...
ValueError: s.json: runs[1].method: a lone surrogate \\ud800 is not text
"""
from __future__ import annotations

import contextlib
import json
import math
import os
import re
import stat
import threading
from itertools import accumulate

__all__ = ["MAX_JSON_BYTES", "MAX_JSON_DEPTH", "MAX_JSON_INT_DIGITS", "MAX_STEPS", "SAFE_NAME", "read_json",
           "parse_json", "check_schema", "ListOf", "MapOf", "NAME_MAX", "note_input", "command_inputs",
           "recorded_inputs", "printable", "json_path"]

MAX_JSON_BYTES = 10 * 2 ** 20     # the largest JSON file read (a tableau's own limit is lower: tableau_json.MAX_BYTES)
MAX_JSON_DEPTH = 64               # nesting of arrays and objects
MAX_JSON_INT_DIGITS = 1000        # digits of a JSON integer (a tableau reads its own: grammar.LIMITS)
MAX_STEPS = 10 ** 9               # steps of one run (scenes; T/h counts)
NAME_LENGTH = 100                  # characters of an output file or folder name made from input
SAFE_NAME = re.compile(rf"[A-Za-z0-9][A-Za-z0-9_.-]{{0,{NAME_LENGTH - 1}}}")   # such a name (never . or ..)

NAME_MAX = 255                    # bytes of one file name (Linux, macOS): longer ones are refused, not tried

# control characters (tab, newline, carriage return aside), lone surrogates, bidirectional overrides
_BAD_CHAR = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff\u202a-\u202e\u2066-\u2069]")
# what may hide a refused string or number (a walk over the value then finds it, with its path)
_SUSPECT = re.compile(r"\\u(?:00[01]|007[fF]|00[89]|[dD][89a-fA-F]|202[a-eA-E]|206[6-9])"
                      r"|[\x7f-\x9f\ud800-\udfff\u202a-\u202e\u2066-\u2069]"
                      r"|NaN|Infinity|[eE][+-]?[0-9]{3}|[0-9]{%d}" % (MAX_JSON_INT_DIGITS + 1))
_STRING = re.compile(r'"[^"\\]*(?:\\.[^"\\]*)*"', re.S)
_NOT_BRACKET = re.compile(r"[^\[\]{}]+")
_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")
_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _escaped(c: str) -> str:
    return f"\\u{ord(c):04x}"


def printable(text: object) -> str:
    """``str(text)`` with lone surrogates and control characters escaped as ``\\uXXXX`` (safe to print)."""
    return _BAD_CHAR.sub(lambda m: _escaped(m.group()), str(text))


def json_path(parts) -> str:
    """``("runs", 0, "method")`` → ``runs[1].method``: positions one-based (the project's entry
    names: ``A[1,1]``, ``q0[1]``, ``runs[1]``), odd keys quoted, escaped."""
    out = ""
    for p in parts:
        if isinstance(p, int):
            out += f"[{p + 1}]"
        elif _KEY.fullmatch(p):
            out += f".{p}" if out else p
        else:
            out += f"[{printable(json.dumps(p))}]"
    return out or "(top level)"


def _fail(error, source, reason, entry=None):
    """The caller's error: a class is called with one message, a function with (source, reason, entry)."""
    if isinstance(error, type):
        return error(f"{source}: {entry}: {reason}" if entry else f"{source}: {reason}")
    return error(source, reason, entry)


class _Dict(dict):
    """An object whose text repeated a key (``dup``)."""
    dup = None


class _Refused:
    """A number JSON allows and this reader refuses, kept to be reported with its entry."""

    def __init__(self, reason):
        self.reason = reason


def _constant(text):
    return _Refused(f"{text} is not a JSON number (NaN and infinities are refused)")


def _int(text):
    digits = len(text.lstrip("-"))
    if digits > MAX_JSON_INT_DIGITS:
        return _Refused(f"an integer of {digits} digits is longer than the limit of {MAX_JSON_INT_DIGITS}")
    return int(text)


def _float(text):
    x = float(text)
    return x if math.isfinite(x) else _Refused(f"the number {text[:40]} is out of the range of a float")


def _depth(text: str) -> int:
    """The deepest nesting of arrays and objects (brackets outside strings)."""
    brackets = _NOT_BRACKET.sub("", _STRING.sub("", text))
    if len(brackets) <= MAX_JSON_DEPTH:
        return len(brackets)                # an upper bound, enough here
    return max(accumulate(1 if c in "[{" else -1 for c in brackets), default=0)


def _check(value, source, error, name=json_path):
    """Duplicate keys, refused numbers and bad characters, with the JSON path of the first
    (``name``: parts → entry name; a tableau names its entries its own one-based way)."""
    path: list[str | int] = []

    def walk(v):
        if isinstance(v, str):
            m = _BAD_CHAR.search(v)
            if m:
                c = m.group()
                what = "a lone surrogate" if 0xD800 <= ord(c) <= 0xDFFF else "the control character"
                raise _fail(error, source, f"{what} {_escaped(c)} is not text", name(path))
        elif isinstance(v, _Refused):
            raise _fail(error, source, v.reason, name(path))
        elif isinstance(v, dict):
            if isinstance(v, _Dict):
                raise _fail(error, source, f"duplicate key {printable(v.dup)!r}", name(path + [v.dup]))
            for k, x in v.items():
                path.append(k)
                walk(k)
                walk(x)
                path.pop()
        elif isinstance(v, list):
            for i, x in enumerate(v):
                path.append(i)
                walk(x)
                path.pop()
    walk(value)                         # depth at most MAX_JSON_DEPTH: checked before json.loads


def parse_json(text, source, error, what: str = "JSON file", *, max_bytes: int = MAX_JSON_BYTES,
               parse_float=_float, parse_int=_int, parse_constant=_constant, name=json_path):
    """The value of JSON ``text`` (str or bytes) read strictly (see the module docstring);
    ``error``: the caller's error class (one message) or a function (source, reason, entry).
    A caller may pass its own hooks (a tableau keeps floats and NaN to refuse them by entry) and
    its own ``name`` of an entry from its JSON path parts."""
    source = printable(source)
    if isinstance(text, bytes):
        if len(text) > max_bytes:
            raise _fail(error, source,
                        f"file is {len(text)} bytes, larger than the {max_bytes}-byte limit for a {what}")
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise _fail(error, source, f"not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    elif len(text) > max_bytes:
        raise _fail(error, source, f"text of {len(text)} characters is larger than the {max_bytes} limit for a {what}")
    if _depth(text) > MAX_JSON_DEPTH:
        raise _fail(error, source, f"not a {what}: JSON nested too deeply (more than {MAX_JSON_DEPTH} levels)")
    duplicates = []

    def pairs(items):
        out = dict(items)
        if len(out) < len(items):
            seen: set = set()
            dup = None
            for k, _ in items:
                if k in seen:
                    dup = k
                    break
                seen.add(k)
            out = _Dict(out)
            out.dup = dup
            duplicates.append(dup)
        return out
    try:
        value = json.loads(text, object_pairs_hook=pairs, parse_float=parse_float, parse_int=parse_int,
                           parse_constant=parse_constant)
    except json.JSONDecodeError as exc:
        raise _fail(error, source, f"not valid JSON: {exc.msg} (line {exc.lineno}, column {exc.colno})") from None
    except RecursionError:
        raise _fail(error, source, f"not a {what}: JSON nested too deeply") from None
    except ValueError as exc:
        raise _fail(error, source, f"not a valid {what}: {printable(exc)}") from None
    if duplicates or _SUSPECT.search(text):
        _check(value, source, error, name)
    return value


_INPUTS = threading.local()       # .files: {(st_dev, st_ino): path} of the running command, or None


@contextlib.contextmanager
def command_inputs(paths=()):
    """The inputs of one command: ``paths`` (files named on its command line) and every file read
    inside the block through :func:`note_input`; :func:`guard_output` refuses to write over any of
    them.  Outside such a block (the Python API) only explicit ``inputs=`` are guarded."""
    old = getattr(_INPUTS, "files", None)
    _INPUTS.files = {} if old is None else old
    try:
        for p in paths:
            note_input(p)
        yield
    finally:
        _INPUTS.files = old


def note_input(path) -> None:
    """Record ``path`` as an input of the running command (:func:`command_inputs`; else nothing)."""
    files = getattr(_INPUTS, "files", None)
    if files is None:
        return
    try:
        st = os.stat(path)
    except (OSError, ValueError, TypeError):
        return
    if stat.S_ISREG(st.st_mode):
        files.setdefault((st.st_dev, st.st_ino), os.fspath(path))


def recorded_inputs() -> list:
    """The inputs recorded by the running command (:func:`command_inputs`), or []."""
    return list((getattr(_INPUTS, "files", None) or {}).values())


def read_json(path, error, what: str = "JSON file", *, max_bytes: int = MAX_JSON_BYTES, input: bool = True, **hooks):
    """The value of the JSON file ``path``, read strictly (see :func:`parse_json`); only a
    regular file of at most ``max_bytes`` is opened (a FIFO or a device is refused at once).
    ``input``: record it as an input of the running command, which then never writes over it
    (:func:`note_input`; False for a command's own file read back, e.g. a
    design checkpoint)."""
    source = printable(os.fspath(path))
    sizes = (len(p.encode("utf-8", "surrogateescape")) for p in os.fspath(path).split(os.sep))
    longest = next((n for n in sizes if n > NAME_MAX), None)
    if longest is not None:
        raise _fail(error, source[:80] + "…", f"cannot read: a file name of {longest} "
                                             f"bytes is longer than the system's limit of {NAME_MAX}")
    try:
        st = os.stat(path)
    except (OSError, ValueError) as exc:      # ValueError: a path with a NUL byte
        raise _fail(error, source, f"cannot read: {printable(getattr(exc, 'strerror', None) or exc)}") from None
    kind = next((k for test, k in _KINDS if test(st.st_mode)), None if stat.S_ISREG(st.st_mode) else "not a file")
    if kind:
        raise _fail(error, source, f"{kind}, not a {what}: only regular files are read")
    if st.st_size > max_bytes:
        raise _fail(error, source, f"file is {st.st_size} bytes, larger than the {max_bytes}-byte limit for a {what}")
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
        with os.fdopen(fd, "rb") as fh:
            regular = stat.S_ISREG(os.fstat(fh.fileno()).st_mode)      # not replaced since the stat
            raw = fh.read(max_bytes + 1) if regular else b""
    except OSError as exc:
        raise _fail(error, source, f"cannot read: {printable(exc.strerror or exc)}") from None
    if not regular:
        raise _fail(error, source, f"not a regular file, not a {what}: only regular files are read")
    if input:
        note_input(path)
    return parse_json(raw, source, error, what, max_bytes=max_bytes, **hooks)


class ListOf:
    """A schema (:func:`check_schema`): a JSON array of ``item``, ``least`` … ``most`` long."""

    def __init__(self, item, most: int, least: int = 0):
        self.item, self.most, self.least = item, most, least


class MapOf:
    """A schema: a JSON object of at most ``most`` keys (any text), each value ``item``."""

    def __init__(self, item, most: int):
        self.item, self.most, self.least = item, most, 0


_TYPE_NAMES = {float: "a number", int: "an integer", str: "text", bool: "true or false", dict: "an object",
               list: "an array", type(None): "null"}


def _schema_name(schema) -> str:
    if isinstance(schema, tuple):
        return " or ".join(_schema_name(s) for s in schema)
    if isinstance(schema, dict):
        return "an object"
    if isinstance(schema, (ListOf, MapOf)):
        return "an array" if isinstance(schema, ListOf) else "an object"
    return _TYPE_NAMES.get(schema, str(schema))


def _conforms(value, schema) -> bool:
    if schema is float:
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if schema is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if isinstance(schema, type):
        return isinstance(value, schema)
    if isinstance(schema, dict):
        return isinstance(value, dict)
    if isinstance(schema, ListOf):
        return isinstance(value, list)
    if isinstance(schema, MapOf):
        return isinstance(value, dict)
    return False


def check_schema(value, schema, source, error, path=()):
    """Check a saved output read back (``value``, from ``source``) against the schema its writer
    follows; the first mismatch is ``error`` (a class) naming the source and the entry.

    A schema is a type (``float``: any JSON number; ``int``, ``str``, ``bool``, ``dict``,
    ``list``, ``type(None)``), a tuple of alternatives, a dict ``{key: schema}`` (an object with
    these keys; a key written ``"?key"`` may be missing; other keys are allowed), a
    :class:`ListOf` or a :class:`MapOf` (with their length bounds).

    >>> check_schema({"runs": [{"n": 1}, {"n": "x"}]}, {"runs": ListOf({"n": int}, 10)}, "d.json", ValueError)
    Traceback (most recent call last):
    ...
    ValueError: d.json: runs[2].n: must be an integer, not 'x'
    >>> check_schema({"runs": []}, {"runs": ListOf({"n": int}, 10, least=1)}, "d.json", ValueError)
    Traceback (most recent call last):
    ...
    ValueError: d.json: runs: must hold at least 1 entry, it holds 0
    """
    path = list(path)
    alternatives = schema if isinstance(schema, tuple) else (schema,)
    match = next((s for s in alternatives if _conforms(value, s)), None)
    if match is None:
        raise _fail(error, printable(source), f"must be {_schema_name(schema)}, not {printable(repr(value))[:60]}",
                    json_path(path))
    if isinstance(match, dict):
        for key, sub in match.items():
            optional = key.startswith("?")
            key = key.lstrip("?")
            if key not in value:
                if optional:
                    continue
                raise _fail(error, printable(source), f"the key {key!r} is missing", json_path(path) if path else None)
            check_schema(value[key], sub, source, error, path + [key])
    elif isinstance(match, (ListOf, MapOf)):
        n = len(value)
        if n > match.most or n < match.least:
            bound = (f"at most {match.most}" if n > match.most else f"at least {match.least}")
            entries = "entry" if bound.endswith(" 1") else "entries"
            raise _fail(error, printable(source), f"must hold {bound} {entries}, it holds {n}", json_path(path))
        items = value.items() if isinstance(match, MapOf) else enumerate(value)
        for k, v in items:
            check_schema(v, match.item, source, error, path + [k])
