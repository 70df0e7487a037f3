"""What an inline stability plot costs (issue 30, item 3): a script, not a test.

In one warm interpreter (tableau_lab, numpy and matplotlib imported, one plot drawn untimed), for
each method: seconds of its first ``plot_stability_region`` (the exact stability function or the
interpolated GLM polynomial, the boundary locus and window, the grid, the contours: what a notebook
cell waits for before the figure is rendered), the best of REPEATS further calls, and the seconds
to render the figure (Agg, what an inline display adds); then the order star and the imaginary-axis
plot (with its exact Y*: ``stability(m)``).  Wall-clock seconds on a shared machine: they vary.

Run: python benchmarks/inline_plots.py
"""
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from tableau_lab.exact.tableau_json import load
from tableau_lab.experiments.inline_plots import plot_imaginary_axis, plot_order_star, plot_stability_region

REGION = ["rk4", "gauss:3", "radau_iia3", "sdirk34", "glm43", "bdf:4", "glm6_moonshot"]
STAR = ["rk4", "gauss:3"]
AXIS = ["rk4", "glm43"]
REPEATS = 3


def timed(plot, m, render: bool = True):
    """(seconds of the call, seconds to render its figure, or 0 without ``render``)."""
    t0 = time.perf_counter()
    ax = plot(m)
    t1 = time.perf_counter()
    if render:
        ax.figure.canvas.draw()
    t2 = time.perf_counter()
    plt.close(ax.figure)
    return t1 - t0, t2 - t1


def main():
    timed(plot_stability_region, load("explicit_euler"))          # warm: matplotlib's first figure
    print(f"plot                   method        first call  best of {REPEATS}  render")
    for kind, plot, names in [("plot_stability_region", plot_stability_region, REGION),
                              ("plot_order_star", plot_order_star, STAR),
                              ("plot_imaginary_axis", plot_imaginary_axis, AXIS)]:
        for name in names:
            m = load(name)
            first, render = timed(plot, m)
            again = min(timed(plot, m, render=False)[0] for _ in range(REPEATS))
            print(f"{kind:22s} {name:13s} {first:8.3f} s  {again:7.3f} s  {render:.3f} s")


if __name__ == "__main__":
    main()
