"""Fuzzing (issue 16, item 4): the entry grammar (tableau and problem dialects), the tableau JSON
loader and the scene loader, each for a bounded time (``TABLEAU_LAB_FUZZ_SECONDS``, default 12 s
per target), with hypothesis.  Every input either gives a value or the project's own input error
(``errors.InputError``: the message names the file and entry); any other exception fails, and so
does one input slower than ``SLOW`` s.  The seed corpus (tests/data/fuzz_seeds.json: inputs that
once crashed or hung, and valid ones to mutate from) runs first, every time.  Each target prints
its example count and its slowest input (``pytest -s -n 0``)."""
import json
import os
import time
from pathlib import Path

import pytest
import sympy as sp
from hypothesis import HealthCheck, given, seed, settings, strategies as st

from tableau_lab.errors import InputError
from tableau_lab.exact.grammar import parse_entry
from tableau_lab.exact.tableau_json import loads
from tableau_lab.experiments.scene import load_scene
from tableau_lab.numeric.expressions import parse_expression

SECONDS = float(os.environ.get("TABLEAU_LAB_FUZZ_SECONDS", "12"))
SLOW = 10.0          # seconds one input may take (the grammar's limits keep each entry small)
SEEDS = json.loads((Path(__file__).parent / "data" / "fuzz_seeds.json").read_text(encoding="utf-8"))

TOKENS = ["0", "1", "2", "3", "7", "12", "99999999999", "1.5", "1e5", "1e-300", ".5", "x", "q", "a", "b1", "pi",
          "nan", "inf", "E", "sqrt", "cos", "sin", "root", "exp", "log", "(", ")", ",", "+", "-", "*", "/", "**", "^",
          " ", "__", "'", '"', "[", "]", ".", "=", ";", "١", "½", "\x1b", "\u202e", "\x00", "é", "x**2 - 2", "pi/7",
          "k"]
entry_text = st.one_of(st.lists(st.sampled_from(TOKENS), max_size=30).map("".join), st.text(max_size=60))
json_value = st.recursive(st.none() | st.booleans() | st.integers(-10, 10 ** 6) | st.floats() | entry_text,
                          lambda inner: st.lists(inner, max_size=4) | st.dictionaries(entry_text, inner, max_size=4),
                          max_leaves=30)


def _fuzz(check, strategy, seeds):
    """Run ``check`` on every seed, then on hypothesis examples until SECONDS pass; returns
    (examples, slowest seconds, slowest input)."""
    stats = {"n": 0, "slow": 0.0, "input": None}

    def timed(x):
        t0 = time.perf_counter()
        try:
            check(x)
        except InputError:
            pass
        dt = time.perf_counter() - t0
        stats["n"] += 1
        if dt > stats["slow"]:
            stats["slow"], stats["input"] = dt, x
        assert dt < SLOW, f"{dt:.1f} s on {x!r:.200}"

    for x in seeds:
        timed(x)
    stop, k = time.monotonic() + SECONDS, 0
    while time.monotonic() < stop:
        @seed(k)
        @settings(max_examples=100, deadline=None, database=None,
                  suppress_health_check=list(HealthCheck))
        @given(strategy)
        def round_(x):
            timed(x)
        round_()
        k += 1
    print(f"\n{check.__name__}: {stats['n']} inputs, slowest {stats['slow']:.3f} s: {stats['input']!r:.120}")
    return stats


def test_fuzz_grammar():
    def grammar(text):
        e = parse_entry(text)
        assert isinstance(e, sp.Expr)
        try:
            parse_expression(text, {"x": sp.Symbol("x"), "q": sp.Symbol("q")})
        except InputError:
            pass
    _fuzz(grammar, entry_text, SEEDS["entries"])


def _method(kind, A, b, c, extra):
    return json.dumps({"format": "tableau_lab/1", "name": "fuzz", "kind": kind, "A": A, "b": b, "c": c, **extra})


method_text = st.one_of(
    st.builds(_method, st.sampled_from(["rk", "glm", "prk", "rocket", ""]), json_value, json_value, json_value,
              st.dictionaries(st.sampled_from(["U", "B", "V", "claims", "constants", "bhat", "Ahat", "x-note"]),
                              json_value, max_size=3)),
    st.builds(_method, st.just("rk"), st.lists(st.lists(entry_text, min_size=2, max_size=2), min_size=2, max_size=2),
              st.lists(entry_text, min_size=2, max_size=2), st.lists(entry_text, min_size=2, max_size=2), st.just({})),
    st.text(max_size=200))


def test_fuzz_tableau_json():
    def tableau(text):
        loads(text, "fuzz.json")
    _fuzz(tableau, method_text, SEEDS["tableaux"])


SCENE_KEYS = ["format", "name", "title", "seed", "notes", "problem", "h", "steps", "T", "runs", "record_every", "plots",
              "precision", "start", "monitor", "modified_energy", "bogus"]
scene_value = st.one_of(json_value, st.sampled_from(["pendulum", "kepler", "1/100", "gauss2.json", 10, "..", "float64",
                                                      "dd", "mp:32", ["invariants"], [{"method": "m.json"}],
                                                      {"terms": 2}, {"terms": "2"}, {"terms": 9}]))
scene_text = st.one_of(st.dictionaries(st.sampled_from(SCENE_KEYS), scene_value, max_size=8).map(json.dumps),
                       st.text(max_size=200))


def test_fuzz_scene(tmp_path):
    (tmp_path / "m.json").write_text(_method("rk", [["1/2"]], ["1"], ["1/2"], {}))
    path = tmp_path / "scene.json"

    def scene(text):
        path.write_text(text, encoding="utf-8", errors="surrogatepass")
        load_scene(path)
    _fuzz(scene, scene_text, SEEDS["scenes"])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.json", "scene.json"]     # nothing written


@pytest.mark.parametrize("text", SEEDS["entries"])
def test_seed_entries_refused_or_exact(text):
    """Each seed entry alone: an exact value or an EntryError, nothing else."""
    try:
        assert isinstance(parse_entry(text), sp.Expr)
    except InputError:
        pass
