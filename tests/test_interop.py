"""NodePy interop (skipped without NodePy) and the plain-data constructor."""
import pytest
import sympy as sp

from tableau_lab.exact.field import is_zero
from tableau_lab.exact.interop import InexactMethod, from_lists, from_nodepy, to_nodepy
from tableau_lab.exact.methods import MethodError
from tableau_lab.exact.tableau_json import load


def test_from_lists_exact_and_refuses_floats():
    m = from_lists([[0, 0], ["2/3", 0]], ["1/4", sp.Rational(3, 4)], name="Ralston")
    assert m.c[1] == sp.Rational(2, 3)
    with pytest.raises(InexactMethod, match="floating-point"):
        from_lists([[0, 0], [0.5, 0]], [0, 1])
    with pytest.raises(MethodError, match="A must be 2×2"):
        from_lists([[0]], [0, 1])


def test_nodepy_round_trip():
    nodepy = pytest.importorskip("nodepy")
    rk = nodepy.rk
    ours = from_nodepy(rk.loadRKM("RK44"))
    assert ours.A == load("rk4").A and ours.b == load("rk4").b
    gl2 = from_nodepy(rk.loadRKM("GL2"))
    gauss2 = load("gauss2")
    assert all(is_zero(x - y) for x, y in zip(list(gl2.A) + list(gl2.b), list(gauss2.A) + list(gauss2.b), strict=True))
    back = to_nodepy(load("gauss2"))
    assert back.order() == 4
    with pytest.raises(InexactMethod, match="floating-point|not exact"):
        from_nodepy(rk.loadRKM("Tsit5"))
