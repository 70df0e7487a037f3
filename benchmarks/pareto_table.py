"""The Pareto table of the known order-4 G-symplectic and symplectic methods (issue 18, item 5):
structure, order, parasitism, stability, error constant and G computed exactly by the ordinary
analyses, then energy error and time of float64 runs of the compiled loop:

    python benchmarks/pareto_table.py --write docs/design.md

rewrites the part of docs/design.md between the markers <!-- pareto-table --> and
<!-- /pareto-table --> (without --write: prints it).

Columns (none typed by hand):

* s, implicit stages (nonzero diagonal entries of A; "DIRK" when A is lower triangular), r;
* order with the best starting method / with θ ≡ 0 (``analysis.order``);
* μ, the parasitic growth parameters (``analysis.parasitism``; "—" for a method with r = 1);
* Y*, the exact imaginary-axis interval (``analysis.stability``, ``bounded_radius``);
* the principal error norm of the underlying one-step method at the order
  (``numeric.objectives.series_defects``);
* G (``analysis.symplectic.g_symplectic``: its representative and whether it is definite);
* measured: max |H − H₀| and the integration seconds the run reports (``Run.seconds``: the
  kernel is loaded by a one-step run first, and its compile/load time is excluded anyway) for
  Kepler (registry "kepler", e = 3/5, delta = 0: unperturbed) and the pendulum (q₀ = 2.3,
  p₀ = 0), h = 1/100, 10⁵ steps (t ∈ [0, 1000]), float64, the compiled loop, exact start.

The energy error is tracked by the compiled loop at every step (``integrate``'s tracking, at
y^[n]_1, against H(y₀)); the run records only its first and last states, so the seconds are the
loop's, not those of Python-side records.  For a GLM that tracking measures the principal
component z_n = wᵀy^[n] only when w = e₁ and the starting method leaves y^[0]_1 = y₀ (true of
every GLM here; checked, else the run records every 10 steps and the maximum over the records
is reported).  A run that stops (overflow, stage equations that no longer converge) is reported
as "blew up at t = …" with the seconds it ran.  Each timed run is repeated (``--repeat``) and
the fastest time kept (the machine is shared); the numbers themselves are identical.

``rows(measure=False)`` builds the exact columns only (tests/test_pareto_table.py)."""
from __future__ import annotations

import argparse
import re
import sys
import textwrap
import time
from pathlib import Path

import sympy as sp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from doc_blocks import write_block  # noqa: E402

from tableau_lab.analysis.order import order  # noqa: E402
from tableau_lab.analysis.parasitism import growth_parameters  # noqa: E402
from tableau_lab.analysis.stability import stability  # noqa: E402
from tableau_lab.analysis.symplectic import g_symplectic  # noqa: E402
from tableau_lab.exact.tableau_json import load  # noqa: E402
from tableau_lab.numeric.objectives import NumericGLM, series_defects  # noqa: E402

COMMAND = "python benchmarks/pareto_table.py --write docs/design.md"
BLOCK = "pareto-table"         # docs/design.md: <!-- pareto-table --> … <!-- /pareto-table -->
METHODS = [("example4_glm.json", "P"), ("glm_n.json", "N"), ("glm43.json", "GLM43"), ("glm4_symmetric.json", "GLM4S"),
           ("glm6_moonshot.json", "GLM6M"), ("gauss2.json", "Gauss2"), ("implicit_midpoint.json", "midpoint")]
PROBLEMS = [("Kepler", "kepler", {"e": sp.Rational(3, 5), "delta": 0}),
            ("pendulum", "pendulum", {"q0": sp.Rational(23, 10), "p0": 0})]
H = sp.Rational(1, 100)
STEPS = 100_000
WIDTH = 100               # prose lines of the markdown block are wrapped here (the tables are not)
DIAGNOSTIC_EVERY = 1000   # GLMs: an untimed second run records the parasitic components this often

# (key, header); the exact columns, then the measured ones
EXACT = [("method", "method"), ("s", "s"), ("implicit", "implicit stages"), ("r", "r"),
         ("order", "order (best start / θ ≡ 0)"), ("mu", "μ"), ("ystar", "Y*"), ("error", "error norm"), ("G", "G")]
MEASURED = [(f"{label}_{what}", f"{label} {head}") for label, _, _ in PROBLEMS
            for what, head in (("dH", "ΔH"), ("sec", "time (s)"))]


def _zero(x) -> bool:
    x = sp.sympify(x)
    return bool(x.is_zero) or (x.is_zero is None and sp.simplify(x) == 0)


def _num(x, digits: int = 4) -> str:
    return f"{float(sp.re(sp.N(x, 30))):.{digits}f}"


def exact_row(path: Path, label: str) -> dict:
    """The exact columns of one method (strings as printed, and the raw values under "_")."""
    m = load(path)
    g = m.as_glm()
    A = g.A
    implicit = sum(1 for i in range(A.rows) if not _zero(A[i, i]))
    lower = all(_zero(A[i, j]) for i in range(A.rows) for j in range(i + 1, A.cols))
    o = order(m)
    if g.r > 1:
        mus = [it.mu for it in growth_parameters(m).items]
        shown = list(dict.fromkeys("0" if _zero(mu) else f"≈ {_num(mu)}" for mu in mus))
        mu = ", ".join(shown) if shown else "none (no ζ ≠ 1 on |ζ| = 1)"
    else:
        mus, mu = [], "—"
    Y = stability(m).bounded_radius
    ystar = "∞" if Y == sp.oo else _num(Y)
    error = series_defects(NumericGLM.of(m), o.order)[1]
    gs = g_symplectic(m)
    if not gs.holds:
        G = "not G-symplectic"
    else:
        Gm = gs.G
        form = (sp.sstr(Gm[0, 0]) if Gm.shape == (1, 1) else
                "diag(" + ", ".join(sp.sstr(Gm[i, i]) for i in range(Gm.rows)) + ")" if Gm.is_diagonal() else
                sp.sstr(Gm.tolist()))
        G = f"{'definite' if gs.definite else 'indefinite' if gs.definite is False else '?'}, G = {form}"
    return {"method": f"{label} (`{path.name}`)", "s": str(g.s),
            "implicit": f"{implicit}" + (" (DIRK)" if lower else ""),
            "r": str(g.r), "order": f"{o.order} / {o.order_identity_start}", "mu": mu, "ystar": ystar,
            "error": f"{error:.3g}", "G": G,
            "_": {"m": m, "order": o.order, "order_identity": o.order_identity_start, "mu": mus, "ystar": Y,
                  "error": error, "definite": gs.definite}}


def _tracks_principal(nm) -> bool:
    """Whether the loop's every-step tracking at y^[n]_1 measures z_n = wᵀy^[n] from y₀."""
    if nm.r == 1:
        return True
    e1 = [1.0] + [0.0] * (nm.r - 1)
    return [float(x) for x in nm.w] == e1 and all(float(xi[0]) == 0 for xi in nm.starting.values())


def measure(m, problem: str, overrides: dict, repeat: int = 3) -> dict:
    """max |H − H₀| and seconds of ``m`` on the problem (h = H, STEPS steps), or where it blew up."""
    from tableau_lab.numeric.codegen import compile_problem
    from tableau_lab.numeric.export import to_numeric
    from tableau_lab.numeric.integrate import IntegrationError, integrate
    from tableau_lab.numeric.problems import get_problem

    nm = to_numeric(m)
    cp = compile_problem(get_problem(problem, **overrides))
    every = STEPS if _tracks_principal(nm) else 10
    integrate(nm, cp, cp.y0, H, 1, invariants=("H",))              # compile / load the kernel
    best = None
    for _ in range(repeat):
        try:
            run = integrate(nm, cp, cp.y0, H, STEPS, invariants=("H",), record_every=every)
        except IntegrationError as exc:
            part = exc.partial
            t = re.search(r"t = ([-+0-9.e]+)", str(exc))
            out = {"failed": True, "t": float(t.group(1)) if t else part.completed * float(H),
                   "seconds": part.seconds, "message": str(exc).split(". Non-principal")[0],
                   "parasitic": {str(k): max(v) for k, v in part.parasitic_components.items() if v}}
        else:
            out = {"failed": False, "dH": run.max_invariant_error()["H"], "seconds": run.seconds,
                   "compile": run.compile_seconds, "newton": run.newton_iterations, "fallbacks": run.fallbacks,
                   "parasitic": {str(k): max(v) for k, v in run.parasitic_components.items() if v}}
        best = out if best is None or out["seconds"] < best["seconds"] else best
    if nm.r > 1:                                  # untimed: the parasitic components along the run
        try:
            run = integrate(nm, cp, cp.y0, H, STEPS, invariants=("H",), record_every=DIAGNOSTIC_EVERY)
        except IntegrationError as exc:
            run = exc.partial
        comps = [max(c) for c in zip(*run.parasitic_components.values(), strict=False)]
        best["history"] = [(t, c) for t, c in zip(run.times, comps, strict=False) if t in (10, 100, 1000)] + \
            ([(run.times[-1], comps[-1])] if comps and run.times[-1] not in (10, 100, 1000) else [])
    return best


def rows(measure_runs: bool = True, repeat: int = 3, log=None) -> tuple[list, list]:
    """(rows, skipped): a dict per method (the EXACT keys, with measure_runs the MEASURED keys and
    the raw runs under "runs"), and (file, reason) for each method that could not be analysed."""
    out, skipped = [], []
    for name, label in METHODS:
        try:
            row = exact_row(ROOT / "methods" / name, label)
        except Exception as exc:                     # a method the analyses refuse: say why
            skipped.append((name, f"{type(exc).__name__}: {exc}"))
            continue
        if measure_runs:
            row["runs"] = {}
            for plabel, prob, overrides in PROBLEMS:
                try:
                    r = measure(row["_"]["m"], prob, overrides, repeat)
                except Exception as exc:             # not an integration failure: the run could not start
                    r = {"failed": True, "t": None, "seconds": None, "message": f"{type(exc).__name__}: {exc}",
                         "parasitic": {}}
                row["runs"][plabel] = r
                if r["failed"]:
                    row[f"{plabel}_dH"] = (f"blew up at t = {r['t']:g}" if r["t"] is not None
                                           else "run failed: " + r["message"])
                else:
                    row[f"{plabel}_dH"] = f"{r['dH']:.2e}"
                row[f"{plabel}_sec"] = "—" if r["seconds"] is None else f"{r['seconds']:.3f}"
                if log:
                    log(f"{label:9s} {plabel:9s} {row[f'{plabel}_dH']:>22s}  {row[f'{plabel}_sec']} s  "
                        + ("" if r["failed"] else f"newton sweeps {r['newton']}, fallbacks {r['fallbacks']}  ")
                        + (f"parasitic {r['history']}" if r.get("history") else ""))
        out.append(row)
    return out, skipped


def markdown_rows(table: list, columns) -> list:
    """The markdown lines (header, rule, rows) of ``table`` for ``columns`` [(key, header)]."""
    lines = ["| " + " | ".join(h for _, h in columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(row[k] for k, _ in columns) + " |" for row in table]
    return lines


def parse_table(text: str) -> tuple[list, list]:
    """(headers, rows of cells) of the first markdown table in ``text``."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip().startswith("|")]
    cells = [[c.strip() for c in ln.strip("|").split("|")] for ln in lines]
    return cells[0], [c for c in cells[2:]]


def block(table: list, skipped: list, seconds: float | None) -> str:
    head = (f"*Generated by `{COMMAND}`" + (f" ({seconds:.0f} s on this machine)" if seconds is not None else "")
            + "; every entry is computed (`benchmarks/pareto_table.py`), none typed by hand.*")
    intro = (
           "Exact: s, the implicit stages (nonzero diagonal entries of A; DIRK: A lower triangular), r, the order "
           "with the best starting method and with θ ≡ 0 (`analysis.order`), the parasitic growth parameters μ "
           "(`analysis.parasitism`; — for r = 1), the imaginary-axis interval Y* (`analysis.stability`), the "
           "principal error norm of the underlying one-step method at that order "
           "(`numeric.objectives.series_defects`), and G (`analysis.symplectic`; an RK method has G = 1). "
           f"Measured: ΔH = max |H − H₀| over every step and the integration seconds (the fastest of repeated "
           f"runs; kernel compile/load excluded) of float64 runs of the compiled loop, h = {H}, {STEPS} steps "
           "(t ∈ [0, 1000]), exact start: Kepler is the registry's `kepler` with delta = 0 (e = 3/5, "
           "unperturbed), the pendulum starts at q₀ = 2.3, p₀ = 0.")
    out = [head, "", intro, "",
           *markdown_rows(table, EXACT + (MEASURED if all("runs" in r for r in table) else []))]
    notes = []
    for row in table:
        for plabel, r in row.get("runs", {}).items():
            label = row["method"].split(" (")[0]
            if r["failed"]:
                notes.append(f"{label} on {plabel} stopped at t = {r['t']:g} after {r['seconds']:.3f} s: "
                             f"{r['message']}")
            if r.get("history"):
                notes.append(f"{label} on {plabel}: largest parasitic component (max over ζ of |c_ζ|, "
                             "`integrate`'s monitor; an untimed run recording every "
                             f"{DIAGNOSTIC_EVERY} steps) "
                             + ", ".join(f"{c:.2g} at t = {t:g}" for t, c in r["history"]))
    if notes:
        out += ["", "Runs:", "", *[textwrap.fill(n, WIDTH, initial_indent="- ", subsequent_indent="  ") for n in notes]]
    if skipped:
        out += ["", "Not in the table: " + "; ".join(f"`{n}` ({why})" for n, why in skipped) + "."]
    return "\n".join(textwrap.fill(ln, WIDTH) if not ln.startswith(("|", "- ", "  ")) else ln
                     for ln in "\n".join(out).split("\n"))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", metavar="MD", help="the markdown file to update between the markers")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per method and problem (the fastest is kept)")
    ap.add_argument("--exact-only", action="store_true", help="the exact columns only (no runs)")
    args = ap.parse_args()
    t0 = time.perf_counter()
    table, skipped = rows(not args.exact_only, args.repeat, log=lambda s: print(s, file=sys.stderr, flush=True))
    text = block(table, skipped, time.perf_counter() - t0)
    if not args.write:
        print(text)
        return 0
    path = Path(args.write)
    write_block(path, BLOCK, text)
    print(f"wrote {path} ({time.perf_counter() - t0:.1f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
