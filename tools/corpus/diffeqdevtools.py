"""SciML DiffEqDevTools.jl's tableaux: the ``construct*`` functions of src/ode_tableaus.jl.

Each returns ``ExplicitRKTableau(A, c, α, order; αEEst, adaptiveorder, fsal, stability_size)`` or
``ImplicitRKTableau(A, c, α, order; αEEst, adaptiveorder)``: the claims are the ``order``
argument and ``adaptiveorder`` (the order of the embedded weights ``αEEst``).  Usage::

    python -m tools.corpus.diffeqdevtools /work/.mirror/SciML+DiffEqDevTools.jl/repo [OUT]
"""
from __future__ import annotations

import re
from pathlib import Path

from .expr import Unsupported
from .julia import functions, integer, keywords, positional, run
from .writer import Library, Tableau, command_line, show

FILE = "src/ode_tableaus.jl"


def constructor(kind: str):
    def build(*args):
        pos, kw = positional(args), keywords(args)
        if len(pos) < 4:
            raise Unsupported(f"{kind} with {len(pos)} positional arguments")
        A, c, b, order = pos[:4]
        claims = {"order": integer(order)}
        read = [f"order = the 4th argument of {kind}"]
        if "adaptiveorder" in kw and "αEEst" in kw:
            claims["embedded_order"] = integer(kw["adaptiveorder"])
            read.append("embedded_order = its adaptiveorder (embedded weights: αEEst)")
        return {"A": A, "b": b, "c": c, "bhat": kw.get("αEEst"), "claims": claims,
                "note": "claims read from the constructor's arguments: " + "; ".join(read)}
    return build


CONSTRUCTORS = {"ExplicitRKTableau": constructor("ExplicitRKTableau"),
                "ImplicitRKTableau": constructor("ImplicitRKTableau")}


def read_functions(lib: Library, path: str, text: str, keep) -> None:
    """Every function of ``text`` that ``keep(name, body)`` selects, as a tableau of ``lib``."""
    text = text.replace("DiffEqBase.", "")
    text = re.sub(r";\s*αEEst\s*,", ", αEEst = αEEst,", text)      # Julia's keyword shorthand f(…; αEEst, …)
    for name, _args, body, line, doc in functions(text):
        if not keep(name, body):
            continue
        where = lib.provenance(path, line)
        try:
            r = run(body, line + 1, CONSTRUCTORS)
            if not isinstance(r, dict):
                raise Unsupported("the function does not end in a tableau constructor")
        except Unsupported as exc:
            lib.skip(name, f"unreadable: {exc}", where)
            continue
        first = " ".join(doc.split())[:300]
        short = name[len("construct"):] if name.startswith("construct") else name
        lib.add(Tableau(name=short, kind="rk", A=r["A"], b=r["b"], c=r["c"], bhat=r["bhat"],
                        claims={k: v for k, v in r["claims"].items() if v is not None},
                        notes=[r["note"]] + ([f"docstring: {first}"] if first else []),
                        source=f"{lib.repository}, {path}, function {name}", provenance=where))


def extract(git_dir: str, out: Path) -> Library:
    lib = Library(out, "diffeqdevtools", "SciML/DiffEqDevTools.jl", git_dir)
    read_functions(lib, FILE, show(git_dir, FILE), lambda name, body: name.startswith("construct"))
    return lib


if __name__ == "__main__":
    command_line(extract, "tools.corpus.diffeqdevtools")
