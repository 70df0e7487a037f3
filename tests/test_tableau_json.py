"""Malformed and hostile tableau files: each is refused with a message naming the file
and the entry, exit code 2, quickly, and with nothing executed."""
import builtins
import json
import subprocess
import sys
import types
from pathlib import Path

import pytest
import sympy as sp

import tableau_lab.analysis.verify  # noqa: F401  (imported before eval/exec are patched)
from tableau_lab.cli import main
from tableau_lab.exact.grammar import parse_entry
from tableau_lab.exact.tableau_json import TableauError, dumps, load, loads

BAD = Path(__file__).parent / "data" / "bad"

# file -> (the entry the message must name, or None for file-level errors; a fragment of the message)
EXPECTED = {
    "truncated.json": (None, "not valid JSON"),
    "not_object.json": (None, "one JSON object"),
    "empty.json": (None, "not valid JSON"),
    "ragged_rows.json": ("A row 2", "ragged"),
    "b_wrong_length.json": (None, "b has shape 3x1, expected 2x1"),
    "A_not_square.json": (None, "A must be square"),
    "unknown_kind.json": ("kind", "unknown or missing kind 'rkk'"),
    "kind_not_string.json": ("kind", "unknown or missing kind"),
    "missing_b.json": ("b", "needs 'b'"),
    "float_entry.json": ("A row 2, column 1", 'write it as a string such as "1/2"'),
    "float_exponent_form.json": ("b[2]", "floating-point"),
    "decimal_string.json": ("b[1]", 'e.g. "1/4"'),
    "unparseable.json": ("b[1]", "expected a number"),
    "unbalanced_parens.json": ("b[1]", "expected ')'"),
    "injection_import.json": ("b[1]", "names must start with a letter"),
    "injection_lambda.json": ("b[1]", "unexpected character ':'"),
    "injection_attribute.json": ("b[1]", "unexpected character '.'"),
    "injection_eval.json": ("b[1]", "unexpected character"),
    "injection_semicolon.json": ("b[1]", "unexpected character ';'"),
    "huge_exponent_tower.json": ("b[1]", "too large"),
    "huge_power.json": ("b[1]", "too large"),
    "long_integer_string.json": ("b[1]", "too long"),
    "long_integer_number.json": ("b[1]", "5000 digits is too long"),
    "nan.json": ("b[1]", "NaN is not a number"),
    "infinity.json": ("b[1]", "Infinity is not a number"),
    "boolean_entry.json": ("b[1]", "boolean"),
    "null_entry.json": ("b[1]", "null"),
    "nested_vector.json": ("b[1]", "flat list"),
    "c_inconsistent.json": (None, "c is not consistent with A"),
    "division_by_zero.json": ("b[1]", "division by zero"),
    "complex_entry.json": ("b[1]", "not a real number"),
    "unknown_function.json": ("b[1]", "unknown function 'exp'"),
    "trig_not_algebraic.json": ("b[1]", "rational multiple of pi"),
    "root_not_real.json": ("b[1]", "0 real root"),
    "radical_of_parameter.json": ("b[1]", "root of an expression in parameters"),
    "unknown_key.json": ("Claims", "unknown key 'Claims'"),
    "unknown_claim.json": ("claims.symplectik", "unknown claim"),
    "claim_wrong_type.json": ("claims.symplectic", "must be a bool"),
    "duplicate_key.json": (None, "duplicate key 'A'"),
    "missing_name.json": ("name", "non-empty string"),
    "glm_U_wrong_shape.json": (None, "U has shape 1x3, expected 1x2"),
    "prk_stage_mismatch.json": (None, "same number of stages"),
    "deep_parentheses.json": ("b[1]", "nested too deeply"),
    "underscore_name.json": ("b[1]", "names must start with a letter"),
    "not_utf8.json": (None, "not UTF-8"),
}


def test_every_bad_file_is_listed():
    assert sorted(p.name for p in BAD.glob("*.json")) == sorted(EXPECTED)
    assert len(EXPECTED) >= 20


@pytest.fixture
def no_eval(monkeypatch):
    """Any call of eval/exec on text (which sympify/parse_expr would make: their code objects come
    from "<string>") fails the test; the interpreter importing a module file (sympy loads some
    lazily) is not evaluation of data and goes through."""
    real = {"eval": builtins.eval, "exec": builtins.exec}

    def guard(kind):
        def refuse(*args, **kwargs):
            code = args[0] if args else None
            if isinstance(code, types.CodeType) and code.co_filename.endswith(".py"):
                return real[kind](*args, **kwargs)
            raise AssertionError(f"eval/exec called with {args[:1]!r}")
        return refuse
    monkeypatch.setattr(builtins, "eval", guard("eval"))
    monkeypatch.setattr(builtins, "exec", guard("exec"))


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_bad_file_refused(name, no_eval, capsys):
    entry, fragment = EXPECTED[name]
    path = str(BAD / name)
    with pytest.raises(TableauError) as info:
        load(path)
    msg = str(info.value)
    assert msg.startswith(path + ": ")
    assert fragment in msg
    if entry is not None:
        assert info.value.entry == entry and f"entry {entry}:" in msg
    assert main(["verify", path]) == 2
    out, err = capsys.readouterr()
    assert out == "" and path in err


def test_cli_rejects_all_bad_files_fast_and_executes_nothing(tmp_path):
    marker = Path("/tmp/tableau_lab_pwned")
    if marker.exists():
        marker.unlink()
    files = sorted(str(p) for p in BAD.glob("*.json"))
    # A hang guard, not a speed assertion: each file must be rejected, all of them together
    # well within the timeout (the closing note reports the measured per-file time).
    proc = subprocess.run([sys.executable, "-m", "tableau_lab", "verify", *files],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert len([line for line in proc.stderr.splitlines() if line.startswith("tableau-lab: error:")]) == len(files)
    assert not marker.exists()


def test_huge_and_deep_files(tmp_path):
    big = tmp_path / "big.json"
    big.write_text('{"name": "x", "kind": "rk", "A": [[0]], "b": [1], "notes": "' + "a" * (1 << 20) + '"}')
    with pytest.raises(TableauError, match="larger than"):
        load(big)
    deep = tmp_path / "deep.json"
    deep.write_text('{"name": "x", "kind": "rk", "A": ' + "[" * 100000 + "]" * 100000 + ', "b": [1]}')
    with pytest.raises(TableauError) as info:
        load(deep)
    assert str(deep) in str(info.value)
    with pytest.raises(TableauError, match="cannot read"):
        load(tmp_path / "missing.json")


def test_good_and_bad_together_exit_2_and_still_report_good(tmp_path, capsys):
    good = tmp_path / "mid.json"
    good.write_text('{"name": "implicit midpoint", "kind": "rk", "A": [["1/2"]], "b": [1]}')
    assert main(["verify", str(good), str(BAD / "nan.json")]) == 2
    out, err = capsys.readouterr()
    assert "implicit midpoint" in out and "nan.json" in err


def test_claim_failure_exit_1(tmp_path, capsys):
    f = tmp_path / "euler.json"
    f.write_text(json.dumps({"name": "explicit Euler", "kind": "rk", "A": [[0]], "b": [1],
                             "claims": {"symplectic": True}}))
    assert main(["verify", "--json", str(f)]) == 1
    out = json.loads(capsys.readouterr().out)
    assert out["claims"]["failed"] == ["symplectic"]


ROUND_TRIP = [
    '{"name": "p", "kind": "rk", "A": [["theta", 0], ["1 - theta", "theta^2"]], "b": ["1/2", "1/2"]}',
    '{"name": "r", "kind": "rk", "A": [["1/(2-2**(1/3))"]], "b": [1]}',
    '{"name": "n", "kind": "rk", "A": [["sqrt(2+sqrt(3))/7", 0], [1, "-43*sqrt(14595)/35490"]], "b": [0, 1]}',
    '{"name": "s", "kind": "prk", "A": [[0]], "b": [1], "Ahat": [[1]], "bhat": [1], "source": "HLW", '
    '"notes": ["a", "b"], "claims": {"symplectic": true}}',
]


@pytest.mark.parametrize("text", ROUND_TRIP)
def test_round_trip_identical(text):
    m = loads(text)
    again = loads(dumps(m))
    assert again == m
    for k, M in m.matrices().items():
        assert again.matrices()[k] == M


def test_x_keys_are_allowed_and_dropped():
    m = loads('{"name": "e", "kind": "rk", "A": [[0]], "b": [1], "x-comment": {"any": [1.5]}}')
    assert m.b[0] == 1


def test_derived_c_for_glm_and_given_c_checked():
    text = ('{"name": "ab2", "kind": "glm", "A": [[0]], "U": [[1, 0]], "B": [["3/2"], [1]], '
            '"V": [[1, "-1/2"], [0, 0]]%s}')
    # derived with the convention w^T v = 0, w = (1, -1/2) the left eigenvector of V:
    # v = (1/2, 1), c = A 1 + U v = 1/2 (the principal value y1 - h f/2 then approximates y(x)).
    assert loads(text % "").c[0] == sp.Rational(1, 2)
    # c = 0 (first value exact) is another starting method: any uniform shift is consistent
    assert loads(text % ', "c": [0]').c[0] == 0
    assert loads(text % ', "c": [1]').c[0] == 1


def test_named_constants():
    """A constant named once and used in entries; refused names and values."""
    from tableau_lab.exact.tableau_json import loads
    g = "1/2 + cos(pi/18)/sqrt(3)"
    text = ('{"name": "sdirk", "kind": "rk", "constants": {"gamma": "%s"}, '
            '"A": [["gamma", 0], ["1 - 2*gamma", "gamma"]], "b": ["1/2", "1/2"]}' % g)
    m = loads(text)
    assert m.A[0, 0] == parse_entry(g) and not m.parameters
    for consts, fragment in [('{"pi": "1"}', "not a constant name"), ('{"g": "theta"}', "must be a number"),
                             ('["g"]', "must be an object"), ('{"g": 0.5}', "floating-point")]:
        bad = '{"name": "x", "kind": "rk", "constants": %s, "A": [["g"]], "b": [1]}' % consts
        with pytest.raises(TableauError) as info:
            loads(bad)
        assert fragment in str(info.value) and "constants" in str(info.value)
