r"""Rooted trees ([B16] ch. 3; [HLW06] III.1; Butcher, *B-Series* (2021) ch. 2).

A tree is the sorted tuple of its children's trees: τ = (), [τ] = ((),), [τ²] = ((), ()).
Trees are hashable, totally ordered and canonical, so equal trees are equal tuples.

>>> [len(trees_of_order(n)) for n in range(1, 9)]
[1, 1, 2, 4, 9, 20, 48, 115]
>>> t = from_children([TAU, from_children([TAU])])          # [τ[τ]]
>>> bracket(t), order(t), density(t), symmetry(t)
('[τ[τ]]', 4, 8, 1)
>>> bracket(butcher_product(TAU, TAU)), symmetry(from_children([TAU, TAU]))
('[τ]', 2)
>>> [bracket(u) for u in subtrees(t)]
['[τ[τ]]', 'τ', '[τ]', 'τ']
"""
from __future__ import annotations

from functools import lru_cache
from math import factorial

__all__ = ["TAU", "trees_of_order", "trees_up_to", "from_children", "order", "density", "symmetry",
           "butcher_product", "bracket", "latex", "leaf_removals", "subtrees"]

TAU = ()


def from_children(children) -> tuple:
    """The tree [t₁ … t_m] with the given children."""
    return tuple(sorted(children))


@lru_cache(maxsize=None)
def trees_of_order(n: int) -> tuple:
    """All rooted trees with n vertices, canonical and sorted (OEIS A000081)."""
    if n < 1:
        return ()
    if n == 1:
        return (TAU,)
    out = set()

    def forests(rem, bound):
        if rem == 0:
            yield ()
            return
        for k in range(min(rem, bound[0]), 0, -1):
            for t in trees_of_order(k):
                if (k, t) <= bound:
                    for rest in forests(rem - k, (k, t)):
                        yield (t,) + rest

    for f in forests(n - 1, (n, ())):
        out.add(tuple(sorted(f)))
    return tuple(sorted(out))


def trees_up_to(n: int):
    """All trees of orders 1..n, by order."""
    for k in range(1, n + 1):
        yield from trees_of_order(k)


@lru_cache(maxsize=None)
def order(t) -> int:
    """|t|, the number of vertices."""
    return 1 + sum(order(c) for c in t)


@lru_cache(maxsize=None)
def density(t) -> int:
    """γ(t) = |t| Π γ(children)."""
    g = order(t)
    for c in t:
        g *= density(c)
    return g


@lru_cache(maxsize=None)
def symmetry(t) -> int:
    """σ(t) = Π over distinct children c of m_c! σ(c)^{m_c}."""
    out = 1
    for c in set(t):
        m = t.count(c)
        out *= factorial(m) * symmetry(c) ** m
    return out


def butcher_product(t, u) -> tuple:
    """t ∘ u: the tree u grafted onto the root of t."""
    return from_children(t + (u,))


def _groups(t):
    i = 0
    while i < len(t):
        j = i
        while j < len(t) and t[j] == t[i]:
            j += 1
        yield t[i], j - i
        i = j


_SUP = "⁰¹²³⁴⁵⁶⁷⁸⁹"


@lru_cache(maxsize=None)
def bracket(t) -> str:
    """Butcher's bracket notation: τ, [τ], [τ²], [[τ]], [τ[τ]], ..."""
    if t == TAU:
        return "τ"
    return "[" + "".join(bracket(c) + ("".join(_SUP[int(d)] for d in str(n)) if n > 1 else "")
                         for c, n in _groups(t)) + "]"


@lru_cache(maxsize=None)
def latex(t) -> str:
    r"""Bracket notation in LaTeX: ``\tau``, ``[\tau^{2}]``, ..."""
    if t == TAU:
        return r"\tau"
    return "[" + "".join(latex(c) + (f"^{{{n}}}" if n > 1 else "") for c, n in _groups(t)) + "]"


@lru_cache(maxsize=None)
def leaf_removals(t) -> tuple:
    """The trees obtained by removing one leaf (not the root), with multiplicity."""
    out = []
    for i, c in enumerate(t):
        rest = t[:i] + t[i + 1:]
        if c == TAU:
            out.append(tuple(sorted(rest)))
        else:
            out.extend(tuple(sorted(rest + (c2,))) for c2 in leaf_removals(c))
    return tuple(out)


@lru_cache(maxsize=None)
def subtrees(t) -> tuple:
    """The subtree rooted at each vertex of t (t itself first, then depth first), with
    multiplicity; γ(t) is the product of their orders."""
    out = [t]
    for c in t:
        out.extend(subtrees(c))
    return tuple(out)
