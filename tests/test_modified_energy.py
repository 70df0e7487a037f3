"""The modified energy H̃ (two correction terms) along float64 runs: conserved ≥ 100× better
than H (tableau_lab.experiments.modified_energy; the full table: benchmarks/modified_energy.py).
Störmer–Verlet is a partitioned RK method: its H̃ comes from a P-series over bicoloured trees."""
import pytest
import sympy as sp

from tableau_lab.exact.tableau_json import load
from tableau_lab.experiments.modified_energy import modified_energy_run, modified_energy_terms


@pytest.mark.parametrize("name, powers", [("implicit_midpoint", [2, 4]), ("gauss2", [4, 6]),
                                          ("stormer_verlet", [2, 4]), ("symplectic_euler", [1, 2])])
def test_modified_energy_conserved_far_better_than_H(name, powers):
    r = modified_energy_run(load(f"methods/{name}.json"), "pendulum", {}, sp.Rational(1, 100), 10000)
    assert r.powers == powers and r.evaluated_at == "y_n"
    assert len(r.times) == len(r.err_H) == len(r.err_Ht) == 1001
    assert r.max_H > 1e-12 and r.ratio >= 100, (r.max_H, r.max_Ht)


def test_midpoint_pendulum_modified_hamiltonian():
    """HLW IX.3: implicit midpoint, H̃ = H − h²/24 (p² cos q + sin² q) + O(h⁴)."""
    q, p, h = sp.symbols("q p h")
    H = p**2 / 2 - sp.cos(q)
    terms = modified_energy_terms(load("methods/implicit_midpoint.json"), H, (q,), (p,), 2)
    assert [k for k, _ in terms] == [2, 4]
    Ht = H + sum(h**k * e for k, e in terms)
    rest = sp.expand(Ht - (H - h**2 / 24 * (p**2 * sp.cos(q) + sp.sin(q)**2)))
    assert rest != 0 and sp.Poly(rest, h).monoms() == [(4,)]        # the remainder is the h⁴ term


def test_stormer_verlet_pendulum_modified_hamiltonian():
    """Störmer–Verlet (velocity form) on H = p²/2 + U(q): H̃ = H + h² (U″(q)(p, p)/12 − |∇U|²/24) + O(h⁴)
    (the BCH term 1/12 {T,{T,U}} − 1/24 {U,{U,T}}), with U = −cos q."""
    q, p = sp.symbols("q p")
    terms = modified_energy_terms(load("methods/stormer_verlet.json"), p**2 / 2 - sp.cos(q), (q,), (p,), 2)
    assert [k for k, _ in terms] == [2, 4]
    assert sp.simplify(terms[0][1] - (p**2 * sp.cos(q) / 12 - sp.sin(q)**2 / 24)) == 0


def test_symplectic_euler_has_an_h1_term():
    """HLW IX.3: symplectic Euler, H̃ = H − h/2 H_p H_q + h²/12 (H_pp H_q² + H_qq H_p²) + O(h³): the h¹
    term sits on the bicoloured free tree with 2 vertices (superfluous, hence absent, for RK methods)."""
    q, p = sp.symbols("q p")
    terms = modified_energy_terms(load("methods/symplectic_euler.json"), p**2 / 2 - sp.cos(q), (q,), (p,), 2)
    assert [k for k, _ in terms] == [1, 2]
    assert sp.simplify(terms[0][1] + p * sp.sin(q) / 2) == 0
    assert sp.simplify(terms[1][1] - (sp.sin(q)**2 + sp.cos(q) * p**2) / 12) == 0
