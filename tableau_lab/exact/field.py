"""Exact fast arithmetic: the one place that knows about number fields.

Every exact computation on a method runs over the smallest convenient field
that holds its entries: ``QQ`` for rational tableaux, an algebraic number field
``QQ<theta>`` (sympy's primitive-element construction) for radicals, and the
rational function field ``K(p1, ..., pk)`` over it when a tableau has named
free parameters.  Matrices are sympy ``DomainMatrix`` objects over that field,
so zero tests are exact normal-form tests, never ``simplify``.

>>> import sympy as sp
>>> K = field_of([sp.sqrt(3) / 6, sp.Rational(1, 2)])
>>> K
QQ<sqrt(3)>
>>> normal_form((2 + sp.sqrt(3)) * (2 - sp.sqrt(3)))
1
>>> is_zero(sp.sqrt(2) * sp.sqrt(8) - 4)
True
"""
from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from functools import lru_cache
from typing import Any, Self

import sympy as sp
from sympy import QQ
from sympy.polys.matrices import DomainMatrix

from ..budget import FIELD_DEGREE
from ..errors import InputError
from .radicals import Reduction, reduce_generators

__all__ = [
    "FieldError", "field_of", "to_dm", "from_dm", "normal_form", "is_zero",
    "solve_linear", "nullspace", "exprs_of", "element", "FastField", "power", "FIELD_DEGREE_LIMIT",
]


class FieldError(InputError):
    """Entries that have no exact field arithmetic here (e.g. a radical of a parameter)."""


def exprs_of(objs: Iterable[Any]) -> list[sp.Expr]:
    """Flatten matrices / expressions / iterables of them to a list of expressions."""
    out: list[sp.Expr] = []
    for o in objs:
        if o is None:
            continue
        if isinstance(o, sp.MatrixBase):
            out.extend(o)
        elif isinstance(o, (list, tuple)):
            out.extend(exprs_of(o))
        else:
            out.append(sp.sympify(o))
    return out


def _generators(exprs: Iterable[sp.Expr]) -> tuple[set[sp.Expr], set[sp.Symbol]]:
    gens: set[sp.Expr] = set()
    syms: set[sp.Symbol] = set()
    for e in exprs:
        if e.has(sp.Float):
            raise FieldError(f"{e} contains a floating-point number; exact entries only")
        syms |= e.free_symbols
        for p in e.atoms(sp.Pow):
            if p.exp.is_Rational and not p.exp.is_Integer:
                if p.base.free_symbols:
                    raise FieldError(f"{p} is a radical of a free parameter: no exact field arithmetic for it")
                gens.add(sp.Pow(p.base, sp.Rational(1, p.exp.q)))
        if e.has(sp.I):
            gens.add(sp.I)       # only analyses make it (eigenvalues of V); the grammar refuses it
        numbers = _algebraic_atoms(e)
        gens |= numbers
        rest = e.xreplace({a: sp.Dummy() for a in numbers}) if numbers else e
        for a in rest.atoms(sp.Function, sp.NumberSymbol, sp.RootOf):
            raise FieldError(f"{a} is not an algebraic number")
    return gens, syms


def _algebraic_atoms(e: sp.Expr) -> set[sp.Expr]:
    """The algebraic numbers of ``e`` that are not radicals: cos(kπ/n), sin(kπ/n) and real
    roots of polynomials (sympy's CRootOf), as :mod:`grammar` makes them; a complex CRootOf
    (an eigenvalue) is a generator too."""
    out: set[sp.Expr] = set()
    for a in e.atoms(sp.cos, sp.sin):
        if a.args[0].free_symbols or not sp.expand(a.args[0] / sp.pi).is_Rational:
            raise FieldError(f"{a} is not an algebraic number")
        out.add(a)
    for r in e.atoms(sp.RootOf):
        if r.free_symbols:
            raise FieldError(f"{r} is a root of a polynomial in a free parameter")
        out.add(r)
    return out


#: the largest degree bound (the product of the degrees of the generators: roots of polynomials,
#: values of cos, sin, radicals) of a number field built here; beyond it the primitive element and
#: its arithmetic cost minutes (all six nodes of 6-stage Gauss: 6⁶; twelve square roots: 2¹²), and
#: such methods are analysed in ℚ by :mod:`conjugate` instead.  The CLI's --max-field-degree sets it.
FIELD_DEGREE_LIMIT = FIELD_DEGREE


def _degree(g: sp.Expr) -> int:
    """A bound on the degree g adds to a field: its polynomial's degree (RootOf, cos, sin), the
    root's index q for a radical r**(p/q) (twelve square roots of primes: 2¹² = 4096)."""
    if isinstance(g, sp.RootOf):
        return int(g.poly.degree())
    if isinstance(g, (sp.cos, sp.sin)):
        return int(sp.degree(sp.minimal_polynomial(g, sp.Dummy("x"))))
    if g.is_Pow and g.exp.is_Rational:
        return int(g.exp.q)
    return 2 if g is sp.I else 1


@lru_cache(maxsize=256)
def _field(gens: tuple[sp.Expr, ...], syms: tuple[sp.Symbol, ...]) -> Any:
    red = reduce_generators(gens)
    bound = 1
    for g in red.basis:
        bound *= _degree(g)
    if bound > FIELD_DEGREE_LIMIT:
        raise FieldError(f"the entries generate a number field of degree up to {bound} (budget "
                         f"FIELD_DEGREE_LIMIT = {FIELD_DEGREE_LIMIT}; raise it with --max-field-degree N): "
                         f"{len(gens)} algebraic numbers such as {gens[0]}")
    K = QQ.algebraic_field(*red.basis) if gens else QQ
    if gens:
        _embed_generators(K, red)
    if syms:
        K = K.frac_field(*syms)
    return K


def _embed_generators(K: Any, red: Reduction) -> None:
    """Record each generator's image in K from the primitive-element construction itself (its
    polynomial in θ) and the reduction's words, so that :func:`element` need not rediscover it:
    sympy's ``to_number_field`` finds an embedding by PSLQ or factoring, seconds per generator."""
    from sympy.polys.numberfields.subfield import primitive_element
    minpoly, _, reps = primitive_element(list(red.basis), ex=True, polys=True)
    mod = K.mod.to_list()
    if minpoly.rep.to_list() != mod:        # not the construction K was built from: leave it to sympy
        return
    images = [K.dtype([QQ.convert(c) for c in rep], mod, QQ) for rep in reps]
    for g, (q, idx) in red.words.items():
        img = K.convert(QQ.convert(q))
        for i in idx:
            img = img * images[i]
        _IMAGES[(K, g)] = img


def field_of(exprs: Iterable[Any]) -> Any:
    """The exact field holding all the given expressions (matrices are flattened)."""
    gens, syms = _generators(exprs_of(list(exprs)))
    return _field(tuple(sorted(gens, key=sp.default_sort_key)),
                  tuple(sorted(syms, key=lambda s: s.name)))


_IMAGES: dict[tuple[Any, sp.Expr], Any] = {}      # (K, generator) → its element of K


def element(K: Any, e: Any) -> Any:
    """An exact expression as an element of K, by field arithmetic on its parts.

    Each distinct radical is mapped into K once (sympy's ``to_number_field`` factors
    polynomials and is slow); sums, products and integer powers are then computed in K.
    Converting the entries of a 5-stage Gauss tableau this way takes milliseconds instead
    of minutes.
    """
    e = sp.sympify(e)
    if e.is_Rational or e.is_Symbol:
        return K.from_sympy(e)
    if e.is_Add:
        out = K.zero
        for a in e.args:
            out = out + element(K, a)
        return out
    if e.is_Mul:
        out = K.one
        for a in e.args:
            out = out * element(K, a)
        return out
    if e.is_Pow and e.exp.is_Rational:
        p, q = e.exp.p, e.exp.q
        if q == 1:
            base = element(K, e.base)
        else:
            key = (K, sp.Pow(e.base, sp.Rational(1, q)))
            if key not in _IMAGES:
                _IMAGES[key] = K.from_sympy(key[1])
            base = _IMAGES[key]
        if p >= 0:
            return base ** p
        # an inverse in a field of high degree is a slow extended gcd: once per radical
        # (G6245's U has ten entries over each of two nested square roots)
        key = (K, sp.Pow(e.base, sp.Rational(-1, q)))
        if key not in _IMAGES:
            _IMAGES[key] = K.one / base
        return _IMAGES[key] ** (-p)
    if isinstance(e, (sp.cos, sp.sin, sp.RootOf)) or e is sp.I:
        key = (K, e)
        if key not in _IMAGES:
            _IMAGES[key] = K.from_sympy(e)
        return _IMAGES[key]
    return K.from_sympy(e)


def to_dm(M: sp.MatrixBase, K: Any) -> DomainMatrix:
    """A sympy matrix as a DomainMatrix over K."""
    rows = [[element(K, x) for x in M.row(i)] for i in range(M.rows)]
    return DomainMatrix(rows, M.shape, K)


def from_dm(M: DomainMatrix) -> sp.ImmutableMatrix:
    """A DomainMatrix as an exact sympy matrix, entries in the field's normal form."""
    K = M.domain
    return sp.ImmutableMatrix(M.shape[0], M.shape[1],
                              [K.to_sympy(x) for row in M.to_list() for x in row])


def normal_form(e: Any, K: Any = None) -> sp.Expr:
    """The canonical form of an exact expression in its field (a polynomial in the
    primitive element over QQ, or a reduced fraction in the parameters)."""
    e = sp.sympify(e)
    K = K or field_of([e])
    return K.to_sympy(element(K, e))


def is_zero(e: Any, K: Any = None) -> bool:
    """Exact zero test in the field of ``e``."""
    e = sp.sympify(e)
    K = K or field_of([e])
    return bool(K.is_zero(element(K, e)))


def nullspace(M: DomainMatrix) -> list[list[Any]]:
    """A basis of {x : M x = 0} as lists of field elements, each normalised so that
    its last pivot-free coordinate (the free variable) is 1."""
    K = M.domain
    n = M.shape[1]
    R, pivots = M.rref()
    rows = R.to_list()
    free = [j for j in range(n) if j not in pivots]
    basis = []
    for f in free:
        x = [K.zero] * n
        x[f] = K.one
        for i, p in enumerate(pivots):
            x[p] = -rows[i][f] / rows[i][p]
        basis.append(x)
    return basis


def solve_linear(M: DomainMatrix, rhs: Sequence[Any]) -> list[Any] | None:
    """One solution of M x = rhs (free variables set to zero), or None if inconsistent."""
    K = M.domain
    m, n = M.shape
    aug = M.hstack(DomainMatrix([[K.convert(v)] for v in rhs], (m, 1), K))
    R, pivots = aug.rref()
    if n in pivots:
        return None
    rows = R.to_list()
    x = [K.zero] * n
    for i, p in enumerate(pivots):
        x[p] = rows[i][n] / rows[i][p]
    return x


def power(F: Any, x: Any, k: int) -> Any:
    """x**k in F (a sympy domain or a :class:`FastField`), with x⁰ = 1 also for x = 0: sympy's
    fields of rational functions refuse 0**0 (a node cᵢ = 0 in cᵢ^(k−1), k = 1)."""
    return x ** k if k else F.one


# ------------------------------------------------------------ C-speed element arithmetic

class FastField:
    """Element arithmetic of K at C speed (python-flint), for the hot loops of the analyses.

    ``QQ`` → flint ``fmpq``; ``QQ<α>`` → ``fmpq_poly`` reduced modulo the minimal polynomial
    of α (exact: the same normal form as sympy's ``ANP``, a hundred times faster);
    any other K (rational functions of parameters) → K's own elements.  ``lift`` takes a K
    element (or a sympy Rational) in, ``drop`` gives a K element back.

    >>> import sympy as sp
    >>> K = field_of([sp.sqrt(2), sp.sqrt(3)])
    >>> F = FastField(K)
    >>> x = F.lift(element(K, sp.sqrt(2) + sp.sqrt(3)))
    >>> sp.expand(K.to_sympy(F.drop(x * x - F.rational(5))))
    2*sqrt(6)
    >>> F.is_zero((x * x - F.rational(5)) ** 2 - F.rational(24))
    True
    """

    zero: Any
    one: Any
    lift: Callable[[Any], Any]      # a K element (or a sympy Rational) → a fast one
    drop: Callable[[Any], Any]      # a fast element → a K element

    def __init__(self, K: Any) -> None:
        import flint

        self.K = K
        self._rationals: dict[sp.Rational, Any] = {}
        if K.is_QQ:
            self.zero, self.one = flint.fmpq(0), flint.fmpq(1)
            self.lift = lambda a: flint.fmpq(int(a.numerator), int(a.denominator))
            self.drop = lambda x: K.convert(sp.Rational(int(x.p), int(x.q)))
        elif K.is_Algebraic:
            mod = flint.fmpq_poly([flint.fmpq(int(c.numerator), int(c.denominator))
                                   for c in reversed(K.mod.to_list())])
            elt = type("NumberFieldElement", (_NFElt,), {"mod": mod, "__slots__": ()})
            self.zero, self.one = elt(flint.fmpq_poly([])), elt(flint.fmpq_poly([1]))
            self.lift = lambda a: elt(flint.fmpq_poly([flint.fmpq(int(c.numerator), int(c.denominator))
                                                       for c in reversed(a.to_list())]))
            self.drop = lambda x: K.new([sp.Rational(int(c.p), int(c.q)) for c in reversed(x.p.coeffs())])
        else:
            self.zero, self.one = K.zero, K.one
            self.lift = self.drop = lambda a: a

    def rational(self, q: Any) -> Any:
        """A rational number (int, sympy Rational) as a fast element (converted once each: the
        order analyses ask for the same 1/γ(t) many times)."""
        q = sp.Rational(q)
        if q not in self._rationals:
            self._rationals[q] = self.lift(self.K.convert(q))
        return self._rationals[q]

    def is_zero(self, x: Any) -> bool:
        return not x

    def to_sympy(self, x: Any) -> sp.Expr:
        return self.K.to_sympy(self.drop(x))


class _NFElt:
    """An element of QQ[x]/(m): an fmpq_poly of degree < deg m (class attribute ``mod``)."""

    __slots__ = ("p",)
    mod: Any = None

    def __init__(self, p: Any) -> None:
        self.p = p

    def __add__(self, o: Self) -> Self:
        return type(self)(self.p + o.p)

    def __sub__(self, o: Self) -> Self:
        return type(self)(self.p - o.p)

    def __neg__(self) -> Self:
        return type(self)(-self.p)

    def __mul__(self, o: Self) -> Self:
        return type(self)((self.p * o.p) % self.mod)

    def __pow__(self, n: int) -> Self:
        out = type(self)(self.p ** 0)
        for _ in range(n):
            out = out * self
        return out

    def __bool__(self) -> bool:
        return not self.p.is_zero()

    def __eq__(self, o: object) -> bool:
        return isinstance(o, _NFElt) and bool(self.p == o.p)

    def __hash__(self) -> int:
        return hash(str(self.p))
