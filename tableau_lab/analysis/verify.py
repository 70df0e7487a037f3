"""Verify a method: run the analyses that apply to its kind and check its claims.

>>> from tableau_lab.exact.tableau_json import loads
>>> m = loads('{"name": "Euler", "kind": "rk", "A": [[0]], "b": [1], "claims": {"symplectic": true}}')
>>> v = verify(m)
>>> v.failed
('symplectic',)
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, overload

import sympy as sp

from ..exact.balls import BallMethod
from ..exact.grammar import format_entry
from ..exact.methods import GeneralLinearMethod, Method
from ..exact.multistep import as_lmm
from ..render.model import Document, Paragraph, Plain, Typeset
from .error_constant import ErrorConstantResult, error_constant
from .glm_order import GLMOrderResult
from .order import order as order_of
from .parasitism import ParasitismResult, growth_parameters
from .prk_order import PRKOrderResult
from .results import Result
from .rk_order import RKOrderResult
from .symplectic import GSymplecticResult, RKSymplecticResult, g_symplectic, rk_symplectic

if TYPE_CHECKING:
    from .certified import CertifiedResult

__all__ = ["verify", "VerifyResult"]

#: claim name -> function of the VerifyResult giving the value found
CHECKS = {
    "symplectic": lambda v: v.rk_symplectic.holds,
    "g_symplectic": lambda v: v.g_symplectic.holds,
    # for RK methods "order" is the classical order (θ ≡ 0), for GLMs the highest achievable
    "order": lambda v: v.order.order,
    "stage_order": lambda v: v.order.stage_order,
    "effective_order": lambda v: v.order.effective_order if v.kind == "rk" else v.order.order,
    "identity_start_order": lambda v: v.order.order_identity_start,
    "parasitism_free": lambda v: v.parasitism.free,
    "embedded_order": lambda v: None if v.order.embedded is None else v.order.embedded.order,
}

@dataclass(frozen=True)
class VerifyResult(Result):
    name: str
    kind: str
    stages: int
    values: int
    parameters: tuple
    g_symplectic: GSymplecticResult | None
    rk_symplectic: RKSymplecticResult | None
    order: RKOrderResult | GLMOrderResult | PRKOrderResult | None
    claims: dict
    found: dict
    failed: tuple
    parasitism: ParasitismResult | None = None
    unchecked: dict = field(default_factory=dict)   # claim -> why it cannot be checked (counted as failed)
    lmm: ErrorConstantResult | None = None          # a linear multistep method: its order and error constant

    @property
    def ok(self) -> bool:
        return not self.failed

    @property
    def next_order(self) -> dict:
        """Φ(t) − 1/γ(t) (or the GLM error term) → for each tree of order p + 1 where it is not
        zero: with free parameters, the order p + 1 holds exactly where all of these vanish."""
        if self.order is None:
            return {}
        return dict(self.order.residuals if isinstance(self.order, RKOrderResult) else self.order.errors)

    @property
    def next_order_never(self) -> bool:
        """True when some condition of order p + 1 is a nonzero constant: no parameter value
        gives order p + 1."""
        return any(not sp.sympify(v).free_symbols for v in self.next_order.values())

    def _parameter_order(self) -> str:
        """The order statement for a tableau with free parameters."""
        o, names = self.order, ", ".join(map(str, self.parameters))
        assert o is not None, "called with an order"
        capped = getattr(o, "capped", False)          # PRK results have no cap flag: errors are empty then
        line = f"  for all values of {names}: order {'at least ' if capped else ''}{o.order}"
        conds = self.next_order
        if not conds:
            return line
        if self.next_order_never:
            lab, v = next((k, v) for k, v in conds.items() if not sp.sympify(v).free_symbols)
            return line + (f"; order {o.order + 1} for no values (the condition of tree {lab} "
                           f"is {format_entry(v)} ≠ 0 whatever the parameters)")
        return line + (f"; order {o.order + 1} exactly where "
                       + ", ".join(f"{k}: {format_entry(v)} = 0" for k, v in conds.items()))

    def display(self) -> Document:
        """Text: the kind, each analysis, the claims; typeset: the symplecticity analyses."""
        kinds = {"rk": "Runge-Kutta", "prk": "partitioned Runge-Kutta", "glm": "general linear method"}
        head = (f"{self.name}: {kinds[self.kind]}, s = {self.stages} stage{'s' * (self.stages != 1)}, "
                f"r = {self.values} value{'s' * (self.values != 1)}")
        if self.parameters:
            head += ", parameters " + ", ".join(map(str, self.parameters))
        symplectic = [r.display() for r in (self.rk_symplectic, self.g_symplectic) if r is not None]
        return Document(head, (Plain(*symplectic, *(Paragraph(x) for x in self._lines())), Typeset(*symplectic)))

    def _lines(self) -> list[str]:
        """The text lines after the symplecticity analyses: order, parasitism, claims."""
        parts: list[str] = []
        if self.order is not None:
            o = self.order
            if isinstance(o, PRKOrderResult):
                parts.append(f"order: {o.order} (bicoloured trees)")
            elif isinstance(o, RKOrderResult):
                parts.append(f"order: classical {o.order}, effective {o.effective_order}, stage order {o.stage_order}; "
                             f"B({o.B}), C({o.C}), D({o.D})")
                if o.consistency:
                    parts.append("  " + o.consistency)
            else:
                parts.append(f"order: {o.order} relative to its starting method ({o.order_identity_start} with θ ≡ 0), "
                             f"stage order {o.stage_order}")
                if self.lmm is not None:
                    parts.append(f"  as a linear multistep method: {self.lmm.line}")
            if self.parameters:
                parts.append(self._parameter_order())
        elif "order" in self.unchecked:
            parts.append(f"order: not computed: {self.unchecked['order']}")
        if self.parasitism is not None:
            parts.append(str(self.parasitism))
        if self.claims:
            marks = [f"{k} = {_show(self.claims[k])} ({self._verdict(k)})" for k in self.claims]
            parts.append("claims: " + "; ".join(marks))
        return parts

    def _verdict(self, k) -> str:
        if k in self.unchecked:
            return f"NOT CHECKED: {self.unchecked[k]}"
        if k in self.failed:
            return f"FAILS: found {_show(self.found[k])}"
        return "holds for generic parameter values" if self.parameters else "holds"

    def to_json(self):
        return {
            "name": self.name, "kind": self.kind, "stages": self.stages, "values": self.values,
            "parameters": [str(p) for p in self.parameters],
            "g_symplectic": None if self.g_symplectic is None else self.g_symplectic.to_json(),
            "rk_symplectic": None if self.rk_symplectic is None else self.rk_symplectic.to_json(),
            "order": None if self.order is None else self._order_json(),
            "parasitism": None if self.parasitism is None else self.parasitism.to_json(),
            "lmm": None if self.lmm is None else self.lmm.to_json(),
            "claims": {"checked": list(self.claims), "failed": list(self.failed),
                       "claimed": dict(self.claims), "found": dict(self.found), "unchecked": dict(self.unchecked)},
        }

    def _order_json(self):
        o = self.order
        assert o is not None, "called with an order"
        full = o.to_json()
        out: dict[str, Any]
        if isinstance(o, PRKOrderResult):
            out = {"order": o.order}
        else:
            out = {"order": o.order, "order_identity_start": o.order_identity_start, "stage_order": o.stage_order}
        if self.kind == "rk":
            out.update({k: full[k] for k in ("effective_order", "B", "C", "D", "residuals", "error_coefficients")})
            out.update({k: full[k] for k in ("starting_method", "finishing_method") if k in full})
        elif self.kind == "glm":
            out.update({k: full[k] for k in ("starting_method", "finishing_method", "u", "w", "error_terms")})
        if self.parameters:
            out["for_all_parameter_values"] = {
                "order": o.order, "capped": bool(getattr(o, "capped", False)),
                "next_order_conditions": {k: str(format_entry(v)) for k, v in self.next_order.items()},
                "next_order_never": self.next_order_never}
        return out


def _ssp_found(m: Method, claimed: Any) -> Any:
    """The exact SSP coefficient (:mod:`ssp`) as found for an exact tableau's claim: the claim as
    written when equal to it (decided in the number field of both), else the value found."""
    from ..exact.field import element, field_of
    from ..exact.grammar import parse_entry
    from .ssp import ssp_coefficient
    R = ssp_coefficient(m).R
    value = parse_entry(claimed if isinstance(claimed, str) else str(claimed))
    if R is None or R == sp.oo:
        return "not computed" if R is None else "oo"
    K = field_of([sp.ImmutableMatrix([R, value])])
    return claimed if K.is_zero(element(K, R - value)) else format_entry(R)


def _show(v):
    return str(v).lower() if isinstance(v, bool) else str(v)


@overload
def verify(m: Method) -> VerifyResult: ...


@overload
def verify(m: BallMethod, **budget: Any) -> CertifiedResult: ...


def verify(m: Method | BallMethod, **budget: Any) -> VerifyResult | CertifiedResult:
    """All applicable analyses of ``m`` and the verdict on each of its claims (``tl.verify``,
    ``m.verify()``, ``tableau-lab verify``): RK/PRK symplecticity (bᵢaᵢⱼ + bⱼaⱼᵢ = bᵢbⱼ, [HLW06]
    Thm VI.4.3), G-symplecticity ([BHHN14]), the order and, for GLMs, the parasitic growth
    parameters; ``failed`` lists the claims of the tableau that do not hold.

    >>> import tableau_lab as tl
    >>> v = tl.verify(tl.load("gauss2"))
    >>> v.failed, v.found["symplectic"]
    ((), True)

    With free parameters every analysis runs over the field of rational functions in them: a
    property holds when it holds identically (for all parameter values where the entries are
    defined), and the order is the order for all values, with the conditions for one more.  A
    claim no analysis can decide is reported as not checked, with the reason, and counts as failed.

    A decimal tableau (a :class:`~tableau_lab.exact.balls.BallMethod`) gets the certified analyses
    in ball arithmetic instead (:func:`~tableau_lab.analysis.certified.certified_verify`, whose
    ``seconds``/``trees`` budget ``budget`` passes on): each property certified, refuted or
    undecided, "to the stated precision" where a ball contains 0; ``failed`` the refuted claims.

    >>> heun = tl.load('{"name": "Heun", "kind": "rk", "numbers": "decimal", "A": [[0, 0], [1, 0]], '
    ...                '"b": ["0.5", "0.5"], "claims": {"order": 3}}')
    >>> r = tl.verify(heun)
    >>> r.failed, r.finding("order").value, r.claims[0].status
    (('order',), 2, 'refuted')
    """
    if isinstance(m, BallMethod):
        from .certified import certified_verify  # the ball analyses only when a decimal tableau needs them
        return certified_verify(m, **budget)
    if budget:
        raise TypeError(f"verify of an exact method takes no budget ({', '.join(budget)}): the exact analyses run "
                        "within the time budget of tableau_lab.budget")
    rk = rk_symplectic(m) if m.kind in ("rk", "prk") else None
    gs = g_symplectic(m) if m.kind in ("rk", "glm") else None
    unchecked = {}
    try:
        order = order_of(m)
    except ValueError as exc:           # e.g. a GLM that is not preconsistent
        order = None
        unchecked.update(dict.fromkeys(("order", "stage_order", "effective_order", "identity_start_order"), str(exc)))
    par = None
    if isinstance(m, GeneralLinearMethod):
        if m.V.free_symbols:
            names = ", ".join(sorted(map(str, m.V.free_symbols)))
            unchecked["parasitism_free"] = (f"V holds the free parameter(s) {names}, so its eigenvalues on the unit "
                                            "circle, and their growth parameters, depend on them")
        else:
            try:
                par = growth_parameters(m)
            except ValueError as exc:   # an eigenvalue of V on the unit circle that is not simple
                unchecked["parasitism_free"] = str(exc)
    partial = VerifyResult(m.name, m.kind, m.s, getattr(m, "r", 1), m.parameters, gs, rk, order, {}, {}, (), par)
    claims = m.claims_dict
    found = {k: CHECKS[k](partial) for k in claims if k not in unchecked and k != "ssp_coefficient"}
    if "ssp_coefficient" in claims:
        found["ssp_coefficient"] = _ssp_found(m, claims["ssp_coefficient"])
    unchecked = {k: v for k, v in unchecked.items() if k in claims}
    failed = tuple(k for k in claims if k in unchecked or found[k] != claims[k])
    lmm = None
    if m.kind == "glm" and as_lmm(m) is not None:
        try:
            lmm = error_constant(m)
        except ValueError:              # not consistent: the order analysis says so
            lmm = None
    return VerifyResult(m.name, m.kind, m.s, getattr(m, "r", 1), m.parameters, gs, rk, order, claims, found, failed,
                        par, unchecked, lmm)
