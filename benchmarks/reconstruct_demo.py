"""Reconstruction (issue 33, item 3) on decimal copies of shipped tableaux: each entry that is not an
integer written to N significant digits by mpmath (the correctly rounded decimal, ± half a unit in
its last digit: the decimal file format's ball), then ``tl.reconstruct``; one block per case with
the summary, the proof about the exact candidate, and whether the candidate equals the shipped
tableau exactly.  docs/reconstruction.md quotes its output.

    python benchmarks/reconstruct_demo.py                  # the cases of docs/reconstruction.md (gauss2:30 in full)
    python benchmarks/reconstruct_demo.py --entries sdirk34:30   # one case with its table of entries
    python benchmarks/reconstruct_demo.py --library 30     # every shipped tableau at 30 digits, one line each

Times are CPU seconds of this process (``time.process_time``: the machine is shared).
"""
from __future__ import annotations

import argparse
import json
import random
import sys
import time
from importlib import resources
from pathlib import Path

import flint
import mpmath
import sympy as sp

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT)]
import tableau_lab as tl  # noqa: E402  (after the path: the checkout's package)
from tableau_lab.exact.grammar import parse_entry  # noqa: E402  (after the path)
from tableau_lab.exact.recognise import recognise  # noqa: E402  (after the path)
from tableau_lab.exact.tableau_json import to_dict  # noqa: E402  (after the path)

CASES = ("rk4:20", "dormand_prince54:20", "gauss2:30", "sdirk34:30", "glm6_moonshot:60", "gauss:4:40", "gauss2:5")
SHOWN = "gauss2:30"         # the case shown with its table of entries


def decimal_text(value, digits: int) -> str:
    """``value`` (exact sympy) written to ``digits`` significant digits, correctly rounded (mpmath
    rounds, working 50 digits beyond), as the numeral ``{m}e{k}`` (k: the exponent of its last digit)."""
    with mpmath.workdps(digits + 50):
        v = mpmath.mpf(sp.N(value, digits + 50))
        e10 = int(mpmath.floor(mpmath.log10(abs(v))))
        k = e10 - digits + 1                      # the exponent of the last digit written
        m = int(mpmath.nint(v / mpmath.mpf(10) ** k))
    return f"{m}e{k}"


def decimal_ball(value, digits: int):
    """The ball :func:`decimal_text` states: the correctly rounded decimal ± half a unit in its last digit."""
    text = decimal_text(value, digits)
    k = int(text.split("e")[1])
    with flint.ctx.workprec(int(digits * 3.33) + 64):
        return flint.arb(f"[{text} +/- 5e{k - 1}]")


def decimal_copy(name: str, digits: int, write=decimal_ball) -> tuple[dict, dict]:
    """A shipped tableau (or a family member, ``gauss:4``) with every entry that is not an integer
    replaced by ``write(value, digits)`` (its decimal ball; :func:`decimal_text`: its decimal, for a
    ``"numbers": "decimal"`` file), and its exact entries (key → rows of sympy numbers)."""
    if ":" in name:
        data = to_dict(tl.load(name))
    else:
        data = json.loads(resources.files("tableau_lab").joinpath(f"methods/{name}.json").read_text())
    exact: dict[str, list] = {}
    for key in ("A", "b", "c", "bhat"):
        if key not in data:
            continue
        matrix = isinstance(data[key][0], list)
        balls = []
        for row in (data[key] if matrix else [data[key]]):
            vals = [parse_entry(x) for x in row]
            exact.setdefault(key, []).append(vals)
            balls.append([int(v) if v.is_Integer else write(v, digits) for v in vals])
        data[key] = balls if matrix else balls[0]
    return data, exact


def decimal_tableau(name: str, digits: int) -> tuple[dict, dict]:
    """:func:`decimal_copy` with every entry that is not an integer its decimal ball."""
    return decimal_copy(name, digits, decimal_ball)


def equals_exactly(result, exact: dict) -> bool:
    """Every entry of the candidate equals the shipped one (the difference's minimal polynomial is x)."""
    x = sp.Symbol("x")
    for key, rows in exact.items():
        got = result.tableau[key] if isinstance(result.tableau[key][0], list) else [result.tableau[key]]
        for i, row in enumerate(rows):
            for j, v in enumerate(row):
                if sp.minimal_polynomial(parse_entry(got[i][j]) - v, x) != x:
                    return False
    return True


def case(spec: str, entries: bool = False) -> None:
    name, digits = spec.rsplit(":", 1)
    data, exact = decimal_tableau(name, int(digits))
    start = time.process_time()
    r = tl.reconstruct(data)
    cpu = time.process_time() - start
    print(f"{name} from {digits} digits: {r.summary().rsplit(';', 1)[0]}; {cpu:.2f} s CPU")
    print(f"  {r.proven()}")
    if r.tableau is not None and r.refused is None:
        print(f"  equals the exact tableau: {equals_exactly(r, exact)}")
    if entries:
        print(str(r))


def misprint(name: str = "dormand_prince54", digits: int = 20, row: int = 3, column: int = 2) -> None:
    """The tableau with one entry changed in its 10th significant digit (times 1 + 10⁻⁹)."""
    data, exact = decimal_tableau(name, digits)
    wrong = exact["A"][row - 1][column - 1] * (1 + sp.Rational(1, 10 ** 9))
    data["A"][row - 1][column - 1] = decimal_ball(wrong, digits)
    r = tl.reconstruct(data)
    entry = next(e for e in r.entries if e.name == f"A row {row}, column {column}")
    print(f"{name} from {digits} digits, A row {row}, column {column} times 1 + 1e-9: {r.summary().rsplit(';', 1)[0]}")
    print(f"  {entry.line()}")
    print(f"  {r.proven()}")


def chance(seed: int = 33, count: int = 100) -> None:
    """Random 20-digit numbers: the largest margin any candidate reached, and how many were strong."""
    rng = random.Random(seed)
    best, strong = -99.0, 0
    for _ in range(count):
        digits = "".join(rng.choice("0123456789") for _ in range(20))
        with flint.ctx.workprec(160):
            r = recognise(flint.arb(f"[0.{digits} +/- 5e-21]"))
        strong += r.strong
        if r.value is not None:
            best = max(best, r.digits - r.needed)
    print(f"{count} random 20-digit numbers: {strong} recognised, best margin {best:.1f} digits (strong from 5)")


def library(digits: int) -> None:
    """Every shipped tableau from ``digits`` digits: one line each (complete, equal to the shipped
    one, the order proven), and the count."""
    names = sorted(p.name[:-5] for p in resources.files("tableau_lab").joinpath("methods").iterdir()
                   if p.name.endswith(".json"))
    exact_count = 0
    for name in names:
        data, exact = decimal_tableau(name, digits)
        r = tl.reconstruct(data)
        same = r.tableau is not None and r.refused is None and equals_exactly(r, exact)
        exact_count += same
        order = f"order {r.verified.order.order}" if r.verified is not None and r.verified.order is not None else ""
        balls = r.summary().split(" entries given as balls")[0]
        print(f"{name}: {balls} balls, {len(r.weak)} weak, {len(r.missing)} not recognised; "
              f"{'exact' if same else 'NOT reconstructed'}{'; ' + order if same and order else ''}")
    print(f"{exact_count} of {len(names)} shipped tableaux reconstructed exactly from {digits} digits")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--entries", nargs="*", metavar="NAME:DIGITS", help="cases shown with their tables of entries")
    ap.add_argument("--library", type=int, metavar="DIGITS", help="every shipped tableau at DIGITS digits")
    args = ap.parse_args(argv)
    if args.library:
        library(args.library)
        return 0
    if args.entries:
        for spec in args.entries:
            case(spec, entries=True)
        return 0
    for spec in CASES:
        case(spec, entries=spec == SHOWN)
    misprint()
    chance()
    return 0


if __name__ == "__main__":
    sys.exit(main())
