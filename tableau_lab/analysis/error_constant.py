r"""The classical error constant of a linear multistep method, exactly.

For Σⱼ₌₀ᵏ αⱼ y_{n+j} = h Σⱼ₌₀ᵏ βⱼ f_{n+j} the difference operator ([HNW93] Hairer, Nørsett &
Wanner, *Solving ODEs I*, §III.2, eq. (2.3); P. Henrici, *Discrete Variable Methods in ODEs*,
1962; J. D. Lambert, *Numerical Methods for Ordinary Differential Systems*, 1991, §3.5)

    L(y, x, h) = Σⱼ αⱼ y(x + jh) − h Σⱼ βⱼ y′(x + jh) = Σ_q C_q h^q y^(q)(x),

    C₀ = Σⱼ αⱼ,   C_q = (1/q!) (Σⱼ αⱼ j^q − q Σⱼ βⱼ j^(q−1))   (q ≥ 1),

vanishes to order p (C₀ = … = C_p = 0) and C_{p+1} ≠ 0 is the error constant.  It scales with
(α, β), so two normalisations are printed:

* ``C`` = C_{p+1} with αₖ = 1 — the value Lambert's tables give (BDF2: −2/9, Adams–Bashforth 2:
  5/12);
* ``normalised`` = C_{p+1}/σ(1), σ(1) = Σ βⱼ — invariant under scaling (Henrici's error
  constant; BDF k: −1/(k + 1)).
  For Adams methods σ(1) = 1 and the two agree.

The method is a linear multistep method when :func:`multistep.as_lmm` finds its (α, β): the
GLM of :func:`multistep.lmm` (the families ``bdf:k``, ``adams_bashforth:k``, ``adams_moulton:k``,
``nystrom:k``, ``milne_simpson:k``; NodePy's ``LinearMultistepMethod`` through ``load``), or a
one-stage GLM whose stage is the solution value (the shipped ``adams_bashforth2``, ``leapfrog``).

>>> from tableau_lab.exact.library import family
>>> e = error_constant(family("bdf:2"))
>>> e.order, e.C, e.normalised
(2, -2/9, -1/3)
>>> print(error_constant(family("adams_bashforth:3")))
Adams–Bashforth, 3 steps (as a GLM): order 3, error constant C₄ = 3/8 (α₃ = 1; C₄/σ(1) = 3/8, σ(1) = 1)
"""
from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..exact.grammar import format_entry
from ..exact.methods import Method, MethodError
from ..exact.multistep import as_lmm
from ..render.model import Document, Math, Paragraph, Typeset
from .results import Result

__all__ = ["error_constant", "ErrorConstantResult", "lmm_constants"]

_SUB = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")


def lmm_constants(alpha, beta, upto: int) -> list:
    """[C₀, C₁, …, C_upto] of the LMM (α, β) (module docstring), exact.

    >>> lmm_constants([-1, 1], [sp.Rational(1, 2), sp.Rational(1, 2)], 3)   # the trapezoidal rule
    [0, 0, 0, -1/12]
    """
    out = [sum(alpha, sp.Integer(0))]
    for q in range(1, upto + 1):
        s = sum((a * sp.Integer(j) ** q for j, a in enumerate(alpha)), sp.Integer(0)) \
            - q * sum((b * sp.Integer(j) ** (q - 1) for j, b in enumerate(beta)), sp.Integer(0))
        out.append(sp.expand(s / sp.factorial(q)))
    return out


@dataclass(frozen=True)
class ErrorConstantResult(Result):
    """Order p and error constant of an LMM, in both normalisations (module docstring);
    ``float(result)`` is C_{p+1} with αₖ = 1."""

    method: str
    order: int
    C: sp.Expr                 # C_{p+1}, αₖ = 1 (exact)
    sigma1: sp.Expr            # σ(1) = Σ βⱼ (αₖ = 1)
    normalised: sp.Expr | None  # C_{p+1}/σ(1); None when σ(1) = 0
    alpha: tuple
    beta: tuple

    def __float__(self):
        return float(self.C)

    @property
    def k(self) -> int:
        return len(self.alpha) - 1

    @property
    def line(self) -> str:
        """The statement without the method's name: "order p, error constant C… = … (…)"."""
        q = str(self.order + 1).translate(_SUB)
        norm = ("; σ(1) = 0: no C/σ(1)" if self.normalised is None
                else f"; C{q}/σ(1) = {format_entry(self.normalised)}, σ(1) = {format_entry(self.sigma1)}")
        return (f"order {self.order}, error constant C{q} = {format_entry(self.C)} "
                f"(α{str(self.k).translate(_SUB)} = 1{norm})")

    def display(self) -> Document:
        q = self.order + 1
        norm = () if self.normalised is None else (
            ", ", Math(f"C_{{{q}}}/\\sigma(1) = {sp.latex(self.normalised)}"), " with ",
            Math(f"\\sigma(1) = {sp.latex(self.sigma1)}"))
        return Document(f"{self.method}: {self.line}", (Typeset(Paragraph(
            "Linear multistep method of order ", Math(str(self.order)), ": error constant ",
            Math(f"C_{{{q}}} = {sp.latex(self.C)}"), " (normalised ", Math(f"\\alpha_{{{self.k}}} = 1"), ")",
            *norm, ".")),))

    def to_json(self):
        def s(x):
            return None if x is None else str(format_entry(x))
        return {"order": self.order, "error_constant": s(self.C), "error_constant_normalisation": "alpha_k = 1",
                "error_constant_over_sigma1": s(self.normalised), "sigma1": s(self.sigma1),
                "alpha": [s(a) for a in self.alpha], "beta": [s(b) for b in self.beta]}


def error_constant(m: Method) -> ErrorConstantResult:
    """The order p and error constant C_{p+1} of the linear multistep method ``m`` (module
    docstring: C_{p+1} with αₖ = 1, and C_{p+1}/σ(1)); a method that is not an LMM, or not
    consistent (C₀ or C₁ ≠ 0), is refused with the reason.  [HNW93] III.2, eq. (2.3); Lambert
    1991, §3.5 (the tables of C_{p+1} with αₖ = 1).

    >>> from tableau_lab.exact.library import family
    >>> [str(error_constant(family("adams_moulton", k=k)).C) for k in (1, 2, 3)]
    ['-1/12', '-1/24', '-19/720']
    """
    coeffs = as_lmm(m)
    if coeffs is None:
        kind = getattr(m, "kind", type(m).__name__)
        hint = ("for a Runge–Kutta method the principal error coefficients are order(m).error_coefficients"
                if kind in ("rk", "prk") else
                "a GLM counts as one when it has one stage and that stage is the solution value (its first "
                "output or first input, as multistep.lmm(α, β) writes it)")
        raise MethodError(f"{getattr(m, 'name', m)}: the error constant C_(p+1) is defined for linear multistep "
                          f"methods (bdf:k, adams_bashforth:k, adams_moulton:k, nystrom:k, milne_simpson:k, "
                          f"multistep.lmm(α, β)), not this {kind} method; {hint}")
    alpha, beta = coeffs
    k = len(alpha) - 1
    C = lmm_constants(alpha, beta, 2 * k + 2)         # order ≤ 2k (Dahlquist): C_{p+1} is among these
    if C[0] != 0 or C[1] != 0:
        which = "Σ αⱼ = 0" if C[0] != 0 else "Σ j αⱼ = Σ βⱼ"
        raise MethodError(f"{m.name}: not consistent ({which} fails): no order, no error constant")
    q = next((q for q in range(2, len(C)) if C[q] != 0), None)
    if q is None:                                     # cannot happen for αₖ = 1 (order ≤ 2k)
        raise MethodError(f"{m.name}: C₀ … C_{len(C) - 1} all vanish: not a k-step method with αₖ ≠ 0")
    sigma1 = sum(beta, sp.Integer(0))
    normalised = None if sigma1 == 0 else sp.cancel(C[q] / sigma1)     # exact (rational functions for parameters)
    return ErrorConstantResult(m.name, q - 1, C[q], sigma1, normalised, tuple(alpha), tuple(beta))
