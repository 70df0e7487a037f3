"""Issue 19, item 5: the docs cannot drift from the code.  ``benchmarks/docs_check.py`` reruns
every command transcript quoted in README.md and docs/*.md and compares the generated blocks with
their scripts; here it must pass on the docs as they are, and fail when a quoted number or word
is changed by hand."""
from pathlib import Path

import pytest
from conftest import benchmark_script

ROOT = Path(__file__).resolve().parents[1]
check = benchmark_script("docs_check")


TRANSCRIPTS = [t for doc in check.DOCS for t in check.transcripts(doc)]


@pytest.mark.parametrize("t", TRANSCRIPTS, ids=lambda t: f"{t.path.name}:{t.line}")
def test_every_quoted_transcript_matches_the_code(t):
    """One transcript a test (README.md alone quotes ten commands), so that the workers share them."""
    assert check.check_transcript(t) == []


@pytest.mark.parametrize("doc", check.DOCS, ids=lambda p: p.name)
def test_every_generated_block_matches_its_script(doc):
    assert check.check_blocks(doc) == []


def test_the_command_checks_a_document(capsys):
    """``python benchmarks/docs_check.py FILE``: transcripts and blocks, the count on stderr."""
    assert check.main([str(ROOT / "docs" / "tableau-format.md")]) == 0, capsys.readouterr().out
    assert "5 transcripts checked, 0 differences" in capsys.readouterr().err


def _verify_transcript(tmp_path, edit=lambda s: s):
    text = (ROOT / "README.md").read_text()
    start = text.index("```\n$ tableau-lab verify methods/example4_glm.json")
    block = text[start:text.index("```", start + 3) + 3]
    md = tmp_path / "doc.md"
    md.write_text(edit(block) + "\n")
    (t,) = check.transcripts(md)
    return t


def test_a_number_or_word_changed_by_hand_is_found(tmp_path):
    t = _verify_transcript(tmp_path)
    code, out = check.run(t)
    assert check.check_transcript(t, out, code) == []                 # the README's own quote passes
    bad = _verify_transcript(tmp_path, lambda s: s.replace("rank 4", "rank 5"))
    assert any("quote 5, the command prints 4" in p for p in check.check_transcript(bad, out, code))
    bad = _verify_transcript(tmp_path, lambda s: s.replace("G is definite", "G is indefinite"))
    assert any("not in the actual output" in p for p in check.check_transcript(bad, out, code))
    bad = _verify_transcript(tmp_path, lambda s: s.replace("methods/example4_glm.json\n== ",
                                                           "methods/example4_glm.json   # exit 1\n== "))
    assert any("exited 0, the docs say 1" in p for p in check.check_transcript(bad, out, code))


def test_number_rule():
    same = check.same_number
    assert same("14616", "14616") and not same("14616", "14617")
    assert same("0.136", "0.137") and not same("0.136", "0.139")           # two units of the last digit
    assert same("-0.6738313830995034", "-0.6738313830995053")              # 16 digits: 1e-9 relative
    assert not same("-0.6738313830995034", "-0.673831380")
    assert same("7.550e-15", "6.772e-15") and not same("7.550e-15", "3e-13")   # round-off: a factor 10
    pairs = check.match("sweeps 3097, 0.150 s\n  H 6.772e-15 ... end",
                        "sweeps 3097,   0.9 s H 6.7e-15 and more text end")
    assert pairs == [("3097", "3097"), (None, "0.9"), ("6.772e-15", "6.7e-15")]     # a duration is not compared
    assert check.match("rank 4 ... G is definite", "rank 4, G is indefinite") == "Gisdefinite"
    assert check.match("x = -1", "x = 1") == "x=-1"                              # a sign is text


def test_a_benchmarks_script_transcript_is_run_but_never_one_that_writes(tmp_path):
    """``$ python benchmarks/NAME.py`` lines are transcripts too; one with a writing option
    (--save, --write …) is not run and is reported, so the check never rewrites tracked files."""
    md = tmp_path / "doc.md"
    md.write_text("```\n$ python benchmarks/symmetric_member.py -- -3/20 2/5\n"
                  "order 4, with θ ≡ 0: 4; G-symplectic: True\n"
                  "$ python benchmarks/symmetric_member.py --save methods/glm4_symmetric.json -- -3/20 2/5\n```\n")
    good, writing = check.transcripts(md)
    assert check.check_transcript(good) == []
    code, out = check.run(writing)
    assert code != 0 and "--save would write files" in out
    assert any("exited" in p for p in check.check_transcript(writing, out, code))
