"""``order(method)``: the order analysis that fits the method's kind.

RK → :func:`rk_order` (elementary weights, simplifying assumptions), partitioned RK →
:func:`prk_order` (bicoloured trees), GLM → :func:`glm_order` (starting methods).

>>> from tableau_lab.exact.tableau_json import load
>>> print(order(load("methods/rk4.json")).order)
4
"""
from __future__ import annotations

from ..exact.methods import Method, PartitionedRungeKutta, RungeKutta
from .glm_order import glm_order
from .prk_order import prk_order
from .rk_order import rk_order

__all__ = ["order"]


def order(m: Method, max_order: int | None = None):
    """The order analysis of ``m`` (``tl.order``, ``m.order()``, ``tableau-lab order``): a result
    object with ``order`` (``int(result)``), ``stage_order`` where defined, the residuals of the
    first failing conditions, and ``print``/``to_json``/``to_latex``.

    * RK: the classical order by elementary weights Φ(t) = 1/γ(t) over rooted trees ([B16]
      Butcher, *Numerical Methods for ODEs*, 3rd ed., ch. 3; [HNW93] §II.2), the simplifying
      assumptions B, C, D, the principal error coefficients and the effective order;
    * partitioned RK: bicoloured trees ([HLW06] §III.2);
    * GLM: the highest order achievable with a starting method, the order with θ ≡ 0, the stage
      order, starting and finishing methods ([B16] ch. 5; [BHHN14]).

    ``max_order`` caps the trees checked (default: the bound 2s, or s when explicit, for RK).

    >>> import tableau_lab as tl
    >>> r = tl.order(tl.load("gauss:3"))
    >>> int(r), r.stage_order                      # Gauss: order 2s, stage order s ([HW96] IV.5)
    (6, 3)
    >>> int(tl.order(tl.load("bdf:3"))), int(tl.order(tl.load("stormer_verlet")))
    (3, 2)
    """
    if isinstance(m, RungeKutta):
        return rk_order(m, max_order)
    if isinstance(m, PartitionedRungeKutta):
        return prk_order(m) if max_order is None else prk_order(m, max_order)
    return glm_order(m) if max_order is None else glm_order(m, max_order)
