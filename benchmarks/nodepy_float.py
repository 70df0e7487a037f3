"""NodePy's floating-point Runge–Kutta methods — the ones ``nodepy_compare.py`` cannot read exactly
(CMR6, PD8, SSP22star, SSP53, SSP54, SSP63, SSP75, SSP85, SSP95, Tsit5, and SSP33's embedded
weights b̂) — as decimal tableaux, through the certified analyses in ball arithmetic, against
NodePy's own values (issue 33, "what it must show", line 1).

    pip install nodepy && python benchmarks/nodepy_float.py --run    # saves reports/nodepy/float.json
    python benchmarks/nodepy_float.py --write docs/nodepy.md        # the block of docs/nodepy.md from it

**The decimals.**  NodePy holds these coefficients as binary doubles (numpy float64 or sympy Float;
CMR6 mixes them with exact rationals, which stay exact here, as does a double that is an integer:
0.0, 1.0).  Each other double x is written as its shortest decimal repr d (Python's ``repr``: the
fewest digits that read back to x — in practice the digits of NodePy's source), and the file states
one radius for all of them (``"radius"``): the largest, over the entries, of half a unit in the last
digit of d (a repr of fewer than 15 significant digits counted at 15: ``0.2`` is the double of
0.200000000000000) and half an ulp of x.  So each entry's ball contains the double, every real
number that rounds to it, and every number written with the printed digits.  The two choices the
format offers beside it fail: the exact doubles with radius 0 (the tableau exactly as NodePy
computes with it) satisfy no order condition beyond round-off, so their order is refuted at about
1e-17 (the column "order, exact doubles" shows the order certified then); half an ulp alone is
narrower than the 13 or 14 digits some sources printed, and narrower than the rounding of a
coefficient NodePy computes in floating point (a 17-digit repr states its last digit to ±5e-18,
half an ulp of 0.3 is 2.8e-17), so it refutes orders that hold to the precision the data has.

**NodePy's values**: ``rkm.order()``, ``rkm.stage_order()`` (tolerance 1e-14 on float residuals),
``rkm.absolute_monotonicity_radius()`` (bisection), ``rkm.real_stability_interval()``,
``rkm.embedded_method.order()``.  Ours: certified order and stage order, and certified enclosures
[lo, hi] of the SSP coefficient and of the real stability interval's end.  A NodePy value agrees
when it equals the certified order, or lies in the enclosure (to 1e-6 relative, NodePy's bisection
and root tolerance).  A disagreement is settled by a 50-digit mpmath evaluation on the decimal
tableau: the largest |Φ(t) − 1/γ(t)| over the trees of each order in question (an order holds to the
printed precision when it is of the size of the digits' rounding), |R(x)| between the two interval
ends, and Kraaijevanger's inequalities at the larger SSP coefficient (``nodepy_compare._decide_ssp``).
"""
from __future__ import annotations

import argparse
import functools
import importlib.util
import json
import math
import sys
import time
import warnings
from decimal import Decimal
from pathlib import Path
from types import SimpleNamespace

import mpmath
import sympy as sp

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "benchmarks")]

from doc_blocks import write_block  # noqa: E402
from nodepy_compare import _decide_ssp  # noqa: E402

from tableau_lab.analysis.certified import certified_verify  # noqa: E402
from tableau_lab.analysis.certified_findings import CERTIFIED  # noqa: E402
from tableau_lab.analysis.trees import density, trees_of_order  # noqa: E402
from tableau_lab.exact.tableau_json import from_dict_any  # noqa: E402

NAMES = ("CMR6", "PD8", "SSP22star", "SSP53", "SSP54", "SSP63", "SSP75", "SSP85", "SSP95", "Tsit5", "SSP33")
TOL = 1e-6              # relative agreement of NodePy's bisection / root finding with a certified enclosure
DIGITS = 50             # the settling evaluations (mpmath)
PADDED = 15             # a shorter repr is written with trailing zeros to this many significant digits (DBL_DIG)
BLOCK = "nodepy-float"
SAVED = ROOT / "reports" / "nodepy" / "float.json"


def _entry(x, exact_double: bool = False):
    """A NodePy coefficient as a tableau entry: an exact rational stays exact, an integer-valued
    double is that integer, any other double its shortest repr (or, ``exact_double``, its exact
    binary value written out in decimal)."""
    if isinstance(x, (sp.Rational, int)) and not isinstance(x, bool):
        return str(sp.Rational(x))
    v = float(x)
    if v.is_integer():
        return int(v)
    return str(Decimal(v)) if exact_double else repr(v)


def _half_units(text: str, v: float) -> Decimal:
    """The larger of half a unit in the last digit of ``text`` (padded to PADDED significant digits)
    and half an ulp of the double ``v``."""
    d = Decimal(text)
    last = d.as_tuple().exponent if len(d.as_tuple().digits) >= PADDED else d.adjusted() - PADDED + 1
    return max(Decimal(5) * Decimal(10) ** (int(last) - 1), Decimal(math.ulp(v)) / 2)


def _radius(entries: list) -> str | None:
    """The file's "radius": the largest half-unit of any decimal entry (module docstring), rounded up."""
    units = [_half_units(e, float(e)) for e in entries if isinstance(e, str) and "/" not in e]
    if not units:
        return None
    top = max(units)
    return f"{math.ceil(top.scaleb(-top.adjusted() + 1)) / 10:.1f}e{top.adjusted()}"


def tableau(name: str, rkm, exact_double: bool = False) -> dict:
    """The decimal tableau of a NodePy method (module docstring); b̂ of a pair included."""
    def vec(v):
        return [_entry(x, exact_double) for x in v]
    out = {"name": f"NodePy {name}", "kind": "rk", "numbers": "decimal",
           "source": f"nodepy.rk.loadRKM('{name}'): floating-point coefficients as their shortest decimal repr",
           "A": [vec(row) for row in rkm.A], "b": vec(rkm.b), "c": vec(rkm.c)}
    if getattr(rkm, "bhat", None) is not None:
        out["bhat"] = vec(rkm.bhat)
    entries = [e for k in ("A", "b", "c", "bhat") for e in (sum(out[k], []) if k == "A" else out.get(k, []))]
    radius = "0" if exact_double else _radius(entries)
    if radius is not None:
        out["radius"] = radius
    return out


def _nodepy_values(rkm) -> dict:
    calls = {"order": lambda: int(rkm.order()), "stage_order": lambda: int(rkm.stage_order()),
             "ssp": lambda: float(rkm.absolute_monotonicity_radius()),
             "real": lambda: float(rkm.real_stability_interval()),
             "embedded": lambda: int(rkm.embedded_method.order()) if hasattr(rkm, "embedded_method") else None}
    out = {}
    for key, call in calls.items():
        try:
            out[key] = call()
        except Exception as exc:         # recorded, not fatal
            out[key] = f"error: {type(exc).__name__}"
    return out


# ------------------------------------------------------------------ 50-digit settling

def _mp(entry):
    return mpmath.mpf(sp.Rational(entry).p) / sp.Rational(entry).q if isinstance(entry, str) and "/" in entry \
        else mpmath.mpf(str(entry))


def _largest_residual(d: dict, p: int, weights: str = "b") -> mpmath.mpf:
    """max |Φ(t) − 1/γ(t)| over the trees of order p, at DIGITS digits, on the decimal values of
    the tableau ``d`` (Φ(t) = bᵀ Ψ(t), Ψ(τ) = 1, Ψ([t₁ … t_k]) = Π A Ψ(tᵢ): [HNW93] II.2,
    evaluated here independently of the package's recursion)."""
    with mpmath.workdps(DIGITS):
        A = mpmath.matrix([[_mp(x) for x in row] for row in d["A"]])
        b = [_mp(x) for x in d[weights]]
        s = len(b)

        @functools.cache
        def psi(t):
            v = mpmath.matrix([1] * s)
            for child in t:
                w = A * psi(child)
                v = mpmath.matrix([v[i] * w[i] for i in range(s)])
            return v
        return max(abs(mpmath.fsum(b[i] * psi(t)[i] for i in range(s)) - mpmath.mpf(1) / density(t))
                   for t in trees_of_order(p))


def _modulus(d: dict, x: float) -> mpmath.mpf:
    """|R(x)| = |1 + x bᵀ(I − xA)⁻¹𝟙| at DIGITS digits on the decimal tableau."""
    with mpmath.workdps(DIGITS):
        A = mpmath.matrix([[_mp(e) for e in row] for row in d["A"]])
        b = mpmath.matrix([_mp(e) for e in d["b"]])
        s = len(d["b"])
        y = mpmath.lu_solve(mpmath.eye(s) - mpmath.mpf(x) * A, mpmath.matrix([1] * s))
        return abs(1 + mpmath.mpf(x) * (b.T * y)[0])


def _settle_order(d: dict, ours: int, theirs: int, weights: str = "b") -> str:
    lo, hi = sorted((ours, theirs))
    parts = [f"order {q}: max |Φ − 1/γ| = {mpmath.nstr(_largest_residual(d, q, weights), 3)}"
             for q in range(max(1, lo), hi + 2)]
    return "; ".join(parts)


def _float(x: str) -> float:
    return float(sp.Rational(x))


def _settle_interval(d: dict, ours: list, theirs: float) -> str:
    lo, hi = (_float(x) for x in ours)
    probe = -(theirs + (lo if theirs > hi else hi)) / 2
    return f"|R({probe:.6g})| = {mpmath.nstr(_modulus(d, probe), 6)} (50 digits)"


def _settle_ssp(d: dict, ours: tuple, theirs: float) -> str:
    with mpmath.workdps(DIGITS):
        A = sp.Matrix([[sp.Float(str(_mp(x)), DIGITS) for x in row] for row in d["A"]])
        b = sp.Matrix([sp.Float(str(_mp(x)), DIGITS) for x in d["b"]])
    m = SimpleNamespace(A=A, b=b, s=len(d["b"]))
    ours_mid = (_float(ours[0]) + _float(ours[1])) / 2
    side = _decide_ssp(m, ours_mid, theirs)
    return f"Kraaijevanger's inequalities at 50 digits at the larger value: {side} right"


# ------------------------------------------------------------------ one method

def _order_cell(f) -> str:
    return str(f.value) if f.status == CERTIFIED else f"≥ {f.value}?"


def _enclosure(f):
    """A certified enclosure (lo, hi) as two rationals in text, or None."""
    if f.status == CERTIFIED and isinstance(f.value, tuple) and None not in f.value:
        return [str(x) for x in f.value]
    return None


def _inside(enc, v: float) -> bool:
    lo, hi = (_float(x) for x in enc)
    return lo - TOL * max(1, abs(lo)) <= v <= hi + TOL * max(1, abs(hi))


def analyse(name: str, rkm) -> dict:
    d = tableau(name, rkm)
    t0 = time.perf_counter()
    r = certified_verify(from_dict_any(d, f"nodepy:{name}"))
    seconds = time.perf_counter() - t0
    f = {x.name: x for x in r.findings}
    theirs = _nodepy_values(rkm)
    exact = certified_verify(from_dict_any(tableau(name, rkm, exact_double=True), f"nodepy:{name}"), ssp=False)
    row = {"name": name, "s": len(rkm), "radius": d.get("radius", "0"), "seconds": seconds, "nodepy": theirs,
           "order": _order_cell(f["order"]), "stage_order": _order_cell(f["stage order"]),
           "embedded": _order_cell(f["embedded order"]) if "embedded order" in f else None,
           "ssp": _enclosure(f["SSP coefficient"]), "ssp_text": f["SSP coefficient"].statement.split(" (")[0],
           "real": _enclosure(f["real stability interval"]),
           "real_text": f["real stability interval"].statement.split(" (")[0],
           "miss": f["order"].evidence[0].text() if f["order"].evidence else "",
           "double_order": _order_cell({x.name: x for x in exact.findings}["order"]), "settled": []}
    for key, ours, weights in (("order", f["order"], "b"), ("stage_order", f["stage order"], None),
                               ("embedded", f.get("embedded order"), "bhat")):
        v = theirs.get(key)
        if ours is None or not isinstance(v, int) or ours.status == CERTIFIED and ours.value == v:
            continue
        row["settled"].append(f"{key}: ours {_order_cell(ours)}, NodePy {v}"
                              + (f" — {_settle_order(d, ours.value, v, weights)}" if weights else ""))
    for key, settle in (("ssp", _settle_ssp), ("real", _settle_interval)):
        v, enc = theirs.get(key), row[key]
        if isinstance(v, float) and enc is not None and not _inside(enc, v):
            row["settled"].append(f"{key}: ours {row[key + '_text']}, NodePy {v:.8g} — {settle(d, enc, v)}")
    return row


def _cell(ours, theirs) -> str:
    if isinstance(theirs, float):
        theirs = "∞" if math.isinf(theirs) else f"{theirs:.6g}"
    return f"{ours} / {theirs}"


def measure() -> dict:
    """Every method analysed, and NodePy's values: saved to SAVED."""
    warnings.filterwarnings("ignore")
    from importlib.metadata import version

    from nodepy import rk
    lib = rk.loadRKM("All")
    t0 = time.perf_counter()
    rows = [analyse(n, lib[n]) for n in NAMES]
    data = {"nodepy": version("nodepy"), "rows": rows, "seconds": time.perf_counter() - t0}
    from tableau_lab.files import atomic_write_text
    atomic_write_text(SAVED, json.dumps(data, indent=1, ensure_ascii=False) + "\n")
    return data


def make(data=None) -> str:
    """The block of docs/nodepy.md from the saved run (``--run`` remakes it)."""
    data = data or json.loads(SAVED.read_text())
    rows = data["rows"]
    lines = [f"NodePy {data['nodepy']}: its {len(rows)} methods with floating-point coefficients (SSP33: its b̂), "
             "certified in ball arithmetic; each cell ours / NodePy's (the SSP coefficient and the real interval: "
             f"our certified bounds); {data['seconds']:.1f} s for all, NodePy's calls and the 50-digit checks "
             "included:", "",
             "| method | s | radius | order | stage order | embedded | SSP coefficient | real interval β | "
             "order, exact doubles | s (ours) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        t = r["nodepy"]
        lines.append(f"| {r['name']} | {r['s']} | {r['radius']} | {_cell(r['order'], t['order'])} | "
                     f"{_cell(r['stage_order'], t['stage_order'])} | "
                     f"{_cell(r['embedded'], t['embedded']) if r['embedded'] else '—'} | "
                     f"{_cell(r['ssp_text'], t['ssp'])} | {_cell(r['real_text'], t['real'])} | "
                     f"{r['double_order']} | {r['seconds']:.2f} |")
    lines += ["", "The condition that bounds each certified order (the first of those whose ball excludes 0):", ""]
    lines += [f"* {r['name']}: {r['miss']}" for r in rows if r["miss"]]
    settled = [f"* {r['name']}: {s}" for r in rows for s in r["settled"]]
    lines += ["", "Disagreements, each with the 50-digit evaluation on the decimal tableau:" if settled
              else "No disagreement.", ""] + settled
    return "\n".join(lines).rstrip()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--run", action="store_true", help="analyse and save reports/nodepy/float.json (needs NodePy)")
    ap.add_argument("--write", metavar="MD", help="rewrite the block in MD from the saved run")
    args = ap.parse_args(argv)
    if args.run and importlib.util.find_spec("nodepy") is None:
        print("NodePy is not installed: pip install nodepy", file=sys.stderr)
        return 2
    text = make(measure() if args.run else None)
    print(text)
    if args.write:
        write_block(args.write, BLOCK, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
