r"""Solution families as objects: the free parameters, the branch conditions and the exact members
of a family that :func:`design.solve` found (issue: design search).

A :class:`Family` holds the method with its free parameters as symbols, the conditions that must
not vanish, and the requirements every member meets (re-verified generically by ``solve``).
:meth:`Family.member` substitutes exact values and returns an ordinary method object, which the
analyses then check like any other.

>>> fams = families_of("methods/design/pn_family.json", ["g-symplectic"])
>>> f = fams[0]
>>> f.free, f.conditions
((u,), (u,))
>>> m = f.member({"u": "1 + 2*sqrt(3)/3"})          # Example 4 (method P) is the member u = 1 + 2/√3
>>> m.A[0, 0]
sqrt(3)/6 + 1/2
>>> try:                                                # doctest: +NORMALIZE_WHITESPACE
...     f.member({"u": 0})
... except FamilyError as exc:
...     print(type(exc).__name__, exc, sep=": ")
FamilyError: 2-stage 2-value G-symplectic family #1: u = 0 makes the branch condition u
vanish
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import sympy as sp

from ..errors import InputError
from ..exact.field import is_zero, normal_form
from ..exact.grammar import parse_entry
from ..exact.methods import GeneralLinearMethod, Method, MethodError

__all__ = ["Family", "FamilyError", "families_of", "family_from_solution", "tableau_family"]


class FamilyError(InputError):
    """A family that cannot be built, or a member outside it."""


@dataclass(frozen=True)
class Family:
    """A solution family: ``method`` has the ``free`` symbols in its entries; ``conditions`` must not
    vanish; ``requirements`` hold for every member (verified by ``solve``)."""

    name: str
    method: Method
    free: tuple
    conditions: tuple
    requirements: tuple

    def _values(self, values) -> dict:
        out = {}
        names = {str(s): s for s in self.free}
        for k, v in values.items():
            key = str(k)
            if key not in names:
                raise FamilyError(f"{self.name}: {key!r} is not a free parameter (free: {', '.join(names)})")
            if isinstance(v, float) or isinstance(v, bool):
                raise FamilyError(f"{self.name}: {key} = {v!r}: exact values only (a fraction, a radical, text such "
                                  "as \"1/3\")")
            val = parse_entry(v) if isinstance(v, str) else sp.sympify(v)
            if val.has(sp.Float) or val.free_symbols:
                raise FamilyError(f"{self.name}: {key} = {v!r} is not an exact number")
            out[names[key]] = val
        missing = [str(s) for s in self.free if s not in out]
        if missing:
            raise FamilyError(f"{self.name}: values missing for {', '.join(missing)}")
        return out

    def member(self, values: dict, name: str | None = None) -> Method:
        """The member with the given exact values (text in the tableau grammar, ints, Rationals,
        sympy numbers) of every free parameter; refused where a branch condition vanishes."""
        vals = self._values(values)
        for c in self.conditions:
            if is_zero(sp.sympify(c).xreplace(vals)):
                shown = ", ".join(f"{k} = {v}" for k, v in vals.items())
                raise FamilyError(f"{self.name}: {shown} makes the branch condition {c} vanish")
        m = self.method
        fields = {k: v for k, v in m.matrices().items() if isinstance(v, sp.MatrixBase)}
        try:
            return replace(m, name=name or f"{self.name} at " + ", ".join(f"{k} = {v}" for k, v in vals.items()),
                           claims=(),
                           **{k: M.applyfunc(lambda e: normal_form(e.xreplace(vals))) for k, M in fields.items()})
        except (MethodError, ValueError) as exc:
            raise FamilyError(f"{self.name}: the member is not a method: {exc}") from None


def family_from_solution(sol, requirements, name: str) -> Family:
    """A :class:`Family` from a :class:`design.Solution` with free parameters."""
    if sol.method is None:
        raise FamilyError(f"{name}: the solution has no method (not re-verified)")
    return Family(name, sol.method, tuple(sol.free), tuple(sol.conditions), tuple(requirements))


def tableau_family(path) -> Family:
    """The tableau file at ``path`` itself as a family: its unknowns are the free parameters, the
    denominators of its entries the branch conditions (no requirement is solved; the search's
    constraints then pick the members, e.g. ``methods/design/glm4_symmetric_family.json``)."""
    from ..exact.tableau_json import read
    from .design import method_from_design
    m, extra = method_from_design(read(path), str(path))
    if extra:
        raise FamilyError(f"{path}: unknown abscissae need a requirement (the row sums of A become equations)")
    if not m.parameters:
        raise FamilyError(f"{path}: no unknowns, so no family to search")
    factors = {f for M in m.matrices().values() if isinstance(M, sp.MatrixBase) for e in M
               for f, _ in sp.factor_list(sp.denom(sp.together(e)))[1] if f.free_symbols}
    return Family(m.name, m, tuple(m.parameters), tuple(sorted(factors, key=str)), ())


def families_of(path, requirements) -> list:
    """Every real, verified solution family of ``requirements`` for the unknowns of the tableau file
    at ``path`` (families without free parameters are single methods: members with no values);
    without requirements, the tableau itself (:func:`tableau_family`)."""
    from .design import solve_file
    if not requirements:
        return [tableau_family(path)]
    res = solve_file(path, list(requirements))          # as `solve` reads it (unknown abscissae dropped)
    if res.status != "solved":
        raise FamilyError(f"{path}: {res.status} for {', '.join(map(str, requirements))}")
    good = [s for s in res.solutions if s.real and s.method is not None]
    return [family_from_solution(s, requirements, f"{res.name} #{i + 1}") for i, s in enumerate(good)]


def dirk_g_symplectic_family(V, G, s: int, name: str = "DIRK G-symplectic family") -> Family:
    r"""GLMs that are G-symplectic and diagonally implicit **by construction** (the structure of GLM43,
    seed §3.2.3): V and G given (VᵀGV = G), D = diag(d₁, …, d_s) with the stage weights as B's first
    row (d_s = d₁, …: the symmetric weights b = (d₁, ½ − d₁, ½ − d₁, d₁) for s = 4), the other rows of
    B free, and then

        U = D⁻¹BᵀGV,        A lower triangular with DA + AᵀD = BᵀGB

    (a_ij = (BᵀGB)_ij/d_i for i > j, a_ii = (BᵀGB)_ii/(2d_i)), so that the three G-symplectic
    conditions hold identically, and U's first column is 1 whenever G's first row is e₁ and V e₁ = e₁.
    Free parameters: d₁ and the s(r − 1) entries b_ij (i ≥ 2) of B; branch conditions: d_i ≠ 0.

    >>> import sympy as sp
    >>> from tableau_lab.exact.tableau_json import load
    >>> g43 = load("methods/glm43.json")
    >>> fam = dirk_g_symplectic_family(*glm43_structure(), 4)
    >>> len(fam.free)
    9
    >>> values = {"d1": g43.B[0, 0], **{f"b{i + 1}{j + 1}": g43.B[i, j] for i in (1, 2) for j in range(4)}}
    >>> m = fam.member(values)
    >>> from tableau_lab.exact.field import is_zero
    >>> all(is_zero(e) for e in m.A - g43.A) and all(is_zero(e) for e in m.U - g43.U)
    True
    """
    V, G = sp.Matrix(V), sp.Matrix(G)
    r = V.rows
    if s != 4:
        raise FamilyError(f"{name}: the symmetric stage weights are written for s = 4 here, not s = {s}")
    d1 = sp.Symbol("d1")
    weights = [d1, sp.Rational(1, 2) - d1, sp.Rational(1, 2) - d1, d1]
    others = [[sp.Symbol(f"b{i + 1}{j + 1}") for j in range(s)] for i in range(1, r)]
    B = sp.Matrix([weights] + others)
    if not all(is_zero(e) for e in V.T * G * V - G):
        raise FamilyError(f"{name}: VᵀGV ≠ G")
    A, U = dirk_stages(B, G, V, sp.zeros)
    A, U = A.applyfunc(sp.cancel), U.applyfunc(sp.cancel)
    m = GeneralLinearMethod(A=sp.ImmutableMatrix(A), U=sp.ImmutableMatrix(U), B=sp.ImmutableMatrix(B),
                            V=sp.ImmutableMatrix(V), name=name)
    free = (d1,) + tuple(x for row in others for x in row)
    return Family(name, m, free, (d1, sp.Rational(1, 2) - d1), ("g-symplectic",))


def dirk_stages(B, G, V, zeros):
    r"""A and U of the G-symplectic, diagonally implicit GLM with output matrix B (first row: the
    stage weights d = diag D), any arithmetic (sympy matrices, numpy arrays; ``zeros(rows, cols)``
    makes a zero matrix of it):

        U = D⁻¹BᵀGV,    a_ij = (BᵀGB)_ij/d_i (i > j),    a_ii = (BᵀGB)_ii/(2d_i),    a_ij = 0 (i < j),

    so that DU = BᵀGV and DA + AᵀD = BᵀGB hold identically (seed §3.2.3)."""
    r, s = B.shape
    d = [B[0, j] for j in range(s)]
    M = B.T @ G @ B
    BtGV = B.T @ G @ V
    U, A = zeros(s, r), zeros(s, s)
    for i in range(s):
        for j in range(r):
            U[i, j] = BtGV[i, j] / d[i]
        for j in range(i):
            A[i, j] = M[i, j] / d[i]
        A[i, i] = M[i, i] / (2 * d[i])
    return A, U


def _qmul(a, b):
    """The quaternion product of (a1, a2, a3, a4) and (b1, b2, b3, b4), any arithmetic."""
    a1, a2, a3, a4 = a
    b1, b2, b3, b4 = b
    return (a1 * b1 - a2 * b2 - a3 * b3 - a4 * b4, a1 * b2 + a2 * b1 + a3 * b4 - a4 * b3,
            a1 * b3 - a2 * b4 + a3 * b1 + a4 * b2, a1 * b4 + a2 * b3 - a3 * b2 + a4 * b1)


def glm43_structure() -> tuple:
    """(V, G) of GLM43 (seed §3.2.3), exactly: V the rotation by 2π/3 on the last two values and
    G = diag(1, −1/4, −1/4), the structure the moonshot families share."""
    half, root = sp.Rational(1, 2), sp.sqrt(3) / 2
    return (sp.ImmutableMatrix([[1, 0, 0], [0, -half, -root], [0, root, -half]]),
            sp.ImmutableMatrix(sp.diag(1, -sp.Rational(1, 4), -sp.Rational(1, 4))))


def parasitism_free_rows(h, q, matrix=sp.Matrix):
    r"""The output matrix B of a member of :func:`dirk_g_symplectic_family` (s = 4, r = 3, V the
    rotation by 2π/3 or any rotation on the last two values, G = diag(1, −γ, −γ)) on which the
    parasitic growth parameters vanish **identically**, from two quaternions h, q (``matrix``: sp.Matrix,
    exact, the default; or a float constructor such as ``np.array``).

    Why: for ζ = e^{iφ} the eigenvectors are x = (0, 1, −i)ᵀ (right) and y = (0, 1, i) (left), so
    with BU = BD⁻¹BᵀGV the growth parameter ([BHHN14]) μ = ζ⁻¹yBUx/(yx) = −(γ/2) Σⱼ |βⱼ|²/dⱼ,
    βⱼ = b₂ⱼ + i b₃ⱼ.  With d = (d₁, ½ − d₁, ½ − d₁, d₁), μ = 0 iff |P|² = κ|Q|², κ = −d₁/(½ − d₁),
    for the quaternions P = (β₁, β₄) and Q = (β₂, β₃); every such pair is P = hQ with |h|² = κ,
    i.e. d₁ = −κ/(2(1 − κ)), Q = q.  So every μ-free member (κ ≠ 1) is B(h, q), and every B(h, q)
    is μ-free: a rational (h, q) gives an exact μ-free method with rational B.

    >>> import sympy as sp
    >>> from tableau_lab.analysis.parasitism import growth_parameters
    >>> V, G = glm43_structure()
    >>> B = parasitism_free_rows([sp.Rational(1, 2), 1, 0, sp.Rational(-1, 3)], [1, 2, sp.Rational(1, 5), -1])
    >>> A, U = dirk_stages(B, G, V, sp.zeros)
    >>> [x.mu for x in growth_parameters(GeneralLinearMethod(A=A, U=U, B=B, V=V)).items]
    [0, 0]
    """
    if matrix is sp.Matrix:                 # exact: plain ints must not divide into floats
        h, q = ([sp.Integer(x) if isinstance(x, int) else x for x in v] for v in (h, q))
    kappa = sum(x * x for x in h)
    d1 = -kappa / (2 * (1 - kappa))
    d2 = (1 - 2 * d1) / 2
    p = _qmul(h, q)
    return matrix([[d1, d2, d2, d1], [p[0], q[0], q[2], p[2]], [p[1], q[1], q[3], p[3]]])
