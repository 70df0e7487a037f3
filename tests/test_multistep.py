"""Linear multistep families as GLMs: coefficients against the published tables, orders pinned
by the LMM's own order conditions and by the GLM theory, BDF stability on the imaginary axis
checked against the roots of ρ(w) − iy σ(w), and the families by name."""
import numpy as np
import pytest
import sympy as sp

from tableau_lab.analysis.glm_order import glm_order
from tableau_lab.analysis.stability import stability
from tableau_lab.analysis.verify import verify
from tableau_lab.exact.library import FamilyError, family
from tableau_lab.exact.multistep import lmm_coefficients
from tableau_lab.exact.tableau_json import TableauError, load

R = sp.Rational

# E. Hairer, S. P. Nørsett, G. Wanner, Solving ODEs I (1993), §III.1, eqs. (1.5), (1.9), (1.22'):
# (α₀ … α_k, β₀ … β_k)
PUBLISHED = {
    ("adams_bashforth", 2): ([0, -1, 1], [R(-1, 2), R(3, 2), 0]),
    ("adams_bashforth", 3): ([0, 0, -1, 1], [R(5, 12), R(-16, 12), R(23, 12), 0]),
    ("adams_bashforth", 4): ([0, 0, 0, -1, 1], [R(-9, 24), R(37, 24), R(-59, 24), R(55, 24), 0]),
    ("adams_moulton", 1): ([-1, 1], [R(1, 2), R(1, 2)]),
    ("adams_moulton", 2): ([0, -1, 1], [R(-1, 12), R(8, 12), R(5, 12)]),
    ("adams_moulton", 3): ([0, 0, -1, 1], [R(1, 24), R(-5, 24), R(19, 24), R(9, 24)]),
    ("bdf", 2): ([R(1, 3), R(-4, 3), 1], [0, 0, R(2, 3)]),
    ("bdf", 3): ([R(-2, 11), R(9, 11), R(-18, 11), 1], [0, 0, 0, R(6, 11)]),
    ("bdf", 4): ([R(3, 25), R(-16, 25), R(36, 25), R(-48, 25), 1], [0] * 4 + [R(12, 25)]),
    ("bdf", 5): ([R(-12, 137), R(75, 137), R(-200, 137), R(300, 137), R(-300, 137), 1], [0] * 5 + [R(60, 137)]),
    ("bdf", 6): ([R(10, 147), R(-72, 147), R(225, 147), R(-400, 147), R(450, 147), R(-360, 147), 1],
                 [0] * 6 + [R(60, 147)]),
    ("nystrom", 2): ([-1, 0, 1], [0, 2, 0]),                        # the explicit midpoint rule
    ("milne_simpson", 2): ([-1, 0, 1], [R(1, 3), R(4, 3), R(1, 3)]),  # Simpson's rule
}


@pytest.mark.parametrize("key", sorted(PUBLISHED))
def test_coefficients_are_the_published_ones(key):
    assert lmm_coefficients(*key) == tuple(PUBLISHED[key])


def _lmm_order(alpha, beta) -> int:
    """The LMM's order from its own conditions Σ αⱼ j^q = q Σ βⱼ j^(q−1) ([HNW93] Thm III.2.4),
    independent of the GLM analysis."""
    def holds(q):
        lhs = sum(a * sp.Integer(j) ** q for j, a in enumerate(alpha))
        return lhs == (q * sum(b * sp.Integer(j) ** (q - 1) for j, b in enumerate(beta)) if q else 0)
    assert holds(0)
    p = 0
    while holds(p + 1):
        p += 1
    return p


ORDERS = [("adams_bashforth", k, k) for k in range(1, 7)] + [("adams_moulton", k, k + 1) for k in range(1, 7)] \
    + [("bdf", k, k) for k in range(1, 8)] + [("nystrom", k, k) for k in range(2, 5)] \
    + [("milne_simpson", 2, 4), ("milne_simpson", 3, 4), ("milne_simpson", 4, 5)]


@pytest.mark.parametrize("name, k, p", ORDERS)
def test_orders_pinned(name, k, p):
    """The published order, the LMM's own conditions (hold up to p, fail at p + 1) and the GLM
    order with a suitable starting method agree."""
    alpha, beta = lmm_coefficients(name, k)
    assert _lmm_order(alpha, beta) == p
    assert glm_order(family(name, k=k)).order == p


def _max_root_modulus(name, k, y):
    alpha, beta = (np.array([float(x) for x in v]) for v in lmm_coefficients(name, k))
    return max(abs(np.roots((alpha - 1j * y * beta)[::-1])))


@pytest.mark.parametrize("k", [2, 3, 4, 5, 6])
def test_bdf_on_the_imaginary_axis(k):
    """BDF2 is A-stable; BDF3 and BDF4 are unstable for small iy (their root locus enters the
    left half-plane near 0), BDF5 and BDF6 stable on a segment whose exact end the analysis
    gives: the roots of ρ(w) − iy σ(w) confirm it on either side."""
    res = stability(family("bdf", k=k))
    if k == 2:
        assert res.a_stable is True
        return
    assert res.a_stable is False
    y = float(res.imaginary_interval)
    if k in (3, 4):
        assert y == 0 and _max_root_modulus("bdf", k, 0.1) > 1 + 1e-9
    else:
        assert y > 0.5
        assert _max_root_modulus("bdf", k, 0.98 * y) <= 1 + 1e-12 and _max_root_modulus("bdf", k, 1.02 * y) > 1


@pytest.mark.parametrize("spec", ["bdf:5", "bdf:6", "bdf:7", "adams_moulton:6"])
def test_verify_of_large_multistep_glms(spec):
    """verify and stability of 6- and 7-value GLMs (once a CRootOf crash and minutes): V's
    eigenvalues on the unit circle are found by factoring its characteristic polynomial."""
    m = load(spec)
    v = verify(m)
    assert v.ok
    assert "parasitism: none" in str(v)
    stability(m)


def test_families_by_name():
    assert load("bdf:5") == load("bdf", k=5) == family("bdf", k=5)
    assert load("gauss2") == load("methods/gauss2.json")             # a shipped file by name
    assert load("gauss:2").A == load("methods/gauss2.json").A
    for bad, fragment in [("bdf:0", "1 … 30"), ("gauss:9", "1 … 8"), ("nystrom:1", "at least 2"),
                          ("bdf", "missing"), ("bdf:x", "not x")]:
        with pytest.raises(TableauError, match=None) as info:
            load(bad)
        assert fragment in str(info.value) and info.value.source == bad
    with pytest.raises(FamilyError, match="k="):
        family("bdf", s=3)
