"""Exact method objects: Runge-Kutta, partitioned Runge-Kutta, general linear.

Each method is a frozen dataclass of exact sympy matrices, validated once on
construction.  Properties of a method are functions in ``tableau_lab.analysis``.

A general linear method (GLM) with s stages and r values ([B16] ch. 5)::

    Y     = h (A ⊗ I) F + (U ⊗ I) y^[n-1],     F_i = f(Y_i)
    y^[n] = h (B ⊗ I) F + (V ⊗ I) y^[n-1]

and every Runge-Kutta method is the GLM with r = 1, U = 1, B = bᵀ, V = [1]:

>>> euler = RungeKutta.from_lists([[0]], [1], name="explicit Euler")
>>> g = euler.as_glm()
>>> (g.s, g.r, g.U.tolist(), g.B.tolist(), g.V.tolist())
(1, 1, [[1]], [[1]], [[1]])

A partitioned RK method integrates y' = f(y, z) with (A, b, c) and
z' = g(y, z) with (Ahat, bhat, chat); for a Hamiltonian H(p, q) the first
partition is q (q' = ∂H/∂p), the second p (p' = -∂H/∂q) ([HLW06] II.2, VI.4).
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, Self

import sympy as sp

from ..errors import InputError
from .conjugate import Conjugate, detect
from .field import FieldError, field_of, from_dm, solve_linear, to_dm
from .queries import Queries
from .render import markdown_literal

__all__ = ["MethodError", "Method", "RungeKutta", "PartitionedRungeKutta", "GeneralLinearMethod", "preconsistency",
           "glm_parts"]


#: an entry typesetter: sympy.latex, or the report's named-constant one
Tex = Callable[[Any], str]


class MethodError(InputError):
    """A tableau whose matrices do not form a method (shapes, nodes, entries)."""


def _exact(e: object, what: str) -> sp.Expr:
    """One matrix entry, exactly and without evaluating text: a string is read by the tableau
    grammar (never ``sympify``, which evaluates Python), an int or a ``Fraction`` becomes a
    rational, a sympy number is kept; floats and every other type are refused."""
    from fractions import Fraction
    from numbers import Integral

    from .grammar import EntryError, parse_entry
    if isinstance(e, sp.Basic):
        return e
    if isinstance(e, Integral) and not isinstance(e, bool):
        e = int(e)                                   # numpy's integers too
    if isinstance(e, Fraction):
        return sp.Rational(e.numerator, e.denominator)
    try:
        return parse_entry(e)
    except EntryError as exc:
        raise MethodError(f"{what}: {exc}") from None


def _exact_rows(x: Any, what: str) -> Any:
    """A matrix, a list of rows or a flat list (a column) with every entry through :func:`_exact`.

    >>> _exact_rows([["1/2", 0]], "A")
    [[1/2, 0]]
    >>> _exact_rows(["__import__('os')"], "b")  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
    ...
    tableau_lab.exact.methods.MethodError: b, entry 1: names must start with a letter, not '_' (at position 1 of
    "__import__('os')")
    """
    if isinstance(x, sp.MatrixBase):
        return x
    if isinstance(x, (str, bytes)) or not hasattr(x, "__iter__"):
        return x                                     # refused by the matrix check with its shape
    rows = list(x)
    if rows and all(not isinstance(r, (str, bytes)) and hasattr(r, "__iter__") for r in rows):
        return [[_exact(e, f"{what}, row {i}, column {j}") for j, e in enumerate(r, 1)] for i, r in enumerate(rows, 1)]
    return [_exact(e, f"{what}, entry {i}") for i, e in enumerate(rows, 1)]


def _matrix(x: Any, what: str) -> sp.ImmutableMatrix:
    try:
        M = sp.ImmutableMatrix(_exact_rows(x, what))
    except (TypeError, ValueError) as exc:
        raise MethodError(f"{what} is not a matrix: {exc}") from None
    for e in M:
        if not isinstance(e, sp.Expr) or e.has(sp.Float):
            raise MethodError(f"{what} has a non-exact entry {e!r}: entries must be exact (rationals, radicals, "
                              "parameters)")
        if e.has(sp.zoo, sp.nan, sp.oo, -sp.oo, sp.I):
            raise MethodError(f"{what} has an entry that is not a finite real number: {e}")
    return M


def _lists(args: dict[str, Any], call: str) -> dict[str, Any]:
    """The matrices of a ``from_lists`` call as ImmutableMatrix; a misplaced argument (a string,
    a number, a mapping where a matrix goes) is named with its position and what goes there.

    >>> RungeKutta.from_lists("x", [[0]], [1])  # doctest: +NORMALIZE_WHITESPACE
    Traceback (most recent call last):
    ...
    tableau_lab.exact.methods.MethodError: RungeKutta.from_lists: argument 1 (A) is the string 'x', not a matrix: A
    is a list of rows (e.g. [[0, 0], ["1/2", 0]]); a name goes in name=...
    """
    out: dict[str, Any] = {}            # name → ImmutableMatrix or None
    for i, (k, x) in enumerate(args.items(), 1):
        if x is None:
            out[k] = None
            continue
        if (isinstance(x, (str, bytes, int, float, complex, dict))
                or isinstance(x, sp.Basic) and not isinstance(x, sp.MatrixBase)):
            what = f"the string {x[:40]!r}" if isinstance(x, str) else f"the {type(x).__name__} {str(x)[:40]}"
            shape = 'rows (e.g. [[0, 0], ["1/2", 0]])' if k.startswith("A") else "values"
            raise MethodError(f"{call}: argument {i} ({k}) is {what}, not a matrix: {k} is a list of {shape}; "
                              "a name goes in name=...")
        try:
            out[k] = sp.ImmutableMatrix(_exact_rows(x, k))
        except MethodError as exc:
            raise MethodError(f"{call}: argument {i}: {exc}") from None
        except (TypeError, ValueError) as exc:
            raise MethodError(f"{call}: argument {i} ({k}) is not a matrix: {str(exc).strip()[:200]}") from None
    return out


def _column(x: Any, what: str) -> sp.ImmutableMatrix:
    M = _matrix(x, what)
    if M.cols != 1:
        if M.rows == 1:
            return M.T
        raise MethodError(f"{what} must be a vector, got shape {M.shape}")
    return M


def _shape(M: sp.MatrixBase, shape: tuple[int, int], what: str, hint: str = "") -> None:
    if M.shape != shape:
        raise MethodError(f"{what} has shape {M.shape[0]}x{M.shape[1]}, expected {shape[0]}x{shape[1]}{hint}")


def _frozen_claims(claims: Mapping[str, Any] | None) -> tuple[tuple[str, Any], ...]:
    return tuple(sorted((claims or {}).items()))


@dataclass(frozen=True)
class Method(Queries):
    """Fields shared by all kinds: name and provenance (not part of the mathematics); the
    analyses as methods (``m.order()``, ``m.stability()``, …: :mod:`queries`)."""

    name: str = field(default="", kw_only=True)
    source: str = field(default="", kw_only=True)
    notes: tuple[str, ...] = field(default=(), kw_only=True)
    claims: tuple[tuple[str, Any], ...] = field(default=(), kw_only=True)
    # where extracted data came from: (("commit", …), ("file", …), ("line", …), ("repository", …))
    provenance: tuple[tuple[str, Any], ...] = field(default=(), kw_only=True, compare=False)

    kind = "method"

    @property
    def claims_dict(self) -> dict[str, Any]:
        return dict(self.claims)

    @property
    def parameters(self) -> tuple[sp.Symbol, ...]:
        """The named free parameters of the tableau, sorted by name."""
        syms: set[sp.Symbol] = set()
        for M in self.matrices().values():
            if M is not None:
                syms |= M.free_symbols
        return tuple(sorted(syms, key=lambda s: s.name))

    def matrices(self) -> dict[str, sp.ImmutableMatrix | None]:  # pragma: no cover - overridden
        raise NotImplementedError

    @property
    def s(self) -> int:  # pragma: no cover - overridden
        """The number of stages."""
        raise NotImplementedError

    def as_glm(self) -> "GeneralLinearMethod":
        """The method as a general linear method (A, U, B, V); a kind without that form (partitioned
        RK) raises TypeError, as the analyses that need it do for a kind they do not apply to."""
        raise TypeError(f"a {_KIND_NAMES.get(self.kind, self.kind)} has no general linear form (A, U, B, V)")

    def field(self) -> Any:
        """The exact field of the tableau's entries."""
        return field_of(self.matrices().values())

    def _check_field(self) -> None:
        try:
            self.field()
        except FieldError as exc:
            raise MethodError(str(exc)) from None

    # ------------------------------------------------------------ display (notebooks, reports)

    def tableau_latex(self, tex: Tex = sp.latex) -> str:  # pragma: no cover - overridden
        """The tableau as LaTeX math (no delimiters), each entry typeset by ``tex``: the PDF
        report passes its named-constant typesetter, notebooks the default ``sympy.latex``."""
        raise NotImplementedError

    def _display_math(self) -> str:
        return self.tableau_latex()

    def _repr_latex_(self) -> str:
        """Jupyter/MathJax: the tableau as display math, exact entries."""
        return f"$${self._display_math()}$$"

    def _repr_markdown_(self) -> str:
        """Jupyter: the name as a heading, the kind and size, then the tableau as display math."""
        size = f"s = {self.s} stage{'s' * (self.s != 1)}"
        if isinstance(self, GeneralLinearMethod):
            size += f", r = {self.r} value{'s' * (self.r != 1)}"
        return (f"### {markdown_literal(self.name or 'unnamed method')}\n\n{_KIND_NAMES[self.kind]}, {size}\n\n"
                f"$${self._display_math()}$$")


_KIND_NAMES = {"rk": "Runge–Kutta method", "prk": "partitioned Runge–Kutta method", "glm": "general linear method"}


def _butcher_array(A: sp.MatrixBase, b: sp.MatrixBase, c: sp.MatrixBase, tex: Tex) -> str:
    """One Butcher tableau, c | A over a rule and bᵀ, as a LaTeX array ([B16] ch. 3)."""
    s = A.rows
    rows = [f"{tex(c[i])} & " + " & ".join(tex(A[i, j]) for j in range(s)) for i in range(s)]
    return (rf"\begin{{array}}{{c|{'c' * s}}} " + r" \\ ".join(rows) + r" \\ \hline & "
            + " & ".join(tex(x) for x in b) + r" \end{array}")


def _meta(kw: Mapping[str, Any]) -> dict[str, Any]:
    out = dict(kw)
    if "claims" in out and isinstance(out["claims"], Mapping):
        out["claims"] = _frozen_claims(out["claims"])
    if "notes" in out and isinstance(out["notes"], str):
        out["notes"] = (out["notes"],)
    elif "notes" in out:
        out["notes"] = tuple(out["notes"])
    return out


def _tableau(A: Any, b: Any, c: Any, hat: str = "") -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix,
                                                                  sp.ImmutableMatrix]:
    """Validate one Butcher tableau; c = A·1 exactly (derived when c is None).
    ``hat`` suffixes the names in messages (the second tableau of a PRK method)."""
    nA, nb, nc = f"A{hat}", f"b{hat}", f"c{hat}"
    A = _matrix(A, nA)
    if A.rows != A.cols or A.rows == 0:
        raise MethodError(f"{nA} must be square and non-empty, got shape {A.rows}x{A.cols}")
    b = _column(b, nb)
    _shape(b, (A.rows, 1), nb, f" (s = {A.rows} stages)")
    rowsum = sp.ImmutableMatrix([sum(A.row(i)) for i in range(A.rows)])
    if c is None:
        return A, b, rowsum
    c = _column(c, nc)
    _shape(c, (A.rows, 1), nc, f" (s = {A.rows} stages)")
    K = field_of([A, c])
    diff = to_dm(c - rowsum, K).to_list()
    bad = [str(i + 1) for i in range(A.rows) if not K.is_zero(diff[i][0])]
    if bad:
        raise MethodError(f"{nc} is not consistent with {nA}: {nc}_i must equal the row sum of {nA} "
                          f"(fails at stage {', '.join(bad)})")
    return A, b, c


@dataclass(frozen=True)
class RungeKutta(Method):
    """An s-stage Runge-Kutta method (A, b, c) with c = A·1 ([B16] Butcher, *Numerical Methods for
    ODEs*, 3rd ed., ch. 3), exact: ``tl.RungeKutta``; ``from_lists`` takes ints, sympy numbers or
    entries in the tableau grammar (floats are refused).  Its analyses are its methods
    (``m.order()``, ``m.stability()``, …).

    >>> import tableau_lab as tl
    >>> heun = tl.RungeKutta.from_lists([[0, 0], [1, 0]], ["1/2", "1/2"], name="Heun")
    >>> heun.c.T, int(heun.order())
    (Matrix([[0, 1]]), 2)
    """

    A: sp.ImmutableMatrix
    b: sp.ImmutableMatrix
    c: sp.ImmutableMatrix = None
    bhat: sp.ImmutableMatrix = field(default=None, kw_only=True)   # embedded weights b̂ (an embedded pair)
    # the method as rational data on the roots of one polynomial (exact.conjugate), when its
    # entries are values of fixed polynomials at the nodes (Gauss, Radau, Lobatto families):
    # the analyses then run in ℚ instead of the field of all the nodes
    conjugate: Conjugate | None = field(default=None, compare=False, repr=False, kw_only=True)

    kind = "rk"

    def __post_init__(self) -> None:
        if self.bhat is not None:
            bh = _column(self.bhat, "bhat")
            _shape(bh, (_matrix(self.A, "A").rows, 1), "bhat", " (the embedded weights: one per stage)")
            object.__setattr__(self, "bhat", bh)
        if self.conjugate is None and self.c is not None and sum(isinstance(x, sp.RootOf) for x in self.c) > 1:
            # a tableau written from exact.conjugate (root(P, k) nodes)
            found = detect(_matrix(self.A, "A"), _column(self.b, "b"), _column(self.c, "c"))
            if found is not None and found.c_polynomial == found.P.gen:       # c = the nodes = A·1
                object.__setattr__(self, "conjugate", found)
        if self.conjugate is not None:
            self._check_conjugate(self.conjugate)
            return
        try:
            parts = _tableau(self.A, self.b, self.c)
        except FieldError as exc:
            raise MethodError(str(exc)) from None
        for k, v in zip("Abc", parts, strict=False):
            object.__setattr__(self, k, v)
        self._check_field()

    def _check_conjugate(self, conjugate: Conjugate) -> None:
        """Shapes, and c = A·1 in ℚ: Ã e₀ = X (the nodes' polynomial) ⟺ A·1 = c."""
        A, b, c = _matrix(self.A, "A"), _column(self.b, "b"), _column(self.c, "c")
        s = conjugate.s
        _shape(A, (s, s), "A", f" (s = {s} nodes)")
        _shape(b, (s, 1), "b")
        _shape(c, (s, 1), "c")
        if list(c) != conjugate.abscissae():
            raise MethodError("c is not consistent with A: c ≠ A·1 (Ã e₀ at the nodes)")
        for k, v in zip("Abc", (A, b, c), strict=False):
            object.__setattr__(self, k, v)

    @classmethod
    def from_lists(cls, A: Any, b: Any, c: Any = None, **meta: Any) -> Self:
        return cls(**_lists({"A": A, "b": b, "c": c}, "RungeKutta.from_lists"), **_meta(meta))

    @property
    def s(self) -> int:
        return int(self.A.rows)

    @property
    def explicit(self) -> bool:
        """A strictly lower triangular (the seed's §1.2.3 says "upper": ERRATA 1)."""
        return all(self.A[i, j] == 0 for i in range(self.s) for j in range(i, self.s))

    @property
    def order_bound(self) -> int:
        """No s-stage RK method has order, classical or effective, above 2s, nor above s when
        explicit: R(z) = e^z + O(z^{p+1}) is necessary (on y' = λy a starting method is a
        scalar factor that commutes with the step) and R has degree s."""
        return self.s if self.explicit else 2 * self.s

    def tableau_latex(self, tex: Tex = sp.latex) -> str:
        """The Butcher tableau c | A over bᵀ."""
        return _butcher_array(self.A, self.b, self.c, tex)

    def matrices(self) -> dict[str, sp.ImmutableMatrix | None]:
        out = {"A": self.A, "b": self.b, "c": self.c}
        if self.bhat is not None:
            out["bhat"] = self.bhat
        return out

    def embedded(self) -> "RungeKutta | None":
        """The embedded method (A, b̂), or None."""
        if self.bhat is None:
            return None
        return RungeKutta(A=self.A, b=self.bhat, c=self.c, name=f"{self.name} (embedded b̂)")

    def as_glm(self) -> "GeneralLinearMethod":
        """The same method as a GLM with r = 1: U = 1, B = bᵀ, V = [1]."""
        return GeneralLinearMethod(A=self.A, U=sp.ones(self.s, 1), B=self.b.T, V=sp.ImmutableMatrix([[1]]),
                                   c=self.c, name=self.name, source=self.source, notes=self.notes,
                                   claims=self.claims)


@dataclass(frozen=True)
class PartitionedRungeKutta(Method):
    """A partitioned RK method: (A, b, c) for the first partition (q), (Ahat, bhat, chat)
    for the second (p).  Both tableaux have the same number of stages ([HLW06] Hairer, Lubich &
    Wanner, *Geometric Numerical Integration*, §II.2, §III.2): ``tl.PartitionedRungeKutta``.

    >>> import tableau_lab as tl
    >>> euler = tl.PartitionedRungeKutta.from_lists([[1]], [1], [[0]], [1], name="symplectic Euler")
    >>> int(euler.order()), euler.verify().rk_symplectic.holds_separable
    (1, True)
    """

    A: sp.ImmutableMatrix
    b: sp.ImmutableMatrix
    Ahat: sp.ImmutableMatrix
    bhat: sp.ImmutableMatrix
    c: sp.ImmutableMatrix = None
    chat: sp.ImmutableMatrix = None

    kind = "prk"

    def __post_init__(self) -> None:
        first = _tableau(self.A, self.b, self.c)
        second = _tableau(self.Ahat, self.bhat, self.chat, hat="hat")
        if first[0].rows != second[0].rows:
            raise MethodError(f"the two tableaux of a partitioned method need the same number of stages "
                              f"(A has {first[0].rows}, Ahat has {second[0].rows})")
        for k, v in zip(("A", "b", "c", "Ahat", "bhat", "chat"), first + second, strict=False):
            object.__setattr__(self, k, v)
        self._check_field()

    @classmethod
    def from_lists(cls, A: Any, b: Any, Ahat: Any, bhat: Any, c: Any = None, chat: Any = None, **meta: Any) -> Self:
        return cls(**_lists({"A": A, "b": b, "Ahat": Ahat, "bhat": bhat, "c": c, "chat": chat},
                            "PartitionedRungeKutta.from_lists"), **_meta(meta))

    @property
    def s(self) -> int:
        return int(self.A.rows)

    def tableau_latex(self, tex: Tex = sp.latex) -> str:
        """Both Butcher tableaux, (A, b, c) then (Â, b̂, ĉ), side by side."""
        return (_butcher_array(self.A, self.b, self.c, tex) + r" \qquad "
                + _butcher_array(self.Ahat, self.bhat, self.chat, tex))

    def matrices(self) -> dict[str, sp.ImmutableMatrix | None]:
        return {"A": self.A, "b": self.b, "c": self.c, "Ahat": self.Ahat, "bhat": self.bhat, "chat": self.chat}

    def tableaux(self) -> tuple[RungeKutta, RungeKutta]:
        return (RungeKutta(A=self.A, b=self.b, c=self.c, name=f"{self.name} (first partition)"),
                RungeKutta(A=self.Ahat, b=self.bhat, c=self.chat, name=f"{self.name} (second partition)"))


def preconsistency(U: sp.MatrixBase, V: sp.MatrixBase) -> sp.ImmutableMatrix | None:
    """The preconsistency vector u with V u = u and U u = 1 ([B16] Sec. 51), or None.

    >>> preconsistency(sp.Matrix([[1, -2], [1, 2]]), sp.Matrix([[1, 0], [0, -1]])).T
    Matrix([[1, 0]])
    """
    r, s = V.rows, U.rows
    K = field_of([U, V])
    M = to_dm(sp.Matrix.vstack(V - sp.eye(r), U), K)
    x = solve_linear(M, [0] * r + [1] * s)
    return None if x is None else sp.ImmutableMatrix([K.to_sympy(v) for v in x])


@dataclass(frozen=True)
class GeneralLinearMethod(Method):
    """A GLM [A U; B V] with s stages and r values, and stage abscissae c ([B16] Butcher,
    *Numerical Methods for ODEs*, 3rd ed., ch. 5): ``tl.GeneralLinearMethod``.

    >>> import tableau_lab as tl
    >>> leapfrog = tl.GeneralLinearMethod(A=[[0]], U=[[1, 0]], B=[[2], [0]], V=[[0, 1], [1, 0]], name="leapfrog")
    >>> leapfrog.r, int(leapfrog.order())
    (2, 2)

    ``c`` may be omitted: it is derived from the order-1 conditions as
    c = A·1 + U v, where (I − V) v = B·1 − u and v has no component along u
    (the first starting-method coefficient with θ(τ) = 0).  A given c must be
    consistent with some such v.
    """

    A: sp.ImmutableMatrix
    U: sp.ImmutableMatrix
    B: sp.ImmutableMatrix
    V: sp.ImmutableMatrix
    c: sp.ImmutableMatrix = None

    kind = "glm"

    def __post_init__(self) -> None:
        A = _matrix(self.A, "A")
        if A.rows != A.cols or A.rows == 0:
            raise MethodError(f"A must be square and non-empty, got shape {A.rows}x{A.cols}")
        s = A.rows
        V = _matrix(self.V, "V")
        if V.rows != V.cols or V.rows == 0:
            raise MethodError(f"V must be square and non-empty, got shape {V.rows}x{V.cols}")
        r = V.rows
        U = _matrix(self.U, "U")
        _shape(U, (s, r), "U", f" (s = {s} stages from A, r = {r} values from V)")
        B = _matrix(self.B, "B")
        _shape(B, (r, s), "B", f" (r = {r} values from V, s = {s} stages from A)")
        for k, v in (("A", A), ("U", U), ("B", B), ("V", V)):
            object.__setattr__(self, k, v)
        self._check_field()
        c = None if self.c is None else _column(self.c, "c")
        if c is not None:
            _shape(c, (s, 1), "c", f" (s = {s} stages)")
        object.__setattr__(self, "c", self._abscissae(c))

    def _abscissae(self, c: Any) -> sp.ImmutableMatrix:
        s, r = self.s, self.r
        u = preconsistency(self.U, self.V)
        if u is None:
            if c is None:
                raise MethodError("c is not given and cannot be derived: the method is not preconsistent "
                                  "(no u with V u = u and U u = 1)")
            return c
        # with unknowns (design) consistency is a condition on them, not a property of the entries
        symbolic = any(X.free_symbols for X in (self.A, self.U, self.B, self.V))
        K = field_of([self.A, self.U, self.B, self.V, u] + ([c] if c is not None else []))
        ones = sp.ones(s, 1)
        rhs_v = list(self.B * ones - u)
        if c is not None:
            # c is consistent iff some v has (I - V) v = B 1 - u and U v = c - A 1.  A method
            # that is not consistent at all (no v, e.g. an RK method with Σb ≠ 1) has order 0
            # whatever c is: its c is accepted and the order analysis reports the failure.
            M = to_dm(sp.Matrix.vstack(sp.eye(r) - self.V, self.U), K)
            consistent = solve_linear(to_dm(sp.eye(r) - self.V, K), rhs_v) is not None
            if consistent and solve_linear(M, rhs_v + list(c - self.A * ones)) is None and not symbolic:
                raise MethodError("c is not consistent with the method: no v with (I - V) v = B·1 - u "
                                  "and c = A·1 + U v (stage order 1 fails for every starting method)")
            return c
        w = _left_eigenvector(self.V, u, K)
        rows = sp.eye(r) - self.V
        rhs = rhs_v
        if w is not None:
            rows = sp.Matrix.vstack(rows, w.T)
            rhs = rhs_v + [0]
        v = solve_linear(to_dm(rows, K), rhs)
        if v is None and symbolic:
            v = [K.zero] * r          # c = A·1 stands in until the unknowns are solved for
        if v is None:
            raise MethodError("c is not given and cannot be derived: the method is not consistent "
                              "((I - V) v = B·1 - u has no solution)")
        v = sp.Matrix([K.to_sympy(x) for x in v])
        c = from_dm(to_dm(self.A * ones + self.U * v, K))
        return c

    @property
    def s(self) -> int:
        return int(self.A.rows)

    @property
    def r(self) -> int:
        return int(self.V.rows)

    def tableau_latex(self, tex: Tex = sp.latex) -> str:
        """The partitioned matrix [A U; B V] ([B16] ch. 5), a rule between stages and values."""
        s, r = self.s, self.r
        top = [" & ".join([tex(self.A[i, j]) for j in range(s)] + [tex(self.U[i, j]) for j in range(r)])
               for i in range(s)]
        bot = [" & ".join([tex(self.B[i, j]) for j in range(s)] + [tex(self.V[i, j]) for j in range(r)])
               for i in range(r)]
        return (r"\begin{bmatrix} A & U \\ B & V \end{bmatrix} = "
                rf"\left[\begin{{array}}{{{'c' * s}|{'c' * r}}} " + r" \\ ".join(top) + r" \\ \hline "
                + r" \\ ".join(bot) + r" \end{array}\right]")

    def abscissae_latex(self, tex: Tex = sp.latex) -> str:
        """The stage abscissae, c = (c₁, …, c_s)."""
        return r"c = (" + r",\ ".join(tex(x) for x in self.c) + ")"

    def _display_math(self) -> str:
        return self.tableau_latex() + r",\qquad " + self.abscissae_latex()

    def matrices(self) -> dict[str, sp.ImmutableMatrix | None]:
        return {"A": self.A, "U": self.U, "B": self.B, "V": self.V, "c": self.c}

    def as_glm(self) -> "GeneralLinearMethod":
        return self


def _left_eigenvector(V: sp.MatrixBase, u: sp.MatrixBase, K: Any) -> sp.Matrix | None:
    """w with wᵀV = wᵀ and wᵀu = 1, when unique (1 a simple eigenvalue of V)."""
    r = V.rows
    M = to_dm(sp.Matrix.vstack(V.T - sp.eye(r), u.T), K)
    if M.rank() < r:
        return None
    x = solve_linear(M, [0] * r + [1])
    return None if x is None else sp.Matrix([K.to_sympy(v) for v in x])


def glm_parts(m: Method) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix, sp.Matrix]:
    """(A, U, B, V) of an RK method or a GLM as mutable sympy matrices, without the validation of
    :meth:`as_glm` (a tableau with unknowns need not be consistent yet): an RK method is
    U = 1, B = bᵀ, V = [1]."""
    if isinstance(m, RungeKutta):
        return sp.Matrix(m.A), sp.ones(m.s, 1), sp.Matrix(m.b).T, sp.Matrix([[1]])
    if isinstance(m, GeneralLinearMethod):
        return sp.Matrix(m.A), sp.Matrix(m.U), sp.Matrix(m.B), sp.Matrix(m.V)
    raise ValueError(f"{m.name}: a partitioned RK method has no single GLM form")
