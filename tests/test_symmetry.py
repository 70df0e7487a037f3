"""Symmetry against independent facts: Gauss and Lobatto IIIA are symmetric, RK4 and Radau IIA
are not ([HLW06] V.2); and, for the GLMs found symmetric, the defining property checked by
running the method: M_{−h}(L M_h(L y)) = y for one step on a nonlinear problem, in mpmath."""
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp

from tableau_lab.analysis.symmetry import symmetric
from tableau_lab.exact.tableau_json import load
from tableau_lab.numeric.export import to_numeric
from tableau_lab.numeric.integrate import step

METHODS = Path(__file__).parent.parent / "methods"


@pytest.mark.parametrize("name, holds", [("gauss2", True), ("gauss3", True), ("lobatto_iiia3", True),
                                         ("implicit_midpoint", True), ("rk4", False), ("radau_iia3", False),
                                         ("explicit_euler", False), ("example4_glm", True)])
def test_symmetric_verdicts(name, holds):
    assert symmetric(load(METHODS / f"{name}.json")).holds is holds


class _Pendulum:
    """y = (q, p), f = (p, −sin q), evaluated in mpmath."""

    def f(self, y):
        return np.array([y[1], -mpmath.sin(y[0])], dtype=object)

    def jac(self, y):
        return np.array([[mpmath.mpf(0), mpmath.mpf(1)], [-mpmath.cos(y[0]), mpmath.mpf(0)]], dtype=object)


@pytest.mark.parametrize("name", ["example4_glm", "gauss2"])
def test_symmetric_step_is_reversible(name):
    m = load(METHODS / f"{name}.json")
    res = symmetric(m)
    nm = to_numeric(m, "mp:40", starting=False)
    a = nm.arith
    with a.context():
        ones, zeros = np.array([mpmath.mpf(1)] * 2, dtype=object), np.array([mpmath.mpf(0)] * 2, dtype=object)
        h = mpmath.mpf("0.3")
        Y0 = np.array([[mpmath.mpf(k + 1) / 7 + mpmath.mpf(i) / 3 for i in range(2)] for k in range(nm.r)],
                      dtype=object)
        L = np.array(sp.Matrix(res.L).tolist(), dtype=object) if res.L is not None else np.eye(1, dtype=object)
        masks = (ones, zeros)
        Y1 = step(nm, _Pendulum(), L @ Y0, h, masks=masks)
        Y2 = step(nm, _Pendulum(), L @ Y1, -h, masks=masks)
        assert max(abs(x) for x in (Y2 - Y0).reshape(-1)) < mpmath.mpf(10) ** -35
        # and a method that is not symmetric does not come back
        rk4 = to_numeric(load(METHODS / "rk4.json"), "mp:40")
        Z1 = step(rk4, _Pendulum(), Y0[:1], h, masks=masks)
        Z2 = step(rk4, _Pendulum(), Z1, -h, masks=masks)
        assert max(abs(x) for x in (Z2 - Y0[:1]).reshape(-1)) > mpmath.mpf(10) ** -10
