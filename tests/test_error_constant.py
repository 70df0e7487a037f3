"""The classical error constant C_{p+1} of linear multistep methods against the published values:
with αₖ = 1 the BDF constants of J. D. Lambert, Numerical Methods for Ordinary Differential
Systems (Wiley 1991; C_{p+1} defined in §3.5): −1/2, −2/9, −3/22, −12/125, −10/137, −20/343, and
the Adams constants of [HNW93] Hairer, Nørsett & Wanner, Solving ODEs I, §III.1 (the tables of γⱼ
and γⱼ*: AB k has γₖ, AM k has γ*ₖ₊₁); C_{p+1}/σ(1) against the closed form −1/(k + 1) of BDF k;
and the C_q checked independently by the local error on y = eˣ in 60-digit arithmetic."""
import re

import mpmath
import pytest
import sympy as sp
from printed import latex_to_grammar

from tableau_lab.analysis.error_constant import error_constant, lmm_constants
from tableau_lab.exact.grammar import parse_entry
from tableau_lab.exact.library import family
from tableau_lab.exact.methods import GeneralLinearMethod, MethodError
from tableau_lab.exact.multistep import as_lmm, lmm, lmm_coefficients
from tableau_lab.exact.tableau_json import load

R = sp.Rational

# (family, k) -> (order, C_{p+1} with αₖ = 1)
PUBLISHED = {
    **{("bdf", k): (k, c) for k, c in enumerate([R(-1, 2), R(-2, 9), R(-3, 22), R(-12, 125), R(-10, 137),
                                                  R(-20, 343)], 1)},
    # explicit Adams: γₖ = 1/2, 5/12, 3/8, 251/720, 95/288
    **{("adams_bashforth", k): (k, c) for k, c in enumerate([R(1, 2), R(5, 12), R(3, 8), R(251, 720),
                                                              R(95, 288)], 1)},
    # implicit Adams: γ*ₖ₊₁ = −1/12, −1/24, −19/720, −3/160
    **{("adams_moulton", k): (k + 1, c) for k, c in enumerate([R(-1, 12), R(-1, 24), R(-19, 720), R(-3, 160)], 1)},
    ("nystrom", 2): (2, R(1, 3)),                # the explicit midpoint rule (Lambert 1991 §3.10)
    ("milne_simpson", 2): (4, R(-1, 90)),        # Simpson's rule (Lambert 1991 §3.10)
}


@pytest.mark.parametrize("key", sorted(PUBLISHED))
def test_published_error_constants(key):
    p, c = PUBLISHED[key]
    e = error_constant(family(key[0], k=key[1]))
    assert (e.order, e.C) == (p, c)
    assert e.normalised == c / sum(lmm_coefficients(*key)[1])
    assert float(e) == float(c)


@pytest.mark.parametrize("k", range(1, 7))
def test_bdf_normalised_constant_is_minus_one_over_k_plus_one(k):
    """BDF k: C_{k+1}/σ(1) = −1/(k + 1).  In backward differences BDF k is Σⱼ₌₁ᵏ ∇ʲy_{n+1}/j =
    h f_{n+1} ([HNW93] III.1 (1.22'), σ(1) = 1 there) and h y′ = Σⱼ≥₁ ∇ʲy/j exactly (−log(1 − ∇)),
    so L(y) = −Σ_{j>k} ∇ʲy/j = −h^{k+1} y^{(k+1)}/(k + 1) + O(h^{k+2})."""
    assert error_constant(family("bdf", k=k)).normalised == R(-1, k + 1)


@pytest.mark.parametrize("spec", ["bdf:3", "adams_bashforth:4", "adams_moulton:3", "milne_simpson:2"])
def test_local_error_on_the_exponential(spec):
    """Independently of the C_q formula: L(e^x, 0, h) = Σ αⱼ e^{jh} − h Σ βⱼ e^{jh} behaves like
    C_{p+1} h^{p+1} (y^{(p+1)} = e^x = 1 at x = 0): the ratio at h = 10⁻⁸, 50 digits."""
    e = error_constant(family(spec))
    with mpmath.workdps(60):
        h = mpmath.mpf(10) ** -8
        L = sum(mpmath.mpf(a.p) / a.q * mpmath.exp(j * h) for j, a in enumerate(e.alpha)) \
            - h * sum(mpmath.mpf(b.p) / b.q * mpmath.exp(j * h) for j, b in enumerate(e.beta))
        ratio = L / h ** (e.order + 1)
        assert abs(ratio - mpmath.mpf(e.C.p) / e.C.q) < 1e-6


def test_scaling_and_the_two_normalisations():
    """C_{p+1} depends on the scaling of (α, β), C_{p+1}/σ(1) does not: the trapezoidal rule written
    with α₁ = 2 is normalised by lmm to α₁ = 1 and gives −1/12 both ways."""
    tr = lmm([-2, 2], [1, 1], name="trapezoidal rule, scaled")
    e = error_constant(tr)
    assert (e.order, e.C, e.normalised) == (2, R(-1, 12), R(-1, 12))
    assert lmm_constants([-2, 2], [1, 1], 3) == [0, 0, 0, R(-1, 6)]          # the unnormalised C₃ doubles


def test_as_lmm_inverts_lmm():
    for name, k in [("bdf", 4), ("adams_bashforth", 3), ("adams_moulton", 1), ("nystrom", 3)]:
        alpha, beta = lmm_coefficients(name, k)
        got = as_lmm(family(name, k=k))
        kk = len(got[0]) - 1                       # leading zero αⱼ, βⱼ are dropped from the GLM
        assert got == (alpha[len(alpha) - 1 - kk:], beta[len(beta) - 1 - kk:])


def test_other_glm_forms_of_a_multistep_method():
    """The shipped adams_bashforth2 and leapfrog files write AB2 and the explicit midpoint rule as
    GLMs of another shape (the stage is the first input value): their constants are the published
    5/12 and 1/3.  BDF3 with its input values reordered (a similarity T V T⁻¹ fixing the first) is
    still BDF3; a one-stage Runge–Kutta method (implicit midpoint) is not a multistep method."""
    assert (error_constant(load("adams_bashforth2")).C, error_constant(load("leapfrog")).C) == (R(5, 12), R(1, 3))
    g = family("bdf:3")
    T = sp.Matrix([[1, 0, 0], [0, 0, 1], [0, 1, 0]])
    h = GeneralLinearMethod(A=g.A, U=g.U * T.inv(), B=T * g.B, V=T * g.V * T.inv(), c=g.c, name="BDF3 reordered")
    assert h.matrices() != g.matrices() and as_lmm(h) == as_lmm(g) == tuple(lmm_coefficients("bdf", 3))
    assert error_constant(h).C == R(-3, 22)
    midpoint = load("implicit_midpoint").as_glm()
    assert as_lmm(midpoint) is None
    with pytest.raises(MethodError, match="linear multistep"):
        error_constant(midpoint)


def test_printed_value_reads_back():
    """The printed C is the exact value (text, LaTeX and JSON re-parse to it)."""
    e = error_constant(family("adams_bashforth:4"))
    assert "C₅ = 251/720" in str(e) and "α₄ = 1" in str(e)
    assert parse_entry(e.to_json()["error_constant"]) == R(251, 720)
    assert parse_entry(e.to_json()["error_constant_over_sigma1"]) == R(251, 720)
    b = error_constant(family("bdf:4"))
    tex = re.search(r"C_\{5\} = (.*?)\$", b.to_latex()).group(1)
    norm = re.search(r"C_\{5\}/\\sigma\(1\) = (.*?)\$", b.to_latex()).group(1)
    assert parse_entry(latex_to_grammar(tex)) == R(-12, 125) and parse_entry(latex_to_grammar(norm)) == R(-1, 5)
    text = re.search(r"C₅ = (\S+) .*C₅/σ\(1\) = ([^,]+),", str(b))
    assert [parse_entry(x) for x in text.groups()] == [R(-12, 125), R(-1, 5)]


def test_not_a_multistep_method_is_refused():
    with pytest.raises(MethodError, match="error_coefficients"):
        error_constant(load("rk4"))
    with pytest.raises(MethodError, match="linear multistep"):
        error_constant(load("example4_glm"))
    with pytest.raises(MethodError, match="not consistent"):
        error_constant(lmm([-1, 1], [0, 2], name="inconsistent"))


def test_verify_shows_the_error_constant_of_a_multistep_method():
    from tableau_lab.analysis.verify import verify
    v = verify(family("bdf:3"))
    assert "as a linear multistep method: order 3, error constant C₄ = -3/22" in str(v)
    assert v.to_json()["lmm"]["error_constant"] == "-3/22"
    assert verify(load("rk4")).lmm is None and verify(load("example4_glm")).to_json()["lmm"] is None
