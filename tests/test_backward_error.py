"""Backward error analysis against independent facts: published modified equations and modified
Hamiltonians ([HLW06] IX.1, IX.3), exact identities (the flow of the modified field is the method;
J⁻¹∇H̃ equals the modified field term by term; I′f̃ vanishes for the modified energy of a GLM),
counting identities of the substitution law, and the structure theorems (Gauss symplectic, RK4
not; trapezoidal rule conjugate to the midpoint rule; AVF energy-preserving and not symplectic)."""
import pytest
import sympy as sp

from tableau_lab.analysis.bseries import (
    BSeries,
    compose,
    exact_flow,
    flow_of,
    inverse,
    modified_field,
    modifying_field,
    series_order,
    substitute,
)
from tableau_lab.analysis.free_trees import free_tree
from tableau_lab.analysis.glm_order import theta_matrix
from tableau_lab.analysis.method_series import method_series
from tableau_lab.analysis.modified import modified_equation
from tableau_lab.analysis.modified_hamiltonian import _hamiltonian_field, elementary_differential, modified_hamiltonian
from tableau_lab.analysis.series_structure import (
    conjugate_symplectic,
    energy_order,
    structure,
    symplectic_order,
    tree_pairs,
)
from tableau_lab.analysis.tree_kinds import BICOLOURED, PLAIN, partitions
from tableau_lab.analysis.trees import butcher_product, parse_tree as T, symmetry, trees_of_order, trees_up_to
from tableau_lab.exact.methods import RungeKutta
from tableau_lab.exact.tableau_json import load

R = sp.Rational


def series(name, n):
    return method_series(load(f"methods/{name}.json"), n).phi


def coefficient(field, text):
    t = T(text)
    return field[t] / symmetry(t)


@pytest.mark.parametrize("n", range(1, 9))
def test_partitions_count_edge_subsets(n):
    """Σ multiplicities = 2^(n−1); the pieces have n vertices in all; the skeleton has one vertex per piece."""
    for kind in (PLAIN, BICOLOURED) if n <= 6 else (PLAIN,):
        for t in kind.trees_of_order(n):
            parts = partitions(kind, t)
            assert sum(m for _, _, m in parts) == 2 ** (n - 1)
            for skel, pieces, _ in parts:
                assert sum(kind.order(p) for p in pieces) == n and kind.order(skel) == len(pieces)


def test_explicit_euler_modified_equation_hlw_ix1():
    """[HLW06] IX.1 (1.6): f̃ = f − h/2 f′f + h²(1/12 f″(f,f) + 1/3 f′f′f) + O(h³)."""
    b = modified_equation(load("methods/explicit_euler.json"), 3).field
    assert [coefficient(b, x) for x in ("τ", "[τ]", "[τ²]", "[[τ]]")] == [1, R(-1, 2), R(1, 12), R(1, 3)]


def test_implicit_midpoint_modified_equation_hlw_ix1():
    """[HLW06] IX.1: the midpoint rule has f̃ = f + h²(−1/24 f″(f,f) + 1/12 f′f′f) + O(h⁴), no odd powers."""
    b = modified_equation(load("methods/implicit_midpoint.json"), 6).field
    assert coefficient(b, "[τ]") == 0 and coefficient(b, "[τ²]") == R(-1, 24) and coefficient(b, "[[τ]]") == R(1, 12)
    assert all(b[t] == 0 for n in (4, 6) for t in trees_of_order(n))


@pytest.mark.parametrize("name", ["explicit_euler", "rk4", "gauss2", "radau_iia3", "glm43", "example4_glm"])
def test_flow_of_modified_field_is_the_method(name):
    """exp(b) = b ⋆ E reproduces the method's series, and the modifying field c gives c ⋆ Φ = E."""
    a = series(name, 6)
    assert flow_of(modified_field(a)) == a
    assert substitute(modifying_field(a), a) == exact_flow(6)


def test_substitution_is_a_group_action():
    """(b ⋆ a)·(b ⋆ c) = b ⋆ (a·c): substitution is a morphism of the composition law ([CHV10] Prop. 3.3)."""
    a, c = series("rk4", 6), series("radau_iia3", 6)
    b = modified_field(series("explicit_euler", 6))
    assert compose(substitute(b, a), substitute(b, c)) == substitute(b, compose(a, c))


def test_gauss_symplectic_rk4_not():
    assert symplectic_order(series("gauss2", 8)) == 8
    assert symplectic_order(series("gauss3", 8)) == 8
    assert symplectic_order(series("rk4", 8)) == 4          # a defect at order 5
    assert structure(series("rk4", 6)).symplectic_witness is not None


def test_conjugate_symplecticity():
    """The trapezoidal rule is conjugate to the midpoint rule ([HLW06] VI.8, Example 8.?): conjugate-
    symplectic to every order, with a certificate χ checked by the plain symplecticity test; the
    underlying one-step methods of the G-symplectic GLMs likewise; every order-2 method is conjugate-
    symplectic to order 3 but the energy-preserving AVF method is not conjugate-symplectic
    ([HLW06] VI.8; Chartier, Faou & Murua 2006)."""
    trap = RungeKutta.from_lists([[0, 0], [R(1, 2), R(1, 2)]], [R(1, 2), R(1, 2)], name="trapezoidal")
    for a in (method_series(trap, 7).phi, series("glm43", 7), series("example4_glm", 7)):
        n, chi = conjugate_symplectic(a)
        assert n == 7 and symplectic_order(a) < 7
        assert symplectic_order(compose(compose(chi, a), inverse(chi))) == 7

    def avf(t):
        v = R(1, len(t) + 1) if t else 1
        for c in t:
            v *= avf(c)
        return v
    s = structure(BSeries.from_function(avf, 7, "AVF"))
    assert s.energy_preserving == 7 and s.symplectic == 2 and 3 <= s.conjugate_symplectic < 7


@pytest.mark.parametrize("n", range(3, 10))
def test_conjugation_kernel_is_hamiltonian(n):
    """The linear system of the conjugation at order n has as kernel exactly the Hamiltonian fields of
    order n − 1 (dimension: the non-superfluous free trees), so the order-by-order choice of χ is
    complete (see series_structure) through order 9, the budget of the docs table."""
    prev = trees_of_order(n - 1)
    index = {t: i for i, t in enumerate(trees_of_order(n))}
    L = theta_matrix(n)
    from sympy.polys.matrices import DomainMatrix
    rows = [[sp.QQ(L[index[butcher_product(u, v)]][j] + L[index[butcher_product(v, u)]][j]) for j in range(len(prev))]
            for u, v in tree_pairs(n)]
    M = DomainMatrix(rows, (len(rows), len(prev)), sp.QQ)
    hamiltonian = {free_tree(t).key for t in prev if not free_tree(t).superfluous}
    assert len(prev) - M.rank() == len(hamiltonian)


def test_energy_preservation_and_exact_flow():
    E = exact_flow(7)
    assert energy_order(modified_field(E)) == 7 and symplectic_order(E) == 7
    assert energy_order(modified_field(series("implicit_midpoint", 5))) == 2


def _pendulum():
    q, p = sp.symbols("q p")
    return p ** 2 / 2 - sp.cos(q), (q,), (p,)


def _henon_heiles():
    q1, q2, p1, p2 = sp.symbols("q1 q2 p1 p2")
    return (p1 ** 2 + p2 ** 2) / 2 + (q1 ** 2 + q2 ** 2) / 2 + q1 ** 2 * q2 - q2 ** 3 / 3, (q1, q2), (p1, p2)


def test_midpoint_modified_hamiltonian_hlw_ix3():
    """[HLW06] IX.3: H̃ = H − h²/24 H″(f, f) + O(h⁴) for the implicit midpoint rule."""
    H, q, p = _pendulum()
    mh = modified_hamiltonian(modified_field(series("implicit_midpoint", 5)))
    f = _hamiltonian_field(H, q, p)
    pairs = list(zip(q + p, f, strict=False))
    Hff = sum(sp.diff(H, x, y) * fx * fy for x, fx in pairs for y, fy in pairs)
    assert sp.expand(mh.expression(H, q, p, 3) + Hff / 24) == 0


@pytest.mark.parametrize("name,upto", [("gauss2", 7), ("implicit_midpoint", 5)])
def test_modified_hamiltonian_generates_the_modified_field(name, upto):
    """For a symplectic method, J⁻¹∇H_k = f̃_k for every power of h (exact, polynomial Hamiltonian)."""
    H, q, p = _henon_heiles()
    y = q + p
    f = _hamiltonian_field(H, q, p)
    b = modified_field(series(name, upto))
    mh = modified_hamiltonian(b)
    assert mh.order == upto and mh.free == 0
    cache: dict = {}
    for n in range(2, upto + 1):
        Hn = mh.expression(H, q, p, n)
        grad = _hamiltonian_field(Hn, q, p)
        field = [sum((b[t] / symmetry(t) * elementary_differential(t, y, f, cache)[i] for t in trees_of_order(n)),
                     sp.Integer(0)) for i in range(len(y))]
        assert all(sp.expand(g - fi) == 0 for g, fi in zip(grad, field, strict=False)), n


def test_glm43_modified_energy_is_conserved_by_its_modified_field():
    """GLM43's underlying one-step method is not symplectic, but its modified field conserves an
    H-series I = H + h⁴ I₅ + …: d/dt I = I′f̃ vanishes at every power of h up to the budget."""
    H, q, p = _henon_heiles()
    y = q + p
    f = _hamiltonian_field(H, q, p)
    N = 6
    b = modified_field(series("glm43", N))
    mh = modified_hamiltonian(b)
    assert mh.order == N
    cache: dict = {}
    fields = {n: [sum((b[t] / symmetry(t) * elementary_differential(t, y, f, cache)[i] for t in trees_of_order(n)),
                      sp.Integer(0)) for i in range(len(y))] for n in range(1, N + 1)}
    terms = {n: mh.expression(H, q, p, n) for n in range(1, N + 1)}
    for k in range(0, N):             # the coefficient of h^k in I′f̃
        total = sum(sp.diff(terms[m], yi) * fields[k + 2 - m][i]
                    for m in range(1, k + 2) for i, yi in enumerate(y) if 1 <= k + 2 - m <= N)
        assert sp.expand(total) == 0, k


def test_symplectic_modified_hamiltonian_matches_the_free_tree_formula():
    """[HLW06] IX.9: for a Hamiltonian modified field, β(π) = b(t)·sign(t)/|Aut(π)| for any rooting t of π."""
    b = modified_field(series("gauss3", 7))
    mh = modified_hamiltonian(b)
    for t in trees_up_to(7):
        ft = free_tree(t)
        if t and not ft.superfluous:
            assert mh.beta.get(ft.key, 0) == b[t] * ft.sign / ft.symmetry


def test_five_stage_method_to_order_eight():
    """The 5-stage effective-order method to order 8 (200 trees); the time is printed by the docs
    command, not asserted here."""
    me = modified_equation(load("methods/butcher_effective5.json"), 8)
    assert series_order(method_series(load("methods/butcher_effective5.json"), 8).phi) == 4
    assert len(me.field.items()) == 200


def test_cli_modified(capsys):
    from tableau_lab.cli import main
    assert main(["modified", "methods/explicit_euler.json", "--order", "3"]) == 0
    out = capsys.readouterr().out
    assert "+ h^2 ( 1/12 f''(f, f) + 1/3 f'f'f )" in out
    assert main(["modified", "methods/stormer_verlet.json", "--order", "3"]) == 0      # a P-series
    assert "- 1/24 f_pp(g, g)" in capsys.readouterr().out
    assert main(["modified", "methods/stormer_verlet.json", "--structure"]) == 0     # P-series: the modified energy,
    assert "not checked: symplectic" in capsys.readouterr().out                     # the B-series checks named
    assert main(["modified", "methods/glm43.json", "--order", "6", "--structure", "--json"]) == 0
    import json
    data = json.loads(capsys.readouterr().out)
    assert data["structure"]["conjugate_symplectic"] == 6 and data["structure"]["symplectic"] == 4


# ------------------------------------------------------------------ P-series (partitioned methods)

def _poisson(F, G, q, p):
    return sum(sp.diff(F, qi) * sp.diff(G, pi) - sp.diff(F, pi) * sp.diff(G, qi) for qi, pi in zip(q, p, strict=False))


def test_symplectic_euler_modified_hamiltonian_hlw_ix3():
    """[HLW06] IX.3 (3.?): symplectic Euler has
    H̃ = H − h/2 H_p H_q + h²/12 (H_pp H_q² + H_qq H_p² + 4 H_pq H_p H_q) + …"""
    H, q, p = _pendulum()
    mh = modified_hamiltonian(modified_field(series("symplectic_euler", 4)))
    Hq, Hp = sp.diff(H, q[0]), sp.diff(H, p[0])
    assert sp.expand(mh.expression(H, q, p, 2) + Hp * Hq / 2) == 0
    h2 = (sp.diff(H, p[0], 2) * Hq ** 2 + sp.diff(H, q[0], 2) * Hp ** 2 + 4 * sp.diff(H, q[0], p[0]) * Hp * Hq) / 12
    assert sp.expand(mh.expression(H, q, p, 3) - h2) == 0


def test_stormer_verlet_modified_hamiltonian_by_bch():
    """Störmer–Verlet (kick–drift–kick, as in methods/) is e^{h/2 U} e^{h T} e^{h/2 U}; the symmetric BCH
    formula gives H̃ = H + h²(1/12 {T,{T,U}} − 1/24 {U,{U,T}}) + O(h⁴), computed here by Poisson brackets,
    independently of trees; the odd powers vanish (symmetric method)."""
    q1, q2, p1, p2 = sp.symbols("q1 q2 p1 p2")
    q, p = (q1, q2), (p1, p2)
    T = (p1 ** 2 + p2 ** 2) / 2 + p1 ** 4 / 4
    U = q1 ** 2 * q2 - q2 ** 3 / 3 + q1 ** 4
    mh = modified_hamiltonian(modified_field(series("stormer_verlet", 5)))
    bch = _poisson(T, _poisson(T, U, q, p), q, p) / 12 - _poisson(U, _poisson(U, T, q, p), q, p) / 24
    assert sp.expand(mh.expression(T + U, q, p, 3) - bch) == 0
    assert mh.expression(T + U, q, p, 2) == 0 and sp.expand(mh.expression(T + U, q, p, 4)) == 0


@pytest.mark.parametrize("name", ["stormer_verlet", "symplectic_euler"])
def test_pseries_modified_hamiltonian_generates_the_modified_field(name):
    """J⁻¹∇H_k equals the P-series modified field's h^(k−1) term, exactly, for a non-separable H."""
    from tableau_lab.analysis.tree_kinds import BICOLOURED as B
    H, q, p = _henon_heiles()
    H = H + q[0] * p[1] ** 2                       # couple q and p: a non-separable Hamiltonian
    y = q + p
    f = _hamiltonian_field(H, q, p)
    N = 4
    b = modified_field(series(name, N))
    mh = modified_hamiltonian(b)
    assert mh.order == N
    cache: dict = {"kind": B, "split": len(q)}
    for n in range(2, N + 1):
        grad = _hamiltonian_field(mh.expression(H, q, p, n), q, p)
        field = [sum((b[t] / B.symmetry(t) * elementary_differential(t, y, f, cache)[i] for t in B.trees_of_order(n)),
                     sp.Integer(0)) for i in range(len(y))]
        assert all(sp.expand(g - fi) == 0 for g, fi in zip(grad, field, strict=False)), n


def test_pseries_algebra():
    """The P-series of a PRK: its modified field's flow is the method, and Störmer–Verlet has order 2."""
    a = series("stormer_verlet", 5)
    assert flow_of(modified_field(a)) == a and series_order(a) == 2
    assert substitute(modifying_field(a), a) == exact_flow(5, a.kind)


def test_documented_outputs_are_current(capsys):
    """Every `$ tableau-lab modified …` block in README.md and docs/bseries.md is the command's output."""
    import re
    import shlex
    from pathlib import Path

    from tableau_lab.cli import main
    root = Path(__file__).resolve().parents[1]
    seen = 0
    for doc in ("README.md", "docs/bseries.md"):
        text = (root / doc).read_text()
        for cmd, shown in re.findall(r"```\n\$ (tableau-lab modified [^\n]*)\n(.*?)```", text, re.S):
            assert main(shlex.split(cmd)[1:]) == 0
            out = capsys.readouterr().out
            expected = shown if shown.startswith("==") else None
            assert (out == expected) if expected else (out.split("\n", 1)[1] == shown), (doc, cmd)
            seen += 1
    assert seen >= 3


@pytest.mark.parametrize("name", ["glm43", "example4_glm"])
def test_glm_step_maps_starting_method_onto_underlying_method(name, monkeypatch):
    """M(S(y₀)) = S(Φ(y₀)) + O(h^{N+1}) for the truncated series of the starting method S and the
    underlying one-step method Φ: one step of the GLM solved by Newton at 40 digits on
    y′ = sin y + y²/3, against the series evaluated from elementary differentials; the least-squares
    slope over h = 1/10 … 1/80 is N + 1 = 6."""
    import mpmath as mp
    monkeypatch.setattr(mp.mp, "dps", 40)
    y = sp.Symbol("y")
    fexpr = sp.sin(y) + y ** 2 / 3
    N = 5
    m = load(f"methods/{name}.json")
    g = m.as_glm()
    ms = method_series(m, N)
    cache: dict = {}
    F = {t: sp.lambdify(y, elementary_differential(t, (y,), (fexpr,), cache)[0], "mpmath") for t in trees_up_to(N)}
    f = sp.lambdify(y, fexpr, "mpmath")

    def num(x):
        return mp.mpf(str(sp.N(x, 50)))
    A, U, B, V = ([[num(x) for x in row] for row in M.tolist()] for M in (g.A, g.U, g.B, g.V))
    u = [num(x) for x in ms.u]
    xi = {t: [num(x) for x in ms.starting[t]] for t in trees_up_to(N)}
    phi = {t: num(ms.phi[t]) for t in trees_up_to(N)}

    def S(v, h):
        return [u[i] * v + sum(h ** PLAIN.order(t) / symmetry(t) * xi[t][i] * F[t](v) for t in trees_up_to(N))
                for i in range(g.r)]

    def Phi(v, h):
        return v + sum(h ** PLAIN.order(t) / symmetry(t) * phi[t] * F[t](v) for t in trees_up_to(N))

    y0, hs, errs = mp.mpf("0.7"), [mp.mpf(1) / k for k in (10, 20, 40, 80)], []
    for h in hs:
        x = S(y0, h)
        Y = mp.findroot(lambda *Y, h=h, x=x: [Y[i] - h * sum(A[i][j] * f(Y[j]) for j in range(g.s))
                                              - sum(U[i][k] * x[k] for k in range(g.r)) for i in range(g.s)],
                        [y0] * g.s)
        Y = list(Y)
        out = [h * sum(B[i][j] * f(Y[j]) for j in range(g.s)) + sum(V[i][k] * x[k] for k in range(g.r))
               for i in range(g.r)]
        errs.append(max(abs(a - b) for a, b in zip(out, S(Phi(y0, h), h), strict=False)))
    lx = [float(mp.log(h)) for h in hs]
    ly = [float(mp.log(e)) for e in errs]
    mx, my = sum(lx) / 4, sum(ly) / 4
    slope = sum((a - mx) * (b - my) for a, b in zip(lx, ly, strict=False)) / sum((a - mx) ** 2 for a in lx)
    assert 5.8 < slope < 6.4, (slope, errs)
