"""Verify a method: run the analyses that apply to its kind and check its claims.

>>> from tableau_lab.exact.tableau_json import loads
>>> m = loads('{"name": "Euler", "kind": "rk", "A": [[0]], "b": [1], "claims": {"symplectic": true}}')
>>> v = verify(m)
>>> v.failed
('symplectic',)
"""
from __future__ import annotations

from dataclasses import dataclass

from ..exact.methods import Method
from .results import Result
from .glm_order import GLMOrderResult
from .order import order as order_of
from .parasitism import ParasitismResult, growth_parameters
from .prk_order import PRKOrderResult
from .rk_order import RKOrderResult
from .symplectic import GSymplecticResult, RKSymplecticResult, g_symplectic, rk_symplectic

__all__ = ["verify", "VerifyResult"]

#: claim name -> function of the VerifyResult giving the value found
CHECKS = {
    "symplectic": lambda v: v.rk_symplectic.holds,
    "g_symplectic": lambda v: v.g_symplectic.holds,
    # for RK methods "order" is the classical order (θ ≡ 0), for GLMs the highest achievable
    "order": lambda v: v.order.order,
    "stage_order": lambda v: v.order.stage_order,
    "effective_order": lambda v: v.order.effective_order if v.kind == "rk" else v.order.order,
    "parasitism_free": lambda v: v.parasitism.free,
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

    @property
    def ok(self) -> bool:
        return not self.failed

    def __str__(self):
        kinds = {"rk": "Runge-Kutta", "prk": "partitioned Runge-Kutta", "glm": "general linear method"}
        head = (f"{self.name}: {kinds[self.kind]}, s = {self.stages} stage{'s' * (self.stages != 1)}, "
                f"r = {self.values} value{'s' * (self.values != 1)}")
        if self.parameters:
            head += ", parameters " + ", ".join(map(str, self.parameters))
        parts = [head]
        if self.rk_symplectic is not None:
            parts.append(str(self.rk_symplectic))
        if self.g_symplectic is not None:
            parts.append(str(self.g_symplectic))
        if self.order is not None:
            o = self.order
            if self.kind == "prk":
                parts.append(f"order: {o.order} (bicoloured trees)")
            elif self.kind == "rk":
                parts.append(f"order: classical {o.order}, effective {o.effective_order}, stage order {o.stage_order}; "
                             f"B({o.B}), C({o.C}), D({o.D})")
            else:
                parts.append(f"order: {o.order} relative to its starting method ({o.order_identity_start} with θ ≡ 0), "
                             f"stage order {o.stage_order}")
        if self.parasitism is not None:
            parts.append(str(self.parasitism))
        if self.claims:
            marks = [f"{k} = {_show(self.claims[k])} ({'holds' if k not in self.failed else f'FAILS: found {_show(self.found[k])}'})"
                     for k in self.claims]
            parts.append("claims: " + "; ".join(marks))
        return "\n".join(parts)

    def to_json(self):
        return {
            "name": self.name, "kind": self.kind, "stages": self.stages, "values": self.values,
            "parameters": [str(p) for p in self.parameters],
            "g_symplectic": None if self.g_symplectic is None else self.g_symplectic.to_json(),
            "rk_symplectic": None if self.rk_symplectic is None else self.rk_symplectic.to_json(),
            "order": None if self.order is None else self._order_json(),
            "parasitism": None if self.parasitism is None else self.parasitism.to_json(),
            "claims": {"checked": list(self.claims), "failed": list(self.failed),
                       "claimed": dict(self.claims), "found": dict(self.found)},
        }

    def _order_json(self):
        o = self.order
        if self.kind == "prk":
            return {"order": o.order}
        full = o.to_json()
        out = {"order": o.order, "order_identity_start": o.order_identity_start, "stage_order": o.stage_order}
        if self.kind == "rk":
            out.update({k: full[k] for k in ("effective_order", "B", "C", "D", "error_coefficients")})
            out.update({k: full[k] for k in ("starting_method", "finishing_method") if k in full})
        else:
            out.update({k: full[k] for k in ("starting_method", "finishing_method", "u", "w", "error_terms")})
        return out

    def to_latex(self):
        parts = []
        if self.rk_symplectic is not None:
            parts.append(self.rk_symplectic.to_latex())
        if self.g_symplectic is not None:
            parts.append(self.g_symplectic.to_latex())
        return "\n\n".join(parts)


def _show(v):
    return str(v).lower() if isinstance(v, bool) else str(v)


def verify(m: Method) -> VerifyResult:
    """All applicable analyses of ``m`` and the verdict on each of its claims."""
    rk = rk_symplectic(m) if m.kind in ("rk", "prk") else None
    gs = g_symplectic(m) if m.kind in ("rk", "glm") else None
    if m.parameters:
        order = None
    else:
        order = order_of(m)
    par = growth_parameters(m) if m.kind == "glm" and not m.V.free_symbols else None
    partial = VerifyResult(m.name, m.kind, m.s, getattr(m, "r", 1), m.parameters, gs, rk, order, {}, {}, (), par)
    claims = m.claims_dict
    found = {k: CHECKS[k](partial) for k in claims}
    failed = tuple(k for k in claims if found[k] != claims[k])
    return VerifyResult(m.name, m.kind, m.s, getattr(m, "r", 1), m.parameters, gs, rk, order, claims, found, failed,
                        par)
