"""Inline stability plots (issue 30, item 3): the drawn region, order star and axis moduli checked
against independent facts — rk4's real-axis end (a root of the exact polynomial), explicit Euler's
disc |1 + z| ≤ 1, BDF2's boundary locus ρ(ζ)/σ(ζ) (HW II, §V.1), the p + 1 sectors of an order
star at the origin (HW II, §IV.4), rk4's imaginary interval 2√2 — and the GLM route (an
interpolated P(w, z)) against the RK route and the exact polynomial."""
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest
import sympy as sp
from matplotlib.axes import Axes

from tableau_lab.analysis.stability import characteristic_polynomial
from tableau_lab.exact.tableau_json import load
from tableau_lab.experiments import inline_plots as ip
from tableau_lab.experiments.stability_plots import coefficient_array, locus_bounded, root_moduli


def _contour(ax, gid="boundary"):
    """The vertices of the drawn level curve (gid "boundary") or the filled region's paths."""
    sets = [c for c in ax.collections if c.get_gid() == gid]
    assert len(sets) == 1
    paths = [p for p in sets[0].get_paths() if len(p.vertices)]
    assert paths, "nothing drawn"
    return paths


def _vertices(ax):
    pts = np.concatenate([p.vertices for p in _contour(ax)])
    return pts[:, 0] + 1j * pts[:, 1]


def _spacing(ax, n):
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    return max(x1 - x0, y1 - y0) / (n - 1)


@pytest.fixture(autouse=True)
def _close():
    yield
    plt.close("all")


def test_rk4_real_interval_end_is_on_the_drawn_boundary():
    # R(x) = 1 at x ≠ 0: 1 + x/2 + x²/6 + x³/24 = 0, i.e. x³ + 4x² + 12x + 24 = 0 (HW II, Fig. IV.2.1)
    x = sp.Symbol("x")
    (end,) = sp.real_roots(x**3 + 4 * x**2 + 12 * x + 24)
    assert abs(float(end) + 2.785293563) < 1e-9
    ax = ip.plot_stability_region("rk4")
    assert isinstance(ax, Axes)
    pts = _vertices(ax)
    h = _spacing(ax, ip.REGION_POINTS)
    assert np.min(np.abs(pts - float(end))) < h
    # and the curve is |R| = 1 everywhere, not just there: a point off it is far from every vertex
    assert np.min(np.abs(pts - (-2.0))) > 10 * h


def test_explicit_euler_region_is_the_disc():
    ax = ip.plot_stability_region("explicit_euler")
    pts = _vertices(ax)
    h = _spacing(ax, ip.REGION_POINTS)
    assert np.max(np.abs(np.abs(1 + pts) - 1)) < h          # the boundary is the circle |1 + z| = 1
    filled = _contour(ax, "region")
    inside = [-1, -1 + 0.5j, -0.2, -1.9, -1 - 0.9j]
    outside = [0.1, -2.1, -1 + 1.1j, 0.3 + 0.3j, -1.8 + 0.8j]

    def shaded(z):
        return any(p.contains_point((z.real, z.imag)) for p in filled)
    assert all(shaded(complex(z)) for z in inside)
    assert not any(shaded(complex(z)) for z in outside)


def test_window_is_honoured_and_checked():
    ax = ip.plot_stability_region("rk4", window=(-6, 2, -1, 5))
    assert tuple(map(float, ax.get_xlim())) == (-6.0, 2.0) and tuple(map(float, ax.get_ylim())) == (-1.0, 5.0)
    fig, given = plt.subplots()
    rk4_file = Path(__file__).resolve().parents[1] / "methods" / "rk4.json"
    assert ip.plot_stability_region(rk4_file, ax=given) is given                # a file, as a Path
    with pytest.raises(ValueError, match="xmin < xmax"):
        ip.plot_stability_region("rk4", window=(2, -6, -1, 5))
    with pytest.raises(ValueError, match="window="):
        ip.plot_stability_region("rk4", window=(0, 1, 2))
    with pytest.raises(ValueError, match="at most 1e"):
        ip.plot_stability_region("rk4", window=(-1e300, 1, -1, 1))
    with pytest.raises(ValueError, match="n=1000000: give an integer 2"):       # the grid is a budget
        ip.plot_stability_region("rk4", n=10**6)
    with pytest.raises(ValueError, match="top=-1"):
        ip.plot_imaginary_axis("rk4", top=-1, exact=False)
    with pytest.raises(TypeError, match="a method or its name"):
        ip.plot_order_star(3)
    with pytest.raises(TypeError, match="harmonic oscillator"):
        ip.plot_stability_region("stormer_verlet")
    with pytest.raises(TypeError, match="RK methods"):
        ip.plot_order_star("bdf:2")


def test_bdf2_region_boundary_is_its_boundary_locus():
    # BDF2 (a GLM with r = 2: the roots of P(·, z) as companion eigenvalues) is A-stable; its region's
    # boundary is the whole locus z(θ) = Σ_{j≤2} (1 − e^{−iθ})^j / j (HW II, §V.1)
    ax = ip.plot_stability_region("bdf:2")
    pts = _vertices(ax)
    h = _spacing(ax, ip.GLM_POINTS)
    u = 1 - np.exp(-1j * np.linspace(0, 2 * np.pi, 400))
    locus = u + u**2 / 2
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    shown = locus[(locus.real > x0 + h) & (locus.real < x1 - h) & (locus.imag > y0 + h) & (locus.imag < y1 - h)]
    assert shown.size > 100
    assert max(np.min(np.abs(pts - z)) for z in shown) < h
    assert x1 > float(np.max(locus.real))                    # the unstable lobe in Re z > 0, whole (max Re z = 4)


@pytest.mark.parametrize("name", ["glm43", "bdf:4", "adams_bashforth2", "leapfrog", "example4_glm", "adams_moulton:1",
                                  "adams_moulton:2"])
def test_glm_polynomial_interpolated_is_the_exact_one(name):
    # and its boundary locus's boundedness, decided in floats, is the exact decision (a root of the
    # leading coefficient on |w| = 1: GLM43, example 4 and the trapezoidal rule AM1 (its locus is the
    # imaginary axis) unbounded; BDF4, AB2, AM2, the leapfrog bounded)
    C, variable, bounded = ip.stability_polynomial_array(name)
    P, _ = characteristic_polynomial(load(name))
    E = coefficient_array(P.as_expr())
    assert C.shape == E.shape and np.allclose(C, E, atol=1e-12 * np.abs(E).max())
    assert bounded == locus_bounded(P.as_expr())


@pytest.mark.parametrize("name", ["rk4", "radau_iia3"])
def test_rk_method_written_as_glm_has_the_same_region(name):
    m = load(name)
    C_rk = ip.stability_polynomial_array(m)[0]
    C_glm, _, bounded = ip.stability_polynomial_array(m.as_glm())
    assert np.allclose(C_rk, C_glm, atol=1e-12)
    assert bounded == ip.stability_polynomial_array(m)[2]
    Z = np.linspace(-4, 4, 81)[None, :] + 1j * np.linspace(-4, 4, 81)[:, None]
    R = ip.order_star_modulus(m)(Z) * np.exp(Z.real)             # |R(z)|, the RK route
    rho = root_moduli(C_glm, Z).max(axis=-1)                      # every root of the GLM's P(·, z)
    clear = np.abs(R - 1) > 1e-6
    assert np.array_equal((R <= 1)[clear], (rho <= 1)[clear]) and clear.sum() > 6000
    box = (-4, 4, -4, 4)
    ra, rb = ip.plot_stability_region(m, window=box), ip.plot_stability_region(m.as_glm(), window=box)
    va, vb = _vertices(ra), _vertices(rb)
    assert max(np.min(np.abs(vb - z)) for z in va[::7]) < 1e-9


@pytest.mark.parametrize("name, order", [("explicit_euler", 1), ("rk4", 4), ("gauss2", 4), ("radau_iia3", 5),
                                         ("implicit_euler", 1)])
def test_order_star_has_p_plus_one_sectors_at_the_origin(name, order):
    # |R(z)e^{−z}| − 1 ≈ C z^{p+1} near 0: 2(p + 1) sign changes on a small circle (HW II, §IV.4)
    f = ip.order_star_modulus(name)
    z = 0.2 * np.exp(2j * np.pi * (np.arange(3600) + 0.5) / 3600)
    s = np.sign(f(z) - 1)
    assert np.all(s != 0)
    assert int(np.sum(s != np.roll(s, 1))) == 2 * (order + 1)
    ax = ip.plot_order_star(name)
    assert isinstance(ax, Axes) and "order star" in ax.get_title()
    filled = _contour(ax, "region")                          # the shaded set is A₊ = {|R e^{−z}| > 1}
    ring = 0.6 * np.exp(2j * np.pi * np.arange(720) / 720)
    values = f(ring)
    most, least = ring[np.argmax(values)], ring[np.argmin(values)]
    assert values.max() > 1 > values.min()
    assert any(p.contains_point((most.real, most.imag)) for p in filled)
    assert not any(p.contains_point((least.real, least.imag)) for p in filled)


def test_imaginary_axis_marks_exact_interval():
    ax = ip.plot_imaginary_axis("rk4")
    assert isinstance(ax, Axes)
    marks = [line for line in ax.lines if "Y^*" in str(line.get_label())]
    assert len(marks) == 1 and abs(marks[0].get_xdata()[0] - 2 * np.sqrt(2)) < 1e-15
    (curve,) = [line for line in ax.lines if line.get_label() == "$|w|$"]
    y, w = np.asarray(curve.get_xdata()), np.asarray(curve.get_ydata())
    # |R(iy)|² = 1 − y⁶/72 + y⁸/576 (HW II, §IV.2): ≤ 1 exactly for |y| ≤ 2√2
    assert np.allclose(w**2, 1 - y**6 / 72 + y**8 / 576, rtol=1e-12)
    ax2 = ip.plot_imaginary_axis("stormer_verlet", exact=False, top=3)
    assert "hω" in ax2.get_xlabel() or "omega" in ax2.get_xlabel()


def test_module_imports_no_matplotlib():
    code = ("import sys, tableau_lab.experiments.inline_plots; "
            "print(sorted(m for m in ('matplotlib', 'scipy', 'numba', 'dask') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_exact_analysis_marks_bdf4_sector():
    # BDF4 is A(α)-stable with α = 73.35° (HW II, Table V.2.3); the plot marks what it is given
    from tableau_lab.analysis.stability_report import stability_report
    report = stability_report(load("bdf:4"))
    ax = ip.plot_stability_region("bdf:4", analysis=report)
    (edge,) = [line for line in ax.lines if "sector" in str(line.get_label())]
    x, y = edge.get_xdata()[1], edge.get_ydata()[1]
    assert abs(np.degrees(np.arctan2(y, -x)) - 73.35) < 0.005
    assert "73.35" in edge.get_label()
    plain = ip.plot_stability_region("bdf:4")
    assert plain.get_xlim() == ax.get_xlim() and plain.get_legend() is None    # nothing marked, same window
