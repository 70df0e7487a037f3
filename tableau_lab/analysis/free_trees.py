r"""Free (unrooted) trees and the elementary Hamiltonians of rooted trees ([HLW06] VI.7.2 and
IX.9; Chartier, Faou & Murua, *Numer. Math.* 103 (2006)).

For a Hamiltonian system y′ = J⁻¹∇H(y) the **elementary Hamiltonian** of a rooted tree
t = [t₁ … t_m] is H(t)(y) = H⁽ᵐ⁾(y)(F(t₁)(y), …, F(t_m)(y)): one derivative tensor of H per
vertex, one J⁻¹ per edge, oriented towards the root.  Moving the root along an edge reverses one
J⁻¹, so H(u∘v) = −H(v∘u): all rootings of a free tree π give ±H(π), with the sign (−1)^d, d the
distance from the root to the **centre** of π (the canonical rooting).  When the two halves at a
central edge are equal (u∘u), H(π) = −H(π) = 0: π is **superfluous**.

>>> from tableau_lab.analysis.trees import parse_tree, bracket
>>> a, b = free_tree(parse_tree("[τ²]")), free_tree(parse_tree("[[τ]]"))
>>> a.key == b.key, a.sign, b.sign, a.symmetry
(True, 1, -1, 2)
>>> free_tree(parse_tree("[τ]")).superfluous, free_tree(parse_tree("[[τ][τ]]")).superfluous
(True, False)
>>> [len(free_trees_of_order(n)) for n in range(1, 11)]   # OEIS A000055
[1, 1, 1, 2, 3, 6, 11, 23, 47, 106]

Bicoloured trees (P-series, [HLW06] IX.10): colour 0 (q) or 1 (p) of a vertex says which variable
its parent differentiates; an edge pairs a q-derivative at one end with a p-derivative at the other,
so moving the root across it swaps the colour of the edge's lower end (c ↦ 1 − c) and changes the
sign, and the root itself carries no colour (NO_COLOUR).  No bicoloured free tree is superfluous:
an automorphism cannot swap the q-end and the p-end of an edge.

>>> from tableau_lab.analysis.tree_kinds import BICOLOURED as B
>>> a = free_tree(B.make(0, [B.make(1, [])]), B)            # [τ○]●: the p-vertex hangs below
>>> b = free_tree(B.make(1, [B.make(1, [])]), B)
>>> a.key == b.key, a.sign * b.sign, a.superfluous
(True, 1, False)
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

from .tree_kinds import PLAIN, TreeKind, labelled

__all__ = ["FreeTree", "free_tree", "free_trees_of_order", "rootings", "NO_COLOUR"]

#: the label of the root of a bicoloured free tree: an elementary Hamiltonian's root is H itself
NO_COLOUR = -1


@dataclass(frozen=True)
class FreeTree:
    """The free tree of a rooted tree t: ``key`` is the canonical rooted tree (rooted at the
    centre; for two centres, the smaller of the two rootings), ``sign`` = (−1)^d with d the
    distance from t's root to that canonical root (H(t) = sign · H(key)), ``superfluous`` when
    the tree is u∘u at its central edge (then H ≡ 0), ``symmetry`` = |Aut(π)|."""

    key: tuple
    sign: int
    superfluous: bool
    symmetry: int


def _rooted_at(kind, adj, lab, v, up=-1, root=True):
    """The tree rooted at v; a bicoloured child w of u gets the colour of the edge as seen from u."""
    ch = [_rooted_at(kind, adj, lab, w, v, False) for w in adj[v] if w != up]
    if not kind.coloured:
        return kind.make(None, ch)
    return kind.make(NO_COLOUR if root else lab(v, up), ch)


@lru_cache(maxsize=None)
def free_tree(t, kind: TreeKind = PLAIN) -> FreeTree:
    """The free tree of ``t`` with the sign of t's rooting; see :class:`FreeTree`."""
    parent, label = labelled(kind, t)
    n = len(parent)
    adj: list[list[int]] = [[] for _ in range(n)]
    for v in range(1, n):
        adj[v].append(parent[v])
        adj[parent[v]].append(v)

    def lab(v, up):
        """The colour of v as a child of up: its own label if up is its parent in t, else flipped."""
        return label[v] if parent[v] == up else 1 - label[up]

    # the centre: peel leaves layer by layer
    degree = [len(a) for a in adj]
    layer = [v for v in range(n) if degree[v] <= 1]
    left = n
    while left > 2:
        left -= len(layer)
        nxt = []
        for v in layer:
            for w in adj[v]:
                degree[w] -= 1
                if degree[w] == 1:
                    nxt.append(w)
        layer = nxt
    centres = layer if n > 1 else [0]
    depth = [0] * n                          # distance from t's root
    for v in range(1, n):
        depth[v] = depth[parent[v]] + 1
    if len(centres) == 1:
        c = centres[0]
        key = _rooted_at(kind, adj, lab, c)
        return FreeTree(key, (-1) ** depth[c], False, kind.symmetry(key))
    c1, c2 = centres
    k1, k2 = _rooted_at(kind, adj, lab, c1), _rooted_at(kind, adj, lab, c2)
    c = c1 if k1 <= k2 else c2
    # |Aut| of a non-superfluous bicentral tree: automorphisms fix the central edge, and no child of
    # c1 is a twin of the c2-half (it would be one level deeper than the centre allows): σ(k1)
    return FreeTree(min(k1, k2), (-1) ** depth[c], k1 == k2, kind.symmetry(k1))


@lru_cache(maxsize=None)
def rootings(n: int, kind: TreeKind = PLAIN) -> dict:
    """{free tree key: ((rooted tree, sign), ...)} over all rooted trees of order n."""
    out: dict = {}
    for t in kind.trees_of_order(n):
        ft = free_tree(t, kind)
        out.setdefault(ft.key, []).append((t, ft.sign))
    return {k: tuple(v) for k, v in out.items()}


def free_trees_of_order(n: int, kind: TreeKind = PLAIN) -> tuple:
    """The canonical keys of the free trees with n vertices (OEIS A000055 for plain trees),
    superfluous ones included."""
    return tuple(sorted(rootings(n, kind)))
