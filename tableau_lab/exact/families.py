"""Runge–Kutta families generated exactly for any number of stages: the collocation methods
Gauss–Legendre, Radau IIA and Lobatto IIIA ([HW96] §IV.5).

Each is built in ℚ on the roots of its node polynomial (:mod:`conjugate`: Ã, b̃ from C(s) and
B(s)); its tableau is written with the nodes as real radicals where they have them (Gauss
s ≤ 5, say) and as exact real roots (``CRootOf``, ``root(P, k)`` in a tableau file) otherwise.

>>> gauss(2).A
Matrix([
[            1/4, 1/4 - sqrt(3)/6],
[1/4 + sqrt(3)/6,             1/4]])
>>> str(gauss(6).c[0])
'CRootOf(924*X**6 - 2772*X**5 + 3150*X**4 - 1680*X**3 + 420*X**2 - 42*X + 1, 0)'
"""
from __future__ import annotations

from functools import lru_cache

import sympy as sp

from .conjugate import collocation, lobatto_nodes, radau_right, shifted_legendre
from .field import field_of, from_dm, to_dm
from .methods import RungeKutta

__all__ = ["gauss", "radau_iia", "lobatto_iiia", "MAX_STAGES"]

#: the largest s generated: the order analysis of 8-stage Gauss checks 376 465 trees (order ≤ 16
#: and one of order 17) in about 14 s; each further stage multiplies that by about seven
MAX_STAGES = 8


def _method(P, name: str, source: str) -> RungeKutta:
    alg = collocation(P)
    A, b, c = alg.tableau()
    if not any(x.has(sp.RootOf) for x in c):      # radicals: the entries in the field's normal form
        K = field_of([c])
        A, b = from_dm(to_dm(A, K)), from_dm(to_dm(b, K))
    return RungeKutta(A=A, b=b, c=c, conjugate=alg, name=name, source=source)


@lru_cache(maxsize=None)          # immutable: built once per process
def gauss(s: int) -> RungeKutta:
    """The s-stage Gauss–Legendre method: nodes the roots of P_s(2x − 1); order 2s."""
    return _method(shifted_legendre(s), f"Gauss–Legendre, {s} stages",
                   "generated: collocation at the roots of P_s(2x-1) ([HW96] Table IV.5.13)")


@lru_cache(maxsize=None)          # immutable: built once per process
def radau_iia(s: int) -> RungeKutta:
    """The s-stage Radau IIA method: nodes the roots of P_s(2x − 1) − P_{s−1}(2x − 1) (c_s = 1);
    order 2s − 1."""
    return _method(radau_right(s), f"Radau IIA, {s} stages",
                   "generated: collocation at the roots of P_s(2x-1) - P_{s-1}(2x-1) ([HW96] Table IV.5.13)")


@lru_cache(maxsize=None)          # immutable: built once per process
def lobatto_iiia(s: int) -> RungeKutta:
    """The s-stage Lobatto IIIA method (s ≥ 2): nodes 0, 1 and the roots of P′_{s−1}(2x − 1);
    order 2s − 2."""
    if s < 2:
        raise ValueError(f"Lobatto methods have at least 2 stages, not {s}")
    return _method(lobatto_nodes(s), f"Lobatto IIIA, {s} stages",
                   "generated: collocation at 0, 1 and the roots of P'_{s-1}(2x-1) ([HW96] Table IV.5.13)")
