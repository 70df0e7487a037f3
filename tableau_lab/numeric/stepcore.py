r"""The step loop, written once for every precision ([B16] ch. 5 for the GLM step; Hairer,
Lubich & Wanner, *Geometric Numerical Integration*, 2nd ed. [HLW06], Sec. VIII.6 for the stage
iteration, VII.1 and the seed's §3.2 for projection).

A step of the partitioned GLM of :mod:`export` on y′ = f(y), input y^[n−1] (r × d):

    Yᵢ = Σₖ Uᵢₖ y^[n−1]ₖ + h Σⱼ A[cls(l)]ᵢⱼ f(Yⱼ)      (component l; cls = 0 for q, 1 for p)
    y^[n]ₖ = Σₗ Vₖₗ y^[n−1]ₗ + h Σⱼ B[cls(l)]ₖⱼ f(Yⱼ)

The functions below are plain Python over scalars and small arrays.  The arithmetic is not
theirs: ``wadd``, ``wmul``, ``g2``, ``wlo`` … come from an arithmetic module (:mod:`ops_f64`,
:mod:`ops_dd`, :mod:`ops_mp`), and the problem's functions ``f_``, ``jac_``, ``inv_``,
``grad_``, ``fq_``, ``fp_`` are bound per problem.  :mod:`kernels` copies this file, one
arithmetic module and the problem's generated functions into one module that numba compiles
(float64, double-double), or executes it as it is with Python wrappers of the problem (the pure
loop: the reference, and mpmath at any precision).  ``dims`` is replaced by constants in a
module specialised to one method shape (s, r, d), so that the small loops unroll, and a
specialised module sets ``LOOP_MODE`` and ``LOOP_PROJECTS`` (the run's stage iteration, its
projection) and which of the method's matrices have no zero, ``DENSE_A`` … (:func:`uses`):
numba prunes the branches these decide before it compiles, so a fixed-point loop holds no Newton
code and a loop without projection no projection (a third of the compile time and of the code).
The decorators (:mod:`jit`) say how numba compiles each function: ``kernel`` (an entry point,
without reference counting: nothing here allocates; its arrays do not alias), ``helper`` (inlined into its caller by LLVM), ``prim`` (small, left to LLVM to inline), ``heavy``
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
from .ops_f64 import *  # noqa: F401,F403 -- the arithmetic; kernels.py binds one per precision
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


def f_(y, c, out, i):
    """f(y) → row i of out (bound per problem)."""
    raise NotImplementedError


def jac_(y, c, out):
    """f′(y) → out (d × d)."""
    raise NotImplementedError


def fq_(y, c, out, i):
    """The q-rate ∂T/∂p of a separable problem → out[i, l] for the q components (reads p only)."""
    raise NotImplementedError


def fp_(y, c, out, i):
    """The p-rate −∂V/∂q of a separable problem → out[i, l] for the p components (reads q only)."""
    raise NotImplementedError


def inv_(k, y, c, out):
    """The k-th invariant of the run → out[0]."""
    raise NotImplementedError


def grad_(k, y, c, out, i):
    """Its gradient → row i of out."""
    raise NotImplementedError


# ---- core ----

# A compiled module specialised to one run's kind (:func:`kernels.module_source`) sets these
# after this text; numba prunes the branches they decide before compiling (the Newton code of a
# fixed-point loop, the projection of a run without it are never compiled).  ANY: the flags decide.
LOOP_MODE = ANY         # EXPLICIT, NEWTON, FIXED or SPLIT
LOOP_PROJECTS = ANY     # 1: projection on, 0: off
# Which of the method's matrices have no zero entry (both classes), set by a module specialised
# to one method (:func:`kernels.dense_matrices`): their coefficients are used without a
# test in the step; the others' (all, here: nothing known) are tested for zero when it runs.
DENSE_A = DENSE_B = DENSE_U = DENSE_V = 0


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
def combine(h, A, dense, cls, i, F, l, s):
    """h Σⱼ A[cls[l], i, j] F[j, l]: the stage sum of component l (``dense``: A has no zero)."""
    k = cls[l]
    acc = wzero()
    for j in range(s):
        a = g3(A, k, i, j)
        if uses(dense, a):
            acc = wmadd(acc, a, g2(F, j, l))
    return wmul(h, acc)


@prim
def stage_sums(h, A, cls, F, out, s, d):
    for i in range(s):
        for l in range(d):
            p2(out, i, l, combine(h, A, DENSE_A, cls, i, F, l, s))


@helper
def stage_input(Ubar, Z, i, Yst, d):
    for l in range(d):
        p1(Yst, l, wadd(g2(Ubar, i, l), g2(Z, i, l)))


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
            for l in range(d):
                acc = wzero()
                for m in range(HISTORY):
                    slot = pos - 1 - m
                    if slot < 0:
                        slot += HISTORY
                    acc = wmadd(acc, wint(HISTORY_WEIGHTS[m]), g3(Fh, slot, i, l))
                p2(W, i, l, acc)
    else:
        last = pos - 1 if pos > 0 else HISTORY - 1
        for i in range(s):
            for l in range(d):
                acc = wzero()
                for j in range(s):
                    acc = wmadd(acc, g2(E, i, j), g3(Fh, last, j, l))
                p2(W, i, l, acc)


@prim
def can_predict(flags):
    return flags[F_PREDICT] == 1 and (flags[F_NHIST] >= HISTORY or (flags[F_NHIST] > 0 and flags[F_HAS_E] == 1))


@prim
def keep(F, Fh, flags, s, d):
    """Push the step's stage derivatives into the ring Fh."""
    pos = flags[F_HPOS]
    for i in range(s):
        for l in range(d):
            p3(Fh, pos, i, l, g2(F, i, l))
    flags[F_HPOS] = pos + 1 if pos + 1 < HISTORY else 0
    flags[F_NHIST] = min(flags[F_NHIST] + 1, HISTORY)


@helper
def explicit_stages(Ubar, h, A, cls, c, Yst, F, stats, s, d):
    for i in range(s):
        for l in range(d):
            acc = g2(Ubar, i, l)
            k = cls[l]
            for j in range(i):
                a = g3(A, k, i, j)
                if uses(DENSE_A, a):
                    acc = wadd(acc, wmul(wmul(h, a), g2(F, j, l)))
            p1(Yst, l, acc)
        f_(Yst, c, F, i)
    stats[S_NFEV] += s


@heavy
def subtract_block(M, hlo, A, cls, J, i, j, d):
    """M[block i, j] −= h A[cls, i, j] J (block column j of I − h(A ⊗ J), per component class)."""
    for k in range(d):
        w = hlo * wlo(g3(A, cls[k], i, j))
        if w != 0.0:
            for l in range(d):
                M[i * d + k, j * d + l] -= w * wlo(g2(J, k, l))


@heavy
def lower_factor(M, piv, hlo, A, cls, J, s, d):
    """Newton's matrix I − h(A ⊗ J) of a diagonally implicit method (A lower triangular,
    ``flags[F_LOWER]``): only its diagonal blocks I − h A[cls, i, i] J, each factored in place
    at its position (s LUs of size d instead of one of size s·d); 1 if one is singular."""
    for i in range(s):
        o = i * d
        for k in range(d):
            for l in range(d):
                M[o + k, o + l] = 1.0 if k == l else 0.0
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
                for l in range(d):
                    acc += wlo(g2(J, k, l)) * R[o + l]
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
def stage_derivatives(Ubar, hinv, Ainv, cls, c, flags, Z, Yst, F, Fh, stats, s, d):
    """f(Yᵢ) of converged stages Y = Ū + Z: A⁻¹Z/h when A is invertible, else evaluated."""
    if flags[F_HAS_INV] == 1:
        stage_sums(hinv, Ainv, cls, Z, F, s, d)
    else:
        eval_stages(Ubar, Z, c, Yst, F, s, d)
        stats[S_NFEV] += s
    keep(F, Fh, flags, s, d)


@helper
def newton_stages(mode, Ubar, h, hinv, A, Ainv, cls, E, flags, c, eps, hA, Fh, F, Z, Yst, J, M, piv, R, W,
                  stats, s, d):
    """Simplified Newton (``NEWTON``), fixed point (``FIXED``: M = I) or full Newton (``FULL``)
    on the stage increments Z; 0 when converged (F holds the stage derivatives), else 1."""
    sd = s * d
    hlo = wlo(h)
    amp = 1.0
    if mode != FIXED:                       # round-off amplified by the stage system's conditioning
        for l in range(d):
            p1(Yst, l, g2(Ubar, 0, l))
        jac_(Yst, c, J)
        jmax = 0.0
        for k in range(d):
            for l in range(d):
                jmax = max(jmax, abs(wlo(g2(J, k, l))))
        amp = 1.0 + hA * jmax
    lower = mode == NEWTON and flags[F_LOWER] == 1
    if mode == NEWTON:
        if lower:
            if lower_factor(M, piv, hlo, A, cls, J, s, d) != 0:
                return 1
        else:
            identity(M, sd)
            for i in range(s):
                for j in range(s):
                    subtract_block(M, hlo, A, cls, J, i, j, d)
            if lu_factor(M, piv, 0, sd) != 0:
                return 1
    scale = 0.0
    for i in range(s):
        for l in range(d):
            scale = max(scale, abs(wlo(g2(Ubar, i, l))))
    scale += 1.0
    predicted = mode != FULL and can_predict(flags)
    sweeps = FULL_NEWTON_SWEEPS if mode == FULL else STAGE_SWEEPS
    for attempt in range(2 if predicted else 1):
        if attempt == 0 and predicted:
            predict(E, Fh, flags, W, s, d)
            stage_sums(h, A, cls, W, Z, s, d)
        else:
            for i in range(s):
                for l in range(d):
                    p2(Z, i, l, wzero())
        prev = -1.0
        for it in range(sweeps):
            eval_stages(Ubar, Z, c, Yst, F, s, d)
            stats[S_NFEV] += s
            if mode == FULL:                # Jacobians at the current stages
                identity(M, sd)
                for j in range(s):
                    stage_input(Ubar, Z, j, Yst, d)
                    jac_(Yst, c, J)
                    for i in range(s):
                        subtract_block(M, hlo, A, cls, J, i, j, d)
                if lu_factor(M, piv, 0, sd) != 0:
                    return 1
            stage_sums(h, A, cls, F, W, s, d)
            for i in range(s):
                for l in range(d):
                    R[i * d + l] = wlo(wsub(g2(W, i, l), g2(Z, i, l)))
            if lower:
                lower_solve(M, piv, hlo, A, cls, J, R, s, d)
            elif mode != FIXED:
                lu_solve(M, piv, R, 0, sd)
            stats[S_SWEEPS] += 1
            size = 0.0
            zn = 0.0
            finite = True
            for i in range(s):
                for l in range(d):
                    dz = R[i * d + l]
                    if not lofinite(dz):
                        finite = False
                    z = waddlo(g2(Z, i, l), dz)
                    p2(Z, i, l, z)
                    size = max(size, abs(dz))
                    zn = max(zn, abs(wlo(z)))
            if not finite:
                break
            # to an ulp of the increments: A⁻¹Z/h passes Z's error to the output unscaled by h
            if converged(size, prev, eps * zn, ROUNDOFF_FLOOR * eps * scale * amp):
                stage_derivatives(Ubar, hinv, Ainv, cls, c, flags, Z, Yst, F, Fh, stats, s, d)
                return 0
            if prev >= 0.0 and it > DIVERGE_AFTER and size > prev:
                break                       # diverging
            prev = size
    return 1


@helper
def advance(h, A, cls, k, F, Ubar, Z, s, d):
    """Z[i, l] = h Σⱼ A[k, i, j] F[j, l] for the components l of class k (0: q, 1: p); returns the
    largest change of Z and the largest stage value |Ū + Z| of that class."""
    change = 0.0
    size = 0.0
    for i in range(s):
        for l in range(d):
            if cls[l] == k:
                z = combine(h, A, DENSE_A, cls, i, F, l, s)
                change = max(change, abs(wlo(wsub(z, g2(Z, i, l)))))
                p2(Z, i, l, z)
                size = max(size, abs(wlo(wadd(g2(Ubar, i, l), z))))
    return change, size


@helper
def split_stages(Ubar, h, A, cls, E, flags, c, eps, Fh, F, Z, Yst, W, stats, s, d):
    """Fixed point on the q stages of a separable problem (``SPLIT``, module docstring); 0 when
    converged (F holds the stage derivatives of the last sweep), else 1."""
    for i in range(s):
        for l in range(d):
            p2(Z, i, l, wzero())
    if can_predict(flags):
        predict(E, Fh, flags, W, s, d)   # forces predicted → p stages → velocities → q stages
        advance(h, A, cls, 1, W, Ubar, Z, s, d)
        for j in range(s):
            stage_input(Ubar, Z, j, Yst, d)
            fq_(Yst, c, F, j)
        stats[S_NVEL] += s
        advance(h, A, cls, 0, F, Ubar, Z, s, d)
    prev = -1.0
    for it in range(STAGE_SWEEPS):
        for j in range(s):                  # forces at the q stages
            stage_input(Ubar, Z, j, Yst, d)
            fp_(Yst, c, F, j)
        stats[S_NFEV] += s
        dp, pn = advance(h, A, cls, 1, F, Ubar, Z, s, d)     # the p stages
        for j in range(s):                  # velocities at the p stages
            stage_input(Ubar, Z, j, Yst, d)
            fq_(Yst, c, F, j)
        stats[S_NVEL] += s
        stats[S_SWEEPS] += 1
        size, qn = advance(h, A, cls, 0, F, Ubar, Z, s, d)   # the new q stages
        if not lofinite(size):
            return 1
        # F was evaluated at the iterate before this correction: stop when the corrections of the
        # q stages and of the p stages (the forces' effect: stiff springs) are at round-off
        # (GNI's test on the iterates), not when the next is estimated to be (Hairer's θ test)
        if (size <= SPLIT_TOL_ULPS * eps * qn and dp <= SPLIT_TOL_ULPS * eps * pn) or (
                prev > 0.0 and size >= STALL_THETA * prev and size <= ROUNDOFF_FLOOR * eps * qn):
            keep(F, Fh, flags, s, d)
            return 0
        if prev >= 0.0 and it > DIVERGE_AFTER and size > prev:
            return 1
        prev = size
    return 1


@kernel
def rescue_stages(Ubar, h, A, cls, c, tol, eps, Fh, F, Z, Yst, W, flags, stats, s, d):
    """The last resort: fixed point on the stage values from Ū, tolerance ``tol``."""
    for i in range(s):
        for l in range(d):
            p2(Z, i, l, wzero())
    eval_stages(Ubar, Z, c, Yst, F, s, d)
    stats[S_NFEV] += s
    prev = -1.0
    for it in range(RESCUE_SWEEPS):
        stage_sums(h, A, cls, F, W, s, d)
        size = 0.0
        yn = 0.0
        for i in range(s):
            for l in range(d):
                size = max(size, abs(wlo(wsub(g2(W, i, l), g2(Z, i, l)))))
                p2(Z, i, l, g2(W, i, l))
                yn = max(yn, abs(wlo(wadd(g2(Ubar, i, l), g2(W, i, l)))))
        stats[S_LAST] = size
        if not lofinite(size):
            return 1
        eval_stages(Ubar, Z, c, Yst, F, s, d)
        stats[S_NFEV] += s
        scale = 1.0 + yn
        if size <= tol * scale or (prev >= 0.0 and size >= STALL_THETA * prev and size <= ROUNDOFF_FLOOR * eps * scale):
            keep(F, Fh, flags, s, d)
            return 0
        prev = size
    return 1


@helper
def primary_stages(Ubar, h, hinv, A, Ainv, cls, E, flags, c, eps, hA, Fh, F, Z, Yst, J, M, piv, R, W, stats, s, d):
    """The stage equations of one step by the run's iteration; 0, or 1 (the step is then redone
    by :func:`rescue_step`, outside the loop: a call site in the loop would cost every step)."""
    if LOOP_MODE == SPLIT or (LOOP_MODE == ANY and flags[F_MODE] == SPLIT):
        return split_stages(Ubar, h, A, cls, E, flags, c, eps, Fh, F, Z, Yst, W, stats, s, d)
    if LOOP_MODE == ANY:
        return newton_stages(flags[F_MODE], Ubar, h, hinv, A, Ainv, cls, E, flags, c, eps, hA, Fh, F, Z, Yst, J, M,
                             piv, R, W, stats, s, d)
    return newton_stages(LOOP_MODE, Ubar, h, hinv, A, Ainv, cls, E, flags, c, eps, hA, Fh, F, Z, Yst, J, M, piv, R, W,
                         stats, s, d)


@kernel
def fallback_stages(Ubar, h, hinv, A, Ainv, cls, E, flags, c, eps, tol, hA, Fh, F, Z, Yst, J, M, piv, R, W,
                    stats, s, d):
    """A step whose first iteration failed: simplified Newton (the run switches to it after
    SWITCH_AFTER such steps), full Newton, then fixed point on the stage values; 0 or 1."""
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
            if newton_stages(fallback, Ubar, h, hinv, A, Ainv, cls, E, flags, c, eps, hA, Fh, F, Z, Yst, J, M, piv,
                             R, W, stats, s, d) == 0:
                return 0
    return rescue_stages(Ubar, h, A, cls, c, tol, eps, Fh, F, Z, Yst, W, flags, stats, s, d)


@prim
def gram(P, Q, out, m, d):
    """out = P Qᵀ in low precision (m × m)."""
    for a in range(m):
        for b in range(m):
            acc = 0.0
            for l in range(d):
                acc += wlo(g2(P, a, l)) * wlo(g2(Q, b, l))
            out[a, b] = acc


@prim
def accept(y, z, stats, its, d):
    for l in range(d):
        p1(y, l, g1(z, l))
    stats[S_PROJ] += its
    return 0


@kernel
def project(y, c, proj, target, eps, tol, G, Gz, GtG, gpiv, g, lam, z, tmp, stats):
    """y + ∇g(y)λ with g = invariants − targets, Newton on λ (matrix ∇g(z)ᵀ∇g(y), refreshed
    each sweep); 0, or 1 (stats[S_PROJ_RES]: the residual).  Converged when g is at ``tol``
    relative to the size of the invariants' terms |I| + Σ|∂I/∂y_l · y_l| (FPU: ω²q² terms of a
    small H), or when the corrections stop shrinking with g already at round-off level."""
    d = y.shape[0]
    m = proj.shape[0]
    for k in range(m):
        grad_(proj[k], y, c, G, k)
    gram(G, G, GtG, m, d)
    if lu_factor(GtG, gpiv, 0, m) != 0:
        return 1
    tscale = 0.0
    for k in range(m):
        terms = abs(wlo(g1(target, k)))
        for l in range(d):
            terms += abs(wlo(g2(G, k, l)) * wlo(g1(y, l)))
        tscale = max(tscale, terms)
        p1(lam, k, wzero())
    tscale += 1.0
    for l in range(d):
        p1(z, l, g1(y, l))
    prev = -1.0
    res = 0.0
    for it in range(PROJECTION_SWEEPS):
        res = 0.0
        for k in range(m):
            inv_(proj[k], z, c, tmp)
            g[k] = wlo(wsub(g1(tmp, 0), g1(target, k)))
            res = max(res, abs(g[k]))
        res /= tscale
        if res <= tol:
            return accept(y, z, stats, it, d)
        if it > 0:                          # Newton on λ: ∇g(z)ᵀ G at the current point
            for a in range(m):
                grad_(proj[a], z, c, Gz, a)
            gram(Gz, G, GtG, m, d)
            if lu_factor(GtG, gpiv, 0, m) != 0:
                return 1
        lu_solve(GtG, gpiv, g, 0, m)
        step = 0.0
        for k in range(m):
            step = max(step, abs(g[k]))
        if prev >= 0.0 and step >= PROJECTION_STALL * prev and res <= PROJECTION_ROUNDOFF * eps:
            return accept(y, z, stats, it, d)
        prev = step
        for k in range(m):
            p1(lam, k, waddlo(g1(lam, k), -g[k]))
        for l in range(d):
            acc = g1(y, l)
            for k in range(m):
                acc = wmadd(acc, g2(G, k, l), g1(lam, k))
            p1(z, l, acc)
    if res <= PROJECTION_ACCEPT * eps:     # round-off noise of a large-term invariant, not divergence
        return accept(y, z, stats, PROJECTION_SWEEPS, d)
    stats[S_PROJ_RES] = res
    return 1


@helper
def row_times(M, dense, i, Y, l, r):
    """Σₖ M[i, k] Y[k, l] (zero coefficients skipped): U y^[n−1] and V y^[n−1]."""
    acc = wzero()
    for k in range(r):
        m = g2(M, i, k)
        if uses(dense, m):
            acc = wmadd(acc, m, g2(Y, k, l))
    return acc


@helper
def stage_inputs(U, Y, Ubar, s, r, d):
    """Ū = U y^[n−1]."""
    for i in range(s):
        for l in range(d):
            p2(Ubar, i, l, row_times(U, DENSE_U, i, Y, l, r))


@helper
def finish_step(Y, h, B, V, cls, flags, c, eps, tol, proj, target, comp, F, Yout, work, stats, s, r, d):
    """y^[n] = V y^[n−1] + h B F (Kahan on the principal value), projection; 0, 2 (not finite)
    or 3 (projection failed)."""
    G, Gz, GtG, gpiv, g, lam, zp, tmp, yfirst = work
    for k in range(r):
        for l in range(d):
            acc = row_times(V, DENSE_V, k, Y, l, r)
            x = combine(h, B, DENSE_B, cls, k, F, l, s)
            if k == 0 and flags[F_COMPENSATE] == 1:     # Kahan: y₁ + (increment + carry)
                x = wadd(x, g1(comp, l))
                y1 = wadd(acc, x)
                p1(comp, l, wadd(wsub(acc, y1), x))
                p2(Yout, k, l, y1)
            else:
                p2(Yout, k, l, wadd(acc, x))
    for k in range(r):
        for l in range(d):
            p2(Y, k, l, g2(Yout, k, l))
    if LOOP_PROJECTS == 1 or (LOOP_PROJECTS == ANY and proj.shape[0] > 0):
        for l in range(d):
            p1(yfirst, l, g2(Y, 0, l))
        if project(yfirst, c, proj, target, eps, tol, G, Gz, GtG, gpiv, g, lam, zp, tmp, stats) != 0:
            return 3
        for l in range(d):
            p2(Y, 0, l, g1(yfirst, l))
    for k in range(r):
        for l in range(d):
            if not lofinite(wlo(g2(Y, k, l))):
                return 2
    return 0


@prim
def observe(track, ttarget, tmax, Y, c, tmp, yfirst, d):
    """The largest |I_k(y^[n]₁) − I_k(y₀)| so far of the invariants in ``track``."""
    for l in range(d):
        p1(yfirst, l, g2(Y, 0, l))
    for k in range(track.shape[0]):
        inv_(track[k], yfirst, c, tmp)
        tmax[k] = max(tmax[k], abs(wlo(wsub(g1(tmp, 0), g1(ttarget, k)))))


@prim
def after_step(n, track_due, record_due, Y, c, track, ttarget, tmax, rec, recn, nrec, work, stats, r, d):
    """The invariants tracked and the record kept, where due after step n; the records so far."""
    tmp, yfirst = work[7], work[8]
    stats[S_DONE] = n
    if track_due and track.shape[0] > 0:
        observe(track, ttarget, tmax, Y, c, tmp, yfirst, d)
    if record_due:
        for k in range(r):
            for l in range(d):
                p3(rec, nrec, k, l, g2(Y, k, l))
        recn[nrec] = n
        nrec += 1
        stats[S_NREC] = nrec
    return nrec


@helper
def fits(Y, A, U, B, V, E, Ainv, Fh, comp, stages, s, r, d):
    """Whether the loop's arrays have the shapes that (s, r, d) give them.  In a module specialised
    to one shape (s, r, d constants) this test also tells LLVM the arrays' row lengths: numba
    indexes a row-major array through its shape, which LLVM otherwise takes for an unknown, so it
    cannot tell a store to F[1, l] from F[0, l] and reloads every stage value after every store
    (the C loop's static arrays have constant rows).  After the test the shape is that constant."""
    Ubar, F, Z, W, Yst, J, M, piv, R, Yout = stages
    sd = s * d
    return (Y.shape[0] == r and Y.shape[1] == d and Yout.shape[0] == r and Yout.shape[1] == d
            and Ubar.shape[0] == s and Ubar.shape[1] == d and F.shape[0] == s and F.shape[1] == d
            and Z.shape[0] == s and Z.shape[1] == d and W.shape[0] == s and W.shape[1] == d
            and Yst.shape[0] == d and comp.shape[0] == d and J.shape[0] == d and J.shape[1] == d
            and M.shape[0] == sd and M.shape[1] == sd and piv.shape[0] == sd and R.shape[0] == sd
            and A.shape[0] == 2 and A.shape[1] == s and A.shape[2] == s
            and Ainv.shape[0] == 2 and Ainv.shape[1] == s and Ainv.shape[2] == s
            and B.shape[0] == 2 and B.shape[1] == r and B.shape[2] == s and U.shape[0] == s and U.shape[1] == r
            and V.shape[0] == r and V.shape[1] == r and E.shape[0] == s and E.shape[1] == s
            and Fh.shape[0] == HISTORY and Fh.shape[1] == s and Fh.shape[2] == d)


@alloc
def workspace(s, r, d, m):
    """The loop's arrays (stage values and derivatives, Newton matrix, projection), allocated by
    the caller once per run: the compiled loop runs without numba's reference counting."""
    stages = (wmat(s, d), wmat(s, d), wmat(s, d), wmat(s, d), wvec(d), wmat(d, d), lomat(s * d, s * d),
              np.zeros(s * d, np.int64), lovec(s * d), wmat(r, d))
    projection = (wmat(m, d), wmat(m, d), lomat(m, m), np.zeros(m, np.int64), lovec(m), wvec(m), wvec(d), wvec(1),
                  wvec(d))
    return stages, projection


@kernel
def run(Y, h, hinv, n0, n1, steps, every, A, U, B, V, cls, E, Ainv, flags, c, eps, tol, hA,
        proj, target, track, ttarget, tmax, track_every, comp, Fh, rec, recn, stats, stages, work):
    """Steps n0+1 … n1 of ``steps``; records of Y every ``every`` steps (and at ``steps``) into
    rec/recn (stats[S_NREC] of them); the largest |I_k(y^[n]₁) − I_k(y₀)| of the invariants in
    ``track`` every ``track_every`` steps into tmax.  Returns the status (module docstring), or
    4: the stage iteration failed at step stats[S_STEP] (Y is y^[n−1]), for :func:`rescue_step`.
    ``stages``, ``work``: the arrays of :func:`workspace` (the loop allocates nothing)."""
    s, r, d = dims(A, Y)
    if not fits(Y, A, U, B, V, E, Ainv, Fh, comp, stages, s, r, d):
        return MISFIT
    Ubar, F, Z, W, Yst, J, M, piv, R, Yout = stages
    nrec = 0
    to_record = every - n0 % every          # countdowns: no division per step
    to_track = track_every - n0 % track_every
    stats[S_NREC] = 0
    for n in range(n0 + 1, n1 + 1):
        stats[S_STEP] = n
        stage_inputs(U, Y, Ubar, s, r, d)
        if LOOP_MODE == EXPLICIT or (LOOP_MODE == ANY and flags[F_EXPLICIT] == 1):
            explicit_stages(Ubar, h, A, cls, c, Yst, F, stats, s, d)
        elif primary_stages(Ubar, h, hinv, A, Ainv, cls, E, flags, c, eps, hA, Fh, F, Z, Yst, J, M, piv, R, W,
                            stats, s, d) != 0:
            stats[S_NREC] = nrec
            return 4
        status = finish_step(Y, h, B, V, cls, flags, c, eps, tol, proj, target, comp, F, Yout, work, stats, s, r, d)
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
        nrec = after_step(n, track_due, record_due, Y, c, track, ttarget, tmax, rec, recn, nrec, work, stats, r, d)
    return 0


@kernel
def rescue_step(Y, h, hinv, n0, n, steps, every, A, U, B, V, cls, E, Ainv, flags, c, eps, tol, hA,
                proj, target, track, ttarget, tmax, track_every, comp, Fh, rec, recn, stats, stages, work):
    """Step n (= n0 + 1; :func:`run`'s arguments) after the loop's stage iteration failed on it
    (:func:`fallback_stages`): 0, or the status of :func:`run`; its record (if due) into rec[0]."""
    s, r, d = dims(A, Y)
    if not fits(Y, A, U, B, V, E, Ainv, Fh, comp, stages, s, r, d):
        return MISFIT
    Ubar, F, Z, W, Yst, J, M, piv, R, Yout = stages
    stats[S_NREC] = 0
    stage_inputs(U, Y, Ubar, s, r, d)
    if fallback_stages(Ubar, h, hinv, A, Ainv, cls, E, flags, c, eps, tol, hA, Fh, F, Z, Yst, J, M, piv, R, W,
                       stats, s, d) != 0:
        return 1
    status = finish_step(Y, h, B, V, cls, flags, c, eps, tol, proj, target, comp, F, Yout, work, stats, s, r, d)
    if status != 0:
        return status
    after_step(n, n % track_every == 0 or n == steps, n % every == 0 or n == steps, Y, c, track, ttarget, tmax, rec,
               recn, 0, work, stats, r, d)
    return 0
