"""Plots of scene data (matplotlib, Agg backend): invariant errors against time, orbits, the
parasitic components of GLM inputs; round-off, convergence and work–precision figures.  Reads
the arrays a run produced; never runs anything itself.  The style (series, legends, labels,
the PNG/PDF/SVG files) is :mod:`~tableau_lab.experiments.figure_style`'s."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..numeric.arith import arith
from . import figure_style as style

__all__ = ["draw", "draw_roundoff", "draw_convergence", "draw_workprecision", "roundoff_title", "convergence_title",
           "plot_floor", "zeta_text"]


def plot_floor(run) -> float:
    """Where exact zeros are drawn on a log axis: a tenth of the unit round-off of the run's
    precision (``run["precision"]``).

    >>> plot_floor({"precision": "float64"}) == 2.0 ** -52 / 10
    True
    """
    return arith(run["precision"]).eps / 10


def draw(scene, meta, arrays, out: Path) -> list:
    """Draw the scene's plots into ``out``; returns the file names (the PNGs; each has its PDF
    and SVG beside it)."""
    plt = style.pyplot()
    names = []
    runs = meta["runs"]
    suffix = "" if meta["complete"] else ".incomplete"
    bad = sum(r["status"] == "degraded" for r in runs)
    title = style.plain(scene.title + ("" if meta["complete"] else " (incomplete)")
                        + (f" ({bad} of {len(runs)} runs DEGRADED)" if bad else ""))
    for kind in scene.plots:
        if kind == "invariants":
            invs = [k for k in scene.problem.invariants if any(f"run{i}_{k}" in arrays for i in range(len(runs)))]
            fig, axes = plt.subplots(len(invs), 1, figsize=(style.PRINT_WIDTH, style.PANEL_HEIGHT * len(invs) + 0.7),
                                     squeeze=False, sharex=True)
            for ax, k in zip(axes[:, 0], invs, strict=False):
                for i, r in enumerate(runs):
                    t, e = arrays.get(f"run{i}_t"), arrays.get(f"run{i}_{k}")
                    if t is None or e is None:
                        continue
                    ax.semilogy(t, np.maximum(np.abs(e), plot_floor(r)), label=_label(r), **style.series_style(i))
                ax.set_ylabel(style.invariant_error(k))
            axes[-1, 0].set_xlabel(style.T_LABEL)
            style.legend(list(axes[:, 0]), "right")
            style.title(fig, title)
        elif kind in ("orbit", "state"):
            fig = _phase(plt, scene.problem, kind, runs, arrays)
            style.title(fig, title)
        elif kind == "parasitic":
            fig, ax = plt.subplots(figsize=(style.PRINT_WIDTH, 3.4))
            k, modes = 0, any(f"run{i}_parasitic_0" in arrays for i in range(len(runs)))
            for i, r in enumerate(runs):
                k = _draw_parasitic(ax, arrays, i, r, k, modes)
            _long_time_axis(ax, arrays, len(runs))
            ax.set_xlabel(style.T_LABEL), ax.set_ylabel(r"parasitic component $|c_\zeta|$" if modes else _INPUTS)
            style.legend(ax, "right")
            style.title(fig, title)
        else:  # pragma: no cover - validated in load_scene
            continue
        name = f"{scene.name}_{kind}{suffix}.png"
        style.save(fig, out / name)
        names.append(name)
    return names


def _label(run) -> str:
    """A run's legend label; a degraded or failed run says so."""
    flag = {"degraded": " (DEGRADED)", "failed": " (failed)"}.get(run.get("status"), "")
    return style.plain(run["label"]) + flag


GOOD = ("completed", "stopped")       # runs drawn in the main phase panel; the others get a panel of their own


def _phase(plt, problem, kind, runs, arrays):
    """The orbit (q₁, q₂) or phase plot (first coordinate, its momentum) of every run, axes
    named by the problem's own variables; an angle (``problem.angles``) wrapped into [−π, π),
    the line broken where it wraps; degraded and failed runs in a second panel, so that a run
    that wandered off does not squeeze the others into a line."""
    names = _state_names(problem, runs, arrays)
    one = len(names) == 1                           # one variable: drawn against time
    half = len(names) // 2 if problem.kind == "hamiltonian" else 1
    orbit = kind == "orbit" and problem.kind == "hamiltonian" and half >= 2
    cols = (0, 1) if orbit or one else (0, half)
    names = ["t", *names] if one else names
    angles = set(getattr(problem, "angles", ()))
    groups = [[i for i, r in enumerate(runs) if f"run{i}_y" in arrays and (r["status"] in GOOD) == good]
              for good in (True, False)]
    groups = [g for g in groups if g] or [[]]
    fig, axes = plt.subplots(1, len(groups), figsize=(style.SQUARE_SIZE[0] * (1 + 0.6 * (len(groups) - 1)),
                                                      style.SQUARE_SIZE[1]), squeeze=False)
    for ax, members in zip(axes[0], groups, strict=False):
        for i in members:
            y = np.array(arrays[f"run{i}_y"], dtype=float)
            if one:
                y = np.column_stack([np.asarray(arrays[f"run{i}_t"], dtype=float)[: len(y)], y[:, 0]])
            xy = [y[:, c].copy() for c in cols]
            for k, c in enumerate(cols):
                if names[c] in angles:
                    xy[k] = np.mod(xy[k] + np.pi, 2 * np.pi) - np.pi
            wrapped = [v for c, v in zip(cols, xy, strict=False) if names[c] in angles]
            jumps = np.flatnonzero(np.any([np.abs(np.diff(v)) > np.pi for v in wrapped], axis=0)) + 1 if wrapped else []
            x, v = (np.insert(a, jumps, np.nan) for a in xy)
            ax.plot(x, v, lw=0.7, label=_label(runs[i]), **style.series_style(i))
        if one:
            ax.set_xlabel(style.T_LABEL), ax.set_ylabel(_axis(names[1], angles))
        else:
            ax.set_xlabel(_axis(names[cols[0]], angles)), ax.set_ylabel(_axis(names[cols[1]], angles))
        if orbit:
            ax.set_aspect("equal", adjustable="datalim")
        if len(groups) > 1:
            ax.set_title("degraded or failed runs" if members and runs[members[0]]["status"] not in GOOD
                         else "runs that completed", loc="left")
    if len(groups) == 1:
        style.legend(axes[0, 0], "below", ncols=1)
    else:                                 # the two panels hold different runs: every panel's entries
        style.legend(list(axes[0]), "below", notes=False, ncols=1, entries=[
            (ln.get_label(), {"color": ln.get_color(), "marker": ln.get_marker(), "linestyle": ln.get_linestyle()})
            for ax in axes[0] for ln in ax.get_lines()])
    return fig


def _state_names(problem, runs, arrays) -> list:
    """The problem's state variables by name; without them (a problem described by its kind
    alone, as a replot of old data may be), q, p or q1 … qk, p1 … pk, or y1 … yd."""
    state = getattr(problem, "state", None)
    if state:
        return [str(s) for s in state]
    d = next((np.shape(arrays[f"run{i}_y"])[1] for i in range(len(runs)) if f"run{i}_y" in arrays), 2)
    if problem.kind != "hamiltonian":
        return [f"y{j + 1}" for j in range(d)] if d > 1 else ["y"]
    k = d // 2
    return ["q", "p"] if k == 1 else [f"{v}{j + 1}" for v in "qp" for j in range(k)]


def _axis(name: str, angles) -> str:
    """An axis label from a state variable's name; an angle says it is taken mod 2π."""
    return f"${style.math_name(name)}$" + (r" (mod $2\pi$)" if name in angles else "")


def zeta_text(values) -> str:
    """ζ as decimals for a legend; a conjugate pair (numbers, not their printed text, compared)
    as a ± bi.

    >>> zeta_text(["1", "-1"])
    '1, -1'
    """
    zs = [style.complex_value(z) for z in values]
    if len(zs) == 2 and None not in zs and zs[0].imag != 0 and abs(zs[0] - zs[1].conjugate()) <= 1e-12 * abs(zs[0]):
        z = zs[0]
        return (f"{style.decimal(z.real)} ± " if z.real != 0 else "± ") + f"{style.decimal(abs(z.imag))}i"
    return ", ".join(style.decimal(z) for z in values)


_INPUTS = r"$\mathrm{max}_{k\geq 2}\,|y^{[n]}_k|$"     # what runs without parasitic components recorded
_PREDICTED = r", $c(t_1)\,\exp\int_{t_1}^t \max\,\mathrm{Re\,eig}(\mu f')\,ds$"      # the dashed lines


def _draw_parasitic(ax, arrays, i, run, k, modes=True) -> int:
    """Run i's parasitic components max_i |c_ζ,i| (one line per ζ; a conjugate ζ with the same
    sizes is drawn once) and, dashed, the prediction c(t₁)·exp(∫_{t₁}^t max Re eig(μ f′) dt) from
    the first nonzero record t₁; runs without components: max |y^[n]_k|, k ≥ 2 (so labelled when
    ``modes``: other runs have components).  ``k`` is the index of the next series; returns the
    next one."""
    t = arrays.get(f"run{i}_t")
    if t is None:
        return k
    floor, groups = plot_floor(run), []
    for j, mode in enumerate(run.get("parasitic_modes", [])):
        c = arrays.get(f"run{i}_parasitic_{j}")
        if c is None:
            continue
        same = next((g for g in groups if len(c) == len(g["c"]) and np.array_equal(c, g["c"])), None)
        if same is not None:
            same["zeta"].append(mode["zeta"])
            continue
        groups.append({"c": c, "zeta": [mode["zeta"]], "mu": mode["mu"], "P": arrays.get(f"run{i}_predicted_{j}")})
    label = style.plain(run["label"])
    for g in groups:
        c, P = g["c"], g["P"]
        s = style.series_style(k)
        k += 1
        ax.semilogy(t[: len(c)], np.maximum(c, floor), label=f"{label}: $\\zeta$ = {zeta_text(g['zeta'])}, "
                                                             f"$\\mu$ = {style.decimal(g['mu'])}", **s)
        start = np.flatnonzero(c > 0)
        if P is not None and len(start):
            n0 = start[0]
            with np.errstate(over="ignore"):
                pred = c[n0] * np.exp(np.minimum(P[n0:] - P[n0], 700.0))
            keep = pred <= 10 * max(float(np.max(c)), floor)
            first = not any(ln.get_label().endswith(_PREDICTED) for ln in ax.get_lines())
            ax.semilogy(t[n0: len(P)][keep], pred[keep], color=s["color"], linestyle=(0, (5, 2)), marker="None",
                        label=f"{label}: predicted" + (_PREDICTED if first else ""))
    if not groups:
        v = arrays.get(f"run{i}_parasitic")
        if v is not None:
            ax.semilogy(t[: len(v)], np.maximum(v, floor), label=f"{label}: {_INPUTS}" if modes else label,
                        **style.series_style(k))
            k += 1
    return k


def _long_time_axis(ax, arrays, n_runs):
    """A logarithmic t axis when the records span more than three decades (a blow-up at t ≈ 30
    and boundedness up to t = 10⁴ both visible)."""
    ts = [arrays[f"run{i}_t"] for i in range(n_runs) if f"run{i}_t" in arrays]
    first = min((float(t[1]) for t in ts if len(t) > 1 and t[1] > 0), default=0.0)
    if first > 0 and max(float(t[-1]) for t in ts) > 1000 * first:
        ax.set_xscale("log")


def roundoff_title(data: dict) -> str:
    """The round-off figure's title from its data file (``tableau-lab roundoff``'s JSON)."""
    return f"Round-off alone: {Path(data['method']).stem} on {data['problem']}, h = {data['h']}"


def draw_roundoff(result: dict, target: Path, title: str) -> None:
    """RMS round-off (float64 − the same method at high precision) against the step number,
    with and without compensated summation, and the √n reference slope."""
    plt = style.pyplot()
    fig, ax = plt.subplots(figsize=(style.PRINT_WIDTH, 3.4))
    n = np.array(result["n"], dtype=float)
    keep = n > 0
    for i, key in enumerate(("plain", "compensated")):
        v = np.array(result[key])
        ax.loglog(n[keep], np.maximum(v[keep], 1e-20),
                  label=f"{key} summation (fitted exponent {_slope(result['slope_' + key])})", **style.series_style(i))
    ref = np.array(result["plain"])[keep]
    if len(ref):
        ax.loglog(n[keep], ref[-1] * np.sqrt(n[keep] / n[keep][-1]), color="0.35", linestyle=":", marker="None",
                  label=r"$\propto\sqrt{n}$ (Brouwer's law)")
    ax.set_xlabel(style.STEPS_LABEL)
    ax.set_ylabel(r"RMS $|y_{\mathrm{float64}} - y_{\mathrm{high\ precision}}|$")
    style.legend(ax, "right")
    style.title(fig, style.plain(title))
    style.save(fig, target)


def _slope(s) -> str:
    return "—" if s is None else f"{s:.2f}"


def convergence_title(results: list) -> str:
    """The convergence figure's title from its data file (``tableau-lab convergence``'s JSON)."""
    c = results[0]
    return f"{c['problem']}, T = {c['T']:g}, {c['precision']}"


def draw_convergence(results: list, target: Path, title: str) -> None:
    """Global error against h (log–log), one panel per order p (the methods of that order, each
    with its fitted slope, and a reference line of slope p), panels sharing both axes, each as
    high as its legend needs."""
    plt = style.pyplot()
    groups: dict = {}
    for c in results:
        groups.setdefault(c.get("order"), []).append(c)
    orders = sorted(groups, key=lambda p: (p is None, p or 0))
    labels = {p: [f"{style.plain(c['method'])}: slope {'—' if c['slope'] is None else format(c['slope'], '.2f')}"
                  for c in groups[p]] for p in orders}
    heights = [max(style.SMALL_PANEL_HEIGHT, style.legend_height(labels[p] + ["reference"])) for p in orders]
    fig, axes = plt.subplots(len(orders), 1, figsize=(style.PRINT_WIDTH, sum(heights) + 0.7), squeeze=False,
                             sharex=True, sharey=True, gridspec_kw={"height_ratios": heights})
    for ax, p in zip(axes[:, 0], orders, strict=False):
        points = []
        for i, (c, label) in enumerate(zip(groups[p], labels[p], strict=False)):
            pts = [(h, e) for h, e in zip(c["h"], c["error"], strict=False) if e is not None and e > 0]
            if not pts:
                ax.plot([], [], label=label + " (no run finished)", **style.series_style(i))
                continue
            h, e = np.array(pts).T
            ax.loglog(h, e, label=label, **style.series_style(i))
            points.append((h, e))
        if p is not None and points:
            _reference_slope(ax, p, points)
        ax.set_title("order unknown" if p is None else f"methods of order $p = {p}$", loc="left")
        ax.set_ylabel("global error at $T$")
        style.legend(ax, "right")
    axes[-1, 0].set_xlabel(style.H_LABEL)
    style.title(fig, style.plain(title))
    style.save(fig, target)


def _reference_slope(ax, p: int, points) -> None:
    """A line of slope p through the median error at the largest h, down to the smallest error
    of the panel (not beyond the points' range of h)."""
    h0 = max(float(h.max()) for h, _ in points)
    e0 = float(np.exp(np.median([np.log(e[np.argmax(h)]) for h, e in points])))
    e_low = min(float(e.min()) for _, e in points)
    h_low = max(min(float(h.min()) for h, _ in points), h0 * (e_low / e0) ** (1 / p))
    hs = np.array([h_low, h0])
    ax.loglog(hs, e0 * (hs / h0) ** p, color="0.4", linestyle=(0, (1, 1.5)), marker="None",
              label=f"reference slope {p} ($\\propto h^{{{p}}}$)")


def draw_workprecision(data: dict, target: Path) -> None:
    """Four panels: error at T and max |I − I₀| against CPU seconds and against f-evaluations,
    one line per method or peer (points that failed are left out), each in the order of its
    sweep; peers (adaptive integrators: their points have an rtol) dashed."""
    plt = style.pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(style.PRINT_WIDTH, 6.4), sharey="row")
    inv = data["invariant"]
    for i, (label, pts) in enumerate(data["series"].items()):
        ok = sorted((p for p in pts if "cpu" in p), key=lambda p: (p.get("nfev", 0), p["cpu"]))
        if not ok:
            continue
        s = {**style.series_style(i), "linestyle": "--" if any("rtol" in p for p in pts) else "-"}
        for row, key in enumerate(("error", "invariant_error")):
            for col, cost in enumerate(("cpu", "nfev")):
                axes[row, col].loglog([p[cost] for p in ok], [max(p[key], 1e-17) for p in ok],
                                      label=style.plain(label), **s)
    for col, cost in enumerate((style.CPU_LABEL, style.NFEV_LABEL)):
        axes[1, col].set_xlabel(cost)
    axes[0, 0].set_ylabel(f"error at $T = {data['T']:g}$ (max norm)")
    axes[1, 0].set_ylabel(f"max {style.invariant_error(inv)}")
    style.legend(list(axes.flat), "below", ncols=3)
    style.title(fig, f"{style.plain(data['title'])} (work–precision; reference error ≤ "
                     f"{data['reference_error_bound']:.1e})")
    style.save(fig, target)
