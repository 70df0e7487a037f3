r"""Plain and bicoloured rooted trees behind one interface, so that the algebra of B-series
(cuts, the substitution law, free trees, grafting) is written once and serves P-series of
partitioned methods too ([HLW06] III.2.1, VI.7.3; Chartier, Hairer & Vilmart 2010, Sec. 5).

A plain tree is the sorted tuple of its children (:mod:`trees`); a bicoloured tree is
``(colour, sorted children)`` with colour 0 for the first partition (q, tableau A, b) and 1 for the
second (p, Â, b̂), as in :mod:`prk_order`.  ``kind.split(t)`` gives (label, children) and
``kind.make(label, children)`` the canonical tree back; a plain tree's label is ``None``.

>>> BICOLOURED.make(1, [(0, ()), (1, ())]) == (1, ((0, ()), (1, ())))
True
>>> [len(BICOLOURED.trees_of_order(n)) for n in range(1, 6)]       # OEIS A000151 (×2)
[2, 4, 14, 52, 214]
>>> t = BICOLOURED.make(0, [BICOLOURED.make(1, [])])
>>> BICOLOURED.bracket(t), BICOLOURED.symmetry(t), BICOLOURED.density(t)
('[○]●', 1, 2)
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from math import factorial

from . import trees as _plain

__all__ = ["TreeKind", "PLAIN", "BICOLOURED", "bicoloured_trees", "labelled", "rebuild", "partitions",
           "kept_cuts", "graft"]


@lru_cache(maxsize=None)
def bicoloured_trees(n: int) -> tuple:
    """All bicoloured rooted trees with n vertices (counts 2, 4, 14, 52, 214, ...: OEIS A000151)."""
    if n == 1:
        return ((0, ()), (1, ()))
    return tuple(sorted({(colour, tuple(sorted(f))) for f in _plain.forests(n - 1, bicoloured_trees)
                         for colour in (0, 1)}))


@dataclass(frozen=True)
class TreeKind:
    """Plain (``coloured=False``) or bicoloured trees."""

    name: str
    coloured: bool

    def split(self, t) -> tuple:
        return t if self.coloured else (None, t)

    def children(self, t) -> tuple:
        return t[1] if self.coloured else t

    def make(self, label, children) -> tuple:
        ch = tuple(sorted(children))
        return (label, ch) if self.coloured else ch

    def trees_of_order(self, n: int) -> tuple:
        return bicoloured_trees(n) if self.coloured else _plain.trees_of_order(n)

    def trees_up_to(self, n: int):
        for k in range(1, n + 1):
            yield from self.trees_of_order(k)

    def leaves(self) -> tuple:
        """The one-vertex trees (τ; or τ● and τ○)."""
        return self.trees_of_order(1)

    def order(self, t) -> int:
        return _order(self, t)

    def density(self, t) -> int:
        return _density(self, t)

    def symmetry(self, t) -> int:
        return _symmetry(self, t)

    def bracket(self, t) -> str:
        return _bracket(self, t)

    def tex(self, t) -> str:
        """The tree in LaTeX: nested brackets of τ, or of bullets (● \\bullet, ○ \\circ) when bicoloured."""
        return _plain.latex(t) if not self.coloured else self.bracket(t).replace("●", r"\bullet ").replace("○", r"\circ ")

    def differential(self, t, tex: bool = False) -> str:
        """F(t): f'f, f''(f, f), … for plain trees; for bicoloured ones q′ = f(q, p), p′ = g(q, p)
        with partial derivatives as subscripts: f_p g, g_qq(f, f), … ([HLW06] III.2.1)."""
        return _plain.differential(t, tex=tex) if not self.coloured else _pdifferential(t, tex)


PLAIN = TreeKind("plain", False)
BICOLOURED = TreeKind("bicoloured", True)


@lru_cache(maxsize=None)
def _order(kind, t) -> int:
    return 1 + sum(_order(kind, c) for c in kind.children(t))


@lru_cache(maxsize=None)
def _density(kind, t) -> int:
    g = _order(kind, t)
    for c in kind.children(t):
        g *= _density(kind, c)
    return g


@lru_cache(maxsize=None)
def _symmetry(kind, t) -> int:
    ch = kind.children(t)
    out = 1
    for c in set(ch):
        m = ch.count(c)
        out *= factorial(m) * _symmetry(kind, c) ** m
    return out


@lru_cache(maxsize=None)
def _bracket(kind, t) -> str:
    if not kind.coloured:
        return _plain.bracket(t)
    mark = {0: "●", 1: "○"}.get(t[0], "")
    return mark if not t[1] else "[" + "".join(_bracket(kind, c) for c in t[1]) + "]" + mark


@lru_cache(maxsize=None)
def _pdifferential(t, tex: bool) -> str:
    colour, ch = t
    head = "f" if colour == 0 else "g"
    if not ch:
        return head
    sub = "".join("q" if c[0] == 0 else "p" for c in ch)
    head += f"_{{{sub}}}" if tex else f"_{sub}"
    args = [_pdifferential(c, tex) for c in ch]
    return head + (" " + args[0] if len(args) == 1 else "(" + ", ".join(args) + ")")


@lru_cache(maxsize=None)
def labelled(kind: TreeKind, t) -> tuple:
    """(parent, label): vertex 0 is the root, vertices are numbered depth first, parent[v] < v."""
    parent, label = [], []

    def walk(node, up):
        lab, ch = kind.split(node)
        parent.append(up)
        label.append(lab)
        v = len(parent) - 1
        for c in ch:
            walk(c, v)

    walk(t, -1)
    return tuple(parent), tuple(label)


def rebuild(kind: TreeKind, kids, label, v, extra=None) -> tuple:
    """The canonical subtree at v of a tree given by child lists and labels (``extra``: {vertex:
    [trees to graft there]})."""
    ch = [rebuild(kind, kids, label, c, extra) for c in kids[v]]
    if extra and v in extra:
        ch += extra[v]
    return kind.make(label[v], ch)


@lru_cache(maxsize=None)
def partitions(kind: TreeKind, t) -> tuple:
    """The partitions of t into subtrees for the substitution law (Chartier, Hairer & Vilmart 2010,
    Sec. 3.2; coloured: Sec. 5): each subset of the edges is kept, the pieces are the components and
    the skeleton contracts each piece to one vertex, labelled as the piece's root.  Returns
    ((skeleton, pieces, multiplicity), ...) over the 2^(|t|−1) edge subsets; pieces sorted."""
    parent, label = labelled(kind, t)
    n = len(parent)
    out: dict = {}
    for mask in range(1 << (n - 1)):
        keep = [False] + [bool(mask >> (v - 1) & 1) for v in range(1, n)]   # edge v–parent(v) kept
        top = list(range(n))                                               # the root of v's piece
        for v in range(1, n):
            if keep[v]:
                top[v] = top[parent[v]]
        kids = [[] for _ in range(n)]      # children inside the piece
        skel = [[] for _ in range(n)]      # for piece roots: the roots of the pieces hanging below
        for v in range(1, n):
            if keep[v]:
                kids[parent[v]].append(v)
            else:
                skel[top[parent[v]]].append(v)
        key = (rebuild(kind, skel, label, 0),
               tuple(sorted(rebuild(kind, kids, label, r) for r in range(n) if top[r] == r)))
        out[key] = out.get(key, 0) + 1
    return tuple(sorted(((s, ps, m) for (s, ps), m in out.items()),
                        key=lambda x: (kind.order(x[0]), x[0], x[1])))


def kept_cuts(kind: TreeKind, t, inner, one=1) -> dict:
    """The cuts of t that keep the root: {trunk: Σ Π inner(pruned part)}; the trunk t itself (no
    cut) has coefficient 1 (``one``)."""
    lab, ch = kind.split(t)
    acc = {(): one}                       # sorted tuple of the trunk's kept children
    for c in ch:
        options = {None: inner(c)}
        options.update(kept_cuts(kind, c, inner, one))
        new = {}
        for trunk, coef in acc.items():
            for sub, cf in options.items():
                key = trunk if sub is None else tuple(sorted(trunk + (sub,)))
                new[key] = new[key] + coef * cf if key in new else coef * cf
        acc = new
    return {kind.make(lab, k): v for k, v in acc.items()}


@lru_cache(maxsize=None)
def graft(kind: TreeKind, t, s) -> tuple:
    """The trees t with s grafted on one vertex, one per vertex of t (with repetitions)."""
    parent, label = labelled(kind, t)
    kids = [[] for _ in parent]
    for v in range(1, len(parent)):
        kids[parent[v]].append(v)
    return tuple(rebuild(kind, kids, label, 0, {v: [s]}) for v in range(len(parent)))
