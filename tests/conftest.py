"""Test-suite settings.

The compiled loops (numba) cost seconds of compilation per problem and method shape on a cold
cache, once; the suite runs the pure loop by default (TABLEAU_LAB_KERNEL=python: the same
algorithm, numeric/stepcore.py run in Python) and compiles only where a test asks for
``kernel="compiled"`` or precision dd — tests/test_kernels.py proves the two agree to
round-off — and then compiles loops for any shape (TABLEAU_LAB_SPECIALISE=0: one module per
problem, not one per problem and shape; test_kernels.py checks that a specialised loop
computes the same numbers bit for bit), and starts no background compile
(TABLEAU_LAB_BACKGROUND=0; tests/test_background.py asks for one).  Set TABLEAU_LAB_KERNEL=auto to run everything
compiled.
"""
import os

import pytest

os.environ.setdefault("TABLEAU_LAB_KERNEL", "python")
os.environ.setdefault("TABLEAU_LAB_SPECIALISE", "0")
os.environ.setdefault("TABLEAU_LAB_BACKGROUND", "0")   # no background compile (numeric/background.py) unless asked
os.environ.setdefault("TABLEAU_LAB_FIGURE_FORMATS", "png")   # figures as PNG only (test_figures.py: all three)


def benchmark_script(name: str):
    """benchmarks/<name>.py imported as a module (the scripts that write docs/ are tested through
    their functions)."""
    import importlib.util
    from pathlib import Path
    path = Path(__file__).resolve().parents[1] / "benchmarks" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    import sys
    sys.modules[name] = mod              # before executing it: dataclasses look their module up
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture
def figures(monkeypatch):
    """The figures that ``figure_style.save`` is given (drawn, before they are closed), in order
    (test_figures.py, test_stability_plots.py)."""
    from tableau_lab.experiments import figure_style as style
    seen = []
    real = style.save

    def save(fig, target, caption=None):
        fig.canvas.draw()
        seen.append(fig)
        return real(fig, target, caption)
    monkeypatch.setattr(style, "save", save)
    return seen
