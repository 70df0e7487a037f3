"""The command line is a table of small commands (cli.COMMANDS): one handler and one options
function per command, the shared options through argparse parents, no patched argparse."""
from __future__ import annotations

import argparse

import pytest

from tableau_lab import cli


def _subparsers(parser):
    (action,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return action


def test_every_command_of_the_table_is_a_subcommand_running_its_handler():
    parser = cli.build_parser()
    sub = _subparsers(parser)
    assert list(sub.choices) == [c.name for c in cli.COMMANDS]
    for cmd in cli.COMMANDS:
        assert sub.choices[cmd.name].get_default("run") is cmd.run
        assert cmd.name in parser.format_help()


def test_add_parser_is_argparse_s_own():
    """The subparsers' add_parser is not replaced on the instance (the old build_parser patched it
    to inject the shared parents)."""
    sub = _subparsers(cli.build_parser())
    assert "add_parser" not in vars(sub)


@pytest.mark.parametrize("cmd", [c.name for c in cli.COMMANDS])
def test_shared_options_after_the_command(cmd):
    """--debug and --entry-limit after every command; --timeout and --max-field-degree after the
    exact commands and the runs with an exact stage, refused (exit 2) after the others."""
    parser = cli.build_parser()
    needed = {"verify": ["f.json"], "reconstruct": ["f.json"], "order": ["f.json"], "modified": ["f.json"],
              "stability": ["f.json"],
              "solve": ["f.json", "--require", "symplectic"], "design": ["f.json"], "report": ["f.json"],
              "convergence": ["f.json", "--problem", "harmonic"], "workprecision": ["s.json"],
              "replot": ["x"], "completion": ["bash"], "audit": ["d"],
              "roundoff": ["--method", "m", "--problem", "p", "--h", "1", "--steps", "1"]}.get(cmd, [])
    args = parser.parse_args([cmd, *needed, "--debug", "--entry-limit", "depth=9"])
    assert args.debug and args.entry_limit == ["depth=9"]
    timed = cmd in cli.EXACT_COMMANDS + cli.BUILT_WITHIN
    if timed:
        assert parser.parse_args([cmd, *needed, "--timeout", "7", "--max-field-degree", "9"]).timeout == 7.0
    else:
        with pytest.raises(SystemExit) as exc:
            parser.parse_args([cmd, *needed, "--timeout", "7"])
        assert exc.value.code == 2
    # given before the command, the option keeps its value (the parents' defaults are SUPPRESS)
    assert parser.parse_args(["--timeout", "3", cmd, *needed]).timeout == 3.0
