r"""Cross-check of tableau_lab.analysis (trees, method B-series, B-series algebra) against the
independent library kauri (PyPI ``kauri`` >= 2.3, D. Shmelev), on all 200 rooted trees of
orders 1..8, except where a check needs kauri's CEM antipode (order 7 there, see N_LOG).

Normalisations, read from the kauri 2.3.0 source:

* ``kauri.Tree(nested list)``: a node is the list of its children ([] = τ, [[]] = [τ]);
  ``Tree.list_repr`` adds a colour label as the last item of every node, so the children are
  ``list_repr[:-1]``; ``Tree(None)`` is ∅.  ``nodes()`` = |t|, ``factorial()`` = t! = γ(t),
  ``sigma()`` = σ(t).  ``kauri.trees_of_order(n)`` lists each tree of order n once.
* ``kauri.BSeries`` is Σ h^|t|/σ(t) φ(t) F(t), our normalisation, so a weight compares directly:
  φ_kauri(t) = a(t), no σ or γ factor.  The exact solution is 1/t! (``kauri.exact_weights``,
  floats); the exact checks use ``Map(t ↦ Rational(1, t.factorial()))`` instead.
* ``kauri.RK(A, b).elementary_weights_map()`` computes bᵀΦ(t) in whatever numbers A and b hold.
  Given our exact tableau entries it is exact: rationals as sympy Rationals (compared by
  ``sympy.expand(difference) == 0``), and Gauss2 and Radau IIA3 as elements of sympy's
  ``QQ.algebraic_field(sqrt(3))`` and ``QQ.algebraic_field(sqrt(6))`` (compared in that field).
  kauri's own float tableaux (euler, rk4, implicit_midpoint, radau_iia, gauss6 = our gauss3) are
  compared with ours to 1e-12, an independent check of our method files.
* The BCK product is ``f * g`` = μ(f⊗g)Δ_BCK with Δ_BCK(t) = Σ (pruned forest) ⊗ (trunk), so f
  acts first: ``f * g`` = our ``compose(f, g)``.  ``RK p * q`` is q first, then p.
  ``f ** -1`` = f∘S_BCK = our ``inverse(f)``, and ``RK.adjoint()`` matches our ``adjoint``.
* The CEM product is ``f ^ g`` = μ(f⊗g)Δ_CEM with Δ_CEM(t) = Σ (forest of pieces) ⊗ (t with
  the pieces contracted), so ``f ^ g`` = our ``substitute(f, g)`` = f ⋆ g.
  ``Map.log()`` = ``modified_equation()`` = φ ^ (e∘S_CEM) is our ``modified_field``.
  ``preprocessed_integrator()`` = e ^ (φ∘S_CEM) is our ``modifying_field``.
  ``kauri.omega`` is the log of explicit Euler.
"""
from collections import Counter
from pathlib import Path

import pytest
import sympy as sp

from tableau_lab.analysis import bseries as bs
from tableau_lab.analysis.method_series import method_series
from tableau_lab.analysis.trees import density, order, symmetry, trees_of_order, trees_up_to
from tableau_lab.exact.tableau_json import load

kauri = pytest.importorskip("kauri")
from kauri import Map, Tree  # noqa: E402 -- after importorskip: the file is skipped without kauri
from kauri.cem import antipode as cem_antipode  # noqa: E402 -- after importorskip, as above

ROOT = Path(__file__).resolve().parents[1]
N = 8        # all 200 trees of orders 1..8
# kauri's first S_CEM evaluation on the 115 trees of order 8 alone takes ~13 s, so the checks that go
# through S_CEM (log, preprocessed integrator, omega) stop at order 7 (85 trees).  The defining
# equation b ^ e = a of the modified field uses the CEM product only and is checked at order 8.
N_LOG = 7
TREES = list(trees_up_to(N))
E_EXACT = Map(lambda k: sp.Rational(1, k.factorial()))     # kauri's exact_weights, exactly


def ours(k) -> tuple:
    """A kauri Tree as our canonical tuple (children = list_repr[:-1], sorted)."""
    def conv(rep):
        return tuple(sorted(conv(c) for c in rep[:-1]))
    return conv(k.list_repr)


def theirs(t) -> Tree:
    """Our tree as a kauri Tree."""
    def nest(u):
        return [nest(c) for c in u]
    return Tree(nest(t))


def method(name):
    return load(ROOT / "methods" / f"{name}.json")


def phi(name, n=N):
    return method_series(method(name), n).phi


def kauri_rk(m, K=None) -> "kauri.RK":
    """kauri's RK with our exact tableau entries: sympy numbers, or elements of sympy's field K."""
    x = K.from_sympy if K is not None else (lambda v: v)
    return kauri.RK([[x(m.A[i, j]) for j in range(m.s)] for i in range(m.s)], [x(m.b[i]) for i in range(m.s)])


def weights(name, K=None) -> Map:
    return kauri_rk(method(name), K).elementary_weights_map()


def same(ours_value, kauri_value, K=None) -> bool:
    if K is not None:                        # kauri computed in sympy's exact field K = QQ<√d>
        return K.from_sympy(ours_value) == kauri_value
    return sp.expand(sp.sympify(ours_value) - sp.sympify(kauri_value)) == 0


def assert_exact(series, kmap, n=N, what="", K=None):
    bad = [(t, series[t], kmap(theirs(t))) for t in TREES if order(t) <= n
           and not same(series[t], kmap(theirs(t)), K)]
    assert not bad, f"{what}: {len(bad)} trees differ, first {bad[:3]}"


def assert_close(series, kmap, n=N, tol=1e-12, what=""):
    bad = [(t, float(series[t]), kmap(theirs(t))) for t in TREES if order(t) <= n
           and abs(float(series[t]) - float(kmap(theirs(t)))) > tol]
    assert not bad, f"{what}: {len(bad)} trees differ, first {bad[:3]}"


# ------------------------------------------------------------------ 1. trees
@pytest.mark.parametrize("n", range(1, N + 1))
def test_trees_of_order_match_kauri(n):
    theirs_n = [ours(k) for k in kauri.trees_of_order(n)]
    assert len(theirs_n) == len(trees_of_order(n)) == [1, 1, 2, 4, 9, 20, 48, 115][n - 1]
    assert Counter(theirs_n) == Counter(trees_of_order(n))          # same multiset, no repeats
    for k in kauri.trees_of_order(n):
        t = ours(k)
        assert theirs(t) == k and ours(theirs(t)) == t
        assert (k.nodes(), k.factorial(), k.sigma()) == (order(t), density(t), symmetry(t)), t


def test_all_200_trees():
    assert len(TREES) == 200 == sum(1 for k in kauri.trees_up_to_order(N) if k.list_repr is not None)


# ------------------------------------------------------------------ 2. Runge–Kutta elementary weights
@pytest.mark.parametrize("name, gen", [("explicit_euler", None), ("rk4", None), ("implicit_midpoint", None),
                                       ("gauss2", 3), ("radau_iia3", 6), ("dormand_prince54", None)])
def test_rk_weights_exact(name, gen):
    K = sp.QQ.algebraic_field(sp.sqrt(gen)) if gen else None
    ours_phi = phi(name)
    assert_exact(ours_phi, weights(name, K), what=name, K=K)
    assert ours_phi[None] == 1 and weights(name)(Tree(None)) == 1


@pytest.mark.parametrize("name, kname", [("explicit_euler", "euler"), ("rk4", "rk4"),
                                         ("implicit_midpoint", "implicit_midpoint"),
                                         ("radau_iia3", "radau_iia"), ("gauss3", "gauss6")])
def test_rk_weights_against_kauri_float_tableaux(name, kname):
    """kauri's built-in tableaux are floats (√6, √15 rounded): 1e-12."""
    assert_close(phi(name), getattr(kauri, kname).elementary_weights_map(), what=name)


def test_exact_solution():
    E = bs.exact_flow(N)
    assert_exact(E, E_EXACT, what="1/γ")
    assert_close(E, kauri.exact_weights, what="kauri.exact_weights")


# ------------------------------------------------------------------ 3. Butcher group (BCK)
@pytest.mark.parametrize("first, second", [("explicit_euler", "implicit_midpoint"),
                                           ("implicit_midpoint", "explicit_euler"),
                                           ("rk4", "dormand_prince54")])
def test_compose_is_bck_product(first, second):
    ours_c = bs.compose(phi(first), phi(second))
    assert_exact(ours_c, weights(first) * weights(second), what=f"{first}·{second}")
    # and the weights of the concatenated tableau (kauri RK p * q runs q first)
    both = kauri_rk(method(second)) * kauri_rk(method(first))
    assert_exact(ours_c, both.elementary_weights_map(), what=f"{first} then {second}, tableau")


def test_compose_with_exact_flow():
    assert_exact(bs.compose(phi("rk4"), bs.exact_flow(N)), weights("rk4") * E_EXACT, what="rk4·E")


@pytest.mark.parametrize("name", ["rk4", "explicit_euler"])
def test_inverse_is_bck_antipode(name):
    assert_exact(bs.inverse(phi(name)), weights(name) ** -1, what=f"{name}⁻¹")
    assert_exact(bs.inverse(phi(name)), (kauri_rk(method(name)) ** -1).elementary_weights_map(),
                 what=f"{name}⁻¹ tableau")


@pytest.mark.parametrize("name, gen", [("rk4", None), ("gauss2", 3), ("radau_iia3", 6)])
def test_adjoint(name, gen):
    K = sp.QQ.algebraic_field(sp.sqrt(gen)) if gen else None
    assert_exact(bs.adjoint(phi(name)), kauri_rk(method(name), K).adjoint().elementary_weights_map(),
                 what=f"{name}*", K=K)


# ------------------------------------------------------------------ 4. substitution (CEM)
def test_substitute_is_cem_product():
    """A field with b(τ) = -2 ≠ 1, so the single-vertex pieces count."""
    def fn(t):
        return sp.Rational((-1) ** order(t) * 2, density(t) + symmetry(t))

    b = bs.BSeries.from_function(fn, N, empty=0)
    kb = Map(lambda k: 0 if k.list_repr is None else fn(ours(k)))
    assert_exact(bs.substitute(b, phi("rk4")), kb ^ weights("rk4"), what="b⋆rk4")


@pytest.mark.parametrize("name", ["explicit_euler", "rk4"])
def test_modified_field_solves_kauri_exp(name):
    """kauri's CEM product: (b ^ e)(t) = a(t) and b.exp() for our b = modified_field(a), order 8."""
    b = bs.modified_field(phi(name))
    kb = Map(lambda k: 0 if k.list_repr is None else b[ours(k)])
    assert_exact(phi(name), kb ^ E_EXACT, what=f"exp(modified field of {name})")
    assert_close(phi(name), kb.exp(), what=f"kauri exp, {name}")


@pytest.mark.parametrize("name", ["explicit_euler", "rk4"])
def test_modified_field_is_kauri_log(name):
    b = bs.modified_field(phi(name, N_LOG))
    w = weights(name)
    assert_exact(b, w ^ (E_EXACT & cem_antipode), n=N_LOG, what=f"log {name}")    # Map.log, exactly
    assert_close(b, w.modified_equation(), n=N_LOG, what=f"modified_equation {name}")
    if name == "explicit_euler":
        assert_close(b, kauri.omega, n=N_LOG, what="omega")
    else:
        assert_close(b, kauri.rk4.modified_equation_map(), n=N_LOG, what="kauri.rk4")


def test_modifying_field_is_kauri_preprocessed_integrator():
    w = weights("rk4")
    ours_m = bs.modifying_field(phi("rk4", N_LOG))
    assert_exact(ours_m, E_EXACT ^ (w & cem_antipode), n=N_LOG, what="preprocessed rk4")
    assert_close(ours_m, w.preprocessed_integrator(), n=N_LOG, what="preprocessed_integrator")
