"""Number fields made small: square roots reduced to a basis (exact.radicals) and the subfield a
quantity lives in (exact.subfield), checked against exact identities and independent numerics."""
from pathlib import Path

import pytest
import sympy as sp

from tableau_lab.exact import field
from tableau_lab.exact.field import element, field_of
from tableau_lab.exact.radicals import reduce_generators
from tableau_lab.exact.subfield import subfield

ROOT = Path(__file__).resolve().parents[1]
NESTED = sp.sqrt(-5668 + 11 * sp.sqrt(265551))


@pytest.mark.parametrize("gens, degree", [
    ([sp.sqrt(3), sp.sqrt(130), sp.sqrt(390)], 4),                    # √390 = √3·√130
    ([sp.sqrt(2), sp.sqrt(8), sp.sqrt(18)], 2),                       # one square class
    ([sp.sqrt(6), sp.sqrt(10), sp.sqrt(15)], 4),                      # √15 = √6·√10/2
    ([sp.sqrt(3), sp.sqrt(88517), sp.sqrt(265551), NESTED, sp.sqrt(sp.Rational(13, 5760)) * NESTED], 16),
    ([sp.I, sp.sqrt(-3), sp.sqrt(3)], 4),                             # √−3 = i·√3
])
def test_reduced_basis_has_the_true_degree(gens, degree):
    """2^(number of square-root generators) after the reduction equals the degree of the field, computed
    independently as the degree of the minimal polynomial of a primitive element (sympy)."""
    atoms = set()
    for g in gens:
        atoms |= field._generators([g])[0]
    red = reduce_generators(atoms)
    assert 2 ** len(red.basis) == degree
    x = sp.Dummy("x")
    theta = sum((k + 1) * b for k, b in enumerate(red.basis))
    assert sp.degree(sp.minimal_polynomial(theta, x), x) == degree


def test_images_of_generators_are_exact():
    """Each original generator's image g satisfies g² = its radicand exactly in the field, and has the
    right sign (a 40-digit evaluation)."""
    gens = [sp.sqrt(3), sp.sqrt(130), sp.sqrt(390), sp.sqrt(88517), sp.sqrt(265551), NESTED,
            sp.sqrt(-sp.Rational(18421, 1440) + sp.Rational(143, 5760) * sp.sqrt(265551))]
    K = field_of(gens)
    for g in gens:
        img = element(K, g)
        assert img * img == element(K, g.base)
        assert abs(sp.N(K.to_sympy(img) - g, 40)) < sp.Float("1e-35")


def test_glm4s_loads_in_a_small_field_quickly():
    """GLM4S's seven square roots generate a field of degree 16 (not the 2⁷ the generators suggest)."""
    from tableau_lab.exact.tableau_json import load
    m = load(ROOT / "methods" / "glm4_symmetric.json")
    K = m.field()
    assert len(K.mod.to_list()) - 1 == 16


def test_subfield_of_the_stability_polynomial():
    """P(w, z) of GLM4S has coefficients in a quadratic subfield of its degree-16 field: each image,
    evaluated back in K at the subfield's generator, is the coefficient exactly."""
    from tableau_lab.analysis.stability import characteristic_polynomial
    from tableau_lab.exact.tableau_json import load
    P, K = characteristic_polynomial(load(ROOT / "methods" / "glm4_symmetric.json"))
    F, images = subfield(K, list(P.values()))
    assert len(F.mod.to_list()) - 1 == 2
    alpha = element(K, F.ext.as_expr())
    for c, img in zip(P.values(), images, strict=False):
        back = K.zero
        for coeff in img.to_list():
            back = back * alpha + K.convert(coeff)
        assert back == c


def test_subfield_edge_cases():
    K = field_of([sp.sqrt(2), sp.sqrt(3)])
    F, (a,) = subfield(K, [element(K, sp.Rational(7, 3))])
    assert F == sp.QQ and a == sp.Rational(7, 3)
    F, (a, b) = subfield(K, [element(K, sp.sqrt(2)), element(K, sp.sqrt(3))])
    assert F is K
    F, (a,) = subfield(K, [element(K, 1 + sp.sqrt(6))])
    assert F.to_sympy(a ** 2) == sp.expand((1 + sp.sqrt(6)) ** 2)


def test_glm4s_exact_imaginary_interval_matches_float64():
    """The exact Y* (in the subfield, seconds instead of minutes) against the float64 search of the
    design objectives, an independent computation (eigenvalues of the stability matrix on a grid)."""
    from tableau_lab.analysis.stability import stability
    from tableau_lab.exact.tableau_json import load
    from tableau_lab.numeric.objectives import NumericGLM, imaginary_interval
    m = load(ROOT / "methods" / "glm4_symmetric.json")
    Y = stability(m).bounded_radius
    assert abs(float(Y) - imaginary_interval(NumericGLM.of(m))) < 1e-6
    assert f"Y* = 40·ρ = {sp.N(Y, 15)}…" in (ROOT / "docs" / "design.md").read_text()     # the quoted value
