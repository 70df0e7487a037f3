"""benchmarks/nodepy_float.py: NodePy's floating-point methods as decimal tableaux, certified (issue 33,
"what it must show", line 1).  Facts: Tsitouras 5(4) is of order 5 with embedded order 4 (Ch.
Tsitouras, Comput. Math. Appl. 62 (2011)); SSP(5,4) of order 4 (Spiteri & Ruuth, SIAM J. Numer.
Anal. 40 (2002)); the sum of NodePy's SSP53 weights, added exactly from its doubles with fractions."""
import math
from fractions import Fraction

import pytest
from conftest import benchmark_script

from tableau_lab.analysis.certified import certified_verify
from tableau_lab.exact.tableau_json import from_dict_any

nodepy = pytest.importorskip("nodepy")
nodepy_float = benchmark_script("nodepy_float")


@pytest.fixture(scope="module")
def lib():
    import warnings
    warnings.filterwarnings("ignore")
    from nodepy import rk
    return rk.loadRKM("All")


def test_every_ball_holds_its_double_and_the_printed_digits(lib):
    for name in ("Tsit5", "SSP53", "PD8"):
        d = nodepy_float.tableau(name, lib[name])
        radius = Fraction(d["radius"])
        for row, x in zip(d["A"], lib[name].A, strict=True):
            for e, v in zip(row, x, strict=True):
                if isinstance(e, str):
                    assert Fraction(e) == Fraction(repr(float(v))) and float(e) == float(v)   # the same double
                    assert abs(Fraction(float(v)) - Fraction(e)) <= radius
                    assert radius >= Fraction(math.ulp(float(v))) / 2


def test_tsit5_is_5_4_and_ssp54_is_4(lib):
    row = nodepy_float.analyse("Tsit5", lib["Tsit5"])
    assert (row["order"], row["embedded"]) == ("5", "4")
    assert row["nodepy"]["order"] == 4 and "order 6" in row["settled"][0]       # NodePy's tolerance, settled
    assert nodepy_float.analyse("SSP54", lib["SSP54"])["order"] == "4"


def test_ssp53_weights_miss_one(lib):
    m = lib["SSP53"]
    miss = sum(Fraction(float(x)) for x in m.b) - 1
    assert 1e-10 < miss < 1e-9
    r = certified_verify(from_dict_any(nodepy_float.tableau("SSP53", m), "SSP53"))
    f = r.finding("order")
    assert f.value == 0 and f.status == "certified"
    assert abs(float(f.evidence[0].ball.mid()) - float(miss)) < 1e-14
