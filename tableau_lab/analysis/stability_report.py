r"""Everything ``tableau-lab stability`` prints, gathered: the stability report of one method
(``tl.stability_report``).  It sits on top of the single analyses it gathers — linear stability
(:mod:`.stability`), algebraic stability, zero-stability, A(α), parasitism, the real-axis
interval, the SSP coefficient, internal stability, and the parametric analysis for a method with
free parameters — and none of them imports it ([HW96] Hairer & Wanner, *Solving ODEs II*, §IV.3,
§IV.12; [BHHN14] Butcher, Habib, Hill & Norton, SIAM J. Numer. Anal. 52 (2014), Sec. 4).

>>> import tableau_lab as tl
>>> r = stability_report(tl.load("gauss2"))
>>> r.linear.a_stable, r.algebraic.holds, r.ssp.R
(True, True, 0)
"""
from __future__ import annotations

from dataclasses import dataclass, field

from ..exact.methods import Method
from ..render.model import Document
from .a_alpha import AAlphaResult, a_alpha
from .algebraic_stability import AlgebraicStabilityResult, algebraic_stability
from .internal_stability import InternalStabilityResult, internal_stability
from .parametric_stability import ParametricStability, parametric_stability
from .parasitism import ParasitismResult, growth_parameters
from .real_interval import RealIntervalResult, real_stability_interval
from .results import Result
from .ssp import SSPResult, ssp_coefficient
from .stability import StabilityResult, stability
from .symplectic import g_symplectic
from .zero_stability import ZeroStabilityResult, zero_stability

__all__ = ["StabilityReport", "stability_report"]


@dataclass(frozen=True)
class StabilityReport(Result):
    """Linear stability, zero-stability and A(α) (GLMs), algebraic stability and parasitism (GLMs)
    of one method together."""

    method: str
    linear: StabilityResult
    algebraic: AlgebraicStabilityResult
    parasitism: ParasitismResult | None = field(default=None)          # GLMs
    zero: ZeroStabilityResult | None = field(default=None)             # GLMs
    sector: AAlphaResult | None = field(default=None)                  # A(α), GLMs
    real: RealIntervalResult | None = field(default=None)              # RK
    ssp: SSPResult | None = field(default=None)                        # RK
    internal: InternalStabilityResult | None = field(default=None)     # RK

    def _parts(self):
        return [p for p in (self.linear, self.real, self.zero, self.sector, self.algebraic, self.ssp, self.internal,
                            self.parasitism) if p is not None]

    def display(self) -> Document:
        """The parts' displays one after the other (each with its heading in text)."""
        return Document(None, tuple(p.display() for p in self._parts()))

    def to_json(self):
        out = dict(self.linear.to_json())
        out["zero_stable"] = self.zero.holds if self.zero is not None else None
        out["zero_stability"] = self.zero.to_json() if self.zero is not None else None
        out["a_alpha"] = self.sector.to_json() if self.sector is not None else None
        for part in (self.real, self.ssp, self.internal):
            if part is not None:
                out.update(part.to_json())
        alg = self.algebraic.to_json()
        out["algebraically_stable"] = alg["algebraically_stable"]
        out["algebraic_stability"] = alg
        out["parasitism"] = self.parasitism.to_json()["parasitism"] if self.parasitism is not None else []
        return out


def stability_report(m: Method) -> StabilityReport | ParametricStability:
    """Everything ``tableau-lab stability`` prints (``tl.stability_report``): linear stability
    (:func:`stability`), algebraic stability and, for RK methods, the real-axis interval, the SSP
    coefficient and the internal stability functions; for GLMs zero-stability, the A(α) angle and
    the parasitic growth parameters ([HW96] §IV.3, §IV.12; [BHHN14] Sec. 4).  A method with free
    parameters gets what holds over their field
    (:func:`~tableau_lab.analysis.parametric_stability.parametric_stability`).

    >>> import tableau_lab as tl
    >>> r = tl.stability_report(tl.load("ssprk:3"))
    >>> r.linear.bounded_radius, r.ssp.R
    (sqrt(3), 1)
    """
    if m.parameters:
        return parametric_stability(m)
    gsym = g_symplectic(m) if m.kind != "prk" else None
    lin = stability(m, gsym)
    alg = algebraic_stability(m, a_stable=lin.a_stable, gsym=gsym)
    if m.kind == "rk":
        return StabilityReport(method=m.name, linear=lin, algebraic=alg, real=real_stability_interval(m),
                               ssp=ssp_coefficient(m), internal=internal_stability(m))
    if m.kind != "glm":
        return StabilityReport(method=m.name, linear=lin, algebraic=alg)
    zero = zero_stability(m)
    try:
        par = growth_parameters(m)
    except ValueError:
        if zero.holds:
            raise
        par = None           # a defective eigenvalue on the circle: no growth parameters, and no stability
    return StabilityReport(method=m.name, linear=lin, algebraic=alg, parasitism=par, zero=zero,
                           sector=a_alpha(m, zero=zero, polynomial=lin.polynomial))
