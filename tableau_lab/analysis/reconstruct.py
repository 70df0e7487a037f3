r"""Exact tableaux from decimal ones: every entry recognised, the candidate proven by the exact analyses.

A tableau known only in decimals (its entries python-flint ``arb`` balls, as the decimal reader
gives them, or exact values where the file is exact) is reconstructed entry by entry
(:func:`~tableau_lab.exact.recognise.recognise`: the simplest rational of the ball, then algebraic
numbers of degree ≤ 4 by an integer relation found by LLL), and then jointly: the number fields
Q(θ) that the recognised entries show (√3 in Gauss 2, SDIRK34's cubic γ) are tried for every
non-rational entry (:func:`~tableau_lab.exact.recognise.recognise_in`), then the field they make
together (:func:`~tableau_lab.exact.recognise.joint_basis`: Gauss 4's entries, of degree 8).  A relation in the right
field has fewer numbers and smaller coefficients than the entry's own minimal polynomial, so it
needs fewer digits, and the whole tableau lands in one field, where the exact analyses are fast.

The candidate is an ordinary exact tableau (entries in the grammar); it is read by the exact reader
(``tableau_json.from_dict``) and verified (``analysis/verify.py``: order, stage order, symplecticity,
and the order of the embedded method).  What is *proven* is proven about the candidate, exactly;
that the candidate is the method the decimals came from is as sure as the weakest entry's margin
(``Recognition.strong``), which the report states entry by entry.

>>> import flint
>>> with flint.ctx.workprec(128):
...     third = flint.arb("[0.33333333333333333333 +/- 5e-21]")
...     sixth = flint.arb("[0.16666666666666666667 +/- 5e-21]")
>>> r = reconstruct_tableau({"name": "Heun 3", "kind": "rk", "A": [[0, 0, 0], [third, 0, 0], [0, "2/3", 0]],
...                          "b": ["1/4", 0, "3/4"], "claims": {"order": 3}})
>>> r.tableau["A"][1][0], r.verified.order.order, r.verified.failed, r.complete
('1/3', 3, (), True)
"""
from __future__ import annotations

import os
import time
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import flint
import sympy as sp

from ..budget import computing, time_limit
from ..exact.balls import BallMethod, is_decimal
from ..exact.grammar import EntryError, format_entry, parse_entry
from ..exact.methods import Method
from ..exact.recognise import (
    LIMIT_OPTION,
    LIMITS,
    Basis,
    Limits,
    Recognition,
    field_degree,
    field_text,
    generator,
    joint_basis,
    limits_with,
    recognise,
    recognise_in,
    recognise_in_basis,
)
from ..exact.render import entry_latex
from ..exact.tableau_json import CLAIMS, DECIMAL_KEYS, KINDS, MAX_SIZE, META, TableauError, entry_name, from_dict
from ..render.model import Document, Math, Paragraph, Table
from .order import order as order_of
from .results import Result
from .verify import VerifyResult, verify

__all__ = ["reconstruct_tableau", "reconstruct", "ball_tableau", "ReconstructResult", "EntryReport"]



@dataclass(frozen=True)
class EntryReport:
    """One entry: its one-based ``name``, the ball it was given as (text; None: given exactly) and
    what was recognised (None: given exactly)."""
    name: str
    given: str | None
    recognition: Recognition | None
    value: sp.Expr | None

    def line(self) -> str:
        if self.recognition is None:
            return f"{self.name}: given exactly, {format_entry(self.value)}"
        return f"{self.name} = {self.given}: {self.recognition.verdict()}"


@dataclass(frozen=True, eq=False)
class ReconstructResult(Result):
    """The candidate exact tableau (``tableau``: a dict in the file format; None when an entry was
    not recognised), the report of each entry, the fields used, and what the exact analyses prove
    about the candidate (``verified``; ``embedded_order`` of an embedded pair's b̂), or why they
    could not run (``refused``)."""
    name: str
    tableau: dict | None
    entries: tuple[EntryReport, ...]
    fields: tuple[sp.Expr, ...]
    verified: VerifyResult | None
    embedded_order: int | None
    refused: str | None
    dropped: tuple[str, ...]
    limits: Limits
    seconds: float
    embedded_claim: int | None = None       # the claim "embedded_order" (checked here: the exact reader has none)
    method: Method | None = None            # the candidate as a method object (None: no valid candidate)

    @property
    def recognised(self) -> tuple[EntryReport, ...]:
        return tuple(e for e in self.entries if e.recognition is not None)

    @property
    def weak(self) -> tuple[EntryReport, ...]:
        return tuple(e for e in self.recognised if e.recognition is not None and e.recognition.weak)

    @property
    def missing(self) -> tuple[EntryReport, ...]:
        return tuple(e for e in self.recognised if e.recognition is not None and e.recognition.value is None)

    @property
    def complete(self) -> bool:
        """Every entry recognised strongly and the candidate read by the exact reader."""
        return self.tableau is not None and not self.weak and self.refused is None

    def summary(self) -> str:
        n, rec = len(self.entries), self.recognised
        kinds: dict[str, int] = {}
        for e in rec:
            assert e.recognition is not None
            kinds[e.recognition.kind] = kinds.get(e.recognition.kind, 0) + 1
        counts = ", ".join(f"{v} {k}" for k, v in sorted(kinds.items()))
        fields = "; fields " + ", ".join(field_text((t,)) for t in self.fields) if self.fields else ""
        return (f"{len(rec)} of {n} entries given as balls ({counts}): {len(self.weak)} weak, "
                f"{len(self.missing)} not recognised{fields}; {self.seconds:.2f} s")

    def proven(self) -> str:
        """What the exact analyses prove about the candidate, in one sentence."""
        if self.tableau is None:
            return "no candidate tableau: " + ", ".join(e.name for e in self.missing) + " not recognised"
        sure = "" if not self.weak else (f" ({len(self.weak)} weak entr{'ies' if len(self.weak) > 1 else 'y'}: "
                                         "the decimals may be another method)")
        if self.refused is not None:
            return f"the candidate is not a valid tableau: {self.refused}{sure}"
        v = self.verified
        assert v is not None
        parts = []
        if v.order is not None:
            parts.append(f"order {v.order.order}")
            if hasattr(v.order, "stage_order"):
                parts.append(f"stage order {v.order.stage_order}")
        if self.embedded_order is not None:
            parts.append(f"embedded order {self.embedded_order}")
        if v.rk_symplectic is not None:
            parts.append("symplectic" if v.rk_symplectic.holds else "not symplectic")
        verdicts = [f"{k} = {v.claims[k]} ({'FAILS' if k in v.failed else 'holds'})" for k in v.claims]
        if self.embedded_claim is not None and "embedded_order" not in v.claims:
            holds = self.embedded_claim == self.embedded_order
            verdicts.append(f"embedded_order = {self.embedded_claim} ({'holds' if holds else 'FAILS'})")
        claims = "; claims " + ", ".join(verdicts) if verdicts else ""
        return "exactly, the candidate has " + ", ".join(parts) + claims + sure

    def display(self) -> Document:
        rows = tuple((e.name, e.given or "exact",
                      Math(entry_latex(e.value), str(format_entry(e.value))) if e.value is not None else "—",
                      _kind(e), _strength(e)) for e in self.entries)
        blocks: list[Any] = [Paragraph(self.summary()),
                             Table(("entry", "given", "exact", "kind, height, digits given/needed", "verdict"), rows,
                                   "lllll"),
                             Paragraph(self.proven())]
        if self.dropped:
            blocks.append(Paragraph("not checked by the exact analyses here: " + ", ".join(self.dropped)))
        return Document(f"Reconstruction of {self.name}", tuple(blocks))

    def to_json(self) -> dict:
        return {
            "name": self.name, "tableau": self.tableau, "complete": self.complete,
            "entries": [{"entry": e.name, "given": e.given,
                         "value": None if e.value is None else str(format_entry(e.value)),
                         **({} if e.recognition is None else {
                             "kind": e.recognition.kind, "height": e.recognition.height,
                             "digits": _finite(e.recognition.digits), "needed": _finite(e.recognition.needed),
                             "weak": e.recognition.weak,
                             "field": [str(format_entry(t)) for t in e.recognition.field]})}
                        for e in self.entries],
            "fields": [str(format_entry(t)) for t in self.fields],
            "verified": None if self.verified is None else self.verified.to_json(),
            "embedded_order": self.embedded_order, "embedded_order_claimed": self.embedded_claim,
            "refused": self.refused, "not_checked": list(self.dropped),
            "proven": self.proven(), "limits": dict(vars(self.limits)), "seconds": round(self.seconds, 3)}


def _finite(x: float) -> float | None:
    return None if x == float("inf") else round(x, 2)


def _kind(e: EntryReport) -> str:
    r = e.recognition
    if r is None:
        return "exact"
    if r.value is None:
        return "none"
    return f"{r.kind}{r.where}, {r.height}, {r.digits:.1f}/{r.needed:.1f}"


def _strength(e: EntryReport) -> str:
    r = e.recognition
    if r is None:
        return "given"
    return "not recognised" if r.value is None else ("recognised" if r.strong else "WEAK")


# ------------------------------------------------------------------ the entries of a tableau

def _positions(data: dict) -> list[tuple[tuple[str | int, ...], Any]]:
    """(JSON path, value) of every coefficient of the tableau dict, in file order."""
    kind = data.get("kind")
    if not isinstance(kind, str) or kind not in KINDS:
        raise TableauError("<reconstruction>", f"unknown or missing kind {kind!r}: use one of {', '.join(KINDS)}",
                           "kind")
    _, required, optional = KINDS[kind]
    out: list[tuple[tuple[str | int, ...], Any]] = []
    for key, shape in list(required.items()) + list(optional.items()):
        value = data.get(key)
        if value is None:
            continue
        if not isinstance(value, list):
            raise TableauError("<reconstruction>", f"{key} must be a list", key)
        for i, row in enumerate(value):
            if shape == "matrix":
                if not isinstance(row, list):
                    raise TableauError("<reconstruction>", f"row {i + 1} of {key} is not a list", f"{key} row {i + 1}")
                out.extend(((key, i, j), x) for j, x in enumerate(row))
            else:
                out.append(((key, i), row))
    return out


def _exact(value: Any, where: str) -> sp.Expr:
    """An entry given exactly: an int, a grammar string or a sympy number (checked by the grammar);
    a decimal is refused with the way to give it as a ball."""
    try:
        return parse_entry(str(format_entry(value)) if isinstance(value, sp.Basic) else value)
    except EntryError as exc:
        hint = ""
        if isinstance(value, float) or is_decimal(value):
            hint = ('; an entry known in decimals is given as a python-flint ball, e.g. flint.arb("[0.5 +/- 5e-2]") '
                    '(read at enough precision: with flint.ctx.workprec(bits))')
        raise TableauError("<reconstruction>", str(exc) + hint, where) from None


def _best(ball: Any, alone: Recognition, fields: list[sp.Expr], joint: _Joint, limits: Limits) -> Recognition:
    """The first strong recognition of the ball in the tableau's fields, in order, then in the field
    they generate together, else ``alone``."""
    if alone.strong and alone.value is not None and alone.value.is_Rational:
        return alone
    for theta in fields:
        r = recognise_in(ball, theta, limits)
        if r.strong:
            return r
    basis = joint.basis
    if basis is not None:
        r = recognise_in_basis(ball, basis, limits)
        if r.strong:
            return r
    return alone


class _Joint:
    """The basis of the field all the tableau's generators make together, computed when first
    asked (None: one generator, or a field of degree above ``limits.basis``)."""

    def __init__(self, fields: list[sp.Expr], limits: Limits):
        self.fields, self.limits = fields, limits

    @cached_property
    def basis(self) -> Basis | None:
        if len(self.fields) < 2:
            return None
        with computing("the field of the tableau's generators"):
            b = joint_basis(tuple(self.fields), self.limits)
        return b if b is not None and len(b.elements) > max(map(field_degree, self.fields)) else None


def _fields(found: list[Recognition], limits: Limits) -> list[sp.Expr]:
    """The generators that strong non-rational recognitions show, fewest digits first (then lowest
    degree), at most ``limits.fields``, one per minimal polynomial."""
    seen: dict[str, tuple[float, int, sp.Expr]] = {}
    for r in found:
        theta = generator(r) if r.strong else None
        if theta is not None:
            key = str(format_entry(theta))
            seen.setdefault(key, (r.needed, field_degree(theta), theta))
    ordered = sorted(seen.values(), key=lambda t: (t[1], t[0]))
    return [t[2] for t in ordered[:limits.fields]]


def _recognise_all(data: dict, limits: Limits) -> tuple[list[EntryReport], list[sp.Expr]]:
    positions = _positions(data)
    alone: dict[int, Recognition] = {}
    for k, (path, value) in enumerate(positions):
        if isinstance(value, flint.arb):
            if not value.is_finite():
                raise TableauError("<reconstruction>", f"the ball {value} is not finite", entry_name(path))
            with computing(f"recognising {entry_name(path)}"):
                alone[k] = recognise(value, limits)
    fields = _fields(list(alone.values()), limits)
    joint = _Joint(fields, limits)
    reports = []
    for k, (path, value) in enumerate(positions):
        name = entry_name(path)
        if k not in alone:
            reports.append(EntryReport(name, None, None, _exact(value, name)))
            continue
        with computing(f"recognising {name} in the tableau's fields"):
            r = _best(value, alone[k], fields, joint, limits)
        reports.append(EntryReport(name, _ball_text(value, r.digits), r, r.value))
    used = {t for e in reports if e.recognition is not None for t in e.recognition.field}
    return reports, [t for t in fields if t in used]


def _ball_text(x: Any, digits: float) -> str:
    """The ball as text, to the digits it states (python-flint prints 15 by default)."""
    n = 60 if digits == float("inf") else max(3, min(60, int(digits) + 2))
    return str(x.str(n, radius=True))              # arb prints from its own bits: no working precision needed


def _candidate(data: dict, reports: list[EntryReport]) -> tuple[dict, tuple[str, ...]]:
    """The exact tableau dict (entries in the grammar) and what of the input it cannot carry."""
    values = iter(str(format_entry(e.value)) for e in reports)
    out: dict[str, Any] = {k: v for k, v in data.items() if k in META and k != "claims" and k not in DECIMAL_KEYS}
    dropped = [k for k in data if k not in META and k not in DECIMAL_KEYS
               and k not in KINDS[data["kind"]][1] and k not in KINDS[data["kind"]][2]]
    for path, _ in _positions(data):
        key = str(path[0])
        if len(path) == 3:
            rows = out.setdefault(key, [])
            if int(path[2]) == 0:
                rows.append([])
            rows[-1].append(next(values))
        else:
            out.setdefault(key, []).append(next(values))
    claims = data.get("claims") or {}
    known = {k: v for k, v in claims.items() if k in CLAIMS}
    if known:
        out["claims"] = known
    dropped += [f"claims.{k}" for k in claims if k not in CLAIMS]
    return out, tuple(dropped)


def reconstruct_tableau(data: dict, limits: Limits = LIMITS, **changes: Any) -> ReconstructResult:
    """Reconstruct the tableau dict ``data`` (the file format: kind, A, b, c, bhat, …, each entry a
    python-flint ``arb`` ball or an exact value) and verify the exact candidate.  ``changes``
    override :class:`~tableau_lab.exact.recognise.Limits` (``degree``, ``height``, ``margin``,
    ``digits``, ``seconds``, ``fields``); the time budget ``seconds`` covers the whole (a
    ``BudgetError`` names what was being computed when it ran out).  See the module's example."""
    limits = limits_with(**{**vars(limits), **changes}) if changes else limits
    if not isinstance(data, dict):
        raise TableauError("<reconstruction>", "a tableau is a dict such as {\"kind\": \"rk\", \"A\": ..., \"b\": ...}")
    name = str(data.get("name", "the tableau"))
    start = time.perf_counter()
    for key in KINDS[str(data.get("kind"))][1] if data.get("kind") in KINDS else ():
        if isinstance(data.get(key), list) and len(data[key]) > MAX_SIZE:
            raise TableauError("<reconstruction>", f"{len(data[key])} rows: beyond the size budget MAX_SIZE = "
                                                   f"{MAX_SIZE} of the exact analyses (tableau_json.py)", key)
    with time_limit(limits.seconds, LIMIT_OPTION), computing(f"reconstruction of {name}"):
        reports, fields = _recognise_all(data, limits)
        if any(e.value is None for e in reports):
            return ReconstructResult(name, None, tuple(reports), tuple(fields), None, None, None, (), limits,
                                     time.perf_counter() - start)
        candidate, dropped = _candidate(data, reports)
        verified, embedded, refused, method = None, None, None, None
        try:
            method = from_dict(candidate, f"reconstruction of {name}")
        except TableauError as exc:
            refused = str(exc)
        else:
            verified = verify(method)
            emb = method.embedded() if hasattr(method, "embedded") else None
            embedded = None if emb is None else int(order_of(emb).order)
    claim = (data.get("claims") or {}).get("embedded_order")
    return ReconstructResult(name, candidate, tuple(reports), tuple(fields), verified, embedded, refused, dropped,
                             limits, time.perf_counter() - start, claim if isinstance(claim, int) else None, method)


def ball_tableau(m: BallMethod) -> dict:
    """A decimal tableau (:class:`~tableau_lab.exact.balls.BallMethod`, ``tl.load`` of a
    ``"numbers": "decimal"`` file) as :func:`reconstruct_tableau`'s dict: each decimal entry its
    ball, each exact entry its exact value; name, source, notes, claims and provenance kept."""
    out: dict[str, Any] = {"name": m.name, "kind": m.kind}
    def one(e, x):
        return str(format_entry(e.exact)) if e.exact is not None else x
    _, required, optional = KINDS[m.kind]
    for key, shape in {**required, **optional}.items():
        entries, balls = getattr(m, key), m.balls(key)
        if entries is None:
            continue
        if shape == "matrix":
            out[key] = [[one(e, x) for e, x in zip(row, xs, strict=True)]
                        for row, xs in zip(entries, balls, strict=True)]
        else:
            out[key] = [one(e, x) for e, x in zip(entries, balls, strict=True)]
    out.update({k: v for k, v in (("source", m.source), ("notes", list(m.notes)), ("claims", dict(m.claims)),
                                  ("provenance", dict(m.provenance))) if v})
    return out


def reconstruct(data: dict | BallMethod | str | os.PathLike, **limits: Any) -> ReconstructResult:
    """``tl.reconstruct``: the exact tableau behind a decimal one (entries as python-flint ``arb``
    balls), recognised entry by entry and in the fields the entries share, and what the exact
    analyses prove about it (``r.method``: the exact candidate as a method object, for
    ``tl.save(r.method, path)``).  Keywords: the limits (``degree=4``, ``height=10**30``,
    ``margin=5`` digits, ``digits=200``, ``seconds=60``, ``fields=3``, ``basis=16``).  How it works,
    what "weak" means and the references (LLL, Ferguson–Bailey PSLQ, Bailey's integer relation
    detection): docs/reconstruction.md.

    >>> import flint, tableau_lab as tl
    >>> with flint.ctx.workprec(128):
    ...     a = flint.arb("[0.21132486540518711775 +/- 5e-21]")     # 1/2 − √3/6
    ...     b = flint.arb("[0.78867513459481288225 +/- 5e-21]")     # 1/2 + √3/6
    ...     a12, a21 = a - flint.arb("0.25"), b - flint.arb("0.25")
    >>> r = tl.reconstruct({"name": "Gauss 2", "kind": "rk", "b": ["1/2", "1/2"], "c": [a, b],
    ...                     "A": [["1/4", a12], [a21, "1/4"]]})
    >>> r.tableau["c"], int(r.verified.order.order), r.verified.rk_symplectic.holds
    (['1/2 - sqrt(3)/6', 'sqrt(3)/6 + 1/2'], 4, True)
    >>> r.method.A == tl.load("gauss2").A
    True
    """
    if isinstance(data, (str, os.PathLike)):
        from ..exact.tableau_json import load_any
        loaded = load_any(data)
        if not isinstance(loaded, BallMethod):
            raise TableauError(str(data), 'the tableau is exact already: reconstruction reads a decimal one '
                               '("numbers": "decimal")')
        data = loaded
    return reconstruct_tableau(ball_tableau(data) if isinstance(data, BallMethod) else data, **limits)
