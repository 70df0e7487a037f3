"""The issue-18 moonshot, numerically: G-symplectic, parasitism-free, diagonally implicit GLMs of
order 4 with θ ≡ 0 (s = 4, r = 3, V the rotation by 2π/3, G = diag(1, −1/4, −1/4), the structure of
GLM43) — how large can the imaginary stability interval Y* be, and at what error constant?

The members are B(h, q) of ``analysis.family.parasitism_free_rows`` (μ = 0 identically) with A, U
from ``analysis.family.dirk_stages`` (G-symplectic identically); the three remaining equations (the
order-3 and order-4 conditions of the underlying one-step method with θ ≡ 0,
``numeric.objectives.order_residuals``) are met by least-squares projection from random starts, and
a (1+1) evolution strategy moves along the feasible set for two goals:

* the largest Y* with every diagonal entry of A ≥ 0;
* the smallest principal error norm with Y* ≥ 2.

Numeric only: these members are not certified (the exact solve of three order conditions in three
unknowns over Q(√3) did not finish within 15 minutes with sympy's Gröbner bases).

    python benchmarks/moonshot.py [--starts N] [--iterations K] [--write docs/design.md]
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from doc_blocks import write_block  # noqa: E402

from tableau_lab.analysis.family import dirk_stages, glm43_structure, parasitism_free_rows  # noqa: E402
from tableau_lab.exact.tableau_json import load  # noqa: E402
from tableau_lab.numeric.arith import arith  # noqa: E402
from tableau_lab.numeric.objectives import (  # noqa: E402
    NumericGLM,
    growth,
    imaginary_interval,
    order_residuals,
    real_interval,
    series_defects,
)

BLOCK = "moonshot-table"
ORDER = 4
FEASIBLE = 1e-10          # max |order residual| of a feasible member
Y_GOAL = 2.0

GLM43 = load(ROOT / "methods" / "glm43.json")
V, G = (arith("float64").matrix(M) for M in glm43_structure())


def member(x) -> NumericGLM:
    B = parasitism_free_rows(np.asarray(x[:4], dtype=float), np.asarray(x[4:], dtype=float),
                             lambda rows: np.array(rows, dtype=float))
    A, U = dirk_stages(B, G, V, lambda n, k: np.zeros((n, k)))
    return NumericGLM(A, U, B, V)


def project(x0):
    with np.errstate(all="ignore"):
        r = least_squares(lambda x: order_residuals(member(x), ORDER), x0, xtol=1e-15, ftol=1e-15, gtol=1e-15,
                          max_nfev=2000)
    return r.x if np.all(np.isfinite(r.fun)) and np.max(np.abs(r.fun)) < FEASIBLE else None


def describe(g: NumericGLM) -> dict:
    return {"Y*": imaginary_interval(g), "X*": real_interval(g), "error": series_defects(g, ORDER)[1],
            "diag": np.diag(g.A), "d1": g.B[0, 0], "mu": max(abs(m) for m in growth(g))}


GOALS = {
    # name: (admissible, value to minimise), both of a member; each computes only what it needs
    "largest Y*, diagonal ≥ 0": (lambda g: bool(np.all(np.diag(g.A) >= 0)), lambda g: -imaginary_interval(g)),
    f"smallest error, Y* ≥ {Y_GOAL:g}": (lambda g: imaginary_interval(g) >= Y_GOAL,
                                         lambda g: series_defects(g, ORDER)[1]),
}


def evolve(x, goal, iterations, rng):
    ok, value = GOALS[goal]
    best, step = value(member(x)), 0.1
    for _ in range(iterations):
        y = project(x + step * rng.standard_normal(len(x)))
        g = None if y is None else member(y)
        if g is not None and ok(g) and value(g) < best:
            x, best, step = y, value(g), step * 1.5
        else:
            step = max(step * 0.95, 1e-7)
    return x


def run(starts: int, iterations: int, seed: int = 0):
    rng = np.random.default_rng(seed)
    t0 = time.perf_counter()
    pool = []
    for _ in range(starts):
        x = project(rng.uniform(-2, 2, 8))
        if x is not None:
            pool.append((x, describe(member(x))))
    rows = {}
    for goal, (ok, value) in GOALS.items():
        seeds = sorted((x for x, _ in pool if ok(member(x))), key=lambda x: value(member(x)))[:2]
        found = [evolve(x, goal, iterations, rng) for x in seeds]
        if found:
            k = int(np.argmin([value(member(x)) for x in found]))
            rows[goal] = (found[k], describe(member(found[k])))
    return pool, rows, time.perf_counter() - t0


def rank(x, tol=1e-5) -> int:
    """The rank of the order residuals' Jacobian at x (central differences; singular values below
    tol relative to the largest count as zero)."""
    J = np.array([(order_residuals(member(x + 1e-6 * e), ORDER) - order_residuals(member(x - 1e-6 * e), ORDER)) / 2e-6
                  for e in np.eye(len(x))]).T
    sv = np.linalg.svd(J, compute_uv=False)
    return int(np.sum(sv > tol * sv[0]))


def table(pool, rows, seconds, starts, iterations) -> str:
    g43 = describe(NumericGLM.of(GLM43))
    rng = np.random.default_rng(1)             # the order-1, 2 residuals at random (unprojected) members
    low = max(float(np.max(np.abs(order_residuals(member(rng.uniform(-2, 2, 8)), 2)))) for _ in range(20))

    def fmt(v):
        return (f"| {v['Y*']:.4f} | {v['X*']:.3g} | {v['error']:.4g} | "
                f"{', '.join(f'{a:.3f}' for a in v['diag'])} | {v['d1']:.4f} | {v['mu']:.1e} |")

    ys = np.array([v["Y*"] for _, v in pool])
    nonneg = [v for _, v in pool if np.all(v["diag"] >= 0)]
    lines = [f"*Generated by `python benchmarks/moonshot.py --starts {starts} --iterations {iterations} --write "
             f"docs/design.md` ({seconds:.0f} s on this machine); not certified.*", "",
             f"{len(pool)} of {starts} random starts projected onto the order-4 (θ ≡ 0) conditions; on those, "
             f"Y* ≥ {Y_GOAL:g} at {int(np.sum(ys >= Y_GOAL))}, and the largest Y* with every a_ii ≥ 0 is "
             f"{max((v['Y*'] for v in nonneg), default=float('nan')):.4f}. "
             "The order-1 and order-2 residuals are at most "
             f"{low:.1e} at 20 random members (they hold identically); "
             "the Jacobian of the order-3 and order-4 residuals "
             f"has rank {', '.join(str(rank(x)) for x, _ in rows.values())} at the members below.", "",
             "| member | Y* | X* (real) | error norm | diag(A) | d₁ | max \\|μ\\| |", "|---|---|---|---|---|---|---|",
             "| GLM43 (`glm43.json`) " + fmt(g43)]
    for goal, (_, v) in rows.items():
        lines.append(f"| {goal} " + fmt(v))
    lines += ["", "Points (h₁…h₄, q₁…q₄):", ""]
    lines += [f"- {goal}: `{', '.join(f'{float(c)!r}' for c in x)}`" for goal, (x, _) in rows.items()]
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--starts", type=int, default=150)
    ap.add_argument("--iterations", type=int, default=400)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--write", metavar="FILE")
    args = ap.parse_args(argv)
    pool, rows, seconds = run(args.starts, args.iterations, args.seed)
    text = table(pool, rows, seconds, args.starts, args.iterations)
    print(text)
    if args.write:
        write_block(args.write, BLOCK, text)


if __name__ == "__main__":
    main()
