"""Zero-stability and the A(α) angle of linear multistep methods (and GLMs): published facts
([HW96] Table V.2.3, [HNW93] Thm III.3.4), hand-made methods with known defects, and independent
floating-point checks (numpy roots of ρ(w) − zσ(w), never the exact code's output)."""
from __future__ import annotations

import json
from functools import lru_cache

import numpy as np
import pytest
import sympy as sp

from tableau_lab.analysis.a_alpha import a_alpha
from tableau_lab.analysis.stability_report import stability_report
from tableau_lab.analysis.zero_stability import zero_stability
from tableau_lab.cli import main
from tableau_lab.exact.library import family
from tableau_lab.exact.multistep import lmm, lmm_coefficients
from tableau_lab.exact.tableau_json import load

R = sp.Rational

# E. Hairer, G. Wanner, Solving ODEs II (1996), Table V.2.3: the A(α) angle of BDF k, in degrees
PUBLISHED_ALPHA = {3: 86.03, 4: 73.35, 5: 51.84, 6: 17.84}


@lru_cache(maxsize=None)
def alpha_of(name, k):
    return a_alpha(family(name, k=k))


def max_root_modulus(alpha, beta, z) -> float:
    """max |w| over the roots of ρ(w) − zσ(w), in floating point."""
    a, b = (np.array([complex(sp.N(x, 20)) for x in v]) for v in (alpha, beta))
    c = (a - z * b)[::-1]
    return float(max(abs(np.roots(c))))


# ---------------------------------------------------------------- A(α) against the published table

@pytest.mark.parametrize("k", sorted(PUBLISHED_ALPHA))
def test_bdf_alpha_is_the_published_angle(k):
    res = alpha_of("bdf", k)
    assert res.status == "computed"
    assert round(res.degrees, 2) == PUBLISHED_ALPHA[k]
    lo, hi = (float(v) for v in res.enclosure)          # certified to 30 digits (radians)
    assert 0 <= hi - lo < 1e-30 and lo <= float(res.alpha) <= hi


@pytest.mark.parametrize("k", [1, 2])
def test_bdf1_and_bdf2_are_a_stable(k):
    res = alpha_of("bdf", k)
    assert res.status == "computed" and res.alpha == sp.pi / 2 and res.degrees == 90.0
    assert stability_report(family("bdf", k=k)).linear.a_stable is True


def test_trapezoidal_rule_is_a_stable_with_sigma_root_on_the_circle():
    """Adams–Moulton 1 (the trapezoidal rule): σ(−1) = 0, so z(θ) → ∞ at θ = π; still α = 90°."""
    assert alpha_of("adams_moulton", 1).alpha == sp.pi / 2


@pytest.mark.parametrize("k", [3, 4, 5, 6])
def test_bdf_alpha_against_a_dense_boundary_locus(k):
    """min |arg(−z(θ))| over 4·10⁶ points of the locus z(θ) = ρ(e^{iθ})/σ(e^{iθ}) in floating point."""
    alpha, beta = lmm_coefficients("bdf", k)
    theta = np.linspace(1e-4, np.pi, 4_000_001)
    w = np.exp(1j * theta)
    z = np.polyval([float(a) for a in alpha[::-1]], w) / np.polyval([float(b) for b in beta[::-1]], w)
    sampled = np.degrees(np.abs(np.angle(-z)).min())
    res = alpha_of("bdf", k)
    assert res.degrees == pytest.approx(sampled, abs=1e-6)
    assert res.theta == pytest.approx(np.degrees(theta[np.abs(np.angle(-z)).argmin()]), abs=1e-3)


@pytest.mark.parametrize("k", [3, 5])
def test_bdf_alpha_to_30_digits_against_mpmath(k):
    """The stationary point of |arg(−z(θ))| by mpmath's findroot at 50 digits, from the reported θ."""
    import mpmath
    alpha, beta = lmm_coefficients("bdf", k)
    res = alpha_of("bdf", k)
    with mpmath.workdps(50):
        a, b = ([mpmath.mpf(x.p) / x.q for x in v] for v in (alpha, beta))

        def arg(th):
            w = mpmath.expj(th)
            return abs(mpmath.arg(-mpmath.polyval(a[::-1], w) / mpmath.polyval(b[::-1], w)))
        th = mpmath.findroot(lambda t: mpmath.diff(arg, t), mpmath.radians(res.theta))
        assert abs(mpmath.degrees(arg(th)) - mpmath.mpf(res.degrees_text(35))) < mpmath.mpf(10) ** -27


def test_bdf4_sector_by_the_roots_of_rho_minus_z_sigma():
    """Inside the claimed sector (0.1° in) every root has |w| ≤ 1 for r from 10⁻³ to 10⁴; 0.1° beyond it
    some z has a root outside the unit circle."""
    alpha, beta = lmm_coefficients("bdf", 4)
    a = np.radians(alpha_of("bdf", 4).degrees)
    inside = np.pi - a + np.radians(0.1)
    outside = np.pi - a - np.radians(0.1)
    for r in np.logspace(-3, 4, 57):
        for sgn in (1, -1):
            assert max_root_modulus(alpha, beta, r * np.exp(sgn * 1j * inside)) <= 1 + 1e-12
    worst = max(max_root_modulus(alpha, beta, r * np.exp(1j * outside)) for r in np.linspace(0.5, 5, 200))
    assert worst > 1 + 1e-6


@pytest.mark.parametrize("name, k", [("adams_bashforth", 1), ("adams_bashforth", 2), ("adams_bashforth", 4),
                                     ("adams_moulton", 2), ("adams_moulton", 4), ("nystrom", 2),
                                     ("milne_simpson", 2)])
def test_methods_with_bounded_regions_have_no_sector(name, k):
    """Explicit methods and Adams–Moulton k ≥ 2 have bounded stability regions: α = 0; Nyström and
    Milne–Simpson are unstable on the whole negative real axis near 0."""
    res = alpha_of(name, k)
    assert res.status == "none" and res.alpha == 0
    alpha, beta = lmm_coefficients(name, k)
    assert max(max_root_modulus(alpha, beta, -r) for r in np.logspace(-2, 3, 200)) > 1


def test_not_zero_stable_has_no_alpha_and_higher_degree_is_not_computed():
    assert alpha_of("bdf", 7).status == "none" and alpha_of("bdf", 7).alpha is None
    text = str(stability_report(load("methods/example4_glm.json")))
    assert "A(α): not computed (P has degree 2 in z)" in text


def test_alpha_over_a_number_field_against_the_roots():
    """BDF3's ρ with σ = β₃w³ + (√3/50)w² (coefficients in ℚ(√3), so the locus polynomials are isolated
    through their norm): the certified angle against the roots just inside and outside the sector."""
    alpha, beta = lmm_coefficients("bdf", 3)
    beta = list(beta)
    beta[2] = sp.sqrt(3) / 50
    res = a_alpha(lmm(alpha, beta, name="BDF3 with an irrational σ"))
    assert res.status == "computed" and 80 < res.degrees < 86
    a = np.radians(res.degrees)
    assert all(max_root_modulus(alpha, beta, r * np.exp(1j * (np.pi - a + 1e-3))) <= 1 + 1e-12
               for r in np.logspace(-3, 4, 71))
    assert max(max_root_modulus(alpha, beta, r * np.exp(1j * (np.pi - a - 1e-3)))
               for r in np.linspace(0.01, 3, 300)) > 1


# ---------------------------------------------------------------- zero-stability

@pytest.mark.parametrize("k", range(1, 7))
def test_bdf_1_to_6_are_zero_stable(k):
    res = zero_stability(family("bdf", k=k))
    assert res.holds and not res.outside


@pytest.mark.parametrize("k", [7, 8])
def test_bdf_7_and_8_are_not_zero_stable(k):
    """[HNW93] Thm III.3.4: BDF k is zero-stable exactly for k ≤ 6.  The offending roots of ρ, certified,
    against numpy's roots."""
    res = zero_stability(family("bdf", k=k))
    assert not res.holds
    alpha, _ = lmm_coefficients("bdf", k)
    big = sorted(abs(np.roots([float(a) for a in alpha[::-1]])))
    outside = [m for m in big if m > 1 + 1e-9]
    assert len(res.outside) == len(outside)
    for d, m in zip(res.outside, sorted(outside, reverse=True), strict=False):
        assert float(d.modulus[0]) == pytest.approx(m, rel=1e-12)
        assert d.modulus[1] - d.modulus[0] < 1e-30
    if k == 7:
        assert f"{float(res.outside[0].modulus[0]):.4f}" == "1.0222"
        assert "outside the unit circle" in res.reason and "1.0222" in res.reason


@pytest.mark.parametrize("name", ["adams_bashforth", "adams_moulton"])
@pytest.mark.parametrize("k", range(1, 7))
def test_adams_methods_are_zero_stable(name, k):
    res = zero_stability(family(name, k=k))
    assert res.holds
    assert [f.circle_roots for f in res.factors if f.on] == [(1,)]        # ρ = w^(k−1)(w − 1)


def test_milne_simpson_2_has_the_simple_root_minus_one_on_the_circle():
    res = zero_stability(family("milne_simpson", k=2))
    assert res.holds
    circle = {z: f for f in res.factors for z in f.circle_roots}
    assert set(circle) == {1, -1} and all(f.multiplicity == 1 for f in circle.values())


def test_double_root_of_rho_at_one_is_not_zero_stable():
    """ρ(ζ) = (ζ − 1)², σ(ζ) = ζ²: V = [[2, −1], [1, 0]] is a Jordan block at 1."""
    res = zero_stability(lmm([1, -2, 1], [0, 0, 1], name="double root at 1"))
    assert not res.holds and not res.outside
    (f,) = [f for f in res.factors if f.on]
    assert f.multiplicity == 2 and f.kernel == 1 and not f.semisimple
    assert "not semisimple" in res.reason


def test_double_root_at_minus_one_not_zero_stable_and_the_report_still_prints():
    """ρ(ζ) = (ζ − 1)(ζ + 1)²: the parasitic growth parameters need simple roots; the report says why
    the method fails instead of stopping."""
    m = lmm([-1, -1, 1, 1], [0, 0, 0, 1], name="double root at -1")
    rep = stability_report(m)
    assert rep.zero.holds is False and rep.sector.status == "none" and rep.parasitism is None
    assert json.loads(json.dumps(rep.to_json()))["zero_stable"] is False


def test_semisimple_double_eigenvalue_on_the_circle_is_zero_stable():
    """V = I (two copies of Euler's method as a GLM): the double eigenvalue 1 is semisimple."""
    from tableau_lab.exact.methods import GeneralLinearMethod
    m = GeneralLinearMethod(A=sp.Matrix([[0]]), U=sp.Matrix([[1, 0]]), B=sp.Matrix([[1], [0]]), V=sp.eye(2),
                            c=sp.Matrix([0]), name="V = I")
    res = zero_stability(m)
    assert res.holds and [(f.multiplicity, f.kernel) for f in res.factors] == [(2, 2)]


def test_irrational_root_outside_is_certified():
    """ρ(ζ) = (ζ − 1)(ζ − √2): over ℚ(√2), the root √2 certified outside."""
    rho = sp.Poly(sp.expand((sp.Symbol("w") - 1) * (sp.Symbol("w") - sp.sqrt(2))), sp.Symbol("w")).all_coeffs()[::-1]
    res = zero_stability(lmm(rho, [0, 0, 1], name="root sqrt(2)"))
    assert not res.holds and len(res.outside) == 1
    import mpmath
    lo, hi = res.outside[0].modulus
    with mpmath.workdps(60):
        assert lo <= mpmath.sqrt(2) <= hi and hi - lo < 1e-30


def test_one_step_methods_are_trivially_zero_stable():
    for name in ("rk4", "gauss2", "implicit_euler"):
        res = zero_stability(load(f"methods/{name}.json"))
        assert res.holds and res.r == 1 and "one-step" in res.reason
    assert zero_stability(load("methods/stormer_verlet.json")).holds


# ---------------------------------------------------------------- the command line

def test_cli_text_and_json(capsys):
    assert main(["stability", "bdf:4", "bdf:7"]) == 0
    out = capsys.readouterr().out
    assert "A(α): α = 73.35°" in out and "zero-stable: yes" in out
    assert "zero-stable: no — 2 eigenvalues of V outside the unit circle" in out and "1.0222" in out
    assert main(["stability", "--json", "bdf:5", "bdf:7", "methods/rk4.json"]) == 0
    b5, b7, rk4 = (json.loads(line) for line in capsys.readouterr().out.splitlines())
    assert b5["zero_stable"] is True and round(b5["a_alpha"]["alpha_degrees"], 2) == 51.84
    assert b5["a_alpha"]["alpha_degrees_digits"].startswith("51.8397558360499")
    assert b7["zero_stable"] is False and b7["a_alpha"]["status"] == "none"
    assert b7["zero_stability"]["factors"][0]["outside"] == 2
    assert rk4["zero_stable"] is None and rk4["a_alpha"] is None       # GLMs only in the report


def test_latex():
    tex = stability_report(family("bdf", k=6)).to_latex()
    assert r"$A(\alpha)$-stable with $\alpha = 17.84^\circ$" in tex and "zero-stable" in tex
