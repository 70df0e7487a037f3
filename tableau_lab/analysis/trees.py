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
>>> parse_tree("[t[t^2]]") == parse_tree("[[τ²]τ]"), differential(parse_tree("[τ[τ]]"))
(True, "f''(f, f'f)")
"""
from __future__ import annotations

import re
from functools import lru_cache
from math import factorial

__all__ = ["bracket_tex", "TAU", "trees_of_order", "trees_up_to", "from_children", "order", "density", "symmetry",
           "butcher_product", "bracket", "latex", "leaf_removals", "subtrees", "parse_tree", "TreeError",
           "differential", "forests"]

TAU = ()


def from_children(children) -> tuple:
    """The tree [t₁ … t_m] with the given children."""
    return tuple(sorted(children))


@lru_cache(maxsize=None)
def trees_of_order(n: int) -> tuple:
    """All rooted trees with n vertices, canonical and sorted (OEIS A000081; [B16] ch. 3,
    Butcher 1963).

    >>> import tableau_lab as tl
    >>> [len(tl.trees_of_order(n)) for n in range(1, 9)]
    [1, 1, 2, 4, 9, 20, 48, 115]
    """
    if n < 1:
        return ()
    if n == 1:
        return (TAU,)
    return tuple(sorted({tuple(sorted(f)) for f in forests(n - 1, trees_of_order)}))


def forests(m: int, trees_of, bound=None):
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


def bracket_tex(b: str) -> str:
    r"""A tree written in bracket notation (:func:`bracket`, τ and superscript multiplicities) in
    LaTeX, for tables keyed by brackets.

    >>> bracket_tex("[τ¹²[τ]]")
    '[\\tau ^{12}[\\tau ]]'
    """
    return re.sub(f"[{_SUP}]+", lambda m: "^{" + "".join(_SUPER_DIGITS[c] for c in m[0]) + "}", b.replace("τ", r"\tau "))


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


class TreeError(ValueError):
    """Text that is not a tree in bracket notation."""


_SUPER_DIGITS = {c: str(i) for i, c in enumerate(_SUP)}
#: the longest text and the most vertices parse_tree reads
TREE_TEXT_MAX, TREE_ORDER_MAX = 400, 40


def parse_tree(text: str) -> tuple:
    """A tree from bracket notation: ``τ`` (or ``t``), ``[τ²]`` (or ``[t^2]``, ``[t t]``),
    ``[τ[τ]]``; the inverse of :func:`bracket`.  Whitespace is ignored; at most
    TREE_TEXT_MAX characters and TREE_ORDER_MAX vertices."""
    if not isinstance(text, str) or len(text) > TREE_TEXT_MAX:
        raise TreeError(f"a tree is a string of at most {TREE_TEXT_MAX} characters in bracket notation such as '[τ[τ]]'")
    s = "".join(text.split())
    pos = 0

    def power():
        nonlocal pos
        digits = ""
        if pos < len(s) and s[pos] == "^":
            pos += 1
            while pos < len(s) and s[pos] in "0123456789":
                digits += s[pos]
                pos += 1
            if not digits:
                raise TreeError(f"{text!r}: '^' must be followed by a count")
        else:
            while pos < len(s) and s[pos] in _SUPER_DIGITS:
                digits += _SUPER_DIGITS[s[pos]]
                pos += 1
        return int(digits) if digits else 1

    def tree(depth):
        nonlocal pos
        if depth > TREE_ORDER_MAX:
            raise TreeError(f"{text!r}: more than {TREE_ORDER_MAX} vertices")
        if pos < len(s) and s[pos] in "τt":
            pos += 1
            return TAU
        if pos < len(s) and s[pos] == "[":
            pos += 1
            kids = []
            while pos < len(s) and s[pos] != "]":
                c = tree(depth + 1)
                n = power()
                if n < 1 or len(kids) + n > TREE_ORDER_MAX:
                    raise TreeError(f"{text!r}: more than {TREE_ORDER_MAX} vertices")
                kids.extend([c] * n)
            if pos >= len(s):
                raise TreeError(f"{text!r}: missing ']'")
            pos += 1
            if not kids:
                raise TreeError(f"{text!r}: '[]' is not a tree (write τ for the single vertex)")
            return from_children(kids)
        raise TreeError(f"{text!r}: expected τ, t or '[' at character {pos + 1}")

    t = tree(0)
    if pos != len(s):
        raise TreeError(f"{text!r}: unexpected {s[pos]!r} at character {pos + 1}")
    if order(t) > TREE_ORDER_MAX:
        raise TreeError(f"{text!r}: {order(t)} vertices; at most {TREE_ORDER_MAX}")
    return t


_PRIMES = ("", "′", "″", "‴")


@lru_cache(maxsize=None)
def differential(t, ascii: bool = True, tex: bool = False) -> str:
    """The elementary differential F(t) in the usual notation ([HLW06] III.1.1): f, f'f,
    f''(f, f), f'f'f, ...; f^(m) for m > 3 derivatives (f^{(m)} with ``tex``); primes as ′ ″ ‴
    with ``ascii=False``."""
    if t == TAU:
        return "f"
    m = len(t)
    head = "f" + (_PRIMES[m] if m < 4 else (f"^{{({m})}}" if tex else f"^({m})"))
    if ascii:
        head = head.replace("′", "'").replace("″", "''").replace("‴", "'''")
    args = [differential(c, ascii, tex) for c in t]
    if m == 1:
        return head + args[0]
    return head + "(" + ", ".join(args) + ")"
