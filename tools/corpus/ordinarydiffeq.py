"""SciML OrdinaryDiffEq.jl's Runge–Kutta tableau functions: lib/OrdinaryDiffEqExplicitTableaus/src/
tableaus_*.jl and lib/OrdinaryDiffEqImplicitTableaus/src/ode_tableaus.jl (the construct* functions
of DiffEqDevTools.jl moved into the monorepo, renamed without "construct"), read as in
:mod:`tools.corpus.diffeqdevtools`.  The solver caches' tableau structs (Tsit5, Verner, SDIRK,
Rosenbrock, RKN, IMEX … in lib/*/src/*_tableaus.jl) are not extracted (the README counts them).
Usage::

    python -m tools.corpus.ordinarydiffeq /work/.mirror/SciML+OrdinaryDiffEq.jl/repo [OUT]
"""
from __future__ import annotations

import sys
from pathlib import Path

from .diffeqdevtools import read_functions
from .writer import Library, show

EXPLICIT = "lib/OrdinaryDiffEqExplicitTableaus/src/"
FILES = tuple(EXPLICIT + f"tableaus_{k}.jl" for k in ("classic", "low_order", "order5", "order6", "order7",
                                                      "order8_9", "high_order")) \
    + ("lib/OrdinaryDiffEqImplicitTableaus/src/ode_tableaus.jl",)


def extract(git_dir: str, out: Path) -> Library:
    lib = Library(out, "ordinarydiffeq", "SciML/OrdinaryDiffEq.jl", git_dir)
    for path in FILES:
        read_functions(lib, path, show(git_dir, path), lambda name, body: "RKTableau(" in body)
    return lib


def main(argv: list[str]) -> None:
    git_dir, out = argv[0], Path(argv[1] if len(argv) > 1 else "corpus")
    extract(git_dir, out).write(f"python -m tools.corpus.ordinarydiffeq {git_dir} {out}")


if __name__ == "__main__":
    main(sys.argv[1:])
