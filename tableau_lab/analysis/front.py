r"""The one-call questions of the public API that no single analysis answered as asked (the names
NodePy users type): the imaginary stability interval, the principal error norm, the stability
function R(z) = P(z)/Q(z), and the modified Hamiltonian of a method for a given H.  Each reads
the exact analysis that owns the property (:mod:`stability`, :mod:`rk_order`,
:mod:`modified_hamiltonian`) and adds nothing to it.

>>> import tableau_lab as tl
>>> rk4 = tl.load("rk4")
>>> imaginary_stability_interval(rk4), float(imaginary_stability_interval(rk4))
(2*sqrt(2), 2.8284271247461903)
>>> principal_error_norm(rk4)           # NodePy: rk4.principal_error_norm() = 0.014504582343198208
sqrt(1745)/2880
>>> print(stability_function(rk4))
R(z) = z**4/24 + z**3/6 + z**2/2 + z + 1
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..errors import InputError
from ..exact.grammar import format_entry
from ..exact.methods import Method, RungeKutta
from ..render.model import Document, Formula, Typeset
from .bseries import modified_field
from .method_series import method_series
from .modified_hamiltonian import ModifiedHamiltonian, modified_hamiltonian as hamiltonian_series
from .results import Result
from .rk_order import rk_order
from .stability import Z, stability, stability_function as rk_polynomials

__all__ = ["imaginary_stability_interval", "principal_error_norm", "stability_function", "StabilityFunction",
           "modified_hamiltonian", "MethodHamiltonian"]


def imaginary_stability_interval(method: Method):
    r"""The exact half-length Y of the imaginary-axis interval in the method's region of absolute
    stability: every root w of the characteristic polynomial has |w| ≤ 1 for z = iy, |y| ≤ Y
    (RK: |R(iy)| ≤ 1; ``sympy.oo`` for the whole axis).  NodePy's
    ``imaginary_stability_interval``, exact: a sympy number (``float()`` gives its value), found by
    the certified axis analysis of :func:`tableau_lab.stability` (its ``bounded_radius``; for a
    (G-)symplectic method the radius where every root stays *on* the unit circle is
    ``m.stability().unit_radius``).  A partitioned RK method is analysed on the harmonic
    oscillator, x = hω.  Reference: [HW96] Hairer & Wanner, *Solving ODEs II*, §IV.2–IV.3; the
    method of docs/stability.md.

    >>> import tableau_lab as tl
    >>> tl.imaginary_stability_interval(tl.load("rk4"))            # [HW96] Fig. IV.2.1: 2√2
    2*sqrt(2)
    >>> tl.imaginary_stability_interval(tl.load("gauss:2")), tl.imaginary_stability_interval(tl.load("explicit_euler"))
    (oo, 0)
    """
    return stability(method).bounded_radius


def principal_error_norm(method: Method):
    r"""A^(p+1) = ‖τ^(p+1)‖₂ of a Runge–Kutta method of order p, exact: the 2-norm of the
    principal error coefficients τ(t) = (Φ(t) − 1/γ(t))/σ(t) over the rooted trees t of order
    p + 1 (NodePy's ``principal_error_norm``, whose float value it equals; [HNW93] Hairer,
    Nørsett & Wanner, *Solving ODEs I*, §II.3; Kennedy, Carpenter & Lewis, Appl. Numer. Math. 35
    (2000) for A^(p+1)).  Computed by :func:`tableau_lab.analysis.rk_order.rk_order`.

    >>> import tableau_lab as tl
    >>> tl.principal_error_norm(tl.load("rk4"))        # NodePy's error_metrics: sqrt(1745)/2880
    sqrt(1745)/2880
    >>> tl.principal_error_norm(tl.load("explicit_euler"))     # τ([τ]) = (0 − 1/2)/1
    1/2
    """
    if not isinstance(method, RungeKutta):
        raise TypeError(f"{method.name}: the principal error norm is defined here for Runge–Kutta methods, "
                        f"not {method.kind!r} (the order analysis m.order() lists the error terms of every kind)")
    result = rk_order(method, effective=False)
    if result.principal_error_norm is None:
        raise InputError(f"{method.name}: the principal error coefficients were not all computed "
                         "(rk_order.ERROR_TREES_BUDGET trees of order p + 1)")
    return result.principal_error_norm


@dataclass(frozen=True)
class StabilityFunction(Result):
    """R(z) = P(z)/Q(z) of an RK method, P = det(I − zA + z𝟙bᵀ), Q = det(I − zA), exact (sympy
    expressions in ``z``); callable: ``R(z0)`` is R at z0."""

    method: str
    numerator: sp.Expr
    denominator: sp.Expr

    @property
    def expression(self) -> sp.Expr:
        """R(z) as one sympy expression, P/Q (a polynomial when Q = 1)."""
        return self.numerator if self.denominator == 1 else self.numerator / self.denominator

    def __call__(self, z):
        return self.expression.subs(Z, z)

    def display(self) -> Document:
        P, Q = (str(format_entry(x)) for x in (self.numerator, self.denominator))
        Pt, Qt = sp.latex(self.numerator), sp.latex(self.denominator)
        if self.denominator == 1:
            return Document(f"R(z) = {P}", (Typeset(Formula(f"R(z) = {Pt}")),), math=True)
        return Document(f"R(z) = ({P})/({Q})", (Typeset(Formula(rf"R(z) = \frac{{{Pt}}}{{{Qt}}}")),), math=True)

    def to_json(self):
        return {"method": self.method, "numerator": str(format_entry(self.numerator)),
                "denominator": str(format_entry(self.denominator))}


def stability_function(method: Method) -> StabilityFunction:
    r"""The stability function R(z) = P(z)/Q(z) of a Runge–Kutta method, exact: the numbers a step
    multiplies y by on y′ = λy, z = hλ ([HW96] §IV.3, eq. (3.3): P(z) = det(I − zA + z𝟙bᵀ),
    Q(z) = det(I − zA); NodePy's ``stability_function`` gives P and Q as float polynomials).
    For GLMs and partitioned methods the characteristic polynomial is ``m.stability().polynomial``.

    >>> import tableau_lab as tl
    >>> R = tl.stability_function(tl.load("gauss:2"))
    >>> print(R)
    R(z) = (z**2/12 + z/2 + 1)/(z**2/12 - z/2 + 1)
    >>> R(-1) == sp.Rational(7, 19)      # the (2,2) Padé approximant of e^z at z = −1
    True
    """
    if method.kind != "rk":
        raise TypeError(f"{method.name}: R(z) is the stability function of a Runge–Kutta method, not of a "
                        f"{method.kind!r}; its characteristic polynomial is m.stability().polynomial")
    N, D, _ = rk_polynomials(method)
    return StabilityFunction(method.name, N.as_expr().subs(sp.Symbol("z"), Z), D.as_expr().subs(sp.Symbol("z"), Z))


@dataclass(frozen=True)
class MethodHamiltonian(Result):
    """A method's modified Hamiltonian for one H: ``expression`` = Σ_{k<n} h^k H̃_k(q, p) (exact
    sympy, in the symbol ``h``), from the H-series ``series`` (β over free trees, [HLW06] IX.9);
    ``order`` < ``max_order`` when no modified energy exists beyond (the method is not
    symplectic or conjugate-symplectic there)."""

    method: str
    H: sp.Expr
    expression: sp.Expr
    max_order: int
    series: ModifiedHamiltonian

    @property
    def order(self) -> int:
        """The free-tree order to which the modified energy exists (≤ ``max_order``)."""
        return self.series.order

    def display(self) -> Document:
        note = "" if self.order == self.max_order else (
            f" (no modified energy beyond order {self.order}: the conditions fail at order {self.order + 1})")
        return Document(f"{self.method}: H̃ = {self.expression}, free trees to order {self.order}{note}",
                        (Typeset(Formula(r"\tilde H = " + sp.latex(self.expression))),), math=True)

    def to_json(self):
        return {"method": self.method, "H": str(self.H), "expression": str(self.expression),
                "max_order": self.max_order, "order": self.order, "series": self.series.to_json()}


def _canonical_pairs(H, q, p):
    """(q, p) as tuples of symbols: given, or H's symbols named q, q1, … and p, p1, … ."""
    if q is None and p is None:
        syms = sorted(H.free_symbols - {sp.Symbol("h")}, key=lambda s: s.name)
        qs = tuple(s for s in syms if s.name[:1] == "q" and s.name[1:].isdigit() | (s.name == "q"))
        ps = tuple(s for s in syms if s.name[:1] == "p" and s.name[1:].isdigit() | (s.name == "p"))
        other = [s.name for s in syms if s not in qs + ps]
        if other or len(qs) != len(ps) or not qs:
            raise InputError(f"modified_hamiltonian: H = {H}: name the positions and momenta q, p (or q1, p1, …), "
                             f"or pass q=(...), p=(...)" + (f"; H also has {', '.join(other)}" if other else ""))
        return qs, ps

    def as_tuple(v):                             # one symbol or a list/tuple of them
        return tuple(v) if isinstance(v, (list, tuple)) else (v,)

    return as_tuple(q), as_tuple(p)


STEP = sp.Symbol("h")      # the step size symbol of H̃'s expression (immutable: a safe default argument)


def modified_hamiltonian(method: Method, H, n: int, q=None, p=None, h=STEP) -> MethodHamiltonian:
    r"""The modified Hamiltonian H̃ = H + h H̃₂ + h² H̃₃ + … of ``method`` for the Hamiltonian ``H``
    (a sympy expression in q, p — or q1, p1, … — or in the symbols ``q``, ``p`` given), with the
    free trees of order ≤ ``n`` (terms up to h^(n−1)): the exact first integral of the method's
    modified equation ([HLW06] Hairer, Lubich & Wanner, *Geometric Numerical Integration*, 2nd
    ed., §IX.3 and Thm IX.9.3; Chartier, Faou & Murua, Numer. Math. 103 (2006)).  One call for
    ``modified_hamiltonian(modified_field(method_series(m, n).phi)).expression(H, q, p, ...)``.
    For a partitioned method the first partition is q.

    >>> import tableau_lab as tl, sympy as sp
    >>> q, p = sp.symbols("q p")
    >>> mh = tl.modified_hamiltonian(tl.load("implicit_midpoint"), p**2/2 - sp.cos(q), 3)
    >>> mh.expression.coeff(sp.Symbol("h"), 2)           # [HLW06] IX.3: −h²/24 H″(f, f) for the midpoint rule
    -p**2*cos(q)/24 - sin(q)**2/24
    """
    if isinstance(H, str):
        raise TypeError("modified_hamiltonian: H is a sympy expression (e.g. p**2/2 - sympy.cos(q)); text is "
                        "not evaluated")
    H = sp.sympify(H, strict=True)
    qs, ps = _canonical_pairs(H, q, p)
    series = hamiltonian_series(modified_field(method_series(method, n).phi))
    total = H
    for k in range(2, series.order + 1):
        total += h ** (k - 1) * sp.expand(series.expression(H, qs, ps, k))
    return MethodHamiltonian(method.name, H, total, n, series)
