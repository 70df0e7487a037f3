"""One tree recursion for plain and bicoloured trees (issue 31, part 5): the elementary weights of
Runge–Kutta and partitioned Runge–Kutta methods come from one definition
(:meth:`TreeKind.elementary_weights`), and :mod:`trees` takes order, density and symmetry from
:mod:`tree_kinds`.  The properties are checked against identities that do not depend on the code:
the labelled-tree counts for bicoloured trees, and a partitioned method with the same tableau in both
partitions having the P-series of the RK method (every colouring of a tree has the RK weight)."""
import re
from math import factorial

import pytest
import sympy as sp

from tableau_lab.analysis import prk_order as prk, rk_order as rk, tree_kinds, trees
from tableau_lab.analysis.tree_kinds import BICOLOURED, PLAIN, TreeKind
from tableau_lab.exact.field import FastField, field_of
from tableau_lab.exact.methods import PartitionedRungeKutta
from tableau_lab.exact.tableau_json import load


def test_trees_takes_order_density_symmetry_from_tree_kinds():
    assert trees.order is tree_kinds.order
    assert trees.density is tree_kinds.density
    assert trees.symmetry is tree_kinds.symmetry


def test_rk_and_prk_weights_run_through_the_one_recursion(monkeypatch):
    """Both order analyses call TreeKind.elementary_weights, once per method, with their own kind."""
    seen = []
    one_recursion = TreeKind.elementary_weights

    def spy(kind, *args):
        seen.append(kind)
        return one_recursion(kind, *args)
    monkeypatch.setattr(TreeKind, "elementary_weights", spy)
    assert rk.rk_order(load("methods/rk4.json"), effective=False).order == 4
    assert prk.prk_order(load("methods/stormer_verlet.json")).order == 2
    assert seen == [PLAIN, BICOLOURED]


def _uncoloured(t):
    return tuple(sorted(_uncoloured(c) for c in t[1]))


@pytest.mark.parametrize("n", range(1, 6))
def test_bicoloured_labelled_tree_counts(n):
    """Σ n!/(σ(t)γ(t)) over the trees of order n is (n − 1)! (monotone labellings, [B16] Thm 301A) for
    plain trees, and 2ⁿ(n − 1)! for bicoloured ones (each vertex coloured freely); Σ n!/σ(t) counts the
    labelled trees, nⁿ⁻¹ (Cayley), so 2ⁿnⁿ⁻¹ bicoloured ones."""
    assert sum(sp.Rational(factorial(n), PLAIN.symmetry(t) * PLAIN.density(t))
               for t in PLAIN.trees_of_order(n)) == factorial(n - 1)
    assert sum(sp.Rational(factorial(n), BICOLOURED.symmetry(t) * BICOLOURED.density(t))
               for t in BICOLOURED.trees_of_order(n)) == 2 ** n * factorial(n - 1)
    assert sum(factorial(n) // BICOLOURED.symmetry(t) for t in BICOLOURED.trees_of_order(n)) == 2 ** n * n ** (n - 1)
    for t in BICOLOURED.trees_of_order(n):          # γ forgets the colours
        assert BICOLOURED.density(t) == PLAIN.density(_uncoloured(t))


def test_same_tableau_in_both_partitions_gives_the_rk_weights():
    """With Â = A and b̂ = b, Φ(t) of every bicoloured tree equals the RK weight of the tree with
    the colours forgotten (the P-series reduces to the B-series, [HLW06] III.2.1)."""
    m = load("methods/radau_iia3.json")
    pm = PartitionedRungeKutta(A=m.A, b=m.b, Ahat=m.A, bhat=m.b, name="Radau IIA x 2")
    K = field_of([m.A, m.b])
    F = FastField(K)
    _, rk_phi = rk.weight_function(m)
    prk_phi = prk.weight_function(pm, K)
    for t in BICOLOURED.trees_up_to(5):
        assert F.lift(prk_phi(t)) == rk_phi(_uncoloured(t))


def test_bicoloured_weights_of_symplectic_euler_by_hand():
    """Symplectic Euler (A = (1), Â = (0), b = b̂ = (1)): Ψ = 1 for every tree, AΨ = 1, ÂΨ = 0, so
    Φ(t) = 1 exactly when no vertex below the root is coloured 1 (p), else 0."""
    phi = BICOLOURED.elementary_weights(([[1]], [[0]]), ([1], [1]), 0, 1)

    def has_p_below_root(t):
        return any(c[0] == 1 or has_p_below_root(c) for c in t[1])
    for t in BICOLOURED.trees_up_to(5):
        assert phi(t) == (0 if has_p_below_root(t) else 1)


def test_parse_tree_inverts_bracket_and_names_what_is_wrong():
    """parse_tree (split into a small recursive-descent parser for ruff's complexity bound) reads
    every bracket back, the ASCII spellings too, and refuses bad text with a message that quotes it."""
    for t in trees.trees_up_to(7):
        b = trees.bracket(t)
        assert trees.parse_tree(b) == t
        assert trees.parse_tree(" ".join(b.replace("τ", "t"))) == t
    assert trees.parse_tree("[t^2[t t]]") == trees.parse_tree("[[τ²]τ²]")
    bad = {"": "expected τ, t or '[' at character 1", "[]": "'[]' is not a tree", "[τ": "missing ']'",
           "[τ^]": "'^' must be followed by a count", "[τ⁰]": "more than 40 vertices", "τ]": "unexpected ']'",
           "[τ^41]": "more than 40 vertices", "[τ^20[τ^20]]": "42 vertices; at most 40", "x": "character 1",
           "[" * 42 + "τ" + "]" * 42: "more than 40 vertices"}
    for text, message in bad.items():
        with pytest.raises(trees.TreeError, match=re.escape(message)) as err:
            trees.parse_tree(text)
        assert repr(text)[:20] in str(err.value) or len(text) > 400
    with pytest.raises(trees.TreeError, match="at most 400 characters"):
        trees.parse_tree("τ" * 401)
