r"""The audit of tableau files (``tableau-lab audit``, ``tl.audit``; issue 33 item 5): every file
through the exact analyses (an exact file: :func:`~tableau_lab.analysis.verify.verify`) or the
certified ones in ball arithmetic (a decimal file, ``"numbers": "decimal"``:
:func:`~tableau_lab.analysis.certified.certified_verify`), every claim of its ``"claims"`` checked,
one :class:`Row` per method: claimed against found for each claimed property, the order, embedded
order and stage order found even where nothing is claimed, and the verdict

* ``agrees`` — every claim holds (exactly, or *to the stated precision* for a decimal file);
* ``DISAGREES`` — a claim is refuted, with its evidence: the failing condition, its tree and its
  residual (a ball that excludes 0 for a decimal file, the exact value for an exact one);
* ``undecided`` — no claim is refuted but one is not decided (the digits, the time budget — a
  method over ``seconds`` is "undecided: budget" — or a claim no analysis checks).

The files run on the project's executor (:mod:`executor`: a process pool, this process, or a Dask
cluster) with a progress bar; a file that cannot be read is reported (:class:`Bad`, its message
naming the file and the entry) and the audit goes on; a JSON file that is no tableau (an index, a
reference table: ``INDEX.json``, ``*_reference.json``, or an object without ``"kind"`` and
``"A"``) is skipped, counted, with the reason (:class:`Skipped`).  The text, Markdown and LaTeX of
the result are one :class:`~tableau_lab.render.model.Document` (``display()``) rendered by the
rendering layer; ``proofs/audit.py`` writes the report files.

>>> import tableau_lab as tl
>>> r = tl.audit(["methods/rk4.json"], workers=1)
>>> row = r.rows[0]
>>> row.verdict, row.found_value("order"), [(c.prop, c.claimed, c.found, c.verdict) for c in row.checks][:2]
('agrees', '4', [('g_symplectic', 'false', 'false', 'agrees'), ('order', '4', '4', 'agrees')])
>>> r.exit_code
0
"""
from __future__ import annotations

import fnmatch
import functools
import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..budget import AUDIT_SECONDS, computing, time_limit
from ..errors import EXIT_BUG, EXIT_CLAIM, EXIT_INPUT, EXIT_OK, BudgetError, InputError
from ..render.displayed import Displayed
from ..render.model import Document, Paragraph, Table, Text

__all__ = ["audit_files", "audit_file", "collect", "AuditResult", "Row", "Check", "Bad", "Skipped", "AGREES",
           "DISAGREES", "UNDECIDED", "AUDIT_SECONDS", "SKIPPED_NAMES"]

AGREES, DISAGREES, UNDECIDED = "agrees", "DISAGREES", "undecided"
#: file names that are never tableaux (a corpus's index, a library's reference values), with what each is
_NOT_TABLEAUX = {"INDEX.json": "an index", "*_reference.json": "reference values"}
SKIPPED_NAMES = tuple(_NOT_TABLEAUX)
#: the conditions shown as evidence per disagreement (all are counted)
EVIDENCE_SHOWN = 3
#: the found properties reported for every method, claimed or not (claim name → the findings' name)
FOUND = (("order", "order"), ("embedded_order", "embedded order"), ("stage_order", "stage order"))
#: a claim's finding in a certified result (a claim not here: its name with spaces)
_FINDING_OF_CLAIM = {**dict(FOUND), "ssp_coefficient": "SSP coefficient"}


@dataclass(frozen=True)
class Check:
    """One claimed property: what the file claims, what was found, the verdict and its evidence."""
    prop: str
    claimed: str
    found: str
    verdict: str
    evidence: tuple[str, ...] = ()

    def to_json(self) -> dict:
        return {"property": self.prop, "claimed": self.claimed, "found": self.found, "verdict": self.verdict,
                "evidence": list(self.evidence)}


@dataclass(frozen=True)
class Row:
    """One method of the audit (module docstring)."""
    file: str
    name: str
    library: str
    kind: str
    numbers: str
    stages: int
    checks: tuple[Check, ...]
    found: tuple[tuple[str, str], ...]
    verdict: str
    seconds: float
    note: str = ""

    def found_value(self, prop: str) -> str | None:
        return dict(self.found).get(prop)

    @property
    def disagreements(self) -> tuple[Check, ...]:
        return tuple(c for c in self.checks if c.verdict == DISAGREES)

    def claims_text(self) -> str:
        """The table's "claimed → found" cell."""
        return "; ".join(f"{c.prop} {c.claimed} → {c.found or '?'}" for c in self.checks) or "none"

    def found_text(self) -> str:
        """The table's "found" cell: the orders found (:data:`FOUND`)."""
        return ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in self.found if k in dict(FOUND))

    def verdict_text(self) -> str:
        return self.verdict + (f": {self.note}" if self.note else "")

    def to_json(self) -> dict:
        return {"file": self.file, "name": self.name, "library": self.library, "kind": self.kind,
                "numbers": self.numbers, "stages": self.stages, "verdict": self.verdict, "note": self.note,
                "found": dict(self.found), "claims": [c.to_json() for c in self.checks],
                "seconds": round(self.seconds, 3)}


@dataclass(frozen=True)
class Bad:
    """A file that could not be read or analysed: its message names the file (and the entry)."""
    file: str
    message: str
    bug: bool = False


@dataclass(frozen=True)
class Skipped:
    """A JSON file that is no tableau, and why."""
    file: str
    why: str


# ------------------------------------------------------------------ the files

def _skipped_by_name(path: Path) -> str | None:
    return next((f"{what} ({pattern}), not a tableau" for pattern, what in _NOT_TABLEAUX.items()
                 if fnmatch.fnmatchcase(path.name, pattern)), None)


def collect(paths) -> tuple[list[tuple[str, str]], list[Skipped], list[Bad]]:
    """The tableau files of ``paths`` (files, and folders searched for ``*.json`` recursively, in
    sorted order) as (file, library folder) pairs — the library of a file found in a folder is the
    first folder below it (``corpus/<library>/…``), of a file given by name its own folder; the
    files skipped by name; the paths that are neither a file nor a folder."""
    files: list[tuple[str, str]] = []
    skipped: list[Skipped] = []
    bad: list[Bad] = []
    for p in map(Path, paths):
        if p.is_dir():
            found = sorted(x for x in p.rglob("*.json") if x.is_file())
            for x in found:
                why = _skipped_by_name(x)
                if why:
                    skipped.append(Skipped(str(x), why))
                else:            # the library: the first folder below the one given (corpus/<library>/…)
                    parts = x.relative_to(p).parts
                    files.append((str(x), parts[0] if len(parts) > 1 else p.resolve().name))
        elif p.exists():
            files.append((str(p), p.resolve().parent.name))
        else:
            bad.append(Bad(str(p), f"{p}: no such file or folder"))
    return files, skipped, bad


# ------------------------------------------------------------------ one file

def audit_file(item: tuple[str, str], seconds: float = AUDIT_SECONDS) -> Row | Bad | Skipped:
    """The audit of one file ``item`` = (path, library folder) within ``seconds`` (a worker's task:
    every error is returned as a :class:`Bad`, so that the other files go on)."""
    from ..exact.tableau_json import from_dict_any, read
    path, folder = item
    start = time.monotonic()
    try:
        with computing(f"audit of {path}"):
            data = read(path)
            if not isinstance(data, dict) or ("kind" not in data and "A" not in data):
                return Skipped(path, "JSON without the keys \"kind\" and \"A\": not a tableau")
            m = from_dict_any(data, path)
            library = str(dict(getattr(m, "provenance", ()) or ()).get("repository") or folder)
            return _analysed(m, path, library, seconds, start)
    except BudgetError:
        return _over_budget(path, folder, data, seconds, start)
    except InputError as exc:
        return Bad(path, str(exc))
    except (RecursionError, MemoryError) as exc:
        return Bad(path, f"{path}: too large or too deeply nested to analyse ({type(exc).__name__})")
    except Exception as exc:        # a bug: reported with the file, the other files go on
        return Bad(path, f"{path}: internal error (a bug): {type(exc).__name__}: {str(exc)[:200]}", bug=True)


def _over_budget(path: str, folder: str, data: Any, seconds: float, start: float) -> Row:
    d = data if isinstance(data, dict) else {}
    claims = d.get("claims") if isinstance(d.get("claims"), dict) else {}
    checks = tuple(Check(k, _shown(v), "", UNDECIDED, (f"the time budget of {seconds:g} s ran out",))
                   for k, v in claims.items())
    A = d.get("A")
    prov = d.get("provenance") if isinstance(d.get("provenance"), dict) else {}
    return Row(path, str(d.get("name", "")), str(prov.get("repository") or folder), str(d.get("kind", "")),
               str(d.get("numbers", "exact")), len(A) if isinstance(A, list) else 0, checks, (), UNDECIDED,
               time.monotonic() - start, "budget")


def _analysed(m: Any, path: str, library: str, seconds: float, start: float) -> Row:
    from ..exact.balls import BallMethod
    if isinstance(m, BallMethod):
        from ..analysis.certified import certified_verify
        with time_limit(2 * seconds + 1):        # the certified analyses keep their own clock; this is the backstop
            res = certified_verify(m, seconds=seconds)
        checks, found = _certified_checks(res)
        note = "budget" if any("budget" in f.statement for f in res.findings) else ""
        numbers = "decimal"
    else:
        from ..analysis.verify import verify
        with time_limit(seconds):
            res = verify(m)
        checks, found = _exact_checks(res)
        note, numbers = "", "exact"
    verdict = (DISAGREES if any(c.verdict == DISAGREES for c in checks) else
               UNDECIDED if any(c.verdict == UNDECIDED for c in checks) else AGREES)
    note = note or ("" if checks else "no claims")
    return Row(path, m.name, library, m.kind, numbers, m.s, checks, found, verdict, time.monotonic() - start, note)


def _shown(v: Any) -> str:
    if isinstance(v, bool):
        return str(v).lower()
    text = getattr(v, "text", None)
    if isinstance(text, str):
        return text
    from ..exact.grammar import format_entry
    return str(v) if isinstance(v, (int, str)) else str(format_entry(v))


def _certified_checks(res: Any) -> tuple[tuple[Check, ...], tuple[tuple[str, str], ...]]:
    """The claims and the found orders of a :class:`~tableau_lab.analysis.certified.CertifiedResult`."""
    from ..analysis.certified_findings import REFUTED, UNDECIDED as NOT_DECIDED
    findings = {f.name: f for f in res.findings}
    checks = []
    for c in res.claims:
        verdict = DISAGREES if c.status == REFUTED else UNDECIDED if c.status == NOT_DECIDED else AGREES
        evidence = tuple(e.text() for e in c.evidence) or ((c.why,) if c.why and verdict != AGREES else ())
        f = findings.get(_FINDING_OF_CLAIM.get(c.claim, c.claim.replace("_", " ")))
        checks.append(Check(c.claim, _shown(c.claimed), "" if f is None else _finding_text(f), verdict, evidence))
    found = tuple((k, _finding_text(findings[name])) for k, name in FOUND if name in findings)
    extra = tuple((name, _finding_text(findings[name])) for name in ("SSP coefficient", "real stability interval")
                  if name in findings)
    return tuple(checks), found + extra


def _finding_text(f: Any) -> str:
    """A finding's value in a table cell: an order (≥ p when undecided), true/false, or its statement."""
    from ..analysis.certified_findings import CERTIFIED
    v = f.value
    if isinstance(v, bool):
        return str(v).lower() if f.status == CERTIFIED else f"{str(v).lower()}?"
    if isinstance(v, int):
        return str(v) if f.status == CERTIFIED else f"≥ {v} (undecided)"
    return f.statement.split(" (")[0]


def _exact_checks(res: Any) -> tuple[tuple[Check, ...], tuple[tuple[str, str], ...]]:
    """The claims and the found orders of an exact :class:`~tableau_lab.analysis.verify.VerifyResult`."""
    checks = []
    for k, claimed in res.claims.items():
        if k in res.unchecked:
            checks.append(Check(k, _shown(claimed), "", UNDECIDED, (f"not checked: {res.unchecked[k]}",)))
            continue
        found = res.found.get(k)
        if k not in res.failed:
            checks.append(Check(k, _shown(claimed), _shown(found), AGREES))
        else:
            checks.append(Check(k, _shown(claimed), _shown(found), DISAGREES, _exact_evidence(res, k, claimed)))
    o = res.order
    found_orders: list[tuple[str, str]] = []
    if o is not None:
        found_orders.append(("order", str(o.order)))
        emb = getattr(o, "embedded", None)
        if emb is not None:
            found_orders.append(("embedded_order", str(emb.order)))
        if getattr(o, "stage_order", None) is not None:
            found_orders.append(("stage_order", str(o.stage_order)))
    return tuple(checks), tuple(found_orders)


def _exact_evidence(res: Any, k: str, claimed: Any) -> tuple[str, ...]:
    """The exact residuals behind a refuted claim: the conditions of order p + 1 that fail (order,
    embedded order), the nonzero entries of the symplecticity matrix, or the value found."""
    from ..exact.grammar import format_entry
    found = res.found.get(k)
    residuals: dict = {}
    if k == "order" and isinstance(claimed, int) and isinstance(found, int) and claimed > found:
        residuals = res.next_order
    elif k == "embedded_order" and res.order is not None and getattr(res.order, "embedded", None) is not None:
        residuals = dict(res.order.embedded.residuals) if claimed > found else {}
    if residuals:
        items = list(residuals.items())
        out = [f"order-{found + 1} condition of tree {t}: Φ(t) − 1/γ(t) = {format_entry(v)} (exact)"
               for t, v in items[:EVIDENCE_SHOWN]]
        if len(items) > EVIDENCE_SHOWN:
            out.append(f"… {len(items)} conditions of order {found + 1} fail in all")
        return tuple(out)
    if k == "symplectic" and res.rk_symplectic is not None and claimed:
        M = res.rk_symplectic.M
        bad = [(i, j) for i in range(M.rows) for j in range(M.cols) if M[i, j] != 0 and j >= i]
        return tuple(f"M[{i + 1},{j + 1}] = b{i + 1}a{i + 1},{j + 1} + b{j + 1}a{j + 1},{i + 1} − b{i + 1}b{j + 1} = "
                     f"{format_entry(M[i, j])} (exact)" for i, j in bad[:EVIDENCE_SHOWN])
    return (f"found {_shown(found)} (exact)",)


# ------------------------------------------------------------------ the audit

@dataclass(frozen=True)
class AuditResult(Displayed):
    """Every row, the bad files and the skipped ones; ``seconds`` the wall time of the audit."""
    rows: tuple[Row, ...]
    bad: tuple[Bad, ...] = ()
    skipped: tuple[Skipped, ...] = ()
    seconds: float = field(default=0.0, compare=False)
    workers: int = 1

    @property
    def disagreements(self) -> tuple[Row, ...]:
        return tuple(r for r in self.rows if r.verdict == DISAGREES)

    @property
    def exit_code(self) -> int:
        """3 an internal error in some file (a bug), 2 a bad file, 1 a disagreement, else 0."""
        if any(b.bug for b in self.bad):
            return EXIT_BUG
        if self.bad:
            return EXIT_INPUT
        return EXIT_CLAIM if self.disagreements else EXIT_OK

    def counts(self) -> dict[str, int]:
        out = {v: sum(r.verdict == v for r in self.rows) for v in (AGREES, DISAGREES, UNDECIDED)}
        out.update(bad=len(self.bad), skipped=len(self.skipped), methods=len(self.rows),
                   libraries=len({r.library for r in self.rows}))
        return out

    def summary(self) -> str:
        c = self.counts()
        return (f"audit of {c['methods']} method{'s' * (c['methods'] != 1)} from {c['libraries']} "
                f"librar{'ies' if c['libraries'] != 1 else 'y'}: {c[AGREES]} agree, {c[DISAGREES]} disagree, "
                f"{c[UNDECIDED]} undecided; {c['bad']} bad file{'s' * (c['bad'] != 1)}, {c['skipped']} skipped; "
                f"{self.seconds:.1f} s ({self.workers} worker{'s' * (self.workers != 1)})")

    def to_json(self) -> dict:
        return {"summary": self.summary(), "counts": self.counts(), "seconds": round(self.seconds, 2),
                "rows": [r.to_json() for r in self.rows],
                "bad": [{"file": b.file, "message": b.message, "bug": b.bug} for b in self.bad],
                "skipped": [{"file": s.file, "why": s.why} for s in self.skipped]}

    def _table(self) -> Table:
        rows = tuple(tuple(map(Text, (r.name, r.library, r.kind, r.numbers, str(r.stages), r.claims_text(),
                                      r.found_text(), r.verdict_text(), f"{r.seconds:.2f}")))
                     for r in self.rows)
        return Table(("method", "library", "kind", "numbers", "s", "claimed → found", "found", "verdict", "s (time)"),
                     rows, "lllllllll")

    def with_evidence(self) -> list[tuple[Row, Check]]:
        """Every disagreement, and every undecided claim with a reason, with its row."""
        return [(r, c) for r in self.rows for c in r.checks
                if c.verdict == DISAGREES or (c.verdict == UNDECIDED and c.evidence)]

    def _evidence(self) -> list[Paragraph]:
        out = []
        for r, c in self.with_evidence():
            head = f"{r.name} ({r.file}): {c.prop} claimed {c.claimed}, found {c.found or '?'}: {c.verdict}"
            out.append(Paragraph(Text(head + (": " + "; ".join(c.evidence) if c.evidence else ""))))
        return out

    def display(self) -> Document:
        """The table, every disagreement (and undecided claim) with its evidence, the bad and skipped files."""
        tail = [Paragraph(Text(f"bad file: {b.message}")) for b in self.bad]
        tail += [Paragraph(Text(f"skipped: {s.file}: {s.why}")) for s in self.skipped]
        ev = self._evidence()
        lead = [Paragraph(Text("Decimal files: certified in ball arithmetic, claims hold to the stated precision; "
                               "exact files: the exact analyses."))]
        return Document(self.summary(), (*lead, self._table(), *( [Paragraph(Text("Evidence:"))] if ev else []),
                                         *ev, *tail))


def audit_files(paths, *, seconds: float = AUDIT_SECONDS, workers: int | None = None, scheduler: Any = None,
                progress: bool | None = None) -> AuditResult:
    """The audit of ``paths`` (files and folders, module docstring) on the executor (``scheduler``,
    ``workers`` as :func:`~tableau_lab.experiments.executor.executor`), each method within
    ``seconds``; a progress bar when stderr is a terminal (or as ``progress`` says)."""
    from .executor import executor
    if not seconds or seconds <= 0:
        raise InputError(f"the time budget of one method must be positive, not {seconds!r}")
    start = time.monotonic()
    files, skipped, bad = collect(paths)
    if not files and not bad:
        raise InputError(f"{', '.join(map(str, paths))[:200]}: no tableau file to audit"
                         + (f" ({len(skipped)} JSON file{'s' * (len(skipped) != 1)} skipped: "
                            f"{skipped[0].why})" if skipped else " (folders are searched for *.json)"))
    task = functools.partial(audit_file, seconds=float(seconds))
    workers = workers or min(len(files), os.cpu_count() or 1) or 1
    with executor(scheduler, workers, progress=progress) as ex:
        outcomes = ex.map(task, files, describe=lambda item: item[0], desc="audit")
        used = ex.workers
    rows = [o for o in outcomes if isinstance(o, Row)]
    bad += [o for o in outcomes if isinstance(o, Bad)]
    skipped += [o for o in outcomes if isinstance(o, Skipped)]
    return AuditResult(tuple(rows), tuple(bad), tuple(skipped), time.monotonic() - start, used)


def markdown_report(result: AuditResult) -> str:
    """audit.md: the summary, the table, every disagreement with its evidence (Markdown)."""
    from ..render.markdown import render
    return f"# Audit\n\n{render(result.display())}\n"
