r"""The verdicts of the certified analyses of a decimal tableau (:mod:`certified`,
:mod:`certified_ssp`): a computed condition with its ball (:class:`Evidence`), a property's finding
(certified / refuted / undecided, :class:`Finding`) and a claim's check (:class:`ClaimCheck`).

>>> import flint
>>> Evidence("Σbᵢ − 1", flint.arb(flint.fmpq(1, 2**30))).text()     # 2⁻³⁰: exact at any precision
'Σbᵢ − 1: residual [9.31323e-10 +/- 4.26e-16]'
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import flint

from ..exact.balls import ball_text, upper_text
from .tree_kinds import TreeKind

__all__ = ["Evidence", "Finding", "ClaimCheck", "CERTIFIED", "REFUTED", "UNDECIDED", "HOLDS", "STATED", "SHOWN",
           "json_value", "shown", "decimal_bound"]

CERTIFIED, REFUTED, UNDECIDED = "certified", "refuted", "undecided"
HOLDS = "holds to the stated precision"
STATED = "to the stated precision"
#: the failing conditions listed per finding (all are counted)
SHOWN = 4


@dataclass(frozen=True)
class Evidence:
    """One computed condition: its name, the ball of its residual (what should be 0) and its tree."""
    condition: str
    ball: flint.arb
    tree: Any = None
    kind: TreeKind | None = None

    @property
    def excludes_zero(self) -> bool:
        return not self.ball.contains(0)

    def text(self) -> str:
        return f"{self.condition}: residual {ball_text(self.ball)}"

    def to_json(self) -> dict:
        return {"condition": self.condition, "tree": None if self.kind is None else self.kind.bracket(self.tree),
                "residual": ball_text(self.ball, 20), "excludes_zero": self.excludes_zero}


@dataclass(frozen=True)
class Finding:
    """One property: ``status`` certified / refuted / undecided, ``statement`` what was found
    (a sentence), ``value`` the order (int) or True/False, ``evidence`` the deciding or failing
    conditions, ``digits`` (undecided) about how many digits would decide, ``largest`` the largest
    |residual| bound of the conditions that vanish to the stated precision."""
    name: str
    status: str
    statement: str
    value: Any = None
    evidence: tuple[Evidence, ...] = ()
    digits: int | None = None
    largest: flint.arb | None = None
    failing: int = 0                 # how many conditions exclude 0 (evidence shows at most SHOWN)

    def line(self) -> str:
        out = f"{self.name}: {self.status.upper()}: {self.statement}"
        if self.largest is not None:
            out += f" (every vanishing residual |r| ≤ {upper_text(self.largest)})"
        if self.digits is not None:
            out += f"; about {self.digits} significant digits would decide it"
        return out

    def to_json(self) -> dict:
        return {"property": self.name, "status": self.status, "statement": self.statement,
                "value": json_value(self.value), "failing": self.failing, "digits_to_decide": self.digits,
                "largest_vanishing_residual": None if self.largest is None else upper_text(self.largest, 3),
                "evidence": [e.to_json() for e in self.evidence]}


@dataclass(frozen=True)
class ClaimCheck:
    """A claim of the file against the findings: ``status`` holds (to the stated precision), refuted
    or undecided, with why."""
    claim: str
    claimed: Any
    status: str
    why: str
    evidence: tuple[Evidence, ...] = ()

    def line(self) -> str:
        word = {REFUTED: "REFUTED", UNDECIDED: "UNDECIDED"}.get(self.status, self.status)
        return f"{self.claim} = {shown(self.claimed)}: {word}" + (f" — {self.why}" if self.why else "")

    def to_json(self) -> dict:
        return {"claim": self.claim, "claimed": shown(self.claimed), "status": self.status, "why": self.why,
                "evidence": [e.to_json() for e in self.evidence]}


def json_value(v: Any) -> Any:
    """An order, a truth value, or the SSP enclosure (lo, hi) of rationals as strings."""
    if isinstance(v, tuple):
        return [None if x is None else str(x) for x in v]
    return v


def shown(v: Any) -> str:
    return str(v).lower() if isinstance(v, bool) else getattr(v, "text", str(v))


def decimal_bound(x: flint.fmpq, places: int, up: bool) -> str:
    """A rational bound as a decimal with ``places`` digits after the point, rounded outwards (up for
    an upper bound): still a bound (the bounds themselves are rationals in a finding's ``value``).

    >>> decimal_bound(flint.fmpq(2, 3), 4, False), decimal_bound(flint.fmpq(2, 3), 4, True)
    ('0.6666', '0.6667')
    """
    scaled = x * 10 ** places
    n = int(-((-scaled).floor()) if up else scaled.floor())
    sign, digits = ("-" if n < 0 else ""), str(abs(n)).rjust(places + 1, "0")
    return f"{sign}{digits[:-places]}.{digits[-places:]}"
