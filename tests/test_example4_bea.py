"""Example 4 (μ ≠ 0) on the pendulum at q0 = 2.3, h = 1/100: before the parasitic onset the
principal component follows the underlying one-step method Φ (its modified energy H̃ is kept
≥ 100× better than H, and z_n stays on Φⁿ(y₀)); then the parasitic component grows by orders of
magnitude, as μ predicts, and the energy bound breaks.  GLM43 (μ = 0) stays bounded.  Short
versions of the runs of benchmarks/example4_smooth_part.py (docs/example4_bea.md), whose
functions are used here."""
from pathlib import Path

import pytest
from conftest import benchmark_script

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def bench():
    return benchmark_script("example4_smooth_part")


def _case(bench, key):
    return next(c for c in bench.CASES if c["key"] == key)


def test_example4_smooth_part_then_parasitic_blowup(bench):
    r = bench.run_case(_case(bench, "ex4_q23"), steps=5000)        # T = 50: the blow-up is near t = 41
    n = r["numbers"]
    assert n["mu"] == ["1 + 2*sqrt(3)/3"] and n["H_tilde_powers"] == [4, 6]
    # before the onset (parasitic component < 1e-12): H̃ ≥ 100× better than H, z_n on Φⁿ(y₀)
    assert n["onset_t"] is not None and n["onset_t"] >= 10, n["onset_t"]
    assert n["pre_onset_max_H_error"] > 1e-12
    assert n["pre_onset_max_Htilde_error"] * 100 <= n["pre_onset_max_H_error"], n
    assert n["pre_onset_max_dist_phi"] * 1000 <= n["pre_onset_max_dist_E"], n
    # then the parasitic component grows by many orders of magnitude, as μ predicts, and H is lost
    assert n["max_parasitic"] >= 1e-2 and n["max_parasitic"] >= 1e8 * n["parasitic_at_t1"], n
    assert n["growth"] is not None and n["growth"]["agree"], n["growth"]
    assert n["max_abs_H_error"] >= 1e4 * n["pre_onset_max_H_error"], n
    assert n["max_abs_Htilde_error"] >= 1e4 * n["pre_onset_max_Htilde_error"], n
    assert n["max_dist_phi"] >= 1e6 * n["pre_onset_max_dist_phi"], n


def test_glm43_stays_bounded_on_the_same_orbit(bench):
    r = bench.run_case(_case(bench, "glm43_q23"), steps=3000, series=False)
    n = r["numbers"]
    assert n["onset_t"] is None and n["max_parasitic"] < 1e-14, n
    assert n["max_abs_H_error"] < 1e-9 and n["pre_onset_ratio"] >= 100, n
