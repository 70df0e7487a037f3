"""corpus/INDEX.json and corpus/README.md from the libraries' extraction records (every number in the
README is counted here), and the source files of other kinds that were not read, counted in the
mirrors.  Usage (after the extraction scripts)::

    python -m tools.corpus.index MIRRORS [OUT]        # MIRRORS: the folder of <owner>+<name>/repo
"""
from __future__ import annotations

import json
import re
import sys
from collections import Counter
from pathlib import Path

from tableau_lab.files import atomic_write_text

from .writer import show

LIBRARIES = ("nodepy", "diffeqdevtools", "ordinarydiffeq", "sundials", "rungekutta_jl", "kauri")
#: source files of other kinds, not read: (repository, path, what, count pattern)
NOT_READ = [
    ("ketch/nodepy", "nodepy/low_storage_rk.py", "low-storage forms (2N, 2R+, 3S*): Butcher A built by NodePy from "
     "the storage coefficients, some of them floats", r"RK\[shortname\] ="),
    ("ketch/nodepy", "nodepy/linear_multistep_method.py", "linear multistep methods", r"^def \w+\("),
    ("LLNL/sundials", "src/arkode/arkode_sprk.c", "symplectic partitioned RK in the a/â (splitting) form",
     r"^static ARKodeSPRKTable arkodeSymplectic\w+\(void\)"),
    ("LLNL/sundials", "src/arkode/arkode_mri_tables.def", "multirate (MRI) coupling tables", r"ARK_MRI_TABLE\("),
    ("SciML/OrdinaryDiffEq.jl", "lib/OrdinaryDiffEqRosenbrockTableaus/src/rosenbrock_tableaus.jl", "Rosenbrock",
     r"^function "),
    ("SciML/OrdinaryDiffEq.jl", "lib/OrdinaryDiffEqRKN/src/rkn_tableaus.jl", "Runge–Kutta–Nyström", r"^function "),
    ("SciML/OrdinaryDiffEq.jl", "lib/OrdinaryDiffEqSymplecticRK/src/symplectic_tableaus.jl",
     "symplectic splitting / composition coefficients", r"^function "),
    ("SciML/OrdinaryDiffEq.jl", "lib/OrdinaryDiffEqSDIRK/src/imex_tableaus.jl", "additive (IMEX) pairs", r"^function "),
    ("SciML/OrdinaryDiffEq.jl", "lib/OrdinaryDiffEqSDIRK/src/sdirk_tableaus.jl",
     "SDIRK solver caches (struct fields γ, a21 …; RK, not yet read)", r"^function "),
    ("SciML/OrdinaryDiffEq.jl", "lib/OrdinaryDiffEqLowOrderRK/src/low_order_rk_tableaus.jl",
     "explicit RK solver caches (struct fields; RK, not yet read)", r"^function "),
    ("SciML/OrdinaryDiffEq.jl", "lib/OrdinaryDiffEqHighOrderRK/src/high_order_rk_tableaus.jl",
     "explicit RK solver caches (struct fields; RK, not yet read)", r"^function "),
    ("SciML/OrdinaryDiffEq.jl", "lib/OrdinaryDiffEqVerner/src/verner_tableaus.jl",
     "Verner solver caches (struct fields; RK, not yet read)", r"^function "),
    ("SciML/OrdinaryDiffEq.jl", "lib/OrdinaryDiffEqFeagin/src/feagin_tableaus.jl",
     "Feagin solver caches (struct fields; RK, not yet read)", r"^function "),
    ("SciML/OrdinaryDiffEq.jl", "lib/OrdinaryDiffEqFIRK/src/firk_tableaus.jl",
     "Radau IIA solver caches (transformed, not Butcher form)", r"^function "),
]


def index(out: Path) -> list[dict]:
    rows = []
    for lib in LIBRARIES:
        for f in sorted((out / lib).glob("*.json")):
            if f.name in ("extraction.json", "nodepy_reference.json"):
                continue
            d = json.loads(f.read_text(encoding="utf-8"))
            rows.append({"file": f"{lib}/{f.name}", "library": lib, "name": d["name"], "kind": d["kind"],
                         "numbers": d.get("numbers", "exact"), "stages": len(d["A"]),
                         "embedded": "bhat" in d, "order": d["claims"].get("order"),
                         "embedded_order": d["claims"].get("embedded_order"), "integer_digits": integer_digits(d)})
    return rows


def integer_digits(d: dict) -> int:
    """The longest integer written in the file's entries (the grammar's ``integer_digits`` limit)."""
    texts = [str(x) for key in ("A", "b", "c", "bhat") for x in (sum(d[key], []) if key == "A" else d.get(key, []))]
    exact = [t for t in texts if not re.fullmatch(r"-?\d+(\.\d*)?([eE][+-]?\d+)?", t) or t.lstrip("-").isdigit()]
    return max((len(m) for t in exact for m in re.findall(r"\d+", t)), default=0)


def not_read(mirrors: Path) -> list[dict]:
    out = []
    for repo, path, what, pattern in NOT_READ:
        text = show(str(mirrors / repo.replace("/", "+") / "repo"), path)
        out.append({"repository": repo, "file": path, "kind": what,
                    "functions": len(re.findall(pattern, text, re.M))})
    return out


def library_section(rec: dict, rows: list[dict]) -> list[str]:
    mine = [r for r in rows if r["library"] == rec["library"]]
    numbers = Counter(r["numbers"] for r in mine)
    reasons = Counter(re.sub(r":.*", "", s["reason"]) for s in rec["skipped"])
    lines = [f"### {rec['library']} — [{rec['repository']}](https://github.com/{rec['repository']}) "
             f"at `{rec['commit']}`", "",
             f"* files read: {', '.join('`' + f + '`' for f in rec['files_read'])}",
             f"* tableaux: **{rec['tableaux']}** ({numbers['exact']} exact, {numbers['decimal']} decimal; "
             f"{sum(r['embedded'] for r in mine)} with embedded weights `bhat`; "
             f"{sum(r['order'] is not None for r in mine)} with a claimed order)",
             f"* skipped: {len(rec['skipped'])}" + ("" if not reasons else " — " + "; ".join(
                 f"{n} {why}" for why, n in sorted(reasons.items())))]
    for s in rec["skipped"]:
        lines.append(f"  * `{s['name']}`: {s['reason']}")
    lines += [f"* regenerate: `PYTHONPATH=$PWD {rec['command']}`", ""]
    return lines


def readme(records: list[dict], rows: list[dict], unread: list[dict], head: str) -> str:
    kinds = Counter(r["library"] for r in rows)
    lines = [head, "## Counts", "",
             f"{len(rows)} tableaux from {len(kinds)} libraries "
             f"({', '.join(f'{lib} {kinds[lib]}' for lib in LIBRARIES)}); "
             f"{sum(r['numbers'] == 'decimal' for r in rows)} decimal, "
             f"{sum(r['numbers'] == 'exact' for r in rows)} exact; all of kind \"rk\".", "",
             "## Per library", ""]
    for rec in records:
        lines += library_section(rec, rows)
    long = [r["file"] for r in rows if r["integer_digits"] > 100]
    lines += [f"{len(long)} files write integers longer than the grammar's default 100 digits (INDEX.json's "
              f"`integer_digits`; read them with `--entry-limit integer_digits=N`): "
              + ", ".join(f"`{f}`" for f in long) + ".", ""]
    lines += ["## Source files of other kinds, not read", "",
              "| repository | file | kind | functions (or tables) in it |", "|---|---|---|---|"]
    lines += [f"| {u['repository']} | `{u['file']}` | {u['kind']} | {u['functions']} |" for u in unread]
    lines += ["", f"{sum(u['functions'] for u in unread)} functions or tables in these files in all "
              "(a function count, not a method count: some files hold helpers too).", ""]
    return "\n".join(lines)


HEAD = """# The library corpus: Runge–Kutta tableaux from public method libraries, as data with provenance

Every file here is one tableau in tableau_lab's format (`"format": "tableau_lab/1"`), extracted
from a library's source text by the scripts in `tools/corpus/` (one per library, sharing
`expr.py`, the float-free reader of the libraries' coefficient expressions, and `writer.py`), with:

* `"provenance"`: repository, commit, file and line (the function or table that builds it) and a
  human `"source"`;
* `"claims"`: exactly what the source states — `order`, `embedded_order` (the order of the
  embedded weights `bhat`), `symplectic` — and a note saying where each was read (a constructor's
  argument, a table's field, a docstring, or a name whose convention states it: NodePy's "SSP 75",
  7 stages, order 5); nothing else is inferred, and no source here states an SSP coefficient or a
  stage order as data;
* `"numbers": "decimal"` when an entry is a decimal: it is then written as the literal's text
  as it stands in the source (a leading `.` gains its `0`); its ball is ± half a unit in its last digit.

Reading rules (in `tools/corpus/expr.py`): integer arithmetic is exact (Julia's `1/3` and C's
`SUN_RCONST(1.0)/SUN_RCONST(3.0)` are 1/3); a decimal literal with an integer value (`2.0`) or at
most 4 significant digits (`0.161`, `0.5`) is read as the exact decimal it writes; `sqrt`, `√`
give exact radicals; a longer literal (`big"…"`, `parse(BigFloat, "…")`, a C double, a Python float)
is a decimal entry; arithmetic on one gives a *derived* decimal, computed in arb (400 bits) from the
literals' balls and written two digits past its ball's width, and the file then has an absolute
`"radius"` covering every decimal entry of the file. No value goes through a Python float (NodePy's
floats are only used to find the literal they were read from, in the method's block of `loadRKM`).

`INDEX.json` lists every file with its library, name, stages, claimed orders. `nodepy/nodepy_reference.json`
holds NodePy's own computed values (order, embedded order, stage order, SSP coefficient, real
stability interval) for its loadRKM methods, from the installed nodepy (`python -m tools.corpus.nodepy_reference`).
Each library folder's `extraction.json` is the extraction record (commit, files read, skipped with reasons).

Regenerate everything (the mirrors are bare git directories, e.g. from the `fetch` of each repository):

    M=/work/.mirror
    PYTHONPATH=$PWD python -m tools.corpus.nodepy_rk $M/ketch+nodepy/repo corpus
    PYTHONPATH=$PWD python -m tools.corpus.diffeqdevtools $M/SciML+DiffEqDevTools.jl/repo corpus
    PYTHONPATH=$PWD python -m tools.corpus.ordinarydiffeq $M/SciML+OrdinaryDiffEq.jl/repo corpus
    PYTHONPATH=$PWD python -m tools.corpus.sundials $M/LLNL+sundials/repo corpus
    PYTHONPATH=$PWD python -m tools.corpus.rungekutta_jl $M/JuliaGNI+RungeKutta.jl/repo corpus
    PYTHONPATH=$PWD python -m tools.corpus.kauri $M/daniil-shmelev+kauri/repo corpus
    PYTHONPATH=$PWD python -m tools.corpus.nodepy_reference corpus
    PYTHONPATH=$PWD python -m tools.corpus.index $M corpus

The output is deterministic (the same mirrors give the same bytes). `tests/test_corpus.py` checks
every file's form and spot-checks entries against independent facts.
"""


def main(argv: list[str]) -> None:
    mirrors, out = Path(argv[0]), Path(argv[1] if len(argv) > 1 else "corpus")
    records = [json.loads((out / lib / "extraction.json").read_text(encoding="utf-8")) for lib in LIBRARIES]
    rows = index(out)
    atomic_write_text(out / "INDEX.json", json.dumps({"tableaux": rows}, indent=1, ensure_ascii=False) + "\n")
    atomic_write_text(out / "README.md", readme(records, rows, not_read(mirrors), HEAD))
    print(f"{len(rows)} tableaux indexed")


if __name__ == "__main__":
    main(sys.argv[1:])
