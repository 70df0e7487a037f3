"""The ``tableau-lab`` command line.

Exit codes: 0 every file read and every claim holds; 1 a claim fails; 2 unreadable input.
"""
from __future__ import annotations

import argparse
import json
import sys

from . import __version__

EXIT_OK, EXIT_CLAIM, EXIT_INPUT = 0, 1, 2


def _verify(args) -> int:
    from .analysis.verify import verify
    from .exact.tableau_json import TableauError, load

    status = EXIT_OK
    for i, path in enumerate(args.files):
        try:
            method = load(path)
        except TableauError as exc:
            print(f"tableau-lab: error: {exc}", file=sys.stderr)
            status = EXIT_INPUT
            continue
        result = verify(method)
        if args.json:
            print(json.dumps({"file": path, **result.to_json()}, ensure_ascii=False), flush=True)
        else:
            if i:
                print()
            print(f"== {path}")
            print(result, flush=True)
        if result.failed and status == EXIT_OK:
            status = EXIT_CLAIM
    return status


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="tableau-lab", description=(
        "Exact verification of Runge-Kutta, partitioned RK and general linear methods."))
    p.add_argument("--version", action="version", version=f"tableau-lab {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    v = sub.add_parser("verify", help="check symplecticity / G-symplecticity and the claims of tableau files",
                       description="Read JSON tableau files, solve the (G-)symplecticity conditions exactly and "
                                   "check each file's claims. Exit 0: all claims hold; 1: a claim fails; "
                                   "2: a file could not be read.")
    v.add_argument("files", nargs="+", metavar="FILE", help="JSON tableau files")
    v.add_argument("--json", action="store_true", help="one JSON object per file, one per line")
    v.set_defaults(run=_verify)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.run(args)
    except KeyboardInterrupt:
        print("tableau-lab: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
