"""The docs check (issue 19, item 5): every command transcript quoted in README.md and docs/*.md
is run again and compared with what the docs say, and every generated block of the docs
(``<!-- name -->`` … ``<!-- /name -->``) is compared with what its script makes now.

    python benchmarks/docs_check.py [FILE.md ...] [--no-blocks]

Exit 0 when everything matches, 1 with one line per difference (file, line, what differs).

**Transcripts.**  A fenced block whose lines start with ``$ tableau-lab …`` or ``$ python
benchmarks/NAME.py …`` is a transcript: each ``$`` line is a command (a trailing ``# exit N`` is
its expected exit code, else 0) and the lines up to the next ``$`` line are its quoted output
(stdout and stderr together).  The command runs in the repository's root (``python -m
tableau_lab`` for ``tableau-lab``, this interpreter for ``python``); a benchmarks script is run only
without ``WRITING`` options (the check never rewrites tracked files: quote the read-only form of the
command).  Its output must contain the quoted text in order, with these rules:

* whitespace and line breaks are not compared (the docs wrap long messages);
* ``...`` (also ``(...)``) stands for any text the docs leave out;
* numbers are compared as numbers (:func:`same_number`): integers exactly; decimals to two units
  of their last quoted digit and, when quoted with 10 or more significant digits, to 1e-9
  relative; values below ``ROUNDOFF`` (round-off: max |H − H₀| of a projected run, say) only
  to within a factor 10; durations (a number followed by ``s`` or ``µs``) not at all.

**Blocks.**  ``BLOCKS`` names, per block, the script whose ``make()`` writes it (``--write``);
blocks whose making reruns experiments (minutes) are checked by their own tests instead and
listed in ``EXPENSIVE``.
"""
from __future__ import annotations

import argparse
import importlib
import math
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
ROUNDOFF = 1e-12          # quoted values below this are round-off: compared to within a factor 10
TIMEOUT = 300.0           # seconds per command
COMMANDS = ("$ tableau-lab", "$ python benchmarks/")      # the $ lines that are transcripts
WRITING = ("--save", "--write", "--family", "--out")    # options of a benchmarks script that write files
# settings the test suite makes (tests/conftest.py) that a user does not: the docs quote the defaults
# (the compiled loop; the pure loop may stop a projection one iteration apart)
USER_DEFAULTS = ("TABLEAU_LAB_KERNEL", "TABLEAU_LAB_SPECIALISE", "TABLEAU_LAB_FIGURE_FORMATS")
# block name -> benchmarks script whose make() writes it (no runs: reads saved outputs)
BLOCKS = {"bench-table": "bench_block", "wp-kepler": "wp_block", "suite-tables": "suite_tables",
          "wp-glm4s": "wp_glm4s", "dense-table": "dense_matrices", "nodepy-stability": "nodepy_stability",
          "nodepy-float": "nodepy_float",
          "scene-format": "scene_doc", "lint-exceptions": "lint_exceptions"}
# blocks made by rerunning searches or sweeps: checked by their tests (tests/test_moonshot.py,
# tests/test_pareto_table.py, tests/test_design_search.py)
EXPENSIVE = {"pareto-table", "moonshot-table", "g43r-ystar", "g43r-error", "series-table",
             "latency"}      # timings of this machine (benchmarks/latency.py): made, not compared

NUMBER = r"(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?"          # unsigned: a sign is compared as text
_TOKEN = re.compile(rf"(\.\.\.)|({NUMBER})|(\s+)|(.)", re.S)


@dataclass
class Transcript:
    path: Path
    line: int                 # of the $ line (1-based)
    command: str
    exit_code: int
    quoted: str


def transcripts(path: Path) -> list[Transcript]:
    """The command transcripts of a markdown file (module docstring)."""
    out, lines = [], Path(path).read_text().splitlines()
    inside, current = False, None
    for k, line in enumerate(lines, 1):
        if line.startswith("```"):
            if inside and current is not None:
                out.append(current)
            inside, current = not inside, None
            continue
        if not inside:
            continue
        if line.startswith(COMMANDS):
            if current is not None:
                out.append(current)
            cmd, _, comment = line[2:].partition("#")
            m = re.search(r"exit\s+(\d+)", comment)
            current = Transcript(Path(path), k, cmd.strip(), int(m.group(1)) if m else 0, "")
        elif current is not None:
            current.quoted += line + "\n"
    return out


def tokens(text: str, durations: bool = False) -> list:
    """Whitespace-free tokens: ("...", None) for an ellipsis, ("n", number) and ("c", character);
    with ``durations``, a number followed by the word ``s`` or ``µs`` is ("d", number)."""
    out = []
    for m in _TOKEN.finditer(text):
        ellipsis, number, space, char = m.groups()
        if ellipsis:
            out.append(("...", None))
        elif number:
            duration = durations and re.match(r"\s?(s|µs)\b", text[m.end():m.end() + 4])
            out.append(("d" if duration else "n", number))
        elif char:
            out.append(("c", char))
    return out


def _find(segment: list, actual: list, start: int) -> int:
    """The first position ≥ start where the quoted segment's tokens occur in ``actual`` (numbers
    and durations match any number), or −1."""
    kinds = {"n": "n", "d": "n", "c": "c"}
    for k in range(start, len(actual) - len(segment) + 1):
        if all(actual[k + i][0] == kinds[kind] and (kind != "c" or actual[k + i][1] == text)
               for i, (kind, text) in enumerate(segment)):
            return k
    return -1


def match(quoted: str, output: str):
    """Pairs (quoted number, printed number) in order when the quoted text occurs in the output
    (module docstring; durations paired with None), else the quoted segment not found."""
    q, a = tokens(quoted, durations=True), tokens(output)
    segments, current = [], []
    for tok in q:
        if tok[0] == "...":
            segments.append(current)
            current = []
        else:
            current.append(tok)
    segments.append(current)
    pos, pairs = 0, []
    for segment in segments:
        if not segment:
            continue
        k = _find(segment, a, pos)
        if k < 0:
            return "".join(text for _, text in segment)
        pairs += [(None if kind == "d" else text, a[k + i][1]) for i, (kind, text) in enumerate(segment) if kind != "c"]
        pos = k + len(segment)
    return pairs


def same_number(quoted: str, actual: str) -> bool:
    """Module docstring's rule for one number."""
    if re.fullmatch(r"[-+]?\d+", quoted):
        return re.fullmatch(r"[-+]?\d+", actual) is not None and int(quoted) == int(actual)
    q, a = float(quoted), float(actual)
    if 0 < abs(q) < ROUNDOFF:
        return a != 0 and abs(math.log10(abs(a) / abs(q))) <= 1
    mantissa = re.match(r"[-+]?([\d.]+)", quoted).group(1)
    digits = mantissa.replace(".", "").lstrip("0")
    exponent = int(quoted.lower().split("e")[1]) if "e" in quoted.lower() else 0
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    unit = 10.0 ** (exponent - decimals)
    if len(digits) >= 10:
        return abs(a - q) <= max(1e-9 * abs(q), 2 * unit)
    return abs(a - q) <= 2 * unit * (1 + 1e-12)


def run(t: Transcript) -> tuple[int, str]:
    argv = shlex.split(t.command)
    if argv[0] == "python":
        writes = [a for a in argv if a.split("=")[0] in WRITING]
        if writes:
            return -1, f"not run: {' '.join(writes)} would write files (quote the command without it)"
        argv = [sys.executable, *argv[1:]]
    else:
        argv = [sys.executable, "-m", "tableau_lab", *argv[1:]]
    env = {k: v for k, v in os.environ.items() if k not in USER_DEFAULTS}     # as a user runs it
    p = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, timeout=TIMEOUT, env=env)
    return p.returncode, p.stdout + p.stderr


def check_transcript(t: Transcript, output: str | None = None, code: int | None = None) -> list[str]:
    """The differences between the quoted and the actual output of one transcript ([] if none)."""
    if output is None:
        code, output = run(t)
    where = f"{t.path.relative_to(ROOT) if t.path.is_relative_to(ROOT) else t.path}:{t.line}"
    problems = []
    if code != t.exit_code:
        problems.append(f"{where}: `{t.command}` exited {code}, the docs say {t.exit_code}")
    pairs = match(t.quoted, output)
    if isinstance(pairs, str):
        problems.append(f"{where}: `{t.command}`: the quoted output is not in the actual output; "
                        f"first difference in: {_first_difference(t.quoted, output)!r}")
        return problems
    for q, a in pairs:
        if q is not None and not same_number(q, a):
            problems.append(f"{where}: `{t.command}`: the docs quote {q}, the command prints {a}")
    return problems


def _first_difference(quoted: str, output: str) -> str:
    """The first quoted line (after the lines still found in order) that is not in the output."""
    lines = [ln for ln in quoted.strip().splitlines() if ln.strip()]
    for k in range(1, len(lines) + 1):
        if isinstance(match("\n".join(lines[:k]), output), str):
            return lines[k - 1].strip()
    return "(none)"


def check_blocks(path: Path) -> list[str]:
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from doc_blocks import read_block
    problems = []
    text = Path(path).read_text()
    for name in re.findall(r"<!-- ([a-z0-9-]+) -->", text):
        if name in EXPENSIVE:
            continue
        if name not in BLOCKS:
            problems.append(f"{path.name}: block <!-- {name} --> has no generating script in docs_check.BLOCKS")
            continue
        module = importlib.import_module(BLOCKS[name])
        if read_block(path, name) != module.make():
            problems.append(f"{path.name}: block <!-- {name} --> differs from `python benchmarks/{BLOCKS[name]}.py`; "
                            f"rewrite it with --write {path.relative_to(ROOT)}")
    return problems


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("files", nargs="*", type=Path, help="markdown files (default: README.md and docs/*.md)")
    ap.add_argument("--no-blocks", action="store_true", help="transcripts only")
    args = ap.parse_args(argv)
    problems, count = [], 0
    for path in args.files or DOCS:
        for t in transcripts(path):
            count += 1
            problems += check_transcript(t)
        if not args.no_blocks:
            problems += check_blocks(path)
    for p in problems:
        print(p)
    print(f"{count} transcripts checked, {len(problems)} differences", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
