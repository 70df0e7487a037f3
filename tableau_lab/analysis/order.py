"""``order(method)``: the order analysis that fits the method's kind.

RK → :func:`rk_order` (elementary weights, simplifying assumptions), partitioned RK →
:func:`prk_order` (bicoloured trees), GLM → :func:`glm_order` (starting methods).

>>> from tableau_lab.exact.tableau_json import load
>>> print(order(load("methods/rk4.json")).order)
4
"""
from __future__ import annotations

from ..exact.methods import Method
from .glm_order import glm_order
from .prk_order import prk_order
from .rk_order import rk_order

__all__ = ["order"]


def order(m: Method, max_order: int | None = None):
    """The order analysis of ``m``: a result object with ``order`` (classical for RK, highest
    achievable for GLMs), ``stage_order`` where defined, and ``print``/``to_json``/``to_latex``."""
    if m.kind == "rk":
        return rk_order(m, max_order)
    if m.kind == "prk":
        return prk_order(m) if max_order is None else prk_order(m, max_order)
    return glm_order(m) if max_order is None else glm_order(m, max_order)
