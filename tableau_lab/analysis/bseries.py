r"""B-series: exact series keyed by rooted trees, and their algebra ([HLW06] III.1, IX.9;
Chartier, Hairer & Vilmart, *Found. Comput. Math.* 10 (2010) 407–427 [CHV10]; Butcher,
*B-Series*, Springer 2021 [B21]).

    B(a, y) = a(∅) y + Σ_t h^{|t|}/σ(t) · a(t) F(t)(y)

A :class:`BSeries` holds a(t) for every tree up to ``max_order`` (trees are the canonical tuples
of :mod:`trees`, the empty tree is ``None``), exact in the method's number field.  With
``kind=BICOLOURED`` (:mod:`tree_kinds`) it is a P-series of a partitioned method over bicoloured
trees, and every operation below works the same way ([HLW06] III.2, IX.10).  A series with
a(∅) = 1 is a map (a method, a flow); one with a(∅) = 0 is a vector field h f̃ = Σ h^{|t|} b(t)/σ(t) F(t).

* ``compose(a, b)``: a then b, B(b, B(a, y)) = B(a·b, y) ([HLW06] Thm III.1.10)
* ``inverse(a)``: the Butcher-group inverse; ``adjoint(a)``: Φ*_h = Φ_{−h}⁻¹
* ``substitute(b, a)``: a applied to the vector field of b, B(a, h f̃_b) = B(b ⋆ a) ([CHV10] Sec. 3.2)
* ``modified_field(a)``: the b with b ⋆ e = a (backward error analysis, [HLW06] IX.1, IX.9)
* ``modifying_field(a)``: the b with b ⋆ a = e (the modifying integrator, [CHV10] Sec. 4)
* ``exact_flow``, ``identity``, ``flow_of(b)`` = b ⋆ e

>>> from tableau_lab.analysis.trees import parse_tree as T
>>> E = exact_flow(4)
>>> E[T("[τ[τ]]")], compose(E, E)[T("[τ[τ]]")], inverse(E)[T("[[τ]]")]
(1/8, 2, -1/6)
>>> euler = BSeries.from_function(lambda t: 1 if t == () else 0, 4, label="explicit Euler")
>>> b = modified_field(euler)
>>> [str(b[T(x)]) for x in ("τ", "[τ]", "[τ²]", "[[τ]]")]          # f − h/2 f′f + h²(1/12 f″(f,f) + 1/3 f′f′f)
['1', '-1/2', '1/6', '1/3']
>>> flow_of(b) == euler
True
"""
from __future__ import annotations

import operator
from dataclasses import dataclass
from functools import lru_cache

import sympy as sp
from sympy import QQ

from ..budget import SERIES_ORDER
from ..errors import BudgetError, InputError
from ..exact.field import FastField
from . import tree_kinds as _kinds
from .tree_kinds import PLAIN, Coefficients, TreeKind, partitions
from .trees import TreeError, parse_tree, trees_up_to

__all__ = ["BSeries", "series_like", "exact_flow", "identity", "compose", "inverse", "adjoint", "substitute",
           "modified_field", "modifying_field", "flow_of", "series_order",
           "stage_derivative", "kept_cuts", "flow_cuts", "compose_coefficients", "inverse_coefficients",
           "check_series_order"]

#: the largest order a B-series is built to here (budget.SERIES_ORDER)
MAX_SERIES_ORDER = SERIES_ORDER


# ------------------------------------------------------------------ coefficient kernels
# Plain dicts {tree: value}; values support + and * (sympy numbers, domain elements or the fast
# elements of FastField); ``one`` is the unit of that arithmetic.

def stage_derivative(a: dict, max_order: int, one=1) -> dict:
    """a′ with h f(B(a, y)) = B(a′, y) for a(∅) = 1: a′(∅) = 0, a′(τ) = 1, a′([t₁…t_m]) = Π a(tᵢ)."""
    out: Coefficients = {None: one - one}
    for t in trees_up_to(max_order):
        v = one
        for c in t:
            v = v * a[c]
        out[t] = v
    return out


def kept_cuts(t, inner, one=1, kind: TreeKind = PLAIN) -> dict:
    """The cuts of t that keep the root: {trunk: Σ Π inner(pruned part)}.
    ``inner`` maps a tree to its coefficient; the trunk t itself (no cut) has coefficient 1."""
    return _kinds.kept_cuts(kind, t, inner, one)


@lru_cache(maxsize=None)
def flow_cuts(t) -> tuple:
    """(trunk, Σ Π 1/γ(pruned)) over the root-keeping cuts of t other than t itself (cached):
    the exact flow applied first, as in S∘E."""
    cuts = kept_cuts(t, lambda c: sp.Rational(1, PLAIN.density(c)))
    return tuple((trunk, coef) for trunk, coef in cuts.items() if trunk != t)


def compose_coefficients(a: dict, b: dict, max_order: int, one=1, kind: TreeKind = PLAIN) -> dict:
    """a·b (a applied first), up to max_order; a(∅) must be 1, b(∅) may be anything (the
    components of a GLM starting method have the preconsistency vector there)."""
    if a.get(None, one) != one:
        raise ValueError("the inner series of a composition must have a(∅) = 1")
    b0 = b.get(None, one)
    out: Coefficients = {None: b0}
    for t in kind.trees_up_to(max_order):
        v = b0 * a[t]
        for trunk, coef in kept_cuts(t, lambda c: a[c], one, kind).items():
            v = v + coef * b[trunk]
        out[t] = v
    return out


def inverse_coefficients(a: dict, max_order: int, one=1, kind: TreeKind = PLAIN) -> dict:
    """a⁻¹ in the Butcher group (a(∅) = 1): a·a⁻¹ = identity."""
    beta: Coefficients = {None: one}
    for t in kind.trees_up_to(max_order):
        acc = a[t]
        for trunk, coef in kept_cuts(t, lambda c: a[c], one, kind).items():
            if trunk != t:
                acc = acc + coef * beta[trunk]
        beta[t] = -acc
    return beta


def _substitute(b: dict, a: dict, max_order: int, F, kind: TreeKind) -> dict:
    out: Coefficients = {None: a[None]}
    for t in kind.trees_up_to(max_order):
        v = F.zero
        for skeleton, pieces, m in partitions(kind, t):
            term = a[skeleton] * F.rational(m)
            for p in pieces:
                term = term * b[p]
            v = v + term
        out[t] = v
    return out


def _solve_substitution(target: dict, outer: dict, max_order: int, F, kind: TreeKind) -> dict:
    """The field b with b ⋆ outer = target, outer(τ) = 1: tree by tree, the partition that keeps
    every edge contributes outer(τ)·b(t); all others involve b on smaller trees."""
    b: Coefficients = {None: F.zero}
    for t in kind.trees_up_to(max_order):
        v = target[t]
        for skeleton, pieces, m in partitions(kind, t):
            if len(pieces) == 1:
                continue
            term = outer[skeleton] * F.rational(m)
            for p in pieces:
                term = term * b[p]
            v = v - term
        b[t] = v
    return b


# ------------------------------------------------------------------ the public object

def check_series_order(n, what: str, lowest: int = 1) -> None:
    """Refuse a series order outside lowest … MAX_SERIES_ORDER: an InputError below (or not an
    integer), the series-order budget (a :class:`~tableau_lab.errors.BudgetError` naming
    budget.SERIES_ORDER) above.

    >>> try:                                                # doctest: +NORMALIZE_WHITESPACE
    ...     check_series_order(50, "the B-series of m")
    ... except BudgetError as exc:
    ...     print(type(exc).__name__, exc, sep=": ")
    BudgetError: the B-series of m to order 50: series order budget of 12 exceeded; raise it with
    budget.SERIES_ORDER
    """
    try:
        k = operator.index(n)
    except TypeError:
        k = None
    if k is None or k < lowest:
        raise InputError(f"{what}: the order must be an integer between {lowest} and {MAX_SERIES_ORDER}, not {n!r}")
    n = k
    if n > MAX_SERIES_ORDER:
        raise BudgetError("series order", MAX_SERIES_ORDER, f"{what} to order {n}", "budget.SERIES_ORDER")


@dataclass(frozen=True, eq=False)
class BSeries:
    """A truncated B-series with exact coefficients (see the module docstring).

    ``series[t]`` takes a tree (a canonical tuple, or bracket text such as ``"[τ[τ]]"``) or
    ``None`` for the empty tree and returns an exact sympy number; ``series.items()`` lists
    (tree, value) by order.  Two series are equal when they have the same order and values.
    ``tl.BSeries``; a method's own series is ``method_series(m, n).phi``
    (:mod:`tableau_lab.analysis.method_series`).  Reference: [HLW06] Hairer, Lubich & Wanner,
    *Geometric Numerical Integration*, §III.1; [B21] Butcher, *B-Series*, Springer 2021.

    >>> import tableau_lab as tl
    >>> euler = tl.BSeries.from_function(lambda t: 1 if t == () else 0, 3, label="explicit Euler")
    >>> euler["τ"], euler["[τ]"], euler == tl.load("explicit_euler").modified_equation(3).field
    (1, 0, False)
    """

    field: FastField
    values: Coefficients         # tree or None -> element of ``field``
    max_order: int
    label: str = ""
    kind: TreeKind = PLAIN       # BICOLOURED: a P-series of a partitioned method

    def __post_init__(self):
        check_series_order(self.max_order, f"the B-series {self.label or ''}".rstrip(), lowest=0)

    @classmethod
    def from_function(cls, fn, max_order: int, label: str = "", empty=1, K=QQ, kind: TreeKind = PLAIN) -> "BSeries":
        """The series t ↦ fn(t) (exact numbers: int, Rational, algebraic) with a(∅) = ``empty``."""
        from ..exact.field import element, field_of
        vals: Coefficients = {t: sp.sympify(fn(t)) for t in kind.trees_up_to(max_order)}
        vals[None] = sp.sympify(empty)
        if K is QQ:
            K = field_of(list(vals.values()))
        F = FastField(K)
        return cls(F, {t: F.lift(element(K, v)) for t, v in vals.items()}, max_order, label, kind)

    def _key(self, t):
        if isinstance(t, str) and not self.kind.coloured:
            try:
                t = parse_tree(t)
            except TreeError as exc:
                raise KeyError(str(exc)) from None
        if t is not None and (not isinstance(t, tuple) or t not in self.values):
            raise KeyError(f"{t!r}: not a tree of order ≤ {self.max_order}")
        return t

    def element(self, t):
        """The coefficient as an element of ``field`` (for further exact arithmetic)."""
        return self.values[self._key(t)]

    def __getitem__(self, t) -> sp.Expr:
        return self.field.to_sympy(self.element(t))

    def items(self):
        return [(t, self[t]) for t in self.kind.trees_up_to(self.max_order)]

    @property
    def is_field(self) -> bool:
        """True for a vector field (b(∅) = 0)."""
        return self.field.is_zero(self.values[None])

    def __eq__(self, other):
        if not isinstance(other, BSeries) or other.max_order != self.max_order or other.kind != self.kind:
            return NotImplemented
        a, b = _common(self, other)
        return all(a.field.is_zero(a.values[t] - b.values[t]) for t in a.values)

    __hash__ = None   # type: ignore[assignment]  # unhashable (equal series); typeshed types __hash__ a method, as for list

    def truncate(self, n: int) -> "BSeries":
        n = min(n, self.max_order)
        return BSeries(self.field, {t: v for t, v in self.values.items() if t is None or self.kind.order(t) <= n},
                       n, self.label, self.kind)

    def to_json(self) -> dict:
        """{bracket: exact value as text} (the empty tree as "∅")."""
        from ..exact.grammar import format_entry
        out = {"∅": str(format_entry(self[None]))}
        out.update({self.kind.bracket(t): str(format_entry(v)) for t, v in self.items()})
        return out

    def __repr__(self):
        shown = ", ".join(f"{self.kind.bracket(t)}: {v}" for t, v in self.items()[:6])
        more = " …" if len(self.values) > 7 else ""
        return f"BSeries({self.label or 'unnamed'}, order {self.max_order}; ∅: {self[None]}, {shown}{more})"


def _common(*series):
    """The series over one field (the smallest holding all) and their common order."""
    K = series[0].field.K
    if len({s.kind for s in series}) > 1:
        raise ValueError("a B-series and a P-series (bicoloured trees) cannot be combined")
    for s in series[1:]:
        if s.field.K != K:
            K = K.unify(s.field.K)
    n = min(s.max_order for s in series)
    out = []
    for s in series:
        if s.field.K == K:
            out.append(s.truncate(n))
            continue
        F = FastField(K)
        out.append(BSeries(F, {t: F.lift(K.convert_from(s.field.drop(v), s.field.K))
                               for t, v in s.values.items() if t is None or s.kind.order(t) <= n}, n, s.label, s.kind))
    return out


def series_like(like: BSeries, values: dict, label: str) -> BSeries:
    """A series with the field, truncation order and tree kind of ``like``, and the coefficients
    ``values`` (tree ↦ field element) under the name ``label``: how the operations of the Butcher
    group build their results ([HLW06] Hairer, Lubich & Wanner, *Geometric Numerical Integration*,
    III.1).

    >>> e = exact_flow(2)
    >>> series_like(e, {t: v + v for t, v in e.values.items()}, "2E")[((),)]
    1
    """
    return BSeries(like.field, values, like.max_order, label, like.kind)


def exact_flow(max_order: int, kind: TreeKind = PLAIN) -> BSeries:
    """E(∅) = 1, E(t) = 1/γ(t): the exact solution."""
    return BSeries.from_function(lambda t: sp.Rational(1, kind.density(t)), max_order, "exact flow", kind=kind)


def identity(max_order: int, kind: TreeKind = PLAIN) -> BSeries:
    """e(∅) = 1, e(t) = 0: the identity map."""
    return BSeries.from_function(lambda t: 0, max_order, "identity", kind=kind)


def compose(a: BSeries, b: BSeries) -> BSeries:
    """a then b: B(b, B(a, y)) = B(a·b, y); a must be a map (a(∅) = 1)."""
    a, b = _common(a, b)
    return series_like(a, compose_coefficients(a.values, b.values, a.max_order, a.field.one, a.kind),
                f"({a.label})·({b.label})")


def inverse(a: BSeries) -> BSeries:
    """The inverse map in the Butcher group (a(∅) = 1)."""
    F = a.field
    if not F.is_zero(a.values[None] - F.one):
        raise ValueError("only maps (a(∅) = 1) are invertible in the Butcher group")
    return series_like(a, inverse_coefficients(a.values, a.max_order, F.one, a.kind), f"({a.label})⁻¹")


def adjoint(a: BSeries) -> BSeries:
    """Φ*_h = Φ_{−h}⁻¹: a*(t) = (−1)^{|t|} a⁻¹(t) ([HLW06] II.3, V.1); symmetric iff a* = a."""
    inv = inverse(a).values
    return series_like(a, {t: (v if t is None or a.kind.order(t) % 2 == 0 else -v) for t, v in inv.items()},
                f"({a.label})*")


def substitute(b: BSeries, a: BSeries) -> BSeries:
    """b ⋆ a: the method a applied to the vector field h f̃ = B(b) (b(∅) = 0) ([CHV10] Thm 3.2)."""
    b, a = _common(b, a)
    if not b.is_field:
        raise ValueError("only a vector field (b(∅) = 0) can be substituted")
    return series_like(a, _substitute(b.values, a.values, a.max_order, a.field, a.kind), f"({b.label})⋆({a.label})")


def flow_of(b: BSeries) -> BSeries:
    """The exact flow of the vector field b: b ⋆ E (the exponential)."""
    return substitute(b, exact_flow(b.max_order, b.kind))


def modified_field(a: BSeries) -> BSeries:
    """The modified vector field of the map a: the b with b ⋆ E = a ([HLW06] IX.1, IX.9.2):
    the numerical solution is, formally, the exact flow of y′ = Σ h^{|t|−1} b(t)/σ(t) F(t)(y)."""
    a, E = _common(a, exact_flow(a.max_order, a.kind))
    F = a.field
    if not F.is_zero(a.values[None] - F.one):
        raise ValueError("a modified equation needs a map (a(∅) = 1)")
    return series_like(a, _solve_substitution(a.values, E.values, a.max_order, F, a.kind),
                       f"modified field of {a.label}")


def modifying_field(a: BSeries) -> BSeries:
    """The modifying integrator of the map a: the field b with b ⋆ a = E, so that the method applied
    to y′ = Σ h^{|t|−1} b(t)/σ(t) F(t) reproduces the exact flow of y′ = f ([CHV10] Sec. 4)."""
    a, E = _common(a, exact_flow(a.max_order, a.kind))
    F = a.field
    if a.max_order and any(not F.is_zero(a.values[t] - F.one) for t in a.kind.leaves()):
        raise ValueError("a modifying integrator needs a consistent method (a(τ) = 1)")
    return series_like(a, _solve_substitution(E.values, a.values, a.max_order, F, a.kind),
                       f"modifying field of {a.label}")


def series_order(a: BSeries) -> int:
    """The largest p ≤ max_order with a(t) = 1/γ(t) for all |t| ≤ p."""
    a, E = _common(a, exact_flow(a.max_order, a.kind))
    for t in a.kind.trees_up_to(a.max_order):
        if not a.field.is_zero(a.values[t] - E.values[t]):
            return a.kind.order(t) - 1
    return a.max_order
