r"""Zero-stability of GLMs, and so of linear multistep methods, exactly ([HNW93] Hairer, Nørsett &
Wanner, *Solving ODEs I*, §III.3–III.4; [B16] Butcher (2016) §§40–41 and ch. 5).

A GLM is zero-stable (stable) when V is power-bounded: every eigenvalue of V lies in the closed
unit disc and those of modulus 1 are semisimple (as many eigenvectors as their multiplicity).
For a linear multistep method V is, up to eigenvalues 0, the companion matrix of ρ, and this is
the root condition ([HNW93] Def. III.3.2); an RK method has V = [1].

Decided exactly: det(wI − V) is factored over its field K (ℚ when rational, which is the rule);
the roots of each irreducible factor f are counted inside, on and outside the circle by the
Cayley map and a Cauchy index (:func:`roots.disc_counts`; only self-reciprocal factors can have
roots on the circle).  The roots of f on the circle are semisimple iff
dim ker f(V) = (multiplicity of f)·deg f (ker f(V) is the sum of the eigenspaces of the roots
of f), an exact rank over K.  Roots outside are given as certified discs
(:func:`roots.outside_roots`), roots on the circle by radicals when sympy finds them.

>>> from tableau_lab.exact.library import family
>>> zero_stability(family("bdf", k=6)).holds
True
>>> z7 = zero_stability(family("bdf", k=7))
>>> z7.holds
False
>>> for d in z7.outside:
...     print(d)
w ≈ 0.0768046058613277144 - 1.01932879466066134i (|w| = 1.02221824)
w ≈ 0.0768046058613277144 + 1.01932879466066134i (|w| = 1.02221824)
"""
from __future__ import annotations

from dataclasses import dataclass

import mpmath
import sympy as sp
from sympy import QQ
from sympy.polys.matrices import DomainMatrix
from sympy.polys.rings import ring

from ..exact.field import field_of, to_dm
from ..exact.methods import Method
from ..exact.real_roots import coefficients, complex_text, disc_counts, exact_circle_roots, outside_roots
from ..render.model import Block, Document, Formula, Math, Paragraph, Plain, Typeset
from .results import Result

__all__ = ["zero_stability", "ZeroStabilityResult", "EigenFactor"]

W = sp.Symbol("w")


@dataclass(frozen=True)
class EigenFactor:
    """The roots of one irreducible factor f of det(wI − V)."""

    factor: sp.Expr                  # f(w), monic, irreducible over the field of det(wI − V)
    multiplicity: int                # of f in det(wI − V): each root's algebraic multiplicity
    inside: int                      # roots of f with |w| < 1, = 1, > 1 (each counted once)
    on: int
    outside: int
    kernel: int | None = None        # dim ker f(V) (only when f has roots on the circle and multiplicity > 1)
    circle_roots: tuple = ()         # its roots on the circle by radicals (empty: none found)
    outside_roots: tuple = ()        # its roots outside, certified (roots.RootDisc)

    @property
    def degree(self) -> int:
        return self.inside + self.on + self.outside

    @property
    def semisimple(self) -> bool:
        return self.multiplicity == 1 or self.kernel == self.multiplicity * self.degree

    def describe(self) -> str:
        parts = [f"{n} {where}" for n, where in ((self.inside, "inside"), (self.on, "on |w| = 1"),
                                                 (self.outside, "outside")) if n]
        name = str(self.factor) if len(str(self.factor)) <= 60 else f"(a factor of degree {self.degree})"
        text = f"  {name}" + (f" (multiplicity {self.multiplicity})" if self.multiplicity > 1 else "") \
            + ": " + ", ".join(parts)
        if self.on:
            roots = ", ".join(f"w = {_show(z)}" for z in self.circle_roots) or f"the roots of {self.factor}"
            text += f": {roots}" + (
                "" if self.multiplicity == 1 else
                " — semisimple" if self.semisimple else
                f" — NOT semisimple (dim ker f(V) = {self.kernel} < {self.multiplicity * self.degree})")
        if self.outside_roots:
            text += "; outside: " + ", ".join(str(d) for d in self.outside_roots)
        return text


def _show(z) -> str:
    return str(sp.nsimplify(z) if z.is_Rational else z)


@dataclass(frozen=True)
class ZeroStabilityResult(Result):
    """Zero-stability (power-boundedness of V) of one method."""

    method: str
    kind: str
    polynomial: sp.Expr              # det(wI − V)
    r: int
    holds: bool
    reason: str
    factors: tuple = ()

    @property
    def outside(self) -> tuple:
        """The certified roots of det(wI − V) outside the unit circle (largest first)."""
        return tuple(sorted((d for f in self.factors for d in f.outside_roots), key=lambda d: -d.modulus[0]))

    def _lines(self) -> list[str]:
        """The plain face, a line each."""
        lines = [f"zero-stable: {'yes' if self.holds else 'no'} — {self.reason}"]
        if self.factors:
            lines.append(f"  det(wI − V) = {sp.factor(self.polynomial)}; its irreducible factors:")
            lines += [f.describe() for f in self.factors]
        return lines

    def to_json(self):
        return {"zero_stable": self.holds, "reason": self.reason, "characteristic_polynomial_V": str(self.polynomial),
                "factors": [{"factor": str(f.factor), "multiplicity": f.multiplicity, "inside": f.inside,
                             "on_unit_circle": f.on, "outside": f.outside,
                             "semisimple": f.semisimple if f.on else None,
                             "unit_circle_roots": [str(z) for z in f.circle_roots],
                             "outside_roots": [{"w": str(d.value), "modulus": float(d.modulus[0]),
                                                "modulus_enclosure": [mpmath.nstr(d.modulus[0], 30),
                                                                      mpmath.nstr(d.modulus[1], 30)],
                                                "radius": d.radius} for d in f.outside_roots]}
                            for f in self.factors]}

    def display(self) -> Document:
        """The plain face: the lines above; the typeset face: det(wI − V) factored and the verdict."""
        typeset: list[Block] = []
        if self.factors:
            typeset.append(Formula(f"\\det(wI - V) = {sp.latex(sp.factor(self.polynomial))}"))
        typeset.append(self._verdict())
        head, *lines = self._lines()
        return Document(head, (Plain(*map(Paragraph, lines)), Typeset(*typeset)))

    def _verdict(self) -> Paragraph:
        """The verdict in a sentence: the eigenvalues on the circle, or the largest outside it, or
        the defective ones."""
        circle = [z for f in self.factors for z in f.circle_roots]
        on = ", ".join(f"w = {sp.latex(z)}" for z in circle)
        if self.holds:
            return Paragraph("The method is zero-stable: every eigenvalue of ", Math("V"), " lies in ",
                             Math(r"|w| \le 1"), *((", and those on ", Math("|w| = 1"), " (", Math(on),
                                                     ") are semisimple.") if on else (".",)))
        big = self.outside
        if big:
            d = big[0]
            return Paragraph("The method is not zero-stable: ", Math("V"),
                             f" has {len(big)} eigenvalue{'s' if len(big) > 1 else ''} outside the unit circle, "
                             "the largest ", Math(f"w \\approx {complex_text(d.center)}"), " with ",
                             Math(f"|w| = {mpmath.nstr(d.modulus[0], 9)}"), ".")
        bad = [f for f in self.factors if f.on and not f.semisimple]
        roots = ", ".join(sp.latex(z) for f in bad for z in f.circle_roots) or sp.latex(bad[0].factor)
        return Paragraph("The method is not zero-stable: the eigenvalue(s) ", Math(roots), " of ", Math("V"), " on ",
                         Math("|w| = 1"), " are not semisimple.")


def _char_poly(V):
    """det(wI − V) as a ring element over ℚ when its coefficients are rational, else over the field
    of V; with V as a DomainMatrix over the field of V."""
    KV = field_of([V])
    Vdm = to_dm(sp.Matrix(V), KV)
    cs = Vdm.charpoly()
    if not KV.is_QQ and all(len(c.to_list()) <= 1 for c in cs):
        K, cs = QQ, [QQ.convert(c.to_list()[0]) if c.to_list() else QQ.zero for c in cs]
    else:
        K = KV
    R = ring("w", K)[0]
    n = len(cs) - 1
    return R.from_dict({(n - i,): c for i, c in enumerate(cs) if c}), K, Vdm, KV


def _kernel_dim(f, Vdm, KV) -> int:
    """dim ker f(V), exactly over the field of V (Horner's rule on matrices)."""
    n = Vdm.shape[0]
    eye = DomainMatrix.eye(n, KV)
    F = DomainMatrix.zeros((n, n), KV)
    for c in coefficients(f):
        F = F * Vdm + eye * KV.convert(c)
    return n - F.rank()


def _factor(f, m, K, Vdm, KV) -> EigenFactor:
    inside, on, outside = disc_counts(f, K)
    kernel = _kernel_dim(f, Vdm, KV) if on and m > 1 else None
    circle = ()
    if on:
        found = exact_circle_roots(sp.Poly(f.as_expr(), f.ring.symbols[0]))
        circle = tuple(found) if found is not None and len(found) == on else ()
    return EigenFactor(factor=f.as_expr(), multiplicity=m, inside=inside, on=on, outside=outside, kernel=kernel,
                       circle_roots=circle, outside_roots=outside_roots(f, K, outside))


def zero_stability(m: Method) -> ZeroStabilityResult:
    """Whether V is power-bounded (module docstring); for a partitioned RK method trivially yes."""
    if m.kind == "prk":
        return ZeroStabilityResult(method=m.name, kind=m.kind, polynomial=(W - 1) ** 2, r=2, holds=True,
                                   reason="a one-step method (V = I)")
    V = sp.Matrix(m.as_glm().V)
    if V.free_symbols:
        raise ValueError(f"{m.name}: V has free parameters; zero-stability needs a numeric V")
    chi, K, Vdm, KV = _char_poly(V)
    _, factors = chi.factor_list()
    items = sorted((_factor(f.monic(), k, K, Vdm, KV) for f, k in factors),
                   key=lambda f: (-f.outside, -f.on, sp.default_sort_key(f.factor)))
    out = [d for f in items for d in f.outside_roots]
    defective = [f for f in items if f.on and not f.outside and not f.semisimple]
    circle = [f for f in items if f.on]
    if out:
        big = max(out, key=lambda d: d.modulus[0])
        n = sum(f.outside for f in items)
        reason = (f"{n} eigenvalue{'s' if n > 1 else ''} of V outside the unit circle"
                  + (f", the largest {big}" if n > 1 else f": {big}"))
    elif defective:
        f = defective[0]
        assert f.kernel is not None, "computed for every factor on the circle with multiplicity > 1"
        roots = ", ".join(_show(z) for z in f.circle_roots) or f"the roots of {f.factor}"
        reason = (f"the eigenvalue{'s' if f.on > 1 else ''} {roots} on |w| = 1 of algebraic multiplicity "
                  f"{f.multiplicity} {'have' if f.on > 1 else 'has'} only {f.kernel // f.degree} "
                  f"eigenvector{'s' if f.kernel // f.degree > 1 else ''} (not semisimple)")
    else:
        on = [_show(z) for f in circle for z in f.circle_roots]
        n_on = sum(f.on for f in circle)
        simple = all(f.multiplicity == 1 for f in circle)
        reason = ("every eigenvalue of V in |w| < 1" if not n_on else
                  "every eigenvalue of V in |w| ≤ 1; on |w| = 1: "
                  + (", ".join(f"w = {z}" for z in on) if len(on) == n_on else f"{n_on} eigenvalues")
                  + (", simple" if simple else ", semisimple"))
        if V.shape == (1, 1):
            reason = "V = [1]: a one-step method" if V[0, 0] == 1 else reason
    return ZeroStabilityResult(method=m.name, kind=m.kind, polynomial=chi.as_expr(), r=V.rows, holds=not out and
                               not defective, reason=reason, factors=tuple(items))
