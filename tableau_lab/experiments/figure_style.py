r"""The one figure style of tableau_lab: every plotting function of the package uses it.

* **Series.**  A colour-blind-safe palette (Okabe & Ito, without its yellow, which is too light
  on white) combined with markers and line styles: series i gets colour i mod 7, marker i mod 8
  and line style ⌊i/7⌋ mod 4, so the first :data:`DISTINCT` (56) series of an axes differ in
  (colour, marker) and the first 28 in (colour, line style) as well.  It is the axes' property
  cycle (:func:`pyplot` sets it), so a plain ``ax.plot`` gets it; :func:`series_style` gives
  the same style by index.  Lines with many points get a marker every :data:`MARK_SPACING` of
  the axes' diagonal (offset per line), not one per point.
* **Coinciding series** (:func:`mark_coinciding`): a later line that lies on an earlier one (in
  the axes' coordinates, within :data:`COINCIDE` everywhere, or at :data:`MOSTLY` of its points)
  is redrawn dashed, in gaps that let the earlier line show, with hollow, larger markers, and its
  label says "(coincides with …)".
* **Legends** never cover data (:func:`legend`): beside the axes (right) or below the figure,
  labels wrapped.
* **Text.**  Axis labels name the quantity and its unit where it has one (:data:`T_LABEL`,
  :data:`H_LABEL`, :data:`CPU_LABEL`, :data:`NFEV_LABEL`); formulas in matplotlib's mathtext
  (:func:`invariant_error`: ``$|H(y_n)-H(y_0)|$``); text from data passes through
  :func:`plain` (a ``$`` in a label is not mathtext); exact constants are printed as decimals
  (:func:`decimal`: ``Y* = 2.0779``, never ``CRootOf(…)``), the exact form going into the
  figure's caption (:func:`save`'s ``caption``: the PDF's Subject, the SVG's and PNG's
  Description) and the data files.
* **Sizes** for print: at most :data:`PRINT_WIDTH` inches wide (a page's text width, so the
  :data:`FONT_SIZE`-point text is printed at that size), panels :data:`PANEL_HEIGHT` high.
* **Files** (:func:`save`): ``NAME.png`` at :data:`DPI` dpi with ``NAME.pdf`` and ``NAME.svg``
  beside it, written as one set (:func:`tableau_lab.files.output_phase`: the folder's lock, all
  three staged and moved into place together, or none), reproducibly (no dates in the PDF or the
  SVG, fixed SVG ids).

matplotlib (Agg backend) is imported by :func:`pyplot`, never at import time.
"""
from __future__ import annotations

import ast
import cmath
import logging
import math
import operator
import os
from pathlib import Path

import numpy as np

__all__ = ["DPI", "FORMATS", "formats", "PALETTE", "MARKERS", "LINESTYLES", "DISTINCT", "PRINT_WIDTH", "PANEL_HEIGHT",
           "FONT_SIZE", "SMALL_FONT", "T_LABEL", "H_LABEL", "CPU_LABEL", "NFEV_LABEL", "pyplot", "rc",
           "series_style", "mark_coinciding", "legend", "title", "wrap", "plain", "math_name", "invariant_error",
           "decimal", "save", "siblings", "thin_markers"]

DPI = 200                                   # the PNG's resolution (dots per inch)
FORMATS = (".png", ".pdf", ".svg")          # written side by side, the PNG first (its name is the figure's)
FORMATS_ENV = "TABLEAU_LAB_FIGURE_FORMATS"   # e.g. "png": fewer formats (the test suite's setting, tests/conftest.py)


def formats() -> tuple:
    """The formats a figure is written in: :data:`FORMATS`, or those named (comma-separated) in
    ``$TABLEAU_LAB_FIGURE_FORMATS`` — the PNG always, as it names the figure.  The test suite
    draws PNG only (a PDF and an SVG add about 0.5 s a figure); tests/test_figures.py checks all three.

    >>> formats() == FORMATS or formats()[0] == ".png"
    True
    """
    raw = os.environ.get(FORMATS_ENV, "").strip()
    if not raw:
        return FORMATS
    chosen = {"." + f.strip().lower().lstrip(".") for f in raw.split(",")}
    return tuple(f for f in FORMATS if f == ".png" or f in chosen)
PALETTE = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000")   # Okabe–Ito
MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")
LINESTYLES = ("-", "--", "-.", ":")
DISTINCT = math.lcm(len(PALETTE), len(MARKERS))     # series with distinct (colour, marker): 56
PRINT_WIDTH = 7.0                           # inches: the widest figure, a page's text width
PANEL_HEIGHT = 2.3                          # inches: one panel of a column of panels
SMALL_PANEL_HEIGHT = 1.75                   # inches: one panel of a grid of small multiples
GRID_COLUMNS = 3                            # panels per row of a grid of small multiples
SQUARE_SIZE = (5.2, 5.0)                    # inches: an orbit, phase plot or region (legend added below)
FONT_SIZE = 9                               # points: labels and titles
SMALL_FONT = 8                              # points: tick labels and legends
LINE_WIDTH = 1.0
MARKER_SIZE = 4.0
DENSE = 30                                  # a line with more points gets spaced markers
MARK_SPACING = 0.1                          # … this fraction of the axes' diagonal apart
COINCIDE = 0.004                            # axes fraction: closer than this, two points coincide
MOSTLY = 0.9                                # fraction of points that makes a line "mostly" coincide
DASH = 3.0                                  # on-length (in line widths) of a coinciding line's dashes
LEGEND_WRAP = 40                            # characters per legend line
LEGEND_LINE = 0.17                           # inches: the height of a legend line
RIGHT_MAX = 8                               # entries beside one axes; more go below it
FLOOR_NOTE = "exact zeros drawn at the floor"

T_LABEL = "time $t$"
H_LABEL = "step size $h$"
CPU_LABEL = "CPU time (s)"
NFEV_LABEL = "$f$-evaluations"
STEPS_LABEL = "steps $n$"


def rc() -> dict:
    """The matplotlib settings of every figure (fonts, sizes, the series cycle, the files)."""
    from cycler import cycler
    styles = [series_style(i) for i in range(DISTINCT)]
    return {
        "font.size": FONT_SIZE, "axes.titlesize": FONT_SIZE, "axes.labelsize": FONT_SIZE,
        "figure.titlesize": FONT_SIZE + 1, "xtick.labelsize": SMALL_FONT, "ytick.labelsize": SMALL_FONT,
        "legend.fontsize": SMALL_FONT, "legend.frameon": False, "legend.handlelength": 3.0,
        "lines.linewidth": LINE_WIDTH, "lines.markersize": MARKER_SIZE,
        "axes.prop_cycle": cycler(color=[s["color"] for s in styles], marker=[s["marker"] for s in styles],
                                  linestyle=[s["linestyle"] for s in styles]),
        "axes.grid": True, "axes.grid.which": "both", "grid.alpha": 0.25, "grid.linewidth": 0.5,
        "mathtext.fontset": "dejavusans", "figure.constrained_layout.use": True,
        "savefig.dpi": DPI, "pdf.fonttype": 42, "svg.fonttype": "path", "svg.hashsalt": "tableau_lab",
        "path.simplify": True,
    }


def pyplot():
    """matplotlib's pyplot on the Agg backend with :func:`rc` applied (imported here, lazily)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    matplotlib.rcParams.update(rc())
    logging.getLogger("fontTools").setLevel(logging.ERROR)      # font subsetting's notes on old fonts
    return plt


def series_style(i: int) -> dict:
    """Colour, marker and line style of the i-th series (the axes' cycle, by index)."""
    return {"color": PALETTE[i % len(PALETTE)], "marker": MARKERS[i % len(MARKERS)],
            "linestyle": LINESTYLES[(i // len(PALETTE)) % len(LINESTYLES)]}


# ---- text ------------------------------------------------------------------------------------

def plain(text) -> str:
    """Text from data (labels, titles) for a figure: a ``$`` is a dollar sign, not mathtext."""
    return str(text).replace("$", r"\$")


def wrap(text: str, width: int = LEGEND_WRAP) -> str:
    """``text`` broken into lines of at most ``width`` characters (never inside a $…$ formula)."""
    if len(text) <= width or "\n" in text:
        return text
    words, lines, line, math_open = text.split(" "), [], "", False
    for w in words:
        if line and not math_open and len(line) + 1 + len(w) > width:
            lines.append(line)
            line = w
        else:
            line = f"{line} {w}" if line else w
        math_open ^= (w.count("$") - w.count(r"\$")) % 2 == 1
    return "\n".join([*lines, line])


def title(target, text: str, width_inches: float | None = None) -> None:
    """A title wrapped to the width of ``target`` (an Axes, or a Figure: its suptitle)."""
    is_fig = hasattr(target, "suptitle")
    fig = target if is_fig else target.figure
    if width_inches is None:
        width_inches = fig.get_figwidth() * (1.0 if is_fig else target.get_position().width)
    size = FONT_SIZE + (1 if is_fig else 0)
    chars = max(30, int(width_inches * 72 / (0.55 * size)))
    text = "\n".join(wrap(part, chars) for part in str(text).split("\n"))
    if is_fig:
        fig.suptitle(text)
    else:
        target.set_title(text)


def math_name(name: str) -> str:
    """An invariant's name in mathtext (inside $…$): H, L_x, I_1, \\tilde{H} for "H~"."""
    name = str(name)
    if name.endswith("~"):
        return rf"\tilde{{{math_name(name[:-1])}}}"
    if len(name) == 1 and name.isalpha():
        return name
    if 2 <= len(name) <= 3 and name[0].isalpha() and name[1:].isalnum():
        return f"{name[0]}_{{{name[1:]}}}"
    safe = "".join(c for c in name if c.isalnum() or c == "_").replace("_", r"\_")
    return rf"\mathrm{{{safe or '?'}}}"


def invariant_error(name: str, at: str = "y_n") -> str:
    """``$|H(y_n)-H(y_0)|$`` for the invariant ``name``."""
    m = math_name(name)
    return f"$|{m}({at})-{m}(y_0)|$"


_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: operator.pow}
_FUNCTIONS = {"sqrt": cmath.sqrt, "exp": cmath.exp, "cos": cmath.cos, "sin": cmath.sin, "log": cmath.log,
              "Abs": abs, "re": lambda z: complex(z).real, "im": lambda z: complex(z).imag}
_NAMES = {"I": 1j, "pi": math.pi, "E": math.e, "oo": math.inf}


def _evaluate(node):
    """A number from the syntax tree of an arithmetic expression (numbers, + − × ÷ **, sqrt, exp,
    cos, sin, log, I, pi, E): never ``eval``."""
    if isinstance(node, ast.Expression):
        return _evaluate(node.body)
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float, complex)) \
            and not isinstance(node.value, bool):
        return node.value
    if isinstance(node, ast.Name) and node.id in _NAMES:
        return _NAMES[node.id]
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        v = _evaluate(node.operand)
        return -v if isinstance(node.op, ast.USub) else v
    if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
        a, b = _evaluate(node.left), _evaluate(node.right)
        if isinstance(node.op, ast.Pow) and abs(b) > 64:
            raise ValueError("exponent too large")
        return _BINARY[type(node.op)](a, b)
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in _FUNCTIONS \
            and len(node.args) == 1 and not node.keywords:
        return _FUNCTIONS[node.func.id](_evaluate(node.args[0]))
    raise ValueError("not an arithmetic expression")


def complex_value(value, digits: int = 15) -> complex | None:
    """An exact constant (a sympy number, a float or complex, or text such as
    "-1/2 - sqrt(3)*I/2", read by a small arithmetic reader, never ``eval``) as a complex
    number to ``digits``; None when it is not a number.

    >>> complex_value("-1/2 - sqrt(3)*I/2") == complex(-0.5, -3 ** 0.5 / 2), complex_value("x") is None
    (True, True)
    """
    if hasattr(value, "evalf"):                          # sympy, without importing it
        try:
            return complex(value.evalf(digits))
        except (TypeError, ValueError):
            value = str(value)
    if isinstance(value, str):
        try:
            return complex(_evaluate(ast.parse(value.strip().replace("^", "**"), mode="eval")))
        except (SyntaxError, ValueError, TypeError, ZeroDivisionError, OverflowError, RecursionError):
            return None
    return complex(value)


def decimal(value, digits: int = 5) -> str:
    """An exact constant as a decimal with ``digits`` significant digits, for a legend or title:
    a sympy number (radicals, ``CRootOf``), a float or complex, or text such as
    "-1/2 - sqrt(3)*I/2" (read by a small arithmetic reader, never ``eval``).  Text that is not a
    number comes back shortened to 24 characters."""
    z = complex_value(value, digits + 10)
    if z is None:
        text = str(value).strip()
        return text if len(text) <= 24 else text[:23] + "…"
    if not cmath.isfinite(z):
        return "-∞" if z.real < 0 and z.imag == 0 else "∞"
    scale = max(abs(z.real), abs(z.imag))
    re = z.real if abs(z.real) > 1e-12 * scale else 0.0
    im = z.imag if abs(z.imag) > 1e-12 * scale else 0.0
    if im == 0:
        return f"{re:.{digits}g}"
    if re == 0:
        return f"{im:.{digits}g}i"
    return f"{re:.{digits}g} {'-' if im < 0 else '+'} {abs(im):.{digits}g}i"


# ---- series ----------------------------------------------------------------------------------

def _labelled(line) -> bool:
    label = line.get_label()
    return bool(label) and not label.startswith("_") and len(line.get_xdata()) > 0


def _own(label: str) -> str:
    """A line's label without a note of this module."""
    return label.split(" (coincides with")[0].split(" (mostly coincides with")[0].replace("\n", " ")


def _leader(earlier: str, later: str) -> str:
    """How a note names the earlier line: its label, without a ": …" ending that the later
    label shares ("GLM43" for "GLM43: ζ = …" beside "GLM43 + projection: ζ = …")."""
    earlier = _own(earlier)
    head, sep, tail = earlier.rpartition(": ")
    return head if sep and head and _own(later).endswith(sep + tail) else earlier


def mark_coinciding(ax, relabel: bool = True) -> list:
    """Make the lines of ``ax`` that lie on an earlier line visible: redrawn dashed (gaps show
    the earlier line), hollow larger markers, offset; with ``relabel`` their labels end in
    "(coincides with …)" ("mostly" when only :data:`MOSTLY` of the points coincide).  Compared in
    the axes' coordinates (log scales included) after autoscaling.  Returns (later label, earlier
    label, fraction of coinciding points) for each."""
    lines = [ln for ln in ax.get_lines() if _labelled(ln)]
    if len(lines) < 2:
        return []
    ax.relim()
    ax.autoscale_view()
    to_axes = ax.transScale + ax.transLimits
    with np.errstate(all="ignore"):
        pts = [to_axes.transform(np.column_stack([np.asarray(ln.get_xdata(), dtype=float),
                                                  np.asarray(ln.get_ydata(), dtype=float)])) for ln in lines]
    leader, found = {}, []
    for j in range(1, len(lines)):
        for i in range(j):
            if i in leader or len(pts[i]) != len(pts[j]):
                continue
            a, b = pts[i], pts[j]
            fa, fb = np.isfinite(a).all(axis=1), np.isfinite(b).all(axis=1)
            both = fa & fb
            close = np.zeros(len(a), dtype=bool)
            close[both] = np.max(np.abs(a[both] - b[both]), axis=1) <= COINCIDE
            close |= ~fa & ~fb
            fraction = float(np.mean(close))
            if fraction >= MOSTLY:
                leader[j] = i
                found.append((j, i, fraction))
                break
    followers: dict = {}
    for j, i, _ in found:
        followers.setdefault(i, []).append(j)
    out = []
    for j, i, fraction in found:
        group = followers[i]
        k, m = group.index(j) + 1, len(group)
        ln = lines[j]
        if _increasing(np.asarray(ln.get_xdata(), dtype=float)):
            ln.set_linestyle((k * DASH, (DASH, m * DASH)))     # its own slot of each period: the leader shows too
        else:                                                # a curve that passes over itself (an orbit):
            ln.set_linestyle("None")                         # dashes would cover the leader; markers only
        if ln.get_marker() in (None, "None", "", " "):
            ln.set_marker(MARKERS[(j + k) % len(MARKERS)])
        ln.set_fillstyle("none")
        ln.set_markersize(MARKER_SIZE * (1.4 + 0.4 * k))
        ln.set_zorder(lines[i].get_zorder() + 0.1 * k)
        what = "coincides" if fraction == 1.0 else "mostly coincides"
        out.append((ln.get_label(), lines[i].get_label(), fraction))
        if relabel:
            ln.set_label(f"{ln.get_label()} ({what} with {_leader(lines[i].get_label(), ln.get_label())})")
    return out


def thin_markers(fig) -> None:
    """Lines with more than :data:`DENSE` points: a marker every :data:`MARK_SPACING` of the
    axes' diagonal along a curve over an increasing x (time series), every n-th point on other
    curves (orbits), offset per line so that markers of different lines do not pile up."""
    for ax in fig.get_axes():
        to_axes = ax.transScale + ax.transLimits
        for k, ln in enumerate(ax.get_lines()):
            x = np.asarray(ln.get_xdata(), dtype=float)
            if ln.get_marker() in (None, "None", "", " ") or ln.get_markevery() is not None or len(x) <= DENSE:
                continue
            share = (k % len(PALETTE)) / len(PALETTE)
            if _increasing(x):             # evenly along the x axis, whatever the curve does
                with np.errstate(all="ignore"):
                    u = to_axes.transform(np.column_stack([x, np.zeros_like(x)]))[:, 0]
                u = np.where(np.isfinite(u), u, -np.inf)
                idx = np.searchsorted(u, np.arange(share * MARK_SPACING, 1.0, MARK_SPACING))
                ln.set_markevery(sorted(set(int(i) for i in idx if i < len(x))))
            else:
                every = max(1, int(len(x) * MARK_SPACING))
                ln.set_markevery((int(share * every), every))


def _increasing(x) -> bool:
    x = x[np.isfinite(x)]
    return bool(len(x)) and bool(np.all(np.diff(x) >= 0))


def legend(axes, where: str = "right", notes: bool = True, entries=None, **kw):
    """The legend of ``axes`` (an Axes, or a list of Axes showing the same series: the first
    one's entries) outside the data: ``where="right"`` beside the (first) axes, ``"below"``
    under the figure.  Coinciding lines are marked first (``notes``; :func:`mark_coinciding`;
    with a list, in every axes, and a label names the panels where it coincides when that is
    not all of them).  ``entries``: (label, line properties) pairs instead of the lines of the
    axes (a legend for many panels whose lines differ).  Labels are wrapped; returns the Legend
    (None without labelled lines)."""
    many = isinstance(axes, (list, tuple, np.ndarray))
    axs = list(np.ravel(axes)) if many else [axes]
    first = axs[0]
    if notes:
        if len(axs) == 1:
            mark_coinciding(first)
        else:
            _mark_panels(axs)
    if entries is not None:
        from matplotlib.lines import Line2D
        handles, labels = [Line2D([], [], **props) for _, props in entries], [label for label, _ in entries]
    else:
        handles, labels = first.get_legend_handles_labels()
    if not handles:
        return None
    labels = [wrap(label) for label in labels]
    fig = first.figure
    alone = sum(ax.get_visible() for ax in fig.get_axes()) == 1
    if where == "right" and alone and len(labels) > RIGHT_MAX:
        where, kw = "below", {"ncols": 2, **kw}                     # a long legend: under the axes, in columns
    if where == "right":
        if alone:                                                   # the legend may need a taller figure
            fig.set_figheight(max(fig.get_figheight(), legend_height(labels) + 1.0))
        return first.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0, **kw)
    if where == "below":
        kw.setdefault("ncols", 2 if len(handles) > 3 else len(handles))
        fig.set_figheight(fig.get_figheight() + legend_height(labels) / kw["ncols"] + 0.1)   # room for it
        return fig.legend(handles, labels, loc="outside lower center", **kw)
    raise ValueError(f"legend: where={where!r} is not 'right' or 'below'")


def legend_height(labels) -> float:
    """Inches that a one-column legend of these labels (wrapped) takes."""
    return LEGEND_LINE * sum(wrap(label).count("\n") + 1.3 for label in labels)


def _mark_panels(axs) -> None:
    """Coinciding lines in panels that show the same series (by label): marked in each panel;
    the first panel's labels carry the notes, naming the panels when not all."""
    notes: dict = {}
    for n, ax in enumerate(axs):
        for later, earlier, fraction in mark_coinciding(ax, relabel=False):
            notes.setdefault((later, earlier), []).append((n, fraction))
    names = [ax.get_ylabel() or f"panel {n + 1}" for n, ax in enumerate(axs)]
    for ln in axs[0].get_lines():
        for (later, earlier), where in notes.items():
            if ln.get_label() != later:
                continue
            what = "coincides" if all(f == 1.0 for _, f in where) else "mostly coincides"
            panels = "" if len(where) == len(axs) else " in " + ", ".join(names[n] for n, _ in where)
            ln.set_label(f"{later} ({what} with {_leader(earlier, later)}{panels})")


# ---- files -----------------------------------------------------------------------------------

def siblings(target) -> list:
    """The files of a figure: NAME.png, NAME.pdf, NAME.svg (``target`` is NAME.png; :func:`formats`)."""
    target = Path(target)
    return [target.with_suffix(s) for s in formats()]


def _metadata(fmt: str, caption: str | None) -> dict:
    if fmt == ".pdf":                       # no creation date: an unchanged figure is the same file
        return {"CreationDate": None, **({"Subject": caption} if caption else {})}
    if fmt == ".svg":
        return {"Date": None, **({"Description": caption} if caption else {})}
    return {"Description": caption} if caption else {}


def save(fig, target, caption: str | None = None) -> list:
    """Write ``fig`` as ``target`` (NAME.png, :data:`DPI` dpi) and NAME.pdf, NAME.svg beside it:
    one set (:func:`tableau_lab.files.output_phase` on the folder: its lock, every file staged
    and moved into place together; inside a caller's phase the files join its set).  ``caption``
    (the exact constants of the figure, say) goes into the files' metadata.  Closes the figure;
    returns the three paths."""
    from ..files import atomic_write, output_phase
    target = Path(target)
    if target.suffix.lower() != ".png":
        raise ValueError(f"{target}: a figure is named by its PNG (NAME.png)")
    thin_markers(fig)
    paths = siblings(target)
    try:
        with output_phase(target.parent):
            for path in paths:
                fmt = path.suffix
                atomic_write(path, lambda tmp, fmt=fmt: fig.savefig(tmp, format=fmt[1:], dpi=DPI, bbox_inches="tight",
                                                                    metadata=_metadata(fmt, caption)), suffix=fmt)
    finally:
        import matplotlib.pyplot as plt
        plt.close(fig)
    return paths
