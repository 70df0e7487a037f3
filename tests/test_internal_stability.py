"""Internal stability functions against a direct evaluation: Qⱼ(x) = x bᵀ(I − xA)⁻¹eⱼ solved with
numpy on a fine grid of the real interval never exceeds the exact maximum, and comes within 1e-6
of it."""
import numpy as np
import pytest
import sympy as sp

from tableau_lab.analysis.internal_stability import internal_stability
from tableau_lab.exact.tableau_json import load


@pytest.mark.parametrize("name", ["rk4", "rule_3_8", "explicit_euler", "dormand_prince54", "butcher_effective5"])
def test_amplification_against_direct_solves(name):
    m = load(name)
    r = internal_stability(m)
    A = np.array(m.A.evalf(30).tolist(), dtype=float)
    b = np.array([float(x) for x in m.b])
    beta, best = float(r.interval), float(r.amplification)
    worst = 0.0
    for x in np.linspace(-beta, 0, 20001):
        q = x * np.linalg.solve((np.eye(m.s) - x * A).T, b)       # (x bᵀ(I − xA)⁻¹)ᵀ
        worst = max(worst, np.abs(q).max())
    assert worst <= best * (1 + 1e-12) and worst >= best * (1 - 1e-6)
    z = sp.Symbol("z")
    x0 = -beta / 3
    direct = x0 * np.linalg.solve((np.eye(m.s) - x0 * A).T, b)
    assert np.allclose([float(q.subs(z, x0)) for q in r.functions], direct, rtol=1e-12, atol=1e-14)


def test_unbounded_interval_says_so():
    assert "unbounded" in str(internal_stability(load("gauss2")))
