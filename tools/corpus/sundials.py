"""SUNDIALS ARKODE's Butcher tables: src/arkode/arkode_butcher_{erk,dirk}.def (X-macros of C).

Each ``ARK_BUTCHER_TABLE(NAME, { … })`` block allocates ``B``, sets ``B->q`` (the order) and
``B->p`` (the embedding's order, 0 without one) and assigns ``B->A[i][j]``, ``B->b[i]``,
``B->d[i]`` (the embedded weights) and ``B->c[i]`` (zero-based); ``const sunrealtype x = …;``
names a value.  Usage::

    python -m tools.corpus.sundials /work/.mirror/LLNL+sundials/repo [OUT]
"""
from __future__ import annotations

import re
from pathlib import Path

from .expr import ZERO, Array, Unsupported, parse_value
from .writer import Library, Tableau, command_line, show

FILES = ("src/arkode/arkode_butcher_erk.def", "src/arkode/arkode_butcher_dirk.def")
BLOCK = re.compile(r"^ARK_BUTCHER_TABLE\((\w+),\s*\{(.*?)^\s*\}\)", re.S | re.M)
ALLOC = re.compile(r"ARKodeButcherTable_Alloc\((\d+),\s*(\w+)\)")
STATEMENT = re.compile(r"(?:B->(\w)\[(\d+)\](?:\[(\d+)\])?|(?:const\s+)?sunrealtype\s+(\w+))\s*=\s*([^;]*);", re.S)
REF = re.compile(r"B->(\w)\[(\d+)\](?:\[(\d+)\])?")
INT_FIELD = re.compile(r"B->([qp])\s*=\s*(\d+)\s*;")


def strip_comments(text: str) -> str:
    return re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group().count("\n"), text, flags=re.S)


def ref_name(m: re.Match) -> str:
    """``B->A[4][0]`` as a name the expression reader can look up."""
    return "Bref_" + "_".join(g for g in m.groups()[:3] if g)


def assign(m: re.Match, A: list, vec: dict, env: dict) -> None:
    field, i, j, local, expr = m.groups()
    value = parse_value(REF.sub(ref_name, expr), env)
    if local:
        env[local] = value
        return
    if field == "A":
        A[int(i)][int(j)] = value
    else:
        vec[field][int(i)] = value
    env[ref_name(m)] = value


def table(name: str, body: str, where: dict) -> Tableau:
    alloc = ALLOC.search(body)
    if not alloc:
        raise Unsupported("no ARKodeButcherTable_Alloc")
    s, embedded = int(alloc.group(1)), alloc.group(2) == "SUNTRUE"
    A = [[ZERO] * s for _ in range(s)]
    vec = {k: [ZERO] * s for k in "bcd"}
    env: dict = {}
    pending = list(STATEMENT.finditer(body))
    for _ in range(3):                    # a statement may read a B-> entry assigned below it
        later = []
        for m in pending:
            try:
                assign(m, A, vec, env)
            except Unsupported as exc:
                if "Bref_" not in str(exc):
                    raise
                later.append(m)
        pending = later
    for m in pending:                     # never assigned: zero, as ARKodeButcherTable_Alloc allocates
        for ref in REF.finditer(m.group(5)):
            env.setdefault(ref_name(ref), ZERO)
        assign(m, A, vec, env)
    ints = {k: int(v) for k, v in INT_FIELD.findall(body)}
    claims = {"order": ints["q"]}
    notes = ["claims read from the table's fields: order = B->q"]
    if embedded and ints.get("p", 0) > 0:
        claims["embedded_order"] = ints["p"]
        notes[0] += ", embedded_order = B->p (embedded weights: B->d)"
    return Tableau(name=name, kind="rk", A=Array(rows=A), b=vec["b"], c=vec["c"],
                   bhat=vec["d"] if embedded else None, claims=claims, notes=notes,
                   source=f"SUNDIALS ARKODE, {where['file']}, ARK_BUTCHER_TABLE({name})", provenance=where)


def extract(git_dir: str, out: Path) -> Library:
    lib = Library(out, "sundials", "LLNL/sundials", git_dir)
    for path in FILES:
        text = strip_comments(show(git_dir, path))
        for m in BLOCK.finditer(text):
            name, body = m.group(1), m.group(2)
            where = lib.provenance(path, text.count("\n", 0, m.start()) + 1)
            if "return NULL" in body and "Alloc" not in body:
                continue                                   # ARKODE_ERK_NONE / ARKODE_DIRK_NONE
            try:
                lib.add(table(name, body, where))
            except Unsupported as exc:
                lib.skip(name, f"unreadable: {exc}", where)
    return lib


if __name__ == "__main__":
    command_line(extract, "tools.corpus.sundials")
