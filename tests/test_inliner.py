"""The pure loop with its one-line operations written in place (numeric/inliner.py): the same
numbers, bit for bit, as stepcore's functions run as they are — for every stage iteration the
pure loop runs (explicit, simplified Newton, fixed point, the split iteration of a separable
problem), with projection, in float64 and in mpmath — and the texts the package ships are the
ones the inliner makes from today's source."""
from pathlib import Path

import numpy as np
import pytest

from tableau_lab.exact.tableau_json import load
from tableau_lab.numeric import inliner, kernels
from tableau_lab.numeric.codegen import compile_problem
from tableau_lab.numeric.export import to_numeric
from tableau_lab.numeric.integrate import integrate

METHODS = Path(__file__).parent.parent / "methods"


CASES = [("rk4", "kepler", (), "float64", "auto"), ("gauss2", "pendulum", (), "float64", "auto"),
         ("glm43", "kepler", (), "float64", "auto"), ("gauss2", "kepler", ("H",), "float64", "auto"),
         ("radau_iia3", "pendulum", (), "float64", "newton"),
         ("lobatto_iiic3", "henon_heiles", (), "float64", "fixedpoint"),
         ("gauss2", "kepler", (), "mp:30", "auto")]


@pytest.mark.parametrize("method,problem,project,precision,solver", CASES)
def test_inlined_loop_is_the_loop_bit_for_bit(monkeypatch, method, problem, project, precision, solver):
    nm = to_numeric(load(METHODS / f"{method}.json"), "float64" if precision == "float64" else precision)
    cp = compile_problem(problem) if precision == "float64" else compile_problem(problem, "mpmath", 30)
    inv = tuple(cp.problem.invariants)
    steps = 40 if precision != "float64" else 300

    def run():
        return integrate(nm, cp, cp.y0, 0.01, steps, kernel="python", invariants=inv, project=project,
                         record_every=10, solver=solver)
    inlined = run()
    monkeypatch.setattr(kernels, "inline_functions", inliner.plain_functions)
    plain = run()
    assert inlined.loop == plain.loop == "python"
    assert [str(x) for x in np.ravel(inlined.final)] == [str(x) for x in np.ravel(plain.final)]
    assert (inlined.nfev, inlined.newton_iterations, inlined.projection_iterations) == \
        (plain.nfev, plain.newton_iterations, plain.projection_iterations)
    assert inlined.invariant_errors == plain.invariant_errors


def test_shipped_texts_are_today_s(tmp_path, monkeypatch):
    """What benchmarks/write_inlined.py ships is what the inliner makes now (otherwise: run it)."""
    monkeypatch.setenv("TABLEAU_LAB_CACHE", str(tmp_path))
    monkeypatch.setattr(inliner, "SHIPPED", tmp_path / "none")
    kernels.pure_loop(compile_problem("pendulum"), "float64")
    kernels.pure_loop(compile_problem("pendulum", "mpmath", 30), "mp")
    made = {p.name: p.read_text() for p in kernels.code_dir().glob("inlined_*.txt")}
    shipped = {p.name: p.read_text() for p in Path(inliner.__file__).parent.joinpath("inlined").glob("*.txt")}
    assert len(made) == 2
    assert made == shipped, "the shipped inlined texts are stale: python benchmarks/write_inlined.py"


def test_what_is_written_in_place_and_what_is_not():
    """One-expression and one-statement bodies are written in place; an argument with an effect
    is not evaluated twice (nor dropped); a constant folds a branch away; a local that shares a
    constant's name stays a local."""
    calls = []

    def twice(x):
        return x + x

    def put(a, i, v):
        a[i] = v

    def pick(flag, a):
        if flag == 1:
            return True
        return a != 0.0

    def effect():
        calls.append(1)
        return 2.0

    def body(out, K):
        put(out, 0, twice(3.0))
        put(out, 1, twice(effect()))
        put(out, 2, pick(FLAG, 0.0))  # noqa: F821 -- FLAG: a constant the inliner puts in
        put(out, 3, K)
    ns = inliner.inline_functions([body], {"twice": twice, "put": put, "pick": pick}, {"FLAG": 1, "K": 7},
                                  {"effect": effect})
    out = [None] * 4
    ns["body"](out, 5)
    assert out == [6.0, 4.0, True, 5] and calls == [1]
    names = ns["body"].__code__.co_names
    assert "put" not in names and "pick" not in names and "FLAG" not in names
    assert names.count("twice") == 1               # kept for the argument with an effect


def test_cached_text_read_only_from_a_regular_file(tmp_path):
    """A FIFO where a cached text would be is not opened (opening it would wait for a writer for
    ever): the text is made again instead."""
    import os
    import threading
    if not hasattr(os, "mkfifo"):
        pytest.skip("no FIFOs here")
    fifo = tmp_path / "inlined_x.txt"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(inliner._read(fifo)), daemon=True)
    reader.start()
    reader.join(timeout=5)
    assert got == [None], "the read waited on a FIFO"
    (tmp_path / "text.txt").write_text("x = 1\n")
    assert inliner._read(tmp_path / "text.txt") == "x = 1\n"
