r"""The step loop, written once for every precision ([B16] ch. 5 for the GLM step; Hairer,
Lubich & Wanner, *Geometric Numerical Integration*, 2nd ed. [HLW06], Sec. VIII.6 for the stage
iteration, VII.1 and the seed's §3.2 for projection).

A step of the partitioned GLM of :mod:`export` on y′ = f(y), input y^[n−1] (r × d):

    Yᵢ = Σₖ Uᵢₖ y^[n−1]ₖ + h Σⱼ A[cls(e)]ᵢⱼ f(Yⱼ)      (component e; cls = 0 for q, 1 for p)
    y^[n]ₖ = Σₗ Vₖₗ y^[n−1]ₗ + h Σⱼ B[cls(e)]ₖⱼ f(Yⱼ)

The functions below are plain Python over scalars and small arrays.  The arithmetic is not
theirs: ``wadd``, ``wmul``, ``g2``, ``wlo`` … come from an arithmetic module (:mod:`ops_f64`,
:mod:`ops_dd`, :mod:`ops_mp`), and the problem's functions ``f_``, ``jac_``, ``inv_``,
``grad_``, ``fq_``, ``fp_`` are bound per problem.  :mod:`kernels` writes the functions of
:data:`LOOP` (each one's source whole), one arithmetic module's and an import of the problem's
generated functions into one module that numba compiles (float64, double-double), or runs these
same function objects bound to an arithmetic and Python wrappers of the problem (the pure loop:
the reference, and mpmath at any precision).  The loop's state travels as a few records
(:class:`Coefficients`, :class:`Controls`, :class:`ProblemData`, :class:`Span`, :class:`State`,
:class:`Stages`, :class:`Projection`).  ``dims`` is replaced by constants in a
module specialised to one method shape (s, r, d), so that the small loops unroll, and a
specialised module sets ``LOOP_MODE`` and ``LOOP_PROJECTS`` (the run's stage iteration, its
projection) and which of the method's matrices have no zero, ``DENSE_A`` … (:func:`uses`):
numba prunes the branches these decide before it compiles, so a fixed-point loop holds no Newton
code and a loop without projection no projection (a third of the compile time and of the code).
The decorators (:mod:`jit`) say how numba compiles each function: ``kernel`` (an entry point,
without reference counting: nothing here allocates; its arrays do not alias), ``helper``
(inlined into its caller by LLVM), ``prim`` (small, left to LLVM to inline), ``heavy``
(the Newton matrix's linear algebra: inlined for small s·d only), ``alloc`` (the workspace); in
the pure loop they do nothing.

Stage equations (``flags[F_MODE]``, chosen by :func:`limits.choose_iteration`):

* explicit methods evaluate the stages in order;
* ``NEWTON``: simplified Newton on the increments Z = Y − Ū with one Jacobian (at Ū₁) per step,
  started from the predicted stage derivatives (:func:`predict`: the last ``HISTORY`` steps'
  extrapolated per stage, or the last step's extrapolated to the new nodes, E[i, j] =
  ℓⱼ(1 + cᵢ)), stopped by Hairer's estimate θ/(1 − θ)‖ΔZ‖ ≤ u‖Z‖ (θ the observed contraction);
  the stage derivatives then come from A⁻¹Z/h (no f-evaluation after convergence) when A is
  invertible; for a diagonally implicit method (``flags[F_LOWER]``) the matrix I − h(A ⊗ J) is
  block lower triangular: s LUs of its d × d diagonal blocks and forward block substitution
  (:func:`lower_factor`, :func:`lower_solve`), not one LU of size s·d;
* ``FIXED``: the same with M = I (no Jacobian, no LU);
* ``SPLIT`` (H = T(p) + V(q)): fixed point on the q stages only — forces at the q stages, the p
  stages from them, the velocities at the p stages, new q stages — as GNI_IRK2 iterates for
  q″ = f(q); the stage derivatives are those of the last sweep (no extra evaluation), stopped
  when the corrections of the q and the p stages are at round-off; started from the predicted
  forces.
* A step whose iteration fails leaves the loop (status 4) and is redone by :func:`rescue_step`:
  simplified Newton (after ``SWITCH_AFTER`` failures the run stays with Newton), then full
  Newton, then fixed point on the stage values (``RESCUE_SWEEPS``); if all fail, status 1.

The principal increment is summed with compensation (Kahan) when V's first row is e₁ᵀ
(``flags[F_COMPENSATE]``).  Projection moves y^[n]₁ onto {I_k = I_k(y₀)} by Newton on the
multipliers, y = ỹ + ∇g(ỹ)λ.  Statuses of :func:`run`: 0 done, 1 stage equations not solved,
2 non-finite state, 3 projection failed, 4 the stage iteration failed (for ``rescue_step``; the
state is that before the failing step), ``MISFIT`` (5) the arrays passed do not have the shape
(s, r, d) of :func:`dims` (:func:`fits`; a bug of the caller, no step taken).
"""
from typing import Any, NamedTuple

import numpy as np

from .limits import (
    ANY,
    DIVERGE_AFTER,
    EXPLICIT,
    F_COMPENSATE,
    F_EXPLICIT,
    F_HAS_E,
    F_HAS_INV,
    F_HAS_JAC,
    F_HPOS,
    F_LOWER,
    F_MODE,
    F_NHIST,
    F_PREDICT,
    FIXED,
    FULL,
    FULL_NEWTON_SWEEPS,
    HISTORY,
    HISTORY_WEIGHTS,
    MISFIT,
    NEWTON,
    PROJECTION_ACCEPT,
    PROJECTION_ROUNDOFF,
    PROJECTION_STALL,
    PROJECTION_SWEEPS,
    RESCUE_SWEEPS,
    ROUNDOFF_FLOOR,
    S_DONE,
    S_FALLBACKS,
    S_LAST,
    S_NFEV,
    S_NREC,
    S_NVEL,
    S_PROJ,
    S_PROJ_RES,
    S_STEP,
    S_SWEEPS,
    SPLIT,
    SPLIT_TOL_ULPS,
    STAGE_SWEEPS,
    STALL_THETA,
    SWITCH_AFTER,
)
from .ops_f64 import (
    alloc,
    g1,
    g2,
    g3,
    heavy,
    helper,
    isnz,
    kernel,
    lofinite,
    lomat,
    lovec,
    p1,
    p2,
    p3,
    prim,
    wadd,
    waddlo,
    wint,
    wlo,
    wmadd,
    wmat,
    wmul,
    wsub,
    wvec,
    wzero,
)

# ---- the loop's records: its state by role, not 32 positional parameters ----
# numba passes a NamedTuple of arrays and scalars as its members (flattened into the call's
# arguments: no indirection, and ``noalias`` still reaches every array), and the pure loop as a
# Python tuple; a field is read as ``method.A``.


class Coefficients(NamedTuple):
    """The method at the working precision (:class:`kernels.Pack`), both component classes
    stacked (index 0: q, 1: p): A and its inverse Ainv (2 × s × s; zeros when A is singular),
    B (2 × r × s), U (s × r), V (r × r), E (s × s: the predicted start's extrapolation) and
    ``cls`` (d integers: each component's class)."""
    A: Any
    U: Any
    B: Any
    V: Any
    cls: Any
    E: Any
    Ainv: Any


class Controls(NamedTuple):
    """The step: h and 1/h (working precision), the unit ``eps`` and the tolerance ``tol`` of
    the stage and projection iterations (:meth:`~.arith.Arith.loop_tolerances`), ``hA`` the
    stage system's scale h‖A‖ (round-off amplification)."""
    h: Any
    hinv: Any
    eps: float
    tol: float
    hA: float


class ProblemData(NamedTuple):
    """The problem's constants ``c`` (the generated functions' parameter) and its invariants:
    those projected on (indices ``proj`` into ``inv_``/``grad_``, values ``target`` at y₀)
    and those tracked (``track``, ``ttarget``)."""
    c: Any
    proj: Any
    target: Any
    track: Any
    ttarget: Any


class Span(NamedTuple):
    """Which steps a call takes: n0+1 … n1 of ``steps``; a record every ``every`` steps (and at
    ``steps``), the tracked invariants every ``track_every``."""
    n0: int
    n1: int
    steps: int
    every: int
    track_every: int


class State(NamedTuple):
    """What a run changes: the input vector Y (r × d), the Kahan carry ``comp`` (d), the ring
    ``Fh`` of the last HISTORY steps' stage derivatives, ``flags`` (limits.F_*), the counters
    ``stats`` (limits.S_*), ``tmax`` (largest tracked invariant errors) and the records ``rec``
    (values) and ``recn`` (their steps)."""
    Y: Any
    comp: Any
    Fh: Any
    flags: Any
    stats: Any
    tmax: Any
    rec: Any
    recn: Any


class Stages(NamedTuple):
    """The stage work arrays (:func:`workspace`): Ū = U y^[n−1], F the stage derivatives, Z the
    increments Y − Ū, W a scratch of the same shape (s × d), Yst one stage value (d), J the
    Jacobian (d × d), M and piv Newton's factored matrix (s·d), R the residual (s·d), Yout the
    new input vector (r × d)."""
    Ubar: Any
    F: Any
    Z: Any
    W: Any
    Yst: Any
    J: Any
    M: Any
    piv: Any
    R: Any
    Yout: Any


class Projection(NamedTuple):
    """The projection's work arrays (:func:`workspace`, m projected invariants): gradients G at
    y and Gz at the iterate (m × d), the factored matrix GtG and piv (m × m), the residual g and
    multipliers lam (m), the iterate z (d), one invariant value tmp, the point yfirst (d)."""
    G: Any
    Gz: Any
    GtG: Any
    gpiv: Any
    g: Any
    lam: Any
    z: Any
    tmp: Any
    yfirst: Any


RECORDS = (Coefficients, Controls, ProblemData, Span, State, Stages, Projection)

# ---- the problem's functions: placeholders, bound per problem ----

def f_(y, c, out, i):
    """f(y) → row i of out (bound per problem)."""
    raise NotImplementedError


def jac_(y, c, out):
    """f′(y) → out (d × d)."""
    raise NotImplementedError


def fq_(y, c, out, i):
    """The q-rate ∂T/∂p of a separable problem → out[i, e] for the q components (reads p only)."""
    raise NotImplementedError


def fp_(y, c, out, i):
    """The p-rate −∂V/∂q of a separable problem → out[i, e] for the p components (reads q only)."""
    raise NotImplementedError


def inv_(k, y, c, out):
    """The k-th invariant of the run → out[0]."""
    raise NotImplementedError


def grad_(k, y, c, out, i):
    """Its gradient → row i of out."""
    raise NotImplementedError


# ---- what a generated module specialises ----
# A compiled module specialised to one run (:func:`kernels.module_source`) gives these other
# values; numba prunes the branches they decide before compiling (the Newton code of a
# fixed-point loop, the projection of a run without it are never compiled).  ANY: the flags decide.
# DENSE_*: which of the method's matrices have no zero entry (both classes;
# :func:`kernels.dense_matrices`): their coefficients are used without a test in the step; the
# others' (all, here: nothing known) are tested for zero when it runs.
SPECIALISED = {
    "LOOP_MODE": ANY,           # EXPLICIT, NEWTON, FIXED or SPLIT
    "LOOP_PROJECTS": ANY,       # 1: projection on, 0: off
    "DENSE_A": 0, "DENSE_B": 0, "DENSE_U": 0, "DENSE_V": 0,
}
LOOP_MODE = SPECIALISED["LOOP_MODE"]
LOOP_PROJECTS = SPECIALISED["LOOP_PROJECTS"]
DENSE_A, DENSE_B, DENSE_U, DENSE_V = (SPECIALISED[k] for k in ("DENSE_A", "DENSE_B", "DENSE_U", "DENSE_V"))


@helper
def uses(dense, a):
    """Whether the coefficient ``a`` of a matrix enters a sum: always when the specialised module
    knows the matrix has no zero (``dense``: LLVM folds the test away; a test that stays becomes a
    select on the step's critical path, docs/speed.md), else when a ≠ 0."""
    if dense == 1:
        return True
    return isnz(a)


@prim
def dims(A, Y):
    """(s, r, d); a module specialised to one shape returns constants."""
    return A.shape[1], Y.shape[0], Y.shape[1]


@heavy
def lu_factor(M, piv, o, n):
    """LU with partial pivoting, in place, of the block M[o:o+n, o:o+n] (low precision; piv
    holds global row indices); 1 if singular."""
    for k in range(o, o + n):
        p = k
        big = abs(M[k, k])
        for i in range(k + 1, o + n):
            if abs(M[i, k]) > big:
                big = abs(M[i, k])
                p = i
        piv[k] = p
        if big == 0.0:
            return 1
        if p != k:
            for j in range(o, o + n):
                tmp = M[k, j]
                M[k, j] = M[p, j]
                M[p, j] = tmp
        inv = 1.0 / M[k, k]
        for i in range(k + 1, o + n):
            m = M[i, k] * inv
            M[i, k] = m
            if m != 0.0:
                for j in range(k + 1, o + n):
                    M[i, j] -= m * M[k, j]
    return 0


@heavy
def lu_solve(M, piv, b, o, n):
    """b[o:o+n] = (the block M[o:o+n, o:o+n] of :func:`lu_factor`)⁻¹ b[o:o+n]."""
    for k in range(o, o + n):
        p = piv[k]
        if p != k:
            tmp = b[k]
            b[k] = b[p]
            b[p] = tmp
    for i in range(o, o + n):
        acc = b[i]
        for j in range(o, i):
            acc -= M[i, j] * b[j]
        b[i] = acc
    for i in range(o + n - 1, o - 1, -1):
        acc = b[i]
        for j in range(i + 1, o + n):
            acc -= M[i, j] * b[j]
        b[i] = acc / M[i, i]


@prim
def converged(size, prev, tol, floor):
    """Stop a contracting iteration: the correction is below tol, or Hairer's estimate
    θ/(1 − θ)·‖Δ‖ (θ = ‖Δ‖/‖Δ_prev‖) is, or it stalls (θ ≥ STALL_THETA) at the round-off floor."""
    if size <= tol:
        return True
    if prev <= 0.0:
        return False
    theta = size / prev
    return (theta < 1.0 and theta / (1.0 - theta) * size <= tol) or (theta >= STALL_THETA and size <= floor)


@helper
def combine(h, A, dense, cls, i, F, e, s):
    """h Σⱼ A[cls[e], i, j] F[j, e]: the stage sum of component e (``dense``: A has no zero)."""
    k = cls[e]
    acc = wzero()
    for j in range(s):
        a = g3(A, k, i, j)
        if uses(dense, a):
            acc = wmadd(acc, a, g2(F, j, e))
    return wmul(h, acc)


@prim
def stage_sums(h, A, cls, F, out, s, d):
    for i in range(s):
        for e in range(d):
            p2(out, i, e, combine(h, A, DENSE_A, cls, i, F, e, s))


@helper
def stage_input(Ubar, Z, i, Yst, d):
    for e in range(d):
        p1(Yst, e, wadd(g2(Ubar, i, e), g2(Z, i, e)))


@prim
def eval_stages(Ubar, Z, c, Yst, F, s, d):
    for i in range(s):
        stage_input(Ubar, Z, i, Yst, d)
        f_(Yst, c, F, i)


@prim
def predict(E, Fh, flags, W, s, d):
    """W ≈ the new step's stage derivatives.  With HISTORY steps of them in the ring Fh, each
    stage's sequence extrapolated in n (Σₘ (−1)^(m+1) C(K, m) F⁽ⁿ⁻ᵐ⁾: smooth in n, as the
    stage values of successive steps lie on one curve per stage); before that, the last step's
    extrapolated to the new nodes by E (E[i, j] = ℓⱼ(1 + cᵢ), GNI's start)."""
    k = flags[F_NHIST]
    pos = flags[F_HPOS]                     # the ring's next slot: the newest is pos − 1
    if k >= HISTORY:
        for i in range(s):
            for e in range(d):
                acc = wzero()
                for m in range(HISTORY):
                    slot = pos - 1 - m
                    if slot < 0:
                        slot += HISTORY
                    acc = wmadd(acc, wint(HISTORY_WEIGHTS[m]), g3(Fh, slot, i, e))
                p2(W, i, e, acc)
    else:
        last = pos - 1 if pos > 0 else HISTORY - 1
        for i in range(s):
            for e in range(d):
                acc = wzero()
                for j in range(s):
                    acc = wmadd(acc, g2(E, i, j), g3(Fh, last, j, e))
                p2(W, i, e, acc)


@prim
def can_predict(flags):
    return flags[F_PREDICT] == 1 and (flags[F_NHIST] >= HISTORY or (flags[F_NHIST] > 0 and flags[F_HAS_E] == 1))


@prim
def keep(F, Fh, flags, s, d):
    """Push the step's stage derivatives into the ring Fh."""
    pos = flags[F_HPOS]
    for i in range(s):
        for e in range(d):
            p3(Fh, pos, i, e, g2(F, i, e))
    flags[F_HPOS] = pos + 1 if pos + 1 < HISTORY else 0
    flags[F_NHIST] = min(flags[F_NHIST] + 1, HISTORY)


@helper
def explicit_stages(method, h, c, stages, stats, s, d):
    """The stages of an explicit method, in order: Yᵢ = Ūᵢ + h Σ_{j<i} aᵢⱼ f(Yⱼ)."""
    A, cls, Ubar, F, Yst = method.A, method.cls, stages.Ubar, stages.F, stages.Yst
    for i in range(s):
        for e in range(d):
            acc = g2(Ubar, i, e)
            k = cls[e]
            for j in range(i):
                a = g3(A, k, i, j)
                if uses(DENSE_A, a):
                    acc = wadd(acc, wmul(wmul(h, a), g2(F, j, e)))
            p1(Yst, e, acc)
        f_(Yst, c, F, i)
    stats[S_NFEV] += s


@heavy
def subtract_block(M, hlo, A, cls, J, i, j, d):
    """M[block i, j] −= h A[cls, i, j] J (block column j of I − h(A ⊗ J), per component class)."""
    for k in range(d):
        w = hlo * wlo(g3(A, cls[k], i, j))
        if w != 0.0:
            for e in range(d):
                M[i * d + k, j * d + e] -= w * wlo(g2(J, k, e))


@heavy
def lower_factor(M, piv, hlo, A, cls, J, s, d):
    """Newton's matrix I − h(A ⊗ J) of a diagonally implicit method (A lower triangular,
    ``flags[F_LOWER]``): only its diagonal blocks I − h A[cls, i, i] J, each factored in place
    at its position (s LUs of size d instead of one of size s·d); 1 if one is singular."""
    for i in range(s):
        o = i * d
        for k in range(d):
            for e in range(d):
                M[o + k, o + e] = 1.0 if k == e else 0.0
        subtract_block(M, hlo, A, cls, J, i, i, d)
        if lu_factor(M, piv, o, d) != 0:
            return 1
    return 0


@heavy
def lower_solve(M, piv, hlo, A, cls, J, R, s, d):
    """R = (I − h(A ⊗ J))⁻¹ R for lower triangular A, by forward block substitution:
    (I − h aᵢᵢ J)Δᵢ = Rᵢ + h Σ_{j<i} aᵢⱼ J Δⱼ, with the blocks of :func:`lower_factor`."""
    for j in range(s):
        o = j * d
        lu_solve(M, piv, R, o, d)
        if j + 1 < s:
            for k in range(d):
                acc = 0.0
                for e in range(d):
                    acc += wlo(g2(J, k, e)) * R[o + e]
                for i in range(j + 1, s):
                    w = hlo * wlo(g3(A, cls[k], i, j))
                    if w != 0.0:
                        R[i * d + k] += w * acc


@heavy
def identity(M, n):
    for a in range(n):
        for b in range(n):
            M[a, b] = 1.0 if a == b else 0.0


@prim
def stage_derivatives(method, hinv, c, st, stages, s, d):
    """f(Yᵢ) of converged stages Y = Ū + Z: A⁻¹Z/h when A is invertible, else evaluated."""
    if st.flags[F_HAS_INV] == 1:
        stage_sums(hinv, method.Ainv, method.cls, stages.Z, stages.F, s, d)
    else:
        eval_stages(stages.Ubar, stages.Z, c, stages.Yst, stages.F, s, d)
        st.stats[S_NFEV] += s
    keep(stages.F, st.Fh, st.flags, s, d)


@helper
def jacobian_amplification(hA, c, stages, d):
    """J = f′(Ū₁) into stages.J; returns 1 + h‖A‖·max|Jₖₑ|, the factor by which the stage
    system's conditioning amplifies round-off (the stall test's floor)."""
    Ubar, Yst, J = stages.Ubar, stages.Yst, stages.J
    for e in range(d):
        p1(Yst, e, g2(Ubar, 0, e))
    jac_(Yst, c, J)
    jmax = 0.0
    for k in range(d):
        for e in range(d):
            jmax = max(jmax, abs(wlo(g2(J, k, e))))
    return 1.0 + hA * jmax


@helper
def newton_factor(lower, hlo, method, stages, s, d):
    """Factor simplified Newton's matrix I − h(A ⊗ J) in place (stages.M, stages.piv): its
    diagonal blocks for a lower triangular A (:func:`lower_factor`), else the whole; 1 if
    singular."""
    A, cls, J, M, piv = method.A, method.cls, stages.J, stages.M, stages.piv
    if lower:
        return lower_factor(M, piv, hlo, A, cls, J, s, d)
    identity(M, s * d)
    for i in range(s):
        for j in range(s):
            subtract_block(M, hlo, A, cls, J, i, j, d)
    return lu_factor(M, piv, 0, s * d)


@helper
def full_newton_factor(hlo, method, c, stages, s, d):
    """Full Newton's matrix, with the Jacobian at each current stage (block column j at Yⱼ),
    factored in place; 1 if singular."""
    A, cls, J, M = method.A, method.cls, stages.J, stages.M
    identity(M, s * d)
    for j in range(s):
        stage_input(stages.Ubar, stages.Z, j, stages.Yst, d)
        jac_(stages.Yst, c, J)
        for i in range(s):
            subtract_block(M, hlo, A, cls, J, i, j, d)
    return lu_factor(M, stages.piv, 0, s * d)


@helper
def stage_start(predicted, method, h, st, stages, s, d):
    """The first iterate of the stage increments: Z = h A W from the predicted stage derivatives
    W (:func:`predict`), or Z = 0."""
    if predicted:
        predict(method.E, st.Fh, st.flags, stages.W, s, d)
        stage_sums(h, method.A, method.cls, stages.W, stages.Z, s, d)
    else:
        for i in range(s):
            for e in range(d):
                p2(stages.Z, i, e, wzero())


@helper
def newton_sweep(mode, lower, hlo, method, h, c, stages, stats, s, d):
    """One sweep of :func:`newton_stages`: the residual R = h A F(Ū + Z) − Z solved with the
    factored matrix (none for ``FIXED``) and added to Z.  Returns (status, ‖ΔZ‖, ‖Z‖): status 0,
    1 (full Newton's matrix singular) or 2 (a correction is not finite)."""
    Z, R = stages.Z, stages.R
    eval_stages(stages.Ubar, Z, c, stages.Yst, stages.F, s, d)
    stats[S_NFEV] += s
    if mode == FULL and full_newton_factor(hlo, method, c, stages, s, d) != 0:
        return 1, 0.0, 0.0
    stage_sums(h, method.A, method.cls, stages.F, stages.W, s, d)
    for i in range(s):
        for e in range(d):
            R[i * d + e] = wlo(wsub(g2(stages.W, i, e), g2(Z, i, e)))
    if lower:
        lower_solve(stages.M, stages.piv, hlo, method.A, method.cls, stages.J, R, s, d)
    elif mode != FIXED:
        lu_solve(stages.M, stages.piv, R, 0, s * d)
    stats[S_SWEEPS] += 1
    size = 0.0
    zn = 0.0
    finite = True
    for i in range(s):
        for e in range(d):
            dz = R[i * d + e]
            if not lofinite(dz):
                finite = False
            z = waddlo(g2(Z, i, e), dz)
            p2(Z, i, e, z)
            size = max(size, abs(dz))
            zn = max(zn, abs(wlo(z)))
    return (0 if finite else 2), size, zn


@helper
def newton_stages(mode, method, ctl, c, st, stages, s, d):
    """Simplified Newton (``NEWTON``), fixed point (``FIXED``: M = I) or full Newton (``FULL``)
    on the stage increments Z; 0 when converged (F holds the stage derivatives), else 1."""
    hlo = wlo(ctl.h)
    amp = 1.0
    if mode != FIXED:                       # round-off amplified by the stage system's conditioning
        amp = jacobian_amplification(ctl.hA, c, stages, d)
    lower = mode == NEWTON and st.flags[F_LOWER] == 1
    if mode == NEWTON and newton_factor(lower, hlo, method, stages, s, d) != 0:
        return 1
    scale = 0.0
    for i in range(s):
        for e in range(d):
            scale = max(scale, abs(wlo(g2(stages.Ubar, i, e))))
    scale += 1.0
    floor = ROUNDOFF_FLOOR * ctl.eps * scale * amp
    predicted = mode != FULL and can_predict(st.flags)
    sweeps = FULL_NEWTON_SWEEPS if mode == FULL else STAGE_SWEEPS
    for attempt in range(2 if predicted else 1):
        stage_start(attempt == 0 and predicted, method, ctl.h, st, stages, s, d)
        prev = -1.0
        for it in range(sweeps):
            status, size, zn = newton_sweep(mode, lower, hlo, method, ctl.h, c, stages, st.stats, s, d)
            if status == 1:
                return 1
            if status == 2:
                break
            # to an ulp of the increments: A⁻¹Z/h passes Z's error to the output unscaled by h
            if converged(size, prev, ctl.eps * zn, floor):
                stage_derivatives(method, ctl.hinv, c, st, stages, s, d)
                return 0
            if prev >= 0.0 and it > DIVERGE_AFTER and size > prev:
                break                       # diverging
            prev = size
    return 1


@helper
def advance(h, A, cls, k, F, Ubar, Z, s, d):
    """Z[i, e] = h Σⱼ A[k, i, j] F[j, e] for the components e of class k (0: q, 1: p); returns the
    largest change of Z and the largest stage value |Ū + Z| of that class."""
    change = 0.0
    size = 0.0
    for i in range(s):
        for e in range(d):
            if cls[e] == k:
                z = combine(h, A, DENSE_A, cls, i, F, e, s)
                change = max(change, abs(wlo(wsub(z, g2(Z, i, e)))))
                p2(Z, i, e, z)
                size = max(size, abs(wlo(wadd(g2(Ubar, i, e), z))))
    return change, size


@helper
def velocities_at_stages(stages, c, s, d):
    """The q-rates ∂T/∂p (:func:`fq_`) at each stage Ū + Z into F."""
    for j in range(s):
        stage_input(stages.Ubar, stages.Z, j, stages.Yst, d)
        fq_(stages.Yst, c, stages.F, j)


@helper
def forces_at_stages(stages, c, s, d):
    """The p-rates −∂V/∂q (:func:`fp_`) at each stage Ū + Z into F."""
    for j in range(s):
        stage_input(stages.Ubar, stages.Z, j, stages.Yst, d)
        fp_(stages.Yst, c, stages.F, j)


@helper
def split_stages(method, ctl, c, st, stages, s, d):
    """Fixed point on the q stages of a separable problem (``SPLIT``, module docstring); 0 when
    converged (F holds the stage derivatives of the last sweep), else 1."""
    h, A, cls, Ubar, F, Z, stats = ctl.h, method.A, method.cls, stages.Ubar, stages.F, stages.Z, st.stats
    for i in range(s):
        for e in range(d):
            p2(Z, i, e, wzero())
    if can_predict(st.flags):
        predict(method.E, st.Fh, st.flags, stages.W, s, d)  # forces predicted → p stages → velocities → q
        advance(h, A, cls, 1, stages.W, Ubar, Z, s, d)
        velocities_at_stages(stages, c, s, d)
        stats[S_NVEL] += s
        advance(h, A, cls, 0, F, Ubar, Z, s, d)
    prev = -1.0
    for it in range(STAGE_SWEEPS):
        forces_at_stages(stages, c, s, d)           # forces at the q stages
        stats[S_NFEV] += s
        dp, pn = advance(h, A, cls, 1, F, Ubar, Z, s, d)     # the p stages
        velocities_at_stages(stages, c, s, d)           # velocities at the p stages
        stats[S_NVEL] += s
        stats[S_SWEEPS] += 1
        size, qn = advance(h, A, cls, 0, F, Ubar, Z, s, d)   # the new q stages
        if not lofinite(size):
            return 1
        # F was evaluated at the iterate before this correction: stop when the corrections of the
        # q stages and of the p stages (the forces' effect: stiff springs) are at round-off
        # (GNI's test on the iterates), not when the next is estimated to be (Hairer's θ test)
        if (size <= SPLIT_TOL_ULPS * ctl.eps * qn and dp <= SPLIT_TOL_ULPS * ctl.eps * pn) or (
                prev > 0.0 and size >= STALL_THETA * prev and size <= ROUNDOFF_FLOOR * ctl.eps * qn):
            keep(F, st.Fh, st.flags, s, d)
            return 0
        if prev >= 0.0 and it > DIVERGE_AFTER and size > prev:
            return 1
        prev = size
    return 1


@kernel
def rescue_stages(method, ctl, c, st, stages, s, d):
    """The last resort: fixed point on the stage values from Ū, tolerance ``ctl.tol``."""
    Ubar, F, Z, W, Yst, stats = stages.Ubar, stages.F, stages.Z, stages.W, stages.Yst, st.stats
    for i in range(s):
        for e in range(d):
            p2(Z, i, e, wzero())
    eval_stages(Ubar, Z, c, Yst, F, s, d)
    stats[S_NFEV] += s
    prev = -1.0
    for _ in range(RESCUE_SWEEPS):
        stage_sums(ctl.h, method.A, method.cls, F, W, s, d)
        size = 0.0
        yn = 0.0
        for i in range(s):
            for e in range(d):
                size = max(size, abs(wlo(wsub(g2(W, i, e), g2(Z, i, e)))))
                p2(Z, i, e, g2(W, i, e))
                yn = max(yn, abs(wlo(wadd(g2(Ubar, i, e), g2(W, i, e)))))
        stats[S_LAST] = size
        if not lofinite(size):
            return 1
        eval_stages(Ubar, Z, c, Yst, F, s, d)
        stats[S_NFEV] += s
        scale = 1.0 + yn
        if size <= ctl.tol * scale or (prev >= 0.0 and size >= STALL_THETA * prev
                                       and size <= ROUNDOFF_FLOOR * ctl.eps * scale):
            keep(F, st.Fh, st.flags, s, d)
            return 0
        prev = size
    return 1


@helper
def primary_stages(method, ctl, c, st, stages, s, d):
    """The stage equations of one step by the run's iteration; 0, or 1 (the step is then redone
    by :func:`rescue_step`, outside the loop: a call site in the loop would cost every step)."""
    if LOOP_MODE == SPLIT or (LOOP_MODE == ANY and st.flags[F_MODE] == SPLIT):
        return split_stages(method, ctl, c, st, stages, s, d)
    if LOOP_MODE == ANY:
        return newton_stages(st.flags[F_MODE], method, ctl, c, st, stages, s, d)
    return newton_stages(LOOP_MODE, method, ctl, c, st, stages, s, d)


@kernel
def fallback_stages(method, ctl, c, st, stages, s, d):
    """A step whose first iteration failed: simplified Newton (the run switches to it after
    SWITCH_AFTER such steps), full Newton, then fixed point on the stage values; 0 or 1."""
    flags, stats = st.flags, st.stats
    mode = flags[F_MODE]
    stats[S_FALLBACKS] += 1
    flags[F_NHIST] = 0                      # restart the prediction
    if flags[F_HAS_JAC] == 1:
        if mode != NEWTON and stats[S_FALLBACKS] >= SWITCH_AFTER:
            flags[F_MODE] = NEWTON          # stiff along the solution: Newton from now on
        for attempt in range(2):            # simplified Newton (unless it just failed), full Newton
            fallback = NEWTON if attempt == 0 else FULL
            if fallback == NEWTON and mode == NEWTON:
                continue
            if newton_stages(fallback, method, ctl, c, st, stages, s, d) == 0:
                return 0
    return rescue_stages(method, ctl, c, st, stages, s, d)


@prim
def gram(P, Q, out, m, d):
    """out = P Qᵀ in low precision (m × m)."""
    for a in range(m):
        for b in range(m):
            acc = 0.0
            for e in range(d):
                acc += wlo(g2(P, a, e)) * wlo(g2(Q, b, e))
            out[a, b] = acc


@prim
def accept(y, z, stats, its, d):
    """y = z, the projected point, after ``its`` sweeps; 0."""
    for e in range(d):
        p1(y, e, g1(z, e))
    stats[S_PROJ] += its
    return 0


@helper
def term_scale(y, target, G, lam, m, d):
    """1 + the largest size of an invariant's terms, |I_k| + Σₑ |∂I_k/∂y_e · y_e| (the scale
    of the projection's residual); λ = 0."""
    tscale = 0.0
    for k in range(m):
        terms = abs(wlo(g1(target, k)))
        for e in range(d):
            terms += abs(wlo(g2(G, k, e)) * wlo(g1(y, e)))
        tscale = max(tscale, terms)
        p1(lam, k, wzero())
    return tscale + 1.0


@helper
def invariant_residual(z, inv, tmp, g, m):
    """g = I(z) − I(y₀) (low precision) of the projected invariants; returns max |g_k|."""
    res = 0.0
    for k in range(m):
        inv_(inv.proj[k], z, inv.c, tmp)
        g[k] = wlo(wsub(g1(tmp, 0), g1(inv.target, k)))
        res = max(res, abs(g[k]))
    return res


@helper
def move_point(y, G, lam, g, z, m, d):
    """λ −= the Newton correction g; z = y + ∇g(y)λ."""
    for k in range(m):
        p1(lam, k, waddlo(g1(lam, k), -g[k]))
    for e in range(d):
        acc = g1(y, e)
        for k in range(m):
            acc = wmadd(acc, g2(G, k, e), g1(lam, k))
        p1(z, e, acc)


@kernel
def project(y, inv, ctl, work, stats):
    """y + ∇g(y)λ with g = invariants − targets, Newton on λ (matrix ∇g(z)ᵀ∇g(y), refreshed
    each sweep); 0, or 1 (stats[S_PROJ_RES]: the residual).  Converged when g is at ``tol``
    relative to the size of the invariants' terms |I| + Σ|∂I/∂y_e · y_e| (FPU: ω²q² terms of a
    small H), or when the corrections stop shrinking with g already at round-off level."""
    G, Gz, GtG, gpiv, g, lam, z = work.G, work.Gz, work.GtG, work.gpiv, work.g, work.lam, work.z
    d = y.shape[0]
    m = inv.proj.shape[0]
    for k in range(m):
        grad_(inv.proj[k], y, inv.c, G, k)
    gram(G, G, GtG, m, d)
    if lu_factor(GtG, gpiv, 0, m) != 0:
        return 1
    tscale = term_scale(y, inv.target, G, lam, m, d)
    for e in range(d):
        p1(z, e, g1(y, e))
    prev = -1.0
    res = 0.0
    for it in range(PROJECTION_SWEEPS):
        res = invariant_residual(z, inv, work.tmp, g, m) / tscale
        if res <= ctl.tol:
            return accept(y, z, stats, it, d)
        if it > 0:                          # Newton on λ: ∇g(z)ᵀ G at the current point
            for a in range(m):
                grad_(inv.proj[a], z, inv.c, Gz, a)
            gram(Gz, G, GtG, m, d)
            if lu_factor(GtG, gpiv, 0, m) != 0:
                return 1
        lu_solve(GtG, gpiv, g, 0, m)
        step = 0.0
        for k in range(m):
            step = max(step, abs(g[k]))
        if prev >= 0.0 and step >= PROJECTION_STALL * prev and res <= PROJECTION_ROUNDOFF * ctl.eps:
            return accept(y, z, stats, it, d)
        prev = step
        move_point(y, G, lam, g, z, m, d)
    if res <= PROJECTION_ACCEPT * ctl.eps:     # round-off noise of a large-term invariant, not divergence
        return accept(y, z, stats, PROJECTION_SWEEPS, d)
    stats[S_PROJ_RES] = res
    return 1


@helper
def row_times(M, dense, i, Y, e, r):
    """Σₖ M[i, k] Y[k, e] (zero coefficients skipped): U y^[n−1] and V y^[n−1]."""
    acc = wzero()
    for k in range(r):
        m = g2(M, i, k)
        if uses(dense, m):
            acc = wmadd(acc, m, g2(Y, k, e))
    return acc


@helper
def stage_inputs(U, Y, Ubar, s, r, d):
    """Ū = U y^[n−1]."""
    for i in range(s):
        for e in range(d):
            p2(Ubar, i, e, row_times(U, DENSE_U, i, Y, e, r))


@helper
def finish_step(method, ctl, inv, st, stages, work, s, r, d):
    """y^[n] = V y^[n−1] + h B F (Kahan on the principal value), projection; 0, 2 (not finite)
    or 3 (projection failed)."""
    Y, comp, Yout, yfirst = st.Y, st.comp, stages.Yout, work.yfirst
    for k in range(r):
        for e in range(d):
            acc = row_times(method.V, DENSE_V, k, Y, e, r)
            x = combine(ctl.h, method.B, DENSE_B, method.cls, k, stages.F, e, s)
            if k == 0 and st.flags[F_COMPENSATE] == 1:     # Kahan: y₁ + (increment + carry)
                x = wadd(x, g1(comp, e))
                y1 = wadd(acc, x)
                p1(comp, e, wadd(wsub(acc, y1), x))
                p2(Yout, k, e, y1)
            else:
                p2(Yout, k, e, wadd(acc, x))
    for k in range(r):
        for e in range(d):
            p2(Y, k, e, g2(Yout, k, e))
    if LOOP_PROJECTS == 1 or (LOOP_PROJECTS == ANY and inv.proj.shape[0] > 0):
        for e in range(d):
            p1(yfirst, e, g2(Y, 0, e))
        if project(yfirst, inv, ctl, work, st.stats) != 0:
            return 3
        for e in range(d):
            p2(Y, 0, e, g1(yfirst, e))
    for k in range(r):
        for e in range(d):
            if not lofinite(wlo(g2(Y, k, e))):
                return 2
    return 0


@prim
def observe(inv, tmax, Y, tmp, yfirst, d):
    """The largest |I_k(y^[n]₁) − I_k(y₀)| so far of the invariants in ``inv.track``."""
    for e in range(d):
        p1(yfirst, e, g2(Y, 0, e))
    for k in range(inv.track.shape[0]):
        inv_(inv.track[k], yfirst, inv.c, tmp)
        tmax[k] = max(tmax[k], abs(wlo(wsub(g1(tmp, 0), g1(inv.ttarget, k)))))


@prim
def after_step(n, track_due, record_due, inv, st, work, nrec, r, d):
    """The invariants tracked and the record kept, where due after step n; the records so far."""
    st.stats[S_DONE] = n
    if track_due and inv.track.shape[0] > 0:
        observe(inv, st.tmax, st.Y, work.tmp, work.yfirst, d)
    if record_due:
        for k in range(r):
            for e in range(d):
                p3(st.rec, nrec, k, e, g2(st.Y, k, e))
        st.recn[nrec] = n
        nrec += 1
        st.stats[S_NREC] = nrec
    return nrec


@helper
def fits(method, st, stages, s, r, d):
    """Whether the loop's arrays have the shapes that (s, r, d) give them.  In a module specialised
    to one shape (s, r, d constants) this test also tells LLVM the arrays' row lengths: numba
    indexes a row-major array through its shape, which LLVM otherwise takes for an unknown, so it
    cannot tell a store to F[1, e] from F[0, e] and reloads every stage value after every store
    (the C loop's static arrays have constant rows).  After the test the shape is that constant."""
    A, U, B, V, E, Ainv, Y, Fh = method.A, method.U, method.B, method.V, method.E, method.Ainv, st.Y, st.Fh
    Ubar, F, Z, W, Yst, J, M, piv, R, Yout = stages
    sd = s * d
    return (Y.shape[0] == r and Y.shape[1] == d and Yout.shape[0] == r and Yout.shape[1] == d
            and Ubar.shape[0] == s and Ubar.shape[1] == d and F.shape[0] == s and F.shape[1] == d
            and Z.shape[0] == s and Z.shape[1] == d and W.shape[0] == s and W.shape[1] == d
            and Yst.shape[0] == d and st.comp.shape[0] == d and J.shape[0] == d and J.shape[1] == d
            and M.shape[0] == sd and M.shape[1] == sd and piv.shape[0] == sd and R.shape[0] == sd
            and A.shape[0] == 2 and A.shape[1] == s and A.shape[2] == s
            and Ainv.shape[0] == 2 and Ainv.shape[1] == s and Ainv.shape[2] == s
            and B.shape[0] == 2 and B.shape[1] == r and B.shape[2] == s and U.shape[0] == s and U.shape[1] == r
            and V.shape[0] == r and V.shape[1] == r and E.shape[0] == s and E.shape[1] == s
            and Fh.shape[0] == HISTORY and Fh.shape[1] == s and Fh.shape[2] == d)


@alloc
def workspace(s, r, d, m):
    """The loop's arrays (:class:`Stages`: stage values and derivatives, Newton matrix;
    :class:`Projection`), allocated by the caller once per run: the compiled loop runs without
    numba's reference counting."""
    stages = Stages(wmat(s, d), wmat(s, d), wmat(s, d), wmat(s, d), wvec(d), wmat(d, d), lomat(s * d, s * d),
                    np.zeros(s * d, np.int64), lovec(s * d), wmat(r, d))
    projection = Projection(wmat(m, d), wmat(m, d), lomat(m, m), np.zeros(m, np.int64), lovec(m), wvec(m), wvec(d),
                            wvec(1), wvec(d))
    return stages, projection


@kernel
def run(span, st, method, ctl, inv, stages, work):
    """Steps span.n0+1 … span.n1 of span.steps; records of Y every ``span.every`` steps (and at
    the last) into st.rec/st.recn (st.stats[S_NREC] of them); the largest |I_k(y^[n]₁) − I_k(y₀)|
    of the invariants in ``inv.track`` every ``span.track_every`` steps into st.tmax.  Returns the
    status (module docstring), or 4: the stage iteration failed at step st.stats[S_STEP] (Y is
    y^[n−1]), for :func:`rescue_step`.  ``stages``, ``work``: the arrays of :func:`workspace`
    (the loop allocates nothing).  The arguments are the records above (:class:`Span` …)."""
    s, r, d = dims(method.A, st.Y)
    if not fits(method, st, stages, s, r, d):
        return MISFIT
    stats, steps, every, track_every = st.stats, span.steps, span.every, span.track_every
    nrec = 0
    to_record = every - span.n0 % every          # countdowns: no division per step
    to_track = track_every - span.n0 % track_every
    stats[S_NREC] = 0
    for n in range(span.n0 + 1, span.n1 + 1):
        stats[S_STEP] = n
        stage_inputs(method.U, st.Y, stages.Ubar, s, r, d)
        if LOOP_MODE == EXPLICIT or (LOOP_MODE == ANY and st.flags[F_EXPLICIT] == 1):
            explicit_stages(method, ctl.h, inv.c, stages, stats, s, d)
        elif primary_stages(method, ctl, inv.c, st, stages, s, d) != 0:
            stats[S_NREC] = nrec
            return 4
        status = finish_step(method, ctl, inv, st, stages, work, s, r, d)
        if status != 0:
            stats[S_NREC] = nrec
            return status
        to_track -= 1
        to_record -= 1
        track_due, record_due = to_track == 0 or n == steps, to_record == 0 or n == steps
        if track_due:
            to_track = track_every
        if record_due:
            to_record = every
        nrec = after_step(n, track_due, record_due, inv, st, work, nrec, r, d)
    return 0


@kernel
def rescue_step(span, st, method, ctl, inv, stages, work):
    """Step n = span.n1 (= span.n0 + 1; :func:`run`'s arguments) after the loop's stage iteration
    failed on it (:func:`fallback_stages`): 0, or the status of :func:`run`; its record (if due)
    into rec[0]."""
    s, r, d = dims(method.A, st.Y)
    if not fits(method, st, stages, s, r, d):
        return MISFIT
    n = span.n1
    st.stats[S_NREC] = 0
    stage_inputs(method.U, st.Y, stages.Ubar, s, r, d)
    if fallback_stages(method, ctl, inv.c, st, stages, s, d) != 0:
        return 1
    status = finish_step(method, ctl, inv, st, stages, work, s, r, d)
    if status != 0:
        return status
    after_step(n, n % span.track_every == 0 or n == span.steps, n % span.every == 0 or n == span.steps, inv, st,
               work, 0, r, d)
    return 0


# The compiled loop's functions, in the order :mod:`kernels` writes them into a generated module
# (each one's source taken whole: one definition of the step, the pure loop runs these objects).
LOOP = (uses, dims, lu_factor, lu_solve, converged, combine, stage_sums, stage_input, eval_stages, predict,
        can_predict, keep, explicit_stages, subtract_block, lower_factor, lower_solve, identity, stage_derivatives,
        jacobian_amplification, newton_factor, full_newton_factor, stage_start, newton_sweep, newton_stages,
        advance, velocities_at_stages, forces_at_stages, split_stages, rescue_stages, primary_stages,
        fallback_stages, gram, accept, term_scale, invariant_residual, move_point, project, row_times,
        stage_inputs, finish_step, observe, after_step, fits, workspace, run, rescue_step)
