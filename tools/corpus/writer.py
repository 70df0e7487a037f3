"""One tableau file of the corpus, in the shared format (``"numbers": "decimal"`` when an entry is a
decimal), and each library's extraction record; deterministic output (sorted, fixed layout).

An entry is written as:

* an exact entry of the tableau grammar (integer, ``"a/b"``, radicals) when the source's value is exact;
* a decimal literal's text as written (a leading ``.`` gets its ``0``, a Fortran ``d`` exponent
  becomes ``e``: the digits are untouched);
* a *derived* decimal (source arithmetic on a decimal literal, e.g. ``1 - 0.2928932188``) as the
  ball's midpoint, two digits past the ball's width (``DERIVED_DIGITS``); the file then carries an absolute
  ``"radius"`` covering every decimal entry of the file (the propagated ball, the rounding of the
  midpoint and each literal's half unit in its last digit).
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sp
from flint import arb

from tableau_lab.exact.grammar import format_entry
from tableau_lab.files import atomic_write_text

from .expr import Array, Unsupported, Val, half_ulp

FORMAT = "tableau_lab/1"
DERIVED_DIGITS = (17, 110)     # a derived decimal's significant digits: two past its ball's width, within these
CLAIM_KEYS = ("order", "embedded_order", "stage_order", "symplectic", "ssp_coefficient")


def commit_of(git_dir: str) -> str:
    return subprocess.run(["git", "--git-dir", git_dir, "rev-parse", "HEAD"], check=True,
                          capture_output=True, text=True).stdout.strip()


def show(git_dir: str, path: str) -> str:
    return subprocess.run(["git", "--git-dir", git_dir, "show", f"HEAD:{path}"], check=True,
                          capture_output=True, text=True).stdout


def file_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._+-]+", "_", name).strip("_") + ".json"


def derived_digits(ball: arb) -> int:
    """Significant digits that write a derived ball's midpoint two digits past the ball's width."""
    lo, hi = DERIVED_DIGITS
    if ball.rad() == 0:
        return hi
    width = abs(ball.mid()) / ball.rad()
    if not width > 1:
        return lo
    return max(lo, min(hi, int((width.log() / arb(10).log()).mid().floor().unique_fmpz()) + 3))


def numeral(text: str) -> str:
    t = text.replace("_", "").replace("d", "e").replace("D", "e").lstrip("+")
    return re.sub(r"^(-?)\.", r"\g<1>0.", t)


class Entries:
    """Writes a tableau's entries, collecting the radius its derived decimals need."""

    def __init__(self) -> None:
        self.decimal = False
        self.radius: arb | None = None
        self.literal_ulp = sp.Integer(0)

    def one(self, v: Val):
        if not isinstance(v, Val):
            raise Unsupported("an entry that is not a number")
        if v.exact is not None:
            if not v.exact.is_real or v.exact.has(sp.zoo, sp.nan):
                raise Unsupported("an entry that is not a finite real number")
            return format_entry(v.exact)
        self.decimal = True
        if v.text is not None:
            self.literal_ulp = max(self.literal_ulp, half_ulp(v.text))
            return numeral(v.text)
        if v.ball.is_zero():
            return 0
        mid = v.ball.mid().str(derived_digits(v.ball), radius=False)
        if "." in mid and "e" not in mid:
            mid = mid.rstrip("0").rstrip(".")
        miss = abs(arb(mid) - v.ball.mid()) + v.ball.rad()
        self.radius = miss if self.radius is None else max(self.radius, miss, key=lambda x: x.upper())
        return mid

    def vector(self, x) -> list:
        if isinstance(x, Array) and x.items is not None:
            return [self.one(v) for v in x.items]
        if isinstance(x, Array) and (len(x.rows) == 1 or all(len(r) == 1 for r in x.rows)):
            return [self.one(v) for v in sum(x.rows, [])]
        if isinstance(x, list):
            return [self.one(v) for v in x]
        raise Unsupported("a vector of this shape")

    def matrix(self, x) -> list:
        rows = x.as_rows() if isinstance(x, Array) else x
        if isinstance(x, Array) and x.items is not None and len(x.items) == 1:
            rows = [x.items]
        out = [[self.one(v) for v in r] for r in rows]
        if any(len(r) != len(out) for r in out):
            raise Unsupported(f"A is {len(out)}×{len(out[0]) if out else 0}, not square")
        return out

    def radius_text(self) -> str | None:
        if self.radius is None:
            return None
        bound = max(sp.Rational(str(self.radius.upper().mid().str(5, radius=False))) * 2, self.literal_ulp)
        exponent = sp.floor(sp.log(bound, 10)) + 1
        return f"1e{int(exponent)}"


@dataclass
class Tableau:
    name: str
    kind: str
    A: object
    b: object
    c: object = None
    bhat: object = None
    Ahat: object = None
    chat: object = None
    claims: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)
    source: str = ""
    provenance: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        e = Entries()
        parts = {"A": e.matrix(self.A), "b": e.vector(self.b)}
        s = len(parts["A"])
        for key, value, shape in (("c", self.c, "v"), ("Ahat", self.Ahat, "m"), ("bhat", self.bhat, "v"),
                                  ("chat", self.chat, "v")):
            if value is not None:
                parts[key] = e.matrix(value) if shape == "m" else e.vector(value)
        for key, value in parts.items():
            if len(value) != s:
                raise Unsupported(f"{key} has {len(value)} entries for {s} stages")
        claims = {k: (e.one(v) if isinstance(v, Val) else v) for k, v in sorted(self.claims.items())}
        out: dict = {"format": FORMAT, "name": self.name, "kind": self.kind}
        if e.decimal:
            out["numbers"] = "decimal"
            if e.radius_text():
                out["radius"] = e.radius_text()
        out.update({"source": self.source, "provenance": self.provenance})
        out.update(parts)
        out["claims"] = claims
        if self.notes:
            out["notes"] = list(self.notes)
        return out


def dumps(d: dict) -> str:
    """The fixed layout: one matrix row a line, like the files in tableau_lab/methods/."""
    lines = ["{"]
    items = list(d.items())
    for i, (k, v) in enumerate(items):
        comma = "," if i < len(items) - 1 else ""
        if isinstance(v, list) and v and isinstance(v[0], list):
            rows = ",\n".join("    " + json.dumps(r, ensure_ascii=False) for r in v)
            lines.append(f"  {json.dumps(k)}: [\n{rows}\n  ]{comma}")
        else:
            lines.append(f"  {json.dumps(k)}: {json.dumps(v, ensure_ascii=False, sort_keys=True)}{comma}")
    lines.append("}")
    return "\n".join(lines) + "\n"


class Library:
    """A library's output folder: its tableau files and its record ``extraction.json``."""

    def __init__(self, out: Path, library: str, repository: str, git_dir: str) -> None:
        self.out, self.library, self.repository = Path(out) / library, library, repository
        self.git_dir, self.commit = git_dir, commit_of(git_dir)
        self.files: dict[str, str] = {}
        self.skipped: list[dict] = []
        self.read: set[str] = set()

    def provenance(self, path: str, line: int) -> dict:
        self.read.add(path)
        return {"repository": self.repository, "commit": self.commit, "file": path, "line": line}

    def add(self, t: Tableau) -> None:
        try:
            text = dumps(t.to_dict())
        except Unsupported as exc:
            self.skip(t.name, f"unreadable: {exc}", t.provenance)
            return
        fname = file_name(t.name)
        if fname in self.files:
            raise ValueError(f"two tableaux named {fname} in {self.library}")
        self.files[fname] = text

    def skip(self, name: str, reason: str, where: dict | None = None) -> None:
        self.skipped.append({"name": name, "reason": reason, **({"file": where.get("file"), "line": where.get("line")}
                                                                 if where else {})})

    def write(self, command: str) -> None:
        self.out.mkdir(parents=True, exist_ok=True)
        for old in self.out.glob("*.json"):
            if old.name not in self.files and old.name not in ("extraction.json", "nodepy_reference.json"):
                old.unlink()
        for fname, text in sorted(self.files.items()):
            atomic_write_text(self.out / fname, text)
        record = {"library": self.library, "repository": self.repository, "commit": self.commit,
                  "files_read": sorted(self.read), "tableaux": len(self.files), "command": command,
                  "skipped": sorted(self.skipped, key=lambda s: (s["reason"], s["name"]))}
        atomic_write_text(self.out / "extraction.json", json.dumps(record, indent=1, ensure_ascii=False) + "\n")
        print(f"{self.library}: {len(self.files)} tableaux, {len(self.skipped)} skipped -> {self.out}")


def command_line(extract: Callable[[str, Path], Library], module: str, argv: list[str] | None = None) -> None:
    """An extractor's command line, ``python -m MODULE GIT_DIR [OUT]`` (OUT defaults to ``corpus``):
    extract from the bare git directory GIT_DIR and write OUT/<library>/, its record naming the command."""
    argv = sys.argv[1:] if argv is None else argv
    git_dir, out = argv[0], Path(argv[1] if len(argv) > 1 else "corpus")
    extract(git_dir, out).write(f"python -m {module} {git_dir} {out}")
