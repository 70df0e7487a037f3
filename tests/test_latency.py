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


def _fake_compiled_loop(folder, capsys, seen):
    """The pure loop dressed as a compiled loop module written in ``folder`` (its first call is a
    'compile'): each call of ``run`` notes what stderr said before it — no numba compile."""
    from types import SimpleNamespace

    from tableau_lab.numeric import kernels
    from tableau_lab.numeric.codegen import compile_problem
    cp = compile_problem("harmonic")
    pure = kernels.pure_loop(cp, "float64")

    def run(*args):
        seen.append(capsys.readouterr().err)
        return pure.run(*args)

    fake = SimpleNamespace(**{k: v for k, v in vars(pure).items() if not k.startswith("__")})
    fake.__name__, fake.__file__ = "tableau_lab_kernel_fake", str(folder / "tableau_lab_kernel_fake.py")
    fake.run, fake.described = run, "harmonic (float64, a shape)"
    return cp, fake


def test_cold_compile_is_announced_before_it_once(tmp_path, monkeypatch, capsys):
    """Issue 32, item 3: a first call whose compile is cold (not in numba's disk cache beside
    the module) is announced on stderr BEFORE it starts, terminal or not (capsys is no
    terminal), naming the problem, arithmetic, shape and the cache folder; once per loop per
    process; a cache load is not announced."""
    from tableau_lab.exact.tableau_json import load
    from tableau_lab.numeric import kernels
    from tableau_lab.numeric.export import to_numeric
    from tableau_lab.numeric.integrate import integrate
    seen: list = []
    cp, fake = _fake_compiled_loop(tmp_path, capsys, seen)
    monkeypatch.setattr(kernels, "compiled_loop", lambda *a, **k: fake)
    monkeypatch.setattr(kernels, "_NOTICED", set())
    nm = to_numeric(load("methods/gauss2.json"))

    def first_call():
        monkeypatch.setattr(kernels, "_COMPILE", {})          # this process has not called it yet
        seen.clear()
        integrate(nm, cp, cp.y0, 0.1, 5, kernel="compiled")
        return seen[0]

    said = first_call()
    assert said.startswith("tableau-lab: compiling the step loop for harmonic (float64, a shape) — one-off, "
                           f"cached in {tmp_path}"), said
    assert said.count("\n") == 1
    assert first_call() == ""                                  # once per loop per process
    monkeypatch.setattr(kernels, "_NOTICED", set())
    (tmp_path / "tableau_lab_kernel_fake.py").write_text("")
    (tmp_path / "__pycache__").mkdir()
    (tmp_path / "__pycache__" / "tableau_lab_kernel_fake.run-1.py311.nbi").write_bytes(b"")
    assert first_call() == ""                                  # in the disk cache: a load, not announced
