"""The safe expression grammar: exact values, refusals, round trips."""
import pytest
import sympy as sp
from hypothesis import given, settings, strategies as st

from tableau_lab.exact.grammar import EntryError, format_entry, parameter, parse_entry


@pytest.mark.parametrize("text, value", [
    ("(3+sqrt(3))/6", (3 + sp.sqrt(3)) / 6),
    ("-43*sqrt(14595)/35490", -43 * sp.sqrt(14595) / 35490),
    ("1/(2-2**(1/3))", 1 / (2 - sp.cbrt(2))),
    ("1/(2-2^(1/3))", 1 / (2 - sp.cbrt(2))),
    ("2**-1", sp.Rational(1, 2)),
    ("-2**2", -4),                    # as in Python: power binds tighter than unary minus
    ("2**3**2", 512),                 # right-associative
    ("8**(2/3)", 4),
    ("4**(-1/2)", sp.Rational(1, 2)),
    ("sqrt(12)", 2 * sp.sqrt(3)),
    (" 1 / 4 ", sp.Rational(1, 4)),
    ("theta", parameter("theta")),
    ("-u22 + 2*u23", -parameter("u22") + 2 * parameter("u23")),
    ("(1 - theta)^2", (1 - parameter("theta")) ** 2),
    (7, 7),
])
def test_values(text, value):
    assert sp.simplify(parse_entry(text) - value) == 0


@pytest.mark.parametrize("text, fragment", [
    ("0.5", 'write it as a fraction, e.g. "1/2"'),
    (".5", "decimal"),
    ("1e-3", "decimal"),
    ("2**theta", "not a rational constant"),
    ("2**sqrt(2)", "not a rational constant"),
    ("2**(1/65)", "too large"),
    ("2**100", "too large"),
    ("pi()", "unknown function"),
    ("", "empty"),
    ("1 2", "unexpected"),
    ("a.b", "unexpected character '.'"),
    ("x[0]", "unexpected character '['"),
    ("'1'", "unexpected character"),
    ("1 // 2", "expected a number"),
    ("sqrt 2", "expected '('"),
])
def test_refused(text, fragment):
    with pytest.raises(EntryError, match=None) as info:
        parse_entry(text)
    assert fragment in str(info.value)


@pytest.mark.parametrize("value", [0.5, True, None, [1], {"a": 1}])
def test_non_text_refused(value):
    with pytest.raises(EntryError):
        parse_entry(value)


def test_parameters_are_real_symbols():
    assert parse_entry("theta").is_real
    assert parse_entry("theta") == sp.Symbol("theta", real=True)


_atoms = st.one_of(
    st.integers(-50, 50).map(str),
    st.sampled_from(["sqrt(2)", "sqrt(3)", "2**(1/3)", "theta", "x1", "(1/7)"]),
)


def _combine(children):
    return st.tuples(children, st.sampled_from(["+", "-", "*", "/"]), children).map(
        lambda t: f"({t[0]} {t[1]} {t[2]})")


@settings(max_examples=150, deadline=None)
@given(st.recursive(_atoms, _combine, max_leaves=6))
def test_round_trip_property(text):
    """parse(format(parse(t))) == parse(t) for random expressions (divisions by zero excluded)."""
    try:
        e = parse_entry(text)
    except EntryError as exc:
        assert "division by zero" in str(exc) or "finite" in str(exc)
        return
    again = parse_entry(format_entry(e))
    assert again == e
