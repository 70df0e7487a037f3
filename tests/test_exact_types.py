"""The type configuration of issue 31 (part 6) and what typing exact/ strictly turned up.

``mypy`` (no arguments) reads [tool.mypy] in pyproject.toml: exact/ and render/ with every flag of --strict,
analysis/ checked, third-party modules without types named one by one (no blanket
ignore_missing_imports).  The CI runs it (.ci/run); these tests pin the configuration's shape
without running mypy (seconds of cold start)."""
import tomllib
from pathlib import Path

from tableau_lab.exact.conjugate import ANY, collocation, shifted_legendre

ROOT = Path(__file__).resolve().parent.parent
STRICT_FLAGS = {"disallow_any_generics", "disallow_subclassing_any", "disallow_untyped_calls", "disallow_untyped_defs",
                "disallow_incomplete_defs", "disallow_untyped_decorators", "warn_return_any", "no_implicit_reexport",
                "extra_checks"}


def _mypy():
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["mypy"]


def test_exact_is_strict_and_analysis_checked():
    cfg = _mypy()
    assert {"tableau_lab/exact", "tableau_lab/render", "tableau_lab/analysis"} <= set(cfg["files"])
    assert cfg["check_untyped_defs"] and cfg["warn_unused_ignores"] and cfg["strict_equality"]
    assert "strict" not in cfg              # global-only: it would make analysis/ strict too
    exact = [o for o in cfg["overrides"] if {"tableau_lab.exact.*", "tableau_lab.render.*"} <= set(o["module"])]
    assert len(exact) == 1 and all(exact[0].get(flag) is True for flag in STRICT_FLAGS)


def test_missing_imports_ignored_only_per_named_module():
    cfg = _mypy()
    assert "ignore_missing_imports" not in cfg
    for o in cfg["overrides"]:
        if o.get("ignore_missing_imports"):
            assert all(not m.startswith("tableau_lab") and m not in ("*", "") for m in o["module"]), o


def test_the_zero_of_every_arithmetic_is_an_identity_on_both_sides():
    """ANY (the start of sums of stage vectors mod P) is an identity whichever side it stands on;
    before typing, a stage vector plus ANY returned ANY."""
    one, x, A, b = collocation(shifted_legendre(3)).operators()
    v = A * (x * x) + one
    assert ANY + v == v and v + ANY == v and (v + ANY) is v
    assert sum((A * x for _ in range(2)), ANY) == (A * x) + (A * x)
    assert b * (v + ANY) == b * v
