r"""Geometric properties of a B-series, exactly and to a stated order.

* **symplectic** map: a(u∘v) + a(v∘u) = a(u) a(v) for all trees u, v ([HLW06] Thm VI.7.6;
  Calvo & Sanz-Serna 1994); a **Hamiltonian** field: b(u∘v) + b(v∘u) = 0 ([HLW06] IX.9.3).
* **symmetric** map: a = a*, a*(t) = (−1)^{|t|} a⁻¹(t) ([HLW06] V.1).
* **energy-preserving** field (H conserved for every H): H′f̃ = Σ_t b(t)/σ(t) H([t]) = 0; the
  elementary Hamiltonian H([t]) is ± that of the free tree of [t], those of the non-superfluous
  free trees are independent, so for each such free tree π: Σ_{[t] ∈ π} sign([t]) b(t)/σ(t) = 0
  ([HLW06] IX.9; Celledoni, McLachlan, Owren & Quispel, *Found. Comput. Math.* 10 (2010)).
* **conjugate-symplectic** map ([HLW06] VI.8; Chartier, Faou & Murua, *Numer. Math.* 103
  (2006); Hairer & Zbinden, *IMA J. Numer. Anal.* 33 (2013)): a near-identity B-series χ with
  χ⁻¹∘Φ∘χ symplectic.  χ is built order by order: at order n the order-(n−1) coefficients c of χ
  enter the order-n coefficients of χ⁻¹Φχ through the Lie bracket with f only (c(τ) = 0; the
  matrix L_n of :func:`glm_order.theta_matrix`), so the symplectic conditions at order n are a
  linear system for c.  Two solutions differ by a Hamiltonian field exactly when the kernel of
  that system is the space of Hamiltonian fields of order n−1 (checked in the tests to order 9):
  then the choice does not matter later, and an inconsistent system proves that no χ exists.

>>> from tableau_lab.exact.tableau_json import load
>>> from tableau_lab.analysis.method_series import method_series
>>> s = structure(method_series(load("methods/gauss2.json"), 6).phi)
>>> s.symplectic, s.symmetric
(6, 6)
>>> r = structure(method_series(load("methods/rk4.json"), 6).phi)
>>> r.symplectic, r.conjugate_symplectic, r.symmetric      # even order p: symmetric to p + 1
(4, 4, 5)
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp
from sympy.polys.matrices import DomainMatrix

from ..exact.field import solve_linear
from ..exact.grammar import format_entry
from ..render.model import Document, Math, Paragraph, Plain, Table, Typeset
from .bseries import BSeries, adjoint, compose, identity, inverse, modified_field, series_like
from .free_trees import free_tree
from .glm_order import theta_matrix
from .results import Result
from .trees import bracket, butcher_product, from_children, symmetry, trees_of_order

__all__ = ["structure", "SeriesStructure", "PSeriesStructure", "symplectic_order", "symmetric_order",
           "hamiltonian_order", "energy_order", "conjugate_symplectic", "tree_pairs"]


@lru_cache(maxsize=None)
def tree_pairs(n: int) -> tuple:
    """The unordered pairs {u, v} of trees with |u| + |v| = n."""
    out = []
    for k in range(1, n // 2 + 1):
        for u in trees_of_order(k):
            for v in trees_of_order(n - k):
                if k < n - k or u <= v:
                    out.append((u, v))
    return tuple(out)


def _symplectic_defects(vals, n, field: bool):
    for u, v in tree_pairs(n):
        d = vals[butcher_product(u, v)] + vals[butcher_product(v, u)]
        if not field:
            d = d - vals[u] * vals[v]
        yield (u, v), d


def _first_failure(a: BSeries, field: bool):
    F = a.field
    for n in range(2, a.max_order + 1):
        for pair, d in _symplectic_defects(a.values, n, field):
            if not F.is_zero(d):
                return n - 1, pair, F.to_sympy(d)
    return a.max_order, None, None


def symplectic_order(a: BSeries) -> int:
    """The largest n ≤ max_order with a(u∘v) + a(v∘u) = a(u)a(v) for |u| + |v| ≤ n."""
    return _first_failure(a, False)[0]


def hamiltonian_order(b: BSeries) -> int:
    """For a vector field: the largest n ≤ max_order with b(u∘v) + b(v∘u) = 0 for |u| + |v| ≤ n."""
    return _first_failure(b, True)[0]


def symmetric_order(a: BSeries) -> int:
    """The largest n ≤ max_order with a*(t) = a(t) for |t| ≤ n."""
    star = adjoint(a)
    for n in range(1, a.max_order + 1):
        if any(not a.field.is_zero(a.values[t] - star.values[t]) for t in trees_of_order(n)):
            return n - 1
    return a.max_order


@lru_cache(maxsize=None)
def _energy_classes(n: int) -> tuple:
    """For |t| = n: ((free tree of [t], ((t, sign([t])), ...)), ...), superfluous classes dropped."""
    classes: dict = {}
    for t in trees_of_order(n):
        ft = free_tree(from_children([t]))
        if not ft.superfluous:
            classes.setdefault(ft.key, []).append((t, ft.sign))
    return tuple((k, tuple(v)) for k, v in sorted(classes.items()))


def energy_order(b: BSeries) -> int:
    """For a vector field h f̃ = Σ h^{|t|} b(t)/σ(t) F(t): the largest n ≤ max_order such that the
    terms of order ≤ n conserve every Hamiltonian H of y′ = J⁻¹∇H (see the module docstring)."""
    F = b.field
    for n in range(1, b.max_order + 1):
        for _, members in _energy_classes(n):
            total = F.zero
            for t, sign in members:
                term = b.values[t] * F.rational(sp.Rational(sign, symmetry(t)))
                total = total + term
            if not F.is_zero(total):
                return n - 1
    return b.max_order


def _conjugated(a: BSeries, chi: BSeries) -> BSeries:
    """χ⁻¹∘Φ∘χ (χ applied first)."""
    return compose(compose(chi, a), inverse(chi))


def conjugate_symplectic(a: BSeries):
    """(n, χ): the largest n ≤ max_order for which a near-identity χ makes χ⁻¹Φχ symplectic up to
    order n, and that χ (a certificate: check it with :func:`symplectic_order`)."""
    F, K = a.field, a.field.K
    N = a.max_order
    chi = identity(N)
    chi = series_like(a, {t: F.lift(K.convert_from(chi.field.drop(v), chi.field.K)) for t, v in chi.values.items()},
               "χ")
    for n in range(2, N + 1):
        psi = _conjugated(a, chi)
        defects = [d for _, d in _symplectic_defects(psi.values, n, False)]
        if all(F.is_zero(d) for d in defects):
            continue
        if n == 2:                      # L₂ = 0: c(τ) never changes order 2
            return 1, chi
        prev = trees_of_order(n - 1)
        index = {t: i for i, t in enumerate(trees_of_order(n))}
        L = theta_matrix(n)
        rows = [[K.convert(L[index[butcher_product(u, v)]][j] + L[index[butcher_product(v, u)]][j])
                 for j in range(len(prev))] for u, v in tree_pairs(n)]
        M = DomainMatrix(rows, (len(rows), len(prev)), K)
        x = solve_linear(M, [-F.drop(d) for d in defects])
        if x is None:
            return n - 1, chi
        for sign in (1, -1):
            vals = dict(chi.values)
            for s, xs in zip(prev, x, strict=False):
                vals[s] = vals[s] + F.lift(xs) * F.rational(sign)
            trial = series_like(chi, vals, "χ")
            if all(F.is_zero(d) for _, d in _symplectic_defects(_conjugated(a, trial).values, n, False)):
                chi = trial
                break
        else:   # pragma: no cover - the linear model of the conjugation is exact; this would be a bug
            raise AssertionError(f"order {n}: the conjugation did not remove the symplectic defects")
    return N, chi


@dataclass(frozen=True)
class SeriesStructure(Result):
    """Orders to which a map's B-series is symplectic, conjugate-symplectic and symmetric, and its
    modified field Hamiltonian and energy-preserving; ``max_order`` is the budget (an order equal
    to it means "at least")."""

    label: str
    max_order: int
    order: int
    symplectic: int
    conjugate_symplectic: int
    symmetric: int
    hamiltonian: int
    energy_preserving: int
    symplectic_witness: tuple | None      # (u, v, defect) at the first failing order
    conjugacy: BSeries | None = None

    def _says(self, n):
        return f"to order ≥ {n} (budget)" if n >= self.max_order else f"to order {n}"

    def _text(self) -> str:
        lines = [f"{self.label}: B-series to order {self.max_order} (method order {self.order})",
                 f"  symplectic            {self._says(self.symplectic)}",
                 f"  conjugate-symplectic  {self._says(self.conjugate_symplectic)}",
                 f"  symmetric             {self._says(self.symmetric)}",
                 f"  modified field Hamiltonian {self._says(self.hamiltonian)}; "
                 f"energy-preserving {self._says(self.energy_preserving)}"]
        if self.symplectic_witness:
            u, v, d = self.symplectic_witness
            lines.append(f"  first symplectic defect: a(u∘v)+a(v∘u)−a(u)a(v) = {format_entry(d)} "
                         f"for u = {bracket(u)}, v = {bracket(v)}")
        return "\n".join(lines)

    def to_json(self):
        w = self.symplectic_witness
        return {"method": self.label, "max_order": self.max_order, "order": self.order,
                "symplectic": self.symplectic, "conjugate_symplectic": self.conjugate_symplectic,
                "symmetric": self.symmetric, "hamiltonian": self.hamiltonian,
                "energy_preserving": self.energy_preserving,
                "symplectic_witness": None if not w else
                {"u": bracket(w[0]), "v": bracket(w[1]), "defect": str(format_entry(w[2]))},
                "conjugating_map": self.conjugacy.to_json() if self.conjugacy is not None else None}

    def display(self) -> Document:
        """Text: each property's order; typeset: the table of them (≥: the budget was reached)."""
        head, *lines = self._text().split("\n")

        def cell(n):
            return Math(rf"\geq {n}" if n >= self.max_order else f"{n}")
        rows = (("symplectic", cell(self.symplectic)), ("conjugate-symplectic", cell(self.conjugate_symplectic)),
                ("symmetric", cell(self.symmetric)), ("energy-preserving", cell(self.energy_preserving)))
        return Document(head, (Plain(*(Paragraph(x) for x in lines)),
                               Typeset(Table(("property", "to order"), rows, "lc"))))


@dataclass(frozen=True)
class PSeriesStructure(Result):
    """What :func:`structure` says of a P-series (a partitioned method): the order to which its
    modified field has a modified energy (an H-series over bicoloured free trees,
    :mod:`modified_hamiltonian`), and which of the B-series checks do not apply."""

    label: str
    max_order: int
    order: int
    energy: int                       # the modified energy exists to this order (max_order: at least)

    NOT_APPLIED = ("symplectic", "conjugate-symplectic", "symmetric", "energy-preserving")

    def _text(self) -> str:
        got = (f"to order ≥ {self.energy} (budget)" if self.energy >= self.max_order
               else f"to order {self.energy} (the conditions fail at order {self.energy + 1})")
        return "\n".join([f"{self.label}: P-series to order {self.max_order} (method order {self.order})",
                          f"  modified energy (H-series over bicoloured free trees) {got}",
                          f"  not checked: {', '.join(self.NOT_APPLIED)} (the checks are written for B-series, "
                          "plain trees; for a partitioned method `verify` decides symplecticity from the tableau)"])

    def to_json(self):
        return {"method": self.label, "max_order": self.max_order, "order": self.order, "series": "P-series",
                "modified_energy": self.energy, "not_checked": list(self.NOT_APPLIED)}

    def display(self) -> Document:
        head, *lines = self._text().split("\n")
        n = rf"\geq {self.energy}" if self.energy >= self.max_order else str(self.energy)
        return Document(head, (Plain(*(Paragraph(x) for x in lines)), Typeset(Paragraph(
            f"As a P-series (order {self.order}) its modified field has a modified energy to order ", Math(n),
            f"; the B-series checks ({', '.join(self.NOT_APPLIED)}) do not apply."))))


def _pseries_structure(a: BSeries, field: BSeries | None) -> PSeriesStructure:
    from .bseries import series_order
    from .modified_hamiltonian import modified_hamiltonian
    b = field if field is not None else modified_field(a)
    return PSeriesStructure(a.label, a.max_order, series_order(a), modified_hamiltonian(b).order)


def structure(a: BSeries, field: BSeries | None = None) -> SeriesStructure | PSeriesStructure:
    """Every property above, for the map ``a`` to its ``max_order`` (``field``: its modified field,
    when the caller has it already); for a P-series the modified energy only
    (:class:`PSeriesStructure` says which checks do not apply)."""
    from .bseries import series_order
    if a.kind.coloured:
        return _pseries_structure(a, field)
    n, pair, d = _first_failure(a, False)
    b = field if field is not None else modified_field(a)
    conj, chi = conjugate_symplectic(a)
    return SeriesStructure(a.label, a.max_order, series_order(a), n, conj, symmetric_order(a),
                           hamiltonian_order(b), energy_order(b), None if pair is None else (pair[0], pair[1], d),
                           chi)
