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


@pytest.mark.parametrize("text, value, minpoly", [
    # cos(π/18) = cos 10°: cos 30° = 4c³ − 3c = √3/2, so 64c⁶ − 96c⁴ + 36c² − 3 = 0
    ("cos(pi/18)", sp.cos(sp.pi / 18), "64*x**6 - 96*x**4 + 36*x**2 - 3"),
    # SDIRK34's γ: the order-4 condition of a 3-stage SDIRK, γ³ − 3γ²/2 + γ/2 − 1/24 = 0 ([HW96] IV.6)
    ("1/2 + cos(pi/18)/sqrt(3)", sp.Rational(1, 2) + sp.cos(sp.pi / 18) / sp.sqrt(3), "24*x**3 - 36*x**2 + 12*x - 1"),
    ("sin(pi/7)", sp.sin(sp.pi / 7), None),
    ("cos(2*pi/3)", sp.Rational(-1, 2), None),
    ("root(x**3 - 3*x + 1, 2)", 2 * sp.cos(4 * sp.pi / 9), "x**3 - 3*x + 1"),     # roots 2cos(2kπ/9)
    ("root(x^3 - 3*x + 1, 0, 1)", 2 * sp.cos(4 * sp.pi / 9), None),
    ("root(2*x - 1, 1)", sp.Rational(1, 2), None),
    ("root(x**2 - 2, 1) + sqrt(2)", 0, None),
])
def test_algebraic_numbers(text, value, minpoly):
    """cos, sin of rational multiples of π and real roots of polynomials are exact algebraic
    numbers: equal to an independent expression (checked numerically to 50 digits, then by
    the minimal polynomial where given), and the printed form reads back to the same value."""
    from tableau_lab.exact.field import is_zero
    e = parse_entry(text)
    assert abs(sp.N(e - value, 50)) < sp.Float("1e-45")
    if minpoly is not None:
        x = sp.Symbol("x")
        assert sp.Poly(sp.minimal_polynomial(e, x), x).monic() == sp.Poly(sp.sympify(minpoly), x).monic()
        assert is_zero(sp.sympify(minpoly).subs(x, e))        # the field layer agrees, exactly
    assert parse_entry(format_entry(e)) == e


@pytest.mark.parametrize("text, fragment", [
    ("cos(1)", "rational multiple of pi"),
    ("cos(theta)", "rational multiple of pi"),
    ("pi", "not algebraic"),
    ("2*pi/3", "not algebraic"),
    ("sin(pi/1000)", "too large"),
    ("root(x**2 + 1, 1)", "0 real root"),
    ("root(x**2 - 2, 3)", "not in 1 … 2"),
    ("root(x**2 - 2, 0)", "not in 1 … 2"),
    ("root(y**2 - 2, 1)", "not a polynomial in x"),
    ("root(x**(1/2) - 2, 1)", "takes a root"),
    ("root(x**2 - 2, -2, 2)", "holds 2 real roots"),
    ("root(x**2 - 2, 1/2)", "index 1/2"),
    ("root(x**41 - 2, 1)", "degree 1 to 40"),
    ("exp(1)", "unknown function 'exp'"),
])
def test_algebraic_refused(text, fragment):
    with pytest.raises(EntryError) as info:
        parse_entry(text)
    assert fragment in str(info.value)


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


# ------------------------------------------------------------- one parser, two dialects

@pytest.fixture
def problem_dialect():
    from tableau_lab.numeric import expressions
    return expressions


def test_one_tokenizer_and_parser_for_tableaux_and_problems(monkeypatch, problem_dialect):
    """numeric.expressions defines no tokenizer or parser of its own: its problem dialect is a
    grammar.Dialect, read by the tokenizer and parser that read tableau entries."""
    import inspect
    import re

    from tableau_lab.exact import grammar
    expressions = problem_dialect
    own = {n for n, o in vars(expressions).items()
           if (inspect.isclass(o) or inspect.isfunction(o)) and o.__module__ == expressions.__name__}
    assert own == {"ExpressionError", "parse_expression", "exact_number"}
    assert not [n for n, o in vars(expressions).items() if isinstance(o, re.Pattern) and o is not grammar.NAME]
    assert isinstance(expressions.PROBLEM, grammar.Dialect) and expressions.NAME is grammar.NAME
    assert issubclass(expressions.ExpressionError, EntryError)
    seen = []
    tokens = grammar._tokens
    monkeypatch.setattr(grammar, "_tokens", lambda text, dialect: seen.append(dialect) or tokens(text, dialect))
    grammar._parse_text.cache_clear()
    assert parse_entry("1/3 + theta") == sp.Rational(1, 3) + parameter("theta")
    q = sp.Symbol("q", real=True)
    assert expressions.parse_expression("q/3 + 0.5", {"q": q}) == q / 3 + sp.Rational(1, 2)
    assert {d.name for d in seen} == {"tableau entries", "problem expressions"}
    assert grammar.TABLEAU in seen and expressions.PROBLEM in seen


@pytest.mark.parametrize("text, value", [
    ("-2**2", -4), ("2**3**2", 512), ("-x^2", -parameter("x") ** 2), ("-x*y", -parameter("x") * parameter("y")),
    ("2^-1", sp.Rational(1, 2)), ("1/2/3", sp.Rational(1, 6)), ("2-3-4", -5),
    ("-(1+x)^2/3", -(1 + parameter("x")) ** 2 / 3),
    ("sqrt(8)/2", sp.sqrt(2)), ("(x*y)^3", (parameter("x") * parameter("y")) ** 3),
])
def test_both_dialects_read_the_same_grammar(text, value, problem_dialect):
    names = {"x": parameter("x"), "y": parameter("y")}
    assert parse_entry(text) == value
    assert problem_dialect.parse_expression(text, names) == value


def test_the_dialects_differ_in_decimals_functions_and_names(problem_dialect):
    q = sp.Symbol("q", real=True)
    parse_expression, ExpressionError = problem_dialect.parse_expression, problem_dialect.ExpressionError
    assert parse_expression("cos(q)", {"q": q}) == sp.cos(q)
    assert parse_expression("cos(1)") == sp.cos(1)
    assert parse_expression("2.95912208286e-4") == sp.Rational(295912208286, 10 ** 15)
    assert parse_expression("0.005") == sp.Rational(1, 200)
    assert parse_expression("(q^2 + 1)^(3/2)", {"q": q}) == (q ** 2 + 1) ** sp.Rational(3, 2)
    for text, fragment in [("0.5", 'write it as a fraction, e.g. "1/2"'), ("cos(1)", "rational multiple of pi"),
                           ("2.95912208286e-4", "decimal"), ("exp(theta)", "unknown function 'exp'"),
                           ("sqrt(theta)", "takes a root")]:
        with pytest.raises(EntryError) as info:
            parse_entry(text)
        assert fragment in str(info.value)
    for text, fragment in [("theta", "unknown name 'theta'"), ("pi", "unknown name 'pi'"),
                           ("root(x - 1, 1)", "unknown function 'root'"), ("q^q", "not a rational constant")]:
        with pytest.raises(ExpressionError) as info:
            parse_expression(text, {"q": q})
        assert fragment in str(info.value)
