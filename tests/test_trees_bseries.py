"""Rooted trees and B-series against independent identities: OEIS A000081, Cayley's
n^(n-1), the count (n-1)! of monotone labellings, HLW06 Table III.1.1 values, and the
group laws E·E = 2^|t|/γ, E⁻¹ = (-1)^|t|/γ, associativity, a·a⁻¹ = e."""
import random
from math import factorial

import pytest
import sympy as sp

from tableau_lab.analysis.bseries import (
    compose,
    compose_coefficients,
    exact_flow,
    identity,
    inverse,
    inverse_coefficients,
    stage_derivative,
)
from tableau_lab.analysis.trees import (
    TAU,
    bracket,
    butcher_product,
    density,
    from_children,
    order,
    subtrees,
    symmetry,
    trees_of_order,
    trees_up_to,
)


def test_counts_a000081():
    assert [len(trees_of_order(n)) for n in range(1, 13)] == [1, 1, 2, 4, 9, 20, 48, 115, 286, 719, 1842, 4766]


@pytest.mark.parametrize("n", range(1, 10))
def test_labelled_tree_identities(n):
    trees = trees_of_order(n)
    assert sum(factorial(n) // symmetry(t) for t in trees) == n ** (n - 1)              # Cayley
    assert sum(sp.Rational(factorial(n), symmetry(t) * density(t)) for t in trees) == factorial(n - 1)


def test_order_4_table():
    """[HLW06] Table III.1.1: γ and σ of the trees of order ≤ 4."""
    expect = {"τ": (1, 1), "[τ]": (2, 1), "[τ²]": (3, 2), "[[τ]]": (6, 1), "[τ³]": (4, 6),
              "[τ[τ]]": (8, 1), "[[τ²]]": (12, 2), "[[[τ]]]": (24, 1)}
    got = {bracket(t): (density(t), symmetry(t)) for t in trees_up_to(4)}
    assert got == expect


def test_butcher_product():
    t = from_children([TAU])
    assert butcher_product(t, TAU) == from_children([TAU, TAU])
    assert order(butcher_product(t, t)) == 4 and bracket(butcher_product(t, t)) == "[τ[τ]]"


@pytest.mark.parametrize("n", range(1, 9))
def test_density_is_product_of_subtree_orders(n):
    """γ(t) = Π over the vertices v of |subtree at v| (the non-recursive definition), and a
    tree of order n has n vertex subtrees."""
    from math import prod
    for t in trees_of_order(n):
        subs = subtrees(t)
        assert len(subs) == n and subs[0] == t
        assert density(t) == prod(order(u) for u in subs)


N = 6


def test_flow_group_laws():
    E = exact_flow(N)
    EE = compose(E, E)
    Einv = inverse(E)
    for t in trees_up_to(N):
        assert EE[t] == sp.Rational(2 ** order(t), density(t))
        assert Einv[t] == sp.Rational((-1) ** order(t), density(t))
    e = compose(E, Einv)
    assert all(e[t] == 0 for t in trees_up_to(N)) and e == identity(N)


def _random_series(seed):
    rnd = random.Random(seed)
    out = {None: 1}
    out.update({t: sp.Rational(rnd.randint(-9, 9), rnd.randint(1, 9)) for t in trees_up_to(N)})
    return out


def test_associativity_and_inverse():
    a, b, c = (_random_series(s) for s in (1, 2, 3))
    left = compose_coefficients(compose_coefficients(a, b, N), c, N)
    right = compose_coefficients(a, compose_coefficients(b, c, N), N)
    assert all(left[t] == right[t] for t in trees_up_to(N))
    ai = inverse_coefficients(a, N)
    assert all(v == 0 for t, v in compose_coefficients(a, ai, N).items() if t is not None)
    assert all(v == 0 for t, v in compose_coefficients(ai, a, N).items() if t is not None)


def test_outer_series_with_nonunit_empty_coefficient_on_linear_problem():
    """For y' = λy only tall trees have F(t) ≠ 0 (F = λ^n y), so B(b, B(a, y)) has
    tall-tree coefficients Σ_k b(tall_k) a(tall_{n-k}) with a(tall_0) = 1, b(tall_0) = b(∅)."""
    a, b = _random_series(4), _random_series(5)
    b[None] = sp.Rational(3, 7)
    ab = compose_coefficients(a, b, N)
    tall = [None]
    for _ in range(N):
        tall.append(from_children([tall[-1]]) if tall[-1] is not None else TAU)
    for n in range(1, N + 1):
        expected = sum(b[tall[k]] * (a[tall[n - k]] if n - k else 1) for k in range(n + 1))
        assert ab[tall[n]] == expected
    assert ab[None] == sp.Rational(3, 7)
    with pytest.raises(ValueError):
        compose_coefficients(b, a, N)            # the inner series must have empty-tree coefficient 1


def test_stage_derivative_of_flow():
    """E′([t₁…t_m]) = Π 1/γ(tᵢ) = |t|/γ(t): the series of h y′(x0 + h) is |t| E(t)."""
    E = exact_flow(N)
    d = stage_derivative({t: E[t] for t in [None, *trees_up_to(N)]}, N)
    assert all(d[t] == order(t) * E[t] for t in trees_up_to(N))
    assert identity(3)[TAU] == 0
