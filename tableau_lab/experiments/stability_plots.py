"""Stability plots (matplotlib, Agg backend) from an exact ``StabilityResult``: the region of the
complex z-plane where every root of P(w, z) has |w| ≤ 1, and the root moduli |w| along the
imaginary axis (x = hω for partitioned methods) with the computed Y* marked.  The exact
polynomial is converted once to floating-point coefficients and its roots are taken on a grid;
the exact analysis (``analysis.stability``) is what the figures illustrate, not what they prove.
Y* is printed as a decimal in the figures; its exact form is the figures' caption (the files'
metadata, :func:`~tableau_lab.experiments.figure_style.save`) and in ``tableau-lab stability``'s
report."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import sympy as sp

from . import figure_style as style

__all__ = ["coefficient_array", "root_moduli", "draw_region", "draw_axis_moduli", "draw_stability"]


def coefficient_array(polynomial, variable: str = "z") -> np.ndarray:
    """C[k, l] = the coefficient of w^k v^l of the exact polynomial (v = z or x), as floats."""
    P = sp.Poly(sp.sympify(polynomial), sp.Symbol("w"), sp.Symbol(variable))
    r, d = P.degree(0), max(P.degree(1), 0)
    C = np.zeros((r + 1, d + 1))
    for (k, l), c in P.terms():
        C[k, l] = float(c)
    return C


def root_moduli(C: np.ndarray, values) -> np.ndarray:
    """|w| of the r roots of Σ C[k, l] w^k v^l at each complex v (shape: values.shape + (r,));
    a root at infinity (vanishing leading coefficient) is +inf."""
    v = np.asarray(values, dtype=complex)
    flat = v.ravel()
    powers = flat[:, None] ** np.arange(C.shape[1])[None, :]          # (N, d + 1)
    coeffs = powers @ C.T.astype(complex)                              # (N, r + 1): w^0 .. w^r
    r = C.shape[0] - 1
    lead = coeffs[:, r]
    bad = np.abs(lead) < 1e-300
    lead = np.where(bad, 1.0, lead)
    monic = coeffs[:, :r] / lead[:, None]
    comp = np.zeros((flat.size, r, r), dtype=complex)
    if r > 1:
        comp[:, 1:, :-1] = np.eye(r - 1)
    comp[:, :, -1] = -monic
    mods = np.abs(np.linalg.eigvals(comp))
    mods[bad] = np.inf
    return mods.reshape(v.shape + (r,))


def _ymax(result) -> float:
    Y = result.imaginary_interval
    return 4.0 if Y == sp.oo or Y == 0 else 1.6 * float(Y)


def _caption(result) -> str:
    """The exact Y* (the figures print it as a decimal)."""
    return f"{result.method}: Y* = {sp.sstr(result.imaginary_interval)} ({result.interval_kind}), exactly"


def draw_region(result, target: Path, n: int = 401) -> Path:
    """The region {z : every root |w| ≤ 1} of an RK method or GLM, with ±iY* marked."""
    plt = style.pyplot()
    C = coefficient_array(result.polynomial, result.variable)
    ext = _ymax(result) * 1.25
    xs, ys = np.linspace(-ext, ext / 2, n), np.linspace(-ext, ext, n)
    Zg = xs[None, :] + 1j * ys[:, None]
    rho = root_moduli(C, Zg).max(axis=-1)
    fig, ax = plt.subplots(figsize=style.SQUARE_SIZE)
    ax.contourf(xs, ys, (rho <= 1 + 1e-9).astype(float), levels=[0.5, 1.5], colors=[style.PALETTE[5]], alpha=0.5)
    ax.contour(xs, ys, np.minimum(rho, 10), levels=[1.0], colors="k", linewidths=0.8)
    ax.axhline(0, color="grey", lw=0.5), ax.axvline(0, color="grey", lw=0.5)
    Y = result.imaginary_interval
    if Y not in (0, sp.oo):
        ax.plot([0, 0], [-float(Y), float(Y)], color=style.PALETTE[1], lw=2.5, marker="None", linestyle="-",
                label=f"$|y| < Y^* = {style.decimal(Y)}$ on the imaginary axis")
        style.legend(ax, "below", ncols=1)
    ax.set_xlabel(r"$\mathrm{Re}\,z$"), ax.set_ylabel(r"$\mathrm{Im}\,z$")
    ax.set_aspect("equal")
    style.title(ax, f"{style.plain(result.method)}: every root $|w| \\leq 1$ (shaded)")
    style.save(fig, Path(target), caption=_caption(result))
    return Path(target)


def draw_axis_moduli(result, target: Path, n: int = 2000) -> Path:
    """|w| of every root along the imaginary axis z = iy (or x = hω), with Y* marked."""
    plt = style.pyplot()
    C = coefficient_array(result.polynomial, result.variable)
    ys = np.linspace(0, _ymax(result), n)
    vals = 1j * ys if result.variable == "z" else ys.astype(complex)
    mods = np.sort(root_moduli(C, vals), axis=-1)
    fig, ax = plt.subplots(figsize=(style.PRINT_WIDTH, 3.4))
    for k in range(mods.shape[1]):
        ax.plot(ys, mods[:, k], label=f"root {k + 1}" if mods.shape[1] > 1 else "$|w|$", **style.series_style(k))
    ax.axhline(1, color="grey", lw=0.6, ls=":")
    Y = result.imaginary_interval
    if Y not in (0, sp.oo):
        ax.axvline(float(Y), color="0.3", lw=1.0, ls="--",
                   label=f"$Y^* \\approx {style.decimal(Y)}$ ({style.plain(result.interval_kind)})")
    a = "$y$ ($z = iy$)" if result.variable == "z" else r"$x = h\omega$"
    ax.set_xlabel(a), ax.set_ylabel("$|w|$")
    top = np.nanmax(np.where(np.isfinite(mods), mods, np.nan))
    ax.set_ylim(0, min(max(1.5, 1.05 * top), 3))
    style.legend(ax, "right")
    style.title(ax, f"{style.plain(result.method)}: root moduli on the axis")
    style.save(fig, Path(target), caption=_caption(result))
    return Path(target)


def draw_stability(result, out: Path, stem: str) -> list:
    """Both figures (the region only for y′ = λy, not for partitioned methods) into ``out``."""
    out = Path(out)
    paths = [draw_axis_moduli(result, out / f"{stem}_axis.png")]
    if result.variable == "z":
        paths.insert(0, draw_region(result, out / f"{stem}_region.png"))
    return paths
