"""Issue 29, item 9: what `design` says about its optima — box-bound optima flagged, each certified
member printed once, the rational snap of smallest height within the objective tolerance, with its
height — and item 11: bad --constrain/--require values and an unreachable scheduler refused (exit 2).
Checked against independent facts: μ = u on the P/N family (so min |μ| on a box sits on its face),
the exact error terms of a family that do not depend on its parameter, brute-force enumeration of
the rationals of smaller height."""
from fractions import Fraction
from math import ceil, floor

import numpy as np
import pytest
import sympy as sp

from tableau_lab.analysis.family import families_of
from tableau_lab.analysis.method_series import error_terms, method_series
from tableau_lab.experiments.design_search import SNAP_TOLERANCE, search
from tableau_lab.numeric.objectives import NumericGLM, series_defects

PN = "methods/design/pn_family.json"


@pytest.fixture(scope="module")
def pn():
    return families_of(PN, ["g-symplectic"])[0]


def _rationals_below(h, lo, hi):
    """Every p/q in [lo, hi] with max(|p|, q) < h (plain enumeration)."""
    out = set()
    for q in range(1, h):
        for p in range(ceil(lo * q), floor(hi * q) + 1):
            r = Fraction(p, q)
            if max(abs(r.numerator), r.denominator) < h:
                out.add(r)
    return sorted(out)


def test_box_face_is_flagged(pn):
    """On this family μ = u exactly, so min |μ| over [1/2, 2] is at the face u = 1/2: the optimum is
    flagged box-bound at that face (and not at the other), in the text and the JSON."""
    res = search(pn, minimize="mu", box=(0.5, 2.0), samples=32, starts=2)
    best = res.candidates[0]
    assert best.exact["u"] == sp.Rational(1, 2)
    assert [(str(s), f) for s, f in best.box_bound] == [("u", 0.5)]
    assert "box-bound: u = 0.5" in str(res)
    assert res.to_json()["candidates"][0]["box_bound"] == [{"parameter": "u", "face": 0.5}]
    inner = search(pn, minimize="mu", box=(0.25, 2.0), samples=32, starts=2).candidates[0]
    assert [f for _, f in inner.box_bound] == [0.25]            # the face moved with the box


def test_interior_optimum_is_not_box_bound(pn):
    """Under order 4 the optima are P and N (u = 1 ± 2/√3), well inside [−3, 3]."""
    res = search(pn, maximize="imaginary-interval", constraints=("order=4",), box=(-3.0, 3.0), seed=1,
                 samples=32, starts=2, certify=False)
    assert res.candidates and all(c.box_bound == () for c in res.candidates)


@pytest.fixture(scope="module")
def flat():
    """The explicit 3-stage order-3 family with c3 = 0 (free b3): its order-4 error terms do not
    depend on b3 (checked exactly here), so every b3 is optimal for the error norm."""
    fam = next(f for f in families_of("methods/design/erk3_general.json", ["order=3"])
               if [str(s) for s in f.free] == ["b3"] and f.method.c[2] == 0)
    terms = error_terms(method_series(fam.method, 4).phi, 4)
    assert all(sp.simplify(sp.diff(t, fam.free[0])) == 0 for t in terms)
    return fam


def test_each_certified_member_once_and_flat_objective_box_bound(flat):
    """Eight local searches of a flat objective end at eight points that certify to one member: it is
    printed once (with the count of the others), and both faces are flagged; the member is the
    rational of smallest height within the box whose tableau exists (b3 = 0 is a pole of a32 = 1/(4 b3);
    the next heights are ±1, the nearer to the optimum first)."""
    res = search(flat, minimize="error-norm", box=(-2.0, 2.0), samples=16, starts=8)
    certified = [c for c in res.candidates if c.certified is not None]
    members = [tuple(c.certified.A) + tuple(c.certified.b) for c in certified]
    assert len(members) == len(set(members)) == 1
    best = certified[0]
    assert best.repeats >= 1 and "also the certified member of" in str(res)
    assert sorted(f for _, f in best.box_bound) == [-2.0, 2.0]
    assert abs(best.exact["b3"]) == 1 and best.height == 1
    assert np.sign(float(best.exact["b3"])) == np.sign(best.point[0])


def test_snap_is_the_smallest_height_within_tolerance(pn):
    """Minimising the error norm (order 2 here, generic) ends at the irrational u = 1 − 2/√3, where it
    vanishes: the snap is a rational within tolerance, and no rational of smaller height near the
    optimum keeps the objective within tolerance (enumerated here, evaluated by the float objective
    that tests/test_design_search.py checks against the exact error norms).  The JSON gives the
    height max(|p|, q)."""
    res = search(pn, minimize="error-norm", box=(-3.0, 3.0), samples=32, starts=2)
    c = next(c for c in res.candidates if c.certified is not None and c.point[0] < 0)
    u = c.exact["u"]
    assert u.is_Rational and c.height == max(abs(u.p), u.q)
    j = next(d for d in res.to_json()["candidates"] if d["exact"]["u"] == str(u))
    assert j["height"] == c.height
    value = c.values["error-norm"]
    p = 2

    def within(r):
        g = NumericGLM(*[np.array(M.subs(pn.free[0], sp.Rational(r.numerator, r.denominator)), dtype=float)
                         for M in (pn.method.A, pn.method.U, pn.method.B, pn.method.V)])
        return abs(series_defects(g, p)[1] - value) <= SNAP_TOLERANCE * max(1.0, abs(value))
    assert within(Fraction(int(u.p), int(u.q)))
    smaller = _rationals_below(c.height, c.point[0] - 0.05, c.point[0] + 0.05)
    assert smaller and not any(within(r) for r in smaller)
