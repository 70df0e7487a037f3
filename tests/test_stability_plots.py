"""Issue 29, item 8: the stability region's window comes from the analysis, A(α) is drawn, a user
can set the window, file names carry no ':'.  Checked against facts computed here independently
of the plotting code: Radau IIA 3's stability function (HW96 Table IV.5.2: the (2, 3) Padé
approximant) and the boundary of its instability island found by bisection along rays; BDF4's
published coefficients, its boundary locus ρ(e^{iθ})/σ(e^{iθ}) and its published angle
α = 73.35° (HW96 Table V.2.3)."""
from __future__ import annotations

from pathlib import Path

import mpmath
import numpy as np
import pytest

from tableau_lab.analysis.stability import stability
from tableau_lab.analysis.stability_report import stability_report
from tableau_lab.cli import main
from tableau_lab.exact.library import family
from tableau_lab.experiments.stability_plots import draw_stability, locus_bounded, window


def radau3(z):
    """R(z) of Radau IIA with 3 stages: the (2, 3) Padé approximant of e^z."""
    return (1 + 2 * z / 5 + z ** 2 / 20) / (1 - 3 * z / 5 + 3 * z ** 2 / 20 - z ** 3 / 60)


def island_boundary(n=61):
    """Points of {|R(z)| = 1} in Re z > 0 by bisection along rays from 0: |R| > 1 next to the origin
    (R = e^z + O(z⁶)), |R| → 0 at infinity."""
    pts = []
    for phi in np.linspace(-np.pi / 2 + 0.05, np.pi / 2 - 0.05, n):
        u = mpmath.exp(1j * mpmath.mpf(phi))
        lo, hi = mpmath.mpf("1e-3"), mpmath.mpf(1000)
        assert abs(radau3(lo * u)) > 1 > abs(radau3(hi * u))
        for _ in range(80):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if abs(radau3(mid * u)) > 1 else (lo, mid)
        pts.append(complex(lo * u))
    return pts


def test_radau_iia_island_is_bounded_and_inside_the_window():
    """The window held [−5, 2.5] × [−5, 5] and cut the island at Re z = 2.5, so that it looked like a
    half-plane; now the locus is known to be bounded (exactly) and the window holds the island."""
    res = stability(family("radau_iia", s=3))
    assert locus_bounded(res.polynomial)
    x0, x1, y0, y1 = window(res)
    pts = island_boundary()
    right = max(p.real for p in pts)
    top = max(abs(p.imag) for p in pts)
    assert 11.8 < right < 11.9                       # |R(x)| = 1 at x ≈ 11.84 on the real axis
    for p in pts:
        assert x0 < p.real < x1 and y0 < p.imag < y1
    assert x1 < 1.3 * right and y1 < 1.3 * top       # enclosed, not lost in a huge box
    assert x0 < 0                                     # the origin (where the island touches) is inside


def test_bdf4_lobe_inside_and_a_alpha_drawn(tmp_path, figures):
    """BDF4: ρ(w) = (25w⁴ − 48w³ + 36w² − 16w + 3)/12, σ(w) = w⁴; the unstable lobe is bounded by
    z(θ) = ρ(e^{iθ})/σ(e^{iθ}) (rightmost z(π) = 32/3, cut at 2.5 before) and the A(α) sector,
    α = 73.35° published, is drawn."""
    rep = stability_report(family("bdf", k=4))
    paths = draw_stability(rep, tmp_path, "bdf:4")
    assert [p.name for p in paths] == ["bdf-4_region.png", "bdf-4_axis.png"]
    ax = figures[0].axes[0]
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    w = np.exp(1j * np.linspace(0, 2 * np.pi, 721))
    locus = (25 * w ** 4 - 48 * w ** 3 + 36 * w ** 2 - 16 * w + 3) / 12 / w ** 4
    assert np.all((locus.real > x0) & (locus.real < x1) & (locus.imag > y0) & (locus.imag < y1))
    assert abs(locus.real.max() - 32 / 3) < 1e-9 and x1 < 1.3 * 32 / 3
    wedge = [line for line in ax.get_lines() if "alpha" in str(line.get_label())]
    assert len(wedge) == 1 and "73.35" in wedge[0].get_label()
    rays = [line for line in ax.get_lines() if line.get_color() == wedge[0].get_color()]
    angles = sorted(np.degrees(np.angle(complex(*line.get_xydata()[1]))) for line in rays)
    assert np.allclose(angles, [-(180 - 73.35), 180 - 73.35], atol=0.01)


def test_window_option_and_safe_file_names(tmp_path, figures, capsys):
    """--window sets the region's axes; a bad one is refused (exit 2); `bdf:4` gives `bdf-4_*` files."""
    assert main(["stability", "bdf:4", "--plot", str(tmp_path), "--window=-12,3,-8,8"]) == 0
    ax = figures[0].axes[0]
    assert ax.get_xlim() == (-12, 3) and ax.get_ylim() == (-8, 8)
    names = sorted(p.name for p in Path(tmp_path).iterdir())
    assert names and not any(":" in n for n in names) and "bdf-4_region.png" in names
    for bad in ("1,0,2,3", "a,b,c,d", "1,2,3", "nan,1,2,3"):
        with pytest.raises(SystemExit) as exc:
            main(["stability", "bdf:4", "--plot", str(tmp_path), f"--window={bad}"])
        assert exc.value.code == 2
    assert "XMIN" in capsys.readouterr().err
