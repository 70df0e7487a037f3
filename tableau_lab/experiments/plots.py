"""Plots of scene data (matplotlib, Agg backend): invariant errors against time, orbits, the
parasitic components of GLM inputs.  Reads the arrays a scene run produced; never runs
anything itself."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..files import atomic_write
from ..numeric.arith import arith

__all__ = ["draw", "draw_roundoff", "draw_convergence", "draw_workprecision"]


def _figure():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(fig, target: Path):
    atomic_write(target, lambda tmp: fig.savefig(tmp, dpi=110, bbox_inches="tight"), suffix=".png")


def _floor(run) -> float:
    """Exact zeros are drawn at a tenth of the precision's unit round-off."""
    return arith(run["precision"]).eps / 10


def draw(scene, meta, arrays, out: Path) -> list:
    """Draw the scene's plots into ``out``; returns the file names."""
    plt = _figure()
    names = []
    runs = meta["runs"]
    suffix = "" if meta["complete"] else ".incomplete"
    title = scene.title + ("" if meta["complete"] else " (incomplete)")
    for kind in scene.plots:
        if kind == "invariants":
            invs = [k for k in scene.problem.invariants if any(f"run{i}_{k}" in arrays for i in range(len(runs)))]
            fig, axes = plt.subplots(len(invs), 1, figsize=(7, 2.6 * len(invs)), squeeze=False, sharex=True)
            for ax, k in zip(axes[:, 0], invs):
                for i, r in enumerate(runs):
                    t, e = arrays.get(f"run{i}_t"), arrays.get(f"run{i}_{k}")
                    if t is None or e is None:
                        continue
                    ax.semilogy(t, np.maximum(np.abs(e), _floor(r)), lw=0.8, label=r["label"])
                ax.set_ylabel(f"|{k}(y) − {k}(y₀)|")
                ax.grid(True, which="both", alpha=0.3)
            axes[-1, 0].set_xlabel("t")
            axes[0, 0].legend(fontsize=8)
            axes[0, 0].set_title(title, fontsize=10)
        elif kind in ("orbit", "state"):
            fig, ax = plt.subplots(figsize=(5.5, 5))
            for i, r in enumerate(runs):
                y = arrays.get(f"run{i}_y")
                if y is None:
                    continue
                d = y.shape[1] // 2 if scene.problem.kind == "hamiltonian" else 1
                if kind == "orbit" and d >= 2:
                    ax.plot(y[:, 0], y[:, 1], lw=0.6, label=r["label"])
                    ax.set_xlabel("q₁"), ax.set_ylabel("q₂")
                    ax.set_aspect("equal", adjustable="datalim")
                else:
                    ax.plot(y[:, 0], y[:, d], lw=0.6, label=r["label"])
                    ax.set_xlabel("q"), ax.set_ylabel("p")
            ax.legend(fontsize=8)
            ax.set_title(title, fontsize=10)
        elif kind == "parasitic":
            fig, ax = plt.subplots(figsize=(7, 3.4))
            for i, r in enumerate(runs):
                _draw_parasitic(ax, arrays, i, r)
            _long_time_axis(ax, arrays, len(runs))
            ax.set_xlabel("t"), ax.set_ylabel("parasitic component")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1))
            ax.set_title(title, fontsize=10)
        else:  # pragma: no cover - validated in load_scene
            continue
        name = f"{scene.name}_{kind}{suffix}.png"
        _save(fig, out / name)
        plt.close(fig)
        names.append(name)
    return names


def _draw_parasitic(ax, arrays, i, run):
    """Run i's parasitic components max_i |c_ζ,i| (one line per ζ; a conjugate ζ with the same
    sizes is drawn once) and, dashed, the prediction c(t₁)·exp(∫_{t₁}^t max Re eig(μ f′) dt) from
    the first nonzero record t₁; runs without components: max |y^[n]_k|, k ≥ 2."""
    t = arrays.get(f"run{i}_t")
    if t is None:
        return
    floor, drawn = _floor(run), []
    for j, mode in enumerate(run.get("parasitic_modes", [])):
        c = arrays.get(f"run{i}_parasitic_{j}")
        if c is None or any(len(c) == len(d) and np.array_equal(c, d) for d in drawn):
            continue
        drawn.append(c)
        line, = ax.semilogy(t[: len(c)], np.maximum(c, floor), lw=0.8,
                            label=f"{run['label']}: ζ = {mode['zeta']}, μ = {_short_number(mode['mu'])}")
        P = arrays.get(f"run{i}_predicted_{j}")
        start = np.flatnonzero(c > 0)
        if P is not None and len(start):
            k = start[0]
            pred = c[k] * np.exp(np.minimum(P[k:] - P[k], 700.0))
            keep = pred <= 10 * max(float(np.max(c)), floor)
            ax.semilogy(t[k: len(P)][keep], pred[keep], "--", color=line.get_color(), lw=0.8,
                        label="predicted: ∫ max Re eig(μ f′) dt")
    if not drawn:
        v = arrays.get(f"run{i}_parasitic")
        if v is not None:
            ax.semilogy(t[: len(v)], np.maximum(v, 1e-300), lw=0.8, label=f"{run['label']}: max |y^[n]_k|, k ≥ 2")


def _short_number(text: str) -> str:
    try:
        return f"{float(text):.5g}"
    except ValueError:
        return text


def _long_time_axis(ax, arrays, n_runs):
    """A logarithmic t axis when the records span more than three decades (a blow-up at t ≈ 30
    and boundedness up to t = 10⁴ both visible)."""
    ts = [arrays[f"run{i}_t"] for i in range(n_runs) if f"run{i}_t" in arrays]
    first = min((float(t[1]) for t in ts if len(t) > 1 and t[1] > 0), default=0.0)
    if first > 0 and max(float(t[-1]) for t in ts) > 1000 * first:
        ax.set_xscale("log")


def draw_roundoff(result: dict, target: Path, title: str) -> None:
    """RMS round-off (float64 − the same method at high precision) against the step number,
    with and without compensated summation, and the √n reference slope."""
    plt = _figure()
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    n = np.array(result["n"], dtype=float)
    keep = n > 0
    for key, style in (("plain", "-"), ("compensated", "-")):
        v = np.array(result[key])
        ax.loglog(n[keep], np.maximum(v[keep], 1e-20), style, lw=0.9,
                  label=f"{key} summation (fitted exponent {result['slope_' + key]:.2f})")
    ref = np.array(result["plain"])[keep]
    if len(ref):
        ax.loglog(n[keep], ref[-1] * np.sqrt(n[keep] / n[keep][-1]), "k:", lw=0.8, label="√n (Brouwer's law)")
    ax.set_xlabel("steps n"), ax.set_ylabel("RMS |y_float64 − y_exact arithmetic|")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    _save(fig, target)
    plt.close(fig)


def draw_convergence(results: list, target: Path, title: str) -> None:
    """Global error against h (log–log) for several methods, with the fitted slopes."""
    plt = _figure()
    fig, ax = plt.subplots(figsize=(7, 5))
    for c in results:
        pts = [(h, e) for h, e in zip(c["h"], c["error"]) if e is not None]
        if not pts:
            continue
        h, e = np.array(pts).T
        slope = "—" if c["slope"] is None else f"{c['slope']:.2f}"
        ax.loglog(h, e, "o-", ms=3, lw=0.8, label=f"{c['method']} (p = {c['order']}, slope {slope})")
    ax.set_xlabel("h"), ax.set_ylabel("global error at T")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6, loc="best")
    ax.set_title(title, fontsize=10)
    _save(fig, target)
    plt.close(fig)


def draw_workprecision(data: dict, target: Path) -> None:
    """Four panels: error at T and max |I − I₀| against CPU seconds and against f-evaluations,
    one line per method or peer (points that failed are left out)."""
    plt = _figure()
    fig, axes = plt.subplots(2, 2, figsize=(11, 8.5), sharey="row")
    inv = data["invariant"]
    for label, pts in data["series"].items():
        ok = sorted((p for p in pts if "cpu" in p), key=lambda p: p["cpu"])
        if not ok:
            continue
        style = "--" if label in ("DOP853", "RK45", "RK23", "Radau", "LSODA") else "-"
        for row, key in enumerate(("error", "invariant_error")):
            for col, cost in enumerate(("cpu", "nfev")):
                axes[row, col].loglog([p[cost] for p in ok], [max(p[key], 1e-17) for p in ok], style,
                                      marker="o", ms=3, label=label)
    for col, cost in enumerate(("CPU seconds", "f-evaluations")):
        axes[1, col].set_xlabel(cost)
    axes[0, 0].set_ylabel(f"error at T = {data['T']:g} (max norm)")
    axes[1, 0].set_ylabel(f"max |{inv} − {inv}₀| over the run")
    for ax in axes.flat:
        ax.grid(True, which="both", alpha=0.3)
    axes[0, 1].legend(fontsize=8)
    fig.suptitle(f"{data['title']} (work–precision; reference error ≤ {data['reference_error_bound']:.1e})")
    _save(fig, target)
    plt.close(fig)
