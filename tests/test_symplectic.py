"""G-symplecticity and RK symplecticity against independent facts: the seed's Example 4
(checked by plain sympy matrix algebra, not by the solver's own path), hand-derived
families, and exact identities."""
import sympy as sp

from tableau_lab.analysis.symplectic import g_symplectic, g_symplectic_residuals, rk_symplectic
from tableau_lab.exact.methods import GeneralLinearMethod, PartitionedRungeKutta, RungeKutta

S3 = sp.sqrt(3)
half = sp.Rational(1, 2)


def example4():
    """The seed's Example 4 (§2.7, eq. 2.7.0.1)."""
    return GeneralLinearMethod(
        A=sp.Matrix([[(3 + S3) / 6, 0], [-S3 / 3, (3 + S3) / 6]]),
        U=sp.Matrix([[1, -(3 + 2 * S3) / 3], [1, (3 + 2 * S3) / 3]]),
        B=sp.Matrix([[half, half], [half, -half]]),
        V=sp.Matrix([[1, 0], [0, -1]]), name="Example 4")


def zero(M):
    return all(sp.radsimp(sp.expand(x)) == 0 for x in sp.Matrix(M))


def test_example4_G_and_D_exact():
    m = example4()
    res = g_symplectic(m)
    assert res.holds and res.dimension == 1
    assert res.G == sp.Matrix([[1, 0], [0, (3 + 2 * S3) / 3]]).applyfunc(sp.expand)
    assert res.D == sp.diag(half, half)
    assert res.definite is True
    # independent check with plain sympy matrices: the three conditions hold
    A, U, B, V, G, D = m.A, m.U, m.B, m.V, sp.Matrix(res.G), sp.Matrix(res.D)
    assert zero(V.T * G * V - G) and zero(D * U - B.T * G * V) and zero(D * A + A.T * D - B.T * G * B)
    for R in res.residuals.values():
        assert R.is_zero_matrix


def test_example4_errata():
    """ERRATA 4: the seed's D = diag(1/2, -1/2) fails DU = BᵀGV; BᵀGB has off-diagonal -√3/6."""
    m = example4()
    G = sp.diag(1, (3 + 2 * S3) / 3)
    printed = g_symplectic_residuals(m, G, sp.diag(half, -half))
    assert not printed["DU − BᵀGV"].is_zero_matrix
    assert printed["VᵀGV − G"].is_zero_matrix
    BtGB = (m.B.T * G * m.B).applyfunc(lambda x: sp.radsimp(sp.expand(x)))
    assert BtGB[0, 1] == BtGB[1, 0] == -S3 / 6
    assert BtGB[0, 0] == (3 + S3) / 6


def test_example4_family_is_one_dimensional_by_hand():
    """By hand: VᵀGV = G with V = diag(1, -1) forces g12 = 0; DU = BᵀGV then fixes
    d1 = d2 = g11/2 and g22 = g11 (3 + 2√3)/3: one free scale."""
    res = g_symplectic(example4())
    (G, D), = res.basis
    assert G[0, 1] == 0 and sp.radsimp(G[1, 1] / G[0, 0] - (3 + 2 * S3) / 3) == 0
    assert D[0, 0] == D[1, 1] == G[0, 0] / 2


def test_leapfrog_indefinite_G():
    lf = GeneralLinearMethod(A=sp.Matrix([[0]]), U=sp.Matrix([[1, 0]]), B=sp.Matrix([[2], [0]]),
                             V=sp.Matrix([[0, 1], [1, 0]]), name="leapfrog")
    res = g_symplectic(lf)
    assert res.holds and res.dimension == 1
    assert res.G == sp.Matrix([[0, 1], [1, 0]]) and res.D == sp.Matrix([[2]])
    assert res.definite is False


def test_family_of_dimension_two_needs_a_combination():
    """Implicit midpoint with a passive second value: G = diag(g11, g22), both basis
    members singular, their sum not."""
    m = GeneralLinearMethod(A=sp.Matrix([[half]]), U=sp.Matrix([[1, 0]]), B=sp.Matrix([[1], [0]]),
                            V=sp.eye(2), name="midpoint + passive value")
    res = g_symplectic(m)
    assert res.dimension == 2 and res.holds
    assert all(sp.Matrix(G).det() == 0 for G, _ in res.basis)
    assert sp.Matrix(res.G).det() != 0


def test_only_singular_G():
    m = GeneralLinearMethod(A=sp.Matrix([[half]]), U=sp.Matrix([[1, 0]]), B=sp.Matrix([[1], [0]]),
                            V=sp.diag(1, 0), name="midpoint + dying value")
    res = g_symplectic(m)
    assert res.dimension == 1 and not res.holds
    assert "singular" in res.reason


def test_parametric_rk_generic_verdict():
    """One-stage RK with a11 = θ: M = [2θ - 1]; symplectic only at θ = 1/2, so generically not."""
    th = sp.Symbol("theta", real=True)
    m = RungeKutta.from_lists([[th]], [1], name="theta method")
    r = rk_symplectic(m)
    assert not r.holds and sp.expand(r.M[0, 0] - (2 * th - 1)) == 0
    g = g_symplectic(m)
    assert not g.holds and g.parameters == (th,)
    assert rk_symplectic(RungeKutta.from_lists([[half]], [1])).holds


def test_partitioned_conditions():
    """Symplectic Euler and Störmer–Verlet ([HLW06] Thm VI.4.6); a pair with M = 0 but b ≠ b̂
    is symplectic for separable Hamiltonians only."""
    se = PartitionedRungeKutta.from_lists([[0]], [1], [[1]], [1], name="symplectic Euler")
    sv = PartitionedRungeKutta.from_lists([[0, 0], [half, half]], [half, half], [[half, 0], [half, 0]],
                                          [half, half], name="Störmer–Verlet")
    for m in (se, sv):
        r = rk_symplectic(m)
        assert r.holds and r.M.is_zero_matrix and r.weights_equal
    # explicit Euler for both partitions: not symplectic
    ee = PartitionedRungeKutta.from_lists([[0]], [1], [[0]], [1])
    assert not rk_symplectic(ee).holds


def test_result_objects_print_serialise_render():
    res = g_symplectic(example4())
    assert "D = diag(1/2, 1/2)" in str(res)
    js = res.to_json()
    assert js["D"] == [["1/2", "0"], ["0", "1/2"]] and js["dimension"] == 1
    tex = res.to_latex()
    assert r"\frac{1}{2}" in tex and "G-symplectic" in tex


def test_parameter_with_radicals_generic_and_special_value():
    """Example 4 with its diagonal entry replaced by a parameter θ: generically not
    G-symplectic (the field is QQ<√3>(θ)); at θ = (3 + √3)/6 it is again."""
    th = sp.Symbol("theta", real=True)
    m = example4()
    fam = GeneralLinearMethod(A=sp.Matrix([[th, 0], [-S3 / 3, th]]), U=m.U, B=m.B, V=m.V, name="θ family")
    res = g_symplectic(fam)
    assert not res.holds and res.parameters == (th,)
    special = GeneralLinearMethod(A=fam.A.subs(th, (3 + S3) / 6), U=m.U, B=m.B, V=m.V)
    assert g_symplectic(special).holds


def test_g_symplectic_of_a_partitioned_method_is_a_clear_type_error():
    """A partitioned RK method has no GLM form (A, U, B, V): g_symplectic and the residuals say so
    (TypeError naming the kind, as rk_symplectic does for a GLM) instead of an AttributeError on
    ``as_glm`` (found by mypy: ``Method`` had no ``as_glm``)."""
    import pytest

    from tableau_lab.exact.tableau_json import load
    prk = load("methods/stormer_verlet.json")
    with pytest.raises(TypeError, match="partitioned Runge–Kutta method has no general linear form"):
        g_symplectic(prk)
    with pytest.raises(TypeError, match="no general linear form"):
        g_symplectic_residuals(prk, [[1]], [[1]])
