"""Reconstruction of exact tableaux from decimals (issue 33, item 3): exact/recognise.py and
analysis/reconstruct.py against independent facts — the published exact tableaux of the library,
turned into decimal balls here with mpmath (not by the code under test), must come back as
exactly those numbers, and their published orders must be re-proven; balls with too few digits
and random numbers must give no strong claim."""
import json
import random
import re
import time

import flint
import pytest
import sympy as sp
from conftest import benchmark_script
from printed import latex_to_grammar

import tableau_lab as tl
from tableau_lab.errors import BudgetError, InputError
from tableau_lab.exact.grammar import format_entry, parse_entry
from tableau_lab.exact.recognise import ball_of, limits_with, recognise, recognise_in
from tableau_lab.exact.render import entry_latex

demo = benchmark_script("reconstruct_demo")      # the balls: mpmath's rounding of the shipped exact entries
decimal_ball, decimal_tableau = demo.decimal_ball, demo.decimal_tableau


def assert_exact(result, exact):
    assert demo.equals_exactly(result, exact)
    for e in result.entries:                                  # the grammar's normal form: re-parses to itself
        assert parse_entry(str(format_entry(e.value))) == e.value


def test_dormand_prince_from_20_digits_is_its_rationals_and_order_5():
    data, exact = decimal_tableau("dormand_prince54", 20)
    start = time.process_time()
    r = tl.reconstruct(data)
    assert r.complete and not r.weak and not r.missing
    assert_exact(r, exact)
    assert {e.recognition.kind for e in r.recognised} <= {"rational", "integer"}
    assert r.verified.order.order == 5 and r.embedded_order == 4 and r.verified.failed == ()
    # DP's largest height is 339200 (b̂₄ = −92097/339200): 2·log10(339200) = 11.06 digits needed
    worst = max(r.recognised, key=lambda e: e.recognition.needed).recognition
    assert worst.height == 339200 and round(worst.needed, 2) == 11.06
    assert time.process_time() - start < 20


def test_rk4_from_20_digits():
    data, exact = decimal_tableau("rk4", 20)
    r = tl.reconstruct(data)
    assert r.complete
    assert_exact(r, exact)
    assert r.verified.order.order == 4 and "order 4" in r.proven()


def test_gauss2_from_30_digits_in_one_quadratic_field():
    data, exact = decimal_tableau("gauss2", 30)
    r = tl.reconstruct(data)
    assert r.complete and r.fields == (sp.sqrt(3),)
    assert_exact(r, exact)
    v = r.verified
    assert v.order.order == 4 and v.rk_symplectic.holds and v.failed == ()
    kinds = {e.name: e.recognition.kind for e in r.recognised}
    assert kinds == {"A row 1, column 1": "rational", "A row 1, column 2": "quadratic",
                     "A row 2, column 1": "quadratic", "A row 2, column 2": "rational",
                     "b[1]": "rational", "b[2]": "rational", "c[1]": "quadratic", "c[2]": "quadratic"}


def test_sdirk34_from_30_digits_in_its_cubic_field():
    data, exact = decimal_tableau("sdirk34", 30)
    r = tl.reconstruct(data)
    assert r.complete, [e.line() for e in r.entries]
    assert len(r.fields) == 1 and all(e.recognition.field == r.fields for e in r.recognised
                                      if not e.recognition.value.is_Rational)
    assert_exact(r, exact)
    assert r.verified.order.order == 4 and r.verified.failed == ()


def test_gauss4_from_40_digits_in_the_field_of_its_nodes():
    """Gauss 4's entries lie in a field of degree 8 (two quartic nodes): no entry alone, all of them in
    the joint basis of the fields the nodes show.  Order 2s = 8 with s = 4 stages, proven exactly,
    makes the candidate Gauss 4 (the one s-stage method of order 2s: Butcher 1964, [HW96] Sec. IV.5),
    without comparing entries (the minimal polynomials of degree-8 differences take seconds)."""
    data, _ = decimal_tableau("gauss:4", 40)
    r = tl.reconstruct(data)
    assert r.complete
    assert r.verified.order.order == 8 and r.verified.rk_symplectic.holds
    assert sorted({e.recognition.kind for e in r.recognised}) == ["degree 4", "degree 8", "quadratic"]


def test_the_shared_field_needs_fewer_digits_than_the_entry_alone():
    """b₁ of SDIRK34, 1/(6(2γ − 1)²): in Q(γ) a relation of 4 small numbers, alone a cubic of larger height."""
    g = parse_entry("1/2 + cos(pi/18)/sqrt(3)")
    b1 = 1 / (6 * (2 * g - 1) ** 2)
    x = decimal_ball(b1, 30)
    alone, joint = recognise(x), recognise_in(x, parse_entry("root(24*x**3 - 36*x**2 + 12*x - 1, 3)"))
    assert joint.strong and joint.needed < alone.needed
    assert sp.minimal_polynomial(joint.value - b1, sp.Symbol("x")) == sp.Symbol("x")


@pytest.mark.parametrize("value, digits", [("1/3", 3), ("sqrt(3)/6 + 1/2", 4), ("19372/6561", 8)])
def test_too_few_digits_make_no_strong_claim(value, digits):
    r = recognise(decimal_ball(parse_entry(value), digits))
    assert not r.strong
    assert r.value is None or r.weak


def test_a_tableau_with_too_few_digits_is_not_complete():
    data, _ = decimal_tableau("gauss2", 5)
    r = tl.reconstruct(data)
    assert not r.complete and (r.weak or r.missing)
    assert "weak" in r.proven().lower() or "not recognised" in r.proven()


def test_a_misprint_in_the_10th_digit_is_not_recognised_as_a_rational():
    data, _ = decimal_tableau("dormand_prince54", 20)
    data["A"][2][1] = decimal_ball(sp.Rational(9, 40) * (1 + sp.Rational(1, 10 ** 9)), 20)   # a₃₂ = 9/40
    r = tl.reconstruct(data)
    bad = [e for e in r.entries if e.name == "A row 3, column 2"][0]
    assert not bad.recognition.strong and not r.complete


def test_random_20_digit_numbers_have_no_small_height():
    rng = random.Random(33)
    for _ in range(12):
        digits = "".join(rng.choice("0123456789") for _ in range(20))
        with flint.ctx.workprec(160):
            x = flint.arb(f"[0.{digits} +/- 5e-21]")
        r = recognise(x)
        assert not r.strong, (digits, r.verdict())


def test_candidate_lies_inside_the_ball_and_reparses():
    x = decimal_ball(sp.sqrt(2) + sp.sqrt(3), 40)          # degree 4: x⁴ − 10x² + 1
    r = recognise(x)
    assert r.strong and r.kind == "degree 4" and r.height == 10
    b = ball_of(x)
    assert b.lo < sp.Rational(str(sp.N(sp.sqrt(2) + sp.sqrt(3), 60))) < b.hi
    assert parse_entry(r.text) == r.value
    assert sp.minimal_polynomial(r.value - sp.sqrt(2) - sp.sqrt(3), sp.Symbol("x")) == sp.Symbol("x")


def test_limits_are_named_checked_and_bind():
    with pytest.raises(ValueError, match="unknown reconstruction limit"):
        limits_with(depth=3)
    with pytest.raises(ValueError, match="degree"):
        limits_with(degree=0)
    with pytest.raises(ValueError, match="from 1 to 5000"):
        limits_with(digits=10 ** 6)
    # a ball tighter than the digits limit is used to that many digits: still recognised, never slower
    tight = decimal_ball(sp.sqrt(3) / 6 + sp.Rational(1, 2), 3000)
    r = recognise(tight, limits_with(digits=50))
    assert r.strong and r.value == parse_entry("sqrt(3)/6 + 1/2") and 49.9 < r.digits <= 50
    x = decimal_ball(sp.sqrt(2) + sp.sqrt(3), 40)
    assert recognise(x, limits_with(degree=2)).value is None or not recognise(x, limits_with(degree=2)).strong
    data, _ = decimal_tableau("dormand_prince54", 20)
    with pytest.raises(BudgetError, match="reconstruction"):
        tl.reconstruct(data, seconds=0.01)
    with pytest.raises(InputError, match="size budget"):
        tl.reconstruct({"kind": "rk", "A": [[0] * 41] * 41, "b": [0] * 41})


def test_the_limits_table_of_the_docs_and_the_command_options_are_the_limits():
    """docs/reconstruction.md's table of limits states each default and ceiling of recognise.Limits /
    CEILINGS, and `tableau-lab reconstruct --degree/--digits` refuse beyond the same ceilings."""
    from pathlib import Path

    from tableau_lab.cli import main
    from tableau_lab.exact.recognise import CEILINGS, LIMITS
    text = (Path(__file__).resolve().parents[1] / "docs/reconstruction.md").read_text(encoding="utf-8")
    rows = {m[1]: (m[2], m[3]) for m in re.finditer(r"^\| `(\w+)` \|([^|]*)\|([^|]*)\|", text, re.M)}
    assert set(rows) == set(vars(LIMITS))
    sup = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹", "0123456789")
    for name, (default, most) in rows.items():
        d = default.strip()
        value = 10 ** int(d[2:].translate(sup)) if d.startswith("10") and len(d) > 2 else float(d)   # 10³⁰
        assert value == getattr(LIMITS, name), name
        assert (int(most) if most.strip() else None) == CEILINGS.get(name), name
    for name in ("degree", "digits"):
        with pytest.raises(SystemExit) as info:
            main(["reconstruct", "x.json", f"--{name}", str(CEILINGS[name] + 1)])
        assert info.value.code == 2


@pytest.mark.parametrize("name, digits", [("sdirk34", 30), ("gauss2", 30)])
def test_printed_entries_reparse_to_the_candidate(name, digits):
    """A printed formula is a claim: each entry's text, LaTeX (root(P, k) counted from 1, as the
    grammar counts, not sympy's CRootOf from 0) and JSON re-parse to the candidate's exact value."""
    data, _ = decimal_tableau(name, digits)
    r = tl.reconstruct(data)
    latex, out = r.to_latex(), json.loads(r.dumps())
    for e, j in zip(r.entries, out["entries"], strict=True):
        tex = entry_latex(e.value)
        assert tex in latex
        assert parse_entry(latex_to_grammar(tex)) == e.value and parse_entry(j["value"]) == e.value
    assert "CRootOf" not in latex and ("root" in latex) == (name == "sdirk34")


def test_report_renders_and_serialises():
    data, _ = decimal_tableau("gauss2", 30)
    r = tl.reconstruct(data)
    text = str(r)
    assert "Reconstruction of" in text and "sqrt(3)" in text and "order 4" in text
    out = json.loads(r.dumps())
    assert out["complete"] is True and out["fields"] == ["sqrt(3)"]
    assert all(e["weak"] is False for e in out["entries"] if "weak" in e)


def test_claims_of_the_decimal_format_are_checked_or_named():
    """The format's claims are carried to the exact candidate and checked there (embedded_order
    against the exact embedded method, once); the keys describing the decimals are consumed, not
    reported."""
    data, _ = decimal_tableau("dormand_prince54", 20)
    data.update({"numbers": "decimal", "digits": 20,
                 "claims": {"order": 5, "embedded_order": 5, "ssp_coefficient": "0"}})
    r = tl.reconstruct(data)
    assert "order = 5 (holds)" in r.proven() and r.proven().count("embedded_order = 5 (FAILS)") == 1
    assert "ssp_coefficient = 0 (holds)" in r.proven() and r.dropped == ()     # DP5 has an SSP coefficient 0
    assert "numbers" not in r.tableau and "digits" not in r.tableau
    assert r.tableau["claims"] == {"order": 5, "embedded_order": 5, "ssp_coefficient": "0"}


@pytest.mark.parametrize("entry", [0.5, "0.5", None, [1], flint.arb("nan"), flint.arb(0, "inf")])
def test_bad_entries_are_refused_naming_the_entry(entry):
    with pytest.raises(InputError, match="A row 2, column 1") as info:
        tl.reconstruct({"kind": "rk", "A": [[0, 0], [entry, 0]], "b": ["1/2", "1/2"]})
    if entry in (0.5, "0.5"):
        assert "flint.arb" in str(info.value)


def _decimal_file(path, name: str, digits: int, change=None):
    """A shipped tableau as a decimal file (``"numbers": "decimal"``): every non-integer entry its
    decimal to ``digits`` significant digits (the demo's decimal_text); ``change``: (key, i, j) of an entry whose
    10th digit is altered."""
    data, _ = demo.decimal_copy(name, digits, demo.decimal_text)
    if change is not None:
        key, i, j = change
        text = data[key][i][j]
        places = [n for n, ch in enumerate(text) if ch.isdigit()]
        first = next(m for m, n in enumerate(places) if text[n] != "0")
        k = places[first + 9]                                      # the 10th significant digit
        data[key][i][j] = text[:k] + str((int(text[k]) + 1) % 10) + text[k + 1:]
    data["numbers"] = "decimal"
    path.write_text(json.dumps(data))
    return path


def test_the_command_reconstructs_saves_and_refuses(tmp_path, capsys):
    """`tableau-lab reconstruct FILE --save OUT`: Dormand–Prince from 20 digits back as the shipped
    rationals (the saved file is the shipped method, exactly), its order claim re-proven (exit 0);
    a 10th-digit change: no candidate whose claims hold (exit 1); an exact input, --save over the
    input: exit 2, nothing written."""
    from tableau_lab.cli import main
    src = _decimal_file(tmp_path / "dp5.json", "dormand_prince54", 20)
    out = tmp_path / "dp5_exact.json"
    assert main(["reconstruct", str(src), "--save", str(out)]) == 0
    assert "order = 5 (holds)" in capsys.readouterr().out
    saved, shipped = tl.load(str(out)), tl.load("dormand_prince54")
    assert (saved.A, saved.b, saved.bhat) == (shipped.A, shipped.b, shipped.bhat)
    bad = _decimal_file(tmp_path / "dp5_bad.json", "dormand_prince54", 20, change=("A", 2, 1))
    assert main(["reconstruct", str(bad)]) == 1
    capsys.readouterr()
    assert main(["reconstruct", str(src), "--save", str(src)]) == 2
    assert "overwrite the input" in capsys.readouterr().err
    exact = tmp_path / "rk4.json"
    exact.write_text(json.dumps({"name": "Euler", "kind": "rk", "A": [[0]], "b": [1]}))
    assert main(["reconstruct", str(exact)]) == 2
    assert "exact already" in capsys.readouterr().err
