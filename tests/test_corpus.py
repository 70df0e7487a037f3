"""The library corpus (corpus/, made by tools/corpus/): every file well-formed in the shared format
(BRIEF: issue 33's file format), and spot checks against independent facts — the exact tableaux of
tableau_lab/methods/, the copies of one method in different libraries agreeing to their stated
digits, a decimal literal found verbatim in its source, and NodePy's Shu–Osher conversion redone in
exact rational arithmetic."""
from __future__ import annotations

import json
import re
import subprocess
import sys
from functools import cache
from pathlib import Path

import mpmath
import pytest
import sympy as sp

from tableau_lab.exact.grammar import LIMITS, EntryError, parse_entry, raise_limit

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))      # tools/ lives beside the package, not in it
from tools.corpus.expr import Array, Unsupported, half_ulp, parse_value  # noqa: E402 -- after the path: the checkout's tools
from tools.corpus.writer import Entries  # noqa: E402 -- after the path

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT / "corpus"
METHODS = ROOT / "tableau_lab" / "methods"
DECIMAL = re.compile(r"-?\d+(\.\d*)?([eE][+-]?\d+)?\Z")
TOP = {"format", "name", "kind", "numbers", "radius", "digits", "source", "provenance", "A", "b", "c", "bhat",
       "claims", "notes"}
CLAIMS = {"order": int, "embedded_order": int, "stage_order": int, "symplectic": bool, "ssp_coefficient": str}
SPECIAL = {"extraction.json", "nodepy_reference.json"}
DEFAULT_DIGITS = LIMITS["integer_digits"]      # the grammar's limit before any test raises it


def tableau_files() -> list[Path]:
    return sorted(p for p in CORPUS.glob("*/*.json") if p.name not in SPECIAL)


@cache
def exact_entry(text: str) -> sp.Expr:
    return parse_entry(text)


def check_entry(x, decimal: bool, where: str) -> None:
    if isinstance(x, int) and not isinstance(x, bool):
        return
    assert isinstance(x, str), f"{where}: {x!r} is neither an integer nor a string"
    if DECIMAL.match(x) and ("." in x or "e" in x.lower()):
        assert decimal, f"{where}: decimal {x!r} in an exact file"
        return
    try:
        exact_entry(x)
    except EntryError as exc:
        raise AssertionError(f"{where}: {x!r} is not an exact entry: {exc}") from None


def check_file(path: Path) -> dict:
    d = json.loads(path.read_text(encoding="utf-8"))
    assert set(d) <= TOP, f"{path}: unknown keys {set(d) - TOP}"
    assert d["format"] == "tableau_lab/1" and d["kind"] == "rk" and d["name"] and d["source"]
    decimal = d.get("numbers", "exact") == "decimal"
    assert d.get("numbers", "exact") in ("exact", "decimal")
    if "radius" in d:
        assert decimal and DECIMAL.match(d["radius"]) and sp.Rational(d["radius"]) > 0
    prov = d["provenance"]
    assert set(prov) == {"repository", "commit", "file", "line"}, path
    assert re.fullmatch(r"[0-9a-f]{40}", prov["commit"]) and prov["line"] >= 1 and "/" in prov["repository"]
    s = len(d["A"])
    assert s >= 1 and all(len(row) == s for row in d["A"]), f"{path}: A is not square"
    for key in ("b", "c", "bhat"):
        if key in d:
            assert len(d[key]) == s, f"{path}: {key} has {len(d[key])} entries for {s} stages"
    for i, row in enumerate(d["A"]):
        for j, x in enumerate(row):
            check_entry(x, decimal, f"{path.name}: A row {i + 1}, column {j + 1}")
    for key in ("b", "c", "bhat"):
        for i, x in enumerate(d.get(key, [])):
            check_entry(x, decimal, f"{path.name}: {key}[{i + 1}]")
    for k, v in d["claims"].items():
        assert isinstance(v, CLAIMS[k]), f"{path}: claim {k} = {v!r}"
    assert decimal == any(isinstance(x, str) and DECIMAL.match(x) and ("." in x or "e" in x.lower())
                          for x in sum(d["A"], []) + d["b"] + d.get("c", []) + d.get("bhat", [])), path
    return d


@pytest.fixture
def long_integers():
    """Some library rationals are long (DormandPrince8: 129-digit integers): the corpus files say
    so in INDEX.json's integer_digits, and a reader raises --entry-limit integer_digits to match."""
    old = LIMITS["integer_digits"]
    raise_limit("integer_digits", 400)
    exact_entry.cache_clear()
    yield
    raise_limit("integer_digits", old)
    exact_entry.cache_clear()


def test_every_corpus_file_is_well_formed_and_indexed(long_integers):
    files = tableau_files()
    libraries = {p.parent.name for p in files}
    assert len(files) >= 300 and len(libraries) >= 4
    for p in files:
        check_file(p)
    index = json.loads((CORPUS / "INDEX.json").read_text(encoding="utf-8"))["tableaux"]
    assert sorted(r["file"] for r in index) == sorted(f"{p.parent.name}/{p.name}" for p in files)
    long = {r["file"] for r in index if r["integer_digits"] > DEFAULT_DIGITS}
    assert "diffeqdevtools/DormandPrince8.json" in long
    for lib in libraries:
        record = json.loads((CORPUS / lib / "extraction.json").read_text(encoding="utf-8"))
        assert record["tableaux"] == sum(p.parent.name == lib for p in files)


def test_the_format_checker_refuses_bad_files(tmp_path):
    good = json.loads((CORPUS / "nodepy" / "RK44.json").read_text(encoding="utf-8"))
    for bad in ({**good, "A": good["A"][:-1]}, {**good, "b": ["0.5"] + good["b"][1:]},
                {**good, "A": [["1/0"] + r[1:] for r in good["A"]]}, {**good, "claims": {"order": "4"}}):
        p = tmp_path / "bad.json"
        p.write_text(json.dumps(bad))
        with pytest.raises(AssertionError):
            check_file(p)


def exact_rows(d: dict, key: str) -> list:
    value = d[key]
    rows = value if isinstance(value[0], list) else [value]
    return [[sp.Integer(x) if isinstance(x, int) else parse_entry(x) for x in r] for r in rows]


@pytest.mark.parametrize("copy", ["nodepy/RK44.json", "diffeqdevtools/RK4.json", "ordinarydiffeq/RK4.json",
                                  "rungekutta_jl/RK416.json"])
def test_classical_rk4_copies_equal_the_exact_tableau(copy):
    ours = json.loads((METHODS / "rk4.json").read_text(encoding="utf-8"))
    theirs = json.loads((CORPUS / copy).read_text(encoding="utf-8"))
    for key in ("A", "b", "c"):
        assert exact_rows(theirs, key) == exact_rows(ours, key), (copy, key)
    assert theirs["claims"]["order"] == 4


@pytest.mark.parametrize("copy", ["nodepy/DP5.json", "ordinarydiffeq/DormandPrince.json",
                                  "sundials/ARKODE_DORMAND_PRINCE_7_4_5.json"])
def test_dormand_prince_copies_equal_the_exact_tableau(copy):
    ours = json.loads((METHODS / "dormand_prince54.json").read_text(encoding="utf-8"))
    theirs = json.loads((CORPUS / copy).read_text(encoding="utf-8"))
    for key in ("A", "b", "c", "bhat"):
        assert exact_rows(theirs, key) == exact_rows(ours, key), (copy, key)
    assert theirs["claims"]["order"] == 5 and theirs["claims"].get("embedded_order", 4) == 4   # NodePy: none stated


def ball(x, radius):
    """(centre, radius) of an entry at 50 digits: a decimal's half unit in its last digit, or the file's radius."""
    if isinstance(x, int):
        return mpmath.mpf(x), mpmath.mpf(0)
    if DECIMAL.match(x) and ("." in x or "e" in x.lower()):
        return mpmath.mpf(x), mpmath.mpf(radius) if radius else mpmath.mpf(half_ulp(x).p) / half_ulp(x).q
    e = parse_entry(x)
    return mpmath.mpf(str(sp.N(e, 60))), mpmath.mpf(0)


TSIT5 = ["nodepy/Tsit5.json", "diffeqdevtools/Tsitouras5.json", "ordinarydiffeq/Tsitouras5.json",
         "sundials/ARKODE_TSITOURAS_7_4_5.json"]


@pytest.mark.parametrize("copy", TSIT5[1:])
def test_tsitouras5_copies_agree_to_their_stated_digits(copy):
    """Four libraries' copies of Tsit5 (NodePy's 80-digit literals, the Julia big"…" strings,
    SUNDIALS' 40-digit doubles) overlap entry by entry at 50 digits.  SUNDIALS' embedded weights
    are another member of Tsit5's family of order-4 embeddings (not NodePy's): not compared."""
    with mpmath.workdps(50):
        first = json.loads((CORPUS / TSIT5[0]).read_text(encoding="utf-8"))
        other = json.loads((CORPUS / copy).read_text(encoding="utf-8"))
        for key in ("A", "b") + (("bhat",) if "sundials" not in copy else ()):
            for r1, r2 in zip(exact_or_rows(first[key]), exact_or_rows(other[key]), strict=True):
                for x, y in zip(r1, r2, strict=True):
                    (u, du), (v, dv) = ball(x, first.get("radius")), ball(y, other.get("radius"))
                    assert abs(u - v) <= du + dv + mpmath.mpf(10) ** -45, (copy, key, x, y)


def exact_or_rows(value):
    return value if isinstance(value[0], list) else [value]


def test_a_changed_digit_breaks_the_agreement():
    """The cross-copy check can fail: a Tsit5 entry with its 10th digit changed is outside the balls."""
    with mpmath.workdps(50):
        first = json.loads((CORPUS / TSIT5[0]).read_text(encoding="utf-8"))["A"][2][1]
        other = json.loads((CORPUS / TSIT5[3]).read_text(encoding="utf-8"))["A"][2][1]
        changed = first[:11] + str((int(first[11]) + 1) % 10) + first[12:]
        (u, du), (v, dv) = ball(changed, None), ball(other, None)
        assert abs(u - v) > du + dv


def test_decimal_literals_are_the_source_text():
    """A decimal entry is the literal as the source writes it (checked in the mirror when present)."""
    d = json.loads((CORPUS / "sundials" / "ARKODE_TSITOURAS_7_4_5.json").read_text(encoding="utf-8"))
    assert d["A"][2][1] == "0.3354806554923569885444268742502307746751"
    git_dir = Path("/work/.mirror/LLNL+sundials/repo")
    if not git_dir.exists():
        pytest.skip("no SUNDIALS mirror here")
    where = f"{d['provenance']['commit']}:{d['provenance']['file']}"
    src = subprocess.run(["git", "--git-dir", str(git_dir), "show", where],
                         capture_output=True, text=True, check=True).stdout.splitlines()
    block = "\n".join(src[d["provenance"]["line"] - 1:d["provenance"]["line"] + 60])
    assert "B->A[2][1] = SUN_RCONST(0.3354806554923569885444268742502307746751);" in block


def test_shu_osher_conversion_matches_exact_rational_arithmetic():
    """NodePy's SSP22star is given as Shu–Osher α, β (15-digit literals, loadRKM): redoing
    A = (I − α₀)⁻¹β₀, b = β₁ + α₁A with the literals as exact rationals lands within the file's radius."""
    alpha = [[0, 0], [1, 0], ["0.261583187659478", "0.738416812340522"]]
    beta = [[0, 0], ["0.822875655532364", 0], ["-0.215250437021539", "0.607625218510713"]]
    al = sp.Matrix([[sp.Rational(str(x)) for x in r] for r in alpha])
    be = sp.Matrix([[sp.Rational(str(x)) for x in r] for r in beta])
    A = (sp.eye(2) - al[:2, :]).inv() * be[:2, :]
    b = be[2, :] + al[2, :] * A
    d = json.loads((CORPUS / "nodepy" / "SSP22star.json").read_text(encoding="utf-8"))
    radius = sp.Rational(d["radius"])
    written = [sp.Rational(x) if isinstance(x, str) else sp.Integer(x) for x in d["b"]]
    assert all(abs(w - e) <= radius for w, e in zip(written, b, strict=True))
    assert sp.Rational(d["A"][1][0]) == A[1, 0]


def test_reading_rules():
    assert parse_value("1/3").exact == sp.Rational(1, 3)                      # Julia's float division, read exactly
    assert parse_value("SUN_RCONST(1.0)/SUN_RCONST(3.0)").exact == sp.Rational(1, 3)
    assert parse_value('big"-.8480655492356988544e-2"').text == "-.8480655492356988544e-2"
    assert parse_value("0.161").exact == sp.Rational(161, 1000)                # ≤ 4 significant digits: exact
    assert parse_value("0.16131").text == "0.16131"                             # 5: a decimal, as written
    row = parse_value("[1 -2 3 - 1]")
    assert isinstance(row, Array) and [v.exact for v in row.rows[0]] == [1, -2, 2]
    assert parse_value("2sqrt(3)").exact == 2 * sp.sqrt(3)
    with pytest.raises(Unsupported):
        parse_value("exp(1)")


def test_derived_decimal_radius_covers_the_ball():
    """1 − 0.2928932188 (a derived decimal): the written midpoint ± the file radius holds the exact
    value for every point of the literal's ball."""
    e = Entries()
    text = e.one(parse_value("1 - 0.2928932188"))
    radius = sp.Rational(e.radius_text())
    for end in (sp.Rational("0.29289321875"), sp.Rational("0.29289321885")):
        assert abs(sp.Rational(text) - (1 - end)) <= radius


def test_nodepy_reference_values():
    ref = json.loads((CORPUS / "nodepy" / "nodepy_reference.json").read_text(encoding="utf-8"))
    assert ref["nodepy"] and ref["numpy"]
    floating = {k for k, v in ref["methods"].items() if v["floating_point"]}
    assert floating == {"CMR6", "PD8", "SSP22star", "SSP33", "SSP53", "SSP54", "SSP63", "SSP75", "SSP85", "SSP95",
                        "Tsit5"}
    for k in floating:
        assert (CORPUS / "nodepy" / f"{k}.json").exists()
        assert isinstance(ref["methods"][k]["order"], int)
    assert ref["methods"]["RK44"]["order"] == 4 and ref["methods"]["DP5"]["embedded_order"] == 4


def test_provenance_lines_name_the_tableau():
    """Each file's provenance line, in the mirrored source at the recorded commit, names the
    tableau (its function, table or loadRKM key); one `git show` per source file."""
    mirrors = Path("/work/.mirror")
    files = [(p, json.loads(p.read_text(encoding="utf-8"))) for p in tableau_files()]
    sources: dict = {}
    checked = 0
    for p, d in files:
        prov = d["provenance"]
        git_dir = mirrors / prov["repository"].replace("/", "+") / "repo"
        if not git_dir.exists():
            continue
        key = (str(git_dir), prov["commit"], prov["file"])
        if key not in sources:
            sources[key] = subprocess.run(["git", "--git-dir", key[0], "show", f"{key[1]}:{key[2]}"],
                                          capture_output=True, text=True, check=True).stdout.splitlines()
        line = sources[key][prov["line"] - 1]
        assert d["name"].split("(")[0] in line, (p.name, prov["line"], line)
        checked += 1
    if not checked:
        pytest.skip("no mirrors here")
    assert checked == len(files)
