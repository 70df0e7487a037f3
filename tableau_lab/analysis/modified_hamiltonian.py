r"""Modified Hamiltonians: first integrals of the modified equation written in elementary
Hamiltonians ([HLW06] IX.3, IX.9 Thm 9.3; Chartier, Faou & Murua, *Numer. Math.* 103 (2006)).

An H-series is I = Σ_π h^{|π|−1} β(π) H(π) over non-superfluous free trees π (H(π) the elementary
Hamiltonian of π's canonical rooting, :mod:`free_trees`), β(τ) = 1 so that I = H + O(h).  Along the
modified field h f̃ = Σ_s h^{|s|} b(s)/σ(s) F(s), the derivative of H(r) in the direction F(s) is
Σ_v H(r with s grafted at the vertex v), so

    d/dt I(ỹ) = Σ_{π, s} h^{|π|+|s|−2} β(π) b(s)/σ(s) Σ_v H(π ←_v s),

and reducing every grafted tree to ± its free tree makes I′f̃ = 0 a triangular linear system for
β, order by order (the unknowns β(π), |π| = n − 1, enter the order-n equations with s = τ).  It is
solvable to every order for symplectic methods (I = H̃, the modified Hamiltonian), conjugate-
symplectic ones (H̃ in the original variables) and energy-preserving ones (I = H); a method
without such a modified energy shows an inconsistent system at some order.

>>> from tableau_lab.exact.tableau_json import load
>>> from tableau_lab.analysis.method_series import method_series
>>> from tableau_lab.analysis.bseries import modified_field
>>> from tableau_lab.analysis.trees import bracket
>>> mh = modified_hamiltonian(modified_field(method_series(load("methods/implicit_midpoint.json"), 5).phi))
>>> mh.order, [(bracket(k), str(v)) for k, v in mh.terms(3)]      # H̃ = H − h²/24 H″(f, f) + …
(5, [('[τ²]', '-1/24')])
>>> import sympy as sp
>>> q, p = sp.symbols("q p")
>>> sp.expand(mh.expression(p**2 / 2 - sp.cos(q), (q,), (p,), 3))     # the h² term for the pendulum
-p**2*cos(q)/24 - sin(q)**2/24
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp
from sympy.polys.matrices import DomainMatrix

from ..exact.field import solve_linear
from ..exact.grammar import format_entry
from ..exact.render import LATEX, TEXT, exact_sum
from ..render.model import Document, Formula, Paragraph, Plain, Typeset
from .bseries import BSeries
from .free_trees import free_tree, rootings
from .results import Result
from .tree_kinds import PLAIN, TreeKind, graft

__all__ = ["modified_hamiltonian", "ModifiedHamiltonian", "elementary_hamiltonian", "elementary_differential"]


@lru_cache(maxsize=None)
def _graftings(key, s, kind: TreeKind) -> tuple:
    """((free key, sign), ...) of key with s grafted at each vertex, superfluous results dropped."""
    out = []
    for g in graft(kind, key, s):
        ft = free_tree(g, kind)
        if not ft.superfluous:
            out.append((ft.key, ft.sign))
    return tuple(out)


@lru_cache(maxsize=None)
def _keys(n: int, kind: TreeKind = PLAIN) -> tuple:
    """The non-superfluous free trees with n vertices (canonical keys)."""
    return tuple(k for k, rs in sorted(rootings(n, kind).items()) if not free_tree(rs[0][0], kind).superfluous)


@dataclass(frozen=True)
class ModifiedHamiltonian(Result):
    """β(π) for the free trees π with |π| ≤ ``order`` (exact); ``order`` < ``max_order`` when the
    system became inconsistent at order + 1 (no modified energy beyond); ``free`` counts the
    undetermined directions met (0 when the invariant is unique)."""

    label: str
    max_order: int
    order: int
    beta: dict                  # free key -> exact sympy value
    free: int = 0
    kind: TreeKind = PLAIN

    def terms(self, n: int) -> list:
        """[(free key, β)] for the nonzero β of free trees with n vertices (the h^(n−1) term)."""
        return [(k, self.beta[k]) for k in _keys(n, self.kind) if k in self.beta and self.beta[k] != 0]

    def expression(self, H, q, p, upto: int, h=None):
        """Σ_{|π| ≤ upto} h^{|π|−1} β(π) H(π) for the Hamiltonian ``H`` in the symbols q, p (sympy),
        with ``h`` a symbol or number (None: only the term of order ``upto``, without h)."""
        state = tuple(q) + tuple(p)
        f = _hamiltonian_field(H, tuple(q), tuple(p))
        cache: dict = {"kind": self.kind, "split": len(q)}
        total = sp.Integer(0)
        orders = range(1, upto + 1) if h is not None else [upto]
        for n in orders:
            for k, b in self.terms(n):
                term = b * elementary_hamiltonian(k, H, state, f, cache)
                total += term * (h ** (n - 1) if h is not None else 1)
        return total

    def display(self) -> Document:
        """H̃ = H + h(…) + …: text one line per power of h, typeset one formula."""
        head = (f"{self.label}: modified energy H̃ = H + …, free trees to order {self.order}"
                + (f" (the conditions fail at order {self.order + 1})" if self.order < self.max_order else ""))
        lines = [Paragraph(f"  h^{n - 1}: {self.sum(n, TEXT)}") for n in range(2, self.order + 1) if self.terms(n)]
        parts = [f"h^{{{n - 1}}}\\left({self.sum(n, LATEX)}\\right)" for n in range(2, self.order + 1) if self.terms(n)]
        tex = r"\tilde H = H + " + " + ".join(parts) if parts else r"\tilde H = H"
        return Document(head, (Plain(*lines), Typeset(Formula(tex))), math=True)

    def sum(self, n: int, notation=TEXT, number=None, **rows) -> str:
        """The h^(n−1) term Σ β(π) H(π) printed in ``notation`` (TEXT or LATEX; ``number``: the
        writer of values, e.g. the report's named constants; ``rows``: :func:`exact_sum`'s)."""
        tree = self.kind.tex if notation is LATEX else self.kind.bracket
        pairs = [(v, f"H({tree(k)})") for k, v in self.terms(n)]
        return exact_sum(pairs, notation if number is None else notation.using(number), **rows)

    def to_json(self):
        return {"label": self.label, "max_order": self.max_order, "order": self.order, "free": self.free,
                "beta": {self.kind.bracket(k): str(format_entry(v)) for k, v in self.beta.items() if v != 0}}


def modified_hamiltonian(b: BSeries) -> ModifiedHamiltonian:
    """The H-series first integral of the modified field ``b`` (see the module docstring), free
    trees up to ``b.max_order``."""
    F, K, kind = b.field, b.field.K, b.kind
    N = b.max_order
    beta = {_keys(1, kind)[0]: F.one}
    free = 0
    for n in range(3, N + 2):                         # β(τ) = 1; conditions on free trees of size n
        targets = _keys(n, kind)
        index = {k: i for i, k in enumerate(targets)}
        known = [F.zero] * len(targets)
        for m in range(1, n - 1):                     # β(π), |π| = m, with fields s of order n − m ≥ 2
            for key in _keys(m, kind):
                bk = beta.get(key)
                if bk is None or F.is_zero(bk):
                    continue
                for s in kind.trees_of_order(n - m):
                    bs = b.values[s]
                    if F.is_zero(bs):
                        continue
                    w = bk * bs * F.rational(sp.Rational(1, kind.symmetry(s)))
                    for gk, sign in _graftings(key, s, kind):
                        known[index[gk]] = known[index[gk]] + (w if sign > 0 else -w)
        unknowns = _keys(n - 1, kind)
        if not unknowns:
            if any(not F.is_zero(x) for x in known):
                return _result(b, n - 2, beta, free)
            continue
        rows = [[K.zero] * len(unknowns) for _ in targets]
        for leaf in kind.leaves():               # b(τ) = 1 for a consistent method (τ●, τ○ for P-series)
            bt = F.drop(b.values[leaf])
            for j, key in enumerate(unknowns):
                for gk, sign in _graftings(key, leaf, kind):
                    rows[index[gk]][j] = rows[index[gk]][j] + (bt if sign > 0 else -bt)
        M = DomainMatrix(rows, (len(targets), len(unknowns)), K)
        x = solve_linear(M, [-F.drop(v) for v in known])
        if x is None:
            return _result(b, n - 2, beta, free)
        free += len(unknowns) - M.rank()
        for key, xv in zip(unknowns, x, strict=False):
            beta[key] = F.lift(xv)
    return _result(b, N, beta, free)


def _result(b, order, beta, free):
    F = b.field
    return ModifiedHamiltonian(b.label, b.max_order, order,
                               {k: F.to_sympy(v) for k, v in beta.items() if b.kind.order(k) <= order}, free, b.kind)


# ------------------------------------------------------------ elementary Hamiltonians of a problem

def _hamiltonian_field(H, q, p):
    return tuple(sp.diff(H, x) for x in p) + tuple(-sp.diff(H, x) for x in q)


def _multilinear(g, state, vectors):
    """g^(m)(y)(v₁, …, v_m) for the directional vectors (expressions in y): differentiate with
    placeholder directions first, so that the vectors' own dependence on y is not differentiated."""
    dirs = [[sp.Dummy() for _ in state] for _ in vectors]
    out = g
    for d in dirs:
        out = sum(sp.diff(out, y) * di for y, di in zip(state, d, strict=False))
    return out.xreplace({di: vi for d, v in zip(dirs, vectors, strict=False) for di, vi in zip(d, v, strict=False)})


def elementary_differential(t, state, f, cache=None) -> tuple:
    """F(t)(y) for the field ``f`` (a tuple of expressions in ``state``), symbolically.  For a
    bicoloured tree (``cache["kind"]`` BICOLOURED, ``cache["split"]`` = d, state = (q₁..q_d, p₁..p_d))
    F(t) is f⁽ᵐ⁾(F(t₁), …) restricted to the block of t's colour (q for 0, p for 1) and zero on the
    other: f_q = ∂H/∂p is then differentiated along q for colour-0 children and p for colour-1 ones."""
    cache = {} if cache is None else cache
    kind, d = cache.get("kind", PLAIN), cache.get("split", 0)
    if ("F", t) not in cache:
        colour, ch = kind.split(t)
        vs = [elementary_differential(c, state, f, cache) for c in ch]
        out = tuple(_multilinear(fi, state, vs) for fi in f) if vs else tuple(f)
        if kind.coloured:
            out = tuple(x if (i < d) == (colour == 0) else sp.Integer(0) for i, x in enumerate(out))
        cache[("F", t)] = out
    return cache[("F", t)]


def elementary_hamiltonian(t, H, state, f, cache=None):
    """H(t)(y) = H^(m)(y)(F(t₁), …, F(t_m)) for t = [t₁ … t_m] (H(τ) = H; a bicoloured root's
    colour plays no part)."""
    cache = {} if cache is None else cache
    vs = [elementary_differential(c, state, f, cache) for c in cache.get("kind", PLAIN).children(t)]
    return _multilinear(H, state, vs)
