"""Issue 19, item 7: shell completion (``tableau-lab completion SHELL``, made by shtab from the
parser) and ``--version``.  The bash script is sourced in a real bash and asked to complete, as
bash would call it on a Tab: command names, options, and file names where a file is expected."""
import shutil
import subprocess
import sys
from importlib.metadata import version

import pytest

from tableau_lab import __version__
from tableau_lab.cli import main

PROGRAM = [sys.executable, "-m", "tableau_lab"]


def _complete(script, words, cwd):
    """COMPREPLY of the completion function for the command line ``words`` (the last one being typed)."""
    line = " ".join(words)
    probe = (f"source {script}\nCOMP_WORDS=({line}); COMP_CWORD={len(words) - 1}; COMP_LINE='{line}'; "
             f"COMP_POINT=${{#COMP_LINE}}\n_shtab_tableau_lab tableau-lab {words[-1]} {words[-2]}\n"
             'printf "%s\\n" "${COMPREPLY[@]}"\n')
    out = subprocess.run(["bash", "-c", probe], capture_output=True, text=True, cwd=cwd, check=True)
    return set(out.stdout.split())


@pytest.mark.skipif(shutil.which("bash") is None, reason="no bash")
def test_bash_completion_completes_commands_options_and_files(tmp_path, capsys):
    assert main(["completion", "bash"]) == 0
    script = tmp_path / "tableau-lab.bash"
    script.write_text(capsys.readouterr().out)
    assert subprocess.run(["bash", "-n", str(script)]).returncode == 0          # valid bash
    (tmp_path / "work").mkdir()
    (tmp_path / "work" / "mine.json").write_text("{}")
    (tmp_path / "work" / "other.txt").write_text("")
    cwd = tmp_path / "work"
    assert _complete(script, ["tableau-lab", "ver"], cwd) == {"verify"}
    assert {"workprecision"} <= _complete(script, ["tableau-lab", "w"], cwd)
    assert {"--problem", "--project"} == _complete(script, ["tableau-lab", "run", "--pro"], cwd)
    assert _complete(script, ["tableau-lab", "verify", "mi"], cwd) == {"mine.json"}
    assert "completion" in _complete(script, ["tableau-lab", "comp"], cwd)


def test_zsh_and_tcsh_scripts_name_every_command(capsys):
    for shell in ("zsh", "tcsh"):
        assert main(["completion", shell]) == 0
        text = capsys.readouterr().out
        for command in ("verify", "order", "solve", "run", "suite", "report", "design"):
            assert command in text, (shell, command)


def test_version_is_the_installed_distribution():
    out = subprocess.run([*PROGRAM, "--version"], capture_output=True, text=True, check=True).stdout.strip()
    assert out == f"tableau-lab {__version__}" == f"tableau-lab {version('tableau_lab')}"


def test_unknown_shell_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["completion", "powershell-9"])
    assert exc.value.code == 2 and "invalid choice" in capsys.readouterr().err
