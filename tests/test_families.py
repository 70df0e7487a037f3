"""The collocation families for any number of stages, analysed in ℚ on the roots of the node
polynomial: orders pinned (all conditions up to p, one failing at p + 1), B/C/D of [HW96]
Table IV.5.13, the nodes and weights against numpy's Gauss–Legendre quadrature, the congruence
Vᵀ M V against M itself where the nodes are radicals, and the stability verdicts of the theory."""
import numpy as np
import pytest
import sympy as sp

from tableau_lab.analysis.algebraic_stability import algebraic_stability
from tableau_lab.analysis.rk_order import rk_order
from tableau_lab.analysis.stability import stability
from tableau_lab.analysis.symplectic import rk_symplectic
from tableau_lab.exact.families import (
    gauss,
    lobatto_iiia,
    lobatto_iiib,
    lobatto_iiic,
    lobatto_iiic_star,
    radau_ia,
    radau_iia,
)
from tableau_lab.exact.field import field_of, is_zero
from tableau_lab.exact.tableau_json import load

# (order, B, C, D) for s stages: Gauss 2s, B(2s) C(s) D(s); Radau IIA 2s−1, B(2s−1) C(s) D(s−1);
# Lobatto IIIA 2s−2, B(2s−2) C(s) D(s−2)  ([HW96] Table IV.5.13)
# Radau IA 2s−1, B(2s−1) C(s−1) D(s); Lobatto IIIB 2s−2, B(2s−2) C(s−2) D(s); IIIC 2s−2, C(s−1) D(s−1);
# IIIC* ([HLW06] II.2) 2s−2, C(s−1) D(s−1).  B, C, D here are with c = A·1, so C(1) always holds; where
# that is not the nodes (Radau IA with s = 1: c = 1, not 0; IIIB with s = 2: c = (1/2, 1/2), not (0, 1))
# D(s) of the nodes is not D(s) of c: D(0) and D(1) there
FACTS = {gauss: lambda s: (2 * s, 2 * s, s, s), radau_iia: lambda s: (2 * s - 1, 2 * s - 1, s, s - 1),
         lobatto_iiia: lambda s: (2 * s - 2, 2 * s - 2, s, s - 2),
         radau_ia: lambda s: (2 * s - 1, 2 * s - 1, max(s - 1, 1), s if s > 1 else 0),
         lobatto_iiib: lambda s: (2 * s - 2, 2 * s - 2, max(s - 2, 1), s if s > 2 else 1),
         lobatto_iiic: lambda s: (2 * s - 2, 2 * s - 2, s - 1, s - 1),
         lobatto_iiic_star: lambda s: (2 * s - 2, 2 * s - 2, s - 1, s - 1)}
# up to 7 Gauss stages (order 14): the pin of Gauss 8 (order 16, its order-17 conditions) alone cost
# a fifth of the suite's exact work; 8 stages are pinned by Radau IIA 8 (order 15) in the same number field degree
CASES = [(gauss, s) for s in range(1, 8)] + [(radau_iia, s) for s in range(1, 9)] \
    + [(lobatto_iiia, s) for s in range(2, 8)] + [(radau_ia, s) for s in range(1, 7)] \
    + [(f, s) for f in (lobatto_iiib, lobatto_iiic, lobatto_iiic_star) for s in range(2, 7)]


@pytest.mark.parametrize("family, s", CASES, ids=lambda x: getattr(x, "__name__", str(x)))
def test_orders_pinned(family, s):
    r = rk_order(family(s))
    assert (r.order, r.B, r.C, r.D) == FACTS[family](s)
    assert r.residuals and not r.capped                      # an order-(p+1) condition fails
    assert r.effective_order == r.order                      # R(z) − e^z = O(z^{p+1}) exactly


@pytest.mark.parametrize("s", [2, 5, 6, 8])
def test_gauss_nodes_and_weights_are_gauss_legendre_quadrature(s):
    """Against numpy's Golub–Welsch nodes and weights on [−1, 1], mapped to [0, 1]; the rows of
    A sum to c."""
    m = gauss(s)
    x, w = np.polynomial.legendre.leggauss(s)
    c = np.array([float(sp.N(v, 30)) for v in m.c])
    b = np.array([float(sp.N(v, 30)) for v in m.b])
    A = np.array([[float(sp.N(v, 30)) for v in m.A.row(i)] for i in range(s)])
    assert np.allclose(c, (x + 1) / 2, atol=1e-14) and np.allclose(b, w / 2, atol=1e-14)
    assert np.allclose(A.sum(axis=1), c, atol=1e-14)


def test_small_members_equal_the_library_files():
    for family, path in [(gauss, "methods/gauss2.json"), (gauss, "methods/gauss3.json"),
                         (radau_iia, "methods/radau_iia3.json"), (lobatto_iiia, "methods/lobatto_iiia3.json"),
                         (lobatto_iiib, "methods/lobatto_iiib3.json"), (lobatto_iiic, "methods/lobatto_iiic3.json")]:
        f = load(path)
        g = family(f.s)
        K = field_of([f.A, f.b, g.A, g.b])
        assert all(is_zero(x - y, K) for x, y in zip(list(f.A) + list(f.b), list(g.A) + list(g.b), strict=False))


@pytest.mark.parametrize("family, s", [(radau_iia, 3), (lobatto_iiia, 3), (gauss, 3)])
def test_congruent_symplecticity_form_has_the_inertia_of_M(family, s):
    """Where the nodes are radicals M itself can be computed in their field: Vᵀ M V from ℚ equals
    it transformed, and both have the same rank."""
    m = family(s)
    K = field_of([m.A, m.b, m.c])
    b, A = m.b, m.A
    M = sp.Matrix(s, s, lambda i, j: b[i] * A[i, j] + b[j] * A[j, i] - b[i] * b[j])
    V = sp.Matrix(s, s, lambda j, k: m.c[j] ** k)
    form = rk_symplectic(m).M
    assert all(is_zero(x - y, K) for x, y in zip(V.T * M * V, form, strict=False))


@pytest.mark.parametrize("family, s, symplectic, a_stable, alg_stable", [
    (gauss, 6, True, True, True), (gauss, 8, True, None, True),       # [HW96] IV.3, IV.12; [HLW06] VI.4
    (radau_iia, 6, False, True, True), (lobatto_iiia, 5, False, True, False)])
def test_stability_verdicts(family, s, symplectic, a_stable, alg_stable):
    m = family(s)
    assert rk_symplectic(m).holds is symplectic
    if a_stable is not None:
        assert stability(m).a_stable is a_stable
    assert algebraic_stability(m).holds is alg_stable


def test_small_members_by_hand():
    """[HW96] Table IV.5.x with s = 2 and [HLW06] II.2 (IIIC*): the tableaux themselves."""
    R = sp.Rational
    assert lobatto_iiic(2).A == sp.Matrix([[R(1, 2), R(-1, 2)], [R(1, 2), R(1, 2)]])
    assert lobatto_iiib(2).A == sp.Matrix([[R(1, 2), 0], [R(1, 2), 0]])
    assert radau_ia(2).A == sp.Matrix([[R(1, 4), R(-1, 4)], [R(1, 4), R(5, 12)]])
    assert lobatto_iiic_star(3).A == sp.Matrix([[0, 0, 0], [R(1, 4), R(1, 4), 0], [0, 1, 0]])
    assert radau_ia(1).A == sp.Matrix([[1]])                 # implicit Euler


def test_families_by_name_and_size_limits():
    assert load("radau_iia:2").c[-1] == 1 and load("lobatto_iiia", s=2).c[0] == 0
    from tableau_lab.exact.tableau_json import TableauError
    with pytest.raises(TableauError, match="at least 2 stages"):
        load("lobatto_iiia:1")
    with pytest.raises(TableauError, match="1 … 8"):
        load("gauss:9")


def test_written_with_named_nodes_and_read_back():
    """6-stage Gauss written as a file (nodes c1 … c6 = root(P, k), entries polynomials in them) is
    recognised when read back: the same Ã and b̃, exactly, and the same order."""
    from tableau_lab.exact.tableau_json import dumps, loads
    m = gauss(6)
    text = dumps(m)
    assert '"constants"' in text and "root(924*x**6" in text
    back = loads(text)
    assert back == m and back.conjugate is not None
    assert (back.conjugate.A_tilde, back.conjugate.b_tilde) == (m.conjugate.A_tilde, m.conjugate.b_tilde)
    assert rk_order(back).order == 12


def test_a_method_on_conjugate_nodes_that_is_not_equivariant_is_not_taken_for_one():
    """Swapping two weights of 6-stage Gauss breaks b = β(c): no conjugate form, and the field of
    all six nodes is refused by its stated budget rather than tried."""
    from tableau_lab.exact.methods import MethodError, RungeKutta
    m = gauss(6)
    b = list(m.b)
    b[0], b[1] = b[1], b[0]
    with pytest.raises(MethodError, match="FIELD_DEGREE_LIMIT"):
        RungeKutta(A=m.A, b=sp.ImmutableMatrix(b), c=m.c)


@pytest.mark.parametrize("spec, order, l_stable", [("sdirk_crouzeix:2", 3, False), ("sdirk_crouzeix:3", 4, False),
                                                   ("sdirk_alexander:2", 2, True), ("sdirk_alexander:3", 3, True)])
def test_sdirk_families(spec, order, l_stable):
    """[HW96] §IV.6: Crouzeix–Nørsett order s + 1, A-stable; Alexander order s, L-stable (R(∞) = 0:
    deg N < deg D)."""
    from tableau_lab.analysis.stability import stability_function
    m = load(spec)
    assert rk_order(m).order == order and stability(m).a_stable is True
    N, D, _ = stability_function(m)
    assert (N.degree() < D.degree()) is l_stable
    if spec == "sdirk_crouzeix:3":
        f = load("sdirk34")
        assert all(is_zero(x - y) for x, y in zip(list(f.A) + list(f.b), list(m.A) + list(m.b), strict=False))
