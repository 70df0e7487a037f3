/* C99 reference of the float64 step loop of tableau_lab (tableau_lab/numeric/stepcore.py, run
 * with ops_f64.py), for benchmarking and sameness checks only: not part of the package.
 * benchmarks/c_reference/check.py tells when the two drift apart.
 *
 * What is here, function for function as in stepcore.py (same names, same arithmetic in the
 * same order, so that the f-evaluation counts are equal and the final states agree to
 * round-off, bit for bit where f is evaluated alike):
 *   the partitioned GLM step, input y^[n-1] (R x D), component class cls[l] (0 = q, 1 = p)
 *     Y_i   = sum_k U[i,k] y_k + h sum_j A[cls(l)][i,j] f(Y_j)
 *     y'_k  = sum_j V[k,j] y_j + h sum_j B[cls(l)][k,j] f(Y_j)   (Kahan on y'_1 if flags[F_COMPENSATE])
 *   explicit stages in order (explicit_stages), or the run's stage iteration (primary_stages):
 *     SPLIT  (split_stages): fixed point on the q stages of a separable problem: forces fp_ at
 *            the q stages -> p stages -> velocities fq_ at the p stages -> new q stages; stop
 *            when the q and p corrections are SPLIT_TOL_ULPS ulps of the stage values, or on a
 *            stall at the round-off floor;
 *     NEWTON / FIXED (newton_stages): simplified Newton on Z = Y - Ubar with the Jacobian at
 *            Ubar_1 (FIXED: M = I), Hairer's theta test, stage derivatives A^-1 Z / h; block
 *            by block for a diagonally implicit method (flags[F_LOWER]: lower_factor, lower_solve);
 *   both started by predict (HISTORY steps of stage derivatives in the ring Fh extrapolated per
 *   stage, or E times the last step's before that); keep pushes them into the ring.
 * Not here: projection, invariant tracking, records, and the fallback chain (rescue_step): a
 * failed primary iteration stops the loop with status 4 (the Python driver would redo the step
 * by the fallbacks); a non-finite state stops it with status 2.
 *
 * Compile-time constants (as the numba loop is specialised per shape):
 *   -DS=.. -DR=.. -DD=..   the method's stages s, input values r, and the problem's dimension d;
 *   -DTL_LIMITS_HEADER: a generated header of stepcore's limits (limits.py: HISTORY,
 *   HISTORY_WEIGHTS, STAGE_SWEEPS, the F_* indices, ...);
 *   -DTL_PROBLEM_HEADER: a generated header of the problem (f_, jac_, and fq_/fp_ if separable;
 *   TL_PROBLEM_D, TL_PROBLEM_NC, TL_PROBLEM_SEPARABLE), printed from its sympy expressions by
 *   c_reference.py; both included below, after the system headers.
 * Two builds of this one file (c_reference.build does them, cached under build/):
 *   the shared library (-DGLM_LIBRARY -shared -fPIC): the entry glm_run (the timed repetitions
 *   of the loop, see below), glm_functions (f, J, fq, fp at a point) and glm_shape, called in
 *   process through ctypes by c_reference.run_c;
 *     gcc -O3 -march=native -std=c99 -ffp-contract=off -shared -fPIC -DGLM_LIBRARY -DS=2 -DR=1 -DD=4 \
 *         -DTL_LIMITS_HEADER='"limits.h"' -DTL_PROBLEM_HEADER='"problem_kepler.h"' -o libglm.so glm_loop.c -lm
 *   the executable (no -DGLM_LIBRARY): main() reads an input file and calls the same glm_run;
 *     gcc -O3 -march=native -std=c99 -ffp-contract=off -DS=2 -DR=1 -DD=4 -DTL_LIMITS_HEADER='"limits.h"' \
 *         -DTL_PROBLEM_HEADER='"problem_kepler.h"' -o glm_loop glm_loop.c -lm
 * glm_run keeps no state between calls: its static Pack, Work and Y are zeroed at the start of
 * every call, and every repetition starts from y^[0] with a zeroed Kahan carry, ring and counters.
 *
 * Executable input (file argv[1]): lines "key count v1 ... vcount", doubles written %.17g.  Keys:
 * shape (S R D, checked), mode (0: run the loop; 1: print f, J, fq, fp at each point), reps,
 * steps, h, hinv, eps, hA, flags (N_FLAGS, limits' F_* layout), c, A (2 S S), U (S R), B (2 R S),
 * V (R R), cls (D), E (S S), Ainv (2 S S), Y (R D, row-major); mode 1: points (n D).
 * Output (stdout): status, completed, step, nfev, sweeps, nvel, seconds (median over the reps
 * of the step loop alone, CLOCK_MONOTONIC), seconds_all, final (R x D, %.17g).
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>
#include <time.h>

#if !defined(S) || !defined(R) || !defined(D)
#error "compile with the method shape: -DS=.. -DR=.. -DD=.."
#endif
#if !defined(TL_LIMITS_HEADER) || !defined(TL_PROBLEM_HEADER)
#error "name the generated headers: -DTL_LIMITS_HEADER='\"limits.h\"' -DTL_PROBLEM_HEADER='\"problem.h\"'"
#endif
#include TL_LIMITS_HEADER
#include TL_PROBLEM_HEADER
#if TL_PROBLEM_D != D
#error "D is not the dimension of the problem"
#endif

#define SD (S * D)
#ifndef DENSE_A                 /* which matrices have no zero (kernels.dense_matrices): */
#define DENSE_A 0               /* -DDENSE_A=1 .. for A, B, U, V; 0: every coefficient tested  */
#define DENSE_B 0               /* for zero when the step runs                                 */
#define DENSE_U 0
#define DENSE_V 0
#endif
#define NC (TL_PROBLEM_NC > 0 ? TL_PROBLEM_NC : 1)
#define MAXREPS 1000
#define MAX(a, b) ((b) > (a) ? (b) : (a))       /* Python's (and numba's) max(a, b) */
#define MIN(a, b) ((b) < (a) ? (b) : (a))
#define GLM_NSTATS 6                            /* glm_run's stats: status, completed, step, nfev, sweeps, nvel */
#if defined(__GNUC__)
#define TL_EXPORT __attribute__((visibility("default")))
#else
#define TL_EXPORT
#endif

/* the method and run constants: the arrays of kernels.Pack */
typedef struct {
    double A[2][S][S], U[S][R], B[2][R][S], V[R][R], E[S][S], Ainv[2][S][S];
    int cls[D];
    double h, hinv, eps, hA;
    double c[NC];
    long flags[N_FLAGS];
} Pack;

/* the loop's arrays (stepcore.workspace), the history ring, the Kahan carry and the counters */
typedef struct {
    double Ubar[S][D], F[S][D], Z[S][D], W[S][D], Yst[D], J[D][D], M[SD][SD], Rv[SD];
    int piv[SD];
    double Yout[R][D], comp[D], Fh[HISTORY][S][D];
    long flags[N_FLAGS];
    long nfev, sweeps, nvel, step;
} Work;

/* ---- core (stepcore.py, same order of operations) -------------------------------------- */

/* LU with partial pivoting, in place, of the block M[o:o+n, o:o+n] (piv: global row indices) */
static inline int lu_factor(double M[SD][SD], int piv[SD], int o, int n)
{
    for (int k = o; k < o + n; k++) {
        int p = k;
        double big = fabs(M[k][k]);
        for (int i = k + 1; i < o + n; i++)
            if (fabs(M[i][k]) > big) {
                big = fabs(M[i][k]);
                p = i;
            }
        piv[k] = p;
        if (big == 0.0)
            return 1;
        if (p != k)
            for (int j = o; j < o + n; j++) {
                double tmp = M[k][j];
                M[k][j] = M[p][j];
                M[p][j] = tmp;
            }
        double inv = 1.0 / M[k][k];
        for (int i = k + 1; i < o + n; i++) {
            double m = M[i][k] * inv;
            M[i][k] = m;
            if (m != 0.0)
                for (int j = k + 1; j < o + n; j++)
                    M[i][j] -= m * M[k][j];
        }
    }
    return 0;
}

static inline void lu_solve(double M[SD][SD], const int piv[SD], double b[SD], int o, int n)
{
    for (int k = o; k < o + n; k++) {
        int p = piv[k];
        if (p != k) {
            double tmp = b[k];
            b[k] = b[p];
            b[p] = tmp;
        }
    }
    for (int i = o; i < o + n; i++) {
        double acc = b[i];
        for (int j = o; j < i; j++)
            acc -= M[i][j] * b[j];
        b[i] = acc;
    }
    for (int i = o + n - 1; i >= o; i--) {
        double acc = b[i];
        for (int j = i + 1; j < o + n; j++)
            acc -= M[i][j] * b[j];
        b[i] = acc / M[i][i];
    }
}

static inline int converged(double size, double prev, double tol, double floor_)
{
    if (size <= tol)
        return 1;
    if (prev <= 0.0)
        return 0;
    double theta = size / prev;
    return (theta < 1.0 && theta / (1.0 - theta) * size <= tol) || (theta >= STALL_THETA && size <= floor_);
}

/* whether the coefficient a of a matrix enters a sum: always if the matrix has no zero (dense,
 * known when compiled), else a != 0 (stepcore.uses; -DDENSE_A=.. by c_reference.py from
 * kernels.dense_matrices) */
static inline int uses(int dense, double a)
{
    return dense || a != 0.0;
}

/* h sum_j A[cls[l]][i][j] F[j][l]: the stage sum of component l (Aq_i, Ap_i: row i of A[0], A[1];
 * also rows of B; dense: the matrix has no zero) */
static inline double combine(double h, const double Aq_i[S], const double Ap_i[S], int dense,
                             int cls_l, double F[S][D], int l)
{
    const double *a_i = cls_l == 0 ? Aq_i : Ap_i;
    double acc = 0.0;
    for (int j = 0; j < S; j++) {
        const double a = a_i[j];
        if (uses(dense, a))
            acc = acc + a * F[j][l];
    }
    return h * acc;
}

static inline void stage_sums(double h, double A[2][S][S], const int cls[D], double F[S][D],
                              double out[S][D])
{
    for (int i = 0; i < S; i++)
        for (int l = 0; l < D; l++)
            out[i][l] = combine(h, A[0][i], A[1][i], DENSE_A, cls[l], F, l);
}

static inline void stage_input(double Ubar[S][D], double Z[S][D], int i, double Yst[D])
{
    for (int l = 0; l < D; l++)
        Yst[l] = Ubar[i][l] + Z[i][l];
}

static inline void eval_stages(double Ubar[S][D], double Z[S][D], const double *c, double Yst[D],
                               double F[S][D])
{
    for (int i = 0; i < S; i++) {
        stage_input(Ubar, Z, i, Yst);
        f_(Yst, c, F[i]);
    }
}

/* W ~ the new step's stage derivatives: the ring's HISTORY steps extrapolated in n, or E times
 * the last step's */
static inline void predict(double E[S][S], double Fh[HISTORY][S][D], const long flags[N_FLAGS],
                           double W[S][D])
{
    const long k = flags[F_NHIST];
    const long pos = flags[F_HPOS];
    if (k >= HISTORY) {
        for (int i = 0; i < S; i++)
            for (int l = 0; l < D; l++) {
                double acc = 0.0;
                for (int m = 0; m < HISTORY; m++) {
                    long slot = pos - 1 - m;
                    if (slot < 0)
                        slot += HISTORY;
                    acc = acc + HISTORY_WEIGHTS[m] * Fh[slot][i][l];
                }
                W[i][l] = acc;
            }
    } else {
        const long last = pos > 0 ? pos - 1 : HISTORY - 1;
        for (int i = 0; i < S; i++)
            for (int l = 0; l < D; l++) {
                double acc = 0.0;
                for (int j = 0; j < S; j++)
                    acc = acc + E[i][j] * Fh[last][j][l];
                W[i][l] = acc;
            }
    }
}

static inline int can_predict(const long flags[N_FLAGS])
{
    return flags[F_PREDICT] == 1 && (flags[F_NHIST] >= HISTORY || (flags[F_NHIST] > 0 && flags[F_HAS_E] == 1));
}

static inline void keep(double F[S][D], double Fh[HISTORY][S][D], long flags[N_FLAGS])
{
    const long pos = flags[F_HPOS];
    for (int i = 0; i < S; i++)
        for (int l = 0; l < D; l++)
            Fh[pos][i][l] = F[i][l];
    flags[F_HPOS] = pos + 1 < HISTORY ? pos + 1 : 0;
    flags[F_NHIST] = MIN(flags[F_NHIST] + 1, HISTORY);
}

static inline void explicit_stages(Pack *P, Work *w)
{
    const double h = P->h;
    for (int i = 0; i < S; i++) {
        for (int l = 0; l < D; l++) {
            double acc = w->Ubar[i][l];
            const int k = P->cls[l];
            for (int j = 0; j < i; j++) {
                const double a = P->A[k][i][j];
                if (uses(DENSE_A, a))
                    acc = acc + (h * a) * w->F[j][l];
            }
            w->Yst[l] = acc;
        }
        f_(w->Yst, P->c, w->F[i]);
    }
    w->nfev += S;
}

/* M[block i, j] -= h A[cls, i, j] J */
static inline void subtract_block(double M[SD][SD], double hlo, double A[2][S][S], const int cls[D],
                                  double J[D][D], int i, int j)
{
    for (int k = 0; k < D; k++) {
        const double wk = hlo * A[cls[k]][i][j];
        if (wk != 0.0)
            for (int l = 0; l < D; l++)
                M[i * D + k][j * D + l] -= wk * J[k][l];
    }
}

/* Newton's matrix of a diagonally implicit method (flags[F_LOWER]): its diagonal blocks
 * I - h A[cls][i][i] J, each factored in place; 1 if one is singular */
static int lower_factor(double M[SD][SD], int piv[SD], double hlo, double A[2][S][S], const int cls[D],
                        double J[D][D])
{
    for (int i = 0; i < S; i++) {
        const int o = i * D;
        for (int k = 0; k < D; k++)
            for (int l = 0; l < D; l++)
                M[o + k][o + l] = k == l ? 1.0 : 0.0;
        subtract_block(M, hlo, A, cls, J, i, i);
        if (lu_factor(M, piv, o, D) != 0)
            return 1;
    }
    return 0;
}

/* Rv = (I - h (A x J))^-1 Rv for lower triangular A, forward block substitution */
static inline void lower_solve(double M[SD][SD], const int piv[SD], double hlo, double A[2][S][S],
                               const int cls[D], double J[D][D], double Rv[SD])
{
    for (int j = 0; j < S; j++) {
        const int o = j * D;
        lu_solve(M, piv, Rv, o, D);
        if (j + 1 < S)
            for (int k = 0; k < D; k++) {
                double acc = 0.0;
                for (int l = 0; l < D; l++)
                    acc += J[k][l] * Rv[o + l];
                for (int i = j + 1; i < S; i++) {
                    const double wk = hlo * A[cls[k]][i][j];
                    if (wk != 0.0)
                        Rv[i * D + k] += wk * acc;
                }
            }
    }
}

static inline void identity(double M[SD][SD])
{
    for (int a = 0; a < SD; a++)
        for (int b = 0; b < SD; b++)
            M[a][b] = a == b ? 1.0 : 0.0;
}

/* f(Y_i) of converged stages Y = Ubar + Z: A^-1 Z / h when A is invertible, else evaluated */
static inline void stage_derivatives(Pack *P, Work *w)
{
    if (w->flags[F_HAS_INV] == 1) {
        stage_sums(P->hinv, P->Ainv, P->cls, w->Z, w->F);
    } else {
        eval_stages(w->Ubar, w->Z, P->c, w->Yst, w->F);
        w->nfev += S;
    }
    keep(w->F, w->Fh, w->flags);
}

/* simplified Newton (NEWTON) or fixed point (FIXED: M = I) on the stage increments Z; 0 when
 * converged (F holds the stage derivatives), else 1 */
static int newton_stages(long mode, Pack *P, Work *w)
{
    const double h = P->h, eps = P->eps;
    const double hlo = h;
    double amp = 1.0;
    if (mode != FIXED) {                    /* round-off amplified by the stage system's conditioning */
        for (int l = 0; l < D; l++)
            w->Yst[l] = w->Ubar[0][l];
        jac_(w->Yst, P->c, &w->J[0][0]);
        double jmax = 0.0;
        for (int k = 0; k < D; k++)
            for (int l = 0; l < D; l++)
                jmax = MAX(jmax, fabs(w->J[k][l]));
        amp = 1.0 + P->hA * jmax;
    }
    const int lower = mode == NEWTON && w->flags[F_LOWER] == 1;
    if (mode == NEWTON) {
        if (lower) {
            if (lower_factor(w->M, w->piv, hlo, P->A, P->cls, w->J) != 0)
                return 1;
        } else {
            identity(w->M);
            for (int i = 0; i < S; i++)
                for (int j = 0; j < S; j++)
                    subtract_block(w->M, hlo, P->A, P->cls, w->J, i, j);
            if (lu_factor(w->M, w->piv, 0, SD) != 0)
                return 1;
        }
    }
    double scale = 0.0;
    for (int i = 0; i < S; i++)
        for (int l = 0; l < D; l++)
            scale = MAX(scale, fabs(w->Ubar[i][l]));
    scale += 1.0;
    const int predicted = can_predict(w->flags);
    for (int attempt = 0; attempt < (predicted ? 2 : 1); attempt++) {
        if (attempt == 0 && predicted) {
            predict(P->E, w->Fh, w->flags, w->W);
            stage_sums(h, P->A, P->cls, w->W, w->Z);
        } else {
            for (int i = 0; i < S; i++)
                for (int l = 0; l < D; l++)
                    w->Z[i][l] = 0.0;
        }
        double prev = -1.0;
        for (int it = 0; it < STAGE_SWEEPS; it++) {
            eval_stages(w->Ubar, w->Z, P->c, w->Yst, w->F);
            w->nfev += S;
            stage_sums(h, P->A, P->cls, w->F, w->W);
            for (int i = 0; i < S; i++)
                for (int l = 0; l < D; l++)
                    w->Rv[i * D + l] = w->W[i][l] - w->Z[i][l];
            if (lower)
                lower_solve(w->M, w->piv, hlo, P->A, P->cls, w->J, w->Rv);
            else if (mode != FIXED)
                lu_solve(w->M, w->piv, w->Rv, 0, SD);
            w->sweeps += 1;
            double size = 0.0, zn = 0.0;
            int finite = 1;
            for (int i = 0; i < S; i++)
                for (int l = 0; l < D; l++) {
                    const double dz = w->Rv[i * D + l];
                    if (!isfinite(dz))
                        finite = 0;
                    const double z = w->Z[i][l] + dz;
                    w->Z[i][l] = z;
                    size = MAX(size, fabs(dz));
                    zn = MAX(zn, fabs(z));
                }
            if (!finite)
                break;
            if (converged(size, prev, eps * zn, ROUNDOFF_FLOOR * eps * scale * amp)) {
                stage_derivatives(P, w);
                return 0;
            }
            if (prev >= 0.0 && it > DIVERGE_AFTER && size > prev)
                break;                      /* diverging */
            prev = size;
        }
    }
    return 1;
}

#if TL_PROBLEM_SEPARABLE
/* fixed point on the q stages of a separable problem (SPLIT); 0 when converged (F holds the
 * stage derivatives of the last sweep), else 1 */
static int split_stages(Pack *P, Work *w)
{
    const double h = P->h, eps = P->eps;
    const int *cls = P->cls;
    for (int i = 0; i < S; i++)
        for (int l = 0; l < D; l++)
            w->Z[i][l] = 0.0;
    if (can_predict(w->flags)) {
        predict(P->E, w->Fh, w->flags, w->W);  /* forces predicted -> p stages -> velocities -> q stages */
        for (int i = 0; i < S; i++)
            for (int l = 0; l < D; l++)
                if (cls[l] == 1)
                    w->Z[i][l] = combine(h, P->A[0][i], P->A[1][i], DENSE_A, cls[l], w->W, l);
        for (int j = 0; j < S; j++) {
            stage_input(w->Ubar, w->Z, j, w->Yst);
            fq_(w->Yst, P->c, w->F[j]);
        }
        w->nvel += S;
        for (int i = 0; i < S; i++)
            for (int l = 0; l < D; l++)
                if (cls[l] == 0)
                    w->Z[i][l] = combine(h, P->A[0][i], P->A[1][i], DENSE_A, cls[l], w->F, l);
    }
    double prev = -1.0;
    for (int it = 0; it < STAGE_SWEEPS; it++) {
        for (int j = 0; j < S; j++) {       /* forces at the q stages */
            stage_input(w->Ubar, w->Z, j, w->Yst);
            fp_(w->Yst, P->c, w->F[j]);
        }
        w->nfev += S;
        double dp = 0.0, pn = 0.0;
        for (int i = 0; i < S; i++)         /* the p stages */
            for (int l = 0; l < D; l++)
                if (cls[l] == 1) {
                    const double z = combine(h, P->A[0][i], P->A[1][i], DENSE_A, cls[l], w->F, l);
                    dp = MAX(dp, fabs(z - w->Z[i][l]));
                    w->Z[i][l] = z;
                    pn = MAX(pn, fabs(w->Ubar[i][l] + z));
                }
        for (int j = 0; j < S; j++) {       /* velocities at the p stages */
            stage_input(w->Ubar, w->Z, j, w->Yst);
            fq_(w->Yst, P->c, w->F[j]);
        }
        w->nvel += S;
        w->sweeps += 1;
        double size = 0.0, qn = 0.0;
        for (int i = 0; i < S; i++)         /* the new q stages */
            for (int l = 0; l < D; l++)
                if (cls[l] == 0) {
                    const double z = combine(h, P->A[0][i], P->A[1][i], DENSE_A, cls[l], w->F, l);
                    size = MAX(size, fabs(z - w->Z[i][l]));
                    w->Z[i][l] = z;
                    qn = MAX(qn, fabs(w->Ubar[i][l] + z));
                }
        if (!isfinite(size))
            return 1;
        if ((size <= SPLIT_TOL_ULPS * eps * qn && dp <= SPLIT_TOL_ULPS * eps * pn) ||
            (prev > 0.0 && size >= STALL_THETA * prev && size <= ROUNDOFF_FLOOR * eps * qn)) {
            keep(w->F, w->Fh, w->flags);
            return 0;
        }
        if (prev >= 0.0 && it > DIVERGE_AFTER && size > prev)
            return 1;
        prev = size;
    }
    return 1;
}
#endif

/* the stage equations of one step by the run's iteration: 0, or 1 */
static inline int primary_stages(Pack *P, Work *w)
{
    const long mode = w->flags[F_MODE];
    if (mode == SPLIT) {
#if TL_PROBLEM_SEPARABLE
        return split_stages(P, w);
#else
        return 1;                           /* no q/p rates: not a separable problem */
#endif
    }
    return newton_stages(mode, P, w);
}

/* sum_k m[k] Y[k][l] (zero coefficients skipped): a row of U or V times y^[n-1] */
static inline double row_times(const double m[R], int dense, double Y[R][D], int l)
{
    double acc = 0.0;
    for (int k = 0; k < R; k++)
        if (uses(dense, m[k]))
            acc = acc + m[k] * Y[k][l];
    return acc;
}

/* Ubar = U y^[n-1] */
static inline void stage_inputs(Pack *P, double Y[R][D], double Ubar[S][D])
{
    for (int i = 0; i < S; i++)
        for (int l = 0; l < D; l++)
            Ubar[i][l] = row_times(P->U[i], DENSE_U, Y, l);
}

/* y^[n] = V y^[n-1] + h B F (Kahan on the principal value); 0, or 2 (not finite) */
static inline int finish_step(Pack *P, Work *w, double Y[R][D])
{
    for (int k = 0; k < R; k++)
        for (int l = 0; l < D; l++) {
            const double acc = row_times(P->V[k], DENSE_V, Y, l);
            double x = combine(P->h, P->B[0][k], P->B[1][k], DENSE_B, P->cls[l], w->F, l);
            if (k == 0 && w->flags[F_COMPENSATE] == 1) {  /* Kahan: y1 + (increment + carry) */
                x = x + w->comp[l];
                const double y1 = acc + x;
                w->comp[l] = (acc - y1) + x;
                w->Yout[k][l] = y1;
            } else {
                w->Yout[k][l] = acc + x;
            }
        }
    for (int k = 0; k < R; k++)
        for (int l = 0; l < D; l++)
            Y[k][l] = w->Yout[k][l];
    for (int k = 0; k < R; k++)
        for (int l = 0; l < D; l++)
            if (!isfinite(Y[k][l]))
                return 2;
    return 0;
}

/* steps 1 .. steps from Y (updated in place): 0 done, 2 non-finite state, 4 the stage iteration
 * failed at step w->step (Y is y^[n-1]) */
static int run(Pack *P, Work *w, double Y[R][D], long steps)
{
    for (long n = 1; n <= steps; n++) {
        w->step = n;
        stage_inputs(P, Y, w->Ubar);
        if (w->flags[F_EXPLICIT] == 1)
            explicit_stages(P, w);
        else if (primary_stages(P, w) != 0)
            return 4;
        const int status = finish_step(P, w, Y);
        if (status != 0)
            return status;
    }
    return 0;
}

/* ---- the entry: repetitions of the timed loop (shared by the library and main) ------- */

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* everything one call uses: static, as the executable has always held it, zeroed entirely at
 * the start of every glm_run, so that no state survives a call (not reentrant: one call at a
 * time per library) */
static Pack P0;
static Work work;
static double Y0[R][D], Y1[R][D];

/* the compiled shape, for the loader's check: S, R, D, N_FLAGS, TL_PROBLEM_NC, GLM_NSTATS */
TL_EXPORT void glm_shape(int64_t out[6])
{
    out[0] = S;
    out[1] = R;
    out[2] = D;
    out[3] = N_FLAGS;
    out[4] = TL_PROBLEM_NC;
    out[5] = GLM_NSTATS;
}

/* reps whole runs of steps steps from y^[0] = Y (R x D, row-major), each from a fresh Kahan
 * carry, history ring and counters; the step loop alone timed by CLOCK_MONOTONIC into
 * seconds[rep].  consts: h, hinv, eps, hA; flags: N_FLAGS (limits' F_* layout); c:
 * TL_PROBLEM_NC; A, Ainv: 2 S S; U: S R; B: 2 R S; V: R R; cls: D (0 or 1); E: S S.  On return
 * Y holds the last run's y^[steps] (or y^[n-1] where it stopped) and stats: status, completed,
 * step, nfev, sweeps, nvel (GLM_NSTATS values) of the last run.  Returns the status (0 done,
 * 2 not finite, 4 the stage iteration failed), or -1 for bad arguments. */
TL_EXPORT int glm_run(const double *consts, const int64_t *flags, const double *c, const double *A,
                      const double *U, const double *B, const double *V, const int64_t *cls,
                      const double *E, const double *Ainv, int64_t steps, int64_t reps, double *Y,
                      int64_t *stats, double *seconds)
{
    if (reps < 1 || steps < 0)
        return -1;
    for (int l = 0; l < D; l++)
        if (cls[l] != 0 && cls[l] != 1)
            return -1;
    memset(&P0, 0, sizeof P0);
    memset(&work, 0, sizeof work);
    memset(Y0, 0, sizeof Y0);
    memset(Y1, 0, sizeof Y1);
    Pack *P = &P0;
    P->h = consts[0];
    P->hinv = consts[1];
    P->eps = consts[2];
    P->hA = consts[3];
    for (int i = 0; i < N_FLAGS; i++)
        P->flags[i] = (long)flags[i];
    for (int i = 0; i < TL_PROBLEM_NC; i++)
        P->c[i] = c[i];
    memcpy(P->A, A, sizeof P->A);
    memcpy(P->U, U, sizeof P->U);
    memcpy(P->B, B, sizeof P->B);
    memcpy(P->V, V, sizeof P->V);
    memcpy(P->E, E, sizeof P->E);
    memcpy(P->Ainv, Ainv, sizeof P->Ainv);
    for (int l = 0; l < D; l++)
        P->cls[l] = (int)cls[l];
    memcpy(Y0, Y, sizeof Y0);
    Work *w = &work;
    int status = 0;
    for (int64_t rep = 0; rep < reps; rep++) {
        memset(w, 0, sizeof *w);            /* Kahan carry, history ring, counters */
        memcpy(w->flags, P->flags, sizeof w->flags);
        memcpy(Y1, Y0, sizeof Y1);
        const double t0 = now();
        status = run(P, w, Y1, (long)steps);
        seconds[rep] = now() - t0;
    }
    memcpy(Y, Y1, sizeof Y1);
    stats[0] = status;
    stats[1] = status == 0 ? steps : w->step - 1;
    stats[2] = w->step;
    stats[3] = w->nfev;
    stats[4] = w->sweeps;
    stats[5] = w->nvel;
    return status;
}

/* the generated functions at one point y (D): f (D), J (D x D), fq, fp (D: their own
 * components, NaN elsewhere; all NaN if the problem is not separable) */
TL_EXPORT void glm_functions(const double *y, const double *c, double *f, double *J, double *fq, double *fp)
{
    double cc[NC] = {0.0};
    for (int i = 0; i < TL_PROBLEM_NC; i++)
        cc[i] = c[i];
    for (int l = 0; l < D; l++)
        fq[l] = fp[l] = NAN;                /* fq_ / fp_ write their own components only */
    f_(y, cc, f);
    jac_(y, cc, J);
#if TL_PROBLEM_SEPARABLE
    fq_(y, cc, fq);
    fp_(y, cc, fp);
#endif
}

#ifndef GLM_LIBRARY
/* ---- the executable: input file, glm_run, output ----------------------------------------- */

static void die(const char *msg, const char *what)
{
    fprintf(stderr, "glm_loop: %s%s\n", msg, what ? what : "");
    exit(2);
}

static void read_into(FILE *fp, const char *key, double *dst, long n, long want)
{
    if (n != want) {
        fprintf(stderr, "glm_loop: %s: %ld values, expected %ld\n", key, n, want);
        exit(2);
    }
    for (long i = 0; i < n; i++) {
        char tok[64];
        if (fscanf(fp, "%63s", tok) != 1)
            die("unexpected end of input in ", key);
        char *end;
        dst[i] = strtod(tok, &end);
        if (*end != '\0')
            die("not a number in ", key);
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void print_row(const char *key, const double *v, int n)
{
    printf("%s %d", key, n);
    for (int i = 0; i < n; i++)
        printf(" %.17g", v[i]);
    printf("\n");
}

/* the input, as glm_run takes it */
static double in_consts[4], in_c[NC], in_A[2 * S * S], in_U[S * R], in_B[2 * R * S], in_V[R * R],
    in_E[S * S], in_Ainv[2 * S * S], in_Y[R * D];
static int64_t in_flags[N_FLAGS], in_cls[D];
static double seconds[MAXREPS], sorted[MAXREPS];

int main(int argc, char **argv)
{
    if (argc != 2)
        die("usage: glm_loop INPUT", NULL);
    FILE *fp = fopen(argv[1], "r");
    if (!fp)
        die("cannot open ", argv[1]);
    double tmp[64], *points = NULL;
    long steps = 0, reps = 1, npoints = 0;
    int mode = 0, have_shape = 0, have_c = 0;
    char key[64];
    while (fscanf(fp, "%63s", key) == 1) {
        long n;
        if (fscanf(fp, "%ld", &n) != 1 || n < 0)
            die("missing count after ", key);
        if (strcmp(key, "shape") == 0) {
            read_into(fp, key, tmp, n, 3);
            if ((int)tmp[0] != S || (int)tmp[1] != R || (int)tmp[2] != D)
                die("the input's shape is not the compiled one (S, R, D)", NULL);
            have_shape = 1;
        } else if (strcmp(key, "mode") == 0) {
            read_into(fp, key, tmp, n, 1);
            mode = (int)tmp[0];
        } else if (strcmp(key, "reps") == 0) {
            read_into(fp, key, tmp, n, 1);
            reps = (long)tmp[0];
            if (reps < 1 || reps > MAXREPS)
                die("reps out of range", NULL);
        } else if (strcmp(key, "steps") == 0) {
            read_into(fp, key, tmp, n, 1);
            steps = (long)tmp[0];
        } else if (strcmp(key, "h") == 0)
            read_into(fp, key, &in_consts[0], n, 1);
        else if (strcmp(key, "hinv") == 0)
            read_into(fp, key, &in_consts[1], n, 1);
        else if (strcmp(key, "eps") == 0)
            read_into(fp, key, &in_consts[2], n, 1);
        else if (strcmp(key, "hA") == 0)
            read_into(fp, key, &in_consts[3], n, 1);
        else if (strcmp(key, "flags") == 0) {
            read_into(fp, key, tmp, n, N_FLAGS);
            for (int i = 0; i < N_FLAGS; i++)
                in_flags[i] = (int64_t)tmp[i];
        } else if (strcmp(key, "c") == 0) {
            read_into(fp, key, in_c, n, TL_PROBLEM_NC);
            have_c = 1;
        } else if (strcmp(key, "A") == 0)
            read_into(fp, key, in_A, n, 2 * S * S);
        else if (strcmp(key, "U") == 0)
            read_into(fp, key, in_U, n, S * R);
        else if (strcmp(key, "B") == 0)
            read_into(fp, key, in_B, n, 2 * R * S);
        else if (strcmp(key, "V") == 0)
            read_into(fp, key, in_V, n, R * R);
        else if (strcmp(key, "cls") == 0) {
            read_into(fp, key, tmp, n, D);
            for (int l = 0; l < D; l++) {
                in_cls[l] = (int64_t)tmp[l];
                if (in_cls[l] != 0 && in_cls[l] != 1)
                    die("cls must be 0 or 1", NULL);
            }
        } else if (strcmp(key, "E") == 0)
            read_into(fp, key, in_E, n, S * S);
        else if (strcmp(key, "Ainv") == 0)
            read_into(fp, key, in_Ainv, n, 2 * S * S);
        else if (strcmp(key, "Y") == 0)
            read_into(fp, key, in_Y, n, R * D);
        else if (strcmp(key, "points") == 0) {
            if (n % D != 0)
                die("points: a multiple of D values needed", NULL);
            points = malloc(sizeof(double) * (size_t)(n > 0 ? n : 1));
            if (!points)
                die("out of memory", NULL);
            read_into(fp, key, points, n, n);
            npoints = n / D;
        } else
            die("unknown key ", key);
    }
    fclose(fp);
    if (!have_shape || (TL_PROBLEM_NC > 0 && !have_c))
        die("the input needs shape and c", NULL);

    if (mode == 1) {                        /* the generated functions at each point */
        for (long k = 0; k < npoints; k++) {
            double f[D], J[D * D], fq[D], fp_[D];
            glm_functions(points + k * D, in_c, f, J, fq, fp_);
            print_row("f", f, D);
            print_row("jac", J, D * D);
#if TL_PROBLEM_SEPARABLE
            print_row("fq", fq, D);
            print_row("fp", fp_, D);
#endif
        }
        free(points);
        return 0;
    }

    int64_t stats[GLM_NSTATS];
    const int status = glm_run(in_consts, in_flags, in_c, in_A, in_U, in_B, in_V, in_cls, in_E, in_Ainv,
                               steps, reps, in_Y, stats, seconds);
    if (status < 0)
        die("glm_run: bad arguments", NULL);
    memcpy(sorted, seconds, sizeof(double) * (size_t)reps);
    qsort(sorted, (size_t)reps, sizeof(double), cmp_double);
    const double median = reps % 2 ? sorted[reps / 2] : 0.5 * (sorted[reps / 2 - 1] + sorted[reps / 2]);
    printf("status %d\n", status);
    printf("completed %lld\n", (long long)stats[1]);
    printf("step %lld\n", (long long)stats[2]);
    printf("nfev %lld\n", (long long)stats[3]);
    printf("sweeps %lld\n", (long long)stats[4]);
    printf("nvel %lld\n", (long long)stats[5]);
    printf("seconds %.9g\n", median);
    printf("seconds_all %ld", reps);
    for (long i = 0; i < reps; i++)
        printf(" %.9g", seconds[i]);
    printf("\n");
    print_row("final", in_Y, R * D);
    return 0;
}
#endif /* GLM_LIBRARY */
