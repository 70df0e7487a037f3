"""Issue 29, item 11 (the exact core's bullets), through the Python API: every refusal is the
project's own error (errors.InputError; a budget a BudgetError naming it), never a TypeError, a
plain ValueError or a sympy exception; JSON-level refusals name tableau entries one-based; the
MemoryError / RecursionError refusal names the command and its file.  The command-line cases are
in tests/hostile_cases.py (block "issue 29: exact core")."""
import argparse
import time

import pytest
import sympy as sp

from tableau_lab import cli
from tableau_lab.analysis.bseries import BSeries
from tableau_lab.analysis.method_series import method_series
from tableau_lab.budget import SERIES_ORDER, time_limit
from tableau_lab.errors import BudgetError, InputError
from tableau_lab.exact.tableau_json import TableauError, load, loads

GOOD = '{"name": "x", "kind": "rk", "A": [["1/2"]], "b": [1]}'


@pytest.mark.parametrize("value", [None, 5, 2.5, ["x"], {"name": "x"}])
def test_loads_of_a_non_text_is_a_tableau_error(value):
    with pytest.raises(TableauError, match="a tableau text is a str or bytes"):
        loads(value)


def test_huge_json_number_refused_at_once():
    t0 = time.process_time()
    with pytest.raises(TableauError, match=r"entry A row 1, column 1: 1e99999999 is a floating-point number"):
        loads(GOOD.replace('"1/2"', "1e99999999"), "m.json")
    assert time.process_time() - t0 < 5


def test_float_hint_is_exact_for_short_floats():
    with pytest.raises(TableauError, match='"5/2"'):
        loads(GOOD.replace('"1/2"', "0.25e1"), "m.json")


@pytest.mark.parametrize("text, entry", [
    (GOOD.replace('"1/2"', '"\\ud800"'), "A row 1, column 1"),
    (GOOD.replace('[1]', '[1, "\\u0007"]'), "b[2]"),
    (GOOD.replace('[1]', '[NaN]'), "b[1]"),
    (GOOD.replace('[["1/2"]]', '[["1/2"], [{"a": 1, "a": 2}]]'), "A row 2, column 1.a"),
    (GOOD.replace('}', ', "notes": ["ok", "\\u001b[2J"]}'), "notes[2]"),
])
def test_json_level_refusals_name_entries_one_based(text, entry):
    with pytest.raises(TableauError) as exc:
        loads(text, "m.json")
    assert f"m.json: entry {entry}:" in str(exc.value)
    assert "[0]" not in str(exc.value)


def test_method_series_beyond_the_budget_names_it():
    m = load("gauss2")
    with pytest.raises(BudgetError, match=f"series order budget of {SERIES_ORDER} exceeded.*budget.SERIES_ORDER"):
        method_series(m, 50)
    for bad in (0, -1, 2.5, "3"):
        with pytest.raises(InputError, match="the order must be an integer"):
            method_series(m, bad)
    with pytest.raises(BudgetError):
        BSeries(sp.QQ, {}, 13)


@pytest.mark.parametrize("exc", [MemoryError, RecursionError])
def test_memory_and_recursion_refusals_name_the_file(exc, capsys):
    def boom(args):
        raise exc()
    args = argparse.Namespace(command="verify", files=["deep/m.json"], run=boom, debug=False, timeout=0,
                              max_field_degree=64, entry_limit=None)
    assert cli.dispatch(args) == 2
    err = capsys.readouterr().err
    assert "verify of deep/m.json" in err and exc.__name__ in err


def test_budget_wrapped_by_library_code_is_still_the_budget():
    """sympy's conversions catch ValueError (BudgetError is one) and raise CoercionFailed in its
    place: the 8th-root exit 3 "at the budget".  The budget is reported, not an internal error."""
    from sympy.polys.polyerrors import CoercionFailed

    def convert():
        try:
            while True:
                pass
        except ValueError:
            raise CoercionFailed("nan is not in any domain")  # noqa: B904 -- sympy's own pattern, imitated
    with pytest.raises(BudgetError, match="time budget of 0.05 s exceeded"):
        with time_limit(0.05):
            convert()


def test_from_lists_never_evaluates_text(tmp_path):
    """A string entry given to the Python constructors is read by the tableau grammar, never by
    sympify (which evaluates Python: on 5ea0488 this entry created the marker file)."""
    import pytest

    from tableau_lab.exact.methods import GeneralLinearMethod, MethodError, RungeKutta
    marker = tmp_path / "pwned"
    evil = f"__import__('os').system('touch {marker}')"
    for make in (lambda: RungeKutta.from_lists([[evil]], [1]),
                 lambda: RungeKutta(A=[[evil]], b=[1], c=[0]),
                 lambda: GeneralLinearMethod(A=[[0]], U=[[1]], B=[[evil]], V=[[1]])):
        with pytest.raises(MethodError, match="names must start with a letter"):
            make()
    assert not marker.exists()
    assert RungeKutta.from_lists([[0, 0], ["2/3", 0]], ["1/4", "3/4"]).A[1, 0] == sp.Rational(2, 3)
