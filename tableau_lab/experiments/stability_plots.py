"""Stability plots (matplotlib, Agg backend) from an exact ``StabilityResult``: the region of the
complex z-plane where every root of P(w, z) has |w| ≤ 1, and the root moduli |w| along the
imaginary axis (x = hω for partitioned methods) with the computed Y* marked.  The exact
polynomial is converted once to floating-point coefficients and its roots are taken on a grid;
the exact analysis (``analysis.stability``) is what the figures illustrate, not what they prove.
Y* is printed as a decimal in the figures; its exact form is the figures' caption (the files'
metadata, :func:`~tableau_lab.experiments.figure_style.save`) and in ``tableau-lab stability``'s
report.

*The window* (:func:`window`) comes from the analysis, not from a fixed box: it encloses the
boundary locus {z : P(e^{iθ}, z) = 0} — every point where a root crosses the unit circle, so
every bounded piece of the stability region and every bounded instability island (Radau IIA's in
Re z > 0, BDF4's lobe) lies inside it whole — together with the real interval [−β, 0], ±iY*
and the origin.  Whether the locus is bounded is decided exactly: a root z of P(e^{iθ}, z) runs
to infinity only where the leading coefficient L(w) of P in z vanishes on |w| = 1
(:func:`~tableau_lab.exact.real_roots.disc_counts`).  An unbounded locus (Gauss: the imaginary
axis) is enclosed where |L(e^{iθ})| ≥ ``UNBOUNDED_CUT`` · max |L| (away from the escape
directions) and |z| ≤ ``UNBOUNDED_SCALE`` times the median |z| there: a view of the part near the
origin, as no window holds an unbounded curve.  The A(α) sector is drawn when it was computed.  A user's window
(``--window XMIN,XMAX,YMIN,YMAX``, ``window=`` here) overrides all this.

>>> from tableau_lab.analysis.stability import stability
>>> from tableau_lab.exact.library import family
>>> x0, x1, y0, y1 = window(stability(family("radau_iia", s=3)))      # the island in Re z > 0, whole
>>> x0 < 0 < 10.0 < x1 < 15 and y0 == -y1
True
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import sympy as sp

from ..numeric.arith import arith
from . import figure_style as style

__all__ = ["coefficient_array", "root_moduli", "boundary_locus", "locus_points", "locus_bounded", "window",
           "enclosing_window", "finite_float", "parse_window", "shade_region", "mark_intervals", "draw_moduli",
           "figure_stem", "figure_paths", "draw_region", "draw_axis_moduli", "draw_stability"]

LOCUS_POINTS = 4096        # θ samples of the boundary locus
UNBOUNDED_CUT = 0.5        # an unbounded locus is enclosed where |L(e^{iθ})| ≥ this · max |L|
UNBOUNDED_SCALE = 3.0      # … and |z| ≤ this · the median |z| there (its other large branches left out)
PAD = 0.12                 # the window's margin, relative to its larger side
MIN_ASPECT = 0.5           # neither side of the window shorter than this times the other
DEFAULT_HALF = 5.0         # half-size of the window when nothing bounded is there to enclose


def coefficient_array(polynomial, variable: str = "z") -> np.ndarray:
    """C[k, j] = the coefficient of w^k v^j of the exact polynomial (v = z or x), as floats."""
    P = sp.Poly(sp.sympify(polynomial), sp.Symbol("w"), sp.Symbol(variable))
    r, d = P.degree(0), max(P.degree(1), 0)
    C = np.zeros((r + 1, d + 1))
    for (k, j), c in P.terms():
        C[k, j] = arith().number(c)
    return C


def _roots(coeffs: np.ndarray) -> tuple:
    """The roots of each row's polynomial (coefficients of v^0 … v^r, shape (N, r + 1)) as the
    eigenvalues of its companion matrix (shape (N, r)), and a mask of the rows whose leading
    coefficient vanishes (a root at infinity)."""
    r = coeffs.shape[1] - 1
    lead = coeffs[:, r]
    bad = np.abs(lead) < 1e-300
    lead = np.where(bad, 1.0, lead)
    monic = coeffs[:, :r] / lead[:, None]
    comp = np.zeros((coeffs.shape[0], r, r), dtype=complex)
    if r > 1:
        comp[:, 1:, :-1] = np.eye(r - 1)
    comp[:, :, -1] = -monic
    return np.linalg.eigvals(comp), bad


def root_moduli(C: np.ndarray, values) -> np.ndarray:
    """|w| of the r roots of Σ C[k, l] w^k v^l at each complex v (shape: values.shape + (r,));
    a root at infinity (vanishing leading coefficient) is +inf."""
    v = np.asarray(values, dtype=complex)
    flat = v.ravel()
    powers = flat[:, None] ** np.arange(C.shape[1])[None, :]          # (N, d + 1)
    coeffs = powers @ C.T.astype(complex)                              # (N, r + 1): w^0 .. w^r
    roots, bad = _roots(coeffs)
    mods = np.abs(roots)
    mods[bad] = np.inf
    return mods.reshape(v.shape + (C.shape[0] - 1,))


def locus_bounded(polynomial, variable: str = "z") -> bool:
    """Whether the boundary locus {z : P(w, z) = 0, |w| = 1} is bounded, exactly: a root z runs to
    infinity only where the leading coefficient L(w) of P in z vanishes on the unit circle
    (counted exactly, :func:`~tableau_lab.exact.real_roots.disc_counts`)."""
    from sympy.polys.rings import ring

    from ..exact.field import field_of
    from ..exact.real_roots import disc_counts
    P = sp.Poly(sp.sympify(polynomial), sp.Symbol(variable))
    if P.degree() <= 0:
        return True
    L = sp.Poly(P.LC(), sp.Symbol("w"))
    if L.degree() <= 0:
        return True
    K = field_of(L.coeffs())
    R = ring("w", K)[0]
    return disc_counts(R.from_dict({m: K.from_sympy(c) for m, c in L.terms()}), K)[1] == 0


def boundary_locus(polynomial, variable: str = "z", n: int = LOCUS_POINTS, bounded: bool | None = None) -> np.ndarray:
    """Points z of the boundary locus, P(e^{iθ}, z) = 0 on a grid of n angles θ (floats: what the
    figure draws); of an unbounded locus (``bounded`` False, decided by :func:`locus_bounded` when
    None) the part where |L(e^{iθ})| ≥ UNBOUNDED_CUT · max |L| and |z| ≤ UNBOUNDED_SCALE · median |z|."""
    if bounded is None:
        bounded = locus_bounded(polynomial, variable)
    return locus_points(coefficient_array(polynomial, variable), bounded, n)


def locus_points(C: np.ndarray, bounded: bool, n: int = LOCUS_POINTS) -> np.ndarray:
    """:func:`boundary_locus` of the polynomial Σ C[k, l] w^k z^l given by its coefficient array
    (floats), its boundedness decided by the caller.

    >>> pts = locus_points(np.array([[-1.0, -1.0], [1.0, 0.0]]), True, 8)     # w − (1 + z): Euler
    >>> bool(np.allclose(np.abs(pts + 1), 1))
    True
    """
    if C.shape[1] < 2:
        return np.zeros(0, dtype=complex)
    w = np.exp(2j * np.pi * np.arange(n) / n)
    coeffs = (w[:, None] ** np.arange(C.shape[0])[None, :]) @ C.astype(complex)     # (n, d + 1): z^0 .. z^d
    roots, bad = _roots(coeffs)
    keep = ~bad
    if not bounded:
        lead = np.abs(coeffs[:, -1])
        keep &= lead >= UNBOUNDED_CUT * lead.max()
    pts = roots[keep].ravel()
    pts = pts[np.isfinite(pts)]
    if not bounded and pts.size:
        pts = pts[np.abs(pts) <= UNBOUNDED_SCALE * np.median(np.abs(pts))]
    return pts


def finite_float(v) -> float | None:
    """An exact value (sympy number, ∞ or None) as a float, None when it is None or not finite."""
    if v is None:
        return None
    v = sp.sympify(v)
    return None if v in (sp.oo, sp.zoo) or not v.is_finite else float(v)


def window(result, real=None, sector=None) -> tuple:
    """(xmin, xmax, ymin, ymax) of the region plot from the exact analysis (module docstring):
    :func:`enclosing_window` of the boundary locus, −β of the real interval (``real``: a
    ``RealIntervalResult``) and ±iY*."""
    return enclosing_window(boundary_locus(result.polynomial, result.variable),
                            finite_float(getattr(real, "beta", None)), finite_float(result.imaginary_interval))


def enclosing_window(points, beta: float | None = None, Y: float | None = None) -> tuple:
    """(xmin, xmax, ymin, ymax) enclosing the points z (a boundary locus), the origin, −β and
    ±iY (when given), with a margin PAD, symmetric about the real axis (P has real
    coefficients), neither side shorter than MIN_ASPECT times the other; a box of half-size
    DEFAULT_HALF when there is nothing bounded to enclose.

    >>> [round(v, 2) for v in enclosing_window(np.array([-2.0, -1 + 1j, -1 - 1j, 0j]))]
    [-2.24, 0.24, -1.24, 1.24]
    """
    pts = list(np.asarray(points, dtype=complex).ravel()) + [0j]
    if beta:
        pts.append(complex(-beta, 0))
    if Y:
        pts.append(complex(0, Y))
    pts = np.asarray(pts)
    x0, x1 = float(pts.real.min()), float(pts.real.max())
    h = float(np.abs(pts.imag).max())
    if x1 - x0 < 1e-12 and h < 1e-12:                 # nothing bounded to enclose
        return (-DEFAULT_HALF, DEFAULT_HALF / 2, -DEFAULT_HALF, DEFAULT_HALF)
    pad = PAD * max(x1 - x0, 2 * h)
    x0, x1, h = x0 - pad, x1 + pad, h + pad
    if x1 - x0 < MIN_ASPECT * 2 * h:                    # too narrow: widen about the middle
        mid, half = (x0 + x1) / 2, MIN_ASPECT * h
        x0, x1 = mid - half, mid + half
    h = max(h, MIN_ASPECT * (x1 - x0) / 2)
    return (x0, x1, -h, h)


def parse_window(text: str) -> tuple:
    """``XMIN,XMAX,YMIN,YMAX`` as four finite floats with XMIN < XMAX, YMIN < YMAX (ValueError
    saying what is wrong otherwise).

    >>> parse_window("-12,3,-8,8")
    (-12.0, 3.0, -8.0, 8.0)
    """
    parts = [p.strip() for p in str(text).split(",")]
    if len(parts) != 4:
        raise ValueError(f"{text!r}: write four numbers XMIN,XMAX,YMIN,YMAX, e.g. -12,3,-8,8")
    try:
        vals = tuple(float(p) for p in parts)
    except ValueError:
        raise ValueError(f"{text!r}: write four numbers XMIN,XMAX,YMIN,YMAX, e.g. -12,3,-8,8") from None
    if not all(np.isfinite(vals)) or max(map(abs, vals)) > 1e12:
        raise ValueError(f"{text!r}: the numbers must be finite and at most 1e12 in size")
    if not (vals[0] < vals[1] and vals[2] < vals[3]):
        raise ValueError(f"{text!r}: need XMIN < XMAX and YMIN < YMAX")
    return vals


def figure_stem(path) -> str:
    """A file-name stem for a method's figures from its file or family name: the name's stem with
    every run of characters other than letters, digits, '_', '.', '-' made one '-' (``bdf:4`` →
    ``bdf-4``; no ':' in a file name), at most 100 characters, ``method`` when nothing is left.

    >>> figure_stem("bdf:4"), figure_stem("methods/gauss2.json"), figure_stem(":::")
    ('bdf-4', 'gauss2', 'method')
    """
    from ..files import derived_name
    return derived_name(Path(str(path)).stem, fill="-", default="method")


def _ymax(result) -> float:
    Y = result.imaginary_interval
    return 4.0 if Y == sp.oo or Y == 0 else 1.6 * float(Y)


def _caption(result) -> str:
    """The exact Y* (the figures print it as a decimal)."""
    return f"{result.method}: Y* = {sp.sstr(result.imaginary_interval)} ({result.interval_kind}), exactly"


def _sector_degrees(sector) -> float | None:
    """α in degrees of a computed A(α) sector (0 < α ≤ 90°), else None."""
    if sector is None or getattr(sector, "status", None) != "computed" or sector.alpha is None:
        return None
    a = float(sector.alpha)
    return float(np.degrees(a)) if a > 0 else None


def grid(box, n: int) -> tuple:
    """(xs, ys, Z): n × n points z = x + iy of the box (xmin, xmax, ymin, ymax), Z[i, j] = xs[j] + i·ys[i]."""
    x0, x1, y0, y1 = box
    xs, ys = np.linspace(x0, x1, n), np.linspace(y0, y1, n)
    return xs, ys, xs[None, :] + 1j * ys[:, None]


def _mirrored(rho, Zg) -> np.ndarray:
    """ρ on a grid symmetric about the real axis, evaluated on its upper half only: ρ(z̄) = ρ(z), as
    the method's polynomials have real coefficients (half the eigenvalue problems of a GLM's grid).

    >>> f = lambda Z: np.abs(Z - 0.3 - 0.7j) * np.abs(Z - 1j)          # not symmetric: the halves differ
    >>> g = lambda Z: np.abs(Z ** 2 - 0.6 * Z + 0.58)                    # real coefficients
    >>> Z = grid((-1, 2, -3, 3), 7)[2]
    >>> bool(np.allclose(_mirrored(g, Z), g(Z))), bool(np.allclose(_mirrored(f, Z), f(Z)))
    (True, False)
    """
    n = Zg.shape[0]
    half = n // 2                                  # rows half … n − 1: Im z ≥ 0
    top = np.asarray(rho(Zg[half:]), dtype=float)
    return np.concatenate([top[n % 2:][::-1], top])          # row i of the lower half mirrors row n − 1 − i


def shade_region(ax, rho, box, n: int, inside: str = "below"):
    """Shade where ``rho(Z)`` (a real function of a complex array: the largest root modulus, or
    |R(z)e^{−z}|) is ≤ 1 (``inside="below"``) or > 1 (``"above"``) on an n × n grid of the box, draw
    the level curve ρ = 1 (``ContourSet``s with gids ``"region"`` and ``"boundary"``), the axes and the box; returns
    the grid values ρ."""
    xs, ys, Zg = grid(box, n)
    rho = _mirrored(rho, Zg) if np.allclose(ys, -ys[::-1]) else np.asarray(rho(Zg), dtype=float)
    inside_mask = rho <= 1 + 1e-9 if inside == "below" else rho > 1 + 1e-9
    shaded = ax.contourf(xs, ys, inside_mask.astype(float), levels=[0.5, 1.5], colors=[style.PALETTE[5]], alpha=0.5)
    shaded.set_gid("region")
    curve = ax.contour(xs, ys, np.minimum(np.nan_to_num(rho, nan=10.0, posinf=10.0), 10), levels=[1.0],
                       colors="k", linewidths=0.8)
    curve.set_gid("boundary")
    ax.axhline(0, color="grey", lw=0.5), ax.axvline(0, color="grey", lw=0.5)
    ax.set_xlim(box[0], box[1]), ax.set_ylim(box[2], box[3])
    ax.set_xlabel(r"$\mathrm{Re}\,z$"), ax.set_ylabel(r"$\mathrm{Im}\,z$")
    ax.set_aspect("equal")
    return rho


def mark_intervals(ax, Y=None, beta=None, sector=None) -> bool:
    """Mark on a region plot the exact imaginary interval |y| < Y (finite, non-zero), the real
    interval [−β, 0] (finite, non-zero) and a computed A(α) sector (``sector``: an
    ``AAlphaResult``), each labelled with its decimal, within the axes' limits (kept); whether
    anything was marked."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    labelled = False
    if Y is not None and Y not in (0, sp.oo):
        ax.plot([0, 0], [-float(Y), float(Y)], color=style.PALETTE[1], lw=2.5, marker="None", linestyle="-",
                label=f"$|y| < Y^* = {style.decimal(Y)}$ on the imaginary axis")
        labelled = True
    b = finite_float(beta)
    if b:
        ax.plot([-b, 0], [0, 0], color=style.PALETTE[2], lw=2.5, marker="None", linestyle="-",
                label=f"$[-\\beta, 0]$, $\\beta = {style.decimal(beta)}$ on the real axis")
        labelled = True
    alpha = _sector_degrees(sector)
    if alpha is not None:
        reach = 2 * max(abs(x0), abs(x1), abs(y0), abs(y1))
        a = np.radians(alpha)
        ends = [reach * complex(-np.cos(a), sgn * np.sin(a)) for sgn in (1, -1)]
        ax.fill([ends[0].real, 0, ends[1].real], [ends[0].imag, 0, ends[1].imag], color=style.PALETTE[4],
                alpha=0.18, lw=0)
        for k, e in enumerate(ends):
            ax.plot([0, e.real], [0, e.imag], color=style.PALETTE[4], lw=1.4, ls="--", marker="None",
                    label=f"A($\\alpha$) sector, $\\alpha = {alpha:.2f}°$" if k == 0 else None)
        labelled = True
    ax.set_xlim(x0, x1), ax.set_ylim(y0, y1)
    return labelled


def draw_region(result, target: Path, n: int = 401, window_=None, real=None, sector=None) -> Path:
    """The region {z : every root |w| ≤ 1} of an RK method or GLM, with ±iY*, the real interval and
    the A(α) sector marked, in ``window_`` (default: :func:`window`)."""
    plt = style.pyplot()
    C = coefficient_array(result.polynomial, result.variable)
    x0, x1, y0, y1 = window_ if window_ is not None else window(result, real, sector)
    fig, ax = plt.subplots(figsize=style.SQUARE_SIZE)
    shade_region(ax, lambda Zg: root_moduli(C, Zg).max(axis=-1), (x0, x1, y0, y1), n)
    labelled = mark_intervals(ax, result.imaginary_interval, getattr(real, "beta", None), sector)
    if labelled:
        style.legend(ax, "below", ncols=1)
    style.title(ax, f"{style.plain(result.method)}: every root $|w| \\leq 1$ (shaded)")
    style.save(fig, Path(target), caption=_caption(result))
    return Path(target)


def draw_axis_moduli(result, target: Path, n: int = 2000, top: float | None = None) -> Path:
    """|w| of every root along the imaginary axis z = iy (or x = hω) up to ``top`` (default from
    Y*), with Y* marked."""
    plt = style.pyplot()
    C = coefficient_array(result.polynomial, result.variable)
    fig, ax = plt.subplots(figsize=(style.PRINT_WIDTH, 3.4))
    draw_moduli(ax, C, result.variable, top if top else _ymax(result), n, result.imaginary_interval,
                result.interval_kind)
    style.title(ax, f"{style.plain(result.method)}: root moduli on the axis")
    style.save(fig, Path(target), caption=_caption(result))
    return Path(target)


def draw_moduli(ax, C: np.ndarray, variable: str, top: float, n: int, Y=None, kind: str = "") -> np.ndarray:
    """|w| of every root of Σ C[k, l] w^k v^l along z = iy (``variable`` "z") or x = hω (``"x"``),
    0 ≤ y ≤ ``top`` on n points, with the line |w| = 1 and the exact Y (when given, finite and
    non-zero: ``kind`` names it) marked; returns the sorted moduli (n × r)."""
    ys = np.linspace(0, top, n)
    vals = 1j * ys if variable == "z" else ys.astype(complex)
    mods = np.sort(root_moduli(C, vals), axis=-1)
    every = max(1, int(n * style.MARK_SPACING))        # evenly spaced markers, offset per line (style.thin_markers)
    for k in range(mods.shape[1]):
        ax.plot(ys, mods[:, k], label=f"root {k + 1}" if mods.shape[1] > 1 else "$|w|$",
                markevery=(int(every * (k % len(style.PALETTE)) / len(style.PALETTE)), every), **style.series_style(k))
    ax.axhline(1, color="grey", lw=0.6, ls=":")
    if Y is not None and Y not in (0, sp.oo):
        ax.axvline(float(Y), color="0.3", lw=1.0, ls="--",
                   label=f"$Y^* \\approx {style.decimal(Y)}$ ({style.plain(kind)})")
    a = "$y$ ($z = iy$)" if variable == "z" else r"$x = h\omega$"
    ax.set_xlabel(a), ax.set_ylabel("$|w|$")
    finite = mods[np.isfinite(mods)]
    ax.set_ylim(0, min(max(1.5, 1.05 * finite.max()) if finite.size else 1.5, 3))
    style.legend(ax, "right")
    return mods


def figure_paths(out: Path, stem: str) -> dict:
    """The figures :func:`draw_stability` writes for a method named ``stem`` into ``out``, by kind
    (``region``, ``axis``), each as its PNG (the other formats are its siblings).

    >>> sorted(p.name for p in figure_paths(Path("f"), "bdf:4").values())
    ['bdf-4_axis.png', 'bdf-4_region.png']
    """
    stem = figure_stem(stem)
    return {kind: Path(out) / f"{stem}_{kind}.png" for kind in ("region", "axis")}


def draw_stability(result, out: Path, stem: str, window_=None) -> list:
    """Both figures (the region only for y′ = λy, not for partitioned methods) into ``out``, named
    from :func:`figure_stem` of ``stem``.  ``result``: a ``StabilityResult``, or a
    ``StabilityReport`` (then its real interval and A(α) sector are drawn and enclosed too);
    ``window_``: (xmin, xmax, ymin, ymax) instead of :func:`window`."""
    paths = figure_paths(out, stem)
    linear = getattr(result, "linear", result)
    real, sector = getattr(result, "real", None), getattr(result, "sector", None)
    if linear.variable != "z":
        return [draw_axis_moduli(linear, paths["axis"])]
    box = window_ if window_ is not None else window(linear, real, sector)
    Y = finite_float(linear.imaginary_interval)
    top = max(box[3], 1.25 * Y) if Y else box[3]
    return [draw_region(linear, paths["region"], window_=box, real=real, sector=sector),
            draw_axis_moduli(linear, paths["axis"], top=top)]
