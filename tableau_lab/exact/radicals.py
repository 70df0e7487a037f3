"""Square roots reduced to a basis before a number field is built from them.

Entries written by hand or by sympy's solvers name the same field through many square roots:
GLM4S (methods/glm4_symmetric.json) has √3, √130, √390, √88517, √265551 and two nested roots
that differ by a rational factor, seven generators of a field of degree 16.  sympy's primitive
element over all of them costs seconds, and finding each one's image in the field again (by PSLQ)
costs seconds more.  Here each square root of a rational is written as q·Π√nᵢ over a basis of
square classes (Besicovitch: √n₁, …, √nₖ for squarefree nᵢ with independent prime supports are
linearly independent, so ℚ(√a₁, …, √aₘ) has degree 2^rank over GF(2)), and a square root of an
irrational base c·P (c rational) as √c·√P with one generator per P.

>>> r = reduce_generators([sp.sqrt(3), sp.sqrt(130), sp.sqrt(390), sp.I])
>>> r.basis
(sqrt(130), sqrt(3), I)
>>> r.words[sp.sqrt(390)]
(1, (0, 1))
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import sympy as sp

__all__ = ["Reduction", "reduce_generators", "square_class"]


def square_class(n: Any) -> frozenset[Any]:
    """The primes of odd exponent in a nonzero rational |n|: √a/√b is rational exactly when
    ``square_class(a) == square_class(b)`` (for a, b > 0)."""
    n = sp.Rational(n)
    out: set[Any] = set()
    for part in (abs(n.p), n.q):
        out ^= {p for p, k in sp.factorint(part).items() if k % 2}
    return frozenset(out)


@dataclass(frozen=True)
class Reduction:
    """``basis``: the generators to adjoin; ``words``: each original generator g ↦ (q, indices)
    with g = q·Π basis[i] exactly (q rational)."""
    basis: tuple[Any, ...]
    words: dict[Any, tuple[Any, tuple[int, ...]]]


class _SquareClasses:
    """Positive rationals' square roots over a growing basis of squarefree integers."""

    def __init__(self, basis: list[Any]) -> None:
        self.basis = basis                 # shared with the caller: generators in adjoin order
        # pivot prime -> (reduced class, set of basis indices)
        self.rows: dict[Any, tuple[frozenset[Any], set[int]]] = {}

    def word(self, c: Any, adjoin: bool = True) -> tuple[Any, tuple[int, ...], Any]:
        """√c = q·Π basis[i]·√n for a positive rational c: n = 1, adjoining √n to the basis if
        needed; with ``adjoin=False`` the basis is left alone and n (squarefree) is what of c's
        class it does not span.  Returns (q, indices, n)."""
        v, used = set(square_class(c)), set[int]()
        while v:
            pivot = max(v)
            if pivot not in self.rows:
                if not adjoin:
                    break
                n = sp.Mul(*v)              # squarefree, what is left of c's class
                self.basis.append(sp.sqrt(n))
                self.rows[pivot] = (frozenset(v), {len(self.basis) - 1})
                used ^= {len(self.basis) - 1}
                v = set()
                break
            row, idx = self.rows[pivot]
            v ^= row
            used ^= idx
        n = sp.Mul(*v) if v else sp.S.One
        product = sp.Mul(*(self.basis[i].base for i in used)) * n
        q = sp.sqrt(sp.Rational(c) / product)
        assert q.is_Rational, (c, product)
        return q, tuple(sorted(used)), n


def reduce_generators(gens: Iterable[Any]) -> Reduction:
    """Rewrite square roots (of rationals, of irrational bases, and i = √−1) over a basis; other
    generators (roots of polynomials, cos, sin, higher radicals) are kept as they are."""
    basis: list[Any] = []
    classes = _SquareClasses(basis)
    words: dict[Any, tuple[Any, tuple[int, ...]]] = {}
    nested: dict[Any, int] = {}
    imaginary: list[int] = []

    def unit() -> int:
        if not imaginary:
            basis.append(sp.I)
            imaginary.append(len(basis) - 1)
        return imaginary[0]

    def rational_root(g: Any) -> bool:
        return bool(g.is_Pow and g.exp == sp.S.Half and g.base.is_Rational)

    # square roots of rationals first: a nested root's rational factor is then written over their
    # classes where it can be, and the rest of it stays under the root (√(c·P) = q·Π√nᵢ·√(n·P)):
    # G6245's √(−347009/1265902 + 2967√330/57541) adds one generator, not √1265902's class as well
    # (a field of degree bound 64 instead of 16, minutes of arithmetic)
    for g in sorted(gens, key=lambda g: (not rational_root(g), sp.default_sort_key(g))):
        if g is sp.I:
            words[g] = (sp.S.One, (unit(),))
        elif rational_root(g):
            q, idx, _ = classes.word(abs(g.base))
            words[g] = (q, idx + ((unit(),) if g.base < 0 else ()))
        elif g.is_Pow and g.exp == sp.S.Half and g.base.as_content_primitive()[0] > 0:
            c, P = g.base.as_content_primitive()
            q, idx, n = classes.word(c, adjoin=False) if c != 1 else (sp.S.One, (), sp.S.One)
            key = sp.expand(n * P)
            if key not in nested:
                basis.append(sp.sqrt(key))
                nested[key] = len(basis) - 1
            words[g] = (q, idx + (nested[key],))
        else:
            basis.append(g)
            words[g] = (sp.S.One, (len(basis) - 1,))
    return Reduction(tuple(basis), words)
