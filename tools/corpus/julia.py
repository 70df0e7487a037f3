"""A reader of the straight-line Julia functions that build tableaux (no loops, no branches).

A function's body is split into statements; ``x = expr``, ``x[i, j] = expr`` and a final call
(``return ExplicitRKTableau(…)``, ``Tableau{T}(…)``) are understood, through the float-free
expression reader of :mod:`tools.corpus.expr`; the final call is handed to a constructor given by
the library's script, which records what its arguments claim.  Anything else (a loop, a call of
an unknown function) raises :class:`Unsupported`, and the tableau is skipped and counted.
"""
from __future__ import annotations

import re

from .expr import Array, Parser, Tok, Unsupported, Val, tokenize

FUNCTION = re.compile(r"^function (\w+)\((.*?)\)[^\n]*\n(.*?)^end\b", re.S | re.M)
CONTINUES = {"+", "-", "*", "/", "//", "^", "=", ",", "(", "[", "{"}
BLOCKS = ("for", "while", "if", "let", "begin", "do", "try")


def functions(text: str):
    """(name, arguments, body, line of the ``function`` keyword, docstring) of each top-level function."""
    for m in FUNCTION.finditer(text):
        before = text[:m.start()].rstrip()
        doc = ""
        if before.endswith('"""'):
            start = before.rfind('"""', 0, len(before) - 3)
            doc = before[start + 3:-3] if start >= 0 else ""
        line = text.count("\n", 0, m.start()) + 1
        yield m.group(1), m.group(2), m.group(3), line, doc


def statements(toks: list[Tok]) -> list[list[Tok]]:
    out, cur, depth = [], [], 0
    for t in toks:
        if t.text in ("(", "[", "{"):
            depth += 1
        elif t.text in (")", "]", "}"):
            depth -= 1
        if (t.kind == "nl" or t.text == ";") and depth == 0:
            if cur and cur[-1].text not in CONTINUES:
                out.append(cur)
                cur = []
            continue
        cur.append(t)
    if cur:
        out.append(cur)
    return out


def _set(env: dict, target: list[Tok], value, parser_env: dict, functions: dict) -> None:
    name = target[0].text
    if len(target) == 1:
        env[name] = value
        return
    if target[1].text != "[" or target[-1].text != "]" or name not in env:
        raise Unsupported(f"assignment to {' '.join(t.text for t in target)}")
    arr = env[name]
    if not isinstance(arr, Array):
        raise Unsupported(f"{name} is not an array")
    idx = [_index(part, parser_env, functions) for part in _split(target[2:-1])]
    if len(idx) == 1 and arr.items is None and len(arr.rows) == 1 == len(arr.rows[0]):
        idx = [[1], idx[0]]                  # A[1] of a 1×1 matrix
    if len(idx) == 1 and arr.items is not None:
        _put(arr.items, idx[0], value)
    elif len(idx) == 2 and arr.rows is not None and len(idx[0]) == 1:
        _put(arr.rows[idx[0][0] - 1], idx[1], value)
    else:
        raise Unsupported(f"an index of {name} of this shape")


def _split(toks: list[Tok]) -> list[list[Tok]]:
    parts: list[list[Tok]] = [[]]
    for k, t in enumerate(toks):
        if t.text == "," and _top(toks, k):
            parts.append([])
        else:
            parts[-1].append(t)
    return parts


def _index(part: list[Tok], env: dict, functions: dict) -> list[int]:
    """One index: ``i`` → [i]; ``i:j`` → [i, …, j]."""
    colon = [k for k, t in enumerate(part) if t.text == ":" and _top(part, k)]
    bounds = [part] if not colon else [part[:colon[0]], part[colon[0] + 1:]]
    ints = [integer(_value(b, env, functions)) for b in bounds]
    if None in ints:
        raise Unsupported("a non-integer index")
    return list(range(ints[0], ints[-1] + 1))


def _put(target: list, where: list[int], value) -> None:
    if len(where) == 1:
        target[where[0] - 1] = value
        return
    items = value.items if isinstance(value, Array) and value.items is not None else (
        value.rows[0] if isinstance(value, Array) and len(value.rows) == 1 else None)
    if items is None or len(items) != len(where):
        raise Unsupported("a slice assignment of a different length")
    for k, v in zip(where, items, strict=True):
        target[k - 1] = v


def run(body: str, line0: int, functions: dict, env: dict | None = None):
    """The value of the function body (its ``return`` or last expression)."""
    env = dict(env or {})
    env.setdefault("true", True)
    env.setdefault("false", False)
    env.setdefault("Inf", "Inf")
    env.setdefault("undef", "undef")
    result = None
    for st in statements(tokenize(body, line0)):
        if st[0].text in BLOCKS or st[0].text == "@assert":
            raise Unsupported(f"a {st[0].text} statement at line {st[0].line}")
        if st[0].text in ("local", "const"):
            st = st[1:]
        if st[0].text == "return":
            st = st[1:]
        eq = next((k for k, t in enumerate(st) if t.text == "=" and _top(st, k)), None)
        if eq is not None:
            target, rhs = st[:eq], st[eq + 1:]
            _set(env, target, _value(rhs, env, functions), env, functions)
            continue
        result = _value(st, env, functions)
    return result


def _top(st: list[Tok], k: int) -> bool:
    depth = 0
    for t in st[:k]:
        depth += (t.text in "([{") - (t.text in ")]}")
    return depth == 0


def _value(toks: list[Tok], env: dict, functions: dict):
    toks = [t for t in toks if not t.text.startswith("@")]
    p = Parser(toks, env, functions)
    x = p.expr()
    if p.peek() is not None:
        raise Unsupported(f"cannot read {p.peek().text!r} at line {p.peek().line}")
    return x


def positional(args: list) -> list:
    return [a for a in args if not isinstance(a, tuple)]


def keywords(args: list) -> dict:
    return dict(a for a in args if isinstance(a, tuple))


def integer(v) -> int | None:
    return int(v.exact) if isinstance(v, Val) and v.exact is not None and v.exact.is_Integer else None
