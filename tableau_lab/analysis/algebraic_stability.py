r"""Algebraic stability of RK methods and GLMs, exactly ([BB80] Burrage & Butcher, BIT 20 (1980);
[HW96] Hairer & Wanner II, §IV.12; [B16] Butcher (2016) ch. 5).

A GLM is algebraically stable when there are a symmetric positive definite r×r matrix G and a
diagonal s×s matrix D ≥ 0 such that

    M = [[DA + AᵀD − BᵀGB,  DU − BᵀGV],
         [UᵀD − VᵀGB,       G − VᵀGV ]]

is positive semidefinite.  Then ‖y⁽ⁿ⁾‖_G does not grow on dissipative problems, and on y′ = λy
with Re λ ≤ 0 the stability matrix is a G-contraction: algebraic stability implies A-stability,
so a method that is not A-stable (``stability.stability``) is certainly not algebraically stable.

*RK methods* (G = [1], D = diag(b), the definition itself): b ≥ 0 and
M = diag(b)A + Aᵀdiag(b) − bbᵀ positive semidefinite; decided exactly (all principal minors,
signs of algebraic numbers certified).  *GLMs*: the (G, D) that make the method G-symplectic
(``symplectic.g_symplectic``) make M = 0; the method is then algebraically stable when G (or −G,
with −D) is positive definite and D ≥ 0.  When that fails and the method is A-stable, other
(G, D) were not searched: the verdict is ``None`` (undecided), and says so.

>>> from tableau_lab.exact.tableau_json import load
>>> algebraic_stability(load("methods/lobatto_iiic3.json")).holds
True
>>> algebraic_stability(load("methods/lobatto_iiia3.json")).holds
False
>>> e4 = algebraic_stability(load("methods/example4_glm.json"))
>>> e4.holds, e4.G.diagonal().tolist(), e4.D.diagonal().tolist()
(True, [[1, 1 + 2*sqrt(3)/3]], [[1/2, 1/2]])
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import sympy as sp

from ..exact.field import element, field_of, from_dm, to_dm
from ..exact.grammar import format_entry, format_matrix
from ..exact.methods import Method
from ..exact.real_roots import sign
from ..render.model import Block, Document, Formula, Paragraph, Plain, Typeset
from .results import Result, matrix_latex, matrix_text
from .symplectic import g_symplectic_residuals_dm

__all__ = ["algebraic_stability", "AlgebraicStabilityResult", "stability_matrix"]


@dataclass(frozen=True)
class AlgebraicStabilityResult(Result):
    method: str
    kind: str
    holds: bool | None               # None: undecided (or not applicable)
    reason: str
    scope: str = ""                  # which (G, D) the verdict covers
    G: sp.ImmutableMatrix | None = None
    D: sp.ImmutableMatrix | None = None
    M: sp.ImmutableMatrix | None = None

    def _lines(self) -> list[str]:
        """The plain face, a line each."""
        word = {True: "yes", False: "no", None: "undecided" if self.kind != "prk" else "not applicable"}[self.holds]
        lines = [f"algebraically stable: {word} — {self.reason}"]
        if self.scope:
            lines.append(f"  scope: {self.scope}")
        if self.G is not None and self.D is not None:
            diag = ", ".join(str(format_entry(x)) for x in self.D.diagonal())
            lines += ["  G =", matrix_text(self.G), f"  D = diag({diag})"]
        if self.M is not None:
            lines.append("  M = 0" if self.M.is_zero_matrix else "  M =\n" + matrix_text(self.M))
        return lines

    def to_json(self):
        return {"algebraically_stable": self.holds, "reason": self.reason, "scope": self.scope,
                "G": None if self.G is None else format_matrix(self.G),
                "D": None if self.D is None else format_matrix(self.D),
                "M": None if self.M is None else format_matrix(self.M)}

    def display(self) -> Document:
        """The plain face: the lines above; the typeset face: G, D and M, and the verdict with its reason."""
        typeset: list[Block] = []
        if self.G is not None and self.D is not None:
            typeset.append(Formula(f"G = {matrix_latex(self.G)}, \\qquad D = {matrix_latex(self.D)}"))
        if self.M is not None:
            typeset.append(Formula(f"M = {matrix_latex(self.M)}"))
        typeset.append(Paragraph({True: "The method is algebraically stable.",
                                  False: "The method is not algebraically stable.",
                                  None: "Algebraic stability is undecided."}[self.holds] + " " + self.reason))
        head, *lines = self._lines()
        return Document(head, (Plain(*map(Paragraph, lines)), Typeset(*typeset)))


def stability_matrix(m: Method, G, D) -> sp.ImmutableMatrix:
    """The algebraic-stability matrix M of a GLM (or an RK method as a GLM) for given G, D, exactly."""
    g = m.as_glm()
    K = field_of([g.A, g.U, g.B, g.V, G, D])
    R1, R2, R3 = g_symplectic_residuals_dm(*(to_dm(sp.Matrix(X), K) for X in (g.A, g.U, g.B, g.V, G, D)))
    # M = [[DA + AᵀD − BᵀGB, DU − BᵀGV], [(DU − BᵀGV)ᵀ, G − VᵀGV]]: the G-symplectic residuals
    return from_dm(R3.hstack(R2).vstack(R2.transpose().hstack(-R1)))


def _nonnegative_minors(M, K, leading=False, strict=False):
    """The index set of the first principal minor of the exact symmetric matrix M (over K) that is
    negative (or ≤ 0 with ``strict``), or None when there is none.  ``leading``: leading minors only
    (Sylvester's test for positive definiteness); otherwise all principal minors (semidefiniteness)."""
    n = M.rows
    Mdm = to_dm(M, K)
    if leading:
        sets = (tuple(range(k)) for k in range(1, n + 1))
    else:
        # Semidefinite iff the coefficients of det(tI − M) = Σ cₖ t^(n−k) alternate, (−1)ᵏcₖ ≥ 0 (M is
        # symmetric: real eigenvalues, all ≥ 0 exactly then; Descartes): n³ work where the 2ⁿ − 1
        # principal minors (67 million for NodePy's 26-stage DC(5)) are not computable.  Only a
        # matrix that is not semidefinite is searched for a negative minor to name (one exists),
        # smallest first, lazily.
        if all(sign(K, c) * (-1) ** k >= 0 for k, c in enumerate(Mdm.charpoly())):
            return None
        sets = (c for k in range(1, n + 1) for c in combinations(range(n), k))
    for idx in sets:
        sub = Mdm.extract(list(idx), list(idx))
        sg = sign(K, sub.det())
        if sg < 0 or (strict and sg == 0):
            return idx
    return None


def _rk(m) -> AlgebraicStabilityResult:
    from .symplectic import rk_symplectic
    negative = [i + 1 for i in range(m.s) if sign(field_of([m.b[i]]), element(field_of([m.b[i]]), m.b[i])) < 0]
    M = rk_symplectic(m).M        # VᵀMV for a method on conjugate nodes: congruent, the same inertia
    common = dict(method=m.name, kind=m.kind, M=M, G=sp.ImmutableMatrix([[1]]), D=sp.ImmutableMatrix(sp.diag(*m.b)),
                  scope="the definition for RK methods: G = [1], D = diag(b), M = diag(b)A + Aᵀdiag(b) − bbᵀ")
    if negative:
        return AlgebraicStabilityResult(holds=False, reason=f"b_{negative[0]} < 0", **common)
    bad = _nonnegative_minors(M, field_of([M]))
    if bad is not None:
        rows = ", ".join(str(i + 1) for i in bad)
        return AlgebraicStabilityResult(holds=False, reason=f"M is not positive semidefinite: its principal minor "
                                        f"on rows {{{rows}}} is negative", **common)
    return AlgebraicStabilityResult(holds=True, reason="b ≥ 0 and M is positive semidefinite"
                                    + (" (M = 0)" if M.is_zero_matrix else ""), **common)


def _definite_pair(G, D):
    """(G, D) or (−G, −D) with G positive definite and D ≥ 0, else None."""
    K = field_of([G, D])
    for sgn in (1, -1):
        Gs, Ds = sgn * G, sgn * D
        if (_nonnegative_minors(Gs, K, leading=True, strict=True) is None
                and all(sign(K, element(K, d)) >= 0 for d in Ds.diagonal())):
            return sp.ImmutableMatrix(Gs), sp.ImmutableMatrix(Ds)
    return None


def algebraic_stability(m: Method, a_stable: bool | None = None, gsym=None) -> AlgebraicStabilityResult:
    """Algebraic stability, exactly where decidable here.  ``a_stable`` (from the linear-stability
    analysis, computed when not given) settles the GLM case negatively: not A-stable ⇒ not
    algebraically stable.  ``gsym``: the method's ``g_symplectic`` result, when already computed."""
    if m.kind == "prk":
        return AlgebraicStabilityResult(method=m.name, kind=m.kind, holds=None,
                                        reason="defined for RK methods and GLMs, not for partitioned methods")
    if m.parameters:
        raise ValueError(f"{m.name}: algebraic stability needs a method without free parameters")
    if m.kind == "rk":
        return _rk(m)
    from .symplectic import g_symplectic
    gs = gsym or g_symplectic(m)
    if a_stable is None:
        from .stability import stability
        a_stable = stability(m, gs).a_stable
    common = dict(method=m.name, kind=m.kind)
    if gs.holds:
        pair = _definite_pair(gs.G, gs.D)
        if pair is not None:
            G, D = pair
            return AlgebraicStabilityResult(holds=True, G=G, D=D, M=stability_matrix(m, G, D),
                                            reason="the G-symplectic G is positive definite and D ≥ 0: M = 0",
                                            scope="the G, D of G-symplecticity (a proof: one admissible pair suffices)",
                                            **common)
        G, D = gs.G, gs.D
        detail = ("the G-symplectic G is definite but D ≱ 0 with it" if gs.definite else
                  "the G-symplectic G is not definite")
        M = stability_matrix(m, G, D)
    else:
        G = D = M = None
        detail = "the method is not G-symplectic"
    if a_stable is False:
        return AlgebraicStabilityResult(holds=False, G=G, D=D, M=M, reason=(
            f"the method is not A-stable, and algebraic stability implies A-stability; {detail}"),
            scope="every G > 0, D ≥ 0 (through A-stability)", **common)
    return AlgebraicStabilityResult(holds=None, G=G, D=D, M=M, reason=(
        f"{detail}; other (G, D) were not searched"),
        scope=("only the G-symplectic (G, D) family" if gs.holds and gs.dimension == 1 else
               "only the G-symplectic (G, D) representative" if gs.holds else "no (G, D) examined"), **common)
