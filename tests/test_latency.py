"""Issue 19, item 4: the exact commands pay only for what they use — none of them imports numba,
scipy, dask or matplotlib (the numeric side's heavy libraries).  Checked in a fresh interpreter
per command, as a user's call would run (``benchmarks/latency.py`` times them)."""
import subprocess
import sys

import pytest

HEAVY = ("numba", "scipy", "dask", "distributed", "matplotlib")
COMMANDS = [["verify", "methods/example4_glm.json"], ["order", "methods/gauss2.json"],
            ["stability", "methods/rk4.json"], ["modified", "methods/explicit_euler.json", "--order", "3"],
            ["solve", "methods/design/erk2_general.json", "--require", "symplectic"]]


@pytest.mark.parametrize("argv", COMMANDS, ids=lambda a: a[0])
def test_exact_commands_import_no_numeric_library(argv):
    probe = ("import sys\nfrom tableau_lab.cli import main\ncode = main(%r)\n"
             "heavy = sorted({m.split('.')[0] for m in sys.modules} & set(%r))\n"
             "print('HEAVY', heavy, file=sys.stderr)\nraise SystemExit(0 if code in (0, 1) else code)") % (argv, HEAVY)
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr[-500:]
    assert "HEAVY []" in p.stderr, p.stderr[-300:]


def test_package_import_is_cheap():
    """Issue 30: ``import tableau_lab`` loads no analysis and none of the heavy libraries (the public
    names are resolved on first use); the must-show calls of the API, in a fresh interpreter, give
    their values and import none of the numeric side's libraries either."""
    probe = ("import sys\nimport tableau_lab as tl\n"
             "heavy = lambda: sorted({m.split('.')[0] for m in sys.modules} & set(%r))\n"
             "first = (heavy(), sorted(m for m in sys.modules if m.startswith(('tableau_lab.', 'sympy'))))\n"
             "import sympy as sp\nm = tl.load('gauss:3'); assert int(m.order()) == 6\n"
             "assert tl.load('rk4').imaginary_stability_interval() == 2 * sp.sqrt(2)\n"
             "assert '1/12 f\\'\\'(f, f) + 1/3 f\\'f\\'f' in str(tl.load('explicit_euler').modified_equation(3))\n"
             "tl.list_methods()\n"
             "print('FIRST', first, 'THEN', heavy())") % (HEAVY,)
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr[-500:]
    assert "FIRST ([], []) THEN []" in p.stdout, p.stdout[-300:]
