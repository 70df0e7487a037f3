r"""The SSP coefficient (radius of absolute monotonicity) of a Runge–Kutta method, exactly.

Kraaijevanger (BIT 31 (1991) 482–528; Ketcheson, SIAM J. Sci. Comput. 30 (2008)): with
K = [[A, 0], [bᵀ, 0]] and e = 1 ((s+1)-vectors), the method is absolutely monotonic at r ≥ 0 when
I + rK is invertible and

    K(I + rK)⁻¹ ≥ 0,        e − rK(I + rK)⁻¹e ≥ 0          (componentwise),

and the set of such r is an interval [0, R]: R is the SSP coefficient (forward Euler's step
bound times R is the method's).  Each entry is a rational function of r with coefficients in the
entries' field, so R is found exactly: the positive real roots of the entries'
numerators and of det(I + rK) cut [0, ∞) into intervals on which every entry keeps its sign;
R is the left end of the first interval where one is negative (tested at a rational point),
∞ when there is none, 0 when K ≥ 0 or the second condition fails at r = 0.  R is then rational
or a real algebraic number (a root of one numerator), printed exactly.

>>> from tableau_lab.exact.tableau_json import load
>>> ssp_coefficient(load("implicit_midpoint")).R, ssp_coefficient(load("implicit_euler")).R
(2, oo)
>>> ssp_coefficient(load("rk4")).R
0
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp
from sympy.polys.matrices import DomainMatrix

from ..exact.grammar import format_entry
from ..exact.methods import Method, RungeKutta
from ..render.model import Document, Math, Paragraph, Typeset
from .results import Result

__all__ = ["ssp_coefficient", "SSPResult", "SSP_MAX_STAGES", "SSP_MAX_EXPLICIT_STAGES"]

#: (s+1)×(s+1) adjugate with a symbolic r and the real roots of its entries: beyond this many
#: stages, not computed (a dense 12-stage tableau with positive entries: about 11 s)
SSP_MAX_STAGES = 12
#: the same for explicit methods, whose entries are polynomials of degree < s (SSPRK(25,3): 2.5 s)
SSP_MAX_EXPLICIT_STAGES = 25
_R = sp.Symbol("r", nonnegative=True)


@dataclass(frozen=True)
class SSPResult(Result):
    method: str
    R: sp.Expr | None          # exact SSP coefficient (sympy number, or oo), None when not computed
    reason: str = ""           # which condition bounds R, or why it was not computed

    def _line(self) -> str:
        """The plain face, one line."""
        if self.R is None:
            return f"SSP coefficient: not computed ({self.reason})"
        approx = "" if self.R in (0, sp.oo) or self.R.is_Rational else f" ≈ {sp.N(self.R, 8)}"
        return f"SSP coefficient (radius of absolute monotonicity): R = {format_entry(self.R)}{approx}" + (
            f" — {self.reason}" if self.reason else "")

    def to_json(self):
        return {"ssp_coefficient": None if self.R is None else ("oo" if self.R == sp.oo else str(format_entry(self.R))),
                "ssp_coefficient_float": None if self.R is None else float(self.R),
                "ssp_reason": self.reason}

    def display(self) -> Document:
        """The plain face: the line above; the typeset face: R in a sentence, with what bounds it."""
        if self.R is None:
            return Document(self._line(), (Typeset(Paragraph(f"SSP coefficient not computed ({self.reason}).")),))
        return Document(self._line(), (Typeset(Paragraph("SSP coefficient ", Math(f"R = {sp.latex(self.R)}"),
                                                         "." + (f" {self.reason}." if self.reason else ""))),))


def ssp_coefficient(m: Method) -> SSPResult:
    """The exact SSP coefficient of an RK method (module docstring).  Over ℚ the cuts are the
    real roots of the numerators; over a number field K (√3 in SSPIRK3) they are those of the
    numerators' norms (ℚ-polynomials whose roots include the numerators'), and each sign at a
    rational probe is certified in K (:func:`stability.sign`).  [GKS11] Gottlieb, Ketcheson &
    Shu, *Strong Stability Preserving Runge–Kutta and Multistep Time Discretizations* (2011),
    ch. 3; Kraaijevanger 1991 (the radius of absolute monotonicity).

    >>> import tableau_lab as tl
    >>> tl.ssp_coefficient(tl.load("ssp104")).R, tl.load("ssprk:3").ssp_coefficient().R   # Ketcheson 2008; Shu–Osher
    (6, 1)
    """
    if not isinstance(m, RungeKutta):
        return SSPResult(m.name, None, f"defined here for Runge–Kutta methods, not {m.kind}")
    if m.parameters:
        return SSPResult(m.name, None, "the tableau has free parameters")
    from ..exact.field import element, field_of
    from ..exact.real_roots import last_good_cut, sign, sign_at
    K = field_of([m.A, m.b])
    s = m.s
    # at r = 0 the conditions are K ≥ 0 (a negative entry: R = 0, whatever the size)
    entries = [(f"a[{i + 1},{j + 1}]", m.A[i, j]) for i in range(s) for j in range(s)]
    entries += [(f"b[{j + 1}]", m.b[j]) for j in range(s)]
    for name, x in entries:
        if sign(K, element(K, x)) < 0:
            return SSPResult(m.name, sp.Integer(0), f"at r = 0: {name} < 0")
    limit, label = ((SSP_MAX_EXPLICIT_STAGES, "SSP_MAX_EXPLICIT_STAGES") if m.explicit
                    else (SSP_MAX_STAGES, "SSP_MAX_STAGES"))
    if s > limit:
        return SSPResult(m.name, None, f"{s} stages exceed {label} = {limit}")
    Kmat = sp.zeros(s + 1, s + 1)
    Kmat[:s, :s] = m.A
    Kmat[s, :s] = m.b.T
    # det(I + rK) and K·adj(I + rK) in K[r] (division-free: sympy's DomainMatrix.adj_det)
    ring = K[_R]
    I_rK = sp.eye(s + 1) + _R * Kmat
    Kdm, Idm = (DomainMatrix([[ring.from_sympy(x) for x in M.row(i)] for i in range(s + 1)], (s + 1, s + 1), ring)
                for M in (Kmat, I_rK))
    adj, det_dm = Idm.adj_det()
    Mdm = Kdm * adj
    e = DomainMatrix([[ring.one] for _ in range(s + 1)], (s + 1, 1), ring)
    vdm = e * det_dm - Mdm * e * ring.from_sympy(_R)

    def poly(x):                                 # an element of K[r] as a sympy Poly in r
        return sp.Poly(ring.to_sympy(x), _R, domain=K)

    det = poly(det_dm)
    named = [(f"K(I + rK)⁻¹ entry ({i + 1}, {j + 1})", Mdm[i, j].element) for i in range(s + 1) for j in range(s + 1)]
    named += [(f"e − rK(I + rK)⁻¹e entry {i + 1}", vdm[i, 0].element) for i in range(s + 1)]
    nums = [(name, poly(n)) for name, n in named if n]

    def sgn(p, x):
        return sign_at(p, x, K)

    def bad_at(x):
        """The first condition violated at r = x (exact), or None."""
        d = sgn(det, x)
        if d == 0:
            return "I + rK is singular"
        for name, n in nums:
            if sgn(n, x) * d < 0:
                return name
        return None

    cuts = set()
    for _, n in nums + [("det", det)]:
        if n.degree() > 0:
            q = n if K.is_QQ else n.norm()         # over ℚ: the same roots, and the conjugates'
            cuts |= {x for x in sp.Poly(q.as_expr(), _R).real_roots() if x > 0}
    end, why = last_good_cut(sp.Integer(0), sorted(cuts, key=lambda x: sp.N(x, 50)), bad_at, +1)
    if end is None:
        return SSPResult(m.name, sp.oo, "absolutely monotonic for every r ≥ 0")
    return SSPResult(m.name, end, f"beyond it {why} < 0")
