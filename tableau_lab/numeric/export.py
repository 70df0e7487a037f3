r"""Exact methods → numeric coefficients, at float64 or any mpmath precision.

Every kind becomes one shape, a *partitioned GLM*: stage matrices A_q, A_p (s×s) acting on the
q- and p-components of the stage derivatives, U (s×r), output matrices B_q, B_p (r×s), V (r×r).
An RK method is A_q = A_p = A, U = 1, B = bᵀ, V = [1]; a partitioned RK method has A_q = A,
A_p = Â; a GLM has A_q = A_p = A.  For a problem that is not Hamiltonian every component is a
q-component.  Coefficients are rounded once from their exact values (``sympy.N`` at the working
precision plus guard digits), never through an intermediate float.

For GLMs, and for RK methods whose effective order exceeds their classical order, the
starting method ξ(t) and the finishing method α⁻¹(t) of the order analysis are exported too,
so that a run can start with y^[0]_k = u_k y₀ + Σ_t ξ_k(t) h^|t|/σ(t) F(t)(y₀) and report
z + Σ_t α⁻¹(t) h^|t|/σ(t) F(t)(z), z = wᵀy^[n].

>>> from tableau_lab.exact.tableau_json import load
>>> nm = to_numeric(load("methods/gauss2.json"))
>>> nm.s, nm.r, nm.explicit, round(float(nm.Aq[0, 1]), 12)
(2, 1, False, -0.038675134595)
>>> roundtrip_error(load("methods/example4_glm.json"), "mp:50") < 1e-49
True
"""
from __future__ import annotations

import sympy as sp

from ..exact.methods import Method
from .arith import arith
from .method import NumericMethod

__all__ = ["NumericMethod", "to_numeric", "roundtrip_error"]


def _exact_parts(m: Method):
    if m.kind == "prk":
        return (m.A, m.Ahat, sp.ones(m.s, 1), m.b.T, m.bhat.T, sp.Matrix([[1]]), m.c)
    if m.kind == "rk":
        return (m.A, m.A, sp.ones(m.s, 1), m.b.T, m.b.T, sp.Matrix([[1]]), m.c)
    g = m.as_glm()
    return (g.A, g.A, g.U, g.B, g.B, g.V, g.c)


def _series(res, a):
    """The starting ξ(t) and finishing α⁻¹(t) coefficients of a GLM order result, numeric,
    keyed by tree, for |t| ≤ its order; a tree whose coefficients are all exactly zero is left
    out (a run evaluates the elementary differentials of the trees it is given, and generates
    f's derivatives up to the largest: GLM43's finishing method is the identity)."""
    from ..analysis.trees import bracket, trees_up_to
    by_name = {bracket(t): t for t in trees_up_to(res.order)}
    return ({by_name[k]: a.array(v) for k, v in res.starting.items() if k in by_name and any(x != 0 for x in v)},
            {by_name[k]: a.number(v) for k, v in res.finishing.items() if k in by_name and v != 0})


def _floats(rows, dps):
    """mpmath rows → a sympy Matrix of Floats with all ``dps`` digits (sympy would round an
    mpf to 15 digits)."""
    return sp.Matrix([[sp.Float(x, dps) for x in row] for row in rows])


def _newton_data(Aq, Ap, c, a, conjugate=None):
    """The stage predictor E (E[i, j] = ℓ_j(1 + c_i), ℓ_j the Lagrange basis on the nodes c:
    the previous step's stage derivatives extrapolated to the new stages, as in Hairer's GNI
    codes) and A_q⁻¹, A_p⁻¹ (stage derivatives from the stage increments, so a converged
    Newton iteration needs no further f-evaluation).  Each is evaluated at 20 digits beyond
    the working precision from the exact entries and rounded once; None where c has repeated
    nodes or A is singular (decided exactly)."""
    import mpmath

    from ..exact.field import normal_form
    wp = arith(f"mp:{max(a.dps, 16) + 20}")
    s = len(c)
    E = None
    # nodes on the roots of one squarefree polynomial (exact.conjugate) are distinct, and det A = det Ã
    distinct = conjugate is not None or all(normal_form(c[i] - c[j]) != 0 for i in range(s) for j in range(i))
    if distinct:
        with wp.context():
            cn = [wp.number(x) for x in c]
            E = [[mpmath.fprod((1 + cn[i] - cn[k]) / (cn[j] - cn[k]) for k in range(s) if k != j)
                  for j in range(s)] for i in range(s)]
        E = a.matrix(_floats(E, wp.dps))
    invs = []
    for A in (Aq, Ap):
        A = sp.Matrix(A)
        if (sp.Matrix(conjugate.A_tilde).det() if conjugate is not None else normal_form(A.det())) == 0:
            invs.append(None)
            continue
        with wp.context():
            Ai = mpmath.inverse(wp.matrix(A).tolist())
            invs.append(a.matrix(_floats(Ai.tolist(), wp.dps)))
    return E, invs[0], invs[1]


def to_numeric(m: Method, precision: str = "float64", starting: bool = True) -> NumericMethod:
    """The numeric form of ``m`` at ``precision`` ("float64" or "mp:DIGITS")."""
    if m.parameters:
        raise ValueError(f"{m.name}: the tableau has free parameters {', '.join(map(str, m.parameters))}; "
                         "solve for them first (tableau-lab solve)")
    a = arith(precision)
    Aq, Ap, U, Bq, Bp, V, c = _exact_parts(m)
    xi, beta, order, u, w = {}, {}, 0, [1], [1]
    order_identity = None
    modes = ()
    if m.kind == "glm":
        from ..analysis.glm_order import glm_order
        from ..analysis.parasitism import numeric_modes
        modes = numeric_modes(m)             # the parasitism monitor's data, once per method
        res = glm_order(m)
        order, u, w = res.order, res.u, res.w
        order_identity = res.order_identity_start
        if starting:
            xi, beta = _series(res, a)
    elif m.kind == "rk":
        from ..analysis.rk_order import rk_order
        res = rk_order(m)
        order = order_identity = res.order
        if starting and res.effective is not None and res.effective_order > res.order:
            # effective order (Butcher 1969): process with the starting method θ, report through α⁻¹
            order = res.effective.order
            xi, beta = _series(res.effective, a)
    else:
        from ..analysis.prk_order import prk_order
        order = prk_order(m).order
    E = Aqi = Api = None
    if not all(sp.Matrix(X)[i, j] == 0 for X in (Aq, Ap) for i in range(len(c)) for j in range(i, len(c))):
        E, Aqi, Api = _newton_data(Aq, Ap, list(c), a, getattr(m, "conjugate", None))
    with a.context():
        return NumericMethod(E=E, Aq_inv=Aqi, Ap_inv=Api, name=m.name, kind=m.kind, arith=a, Aq=a.matrix(Aq),
                             Ap=a.matrix(Ap), U=a.matrix(U), Bq=a.matrix(Bq), Bp=a.matrix(Bp), V=a.matrix(V),
                             c=a.array(list(c)), u=a.array(list(u)), w=a.array(list(w)), order=order, starting=xi,
                             finishing=beta, exact=m, modes=modes,
                             order_identity=order if order_identity is None else order_identity)


def roundtrip_error(m: Method, precision: str = "float64") -> float:
    """Largest |numeric − exact| over the exported coefficients, measured at 60 digits more than
    the working precision: the export's own round-off (≈ ulp of the precision)."""
    import mpmath
    nm = to_numeric(m, precision, starting=False)
    parts = _exact_parts(m)
    worst = mpmath.mpf(0)
    with mpmath.workdps(nm.arith.dps + 60):
        for X, M in zip((nm.Aq, nm.Ap, nm.U, nm.Bq, nm.Bp, nm.V), parts[:6], strict=False):
            M = sp.Matrix(M)
            for i in range(M.rows):
                for j in range(M.cols):
                    exact = mpmath.mpf(str(sp.N(M[i, j], nm.arith.dps + 60)))
                    worst = max(worst, abs(mpmath.mpf(X[i, j]) - exact))
    return float(worst)
