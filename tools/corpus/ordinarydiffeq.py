"""SciML OrdinaryDiffEq.jl's Runge–Kutta tableau functions: lib/OrdinaryDiffEqExplicitTableaus/src/
tableaus_*.jl and lib/OrdinaryDiffEqImplicitTableaus/src/ode_tableaus.jl (the construct* functions
of DiffEqDevTools.jl moved into the monorepo, renamed without "construct"), read as in
:mod:`tools.corpus.diffeqdevtools`.  The solver caches' tableau structs (Tsit5, Verner, SDIRK,
Rosenbrock, RKN, IMEX … in lib/*/src/*_tableaus.jl) are not extracted (the README counts them).
Usage::

    python -m tools.corpus.ordinarydiffeq /work/.mirror/SciML+OrdinaryDiffEq.jl/repo [OUT]
"""
from __future__ import annotations

from pathlib import Path

from .diffeqdevtools import read_functions
from .writer import Library, command_line, show

EXPLICIT = "lib/OrdinaryDiffEqExplicitTableaus/src/"
FILES = tuple(EXPLICIT + f"tableaus_{k}.jl" for k in ("classic", "low_order", "order5", "order6", "order7",
                                                      "order8_9", "high_order")) \
    + ("lib/OrdinaryDiffEqImplicitTableaus/src/ode_tableaus.jl",)


def extract(git_dir: str, out: Path) -> Library:
    lib = Library(out, "ordinarydiffeq", "SciML/OrdinaryDiffEq.jl", git_dir)
    for path in FILES:
        read_functions(lib, path, show(git_dir, path), lambda name, body: "RKTableau(" in body)
    return lib


if __name__ == "__main__":
    command_line(extract, "tools.corpus.ordinarydiffeq")
