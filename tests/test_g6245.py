"""G6245 (issue 29, item 7): the published sixth-order G-symplectic GLM of Butcher, Imran and
Podhaisky (BIT 57 (2017) 313-328; Butcher, B-Series, Springer 2021, Sec. 7.6-7.7: p q r s = 6 2 4 5,
the case t = 1/3, real form), tests/data/g6245.json.

Facts from the publication: order 6 with the identity as first starting component, stage order 2
(C(2)), G-symplectic with G = diag(1, -1, -1, 1) and D = diag(b).  Its entries are nested square
roots over Q(√330); with √5 the field Q(√5, √330, √β₁², √γ₁²) has degree at most 16.  Splitting a
nested root √(c·P) into √c·√P (2a84a79) added the square classes of the two rational factors c as
generators of their own: a field of degree bound 64, 418 s of CPU for `order`, over the default
300 s budget.  Now the analysis runs under a budget far below the default.
"""
from pathlib import Path

import sympy as sp

from tableau_lab.analysis.glm_order import glm_order
from tableau_lab.budget import time_limit
from tableau_lab.exact.radicals import reduce_generators
from tableau_lab.exact.tableau_json import entries, load, read

G6245 = Path(__file__).parent / "data" / "g6245.json"


def _matrices():
    d = read(G6245)
    return {k: entries(d[k], "g6245.json", k) for k in ("A", "U", "B", "V")}


def test_published_g_symplecticity_numerically():
    """The transcription: VᵀGV = G, DU = BᵀGV, DA + AᵀD = BᵀGB with the book's G and D = diag(b),
    evaluated to 50 digits (no code of ours)."""
    M = _matrices()
    A, U, B, V = (sp.Matrix(M[k]) for k in "AUBV")
    G, D = sp.diag(1, -1, -1, 1), sp.diag(*B.row(0))
    for X in (V.T * G * V - G, D * U - B.T * G * V, D * A + A.T * D - B.T * G * B):
        assert max(abs(sp.N(x, 50)) for x in X) < sp.Float("1e-40")


def test_field_degree_bound_is_16():
    """Four generators (√5, √330 and the two nested roots), not six: degree bound 2⁴."""
    M = _matrices()
    roots = {p for X in M.values() for x in X for p in x.atoms(sp.Pow) if p.exp == sp.S.Half}
    assert len(roots) == 4
    red = reduce_generators(tuple(sorted(roots, key=sp.default_sort_key)))
    assert all(g.is_Pow and g.exp == sp.S.Half for g in red.basis)
    assert 2 ** len(red.basis) == 16


def test_order_6_stage_order_2_within_budget():
    with time_limit(60):            # was 418 s of CPU; ~2 s now
        res = glm_order(load(G6245))
    assert (res.order, res.order_identity_start, res.stage_order) == (6, 6, 2)
    assert res.errors                # exactly 6: an order-7 condition fails
