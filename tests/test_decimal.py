"""Decimal tableaux (``"numbers": "decimal"``) and their certified analysis in ball arithmetic
(tableau_lab/exact/balls.py, analysis/certified.py, analysis/certified_ssp.py; issue 33 items 1–2).

The decimal copies are made here from the exact rationals of tableau_lab/methods/*.json with
mpmath at 20 significant digits (trailing zeros written: "0.5" alone would be the ball 0.5 ± 0.05);
the facts checked are independent of the code: the published orders (RK4: 4; Dormand–Prince 5(4):
5 with embedded 4; SSPRK(3,3): R = 1, Shu & Osher 1988), and the size of a miss computed by hand
from the change (Σb − 1 = δ; the order-2 residual Σbᵢcᵢ − 1/2 moves by b₃δ when a₃₂ moves by δ)."""
import json

import flint
import mpmath
import pytest
import sympy as sp

import tableau_lab as tl
from tableau_lab.cli import main
from tableau_lab.exact.balls import BallMethod
from tableau_lab.exact.grammar import parse_entry
from tableau_lab.exact.tableau_json import TableauError, read

METHODS = "tableau_lab/methods"


def _decimal(x, digits: int) -> str | int:
    """An exact entry of a shipped file at ``digits`` significant digits (integers stay exact;
    radicals through sympy's evaluation at 20 more digits)."""
    v = parse_entry(x) if isinstance(x, str) else sp.Integer(x)
    if v.is_Integer:
        return int(v)
    with mpmath.workdps(digits + 20):
        x = mpmath.mpf(int(v.p)) / int(v.q) if v.is_Rational else mpmath.mpf(str(sp.N(v, digits + 20)))
        return mpmath.nstr(x, digits, strip_zeros=False, min_fixed=-5, max_fixed=5)


def decimal_copy(name: str, digits: int = 20, **claims) -> dict:
    d = read(f"{METHODS}/{name}.json")
    out = {"name": f"{d['name']} ({digits} digits)", "kind": "rk", "numbers": "decimal"}
    for k in ("A", "b", "c", "bhat"):
        if k in d:
            out[k] = ([[_decimal(x, digits) for x in row] for row in d[k]] if k == "A"
                      else [_decimal(x, digits) for x in d[k]])
    out["claims"] = claims
    return out


def tenth_digit_changed(text: str) -> str:
    """The decimal with its 10th significant digit raised by one (mod 10)."""
    seen = 0
    for i, ch in enumerate(text):
        if ch.isdigit() and (seen or ch != "0"):
            seen += 1
            if seen == 10:
                return text[:i] + str((int(ch) + 1) % 10) + text[i + 1:]
    raise AssertionError(text)


def verify(d: dict, **budget):
    m = tl.load(json.dumps(d))
    assert isinstance(m, BallMethod)
    return tl.verify(m, **budget)


def test_rk4_at_20_digits_has_order_4_certified():
    r = verify(decimal_copy("rk4", order=4))
    order = r.finding("order")
    assert (order.value, order.status) == (4, "certified")
    assert order.largest < 1e-18                      # 20-digit rounding: the vanishing residuals are ~1e-20
    assert order.evidence and all(e.excludes_zero and e.kind.order(e.tree) == 5 for e in order.evidence)
    assert r.claims[0].status == "holds to the stated precision" and r.failed == ()
    assert "exactly" not in str(r) and "to the stated precision" in str(r)


def test_dormand_prince_at_20_digits_is_5_4():
    r = verify(decimal_copy("dormand_prince54", order=5, embedded_order=4))
    assert (r.finding("order").value, r.finding("order").status) == (5, "certified")
    assert (r.finding("embedded order").value, r.finding("embedded order").status) == (4, "certified")
    assert r.finding("c = A1").status == "certified"
    assert r.failed == () and r.undecided == ()


def test_a_weight_changed_in_its_10th_digit_refutes_the_order():
    d = decimal_copy("rk4", order=4)
    d["b"][0] = tenth_digit_changed(d["b"][0])        # 0.16666666666666666667 → 0.16666666676666666667
    r = verify(d)
    assert r.failed == ("order",)
    order = r.finding("order")
    assert order.value == 0 and order.status == "certified"
    miss = order.evidence[0]
    assert order.evidence[0].tree == () and "tree τ" in miss.condition          # Σbᵢ = 1, the tree τ
    assert abs(float(miss.ball.mid()) - 1e-10) < 1e-18 and miss.ball.rad() < 1e-18     # Σbᵢ − 1 = δ = 1e-10
    assert "REFUTED" in str(r) and "tree τ" in str(r)


def test_dormand_prince_a32_changed_in_its_10th_digit_refutes_the_order():
    d = decimal_copy("dormand_prince54", order=5)
    d["A"][2][1] = tenth_digit_changed(d["A"][2][1])   # a₃₂ = 9/40 = 0.225 → 0.2250000001: δ = 1e-10
    r = verify(d)
    assert r.failed == ("order",) and r.finding("order").value == 1
    miss = r.finding("order").evidence[0]
    assert "tree [τ]" in miss.condition
    expected = float(sp.Rational(500, 1113) * sp.Rational(1, 10 ** 10))     # b₃·δ
    assert abs(float(miss.ball.mid()) - expected) < 1e-18 and miss.ball.rad() < 1e-18
    assert r.finding("c = A1").status == "refuted"      # c₃ = 3/10 no longer the row sum


def test_lobatto_iiia_iiib_pair_at_20_digits_is_symplectic_of_order_4():
    """[HLW06] Thm VI.4.6 and Table II.2.1: the 3-stage Lobatto IIIA–IIIB pair is symplectic, of
    order 2s − 2 = 4 (bicoloured trees)."""
    a, b = read(f"{METHODS}/lobatto_iiia3.json"), read(f"{METHODS}/lobatto_iiib3.json")
    d = {"name": "Lobatto IIIA-IIIB 3", "kind": "prk", "numbers": "decimal",
         "A": [[_decimal(x, 20) for x in r] for r in a["A"]], "b": [_decimal(x, 20) for x in a["b"]],
         "Ahat": [[_decimal(x, 20) for x in r] for r in b["A"]], "bhat": [_decimal(x, 20) for x in b["b"]],
         "claims": {"order": 4, "symplectic": True}}
    r = verify(d)
    assert (r.finding("order").value, r.finding("order").status) == (4, "certified")
    assert r.finding("symplectic").value is True and r.failed == () and r.undecided == ()
    d["bhat"][1] = tenth_digit_changed(d["bhat"][1])          # b ≠ b̂: no longer symplectic, order 0 in p
    r = verify(d)
    assert r.failed == ("order", "symplectic")
    assert r.finding("symplectic").evidence[0].excludes_zero


def test_exact_entries_stay_exact():
    d = decimal_copy("rk4")
    d["A"][1][0] = "1/2"
    m = tl.load(json.dumps(d))
    assert m.entry("A", 2, 1).exact == sp.Rational(1, 2) and m.entry("A", 2, 1).radius == 0
    assert m.entry("A", 4, 3).exact == 1 and m.entry("A", 1, 1).exact == 0
    assert m.entry("b", 1).exact is None and m.entry("b", 1).radius == sp.Rational(1, 2 * 10 ** 20)
    assert m.explicit() and m.order_bound == 4
    assert m.balls("A")[1][0].is_exact() and m.balls("A")[1][0] == flint.arb(flint.fmpq(1, 2))


@pytest.mark.parametrize("key, value, radius", [("digits", 30, sp.Rational(1, 2 * 10 ** 30)),
                                                ("radius", "1e-25", sp.Rational(1, 10 ** 25))])
def test_the_file_states_the_rounding(key, value, radius):
    d = {"name": "x", "kind": "rk", "numbers": "decimal", "A": [["0.5"]], "b": [1], key: value}
    m = tl.load(json.dumps(d))
    assert m.entry("A", 1, 1).radius == radius
    assert m.prec >= 30 * 3.32


def test_ssp_coefficient_of_ssprk33_encloses_1():
    d = {"name": "SSPRK(3,3)", "kind": "rk", "numbers": "decimal",
         "A": [[0, 0, 0], [1, 0, 0], ["0.25000000000000000000", "0.25000000000000000000", 0]],
         "b": [_decimal("1/6", 20), _decimal("1/6", 20), _decimal("2/3", 20)],
         "claims": {"ssp_coefficient": "1.0000000000"}}
    r = verify(d)
    lo, hi = r.finding("SSP coefficient").value
    assert lo <= 1 <= hi and float(hi - lo) < 1e-8
    assert r.failed == ()
    d["claims"]["ssp_coefficient"] = "1.1"
    assert verify(d).failed == ("ssp_coefficient",)


def test_undecided_when_the_digits_do_not_decide_and_the_budget():
    d = decimal_copy("rk4", digits=1, order=4)      # ± 0.05, and the zeros too: no condition excludes 0
    d["A"] = [["0.0" if x == 0 else x for x in row] for row in d["A"]]
    r = verify(d)
    f = r.finding("order")
    assert f.status == "undecided" and f.value == 8 and f.digits is not None and f.digits > 1
    assert m_bound(d) == 8                           # not explicit: a decimal 0.0 is not a zero; bound 2s
    assert r.claims[0].status == "undecided" and r.failed == ()
    short = verify(decimal_copy("rk4", order=4), trees=5)
    assert short.finding("order").status == "undecided" and "tree budget" in short.finding("order").statement


def m_bound(d: dict) -> int:
    return tl.load(json.dumps(d)).order_bound


def test_renders_in_every_format():
    r = verify(decimal_copy("rk4", order=4))
    assert json.loads(r.dumps())["findings"][2]["value"] == 4
    tex, md = r.to_latex(), r._repr_markdown_()
    assert "tabular" in tex and "certified" in md and "exactly" not in tex + md


def test_cli_verify_exit_codes(tmp_path, capsys):
    good, bad = tmp_path / "rk4.json", tmp_path / "rk4_bad.json"
    good.write_text(json.dumps(decimal_copy("rk4", order=4)))
    d = decimal_copy("rk4", order=4)
    d["b"][0] = tenth_digit_changed(d["b"][0])
    bad.write_text(json.dumps(d))
    assert main(["verify", str(good)]) == 0
    assert main(["verify", str(bad)]) == 1
    out = capsys.readouterr().out
    assert "order = 4: REFUTED" in out and "tree τ" in out


@pytest.mark.parametrize("entries, where", [
    ({"A": [[0, 0], ["1.x", 0]]}, "entry A row 2, column 1"),
    ({"b": ["0.5", None]}, "entry b[2]"),
    ({"b": ["0.5", "1e99999"]}, "entry b[2]"),
    ({"b": ["0.5", "0.5", "0.5"]}, "entry b"),
    ({"digits": 0}, "entry digits"),
    ({"radius": "-1e-3"}, "entry radius"),
    ({"provenance": {"repository": "a/b", "commit": "xyz", "file": "f"}}, "entry provenance.commit"),
    ({"b": ["0." + "3" * 2500, "0.5"]}, "entry b[1]"),                 # MAX_DECIMAL_DIGITS
    ({"A": [["0.5"] * 41] * 41}, "entry A"),                            # the exact reader's MAX_SIZE
    ({"kind": "glm"}, "entry kind"),
])
def test_bad_decimal_input_names_file_and_entry(tmp_path, capsys, entries, where):
    d = {"name": "x", "kind": "rk", "numbers": "decimal", "A": [[0, 0], ["0.5", 0]], "b": ["0.5", "0.5"], **entries}
    f = tmp_path / "t.json"
    f.write_text(json.dumps(d))
    assert main(["verify", str(f)]) == 2
    assert f"{f}: {where}" in capsys.readouterr().err


def test_a_float_in_an_exact_file_is_refused_naming_the_key(tmp_path, capsys):
    f = tmp_path / "t.json"
    f.write_text('{"name": "x", "kind": "rk", "A": [[0, 0], [0.5, 0]], "b": ["1/2", "1/2"]}')
    assert main(["verify", str(f)]) == 2
    err = capsys.readouterr().err
    assert "entry A row 2, column 1: 0.5 is a floating-point number" in err and '"numbers": "decimal"' in err
    with pytest.raises(TableauError, match='"numbers": "decimal"'):
        tl.load('{"name": "x", "kind": "rk", "A": [["0.5"]], "b": [1]}')


def test_exact_commands_refuse_a_decimal_tableau(tmp_path, capsys):
    f = tmp_path / "t.json"
    f.write_text(json.dumps(decimal_copy("rk4")))
    assert main(["order", str(f)]) == 2
    assert "entry numbers" in capsys.readouterr().err


def test_provenance_and_new_claims_of_an_exact_file():
    commit = "0123456789abcdef0123456789abcdef01234567"
    d = read(f"{METHODS}/dormand_prince54.json")
    d.update(provenance={"repository": "owner/name", "commit": commit, "file": "src/dp.jl", "line": 12},
             claims={"order": 5, "embedded_order": 4})
    m = tl.load(json.dumps(d))
    assert dict(m.provenance)["line"] == 12 and tl.verify(m).failed == ()
    d["claims"] = {"embedded_order": 5}
    assert tl.verify(tl.load(json.dumps(d))).failed == ("embedded_order",)
    ssp = {"name": "SSPRK(3,3)", "kind": "rk", "A": [[0, 0, 0], [1, 0, 0], ["1/4", "1/4", 0]],
           "b": ["1/6", "1/6", "2/3"], "claims": {"ssp_coefficient": "1"}}
    assert tl.verify(tl.load(json.dumps(ssp))).failed == ()
    ssp["claims"] = {"ssp_coefficient": "3/2"}
    assert tl.verify(tl.load(json.dumps(ssp))).failed == ("ssp_coefficient",)


def test_the_ssp_bisection_keeps_its_time_budget():
    from tableau_lab.analysis.certified_ssp import certified_ssp
    d = {"name": "SSPRK(3,3)", "kind": "rk", "numbers": "decimal",
         "A": [[0, 0, 0], [1, 0, 0], ["1/4", "1/4", 0]], "b": [_decimal("1/6", 20), _decimal("1/6", 20),
                                                                 _decimal("2/3", 20)]}
    f = certified_ssp(tl.load(json.dumps(d)), seconds=0.0)
    lo, hi = f.value
    assert f.status == "undecided" and "time budget" in f.statement and lo <= 1 <= hi


def test_real_stability_interval_of_rk4_and_gauss():
    """RK4: β = −2·(the real root of x³ + 2x² + 3x + 3) = 2.7852935634… ([HW96] IV.2, Fig. 2.1),
    here from mpmath's roots; Gauss is A-stable (β = ∞): undecided beyond the walk's end."""
    r = verify(decimal_copy("rk4"))
    lo, hi = r.finding("real stability interval").value
    with mpmath.workdps(40):
        root = next(x for x in mpmath.polyroots([1, 2, 3, 3], extraprec=100) if abs(mpmath.im(x)) < 1e-30)
        beta = -2 * mpmath.re(root)
        assert mpmath.mpf(int(lo.p)) / int(lo.q) <= beta <= mpmath.mpf(int(hi.p)) / int(hi.q)
    assert hi - lo < flint.fmpq(1, 10 ** 15)
    g = verify(decimal_copy("gauss2")).finding("real stability interval")
    assert g.status == "undecided" and g.value[1] is None and "β ≥ 1024" in g.statement
