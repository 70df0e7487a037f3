"""Partitioned RK order from bicoloured trees, pinned at p + 1, against published orders
([HLW06] I.1 and II.2: symplectic Euler 1, Störmer–Verlet 2) and OEIS A000151."""
from pathlib import Path

import sympy as sp

from tableau_lab.analysis.prk_order import bicoloured_trees, prk_order
from tableau_lab.exact.methods import PartitionedRungeKutta
from tableau_lab.exact.tableau_json import load

METHODS = Path(__file__).parent.parent / "methods"
half = sp.Rational(1, 2)


def test_bicoloured_tree_counts():
    assert [len(bicoloured_trees(n)) for n in range(1, 7)] == [2, 4, 14, 52, 214, 916]


def test_library_partitioned_orders():
    se = prk_order(load(METHODS / "symplectic_euler.json"))
    sv = prk_order(load(METHODS / "stormer_verlet.json"))
    assert (se.order, sv.order) == (1, 2)
    assert se.errors and sv.errors          # fails at p + 1


def test_same_tableau_in_both_partitions_is_the_rk_order():
    """Gauss 2 used for both partitions: order 4 (its RK order), not 5."""
    s3 = sp.sqrt(3)
    A = [[sp.Rational(1, 4), sp.Rational(1, 4) - s3 / 6], [sp.Rational(1, 4) + s3 / 6, sp.Rational(1, 4)]]
    m = PartitionedRungeKutta.from_lists(A, [half, half], A, [half, half], name="Gauss2 x 2")
    assert prk_order(m).order == 4


def test_lobatto_iiia_iiib_3_stage_pair_has_order_4():
    """The 3-stage Lobatto IIIA–IIIB pair has order 2s - 2 = 4 ([HLW06] Thm II.2.2 / Table II.2.?)."""
    a = load(METHODS / "lobatto_iiia3.json")
    b = load(METHODS / "lobatto_iiib3.json")
    m = PartitionedRungeKutta(A=a.A, b=a.b, Ahat=b.A, bhat=b.b, name="Lobatto IIIA-IIIB 3")
    assert prk_order(m).order == 4
