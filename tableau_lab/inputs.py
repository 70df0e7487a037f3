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

import json
import math
import os
import re
import stat
from itertools import accumulate

__all__ = ["MAX_JSON_BYTES", "MAX_JSON_DEPTH", "MAX_JSON_INT_DIGITS", "MAX_STEPS", "SAFE_NAME", "read_json", "parse_json",
           "printable", "json_path"]

MAX_JSON_BYTES = 10 * 2 ** 20     # the largest JSON file read (a tableau's own limit is lower: tableau_json.MAX_BYTES)
MAX_JSON_DEPTH = 64               # nesting of arrays and objects
MAX_JSON_INT_DIGITS = 1000        # digits of a JSON integer (a tableau reads its own: grammar.LIMITS)
MAX_STEPS = 10 ** 9               # steps of one run (scenes; T/h counts)
SAFE_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}")   # an output file or folder named by input (never . or ..)

# control characters (tab, newline, carriage return aside), lone surrogates, bidirectional overrides
_BAD_CHAR = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff\u202a-\u202e\u2066-\u2069]")
# what may hide a refused string or number (a walk over the value then finds it, with its path)
_SUSPECT = re.compile(r"\\u(?:00[01]|007[fF]|00[89]|[dD][89a-fA-F]|202[a-eA-E]|206[6-9])|[\x7f-\x9f\ud800-\udfff\u202a-\u202e"
                      r"\u2066-\u2069]|NaN|Infinity|[eE][+-]?[0-9]{3}|[0-9]{%d}" % (MAX_JSON_INT_DIGITS + 1))
_STRING = re.compile(r'"[^"\\]*(?:\\.[^"\\]*)*"', re.S)
_NOT_BRACKET = re.compile(r"[^\[\]{}]+")
_KEY = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")
_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _escaped(c: str) -> str:
    return f"\\u{ord(c):04x}"


def printable(text: str) -> str:
    """``text`` with lone surrogates and control characters escaped as ``\\uXXXX`` (safe to print)."""
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


def _check(value, source, error):
    """Duplicate keys, refused numbers and bad characters, with the JSON path of the first."""
    path = []

    def walk(v):
        if isinstance(v, str):
            m = _BAD_CHAR.search(v)
            if m:
                c = m.group()
                what = "a lone surrogate" if 0xD800 <= ord(c) <= 0xDFFF else "the control character"
                raise _fail(error, source, f"{what} {_escaped(c)} is not text", json_path(path))
        elif isinstance(v, _Refused):
            raise _fail(error, source, v.reason, json_path(path))
        elif isinstance(v, dict):
            if isinstance(v, _Dict):
                raise _fail(error, source, f"duplicate key {printable(v.dup)!r}", json_path(path + [v.dup]))
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
               parse_float=_float, parse_int=_int, parse_constant=_constant):
    """The value of JSON ``text`` (str or bytes) read strictly (see the module docstring);
    ``error``: the caller's error class (one message) or a function (source, reason, entry).
    A caller may pass its own hooks (a tableau keeps floats and NaN to refuse them by entry)."""
    source = printable(source)
    if isinstance(text, bytes):
        if len(text) > max_bytes:
            raise _fail(error, source, f"file is {len(text)} bytes, larger than the {max_bytes}-byte limit for a {what}")
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
            seen = set()
            out, dup = _Dict(out), next(k for k, _ in items if k in seen or seen.add(k))
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
        _check(value, source, error)
    return value


def read_json(path, error, what: str = "JSON file", *, max_bytes: int = MAX_JSON_BYTES, **hooks):
    """The value of the JSON file ``path``, read strictly (see :func:`parse_json`); only a
    regular file of at most ``max_bytes`` is opened (a FIFO or a device is refused at once)."""
    source = printable(os.fspath(path))
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
    return parse_json(raw, source, error, what, max_bytes=max_bytes, **hooks)
