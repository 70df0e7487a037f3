"""Figures (issue 19, item 1): one style for every plot, each written as PNG (200 dpi), PDF and
SVG as one set; series distinct in (colour, marker, line style); legends outside the data;
coinciding series visible and named; exact constants as decimals; ``replot`` redraws saved
outputs without running anything; every figure under reports/ has its three files.  The data are
built here, tiny; nothing is integrated."""
import json
import struct
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import sympy as sp

from tableau_lab import files
from tableau_lab.experiments import figure_style as style, plots
from tableau_lab.files import OutputError


@pytest.fixture(autouse=True)
def _all_formats(monkeypatch):
    """This file checks the three formats a user gets (the suite draws PNG only: tests/conftest.py)."""
    monkeypatch.delenv("TABLEAU_LAB_FIGURE_FORMATS", raising=False)


ROOT = Path(__file__).resolve().parent.parent
METHODS = ROOT / "methods"


def _png_dpi(path: Path):
    """(x, y) pixels per inch from the PNG's pHYs chunk (None without one)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    at = 8
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at: at + 8])
        if kind == b"pHYs":
            x, y, unit = struct.unpack(">IIB", data[at + 8: at + 17])
            assert unit == 1                                    # pixels per metre
            return x * 0.0254, y * 0.0254
        at += 12 + length
    return None


def _check_set(png: Path):
    """PNG at 200 dpi, PDF and SVG beside it, no temporary file left."""
    assert png.suffix == ".png" and png.exists()
    dpi = _png_dpi(png)
    assert dpi is not None and all(abs(d - style.DPI) < 0.5 for d in dpi), dpi
    pdf, svg = png.with_suffix(".pdf"), png.with_suffix(".svg")
    assert pdf.read_bytes().startswith(b"%PDF") and b"%%EOF" in pdf.read_bytes()[-1024:]
    assert b"<svg" in svg.read_bytes()[:2000]
    assert not [f for f in png.parent.iterdir() if files.is_temp(f.name)]


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 - 0.5 and b.x0 < a.x1 - 0.5 and a.y0 < b.y1 - 0.5 and b.y0 < a.y1 - 0.5


def _legends_outside(fig):
    """No legend of ``fig`` overlaps the data area of any of its axes (window extents after a
    draw); returns the number of legends."""
    fig.canvas.draw()
    legends = [*fig.legends, *(ax.get_legend() for ax in fig.get_axes() if ax.get_legend() is not None)]
    for leg in legends:
        box = leg.get_window_extent()
        for ax in fig.get_axes():
            if ax.get_visible():
                assert not _overlap(box, ax.get_window_extent()), (leg, ax)
    return len(legends)


def _styles(ax):
    from matplotlib.colors import to_hex
    return [(to_hex(ln.get_color()), ln.get_marker(), str(ln.get_linestyle())) for ln in ax.get_lines()
            if not ln.get_label().startswith("_")]


def test_save_writes_png_pdf_svg_as_one_set(tmp_path):
    plt = style.pyplot()
    fig, ax = plt.subplots()
    ax.plot([1, 2, 3], [1, 4, 9], label="x²")
    paths = style.save(fig, tmp_path / "f.png", caption="Y* = CRootOf(x**5 - x - 1, 0)")
    assert [p.name for p in paths] == ["f.png", "f.pdf", "f.svg"]
    _check_set(tmp_path / "f.png")
    assert b"Y* = CRootOf" in (tmp_path / "f.pdf").read_bytes()                  # the caption: exact form
    assert b"CRootOf(x**5 - x - 1, 0)" in (tmp_path / "f.svg").read_bytes()
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    fig, ax = plt.subplots()
    ax.plot([1, 2, 3], [1, 4, 9], label="x²")
    style.save(fig, tmp_path / "f.png", caption="Y* = CRootOf(x**5 - x - 1, 0)")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before       # reproducible: no dates
    with pytest.raises(ValueError):
        style.save(plt.figure(), tmp_path / "f.pdf")


def test_a_failed_format_leaves_the_previous_set(tmp_path, monkeypatch):
    """A full disk while the SVG is written: OutputError, and the PNG and PDF of the set are not
    moved into place either (the previous three files stay, byte for byte)."""
    plt = style.pyplot()
    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    style.save(fig, tmp_path / "f.png")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    real = files._fill

    def fill(tmp, write):
        if tmp.endswith(".svg"):
            raise OSError(28, "No space left on device")
        return real(tmp, write)
    monkeypatch.setattr(files, "_fill", fill)
    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    with pytest.raises(OutputError, match=r"f\.svg: cannot write it"):
        style.save(fig, tmp_path / "f.png")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_24_series_are_distinct_and_the_legend_is_outside(tmp_path, figures):
    """The style's cycle: 24 series in one axes, no two with the same (colour, marker, line
    style); also through draw_convergence with 24 methods of one order (one panel)."""
    plt = style.pyplot()
    fig, ax = plt.subplots(figsize=(style.PRINT_WIDTH, 3))
    for i in range(24):
        ax.plot([1, 2, 3], [i, i + 1, i + 3], label=f"series {i}")
    assert len(set(_styles(ax))) == 24
    assert len({(c, m) for c, m, _ in _styles(ax)}) == 24             # colour and marker alone already differ
    style.legend(ax, "right")
    assert _legends_outside(fig) == 1
    plt.close(fig)
    assert len({tuple(style.series_style(i).values()) for i in range(style.DISTINCT)}) == style.DISTINCT
    h = [0.1, 0.05, 0.025]
    results = [{"method": f"method {i}", "order": 4, "h": h, "error": [(1 + i / 10) * x ** 4 for x in h],
                "slope": 4.0, "problem": "kepler", "T": 10.0, "precision": "float64"} for i in range(24)]
    plots.draw_convergence(results, tmp_path / "c.png", plots.convergence_title(results))
    (fig,) = figures
    (ax,) = fig.get_axes()
    assert len(ax.get_lines()) == 25                                  # 24 methods and the reference slope
    assert len(set(_styles(ax))) == 25
    labels = [t.get_text() for t in fig.legends[0].get_texts()] if fig.legends else \
        [t.get_text() for t in ax.get_legend().get_texts()]
    assert "method 3: slope 4.00" in labels
    assert _legends_outside(fig) == 1
    _check_set(tmp_path / "c.png")


def test_convergence_is_faceted_by_order(tmp_path, figures):
    """One panel per order, each with the fitted slope in its labels and a reference line."""
    h = [0.1, 0.05, 0.025, 0.0125]
    results = [{"method": name, "order": p, "h": h, "error": [k * x ** p for x in h], "slope": float(p),
                "problem": "pendulum", "T": 10.0, "precision": "dd"}
               for name, p, k in [("Euler", 1, 1), ("midpoint", 2, 1), ("RK4", 4, 1), ("Gauss2", 4, 0.01),
                                  ("Verlet", 2, 30)]]
    plots.draw_convergence(results, tmp_path / "c.png", plots.convergence_title(results))
    (fig,) = figures
    axes = fig.get_axes()
    assert [ax.get_title(loc="left") for ax in axes] == [f"methods of order $p = {p}$" for p in (1, 2, 4)]
    texts = [[t.get_text() for t in ax.get_legend().get_texts()] for ax in axes]
    assert texts[1][:2] == ["midpoint: slope 2.00", "Verlet: slope 2.00"]
    assert any("reference slope 4" in t for t in texts[2])
    assert _legends_outside(fig) == 3


def _fake_scene(name="s", plots_=("invariants", "state"), invariants=("H",)):
    problem = SimpleNamespace(invariants={k: None for k in invariants}, kind="hamiltonian")
    return SimpleNamespace(name=name, title="A $5 scene: identical runs", plots=plots_, problem=problem)


def _run_meta(label):
    return {"label": label, "precision": "float64", "status": "completed"}


def test_coinciding_series_are_made_visible(tmp_path, figures):
    """Runs with identical data (fig3_09: Gauss2 with and without projection): the later one is
    dashed in gaps of the earlier one, with hollow markers, and its label says so; a run that
    differs is left alone.  Every plot of the scene has its legend outside the data."""
    t = np.linspace(0, 10, 200)
    e = 1e-10 * (1 + np.sin(t) ** 2)
    y = np.column_stack([np.cos(t), -np.sin(t)])
    arrays = {"run0_t": t, "run0_H": e, "run0_y": y, "run1_t": t, "run1_H": e.copy(), "run1_y": y.copy(),
              "run2_t": t, "run2_H": 1e-6 * t, "run2_y": 1.5 * y}
    meta = {"complete": True, "runs": [_run_meta("Gauss2"), _run_meta("Gauss2 + projection"), _run_meta("RK4")]}
    names = plots.draw(_fake_scene(), meta, arrays, tmp_path)
    assert names == ["s_invariants.png", "s_state.png"]
    for fig in figures:
        assert _legends_outside(fig) == 1
        ax = fig.get_axes()[0]
        lines = [ln for ln in ax.get_lines() if not ln.get_label().startswith("_")]
        assert lines[1].get_label() == "Gauss2 + projection (coincides with Gauss2)"
        assert "coincides" not in lines[2].get_label() and "coincides" not in lines[0].get_label()
        assert lines[1].get_linestyle() != lines[0].get_linestyle() and lines[1].get_fillstyle() == "none"
        assert len(set(_styles(ax))) == 3
        legend = fig.legends[0] if fig.legends else ax.get_legend()
        assert "Gauss2 + projection (coincides with Gauss2)" in " ".join(
            t.get_text().replace("\n", " ") for t in legend.get_texts())
        assert all("$5" not in t.get_text() or "\\$5" in t.get_text() for t in fig.findobj(_text_class()))
    for n in names:
        _check_set(tmp_path / n)


def _text_class():
    from matplotlib.text import Text
    return Text


def test_mostly_coinciding_series_are_named_with_the_panels(tmp_path, figures):
    """Several panels with the same runs: a run that coincides in one panel only is marked
    there, and its label names that panel."""
    t = np.linspace(0, 10, 100)
    arrays = {"run0_t": t, "run0_H": 1e-8 + 0 * t, "run0_L": 1e-9 * (1 + t),
              "run1_t": t, "run1_H": 1e-8 + 0 * t, "run1_L": 1e-12 * (1 + t)}
    meta = {"complete": True, "runs": [_run_meta("A"), _run_meta("B")]}
    plots.draw(_fake_scene(plots_=("invariants",), invariants=("H", "L")), meta, arrays, tmp_path)
    (fig,) = figures
    label = [ln.get_label() for ln in fig.get_axes()[0].get_lines()][1]
    assert label.startswith("B (coincides with A in $|H(y_n)-H(y_0)|$")
    assert _legends_outside(fig) == 1


def test_parasitic_plot_prints_constants_as_decimals(tmp_path, figures):
    t = np.linspace(0, 10, 50)
    c = 1e-8 * np.exp(0.3 * t)
    arrays = {"run0_t": t, "run0_parasitic_0": c, "run0_parasitic_1": c.copy(), "run0_predicted_0": 0.3 * t}
    modes = [{"zeta": "-1/2 - sqrt(3)*I/2", "mu": "2.15470053838", "max": 1.0},
             {"zeta": "-1/2 + sqrt(3)*I/2", "mu": "2.15470053838", "max": 1.0}]
    meta = {"complete": False, "runs": [{**_run_meta("GLM"), "parasitic_modes": modes}]}
    assert plots.draw(_fake_scene(plots_=("parasitic",)), meta, arrays, tmp_path) == ["s_parasitic.incomplete.png"]
    (fig,) = figures
    texts = [t.get_text() for t in fig.findobj(_text_class())]
    assert any("$\\zeta$ = -0.5 ± 0.86603i, $\\mu$ = 2.1547" in t.replace("\n", " ") for t in texts), texts
    assert not any("sqrt" in t for t in texts)
    assert _legends_outside(fig) == 1


def test_decimal():
    assert style.decimal(sp.CRootOf(sp.Symbol("x") ** 5 - sp.Symbol("x") - 1, 0)) == "1.1673"
    assert style.decimal(1 + 2 * sp.sqrt(3) / 3) == "2.1547"
    assert style.decimal("-1/2 + sqrt(3)*I/2") == "-0.5 + 0.86603i"
    assert style.decimal("(1+2j)") == "1 + 2i"
    assert style.decimal("__import__('os').system('true')").startswith("__import__")     # read, never run
    assert style.decimal(sp.oo) == "∞"


def test_conjugate_zetas_joined_by_value_not_by_text():
    """A legend's ζ pair is written a ± bi only when the two are complex conjugates as numbers:
    the same pair given as sympy numbers and as differently spelt text; two real ζ (whose
    decimals also differ by a sign) and a repeated complex ζ stay a list."""
    w = sp.Rational(-1, 2) + sp.sqrt(3) * sp.I / 2
    spelt = plots.zeta_text(["-1/2 - sqrt(3)*I/2", "(-0.5+0.8660254037844386j)"])
    assert plots.zeta_text([w, sp.conjugate(w)]) == spelt == "-0.5 ± 0.86603i"
    assert plots.zeta_text([sp.I, -sp.I]) == "± 1i"
    assert plots.zeta_text(["1", "-1"]) == "1, -1"
    assert plots.zeta_text([w, w]) == "-0.5 + 0.86603i, -0.5 + 0.86603i"


def test_stability_figures_print_decimals_not_crootof(tmp_path, figures):
    """A Y* that is a CRootOf: the legends show 1.1673, no text of either figure contains
    CRootOf (the exact form is the files' caption)."""
    from tableau_lab.experiments.stability_plots import draw_stability
    x = sp.Symbol("x")
    result = SimpleNamespace(method="RK4 with a made-up Y*", variable="z", interval_kind="every |w| <= 1",
                             polynomial="w - (1 + z + z**2/2 + z**3/6 + z**4/24)",
                             imaginary_interval=sp.CRootOf(x ** 5 - x - 1, 0))
    paths = draw_stability(result, tmp_path, "m")
    assert [p.name for p in paths] == ["m_region.png", "m_axis.png"]
    assert len(figures) == 2
    for fig in figures:
        texts = [t.get_text() for t in fig.findobj(_text_class())]
        assert not any("CRootOf" in t for t in texts), texts
        assert any("1.1673" in t for t in texts)
        assert _legends_outside(fig) == 1
    for p in paths:
        _check_set(p)
        assert b"CRootOf" in p.with_suffix(".pdf").read_bytes()


def test_workprecision_and_roundoff_figures(tmp_path, figures):
    pts = [{"steps": n, "cpu": 1e-3 * n, "nfev": 4 * n, "error": 1.0 / n ** 4, "invariant_error": 1.0 / n ** 4}
           for n in (100, 200, 400)]
    peer = [{"rtol": r, "cpu": 0.1 / r ** 0.1, "nfev": int(10 / r ** 0.2), "error": r, "invariant_error": r}
            for r in (1e-4, 1e-6)]
    data = {"name": "wp", "title": "Kepler", "problem": "kepler", "T": 100.0, "invariant": "H",
            "reference_error_bound": 1e-13, "series": {"RK4": pts, "Gauss2": [dict(p) for p in pts], "DOP853": peer}}
    plots.draw_workprecision(data, tmp_path / "wp.png")
    n = {"method": "m.json", "problem": "harmonic", "h": "1/100", "n": [0, 10, 100, 1000],
         "plain": [0, 1e-16, 3e-16, 1e-15], "compensated": [0, 1e-17, 2e-17, 4e-17],
         "slope_plain": 0.5, "slope_compensated": 0.4}
    plots.draw_roundoff(n, tmp_path / "r.png", plots.roundoff_title(n))
    wp, ro = figures
    assert _legends_outside(wp) == 1 and _legends_outside(ro) == 1
    labels = [t.get_text() for t in wp.legends[0].get_texts()]
    assert "Gauss2 (coincides with RK4)" in labels                   # identical sweeps, in all four panels
    assert [ax.get_xlabel() for ax in wp.get_axes()[2:]] == [style.CPU_LABEL, style.NFEV_LABEL]
    assert ro.get_axes()[0].get_xlabel() == style.STEPS_LABEL
    _check_set(tmp_path / "wp.png")
    _check_set(tmp_path / "r.png")


def _tiny_scene(tmp_path):
    """A scene folder as ``tableau-lab run`` leaves it, written here by hand (no run)."""
    (tmp_path / "gauss2.json").write_bytes((METHODS / "gauss2.json").read_bytes())
    scene = {"format": "tableau_lab/scene/1", "name": "tiny", "title": "Tiny", "problem": "harmonic",
             "h": "1/10", "steps": 20, "record_every": 2, "plots": ["invariants", "state"],
             "runs": [{"method": "gauss2.json", "label": "Gauss2"},
                      {"method": "gauss2.json", "project": ["H"], "label": "Gauss2 + projection"}]}
    (tmp_path / "tiny.json").write_text(json.dumps(scene))
    out = tmp_path / "out" / "tiny"
    out.mkdir(parents=True)
    t = np.linspace(0, 2, 11)
    y = np.column_stack([np.sin(t), np.cos(t)])
    np.savez_compressed(out / "data.npz", run0_t=t, run0_H=1e-16 * t, run0_y=y, run1_t=t, run1_H=0 * t, run1_y=y)
    runs = [{**_run_meta(label), "file": "gauss2.json", "projection": p, "method": "Gauss2"}
            for label, p in (("Gauss2", []), ("Gauss2 + projection", ["H"]))]
    meta = {"scene": str(tmp_path / "tiny.json"), "name": "tiny", "title": "Tiny", "complete": True, "runs": runs}
    (out / "meta.json").write_text(json.dumps(meta))
    return out


def test_replot_redraws_a_scene_folder_without_running(tmp_path, monkeypatch):
    """replot reads meta.json, data.npz and the scene file; the integrator is never called; the
    data files are left byte for byte; the figures are the three formats; the command line
    prints what it wrote."""
    from tableau_lab.cli import main
    from tableau_lab.experiments import scene
    from tableau_lab.experiments.replot import ReplotError, replot
    from tableau_lab.numeric import integrate

    def no_run(*a, **k):
        raise AssertionError("replot ran an integration")
    monkeypatch.setattr(integrate, "integrate", no_run)
    monkeypatch.setattr(scene, "run_one", no_run)
    out = _tiny_scene(tmp_path)
    data = {p.name: p.read_bytes() for p in out.iterdir()}
    written = replot(out)
    assert [p.name for p in written] == ["tiny_invariants.png", "tiny_state.png"]
    for p in written:
        _check_set(p)
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.name in data} == data
    assert main(["replot", str(tmp_path / "out")]) == 0                 # a folder above: searched
    with pytest.raises(ReplotError, match="not a saved output"):
        replot(tmp_path / "tiny.json")
    assert main(["replot", str(tmp_path / "tiny.json")]) == 2


def test_replot_redraws_json_outputs(tmp_path):
    """Convergence and round-off JSON files: NAME.png (and PDF, SVG) beside them."""
    from tableau_lab.experiments.replot import kind_of, replot
    h = [0.1, 0.05]
    conv = [{"method": "RK4", "order": 4, "h": h, "error": [1e-4, 6.25e-6], "slope": 4.0, "verdict": "order confirmed",
             "problem": "kepler", "T": 10.0, "precision": "float64"}]
    (tmp_path / "convergence_kepler_float64.json").write_text(json.dumps(conv))
    ro = {"method": "methods/rk4.json", "problem": "harmonic", "h": "1/100", "steps": 100, "n": [0, 10, 100],
          "plain": [0, 1e-16, 3e-16], "compensated": [0, 1e-17, 2e-17], "slope_plain": 0.5, "slope_compensated": 0.4}
    (tmp_path / "roundoff_rk4_harmonic.json").write_text(json.dumps(ro))
    assert kind_of(tmp_path / "convergence_kepler_float64.json") == "convergence"
    assert kind_of(tmp_path / "roundoff_rk4_harmonic.json") == "roundoff"
    written = replot(tmp_path)
    assert sorted(p.name for p in written) == ["convergence_kepler_float64.png", "roundoff_rk4_harmonic.png"]
    for p in written:
        _check_set(p)


def test_style_imports_no_matplotlib():
    """Importing the style module (and so plots.py) costs no matplotlib: exact commands stay light."""
    code = ("import sys; import tableau_lab.experiments.figure_style, tableau_lab.experiments.replot; "
            "assert 'matplotlib' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


def test_every_figure_under_reports_has_pdf_and_svg():
    """Every figure stem under reports/ (reports/proofs aside: proof reports) has its PNG, PDF
    and SVG."""
    pngs = [p for p in (ROOT / "reports").rglob("*.png") if "proofs" not in p.relative_to(ROOT / "reports").parts]
    assert pngs
    missing = [str(p.relative_to(ROOT)) for p in pngs
               if not (p.with_suffix(".pdf").exists() and p.with_suffix(".svg").exists())]
    assert not missing, f"figures without their PDF or SVG (tableau-lab replot reports): {missing}"
