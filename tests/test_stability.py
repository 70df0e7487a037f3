"""Linear and algebraic stability: published facts, exact identities and independent numerical
checks (eigenvalues of M(z) = V + zB(I − zA)⁻¹U in floating point, never the exact code's output)."""
from __future__ import annotations

import json
from functools import lru_cache

import numpy as np
import pytest
import sympy as sp

from tableau_lab.analysis.algebraic_stability import algebraic_stability
from tableau_lab.analysis.stability import W, Z, stability, stability_function
from tableau_lab.cli import main
from tableau_lab.exact.field import field_of
from tableau_lab.exact.real_roots import all_roots_right, sign
from tableau_lab.exact.tableau_json import load

LIBRARY = ["adams_bashforth2", "butcher_effective5", "example4_glm", "explicit_euler", "gauss2", "gauss3", "glm43",
           "implicit_euler", "implicit_midpoint", "leapfrog", "lobatto_iiia3", "lobatto_iiib3", "lobatto_iiic3",
           "radau_iia3", "rk4", "rule_3_8", "stormer_verlet", "symplectic_euler"]


@lru_cache(maxsize=None)
def method(name):
    return load(f"methods/{name}.json")


@lru_cache(maxsize=None)
def lin(name):
    return stability(method(name))


@lru_cache(maxsize=None)
def float_parts(name):
    g = method(name).as_glm()
    return tuple(np.array(sp.Matrix(X).evalf(20).tolist(), dtype=float) for X in (g.A, g.U, g.B, g.V))


def numeric_moduli(name, z):
    """|w| of the eigenvalues of M(z) = V + zB(I − zA)⁻¹U, in floating point."""
    A, U, B, V = float_parts(name)
    M = V + z * B @ np.linalg.solve(np.eye(A.shape[0]) - z * A, U)
    return np.abs(np.linalg.eigvals(M))


# ---------------------------------------------------------------- published facts

@pytest.mark.parametrize("name", ["gauss2", "gauss3", "implicit_midpoint"])
def test_gauss_methods_are_a_stable_with_the_whole_axis_on_the_circle(name):
    res = lin(name)
    assert res.a_stable is True
    assert res.imaginary_interval == sp.oo and res.unit_radius == sp.oo and res.symplectic


def test_rk4_interval_is_two_root_two_and_r_is_the_taylor_polynomial():
    res = lin("rk4")
    assert sp.simplify(res.imaginary_interval - 2 * sp.sqrt(2)) == 0
    assert res.interval_kind == "|w| <= 1"
    assert sp.expand(res.stability_function - (1 + Z + Z**2 / 2 + Z**3 / 6 + Z**4 / 24)) == 0
    assert res.a_stable is False and res.unit_radius == 0
    # |R(iy)|² = 1 − y⁶/72 + y⁸/576 by hand: ≤ 1 exactly for y² ≤ 8
    assert np.all(numeric_moduli("rk4", 2.828j) <= 1) and np.all(numeric_moduli("rk4", 2.829j) > 1)


def test_leapfrog_interval_is_one_with_a_double_root_i_at_the_end():
    res = lin("leapfrog")
    assert res.imaginary_interval == 1 and res.unit_radius == 1 and res.bounded_radius == 1
    # by hand: P(w, z) = w² − 2zw − 1, so P(w, i) = (w − i)²
    assert sp.expand(res.polynomial - (W**2 - 2 * Z * W - 1)) == 0
    assert sp.expand(res.polynomial.subs(Z, sp.I) - (W - sp.I) ** 2) == 0
    assert [(r.root, r.multiplicity) for r in res.endpoint_roots] == [(sp.I, 2)]
    assert np.allclose(numeric_moduli("leapfrog", 0.999j), 1) and numeric_moduli("leapfrog", 1.001j).max() > 1.01


@pytest.mark.parametrize("name,expected", [("explicit_euler", False), ("implicit_euler", True),
                                           ("radau_iia3", True), ("lobatto_iiic3", True), ("lobatto_iiia3", True),
                                           ("rule_3_8", False), ("butcher_effective5", False),
                                           ("sdirk34", True)])      # [HW96] IV.6: A-stable for this γ
def test_a_stability_of_rk_methods(name, expected):
    assert lin(name).a_stable is expected


@pytest.mark.parametrize("name", ["explicit_euler", "implicit_euler", "radau_iia3", "rk4", "gauss2", "sdirk34"])
def test_rk_verdict_agrees_with_the_glm_verdict_of_the_same_method(name):
    """The E-polynomial test (RK) and the root-locus test (the method as a GLM) are separate code paths."""
    as_glm = stability(method(name).as_glm())
    assert as_glm.a_stable is lin(name).a_stable
    assert as_glm.bounded_radius == lin(name).bounded_radius


@pytest.mark.parametrize("name", ["stormer_verlet", "symplectic_euler"])
def test_partitioned_methods_on_the_harmonic_oscillator(name):
    res = lin(name)
    x = sp.Symbol("x")
    # by hand: M(x) has trace 2 − x² and determinant 1, stable exactly for |x| < 2 (hω < 2)
    assert sp.expand(res.polynomial - (W**2 - (2 - x**2) * W + 1)) == 0
    assert res.imaginary_interval == 2 and res.a_stable is None
    assert [(r.root, r.multiplicity) for r in res.endpoint_roots] == [(-1, 2)]


# ---------------------------------------------------------------- exact identities

@pytest.mark.parametrize("name", ["example4_glm", "leapfrog", "adams_bashforth2", "glm43", "rk4", "gauss2"])
def test_polynomial_at_zero_is_the_characteristic_polynomial_of_V(name):
    g = method(name).as_glm()
    expected = (W * sp.eye(g.r) - g.V).det()
    assert sp.expand(lin(name).polynomial.subs(Z, 0) - expected) == 0


@pytest.mark.parametrize("name", ["example4_glm", "leapfrog", "radau_iia3"])
def test_polynomial_is_det_i_minus_za_times_det_w_minus_m(name):
    g = method(name).as_glm()
    z0 = sp.Rational(-3, 7)
    M = g.V + z0 * g.B * (sp.eye(g.s) - z0 * g.A).inv() * g.U
    expected = (sp.eye(g.s) - z0 * g.A).det() * (W * sp.eye(g.r) - M).det()
    assert sp.simplify(sp.expand(lin(name).polynomial.subs(Z, z0) - expected)) == 0


def test_stability_function_is_n_over_d():
    N, D, K = stability_function(method("implicit_euler"))
    assert (N.as_expr(), D.as_expr()) == (1, 1 - Z)


def test_certified_signs_and_routh_hurwitz():
    K = field_of([sp.sqrt(2)])
    close = K.from_sympy(sp.sqrt(2) - sp.Rational(14142135623730951, 10**16))     # ≈ −4.4e-17
    assert sign(K, close) == -1 and sign(K, K.zero) == 0
    from sympy.polys.rings import ring
    R, z = ring("z", sp.QQ)
    assert all_roots_right((z - 1) * (z**2 - 2 * z + 5), sp.QQ)        # 1, 1 ± 2i
    assert not all_roots_right((z - 1) * (z**2 + 1), sp.QQ)            # ±i on the axis
    assert not all_roots_right((z - 1) * (z**2 + 2 * z + 5), sp.QQ)


# ---------------------------------------------------------------- GLMs against dense numerics

def test_example4_on_the_circle_along_the_whole_axis_and_a_stable():
    res = lin("example4_glm")
    assert res.unit_radius == sp.oo and res.a_stable is True
    for y in np.linspace(0.01, 60, 600):
        assert np.allclose(numeric_moduli("example4_glm", 1j * y), 1, atol=1e-9)
    rng = np.random.default_rng(4)
    for z in -rng.exponential(3, 200) + 1j * rng.normal(0, 10, 200):     # Re z < 0
        assert numeric_moduli("example4_glm", z).max() <= 1 + 1e-12


def test_glm43_interval_against_dense_numerics():
    res = lin("glm43")
    Y = float(res.imaginary_interval)
    assert res.symplectic and res.unit_radius == res.bounded_radius
    ys = np.linspace(0.005, 4, 4000)
    off = np.array([np.abs(numeric_moduli("glm43", 1j * y) - 1).max() for y in ys])
    first_off = ys[np.argmax(off > 1e-6)]
    assert abs(first_off - Y) < 2e-3
    assert off[ys < Y - 1e-3].max() < 1e-7
    doubles = [r for r in res.endpoint_roots if r.multiplicity == 2]
    assert len(doubles) == 1 and abs(doubles[0].modulus - 1) < 1e-12      # a collision on the circle


def test_adams_bashforth2_has_no_imaginary_interval():
    res = lin("adams_bashforth2")
    assert res.imaginary_interval == 0 and res.a_stable is False
    assert numeric_moduli("adams_bashforth2", 0.05j).max() > 1


# ---------------------------------------------------------------- algebraic stability

@pytest.mark.parametrize("name,expected", [("gauss2", True), ("gauss3", True), ("implicit_midpoint", True),
                                           ("radau_iia3", True), ("lobatto_iiic3", True), ("implicit_euler", True),
                                           ("lobatto_iiia3", False), ("lobatto_iiib3", False),
                                           ("explicit_euler", False), ("rk4", False), ("rule_3_8", False)])
def test_algebraic_stability_of_rk_methods(name, expected):
    res = algebraic_stability(method(name))
    assert res.holds is expected
    if name.startswith("gauss"):
        assert res.M.is_zero_matrix


def test_example4_is_algebraically_stable_with_its_g_symplectic_pair():
    res = algebraic_stability(method("example4_glm"))
    assert res.holds is True and res.M.is_zero_matrix
    assert sp.simplify(res.G - sp.diag(1, (3 + 2 * sp.sqrt(3)) / 3)) == sp.zeros(2)
    assert res.D == sp.diag(sp.Rational(1, 2), sp.Rational(1, 2))


def test_leapfrog_is_not_algebraically_stable():
    res = algebraic_stability(method("leapfrog"), a_stable=lin("leapfrog").a_stable)
    assert res.holds is False and res.G == sp.Matrix([[0, 1], [1, 0]])


@pytest.mark.parametrize("name", [n for n in LIBRARY if n not in ("stormer_verlet", "symplectic_euler")])
def test_algebraic_stability_implies_a_stability(name):
    res = algebraic_stability(method(name), a_stable=lin(name).a_stable)
    if res.holds:
        assert lin(name).a_stable is True


# ---------------------------------------------------------------- the command line

def test_cli_json_and_exit_codes(capsys, tmp_path):
    assert main(["stability", "--json", "methods/rk4.json", "methods/example4_glm.json"]) == 0
    rk4, e4 = (json.loads(line) for line in capsys.readouterr().out.splitlines())
    assert rk4["imaginary_interval"] == "2*sqrt(2)" and rk4["parasitism"] == []
    assert rk4["algebraically_stable"] is False and rk4["a_stable"] is False
    assert rk4["stability_function"]["R"] == "z**4/24 + z**3/6 + z**2/2 + z + 1"
    assert e4["imaginary_interval"] == "inf" and e4["algebraically_stable"] is True
    assert [set(p) for p in e4["parasitism"]] == [{"zeta", "mu"}]
    assert main(["stability", "tests/data/bad/truncated.json"]) == 2
    assert main(["stability", "--plot", str(tmp_path), "methods/leapfrog.json"]) == 0
    from tableau_lab.experiments.figure_style import formats
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(f"leapfrog_{k}{ext}" for k in ("axis", "region")
                                                                for ext in formats())
