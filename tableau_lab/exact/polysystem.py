r"""Exact solution of polynomial systems: the algebra behind method design.

A system of polynomial equations over QQ or a number field QQ<α> is split into
components by Gröbner bases and factorisation: compute the reduced lex Gröbner basis;
if it is {1} there is no solution; if one of its elements factors, the variety is the
union of the varieties obtained by adding each factor, and each is treated again;
otherwise the basis is a component.  Components contained in another one are dropped.
Each component is then parametrised by back-substitution in its lex basis, smallest
variable first: a variable that leads no basis element is free; one whose leading
element is linear in it is a rational function of the variables below it (its
coefficient must not vanish: a branch condition); one whose leading element is a
polynomial with constant coefficients takes each of its roots in radicals (sympy
``roots``), one branch per root.  Nothing here uses floating point except to tell
real roots from complex ones after they are found exactly (50 digits).

Gröbner bases are sympy's (Buchberger / F5B over ``QQ`` or ``QQ<α>``).  They are doubly
exponential in the worst case: systems of a dozen unknowns of low degree, as in the
design of methods with few stages, take seconds; large ones can take very long.

>>> import sympy as sp
>>> x, y = sp.symbols("x y", real=True)
>>> sys = PolynomialSystem([x, y])
>>> comps = sys.components([sys.poly(x**2 - y), sys.poly(x * y - y)])
>>> sorted(str([g.as_expr() for g in c]) for c in comps)
['[x - 1, y - 1]', '[x, y]']
>>> [b.values for b in sys.parametrise(sys.components([sys.poly(x**2 - 2)])[0])]
[{x: -sqrt(2)}, {x: sqrt(2)}]
"""
from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import sympy as sp
from sympy.polys.groebnertools import groebner
from sympy.polys.orderings import lex
from sympy.polys.rings import PolyRing

from ..budget import computing
from ..errors import InputError
from .field import element, field_of, is_zero, normal_form

__all__ = ["PolynomialSystem", "Branch", "SystemError_"]


class SystemError_(InputError):
    """An expression that is not a rational function of the unknowns over a number field."""


@dataclass
class Branch:
    """One parametrised piece of a component: ``values`` maps each determined unknown to an
    exact expression in the ``free`` ones; ``conditions`` are expressions that must not vanish;
    ``implicit`` lists unknowns given only as a root of a polynomial (no radical form);
    ``real`` is False when a value is a non-real complex number."""

    values: dict[sp.Symbol, sp.Expr]
    free: list[sp.Symbol] = field(default_factory=list)
    conditions: list[sp.Expr] = field(default_factory=list)
    implicit: dict[sp.Symbol, sp.Expr] = field(default_factory=dict)
    real: bool = True


class PolynomialSystem:
    """Polynomials in the given unknowns (lex order: first is largest) over the number field
    of the constants that appear (``constants``: expressions whose radicals must be in it)."""

    def __init__(self, unknowns: Iterable[sp.Symbol], constants: Iterable[Any] = ()) -> None:
        self.K = field_of([sp.sympify(c) for c in constants] or [sp.Integer(0)])
        if not (self.K.is_QQ or self.K.is_Algebraic):
            raise SystemError_("the constants of a system must be numbers (no free symbols)")
        self._order(unknowns)

    def _order(self, unknowns: Iterable[sp.Symbol]) -> None:
        self.unknowns = list(unknowns)
        self.R = PolyRing(self.unknowns, self.K, lex)
        self.F = self.R.to_field()
        self._index = {s: i for i, s in enumerate(self.unknowns)}

    # ------------------------------------------------------------ conversion
    def frac(self, e: Any) -> Any:
        """A sympy expression as an element of the fraction field K(unknowns)."""
        e = sp.sympify(e)
        F = self.F
        if e.is_Symbol:
            if e not in self._index:
                raise SystemError_(f"{e} is not one of the unknowns {', '.join(map(str, self.unknowns))}")
            return F.gens[self._index[e]]
        if not e.free_symbols:
            return F.ground_new(element(self.K, e))
        if e.is_Add:
            out = F.zero
            for a in e.args:
                out = out + self.frac(a)
            return out
        if e.is_Mul:
            out = F.one
            for a in e.args:
                out = out * self.frac(a)
            return out
        if e.is_Pow and e.exp.is_Integer:
            base = self.frac(e.base)
            return base ** int(e.exp) if e.exp >= 0 else F.one / base ** int(-e.exp)
        raise SystemError_(f"{e} is not a rational function of the unknowns")

    def poly(self, e: Any) -> Any:
        """The numerator of a rational expression: the polynomial whose zeros are wanted."""
        return self.frac(e).numer

    def expr(self, p: Any) -> sp.Expr:
        return p.as_expr()

    # ------------------------------------------------------------ solving
    def groebner(self, polys: Iterable[Any]) -> list[Any]:
        polys = [p for p in polys if p]
        if not polys:
            return []
        with computing(f"Gröbner basis of {len(polys)} equations in {len(self.R.gens)} unknowns"):
            basis: list[Any] = groebner(polys, self.R)
            return basis

    def consistent(self, polys: Iterable[Any]) -> bool:
        return self.groebner(polys) != [self.R.one]

    def components(self, polys: Iterable[Any]) -> list[list[Any]]:
        """Reduced lex Gröbner bases of the components (no factor splits further), minimal:
        none lies inside another."""
        out: list[list[Any]] = []
        seen: set[tuple[str, ...]] = set()
        stack = [list(polys)]
        while stack:
            G = self.groebner(stack.pop())
            if G == [self.R.one]:
                continue
            key = tuple(sorted(str(g) for g in G))
            if key in seen:
                continue
            seen.add(key)
            split = None
            for g in G:          # a product, or a power of one factor: one system per factor
                factors = [(f, e) for f, e in g.factor_list()[1] if not f.is_ground]
                if len(factors) > 1 or any(e > 1 for _, e in factors):
                    split = [f for f, _ in factors]
                    break
            if split:
                stack.extend(G + [f] for f in split)
            else:
                out.append(G)
        return self._minimal(out)

    def _contains(self, big: list[Any], small: list[Any]) -> bool:
        """V(small) ⊆ V(big): every generator of big reduces to zero modulo small's basis."""
        return all(not g.rem(small) for g in big) if small else not big

    def _minimal(self, comps: list[list[Any]]) -> list[list[Any]]:
        keep = []
        for i, c in enumerate(comps):
            inside = any(j != i and self._contains(d, c) and not (self._contains(c, d) and j > i)
                         for j, d in enumerate(comps))
            if not inside:
                keep.append(c)
        return keep

    def core(self, labelled: list[tuple[str, object]]) -> list[tuple[str, object]]:
        """A minimal inconsistent subset (deletion filter) of an inconsistent labelled system."""
        cur = list(labelled)
        i = 0
        while i < len(cur):
            trial = cur[:i] + cur[i + 1:]
            if not self.consistent([p for _, p in trial]):
                cur = trial
            else:
                i += 1
        return cur

    def reorder(self, unknowns: Iterable[sp.Symbol]) -> PolynomialSystem:
        """The same system with another variable order (constants shared)."""
        other = PolynomialSystem.__new__(PolynomialSystem)
        other.K = self.K
        other._order(unknowns)
        return other

    def explicit_parametrisation(self, G: list[Any], movable: Iterable[sp.Symbol]
                                 ) -> tuple[PolynomialSystem, list[Branch]]:
        """Branches of the component G, trying other lex orders (each of ``movable`` made the
        smallest variable in turn) when the first one leaves an unknown implicit (a root of a
        polynomial with parametric coefficients): a curve that is 2:1 over one coordinate can be
        rational over another."""
        branches = self.parametrise(G)
        if not any(b.implicit for b in branches):
            return self, branches
        exprs = [g.as_expr() for g in G]
        for v in movable:
            other = self.reorder([u for u in self.unknowns if u != v] + [v])
            alt = other.parametrise(other.groebner([other.poly(e) for e in exprs]))
            if alt and not any(b.implicit for b in alt):
                return other, alt
        return self, branches

    def parametrise(self, G: list[Any]) -> list[Branch]:
        """Branches of the component with lex basis G (see the module docstring)."""
        gens = self.unknowns
        lead: dict[sp.Symbol, list[Any]] = {}
        for g in G:
            v = min(i for i in range(len(gens)) if any(m[i] for m in g.monoms()))
            lead.setdefault(gens[v], []).append(g)
        branches = [Branch(values={})]
        for x in reversed(gens):
            nxt = []
            for br in branches:
                nxt.extend(self._solve_for(x, lead.get(x, []), br))
            branches = nxt
        return branches

    def _solve_for(self, x: sp.Symbol, polys: list[Any], br: Branch) -> list[Branch]:
        if not br.real:            # a complex branch is reported, not parametrised further
            return [br]
        if not polys:
            br.free.insert(0, x)
            return [br]
        subs = [sp.expand(p.as_expr().subs(br.values)) for p in polys]
        subs = [q for q in subs if not _zero(q)]
        if not subs:
            br.free.insert(0, x)
            return [br]
        q = min(subs, key=lambda e: sp.degree(e, x))
        P = sp.Poly(q, x)
        if P.degree() == 1:
            c1, c0 = P.all_coeffs()
            val = _nf(-c0 / c1)
            if c1.free_symbols and not _zero(c1):
                br.conditions.append(_nf(c1))
            return self._check(x, val, subs, br)
        coeffs = P.all_coeffs()
        if any(c.free_symbols for c in coeffs):
            br.implicit[x] = q
            return [br]
        roots = sp.roots(P, multiple=True)
        if len(roots) < P.degree():
            br.implicit[x] = q
            return [br]
        out: list[Branch] = []
        real = {r: _is_real(r) for r in dict.fromkeys(roots)}
        for r in sorted(real, key=lambda r: (not real[r], complex(sp.N(r, 30)).real)):
            nb = Branch(values=dict(br.values), free=list(br.free), conditions=list(br.conditions),
                        implicit=dict(br.implicit), real=real[r])
            out.extend(self._check(x, _nf(r) if nb.real else r, subs, nb))
        return out

    def _check(self, x: sp.Symbol, val: sp.Expr, subs: list[sp.Expr], br: Branch) -> list[Branch]:
        br.values[x] = val
        if br.real and not br.implicit:     # with an implicit unknown, zero tests need its relation
            for q in subs:
                if not _zero(q.subs(x, val)):
                    return []
        return [br]


def _is_real(r: sp.Expr) -> bool:
    """A root in radicals is real when its imaginary part vanishes (to 50 digits: roots of a
    polynomial over QQ<α> are separated far more widely than that)."""
    return not r.has(sp.I) or abs(complex(sp.N(sp.im(r), 50))) < 1e-40


def _zero(e: Any) -> bool:
    """Exact zero test (complex branches are never parametrised, so no i reaches here)."""
    return is_zero(sp.sympify(e))


def _nf(e: Any) -> sp.Expr:
    return normal_form(sp.sympify(e))
