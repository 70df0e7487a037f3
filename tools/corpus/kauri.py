"""kauri's named Runge–Kutta methods: the ``name = RK(A, b, 'Name')`` assignments of
kauri/rk_methods.py (Python literals: ``1/6``, ``0.5``, ``sqrt(15)`` from ``math``), each
followed by ``name.__doc__ = \"\"\"…\"\"\"``; the claim is an "order N" the docstring states
("The Radau IIA method of order 5").  The EES25(x), EES27(x) families take a real parameter: not
extracted (counted).  Usage::

    python -m tools.corpus.kauri /work/.mirror/daniil-shmelev+kauri/repo [OUT]
"""
from __future__ import annotations

import re
from pathlib import Path

from .expr import Parser, Unsupported, tokenize
from .writer import Library, Tableau, command_line, show

FILE = "kauri/rk_methods.py"
ASSIGN = re.compile(r"^(\w+) = RK\(", re.M)


def call_text(text: str, start: int) -> str:
    """The text of the call whose '(' is at ``start`` - 1, to its matching ')'."""
    depth, i = 1, start
    while depth:
        depth += (text[i] == "(") - (text[i] == ")")
        i += 1
    return text[start:i - 1]


def docstring(text: str, var: str) -> str:
    m = re.search(rf'^{var}\.__doc__ = """(.*?)"""', text, re.S | re.M)
    return " ".join(m.group(1).split(".. math::")[0].split()) if m else ""


def extract(git_dir: str, out: Path) -> Library:
    lib = Library(out, "kauri", "daniil-shmelev/kauri", git_dir)
    text = show(git_dir, FILE).replace("\r\n", "\n")
    for m in ASSIGN.finditer(text):
        var, line = m.group(1), text.count("\n", 0, m.start()) + 1
        where = lib.provenance(FILE, line)
        toks = [t for t in tokenize(call_text(text, m.end())) if t.kind != "nl"]   # Python: newlines inside brackets
        try:
            args = Parser(toks).args_until_end()
            if len(args) != 3 or not isinstance(args[2], str):
                raise Unsupported("RK(A, b, name) with other arguments")
        except Unsupported as exc:
            lib.skip(var, f"unreadable: {exc}", where)
            continue
        doc = docstring(text, var)
        order = re.search(r"(?<!antisymmetric )\border (\d+)\b", doc)
        lib.add(Tableau(name=var, kind="rk", A=args[0], b=args[1],
                        claims={"order": int(order.group(1))} if order else {},
                        notes=[("claims read from the docstring: " if order else "no order stated; docstring: ")
                               + repr(doc[:200])],
                        source=f"kauri, {FILE}, {var} = RK(…, {args[2]!r})", provenance=where))
    for m in re.finditer(r"^def (EES\w+)\(", text, re.M):
        lib.skip(m.group(1), "a family in a real parameter x, not one tableau",
                 lib.provenance(FILE, text.count("\n", 0, m.start()) + 1))
    return lib


if __name__ == "__main__":
    command_line(extract, "tools.corpus.kauri")
