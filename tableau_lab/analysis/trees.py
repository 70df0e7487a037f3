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
from collections.abc import Iterable, Iterator
from functools import lru_cache

from .tree_kinds import PLAIN, SUPERSCRIPTS, Tree, density, forests, order, plain_differential, symmetry

__all__ = ["bracket_tex", "TAU", "trees_of_order", "trees_up_to", "from_children", "order", "density", "symmetry",
           "butcher_product", "bracket", "latex", "leaf_removals", "subtrees", "parse_tree", "TreeError",
           "differential", "forests", "Tree"]

TAU = ()


def from_children(children: Iterable[Tree]) -> Tree:
    """The tree [t₁ … t_m] with the given children."""
    return tuple(sorted(children))


def trees_of_order(n: int) -> tuple:
    """All rooted trees with n vertices, canonical and sorted (OEIS A000081; [B16] ch. 3,
    Butcher 1963).

    >>> import tableau_lab as tl
    >>> [len(tl.trees_of_order(n)) for n in range(1, 9)]
    [1, 1, 2, 4, 9, 20, 48, 115]
    """
    return PLAIN.trees_of_order(n)


def trees_up_to(n: int) -> Iterator[Tree]:
    """All trees of orders 1..n, by order."""
    return PLAIN.trees_up_to(n)


def butcher_product(t: Tree, u: Tree) -> Tree:
    """t ∘ u: the tree u grafted onto the root of t."""
    return from_children(t + (u,))


def bracket(t: Tree) -> str:
    """Butcher's bracket notation: τ, [τ], [τ²], [[τ]], [τ[τ]], ..."""
    return PLAIN.bracket(t)


def bracket_tex(b: str) -> str:
    r"""A tree written in bracket notation (:func:`bracket`, τ and superscript multiplicities) in
    LaTeX, for tables keyed by brackets.

    >>> bracket_tex("[τ¹²[τ]]")
    '[\\tau ^{12}[\\tau ]]'
    """
    return re.sub(f"[{SUPERSCRIPTS}]+", lambda m: "^{" + "".join(_SUPER_DIGITS[c] for c in m[0]) + "}",
                  b.replace("τ", r"\tau "))


def latex(t: Tree) -> str:
    r"""Bracket notation in LaTeX: ``\tau``, ``[\tau^{2}]``, ..."""
    return PLAIN.tex(t)


@lru_cache(maxsize=None)
def leaf_removals(t: Tree) -> tuple:
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
def subtrees(t: Tree) -> tuple:
    """The subtree rooted at each vertex of t (t itself first, then depth first), with
    multiplicity; γ(t) is the product of their orders."""
    out = [t]
    for c in t:
        out.extend(subtrees(c))
    return tuple(out)


class TreeError(ValueError):
    """Text that is not a tree in bracket notation."""


_SUPER_DIGITS = {c: str(i) for i, c in enumerate(SUPERSCRIPTS)}
#: the longest text and the most vertices parse_tree reads
TREE_TEXT_MAX, TREE_ORDER_MAX = 400, 40


def parse_tree(text: str) -> Tree:
    """A tree from bracket notation: ``τ`` (or ``t``), ``[τ²]`` (or ``[t^2]``, ``[t t]``),
    ``[τ[τ]]``; the inverse of :func:`bracket`.  Whitespace is ignored; at most
    TREE_TEXT_MAX characters and TREE_ORDER_MAX vertices."""
    if not isinstance(text, str) or len(text) > TREE_TEXT_MAX:
        raise TreeError(f"a tree is a string of at most {TREE_TEXT_MAX} characters in bracket notation "
                        "such as '[τ[τ]]'")
    return _BracketParser(text).whole()


class _BracketParser:
    """Recursive descent over bracket notation (:func:`parse_tree`): ``pos`` is the next character
    of ``s``, the text without whitespace; errors quote the text as given."""

    def __init__(self, text: str) -> None:
        self.text, self.s, self.pos = text, "".join(text.split()), 0

    def error(self, what: str) -> TreeError:
        return TreeError(f"{self.text!r}: {what}")

    def peek(self) -> str:
        return self.s[self.pos] if self.pos < len(self.s) else ""

    def whole(self) -> Tree:
        t = self.tree(0)
        if self.pos != len(self.s):
            raise self.error(f"unexpected {self.peek()!r} at character {self.pos + 1}")
        if order(t) > TREE_ORDER_MAX:
            raise self.error(f"{order(t)} vertices; at most {TREE_ORDER_MAX}")
        return t

    def digits(self, alphabet: dict | str) -> str:
        out = ""
        while self.peek() and self.peek() in alphabet:
            out += alphabet[self.peek()] if isinstance(alphabet, dict) else self.peek()
            self.pos += 1
        return out

    def power(self) -> int:
        """The multiplicity after a child: ^n, superscript digits, or 1."""
        if self.peek() != "^":
            return int(self.digits(_SUPER_DIGITS) or 1)
        self.pos += 1
        digits = self.digits("0123456789")
        if not digits:
            raise self.error("'^' must be followed by a count")
        return int(digits)

    def tree(self, depth: int) -> Tree:
        if depth > TREE_ORDER_MAX:
            raise self.error(f"more than {TREE_ORDER_MAX} vertices")
        c = self.peek()
        if c and c in "τt":
            self.pos += 1
            return TAU
        if c != "[":
            raise self.error(f"expected τ, t or '[' at character {self.pos + 1}")
        self.pos += 1
        kids: list = []
        while self.peek() not in ("]", ""):
            child = self.tree(depth + 1)
            n = self.power()
            if n < 1 or len(kids) + n > TREE_ORDER_MAX:
                raise self.error(f"more than {TREE_ORDER_MAX} vertices")
            kids.extend([child] * n)
        if not self.peek():
            raise self.error("missing ']'")
        self.pos += 1
        if not kids:
            raise self.error("'[]' is not a tree (write τ for the single vertex)")
        return from_children(kids)


def differential(t: Tree, ascii: bool = True, tex: bool = False) -> str:
    """The elementary differential F(t) in the usual notation ([HLW06] III.1.1): f, f'f,
    f''(f, f), f'f'f, ...; f^(m) for m > 3 derivatives (f^{(m)} with ``tex``); primes as ′ ″ ‴
    with ``ascii=False``."""
    return plain_differential(t, ascii, tex)
