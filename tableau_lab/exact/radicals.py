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

from dataclasses import dataclass

import sympy as sp

__all__ = ["Reduction", "reduce_generators", "square_class"]


def square_class(n) -> frozenset:
    """The primes of odd exponent in a nonzero rational |n|: √a/√b is rational exactly when
    ``square_class(a) == square_class(b)`` (for a, b > 0)."""
    n = sp.Rational(n)
    out: set = set()
    for part in (abs(n.p), n.q):
        out ^= {p for p, k in sp.factorint(part).items() if k % 2}
    return frozenset(out)


@dataclass(frozen=True)
class Reduction:
    """``basis``: the generators to adjoin; ``words``: each original generator g ↦ (q, indices)
    with g = q·Π basis[i] exactly (q rational)."""
    basis: tuple
    words: dict


class _SquareClasses:
    """Positive rationals' square roots over a growing basis of squarefree integers."""

    def __init__(self, basis: list):
        self.basis = basis                 # shared with the caller: generators in adjoin order
        self.rows: dict = {}               # pivot prime -> (reduced class, set of basis indices)

    def word(self, c) -> tuple:
        """√c = q·Π basis[i] for a positive rational c, adjoining √n to the basis if needed."""
        v, used = set(square_class(c)), set()
        while v:
            pivot = max(v)
            if pivot not in self.rows:
                n = sp.Mul(*v)              # squarefree, what is left of c's class
                self.basis.append(sp.sqrt(n))
                self.rows[pivot] = (frozenset(v), {len(self.basis) - 1})
                used ^= {len(self.basis) - 1}
                break
            row, idx = self.rows[pivot]
            v ^= row
            used ^= idx
        product = sp.Mul(*(self.basis[i].base for i in used))
        q = sp.sqrt(sp.Rational(c) / product)
        assert q.is_Rational, (c, product)
        return q, tuple(sorted(used))


def reduce_generators(gens) -> Reduction:
    """Rewrite square roots (of rationals, of irrational bases, and i = √−1) over a basis; other
    generators (roots of polynomials, cos, sin, higher radicals) are kept as they are."""
    basis: list = []
    classes = _SquareClasses(basis)
    words: dict = {}
    nested: dict = {}
    imaginary = []

    def unit() -> int:
        if not imaginary:
            basis.append(sp.I)
            imaginary.append(len(basis) - 1)
        return imaginary[0]

    for g in sorted(gens, key=sp.default_sort_key):
        if g is sp.I:
            words[g] = (sp.S.One, (unit(),))
        elif g.is_Pow and g.exp == sp.S.Half and g.base.is_Rational:
            q, idx = classes.word(abs(g.base))
            words[g] = (q, idx + ((unit(),) if g.base < 0 else ()))
        elif g.is_Pow and g.exp == sp.S.Half and g.base.as_content_primitive()[0] > 0:
            c, P = g.base.as_content_primitive()
            if P not in nested:
                basis.append(sp.sqrt(P))
                nested[P] = len(basis) - 1
            q, idx = classes.word(c) if c != 1 else (sp.S.One, ())
            words[g] = (q, idx + (nested[P],))
        else:
            basis.append(g)
            words[g] = (sp.S.One, (len(basis) - 1,))
    return Reduction(tuple(basis), words)
