r"""Plain and bicoloured rooted trees behind one interface, so that each recursion over trees
is written once and serves B-series of Runge–Kutta methods and P-series of partitioned ones
([HLW06] III.1, III.2.1, VI.7.3; Chartier, Hairer & Vilmart 2010, Sec. 5): the enumeration
(:func:`forests`, ``kind.trees_of_order``), order, density and symmetry, the notations, the
elementary weights (:meth:`TreeKind.elementary_weights`, used by :mod:`rk_order` and
:mod:`prk_order`), cuts, the substitution law and grafting.  :mod:`trees` adds what only plain
trees have (Butcher's product, leaf removal, parsing of bracket notation) on top of this module.

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

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from functools import lru_cache
from math import factorial
from typing import Any

__all__ = ["TreeKind", "PLAIN", "BICOLOURED", "Tree", "Coefficients", "children", "order", "density", "symmetry",
           "forests", "bicoloured_trees", "plain_differential", "SUPERSCRIPTS", "labelled", "rebuild", "partitions",
           "kept_cuts", "graft"]


Tree = tuple   # a plain tree: the sorted tuple of its children; bicoloured: (colour, sorted children)
Coefficients = dict[Tree | None, Any]   # a series' coefficients {tree: value}, None the empty tree ∅


def forests(m: int, trees_of: Callable[[int], tuple], bound: tuple | None = None) -> Iterator[tuple]:
    """Every multiset of trees with m vertices in all, once, as a tuple in decreasing (order, tree);
    ``trees_of(k)`` lists the trees with k vertices (plain or coloured), ``bound`` the largest
    (order, tree) allowed first."""
    if m == 0:
        yield ()
        return
    for k in range(min(m, bound[0]) if bound else m, 0, -1):
        for t in trees_of(k):
            if bound is None or (k, t) <= bound:
                for rest in forests(m - k, trees_of, (k, t)):
                    yield (t,) + rest


def bicoloured_trees(n: int) -> tuple:
    """All bicoloured rooted trees with n vertices (counts 2, 4, 14, 52, 214, ...: OEIS A000151)."""
    return BICOLOURED.trees_of_order(n)


@dataclass(frozen=True)
class TreeKind:
    """Plain (``coloured=False``) or bicoloured trees."""

    name: str
    coloured: bool

    @property
    def labels(self) -> tuple:
        """The labels a vertex can carry: (None,) for plain trees, the colours (0, 1) otherwise."""
        return (0, 1) if self.coloured else (None,)

    def split(self, t: Tree) -> tuple:
        return t if self.coloured else (None, t)

    def children(self, t: Tree) -> tuple:
        return t[1] if self.coloured else t

    def make(self, label: int | None, children: Iterable[Tree]) -> Tree:
        ch = tuple(sorted(children))
        return (label, ch) if self.coloured else ch

    def trees_of_order(self, n: int) -> tuple:
        """All trees with n vertices, canonical and sorted: the labelled root over every forest of
        n − 1 vertices (OEIS A000081 plain, A000151 bicoloured)."""
        return _trees_of_order(self, n)

    def trees_up_to(self, n: int) -> Iterator[Tree]:
        for k in range(1, n + 1):
            yield from self.trees_of_order(k)

    def leaves(self) -> tuple:
        """The one-vertex trees (τ; or τ● and τ○)."""
        return self.trees_of_order(1)

    def order(self, t: Tree) -> int:
        """|t|, the number of vertices (:func:`order`)."""
        return order(t)

    def density(self, t: Tree) -> int:
        """γ(t) (:func:`density`)."""
        return density(t)

    def symmetry(self, t: Tree) -> int:
        """σ(t) (:func:`symmetry`)."""
        return symmetry(t)

    def bracket(self, t: Tree) -> str:
        """Butcher's bracket notation: τ, [τ], [τ²], [[τ]], [τ[τ]], ...; bicoloured: ●, ○, [○]●, ..."""
        return _bracket(t) if self.coloured else _plain_bracket(t)

    def tex(self, t: Tree) -> str:
        """The tree in LaTeX: nested brackets of τ, or of bullets (● \\bullet, ○ \\circ) when bicoloured."""
        if not self.coloured:
            return _plain_latex(t)
        return self.bracket(t).replace("●", r"\bullet ").replace("○", r"\circ ")

    def differential(self, t: Tree, tex: bool = False) -> str:
        """F(t): f'f, f''(f, f), … for plain trees; for bicoloured ones q′ = f(q, p), p′ = g(q, p)
        with partial derivatives as subscripts: f_p g, g_qq(f, f), … ([HLW06] III.2.1)."""
        return _pdifferential(t, tex) if self.coloured else plain_differential(t, tex=tex)

    def elementary_weights(self, A: Any, b: Any, zero: Any, one: Any) -> Callable[[Tree], Any]:
        """t ↦ Φ(t) = b_{ℓ(t)}ᵀΨ(t), Ψ(t) = Π over the children c of A_{ℓ(c)}Ψ(c) (componentwise),
        ℓ the label of a vertex ([HNW93] II.2, [HLW06] III.1.4; partitioned: III.2.1).  A plain
        kind takes one matrix and weight vector; a bicoloured one the pairs (A, Â) and (b, b̂)
        indexed by colour.  Entries are any ring elements with +, * (``zero``, ``one`` its
        identities); the stage vectors Ψ(t) and A_{ℓ(t)}Ψ(t) are cached across trees.

        >>> import sympy as sp
        >>> h = sp.Rational(1, 2)
        >>> phi = PLAIN.elementary_weights([[0, 0], [1, 0]], [h, h], 0, 1)     # Heun's method
        >>> [phi(t) for t in PLAIN.trees_up_to(3)]
        [1, 1/2, 1/2, 0]
        >>> phi = BICOLOURED.elementary_weights(([[1]], [[0]]), ([1], [1]), 0, 1)   # symplectic Euler
        >>> [(BICOLOURED.bracket(t), phi(t)) for t in BICOLOURED.trees_of_order(2)]
        [('[●]●', 1), ('[○]●', 0), ('[●]○', 1), ('[○]○', 0)]
        """
        mats = dict(zip(self.labels, A if self.coloured else (A,), strict=True))
        weights = dict(zip(self.labels, b if self.coloured else (b,), strict=True))
        s = len(weights[self.labels[0]])
        split = self.split
        psi: dict = {}       # t ↦ Ψ(t)
        apsi: dict = {}      # t ↦ A_{ℓ(t)}Ψ(t)

        def stage(t: Tree) -> list:
            v = psi.get(t)
            if v is None:
                v = [one] * s
                for c in split(t)[1]:
                    w = apsi.get(c)
                    if w is None:
                        pc = stage(c)
                        w = apsi[c] = [sum((a * x for a, x in zip(row, pc, strict=True)), zero)
                                       for row in mats[split(c)[0]]]
                    v = [x * y for x, y in zip(v, w, strict=True)]
                psi[t] = v
            return v

        def phi(t: Tree) -> Any:
            return sum((bi * x for bi, x in zip(weights[split(t)[0]], stage(t), strict=True)), zero)
        return phi


PLAIN = TreeKind("plain", False)
BICOLOURED = TreeKind("bicoloured", True)


@lru_cache(maxsize=None)
def _trees_of_order(kind: TreeKind, n: int) -> tuple:
    if n < 1:
        return ()
    return tuple(sorted({kind.make(label, f) for f in forests(n - 1, kind.trees_of_order) for label in kind.labels}))


def children(t: Tree) -> tuple:
    """The children of a plain or a bicoloured tree: the two representations tell themselves apart,
    a bicoloured tree starting with its colour (an int), a plain one with a child (a tuple).

    >>> children(((), ((),))), children((1, ((0, ()),)))
    (((), ((),)), ((0, ()),))
    """
    return t[1] if t and type(t[0]) is int else t


@lru_cache(maxsize=None)
def order(t: Tree) -> int:
    """|t|, the number of vertices of a plain or bicoloured tree."""
    return 1 + sum(order(c) for c in children(t))


@lru_cache(maxsize=None)
def density(t: Tree) -> int:
    """γ(t) = |t| Π γ(children) ([HLW06] III.1.2), plain or bicoloured (the colours do not enter)."""
    g = order(t)
    for c in children(t):
        g *= density(c)
    return g


@lru_cache(maxsize=None)
def symmetry(t: Tree) -> int:
    """σ(t) = Π over distinct children c of m_c! σ(c)^{m_c} ([HLW06] III.1.3), plain or bicoloured
    (children of different colours are different)."""
    ch = children(t)
    out = 1
    for c in set(ch):
        m = ch.count(c)
        out *= factorial(m) * symmetry(c) ** m
    return out


#: superscript digits of the bracket notation's multiplicities (τ² for τ τ)
SUPERSCRIPTS = "⁰¹²³⁴⁵⁶⁷⁸⁹"


def _groups(t: Tree) -> Iterator[tuple]:
    """(child, multiplicity) over a plain tree's children, in order."""
    i = 0
    while i < len(t):
        j = i
        while j < len(t) and t[j] == t[i]:
            j += 1
        yield t[i], j - i
        i = j


def _multiplicity(n: int) -> str:
    return "".join(SUPERSCRIPTS[int(d)] for d in str(n)) if n > 1 else ""


@lru_cache(maxsize=None)
def _plain_bracket(t: Tree) -> str:
    if t == ():
        return "τ"
    return "[" + "".join(_plain_bracket(c) + _multiplicity(n) for c, n in _groups(t)) + "]"


@lru_cache(maxsize=None)
def _plain_latex(t: Tree) -> str:
    if t == ():
        return r"\tau"
    return "[" + "".join(_plain_latex(c) + (f"^{{{n}}}" if n > 1 else "") for c, n in _groups(t)) + "]"


_PRIMES = ("", "′", "″", "‴")


@lru_cache(maxsize=None)
def plain_differential(t: Tree, ascii: bool = True, tex: bool = False) -> str:
    """The elementary differential F(t) of a plain tree in the usual notation ([HLW06] III.1.1): f,
    f'f, f''(f, f), f'f'f, ...; f^(m) for m > 3 derivatives (f^{(m)} with ``tex``); primes as ′ ″ ‴
    with ``ascii=False``."""
    if t == ():
        return "f"
    m = len(t)
    head = "f" + (_PRIMES[m] if m < 4 else (f"^{{({m})}}" if tex else f"^({m})"))
    if ascii:
        head = head.replace("′", "'").replace("″", "''").replace("‴", "'''")
    args = [plain_differential(c, ascii, tex) for c in t]
    if m == 1:
        return head + args[0]
    return head + "(" + ", ".join(args) + ")"


@lru_cache(maxsize=None)
def _bracket(t: Tree) -> str:
    mark = {0: "●", 1: "○"}.get(t[0], "")
    return mark if not t[1] else "[" + "".join(_bracket(c) for c in t[1]) + "]" + mark


@lru_cache(maxsize=None)
def _pdifferential(t: Tree, tex: bool) -> str:
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
        kids: list[list[int]] = [[] for _ in range(n)]      # children inside the piece
        skel: list[list[int]] = [[] for _ in range(n)]      # for piece roots: the roots of the pieces hanging below
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
        new: dict[tuple, Any] = {}
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
    kids: list[list[int]] = [[] for _ in parent]
    for v in range(1, len(parent)):
        kids[parent[v]].append(v)
    return tuple(rebuild(kind, kids, label, 0, {v: [s]}) for v in range(len(parent)))
