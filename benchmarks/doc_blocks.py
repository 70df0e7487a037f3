"""Generated blocks of the docs: the text between ``<!-- name -->`` and ``<!-- /name -->`` in a
markdown file, read by the tests (is the block current?) and rewritten by the scripts that make it."""
from __future__ import annotations

from pathlib import Path


def markers(name: str) -> tuple:
    return f"<!-- {name} -->", f"<!-- /{name} -->"


def read_block(path, name: str) -> str:
    """The text between the markers (without the newlines next to them)."""
    start, end = markers(name)
    doc = Path(path).read_text()
    if doc.count(start) != 1 or doc.count(end) != 1 or doc.index(start) > doc.index(end):
        raise SystemExit(f"{path}: markers {start} … {end} missing (or repeated)")
    return doc.split(start, 1)[1].split(end, 1)[0].strip("\n")


def write_block(path, name: str, text: str) -> None:
    """Replace the block's text, atomically (no half-written docs)."""
    import sys
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from tableau_lab.files import atomic_write_text
    read_block(path, name)                       # the markers are there, once
    start, end = markers(name)
    doc = Path(path).read_text()
    head, rest = doc.split(start, 1)
    atomic_write_text(path, head + start + "\n" + text + "\n" + end + rest.split(end, 1)[1])


def cli(description: str, name: str, make, argv=None) -> int:
    """The command line of a script that makes one block: print the text ``make()`` returns, and with
    ``--write MD`` put it between the block's markers in MD."""
    import argparse
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--write", metavar="MD", help="the markdown file whose block to rewrite")
    args = ap.parse_args(argv)
    text = make()
    print(text)
    if args.write:
        write_block(args.write, name, text)
    return 0
