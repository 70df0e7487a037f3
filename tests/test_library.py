"""The method library: every file reads, round-trips, cites a source, and its claims hold;
verdicts are checked against independent facts (quadrature conditions, the symplecticity
matrix recomputed with plain sympy, hand-derived G for the leapfrog)."""
from pathlib import Path

import pytest
import sympy as sp

from tableau_lab.analysis.symplectic import g_symplectic, rk_symplectic
from tableau_lab.analysis.verify import verify
from tableau_lab.exact.tableau_json import dumps, load, loads

FILES = sorted((Path(__file__).parent.parent / "methods").glob("*.json"))
RK = {p.stem: load(p) for p in FILES if load(p).kind == "rk"}

SYMPLECTIC_RK = {"implicit_midpoint", "gauss2", "gauss3"}          # [HLW06] Thm VI.4.3 / VI.4.2
# order of each RK method in the literature: its quadrature conditions b·c^(k-1) = 1/k hold for k <= p
QUADRATURE_ORDER = {"explicit_euler": 1, "implicit_euler": 1, "implicit_midpoint": 2, "rk4": 4, "rule_3_8": 4,
                    "gauss2": 4, "gauss3": 6, "lobatto_iiia3": 4, "lobatto_iiib3": 4, "lobatto_iiic3": 4,
                    "radau_iia3": 5}


def _z(x):
    return sp.radsimp(sp.expand(x)) == 0


def test_library_complete():
    names = {p.stem for p in FILES}
    assert {"explicit_euler", "implicit_euler", "symplectic_euler", "stormer_verlet", "implicit_midpoint", "rk4",
            "rule_3_8", "gauss2", "gauss3", "lobatto_iiia3", "lobatto_iiib3", "lobatto_iiic3", "radau_iia3",
            "adams_bashforth2", "leapfrog", "example4_glm", "glm43_printed"} <= names


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_file_reads_round_trips_and_claims_hold(path):
    m = load(path)
    assert loads(dumps(m)) == m
    assert m.source and m.claims
    v = verify(m)
    assert v.ok, f"{path.name}: failed claims {v.failed}"


@pytest.mark.parametrize("name", sorted(QUADRATURE_ORDER))
def test_quadrature_conditions(name):
    """Independent facts of the published order: b·c^(k-1) = 1/k for k <= p, and c = A·1."""
    m = RK[name]
    for k in range(1, QUADRATURE_ORDER[name] + 1):
        assert _z(sum(bi * ci ** (k - 1) for bi, ci in zip(m.b, m.c, strict=False)) - sp.Rational(1, k)), (name, k)


@pytest.mark.parametrize("name", sorted(RK))
def test_rk_symplectic_against_plain_sympy_and_glm_solver(name):
    m = RK[name]
    Bd = sp.diag(*m.b)
    M = Bd * m.A + m.A.T * Bd - m.b * m.b.T
    plain_zero = all(_z(x) for x in M)
    assert plain_zero == (name in SYMPLECTIC_RK)
    r, g = rk_symplectic(m), g_symplectic(m)
    assert r.holds == plain_zero == g.holds       # an RK method seen as a GLM: the solvers agree
    if g.holds:                                   # G = [1], D = diag(b)
        assert g.G == sp.Matrix([[1]]) and all(_z(g.D[i, i] - m.b[i]) for i in range(m.s))


def test_leapfrog_and_adams_bashforth():
    lf = g_symplectic(load(FILES[0].parent / "leapfrog.json"))
    assert lf.holds and lf.G == sp.Matrix([[0, 1], [1, 0]]) and lf.definite is False
    ab = g_symplectic(load(FILES[0].parent / "adams_bashforth2.json"))
    assert not ab.holds


def test_partitioned_library_methods_symplectic():
    for name in ("symplectic_euler", "stormer_verlet"):
        assert rk_symplectic(load(FILES[0].parent / f"{name}.json")).holds


def test_glm43_as_printed_is_not_g_symplectic():
    res = g_symplectic(load(FILES[0].parent / "glm43_printed.json"))
    assert not res.holds and res.dimension == 0 and res.rank == res.unknowns == 10
