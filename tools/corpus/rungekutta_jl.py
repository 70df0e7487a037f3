"""JuliaGNI RungeKutta.jl's tableaux written as data: the ``Tableau*`` functions of
src/tableaus/{erk,dirk,firk}.jl, each ending in ``Tableau{T}(:Name, o, a, b, c; R∞=…)`` with
``@big`` array literals (``1//2`` rationals, ``1/2``, ``√15``).  The claim is the order argument
``o``.  The Gauss, Lobatto and Radau families (gauss.jl, lobatto.jl, radau.jl, prk.jl) are computed
by algorithms from the number of stages (roots of Legendre polynomials in BigFloat), not written
as data: they are not extracted (the README counts them).  Usage::

    python -m tools.corpus.rungekutta_jl /work/.mirror/JuliaGNI+RungeKutta.jl/repo [OUT]
"""
from __future__ import annotations

import re
from pathlib import Path

from .expr import Unsupported
from .julia import functions, integer, positional, run
from .writer import Library, Tableau, command_line, show

DATA = ("src/tableaus/erk.jl", "src/tableaus/dirk.jl", "src/tableaus/firk.jl")
COMPUTED = ("src/tableaus/gauss.jl", "src/tableaus/lobatto.jl", "src/tableaus/radau.jl", "src/tableaus/prk.jl")


def tableau(*args):
    pos = positional(args)
    if len(pos) != 5:
        raise Unsupported(f"Tableau with {len(pos)} positional arguments")
    _, o, a, b, c = pos
    return {"A": a, "b": b, "c": c, "order": integer(o)}


def extract(git_dir: str, out: Path) -> Library:
    lib = Library(out, "rungekutta_jl", "JuliaGNI/RungeKutta.jl", git_dir)
    for path in DATA:
        for name, args, body, line, doc in functions(show(git_dir, path)):
            where = lib.provenance(path, line)
            if "args..." in args:
                lib.skip(name, "an alias: builds another Tableau function's tableau under a new name", where)
                continue
            try:
                r = run(body, line + 1, {"Tableau": tableau})
                if not isinstance(r, dict):
                    raise Unsupported("the function does not end in Tableau(…)")
            except Unsupported as exc:
                lib.skip(name, f"unreadable: {exc}", where)
                continue
            first = " ".join(doc.split("```")[0].split())
            claims = {"order": r["order"]}
            notes = ["claims read from the order argument o of Tableau{T}(:Name, o, a, b, c)"]
            if re.search(r"\bsymplectic\b", first) and not re.search(r"non-?symplectic", first):
                claims["symplectic"] = True
                notes.append("symplectic: true read from the docstring")
            lib.add(Tableau(name=name[len("Tableau"):], kind="rk", A=r["A"], b=r["b"], c=r["c"],
                            claims={k: v for k, v in claims.items() if v is not None},
                            notes=notes + [f"docstring: {first}"],
                            source=f"RungeKutta.jl, {path}, function {name}", provenance=where))
    for path in COMPUTED:
        text = show(git_dir, path)
        for m in re.finditer(r"^function (\w+)\(", text, re.M):
            if m.group(1).startswith(("Tableau", "PartitionedTableau")):
                lib.skip(m.group(1), "a family computed by an algorithm from the number of stages, not data",
                         lib.provenance(path, text.count("\n", 0, m.start()) + 1))
    return lib


if __name__ == "__main__":
    command_line(extract, "tools.corpus.rungekutta_jl")
