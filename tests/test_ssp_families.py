"""The explicit SSP families by name: each member's classical order pinned (every condition up to
p holds, one of order p + 1 fails) and its SSP coefficient, computed by analysis.ssp, equal to the
published value — SSPRK(s,2): s − 1 and SSPRK(n²,3): n² − n (Ketcheson, SIAM J. Sci. Comput. 30
(2008) 2113; Gottlieb, Ketcheson & Shu, SSP Runge–Kutta and Multistep Time Discretizations
(2011), ch. 6), SSPRK(3,3) and SSPRK(2,2): 1 (Shu & Osher 1988; Gottlieb & Shu,
Math. Comp. 67 (1998)), SSP(10,4): 6 (Ketcheson 2008; NodePy's SSP104 gives 5.99999999995).
The Butcher tableaux are checked against the forms the papers print, written out here."""
import pytest
import sympy as sp

from tableau_lab.analysis.rk_order import rk_order
from tableau_lab.analysis.ssp import ssp_coefficient
from tableau_lab.exact.families import MAX_SSP_STAGES, shu_osher, ssprk2
from tableau_lab.exact.library import ALIASES, FAMILIES, FamilyError, family, family_sizes, is_family
from tableau_lab.exact.tableau_json import TableauError, load

R = sp.Rational

# spec, order, published SSP coefficient
PUBLISHED = [(f"ssprk2:{s}", 2, s - 1) for s in (2, 3, 4, 6, 10)] \
    + [("ssprk3:3", 3, 1), ("ssprk3:4", 3, 2), ("ssprk3:9", 3, 6), ("ssprk3:16", 3, 12)] \
    + [("ssprk:1", 1, 1), ("ssprk:2", 2, 1), ("ssprk:3", 3, 1), ("ssprk4:10", 4, 6), ("ssp104", 4, 6)]


@pytest.mark.parametrize("spec, p, C", PUBLISHED)
def test_order_pinned_and_published_ssp_coefficient(spec, p, C):
    m = family(spec)
    r = rk_order(m, effective=False)
    assert r.order == p and not r.capped and r.residuals          # one order-(p+1) condition fails
    assert all(v == 0 for (n, *_, v) in r.conditions if n <= p)   # and every one up to p holds
    assert ssp_coefficient(m).R == C


def test_tableaux_as_published():
    """SSPRK(3,3) (Shu & Osher 1988, in Butcher form), SSPRK(4,3) (Kraaijevanger 1991; NodePy's
    SSPRK3(4) prints it), SSPRK(s,2): aᵢⱼ = 1/(s − 1), bⱼ = 1/s (NodePy's SSPRK2(4) prints s = 4)."""
    m = family("ssprk:3")
    assert m.A.tolist() == [[0, 0, 0], [1, 0, 0], [R(1, 4), R(1, 4), 0]] and list(m.b) == [R(1, 6), R(1, 6), R(2, 3)]
    m = family("ssprk3:4")
    assert m.A.tolist() == [[0, 0, 0, 0], [R(1, 2), 0, 0, 0], [R(1, 2), R(1, 2), 0, 0], [R(1, 6), R(1, 6), R(1, 6), 0]]
    assert list(m.b) == [R(1, 6), R(1, 6), R(1, 6), R(1, 2)]
    for s in (2, 5):
        m = family("ssprk2", s=s)
        assert all(m.A[i, j] == (R(1, s - 1) if j < i else 0) for i in range(s) for j in range(s))
        assert list(m.b) == [R(1, s)] * s
    # SSP(10,4) from its low-storage form (Ketcheson 2008): c and b
    m = family("ssp104")
    assert list(m.b) == [R(1, 10)] * 10
    assert list(m.c) == [0, R(1, 6), R(1, 3), R(1, 2), R(2, 3), R(1, 3), R(1, 2), R(2, 3), R(5, 6), 1]


def test_sizes_listed_are_the_sizes_built():
    """family_sizes (what a listing shows) agrees with the constructors: every listed size of
    the SSP families builds, the sizes around them are refused with the reason."""
    for name in ("ssprk", "ssprk2", "ssprk3", "ssprk4"):
        sizes = family_sizes(name)
        assert sizes[-1] == FAMILIES[name][2]
        for n in range(1, FAMILIES[name][2] + 2):
            if n in sizes:
                assert family(name, s=n).s == n
            else:
                with pytest.raises(FamilyError):
                    family(name, s=n)
    assert family_sizes("ssprk3") == (3, 4, 9, 16, 25) and MAX_SSP_STAGES == 25
    assert family_sizes("lobatto_iiia")[0] == 2 and family_sizes("nystrom")[0] == 2
    with pytest.raises(FamilyError):
        family("lobatto_iiia", s=1)
    with pytest.raises(FamilyError):
        family("nystrom", k=1)


def test_names_aliases_and_messages():
    assert is_family("ssprk:3") and is_family("ssprk3") and is_family("ssp104") and not is_family("gauss2")
    assert load("ssprk:3") == family("ssp33") == family("ssprk3", s=3)
    assert load("ssp104") == family("ssprk4:10")
    assert set(ALIASES.values()) <= {f"{n}:{s}" for n in FAMILIES for s in family_sizes(n)}
    for bad, fragment in [("ssprk3:5", "s = 3 and s = n²"), ("ssprk3", "one of 3, 4, 9, 16, 25"),
                          ("ssprk4:9", "10 only"), ("ssprk:4", "1 … 3"), ("ssprk2:1", "at least 2")]:
        with pytest.raises(TableauError) as info:
            load(bad)
        assert fragment in str(info.value) and info.value.source == bad
    assert load("gauss2") == load("methods/gauss2.json")            # a file name with a digit is still a file


def test_shu_osher_refuses_what_it_cannot_take():
    with pytest.raises(ValueError, match="exact rationals"):
        shu_osher([[0], ["1/2"]], [[0], [1]])                       # text is not evaluated
    with pytest.raises(ValueError, match="exact rationals"):
        shu_osher([[0], [0.5]], [[0], [1]])
    with pytest.raises(ValueError, match="earlier stages"):
        shu_osher([[0, 1], [1, 0], [0, 1]], [[0, 0], [1, 0], [0, 1]])
    with pytest.raises(ValueError, match="shape"):
        shu_osher([[0], [1]], [[0, 0], [1, 0], [0, 1]])
    assert ssprk2(3) is family("ssprk2:3")                          # built once
