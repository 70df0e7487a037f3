r"""B-series as maps tree → coefficient ([HLW06] III.1; [B21]).

B(a, y) = a(∅) y + Σ_t h^{|t|}/σ(t) · a(t) F(t)(y).  A series is a dict {tree: value}
with the empty tree as ``None``; values are exact (sympy numbers or field elements).

Composition ([HLW06] Thm III.1.10): B(b, B(a, y)) = B(a·b, y) with
(a·b)(t) = Σ over admissible cuts b(trunk) Π a(pruned parts), where the empty cut keeps
the whole tree as trunk and the full cut gives b(∅) a(t).  The inner series must have
a(∅) = 1; the outer one may have any b(∅) (as the components of a GLM starting method,
whose empty-tree coefficients form the preconsistency vector).

>>> from tableau_lab.analysis.trees import trees_of_order, order, density
>>> E = exact_flow(4)
>>> EE = compose(E, E, 4)
>>> all(EE[t] == sp.Rational(2 ** order(t), density(t)) for t in trees_of_order(4))
True
"""
from __future__ import annotations

from functools import lru_cache

import sympy as sp

from .trees import density, trees_up_to

__all__ = ["exact_flow", "identity", "compose", "inverse", "stage_derivative", "kept_cuts", "flow_cuts"]


def exact_flow(max_order: int) -> dict:
    """E(∅) = 1, E(t) = 1/γ(t)."""
    out = {None: sp.Integer(1)}
    out.update({t: sp.Rational(1, density(t)) for t in trees_up_to(max_order)})
    return out


def identity(max_order: int) -> dict:
    """e(∅) = 1, e(t) = 0: the identity map."""
    out = {None: sp.Integer(1)}
    out.update({t: sp.Integer(0) for t in trees_up_to(max_order)})
    return out


def stage_derivative(a: dict, max_order: int) -> dict:
    """a′ with h f(B(a, y)) = B(a′, y) for a(∅) = 1: a′(∅) = 0, a′(τ) = 1, a′([t₁…t_m]) = Π a(tᵢ)."""
    out = {None: 0}
    for t in trees_up_to(max_order):
        v = 1
        for c in t:
            v = v * a[c]
        out[t] = v
    return out


def kept_cuts(t, inner) -> dict:
    """The cuts of t that keep the root: {trunk: Σ Π inner(pruned part)}.
    ``inner`` maps a tree to its coefficient; the trunk t itself (no cut) has coefficient 1."""
    acc = {(): 1}
    for c in t:
        options = {None: inner(c)}
        options.update(kept_cuts(c, inner))
        new = {}
        for trunk, coef in acc.items():
            for sub, cf in options.items():
                key = trunk if sub is None else tuple(sorted(trunk + (sub,)))
                new[key] = new.get(key, 0) + coef * cf
        acc = new
    return acc


@lru_cache(maxsize=None)
def flow_cuts(t) -> tuple:
    """(trunk, Σ Π 1/γ(pruned)) over the root-keeping cuts of t other than t itself (cached):
    the exact flow applied first, as in S∘E."""
    cuts = kept_cuts(t, lambda c: sp.Rational(1, density(c)))
    return tuple((trunk, coef) for trunk, coef in cuts.items() if trunk != t)


def compose(a: dict, b: dict, max_order: int) -> dict:
    """a·b (a applied first), up to max_order; a(∅) must be 1."""
    if a.get(None, 1) != 1:
        raise ValueError("the inner series of a composition must have a(∅) = 1")
    out = {None: b.get(None, 1)}
    for t in trees_up_to(max_order):
        v = b.get(None, 1) * a[t]
        for trunk, coef in kept_cuts(t, lambda c: a[c]).items():
            v = v + coef * b[trunk]
        out[t] = v
    return out


def inverse(a: dict, max_order: int) -> dict:
    """a⁻¹ in the Butcher group (a(∅) = 1): a·a⁻¹ = identity."""
    if a.get(None, 1) != 1:
        raise ValueError("only series with a(∅) = 1 are invertible in the Butcher group")
    beta = {None: 1}
    for t in trees_up_to(max_order):
        acc = a[t]
        for trunk, coef in kept_cuts(t, lambda c: a[c]).items():
            if trunk != t:
                acc = acc + coef * beta[trunk]
        beta[t] = -acc
    return beta
