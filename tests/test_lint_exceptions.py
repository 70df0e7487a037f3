"""benchmarks/lint_exceptions.py, which makes the list of per-line lint exceptions in
docs/development.md: only real comments count (a "# noqa" inside a string does not), reasons are
read in the project's three spellings, and a code the ruff selection does not cover is marked as
suppressing nothing."""
from conftest import benchmark_script

lint = benchmark_script("lint_exceptions")


def _project(root, select, name, text):
    """A repository at ``root``: pyproject.toml selecting ``select``, and pkg/``name`` holding ``text``."""
    (root / "pyproject.toml").write_text(f"[tool.ruff.lint]\nselect = {select!r}\n".replace("'", '"'))
    (root / "pkg").mkdir()
    (root / "pkg" / name).write_text(text)


def test_comments_reasons_and_selection(tmp_path):
    _project(tmp_path, ["E", "B", "C90"], "a.py",
        'import os  # noqa: F401 -- re-exported\n'
        'text = "# noqa: E501 -- not a comment"\n'
        'f = lambda x: x  # noqa: E731\n'
        'try:\n    pass\nexcept Exception:  # noqa: BLE001 - blind on purpose\n    pass\n'
        'def g():  # noqa: C901  (a table of cases)\n    pass\n')
    (tmp_path / "reports").mkdir()
    (tmp_path / "reports" / "gen.py").write_text("x = 1  # noqa: E501\n")       # generated: left out
    assert lint.exceptions(tmp_path) == [("pkg/a.py", ("F401",), "re-exported"), ("pkg/a.py", ("E731",), ""),
                                         ("pkg/a.py", ("BLE001",), "blind on purpose"),
                                         ("pkg/a.py", ("C901",), "a table of cases")]
    block = lint.make(tmp_path)
    assert "4 lines carry a `# noqa`, in 1 files" in block
    assert "| BLE001 | not selected: the comment suppresses nothing | 1 | 1 |" in block
    assert "| C901 | too complex (mccabe > 15) | 1 | 1 |" in block
    assert "- `pkg/a.py`: no reason given" in block and "- `pkg/a.py`: a table of cases" in block


def test_type_ignores_listed_with_codes_and_reasons(tmp_path):
    """Each ``# type: ignore[code]`` comment (mypy's per-line exception) is listed with its codes
    and the reason after it; one without codes (every error of the line) shows ``*``; one in a
    string is not a comment."""
    _project(tmp_path, ["E"], "b.py",
        '__hash__ = None  # type: ignore[assignment]  # unhashable, typeshed says a method\n'
        'x = f()  # type: ignore\n'
        'text = "# type: ignore[misc] -- not a comment"\n'
        'y = 1  # noqa: E501 -- long  # type: ignore[misc, arg-type]\n')
    assert lint.exceptions(tmp_path, lint.TYPE_IGNORE) == [
        ("pkg/b.py", ("assignment",), "unhashable, typeshed says a method"), ("pkg/b.py", ("*",), ""),
        ("pkg/b.py", ("misc", "arg-type"), "")]
    block = lint.make(tmp_path)
    assert "3 lines carry a `# type: ignore[code]` (mypy), in 1 files:" in block
    assert "- `pkg/b.py` [assignment]: unhashable, typeshed says a method" in block
    assert "- `pkg/b.py` [*]: no reason given" in block
