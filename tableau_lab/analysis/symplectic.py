r"""Symplecticity of RK and partitioned RK methods, and G-symplecticity of GLMs.

G-symplecticity ([BB80]; Butcher, *B-Series* (2021) ch. 7; the seed's Theorem 1):
a GLM is G-symplectic if there are a symmetric nonsingular r×r matrix G and a
diagonal s×s matrix D with

    VᵀGV = G,    DU = BᵀGV,    DA + AᵀD = BᵀGB.

These are homogeneous and linear in the entries of (G, D); :func:`g_symplectic`
solves them exactly over the field of the tableau and reports the whole
solution family.  For a Runge-Kutta method they reduce to the symplecticity
condition bᵢaᵢⱼ + bⱼaⱼᵢ − bᵢbⱼ = 0 (Sanz-Serna 1988; [HLW06] Thm VI.4.3) with
G = [1], D = diag(b), which :func:`rk_symplectic` checks directly.

>>> from tableau_lab.exact.tableau_json import loads
>>> mid = loads('{"name": "implicit midpoint", "kind": "rk", "A": [["1/2"]], "b": [1]}')
>>> rk_symplectic(mid).holds, g_symplectic(mid).holds
(True, True)
>>> g_symplectic(mid).D
Matrix([[1]])
"""
from __future__ import annotations

from dataclasses import dataclass, field
from itertools import product
from typing import Any

import sympy as sp
from sympy.polys.matrices import DomainMatrix

from ..exact.field import field_of, from_dm, nullspace, to_dm
from ..exact.grammar import format_entry, format_matrix
from ..exact.methods import Method, PartitionedRungeKutta, RungeKutta
from ..exact.render import matrix_latex, matrix_text
from ..render.model import Block, Document, Formula, Paragraph, Plain, Typeset
from .results import Result

Pair = tuple[DomainMatrix, DomainMatrix]     # (G, D) over the method's field

__all__ = ["rk_symplectic", "g_symplectic", "g_symplectic_residuals", "g_symplectic_residuals_dm", "RKSymplecticResult",
           "GSymplecticResult"]


# --------------------------------------------------------------------------- RK

@dataclass(frozen=True)
class RKSymplecticResult(Result):
    """M = diag(b)A + Aᵀdiag(b) − bbᵀ (RK) or Mᵢⱼ = bᵢâᵢⱼ + b̂ⱼaⱼᵢ − bᵢb̂ⱼ (partitioned RK)."""

    method: str
    kind: str
    M: sp.ImmutableMatrix
    holds: bool
    weights_equal: bool = True      # b = bhat (partitioned methods)
    holds_separable: bool = True    # M = 0 alone: enough for H = T(p) + U(q)
    congruent: bool = False         # M shown as VᵀMV (V the nodes' Vandermonde matrix; exact.conjugate)

    def display(self) -> Document:
        cond = (r"M = \operatorname{diag}(b)A + A^{\mathsf T}\operatorname{diag}(b) - bb^{\mathsf T}"
                if self.kind == "rk" else r"M_{ij} = b_i\hat a_{ij} + \hat b_j a_{ji} - b_i\hat b_j")
        head, *lines = self._text().split("\n")
        return Document(head, (Plain(*(Paragraph(x) for x in lines)), Typeset(
            Formula(f"{cond} = {matrix_latex(self.M)}"),
            Paragraph(f"The method is {'symplectic' if self.holds else 'not symplectic'}."))))

    def _text(self) -> str:
        if self.kind == "rk":
            head = f"symplectic (RK): {'yes' if self.holds else 'no'}  [M = diag(b)A + Aᵀdiag(b) − bbᵀ]"
        else:
            head = (f"symplectic (partitioned RK): {'yes' if self.holds else 'no'}"
                    f"  [Mᵢⱼ = bᵢâᵢⱼ + b̂ⱼaⱼᵢ − bᵢb̂ⱼ; b = b̂: {'yes' if self.weights_equal else 'no'}]")
            if not self.holds and self.holds_separable:
                head += "\n  symplectic for separable H = T(p) + U(q) only (M = 0 but b ≠ b̂)"
        if self.congruent:
            return (head + "\n  VᵀMV (V = [cⱼ^m], congruent to M: same rank and inertia) =\n"
                    + matrix_text(self.M, "    "))
        return head + "\n  M =\n" + matrix_text(self.M, "    ")

    def to_json(self):
        out = {"holds": self.holds, "M": format_matrix(self.M)}
        if self.kind == "prk":
            out.update(weights_equal=self.weights_equal, holds_separable=self.holds_separable)
        return out


def rk_symplectic(m: Method) -> RKSymplecticResult:
    """The symplecticity matrix of an RK or partitioned RK method, exactly.

    For partitioned methods ([HLW06] Thm VI.4.6) the method is symplectic for
    every Hamiltonian when M = 0 and b = b̂, and for separable H when M = 0.

    >>> from tableau_lab.exact.methods import RungeKutta
    >>> rk_symplectic(RungeKutta.from_lists([[0]], [1])).M
    Matrix([[-1]])
    """
    if isinstance(m, RungeKutta):
        A, b, Ah, bh = m.A, m.b, m.A, m.b
    elif isinstance(m, PartitionedRungeKutta):
        A, b, Ah, bh = m.A, m.b, m.Ahat, m.bhat
    else:
        raise TypeError(f"rk_symplectic applies to RK and partitioned RK methods, not {m.kind!r}")
    s = A.rows
    conjugate = m.conjugate if isinstance(m, RungeKutta) else None
    if conjugate is not None:      # in ℚ: VᵀMV (exact.conjugate)
        form = sp.ImmutableMatrix(conjugate.symplecticity_form())
        return RKSymplecticResult(m.name, m.kind, form, form.is_zero_matrix, True, form.is_zero_matrix, congruent=True)
    K = field_of([A, b, Ah, bh])
    raw = sp.Matrix(s, s, lambda i, j: b[i] * Ah[i, j] + bh[j] * A[j, i] - b[i] * bh[j])
    Mdm = to_dm(raw, K)
    weights_equal = to_dm(sp.Matrix(b - bh), K).is_zero_matrix
    zero = Mdm.is_zero_matrix
    return RKSymplecticResult(m.name, m.kind, from_dm(Mdm), zero and weights_equal, weights_equal, zero)


# --------------------------------------------------------------------------- GLM

def g_symplectic_residuals_dm(A, U, B, V, G, D):
    """The three G-symplectic residuals VᵀGV − G, DU − BᵀGV and DA + AᵀD − BᵀGB of the GLM
    (A, U, B, V) for given G, D, all ``DomainMatrix`` over one field: the method is G-symplectic
    with (G, D) exactly when all three vanish ([BHHN14] Butcher, Habib, Hill & Norton, SIAM J.
    Numer. Anal. 52 (2014), Def. 1; :func:`g_symplectic_residuals` for a method object).

    >>> from sympy import QQ
    >>> from sympy.polys.matrices import DomainMatrix
    >>> half, one = DomainMatrix([[QQ(1, 2)]], (1, 1), QQ), DomainMatrix([[QQ(1)]], (1, 1), QQ)
    >>> [R.is_zero_matrix for R in g_symplectic_residuals_dm(half, one, one, one, one, one)]  # midpoint, G = D = 1
    [True, True, True]
    """
    Vt, Bt = V.transpose(), B.transpose()
    BtG = Bt * G
    return (Vt * G * V - G, D * U - BtG * V, D * A + A.transpose() * D - BtG * B)


RESIDUAL_NAMES = ("VᵀGV − G", "DU − BᵀGV", "DA + AᵀD − BᵀGB")
RESIDUAL_LATEX = (r"V^{\mathsf T}GV - G", r"DU - B^{\mathsf T}GV", r"DA + A^{\mathsf T}D - B^{\mathsf T}GB")


def g_symplectic_residuals(m: Method, G, D) -> dict:
    """The residuals VᵀGV − G, DU − BᵀGV, DA + AᵀD − BᵀGB for given G, D, exactly.

    Used to check a printed (G, D) against the method, e.g. the seed's D = diag(1/2, −1/2)
    for its Example 4, which leaves DU − BᵀGV nonzero.
    """
    g = m.as_glm()
    G, D = sp.Matrix(G), sp.Matrix(D)
    K = field_of([g.A, g.U, g.B, g.V, G, D])
    dms = [to_dm(X, K) for X in (g.A, g.U, g.B, g.V, G, D)]
    return {name: from_dm(R) for name, R in zip(RESIDUAL_NAMES, g_symplectic_residuals_dm(*dms), strict=False)}


@dataclass(frozen=True)
class GSymplecticResult(Result):
    """The solution family of the G-symplectic conditions and its verdict."""

    method: str
    s: int
    r: int
    dimension: int                     # of the space of solutions (G, D)
    basis: tuple                       # ((G_k, D_k), ...) exact
    holds: bool                        # a solution with det G ≠ 0 exists
    G: sp.ImmutableMatrix | None       # normalised representative (first nonzero entry of G is 1)
    D: sp.ImmutableMatrix | None
    residuals: dict = field(default_factory=dict)   # name -> exact matrix (zero when holds)
    reason: str = ""
    rank: int = 0                      # rank of the linear system
    unknowns: int = 0
    equations: int = 0
    parameters: tuple = ()             # free parameters: verdict is generic in them
    definite: bool | None = None       # G (representative) positive or negative definite

    def display(self) -> Document:
        head, *lines = self._text().split("\n")
        out: list[Block] = [Paragraph(f"Solution family of dimension {self.dimension}.")]
        if self.G is not None and self.D is not None:
            out.append(Formula(f"G = {matrix_latex(self.G)}, \\qquad D = {matrix_latex(self.D)}"))
            out += [Formula(f"{tex} = {matrix_latex(R)}")
                    for R, tex in zip(self.residuals.values(), RESIDUAL_LATEX, strict=False)]
        verdict = "G-symplectic." if self.holds else "not G-symplectic. " + self.reason
        out.append(Paragraph("The method is " + verdict))
        return Document(head, (Plain(*(Paragraph(x) for x in lines)), Typeset(*out)))

    def _text(self) -> str:
        lines = [f"G-symplectic: {'yes' if self.holds else 'no'}"
                 f"  (solution family of dimension {self.dimension}; linear system: {self.equations} equations,"
                 f" {self.unknowns} unknowns, rank {self.rank})"]
        if self.parameters:
            lines.append("  generic in the parameters " + ", ".join(map(str, self.parameters))
                         + " (special values may behave differently)")
        if self.G is not None and self.D is not None:
            diag = ", ".join(str(format_entry(x)) for x in self.D.diagonal())
            lines += ["  G =", matrix_text(self.G), f"  D = diag({diag})"]
            if self.definite is not None:
                lines.append(f"  G is {'definite' if self.definite else 'indefinite'}")
        for name, R in self.residuals.items():
            state = "= 0 exactly" if R.is_zero_matrix else "≠ 0:\n" + matrix_text(R)
            lines.append(f"  {name} {state}")
        if self.reason:
            lines.append("  " + self.reason)
        return "\n".join(lines)

    def to_json(self):
        return {
            "holds": self.holds,
            "G": None if self.G is None else format_matrix(self.G),
            "D": None if self.D is None else format_matrix(self.D),
            "dimension": self.dimension,
            "basis": [{"G": format_matrix(G), "D": format_matrix(D)} for G, D in self.basis],
            "residuals": {k: format_matrix(v) for k, v in self.residuals.items()},
            "definite": self.definite,
            "reason": self.reason,
            "parameters": [str(p) for p in self.parameters],
        }


def _unknown_basis(r: int, s: int, K: Any) -> list[Pair]:
    """Unit (G, D) pairs, one per unknown: g_ij (i ≤ j, symmetric) then d_i."""
    units = []
    for i in range(r):
        for j in range(i, r):
            G = DomainMatrix.zeros((r, r), K).to_dense()
            G[i, j] = K.one
            G[j, i] = K.one
            units.append((G, DomainMatrix.zeros((s, s), K).to_dense()))
    for i in range(s):
        D = DomainMatrix.zeros((s, s), K).to_dense()
        D[i, i] = K.one
        units.append((DomainMatrix.zeros((r, r), K).to_dense(), D))
    return units


def _combine(units: list[Pair], coeffs: list[Any], K: Any) -> Pair:
    G = sum((u[0] * c for u, c in zip(units, coeffs, strict=False) if not K.is_zero(c)), units[0][0] * K.zero)
    D = sum((u[1] * c for u, c in zip(units, coeffs, strict=False) if not K.is_zero(c)), units[0][1] * K.zero)
    return G, D


def _normalise(G: DomainMatrix, D: DomainMatrix, K: Any) -> Pair:
    flat = [x for row in G.to_list() for x in row] + [x for row in D.to_list() for x in row]
    lead = next(x for x in flat if not K.is_zero(x))
    return G * (K.one / lead), D * (K.one / lead)


def _nonsingular_member(family: list[Pair], K: Any) -> Pair | None:
    """A member of the span of the G's with det ≠ 0, or None when det vanishes identically."""
    d = len(family)
    for G, D in family:
        if not K.is_zero(G.det()):
            return G, D
    if d == 1:
        return None
    # det(Σ λ_k G_k) is a polynomial of degree r in λ; if it is not identically zero
    # it is nonzero somewhere on the grid {0..r}^d (Schwartz-Zippel / Combinatorial Nullstellensatz).
    r = family[0][0].shape[0]
    for lam in product(range(r + 1), repeat=d):
        if not any(lam):
            continue
        coeffs = [K.convert(x) for x in lam]
        G = sum((F[0] * c for F, c in zip(family, coeffs, strict=False)), family[0][0] * K.zero)
        if not K.is_zero(G.det()):
            D = sum((F[1] * c for F, c in zip(family, coeffs, strict=False)), family[0][1] * K.zero)
            return G, D
    return None


def _definite(G) -> bool | None:
    """Whether an exact symmetric matrix is (positive or negative) definite, via leading minors."""
    if G.free_symbols:
        return None
    G = sp.Matrix(G)
    if G[0, 0].is_negative:
        G = -G
    return all(sp.Matrix(G[:k, :k]).det().is_positive for k in range(1, G.rows + 1))


def g_symplectic(m: Method) -> GSymplecticResult:
    """Solve VᵀGV = G, DU = BᵀGV, DA + AᵀD = BᵀGB exactly for symmetric G and diagonal D.

    Works on any GLM, and on an RK method through its GLM form.  The unknowns are the
    r(r+1)/2 entries of G and the s diagonal entries of D; the solution space is the
    nullspace of the coefficient matrix of the three conditions, computed over the
    method's number field (or, with free parameters, its rational function field, in
    which case the answer is the generic one).  ``tl.g_symplectic``, ``m.g_symplectic()``;
    the conditions are those of [BHHN14] Butcher, Habib, Hill & Norton, SIAM J. Numer. Anal. 52
    (2014), Def. 2.1 ([B16] Sec. 54).

    >>> import tableau_lab as tl
    >>> g = tl.g_symplectic(tl.load("example4_glm"))
    >>> g.holds, list(g.G)
    (True, [1, 0, 0, 1 + 2*sqrt(3)/3])
    """
    if getattr(m, "conjugate", None) is not None:
        return _g_symplectic_conjugate(m)
    g = m.as_glm()
    s, r = g.s, g.r
    K = field_of([g.A, g.U, g.B, g.V])
    A, U, B, V = (to_dm(X, K) for X in (g.A, g.U, g.B, g.V))
    units = _unknown_basis(r, s, K)
    columns = []
    for G, D in units:
        col: list[Any] = []
        for R in g_symplectic_residuals_dm(A, U, B, V, G, D):
            col.extend(x for row in R.to_list() for x in row)
        columns.append(col)
    n, neq = len(units), len(columns[0])
    system = DomainMatrix([[columns[k][i] for k in range(n)] for i in range(neq)], (neq, n), K)
    rank = system.rank()
    family = [_combine(units, vec, K) for vec in nullspace(system)]
    family = [_normalise(G, D, K) for G, D in family]
    common = dict(method=m.name, s=s, r=r, dimension=len(family), rank=rank, unknowns=n, equations=neq,
                  basis=tuple((from_dm(G), from_dm(D)) for G, D in family), parameters=g.parameters)
    if not family:
        return GSymplecticResult(holds=False, G=None, D=None, reason=(
            f"The only solution is G = 0, D = 0: the {neq}×{n} linear system has full column rank {rank}."), **common)
    member = _nonsingular_member(family, K)
    if member is None:
        G, D = family[0]
        reason = ("Every solution has a singular G: det G = 0 on the whole family"
                  + (" (the determinant of the general member vanishes identically)." if len(family) > 1 else "."))
        holds = False
    else:
        G, D = _normalise(*member, K)
        reason, holds = "", True
    residuals = g_symplectic_residuals_dm(A, U, B, V, G, D)
    res = {name: from_dm(R) for name, R in zip(RESIDUAL_NAMES, residuals, strict=False)}
    Gs = from_dm(G)
    return GSymplecticResult(holds=holds, G=Gs, D=from_dm(D), residuals=res, reason=reason,
                             definite=_definite(Gs) if holds else None, **common)


def _g_symplectic_conjugate(m) -> GSymplecticResult:
    """An RK method on the roots of one polynomial (exact.conjugate): with r = 1, VᵀGV = G holds
    for every G = [g], DU = BᵀGV forces D = g·diag(b), and DA + AᵀD = BᵀGB is g·M = 0 — so the
    solutions are that line when M = 0 (tested in ℚ as VᵀMV = 0), and only G = 0 otherwise."""
    s = m.s
    M = rk_symplectic(m)
    common = dict(method=m.name, s=s, r=1, unknowns=s + 1, equations=1 + s + s * s, parameters=())
    if not M.holds:
        return GSymplecticResult(holds=False, G=None, D=None, dimension=0, rank=s + 1, basis=(), reason=(
            "The only solution is G = 0, D = 0: D = g·diag(b) is forced and g·M = 0 needs g = 0, as M ≠ 0 "
            "(VᵀMV ≠ 0, V the nodes' Vandermonde matrix)."), **common)
    G, D = sp.ImmutableMatrix([[1]]), sp.ImmutableMatrix(sp.diag(*m.b))
    shapes = ((1, 1), (s, 1), (s, s))
    zero = {name: sp.ImmutableMatrix(sp.zeros(*shape)) for name, shape in zip(RESIDUAL_NAMES, shapes, strict=False)}
    return GSymplecticResult(holds=True, G=G, D=D, residuals=zero, reason="", definite=True, dimension=1, rank=s,
                             basis=((G, D),), **common)
