r"""Certified analysis of a decimal tableau in ball arithmetic (python-flint ``arb``; [Joh17]
Johansson, IEEE Trans. Comput. 66 (2017) 1281–1292): every quantity that should vanish is computed
as a ball that contains its value for EVERY tableau within the entries' balls
(:mod:`tableau_lab.exact.balls`), so that

* a ball that excludes 0 is a proof: no tableau within the stated precision satisfies the
  condition (*refuted*, with the condition, its tree and the residual ball: the size of the miss);
* a ball that contains 0 is not: the condition holds only *to the stated precision* (some tableau
  within the balls may satisfy it; none is proven to).

The order is certified at p when every order condition Φ(t) = 1/γ(t) with |t| ≤ p vanishes to
the stated precision and one of order p + 1 excludes 0 ([HNW93] II.2; the elementary weights are
the one recursion, :meth:`~tableau_lab.analysis.tree_kinds.TreeKind.elementary_weights`, over
balls); *undecided* when the precision, the stage bound (2s, or s explicit, [B16] ch. 3) or the
budget leaves it open, with the digits that would decide.  The same for the embedded weights b̂,
the stage order (C(q): Σⱼ aᵢⱼcⱼ^{k−1} = cᵢ^k/k), Σbᵢ − 1, c − A1 and the symplecticity matrix
bᵢaᵢⱼ + bⱼaⱼᵢ − bᵢbⱼ ([HLW06] Thm VI.4.3); partitioned methods by bicoloured trees ([HLW06] III.2.2)
and the PRK symplecticity condition bᵢâᵢⱼ + b̂ⱼaⱼᵢ − bᵢb̂ⱼ (Thm VI.4.6); the SSP coefficient in
:mod:`certified_ssp`.  Nothing here says "exactly": a vanishing condition is exact only after
reconstruction.

>>> import tableau_lab as tl
>>> rk4 = ('{"name": "RK4, 10 digits", "kind": "rk", "numbers": "decimal", "A": [[0, 0, 0, 0], ["0.5", 0, 0, 0],'
...        ' [0, "0.5", 0, 0], [0, 0, 1, 0]], "b": ["0.1666666667", "0.3333333333", "0.3333333333", "0.1666666667"],'
...        ' "claims": {"order": 4}}')
>>> r = tl.verify(tl.load(rk4))
>>> r.finding("order").value, r.finding("order").status, r.failed
(4, 'certified', ())
>>> print(r.finding("order").evidence[0].condition)
order-5 condition of tree [[[[τ]]]]
"""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import flint

from ..budget import CERTIFIED_SECONDS, CERTIFIED_TREES
from ..exact.balls import BallMethod, ball_text
from ..render.model import Document, Math, Paragraph, Plain, Table, Text, Typeset
from .certified_findings import (
    CERTIFIED,
    HOLDS,
    REFUTED,
    SHOWN,
    STATED,
    UNDECIDED,
    ClaimCheck,
    Evidence,
    Finding,
    shown,
)
from .results import Result
from .tree_kinds import BICOLOURED, PLAIN, TreeKind, density

__all__ = ["certified_verify", "CertifiedResult", "Finding", "Evidence", "ClaimCheck", "CERTIFIED", "REFUTED",
           "UNDECIDED", "HOLDS"]

@dataclass(frozen=True)
class CertifiedResult(Result):
    """``tl.verify`` of a decimal tableau: the findings and the claims (module docstring)."""
    name: str
    kind: str
    stages: int
    prec: int
    rounding: str
    least_digits: int
    findings: tuple[Finding, ...]
    claims: tuple[ClaimCheck, ...] = ()
    provenance: tuple = ()
    seconds: float = field(default=0.0, compare=False)

    @property
    def failed(self) -> tuple[str, ...]:
        """The refuted claims (exit 1 of ``tableau-lab verify``)."""
        return tuple(c.claim for c in self.claims if c.status == REFUTED)

    @property
    def undecided(self) -> tuple[str, ...]:
        return tuple(c.claim for c in self.claims if c.status == UNDECIDED)

    @property
    def ok(self) -> bool:
        return not self.failed

    def finding(self, name: str) -> Finding:
        """The finding of the property ``name`` ("order", "stage order", ...)."""
        return next(f for f in self.findings if f.name == name)

    def _head(self) -> str:
        kinds = {"rk": "Runge-Kutta", "prk": "partitioned Runge-Kutta"}
        return (f"{self.name}: {kinds[self.kind]}, s = {self.stages} stage{'s' * (self.stages != 1)}, decimal "
                f"entries as balls ({self.rounding}; the fewest digits: {self.least_digits}), working precision "
                f"{self.prec} bits")

    def _lines(self) -> list[str]:
        out = ["certified in ball arithmetic: a condition whose ball contains 0 holds only to the stated precision; "
               "one whose ball excludes 0 fails for every tableau within it"]
        for f in self.findings:
            out.append("  " + f.line())
            out.extend(f"    {e.text()}" for e in f.evidence)
            if f.failing > len(f.evidence):
                out.append(f"    … {f.failing} conditions exclude 0 in all")
        if self.claims:
            out.append("claims:")
            out.extend("  " + c.line() for c in self.claims)
        if self.provenance:
            out.append("provenance: " + ", ".join(f"{k} {v}" for k, v in self.provenance))
        return out

    def display(self) -> Document:
        """Text: one line per property and per claim, the evidence under each; typeset: two tables."""
        rows = tuple((Text(f.name), Text(f.status), Text(f.statement), _evidence_cell(f.evidence))
                     for f in self.findings)
        claim_rows = tuple((Text(c.claim), Text(shown(c.claimed)), Text(c.status), Text(c.why)) for c in self.claims)
        typeset: list[Paragraph | Table] = [
            Paragraph(self._head() + ". A condition whose ball contains 0 holds only to the stated precision; one "
                      "whose ball excludes 0 fails for every tableau within the balls."),
            Table(("property", "status", "found", "evidence"), rows, "llll")]
        if claim_rows:
            typeset.append(Table(("claim", "claimed", "status", "why"), claim_rows, "llll"))
        return Document(self._head(), (Plain(*(Paragraph(x) for x in self._lines())), Typeset(*typeset)))

    def to_json(self) -> dict:
        return {"numbers": "decimal", "kind": self.kind, "stages": self.stages, "precision_bits": self.prec,
                "rounding": self.rounding, "least_digits": self.least_digits,
                "findings": [f.to_json() for f in self.findings],
                "claims": {"checked": [c.to_json() for c in self.claims], "failed": list(self.failed),
                           "undecided": list(self.undecided)},
                "provenance": dict(self.provenance), "seconds": round(self.seconds, 3)}


def _evidence_cell(evidence: tuple[Evidence, ...]) -> tuple:
    parts: list = []
    for e in evidence[:2]:
        if e.kind is not None:
            parts += [Math(e.kind.tex(e.tree)), Text(f" residual {ball_text(e.ball, 4)}; ")]
        else:
            parts.append(Text(f"{e.condition}: {ball_text(e.ball, 4)}; "))
    return tuple(parts) or (Text(""),)


# ------------------------------------------------------------------ arithmetic

def _zero() -> flint.arb:
    return flint.arb(0)


def _dot(xs: list, ys: list) -> flint.arb:
    return sum((x * y for x, y in zip(xs, ys, strict=True)), _zero())


def _digits_to_decide(ball: flint.arb, digits: int) -> int | None:
    """About how many significant digits would make ``ball`` (containing 0) exclude it, were the
    residual as large as its midpoint and its radius proportional to the entries'; None when the
    midpoint is 0."""
    mid, rad = ball.mid(), ball.rad()
    if mid == 0 or rad == 0:
        return None
    magnitude = ((rad / abs(mid)).log() / flint.arb(10).log()).ceil()      # ⌈log₁₀(radius/|midpoint|)⌉
    exponent = magnitude.unique_fmpz()
    return None if exponent is None else digits + max(1, int(exponent) + 1)


class _Clock:
    """The time and tree budget of one certified analysis."""

    def __init__(self, seconds: float, trees: int) -> None:
        self.end, self.trees, self.seconds, self.max_trees = time.monotonic() + seconds, trees, seconds, trees

    def spend(self) -> str | None:
        """Count one tree; the budget that ran out, or None."""
        self.trees -= 1
        if self.trees < 0:
            return f"the tree budget of {self.max_trees} conditions (CERTIFIED_TREES, budget.py) ran out"
        if time.monotonic() > self.end:
            return f"the time budget of {self.seconds:g} s (CERTIFIED_SECONDS, budget.py) ran out"
        return None


# ------------------------------------------------------------------ order by trees

def _tree_order(name: str, kind: TreeKind, phi: Callable, bound: int, digits: int, clock: _Clock) -> Finding:
    """The order of the weights ``phi`` (t ↦ Φ(t) as a ball): certified p when every condition to p
    vanishes to the stated precision and one of order p + 1 excludes 0 (module docstring)."""
    largest: flint.arb | None = None
    p = 0
    for n in range(1, bound + 2):
        failing: list[Evidence] = []
        count = 0
        closest: Evidence | None = None          # the vanishing residual nearest to deciding (largest |mid|/rad)
        for t in kind.trees_of_order(n):
            stop = clock.spend()
            if stop:
                return Finding(name, UNDECIDED, f"at least {p} {STATED}; order {n} not decided: {stop}", p,
                               largest=largest)
            r = phi(t) - flint.arb(flint.fmpq(1, density(t)))
            ev = Evidence(f"order-{n} condition of tree {kind.bracket(t)}", r, t, kind)
            if ev.excludes_zero:
                count += 1
                if len(failing) < SHOWN:
                    failing.append(ev)
            else:
                largest = r.abs_upper() if largest is None else largest.max(r.abs_upper())
                if closest is None or abs(r.mid()) * closest.ball.rad() > abs(closest.ball.mid()) * r.rad():
                    closest = ev
        if count:
            upto = f"every condition to order {p} vanishes {STATED}; " if p else ""
            return Finding(name, CERTIFIED, f"{p} ({upto}{count} of order {n} exclude{'s' * (count == 1)} 0)", p,
                           tuple(failing), None, largest, count)
        p = n
    assert closest is not None, "the last order has trees"
    return Finding(name, UNDECIDED, f"at least {bound} {STATED}, yet every condition of order {bound + 1} contains 0 "
                                    "though one must fail (no method of this size has that order): too few digits",
                   bound, (closest,), _digits_to_decide(closest.ball, digits), largest)


# ------------------------------------------------------------------ the single conditions

def _vanishing(name: str, conditions: list[Evidence], holds: str, fails: str) -> Finding:
    """A property made of conditions that should all vanish: certified (to the stated precision) when
    every ball contains 0, refuted (with the failing ones) otherwise."""
    bad = [e for e in conditions if e.excludes_zero]
    if bad:
        return Finding(name, REFUTED, fails, False, tuple(bad[:SHOWN]), failing=len(bad))
    largest = None
    for e in conditions:
        largest = e.ball.abs_upper() if largest is None else largest.max(e.ball.abs_upper())
    return Finding(name, CERTIFIED, f"{holds} {STATED}", True, largest=largest)


def _consistency(b: list, hat: str = "") -> Finding:
    r = sum(b, _zero()) - 1
    return _vanishing(f"Σb{hat}ᵢ = 1", [Evidence(f"Σb{hat}ᵢ − 1", r)], f"Σb{hat}ᵢ = 1", f"Σb{hat}ᵢ ≠ 1")


def _nodes(m: BallMethod, key: str = "c", matrix: str = "A") -> Finding | None:
    """c − A1, when the file gives c (else c is A1 by definition)."""
    if getattr(m, key) is None:
        return None
    A, c = m.balls(matrix), m.balls(key)
    conds = [Evidence(f"{key}[{i + 1}] − ({matrix}1)[{i + 1}]", c[i] - sum(A[i], _zero())) for i in range(m.s)]
    return _vanishing(f"{key} = {matrix}1", conds, f"{key} = {matrix}·1", f"{key} ≠ {matrix}·1")


def _symplectic(m: BallMethod) -> Finding:
    """bᵢaᵢⱼ + bⱼaⱼᵢ − bᵢbⱼ (RK) or bᵢâᵢⱼ + b̂ⱼaⱼᵢ − bᵢb̂ⱼ (PRK, with bᵢ = b̂ᵢ) for all i, j ([HLW06] VI.4):
    all vanishing, symplectic to the stated precision; one excluding 0, certified not symplectic."""
    A, b = m.balls("A"), m.balls("b")
    if m.kind == "rk":
        Ah, bh, pairs = A, b, [(i, j) for i in range(m.s) for j in range(i, m.s)]
        form = "b{i}·a{i},{j} + b{j}·a{j},{i} − b{i}·b{j}"
    else:
        Ah, bh, pairs = m.balls("Ahat"), m.balls("bhat"), [(i, j) for i in range(m.s) for j in range(m.s)]
        form = "b{i}·â{i},{j} + b̂{j}·a{j},{i} − b{i}·b̂{j}"
    conds = [Evidence(form.format(i=i + 1, j=j + 1), b[i] * Ah[i][j] + bh[j] * A[j][i] - b[i] * bh[j])
             for i, j in pairs]
    if m.kind == "prk":
        conds += [Evidence(f"b{i + 1} − b̂{i + 1}", b[i] - bh[i]) for i in range(m.s)]
    found = _vanishing("symplectic", conds, "symplectic", "not symplectic")
    if found.status == REFUTED:       # not symplectic is a certified answer, not a failed condition
        return Finding("symplectic", CERTIFIED, "not symplectic", False, found.evidence, failing=found.failing)
    return found


def _stage_order(m: BallMethod, order: Finding, digits: int) -> Finding:
    """The largest q with C(1), …, C(q) vanishing (Σⱼ aᵢⱼcⱼ^{k−1} = cᵢ^k/k), capped by the order, as
    ``rk_order`` does; certified when C(q + 1) excludes 0 or the order caps it."""
    A, c = m.balls("A"), m.balls("c")
    q, failing = 0, []
    for k in range(1, m.s + 2):
        ck = [x ** (k - 1) for x in c]
        conds = [Evidence(f"C({k}) at stage {i + 1}", _dot(A[i], ck) - c[i] ** k / k) for i in range(m.s)]
        failing = [e for e in conds if e.excludes_zero]
        if failing:
            break
        q = k
    p = order.value if isinstance(order.value, int) else 0
    if failing and q <= p and (order.status == CERTIFIED or q < p):
        held = f"C({q}) {STATED}; " if q else ""
        return Finding("stage order", CERTIFIED, f"{q} ({held}C({q + 1}) fails)", q,
                       tuple(failing[:SHOWN]), failing=len(failing))
    if order.status == CERTIFIED and p <= q:
        return Finding("stage order", CERTIFIED, f"{p} (C({q}) {STATED}, and the order is {p})", p)
    return Finding("stage order", UNDECIDED, f"at least {min(p, q)} {STATED}", min(p, q))


# ------------------------------------------------------------------ claims

def _order_claim(claim: str, claimed: int, f: Finding) -> ClaimCheck:
    p = f.value
    if f.status == CERTIFIED and claimed == p:
        return ClaimCheck(claim, claimed, HOLDS, "")
    if f.status == CERTIFIED and claimed > p:
        miss = f.evidence[0].text() if f.evidence else f"a condition of order {p + 1} fails"
        return ClaimCheck(claim, claimed, REFUTED, f"the {f.name} is {p}: the {miss}", f.evidence[:1])
    if claimed < p or f.status != CERTIFIED:
        return ClaimCheck(claim, claimed, UNDECIDED,
                          f"the conditions of order {claimed + 1} vanish {STATED} ({f.name} found: {f.statement}); "
                          "more digits, or the exact tableau, decide" if claimed < p else f"{f.name} found: "
                          + f.statement)
    return ClaimCheck(claim, claimed, UNDECIDED, f.statement)    # pragma: no cover - the cases above are all


def _claim(name: str, claimed: Any, findings: dict[str, Finding]) -> ClaimCheck:
    """One claim against the findings."""
    orders = {"order": "order", "embedded_order": "embedded order", "stage_order": "stage order"}
    if name in orders and orders[name] in findings:
        return _order_claim(name, claimed, findings[orders[name]])
    if name == "symplectic":
        f = findings["symplectic"]
        if f.value is claimed:
            return ClaimCheck(name, claimed, HOLDS if claimed else "holds", "")
        if claimed:
            return ClaimCheck(name, claimed, REFUTED, "a symplecticity condition excludes 0", f.evidence[:1])
        return ClaimCheck(name, claimed, UNDECIDED, f"the symplecticity conditions vanish {STATED}")
    if name == "ssp_coefficient" and "SSP coefficient" in findings:
        from .certified_ssp import ssp_claim
        return ssp_claim(claimed, findings["SSP coefficient"])
    return ClaimCheck(name, claimed, UNDECIDED, "not analysed in ball arithmetic (only the exact analyses check it)")


# ------------------------------------------------------------------ the analysis

def _weights(m: BallMethod, b_key: str = "b") -> tuple[TreeKind, Callable]:
    if m.kind == "rk":
        return PLAIN, PLAIN.elementary_weights(m.balls("A"), m.balls(b_key), _zero(), flint.arb(1))
    return BICOLOURED, BICOLOURED.elementary_weights((m.balls("A"), m.balls("Ahat")), (m.balls("b"), m.balls("bhat")),
                                                     _zero(), flint.arb(1))


def certified_verify(m: BallMethod, seconds: float = CERTIFIED_SECONDS, trees: int = CERTIFIED_TREES,
                     ssp: bool = True) -> CertifiedResult:
    """Every certified analysis of a decimal tableau and the verdict on each claim (module
    docstring); ``seconds`` and ``trees`` the budget of the order conditions (beyond: undecided,
    saying so); ``ssp``: the SSP coefficient of an RK method (:mod:`certified_ssp`)."""
    start = time.monotonic()
    clock = _Clock(seconds, trees)
    digits = m.least_digits or 30
    findings: list[Finding] = []
    with flint.ctx.workprec(m.prec):
        findings.append(_consistency(m.balls("b")))
        if m.kind == "prk":
            findings.append(_consistency(m.balls("bhat"), "\u0302"))
        for key, matrix in (("c", "A"), ("chat", "Ahat")):
            f = _nodes(m, key, matrix)
            if f is not None:
                findings.append(f)
        kind, phi = _weights(m)
        order = _tree_order("order", kind, phi, m.order_bound, digits, clock)
        findings.append(order)
        if m.kind == "rk":
            findings.append(_stage_order(m, order, digits))
            if m.bhat is not None:
                findings.append(_tree_order("embedded order", PLAIN, _weights(m, "bhat")[1], m.order_bound, digits,
                                            clock))
        findings.append(_symplectic(m))
        if ssp and m.kind == "rk":
            from .certified_ssp import certified_ssp
            from .certified_stability import real_interval
            findings.append(certified_ssp(m, max(0.0, clock.end - time.monotonic())))
            findings.append(real_interval(m, max(0.0, clock.end - time.monotonic())))
    by_name = {f.name: f for f in findings}
    claims = tuple(_claim(k, v, by_name) for k, v in m.claims)
    return CertifiedResult(m.name, m.kind, m.s, m.prec, m.rounding.describe(), m.least_digits, tuple(findings),
                           claims, m.provenance, time.monotonic() - start)
