r"""Fast stability plots for a notebook: the stability region, the order star and the root moduli
along the imaginary axis of a method, drawn into a matplotlib ``Axes`` and returned (nothing is
written; pyplot makes the figure only when no ``ax`` is given, so a notebook shows it inline and a
script without a display draws on Agg).

*The numbers.*  An RK method's stability function R = N/D comes from its exact tableau
(:func:`~tableau_lab.analysis.stability.stability_function`: N = det(I − zA + z𝟙bᵀ),
D = det(I − zA)), its coefficients rounded once to floats (``numeric.arith``); |R(z)| is then evaluated on the
grid with numpy ([HW96] Hairer & Wanner, *Solving ODEs II*, §IV.2–3).  A GLM's stability
polynomial P(w, z) = det[[I − zA, −U], [−zB, wI − V]] = det(I − zA)·det(wI − M(z))
([B16] Butcher 2016, ch. 5) is interpolated in floats from the matrices' entries: P has degree
≤ r in w and ≤ s in z (w stands only in the last r columns, z only in the first s), so its
values at the (r + 1)-th and (s + 1)-th roots of unity give every coefficient by one 2-D FFT —
no exact determinant over the method's number field (slow for GLM6's); the region is where
every root w of P(·, z), a companion-matrix eigenvalue batched over the grid, has |w| ≤ 1.
A partitioned RK method's P(w, x) on the harmonic oscillator (x = hω real) is exact and cheap.

*The window* is the one the exact analysis draws (:func:`~.stability_plots.enclosing_window`):
the box of the boundary locus {z : P(e^{iθ}, z) = 0} — every bounded piece of the region and
every bounded unstable island (Radau IIA's in Re z > 0, BDF4's lobe) whole, and with it the real
interval's end −β and ±iY* where they are finite, as they lie on the locus.  Whether the locus is
bounded (the leading coefficient L(w) of P in z has no root on |w| = 1) is decided exactly for RK
methods and in floats (a root of L within ``CIRCLE_TOL`` of the circle) for GLMs.  ``window=``
(xmin, xmax, ymin, ymax) overrides it.

*The order star* of an RK method ([HW96] §IV.4; Wanner, Hairer & Nørsett, BIT 18 (1978)) is the
set A₊ = {z : |R(z) e^{−z}| > 1}, shaded; a method of order p has p + 1 of its sectors at the
origin, where |R(z)e^{−z}| − 1 ≈ C z^{p+1}.

>>> import matplotlib.pyplot as plt
>>> ax = plot_stability_region("rk4")
>>> type(ax).__name__, bool(ax.get_xlim()[0] < -2.785 < ax.get_xlim()[1])
('Axes', True)
>>> plt.close(ax.figure)
>>> fig, (a, b) = plt.subplots(1, 2)
>>> plot_order_star("gauss2", ax=a) is a, plot_imaginary_axis("leapfrog", ax=b) is b
(True, True)
>>> plt.close(fig)
"""
from __future__ import annotations

import numpy as np
import sympy as sp

from ..exact.catalog import load_with_numbers
from ..exact.methods import Method
from ..numeric.arith import arith
from . import figure_style as style
from .stability_plots import (
    coefficient_array,
    draw_moduli,
    enclosing_window,
    finite_float,
    locus_points,
    mark_intervals,
    root_moduli,
    shade_region,
)

__all__ = ["plot_stability_region", "plot_order_star", "plot_imaginary_axis", "stability_polynomial_array",
           "region_window", "order_star_modulus", "REGION_POINTS", "GLM_POINTS", "AXIS_POINTS", "CIRCLE_TOL",
           "STAR_HALF", "MAX_POINTS"]

REGION_POINTS = 301        # grid points per side of a region or order-star plot
GLM_POINTS = 201           # … of a GLM's region (r ≥ 2 roots per point: an eigenvalue problem each, 7 µs)
AXIS_POINTS = 1000         # points along the imaginary axis
CIRCLE_TOL = 1e-4          # a float root of L(w) this close to |w| = 1 makes a GLM's boundary locus unbounded
                           # (it reaches |z| ~ 1/distance; a k-fold root on the circle is found within eps^(1/k))
NEGLIGIBLE = 1e-13         # an interpolated coefficient below this times the largest is round-off: zero
STAR_HALF = 3.0            # the order star's window: at least this half-size about 0 …
STAR_SCALE = 1.3           # … and this times the largest |zero| or |pole| of R
FIGURE_SIZE = (4.5, 4.0)   # inches: a plot made without an ``ax``
MAX_POINTS = 2001          # the largest grid side (or axis points) a caller may ask for: 4·10⁶ root problems
MAX_COORDINATE = 1e12      # the largest |coordinate| of a window (as ``--window``: stability_plots.parse_window)


def _rk_parts(m: Method) -> tuple:
    """(N, D, bounded) of an RK method: N and D as float coefficient arrays (z^0 … z^s) from the
    exact N and D, and whether the boundary locus {z : R(z) = e^{iθ}} is bounded, decided exactly:
    the leading coefficient of w·D − N in z is L(w) = d·w − n (d, n the coefficients of z^m,
    m = max(deg N, deg D)), with a root on |w| = 1 exactly when n² = d² ≠ 0 (|R(∞)| = 1: Gauss),
    tested in the method's field (the general test, :func:`~.stability_plots.locus_bounded`, would
    first find the coefficients' minimal polynomials: seconds for SDIRK34)."""
    from ..analysis.stability import stability_function
    N, D, K = stability_function(m)
    Z = sp.Symbol("z")
    N_, D_ = (arith().array(sp.Poly(p.as_expr(), Z).all_coeffs()[::-1]) for p in (N, D))
    top = max(N.degree(), D.degree())
    n, d = N.coeff_wrt(0, top) if N.degree() == top else K.zero, D.coeff_wrt(0, top) if D.degree() == top else K.zero
    return N_, D_, not (d != K.zero and n * n == d * d)


def _glm_array(m: Method) -> np.ndarray:
    """C[k, l] = coefficient of w^k z^l of det[[I − zA, −U], [−zB, wI − V]], interpolated in floats
    at roots of unity (module docstring)."""
    g = m.as_glm()
    A, U, B, V = (arith().matrix(M) for M in (g.A, g.U, g.B, g.V))
    s, r = A.shape[0], V.shape[0]
    ws = np.exp(2j * np.pi * np.arange(r + 1) / (r + 1))
    zs = np.exp(2j * np.pi * np.arange(s + 1) / (s + 1))
    M = np.zeros((r + 1, s + 1, s + r, s + r), dtype=complex)      # the block matrix at (w_j, z_k)
    z, w = zs[None, :, None, None], ws[:, None, None, None]
    M[:, :, :s, :s] = np.eye(s) - z * A
    M[:, :, :s, s:] = -U
    M[:, :, s:, :s] = -z * B
    M[:, :, s:, s:] = w * np.eye(r) - V
    values = np.linalg.det(M)                                          # (r + 1, s + 1)
    C = np.fft.fft2(values).real / values.size
    C[np.abs(C) < NEGLIGIBLE * np.abs(C).max()] = 0.0
    return C


def _trim(C: np.ndarray) -> np.ndarray:
    """C without its trailing zero columns (the degree in z) and rows (in w)."""
    cols = np.nonzero(np.any(C != 0, axis=0))[0]
    rows = np.nonzero(np.any(C != 0, axis=1))[0]
    return C[: rows[-1] + 1 if rows.size else 1, : cols[-1] + 1 if cols.size else 1]


def _bounded_float(C: np.ndarray) -> bool:
    """Whether L(w) = Σ_k C[k, −1] w^k (the leading coefficient in z) has no root on |w| = 1."""
    lead = np.trim_zeros(C[:, -1], "b")
    if C.shape[1] < 2 or lead.size < 2:
        return True
    return bool(np.all(np.abs(np.abs(np.roots(lead[::-1])) - 1) > CIRCLE_TOL))


def stability_polynomial_array(method) -> tuple:
    """(C, variable, bounded): the stability polynomial P(w, v) = Σ C[k, l] w^k v^l in floats
    (v = z; v = x = hω for a partitioned method), and whether its boundary locus is bounded.

    An RK method written as a GLM gives the same polynomial, w·D(z) − N(z):

    >>> from tableau_lab.exact.tableau_json import load
    >>> C, v, bounded = stability_polynomial_array("explicit_euler")     # w − 1 − z
    >>> C.tolist(), v, bounded
    ([[-1.0, -1.0], [1.0, 0.0]], 'z', True)
    >>> G = stability_polynomial_array(load("explicit_euler").as_glm())[0]
    >>> bool(np.allclose(G, C))
    True
    """
    m = load_with_numbers(method, "a plot")
    if m.kind == "rk":
        N, D, bounded = _rk_parts(m)
        C = np.zeros((2, max(len(N), len(D))))
        C[0, : len(N)], C[1, : len(D)] = -N, D
        return _trim(C), "z", bounded
    if m.kind == "prk":
        from ..analysis.stability import characteristic_polynomial
        P, _ = characteristic_polynomial(m)
        return coefficient_array(P.as_expr(), "x"), "x", True
    C = _trim(_glm_array(m))
    return C, "z", _bounded_float(C)


def _polyval(c: np.ndarray, Z):
    """Σ c[l] Z^l (coefficients from z^0 up)."""
    return np.polyval(c[::-1], Z)


def region_window(method) -> tuple:
    """(xmin, xmax, ymin, ymax) of :func:`plot_stability_region`: the box of the boundary locus
    (module docstring), the origin included.

    >>> x0, x1, y0, y1 = region_window("radau_iia3")          # the unstable island in Re z > 0, whole
    >>> x0 < 0 < 10.0 < x1 < 15 and y0 == -y1
    True
    """
    C, variable, bounded = stability_polynomial_array(method)
    if variable != "z":
        raise TypeError(f"{load_with_numbers(method, 'a plot').name}: a partitioned method has no region in the "
                        "z-plane (it is analysed on the harmonic oscillator: plot_imaginary_axis)")
    return enclosing_window(locus_points(C, bounded))


def _axes(ax, size=FIGURE_SIZE):
    """``ax``, or the axes of a new pyplot figure (shown inline by a notebook).  Call it inside
    :func:`_styled`."""
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt
    return plt.subplots(figsize=size)[1]


def _styled():
    """The figures' matplotlib settings (:func:`~.figure_style.rc`) for the drawing only: the
    user's own settings are left as they were."""
    import matplotlib
    return matplotlib.rc_context(style.rc())


def _box(window) -> tuple:
    try:
        box = tuple(float(v) for v in window)
    except (TypeError, ValueError):
        box = ()
    if len(box) != 4 or not all(np.isfinite(box)) or max(map(abs, box)) > MAX_COORDINATE \
            or not (box[0] < box[1] and box[2] < box[3]):
        raise ValueError(f"window={window!r}: give four numbers (xmin, xmax, ymin, ymax), xmin < xmax, "
                         f"ymin < ymax, each finite and at most {MAX_COORDINATE:g} in size")
    return box


def _top(top) -> float:
    """``top`` as a float 0 < top ≤ MAX_COORDINATE."""
    try:
        value = float(top)
    except (TypeError, ValueError):
        value = float("nan")
    if not (np.isfinite(value) and 0 < value <= MAX_COORDINATE):
        raise ValueError(f"top={top!r}: give a number 0 < top ≤ {MAX_COORDINATE:g}")
    return value


def _points(n, name: str = "n") -> int:
    """The grid size ``n``, an integer 2 … MAX_POINTS (the plot's cost is n² root problems)."""
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or not 2 <= n <= MAX_POINTS:
        raise ValueError(f"{name}={n!r}: give an integer 2 … {MAX_POINTS}")
    return int(n)


def plot_stability_region(method, ax=None, window=None, n: int | None = None, analysis=None):
    """The stability region {z : every root w of P(w, z) has |w| ≤ 1} (for an RK method
    |R(z)| ≤ 1) shaded, its boundary drawn, in ``window`` (xmin, xmax, ymin, ymax) or the window of
    :func:`region_window`, on an n × n grid (default REGION_POINTS, GLM_POINTS for r ≥ 2); returns
    the matplotlib Axes ([HW96] §IV.2; [B16] ch. 5).  ``analysis``: the method's exact
    ``stability(m)`` or ``stability_report(m)``, when computed, marks the imaginary interval ±iY*,
    the real interval [−β, 0] and the A(α) sector (and the window encloses them): the plot itself
    computes none of them.

    >>> import matplotlib.pyplot as plt
    >>> ax = plot_stability_region("bdf:4", window=(-5, 15, -10, 10))
    >>> [float(v) for v in ax.get_xlim()], "stability region" in ax.get_title()
    ([-5.0, 15.0], True)
    >>> plt.close(ax.figure)
    >>> from tableau_lab.analysis.stability_report import stability_report
    >>> from tableau_lab.exact.tableau_json import load
    >>> ax = plot_stability_region("rk4", analysis=stability_report(load("rk4")))
    >>> print(*[t.get_text() for t in ax.get_legend().get_texts()], sep="\\n")
    $|y| < Y^* = 2.8284$ on the imaginary axis
    $[-\\beta, 0]$, $\\beta = 2.7853$ on the real axis
    >>> plt.close(ax.figure)
    """
    m = load_with_numbers(method, "a plot")
    C, variable, bounded = stability_polynomial_array(m)
    if variable != "z":
        raise TypeError(f"{m.name}: a partitioned method has no region in the z-plane "
                        "(it is analysed on the harmonic oscillator: plot_imaginary_axis)")
    linear = getattr(analysis, "linear", analysis)
    Y = getattr(linear, "imaginary_interval", None)
    beta = getattr(getattr(analysis, "real", None), "beta", None)
    sector = getattr(analysis, "sector", None)
    if window is not None:
        box = _box(window)
    else:
        box = enclosing_window(locus_points(C, bounded), finite_float(beta), finite_float(Y))
    n = _points(n) if n is not None else REGION_POINTS if C.shape[0] == 2 else GLM_POINTS
    if C.shape[0] == 2:                    # r = 1: |R(z)| = |N(z)/D(z)|
        N, D = -C[0], C[1]

        def rho(Z):
            with np.errstate(divide="ignore", invalid="ignore"):
                return np.abs(_polyval(N, Z) / _polyval(D, Z))
    else:
        def rho(Z):
            return root_moduli(C, Z).max(axis=-1)
    with _styled():
        ax = _axes(ax)
        shade_region(ax, rho, box, n)
        if mark_intervals(ax, Y, beta, sector):
            ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14))    # under the axes: the figure may be the user's
        style.title(ax, f"{style.plain(m.name)}: stability region (shaded)")
    return ax


def order_star_modulus(method):
    """z ↦ |R(z) e^{−z}| of an RK method (numpy, elementwise), the function whose level set 1
    bounds the order star.

    >>> f = order_star_modulus("explicit_euler")           # |1 + z| e^{−Re z}
    >>> [round(float(v), 12) for v in f(np.array([-1, 1j, 1]))]
    [0.0, 1.414213562373, 0.735758882343]
    """
    m = load_with_numbers(method, "a plot")
    if m.kind != "rk":
        raise TypeError(f"{m.name}: the order star is drawn for RK methods (R(z)), not {m.kind}")
    N, D, _ = _rk_parts(m)

    def f(Z):
        Z = np.asarray(Z, dtype=complex)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return np.abs(_polyval(N, Z) / _polyval(D, Z)) * np.exp(-Z.real)
    f.zeros, f.poles = (np.roots(c[::-1]) if len(c) > 1 else np.zeros(0) for c in (N, D))
    return f


def plot_order_star(method, ax=None, window=None, n: int = REGION_POINTS):
    """The order star A₊ = {z : |R(z)e^{−z}| > 1} of an RK method shaded, its boundary drawn
    ([HW96] §IV.4; Wanner, Hairer & Nørsett 1978), in ``window`` or a square about 0 of half-size
    max(STAR_HALF, STAR_SCALE · the largest |zero| or |pole| of R); returns the matplotlib Axes.

    >>> import matplotlib.pyplot as plt
    >>> ax = plot_order_star("rk4")
    >>> [float(v) for v in ax.get_xlim()]
    [-4.0, 4.0]
    >>> plt.close(ax.figure)
    """
    m = load_with_numbers(method, "a plot")
    f = order_star_modulus(m)
    if window is not None:
        box = _box(window)
    else:
        size = np.abs(np.concatenate([f.zeros, f.poles]))
        half = float(np.ceil(max(STAR_HALF, STAR_SCALE * size.max() if size.size else 0)))
        box = (-half, half, -half, half)
    with _styled():
        ax = _axes(ax)
        shade_region(ax, f, box, _points(n), inside="above")
        style.title(ax, f"{style.plain(m.name)}: order star $|R(z)e^{{-z}}| > 1$ (shaded)")
    return ax


def plot_imaginary_axis(method, ax=None, top=None, exact: bool = True, n: int = AXIS_POINTS):
    """|w| of every root of P(w, iy) along the imaginary axis (x = hω for a partitioned method),
    0 ≤ y ≤ ``top``, with the exact imaginary stability interval Y* marked (from
    :func:`~tableau_lab.analysis.stability.stability`, exact; ``exact=False`` skips it for a method
    whose exact analysis is slow); ``top`` defaults to 1.6 Y* (4 when Y* is 0 or ∞); returns the
    matplotlib Axes ([HW96] §IV.3; [BHHN14]).

    >>> import matplotlib.pyplot as plt
    >>> ax = plot_imaginary_axis("rk4")
    >>> [line.get_xdata()[0] for line in ax.lines if "Y^*" in str(line.get_label())]  # 2√2
    [2.8284271247461903]
    >>> plt.close(ax.figure)
    """
    m = load_with_numbers(method, "a plot")
    C, variable, _ = stability_polynomial_array(m)
    Y, kind = None, ""
    if exact:
        from ..analysis.stability import stability
        result = stability(m)
        Y, kind = result.imaginary_interval, result.interval_kind
    if top is None:
        top = 4.0 if Y is None or Y == 0 or Y == sp.oo else 1.6 * float(Y)
    else:
        top = _top(top)
    with _styled():
        ax = _axes(ax, (style.PRINT_WIDTH, 3.4))
        draw_moduli(ax, C, variable, top, _points(n), Y, kind)
        style.title(ax, f"{style.plain(m.name)}: root moduli on the {'imaginary axis' if variable == 'z' else 'axis'}")
    return ax
