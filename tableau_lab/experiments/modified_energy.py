r"""The modified energy along numerical solutions: H̃ = H + h^k H_{k+1} + … taken to its two
lowest nonzero correction terms is conserved far better than H ([HLW06] IX.3, IX.8; for GLMs
the underlying one-step method's H̃, [HLW06] XV.2, analysis/method_series.py).

``modified_energy_run`` builds H̃ exactly (analysis/modified_hamiltonian.py, β found order by order
until ``terms`` nonzero corrections appear), substitutes the exact step size, adds it to the
problem as the invariant "H~", integrates in float64 and compares max |H − H₀| with
max |H̃ − H̃₀| over the records.  For a GLM both are evaluated at the principal component
z_n = wᵀy^[n] of the input vector: H̃ is the modified energy of the underlying one-step method in
the normalisation wᵀS(y) = y, and it is z_n that follows that map (the finishing method, if
any, is switched off for the records).  Errors are measured from the first record (H̃(z₀)).
Every kind with a series works the same way: RK methods and GLMs have B-series, partitioned RK
methods (Störmer–Verlet, symplectic Euler; kind "prk") P-series over bicoloured trees, and
``method_series(...).phi`` / ``modified_field`` / ``modified_hamiltonian`` treat both alike; the
numeric integrator runs a PRK as a one-step method (r = 1), so H̃ is tracked at y_n.

``energy_errors`` and ``plot_energy_panels`` serve scenes (experiments/scene.py, key
``"modified_energy"``): H and H̃ evaluated at the states a scene run recorded, drawn side by side.

>>> import sympy as sp
>>> from tableau_lab.exact.tableau_json import load
>>> q, p, h = sp.symbols("q p h")
>>> t = modified_energy_terms(load("methods/implicit_midpoint.json"), p**2 / 2 - sp.cos(q), (q,), (p,), 2)
>>> [k for k, _ in t], sp.expand(t[0][1])
([2, 4], -p**2*cos(q)/24 - sin(q)**2/24)
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import sympy as sp

from ..analysis.bseries import MAX_SERIES_ORDER, modified_field
from ..analysis.method_series import method_series
from ..analysis.modified_hamiltonian import modified_hamiltonian
from ..numeric.codegen import compile_problem
from ..numeric.export import to_numeric
from ..numeric.integrate import integrate
from ..numeric.problems import get_problem

__all__ = ["NAME", "ModifiedEnergyRun", "modified_energy_run", "modified_energy_terms", "plot_modified_energy",
           "problem_hamiltonian", "modified_energy_expression", "energy_errors", "plot_energy_panels"]

NAME = "H~"


def modified_energy_terms(method, H, q, p, terms: int = 2) -> list:
    """[(k, H_{k+1})]: the ``terms`` lowest nonzero corrections h^k H_{k+1} of the modified energy
    of ``method`` (exact sympy expressions in q, p, without the power of h).  ValueError if the
    modified energy does not exist that far (the conditions fail) or needs trees beyond
    MAX_SERIES_ORDER."""
    for n in range(3, MAX_SERIES_ORDER + 1):
        mh = modified_hamiltonian(modified_field(method_series(method, n).phi))
        # free trees from 2 vertices (the h¹ term): superfluous for B-series, but a P-series has the
        # bicoloured ●–○ (symplectic Euler: −h/2 H_p H_q)
        orders = [k for k in range(2, min(n, mh.order) + 1) if mh.terms(k)]
        if len(orders) >= terms:
            return [(k - 1, mh.expression(H, q, p, k)) for k in orders[:terms]]
        if mh.order < n:
            raise ValueError(f"{method.name}: no modified energy beyond free trees of order {mh.order} "
                             f"(the conditions fail at order {mh.order + 1})")
    raise ValueError(f"{method.name}: fewer than {terms} nonzero corrections up to order {MAX_SERIES_ORDER}")


def problem_hamiltonian(prob):
    """(H, q, p) of a Hamiltonian problem, its parameters replaced by their values (a smaller H̃);
    ValueError for a problem that is not Hamiltonian."""
    if prob.kind != "hamiltonian":
        raise ValueError(f"problem {prob.name!r} is not Hamiltonian: no modified energy")
    values = {s: prob.parameters[k] for k, s in prob.parameter_symbols.items()}
    return prob.hamiltonian.xreplace(values), prob.q, prob.p


def modified_energy_expression(method, prob, h, terms: int = 2):
    """(corrections, H, H̃) of ``method`` on the Hamiltonian problem ``prob`` at the exact step
    ``h``: H̃ = H + Σ h^k H_{k+1} over the ``terms`` lowest nonzero corrections
    (``modified_energy_terms``; ValueError when the method has no modified energy that far)."""
    H, q, p = problem_hamiltonian(prob)
    corr = modified_energy_terms(method, H, q, p, terms)
    return corr, H, H + sum(h**k * e for k, e in corr)


def energy_errors(prob, exprs, states) -> list:
    """[I(y_n) − I(y_0)] (float64 arrays) for each expression I in the problem's state symbols,
    at the rows of ``states`` (records × dimension; the first row is y_0)."""
    Y = np.asarray(states, dtype=float)
    if Y.ndim != 2 or not len(Y):
        return [np.zeros(0) for _ in exprs]
    out = []
    for e in exprs:
        f = sp.lambdify([list(prob.state)], e, modules="numpy")
        with np.errstate(all="ignore"):
            v = np.broadcast_to(np.asarray(f(Y.T), dtype=float), (len(Y),))
        out.append(v - v[0])
    return out


@dataclass
class ModifiedEnergyRun:
    method: str
    problem: str
    parameters: dict
    h: sp.Expr
    steps: int
    terms: list                       # [(k, H_{k+1})] exact, the h^k corrections
    evaluated_at: str
    times: np.ndarray = field(repr=False)
    err_H: np.ndarray = field(repr=False)          # H(y_n) − H(y_0) at the records
    err_Ht: np.ndarray = field(repr=False)         # H̃(y_n) − H̃(y_0)
    max_H: float = 0.0
    max_Ht: float = 0.0
    seconds: dict = field(default_factory=dict)    # symbolic, compile, integrate
    start_order: int | None = None
    parasitic: float | None = None                 # GLMs: max parasitic component at the records

    @property
    def ratio(self) -> float:
        return self.max_H / self.max_Ht if self.max_Ht > 0 else float("inf")

    @property
    def powers(self) -> list:
        return [k for k, _ in self.terms]

    def to_json(self) -> dict:
        return {"method": self.method, "problem": self.problem,
                "parameters": {k: str(v) for k, v in self.parameters.items()}, "h": str(self.h),
                "steps": self.steps, "T": float(self.h * self.steps), "powers": self.powers,
                "terms": {f"h^{k}": str(e) for k, e in self.terms}, "evaluated_at": self.evaluated_at,
                "start_order": self.start_order, "max_parasitic_component": self.parasitic,
                "records": len(self.times), "max_abs_H_error": self.max_H, "max_abs_Htilde_error": self.max_Ht,
                "ratio": self.ratio, "seconds": {k: round(v, 3) for k, v in self.seconds.items()}}


def modified_energy_run(method, problem_name, params=None, h=None, steps: int = 100000,
                        terms: int = 2, record_every: int = 10, start_order: int | None = None) -> ModifiedEnergyRun:
    """Integrate ``method`` (an exact Method) on the Hamiltonian problem ``problem_name`` (with
    ``params``: parameters or initial values, as get_problem takes them) with step ``h`` (exact)
    for ``steps`` steps, tracking H and H̃ (H plus its ``terms`` lowest nonzero corrections, at
    this h; None: 1/100).  Errors are recorded every ``record_every`` steps (the curves); the maxima also
    include the integrator's every-step tracking where it measures the same quantity (RK and
    partitioned RK methods; GLMs whose y^[n]_1 is z_n and whose start keeps z₀ = y₀).  ``start_order`` (GLMs):
    None starts with the exported starting method (the integrator's default, trees up to the
    method's order); an integer starts with the exact S of analysis/method_series.py (wᵀS(y) = y)
    on the trees up to that order, which puts y^[0] closer to the invariant manifold."""
    t0 = time.perf_counter()
    params = dict(params or {})
    h = sp.Rational(1, 100) if h is None else h if isinstance(h, sp.Basic) else sp.nsimplify(h)
    prob = get_problem(problem_name, **params)
    corr, _, Ht = modified_energy_expression(method, prob, h, terms)     # fixed parameters: a smaller H̃
    ext = replace(prob, invariants={**prob.invariants, NAME: Ht})
    t1 = time.perf_counter()
    nm = to_numeric(method)
    glm = nm.r > 1
    if glm and any(v != 0 for v in nm.finishing.values()):
        nm = replace(nm, finishing={})             # records at z = wᵀy^[n], not at the output
    if glm and start_order is not None:
        S = method_series(method, start_order).starting
        nm = replace(nm, starting={t: nm.arith.array([nm.arith.number(x) for x in xi]) for t, xi in S.items()})
    cp = compile_problem(ext)
    names = ("H", NAME)
    integrate(nm, cp, cp.y0, h, 1, invariants=names)       # compile / load the kernel
    t2 = time.perf_counter()
    run = integrate(nm, cp, cp.y0, h, steps, invariants=names, record_every=record_every)
    t3 = time.perf_counter()
    times, errs, maxima = np.array(run.times), {}, {}
    first = [1.0] + [0.0] * (nm.r - 1)
    same = not glm or [float(x) for x in nm.w] == first
    for k in names:
        e = np.array([float(x) for x in run.invariant_errors[k]])
        same = same and e[0] == 0                  # tracking is relative to I(y₀)
        errs[k] = e - e[0]                         # from the first record: H̃(z₀) for a GLM
    for k in names:
        maxima[k] = max(float(np.max(np.abs(errs[k]))), run.tracked.get(k, 0.0) if same else 0.0)
    where = "y_n"
    if glm:
        where = (f"z_n = wᵀy^[n], w = {[float(x) for x in nm.w]} (the principal component of the input vector; "
                 + ("the exported starting method)" if start_order is None
                    else f"starting method S to order {start_order})"))
    return ModifiedEnergyRun(method.name, prob.name, params, h, steps, corr, where, times, errs["H"], errs[NAME],
                             maxima["H"], maxima[NAME], {"symbolic": t1 - t0, "compile": t2 - t1, "integrate": t3 - t2},
                             start_order, max((max(c) for c in run.parasitic_components.values() if c), default=None))


def plot_modified_energy(runs, target, title: str = "") -> Path:
    """One figure (PNG, PDF, SVG): a panel per run with |H − H₀| and |H̃ − H̃₀| against t (log scale)."""
    panels = [{"t": r.times, "err_H": r.err_H, "err_Ht": r.err_Ht, "powers": r.powers,
               "title": f"{r.method} (ratio of maxima {r.ratio:.3g})"} for r in runs]
    return plot_energy_panels(panels, target, title)


def plot_energy_panels(panels, target, title: str = "", floor: float | None = None) -> Path:
    """One figure (PNG, PDF, SVG), a panel per dict of ``panels``: "t", "err_H" (H(y_n) − H₀),
    "title", and either "err_Ht" with "powers" (H̃ − H̃₀, H̃ to those powers of h) or "note"
    (why there is no H̃: the panel shows |H − H₀| alone and says so).  Exact zeros are drawn at
    ``floor`` (default: a tenth of float64's unit round-off, as in plots.py).  Written
    atomically."""
    from . import figure_style as style
    plt = style.pyplot()
    floor = np.finfo(float).eps / 10 if floor is None else floor
    fig, axes = plt.subplots(len(panels), 1, figsize=(style.PRINT_WIDTH, style.PANEL_HEIGHT * len(panels) + 0.8),
                             squeeze=False, sharex=True)
    for ax, r in zip(axes[:, 0], panels, strict=False):
        t = np.asarray(r["t"], dtype=float)
        eH = np.asarray(r["err_H"], dtype=float)
        ax.semilogy(t[: len(eH)], np.maximum(np.abs(eH), floor), lw=0.6, label=style.invariant_error("H"),
                    **style.series_style(0))
        if r.get("err_Ht") is not None:
            powers = " + ".join(f"h^{{{k}}}" for k in r["powers"])
            eT = np.asarray(r["err_Ht"], dtype=float)
            ax.semilogy(t[: len(eT)], np.maximum(np.abs(eT), floor), lw=0.6,
                        label=f"{style.invariant_error(NAME)}, $\\tilde{{H}}$ to ${powers}$", **style.series_style(1))
        else:
            ax.plot([], [], " ", label=f"no $\\tilde{{H}}$: {style.plain(r.get('note') or 'no modified energy')}")
        ax.set_ylabel("energy error")
        style.title(ax, style.plain(r.get("title", "")))
        style.legend(ax, "right")
    axes[-1, 0].set_xlabel(style.T_LABEL)
    if title:
        style.title(fig, style.plain(title))
    target = Path(target)
    style.save(fig, target)
    return target
