"""Method families generated exactly (nodes as algebraic numbers, A by exact linear algebra).

>>> gauss(2).A
Matrix([
[            1/4, 1/4 - sqrt(3)/6],
[1/4 + sqrt(3)/6,             1/4]])
"""
from __future__ import annotations

import sympy as sp

from .field import field_of, from_dm, to_dm
from .methods import RungeKutta

__all__ = ["gauss"]


def gauss(s: int) -> RungeKutta:
    """The s-stage Gauss–Legendre method ([HW96] §IV.5): nodes the roots of the shifted
    Legendre polynomial P_s(2x − 1) as radicals, A and b from the simplifying assumptions
    C(s) and B(s) (Vandermonde systems solved in the nodes' number field).  Order 2s."""
    x = sp.Symbol("x")
    roots = sp.roots(sp.Poly(sp.legendre(s, 2 * x - 1), x))
    if sum(roots.values()) != s or any(r.has(sp.I) for r in roots):
        # s = 6: a cubic in (x − 1/2)² with three real roots (casus irreducibilis): radicals of
        # complex numbers only; the field of all nodes then has degree up to 48
        raise ValueError(f"the Gauss nodes for s = {s} have no expression in real radicals; "
                         "generated families go up to s = 5 for now")
    c = sorted(roots, key=lambda r: float(r))
    K = field_of(c)
    Vt = to_dm(sp.Matrix(s, s, lambda k, j: c[j] ** k), K)          # Vᵀ, V_jk = c_j^k
    Vinv = Vt.inv()
    Ct = to_dm(sp.Matrix(s, s, lambda k, i: c[i] ** (k + 1) / (k + 1)), K)
    A = from_dm((Vinv * Ct).transpose())             # Σ_j a_ij c_j^k = c_i^(k+1)/(k+1)
    b = from_dm(Vinv * to_dm(sp.Matrix([sp.Rational(1, k + 1) for k in range(s)]), K))
    return RungeKutta(A=A, b=b, c=sp.Matrix(c), name=f"Gauss–Legendre, {s} stages",
                      source="generated: nodes of P_s(2x-1), A from C(s), b from B(s)")
