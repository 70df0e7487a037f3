/* Hand-written C99 reference of the compiled float64 step loop of tableau_lab
 * (tableau_lab/numeric/kernel_source.py, LOOP: lu_factor_, lu_solve_, converged_, rhs_,
 * newton_, run_), for benchmarking only: not part of the package.  Projection and the
 * per-step invariant tracking (``track``) are left out (the benchmark runs without them).
 * Mirrors the float64 LOOP as of commit a265458 (stage derivatives as rhs_(1/h, Aqi, Api, Z));
 * benchmarks/c_reference/check.py tells when the two drift apart.
 *
 * The algorithm, line for line as in the numba loop: the partitioned GLM step
 *   Yi   = sum_k U[i,k] y_k + h sum_j (Aq[i,j] Pq + Ap[i,j] Pp) f(Yj)
 *   y'_k = sum_l V[k,l] y_l + h sum_j (Bq[k,j] Pq + Bp[k,j] Pp) f(Yj)
 * explicit stages in order, or simplified Newton on the stage increments Z = Y - Ubar with one
 * Jacobian (at Ubar[0]) per step, started from the previous step's stage derivatives
 * extrapolated by E, stopped by Hairer's theta/(1 - theta)|dZ| test; stage derivatives from
 * (1/h) A^-1 Z when A is invertible; Kahan summation of the principal increment; a non-finite
 * state or a failed Newton stops the loop with status 2 / 1 (the Python driver would redo the
 * step on the pure path; here the run just reports it).
 *
 * f and the Jacobian are written by hand for two problems:
 *   pendulum  y = (q, p), H = p^2/2 - cos q
 *   kepler    y = (q1, q2, p1, p2), H = |p|^2/2 - 1/r - delta/(2 r^3)   (delta = c[1] = 0.005)
 *
 * Input (file given as argv[1]): lines "key count v1 ... vcount" (doubles written %.17g), and
 * "problem NAME".  Keys: dims (s r d reps), steps, mode (0: run, 1: print f and J at each row
 * of Y), h, eps, hA, flags (explicit, has_E, has_inv, compensated, have_prev), c, Aq, Ap, U,
 * Bq, Bp, V, mq, mp, E, Aqi, Api, Y (r x d, row-major).
 * Output (stdout): status, completed, nfev, newton, seconds (median over the reps of the step
 * loop alone, CLOCK_MONOTONIC), seconds_all, final (r x d, %.17g).
 *
 * Build: gcc -O2 -o glm_loop glm_loop.c -lm
 */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAXS 8
#define MAXR 8
#define MAXD 8
#define MAXSD (MAXS * MAXD)
#define MAXREPS 1000
#define MAX(a, b) ((b) > (a) ? (b) : (a))     /* Python's max(a, b) */

enum { PENDULUM = 0, KEPLER = 1 };

/* ---- the problems, by hand ------------------------------------------------------------ */

static void f_pendulum(const double *y, double *out)
{
    out[0] = y[1];
    out[1] = -sin(y[0]);
}

static void jac_pendulum(const double *y, double *J)          /* d x d, row-major */
{
    J[0] = 0.0;
    J[1] = 1.0;
    J[2] = -cos(y[0]);
    J[3] = 0.0;
}

/* f = (p1, p2, -q1 g, -q2 g),  g = 1/r^3 + 1.5 delta / r^5 */
static void f_kepler(const double *y, const double *c, double *out)
{
    const double delta = c[1];
    const double r2 = y[0] * y[0] + y[1] * y[1];
    const double r = sqrt(r2);
    const double ir3 = 1.0 / (r2 * r);
    const double g = ir3 * (1.0 + 1.5 * delta / r2);
    out[0] = y[2];
    out[1] = y[3];
    out[2] = -y[0] * g;
    out[3] = -y[1] * g;
}

/* d(-qi g)/dqj = -g delta_ij - qi dg/dqj,  dg/dqj = -qj (3/r^5 + 7.5 delta/r^7) =: -qj k
 * so J[2+i][j] = -g delta_ij + qi qj k;  dp/dp rows: J[i][2+i] = 1. */
static void jac_kepler(const double *y, const double *c, double *J)
{
    const double delta = c[1];
    const double q1 = y[0], q2 = y[1];
    const double r2 = q1 * q1 + q2 * q2;
    const double r = sqrt(r2);
    const double ir2 = 1.0 / r2;
    const double ir3 = ir2 / r;
    const double ir5 = ir3 * ir2;
    const double g = ir3 + 1.5 * delta * ir5;
    const double k = 3.0 * ir5 + 7.5 * delta * ir5 * ir2;
    const double off = q1 * q2 * k;
    memset(J, 0, 16 * sizeof(double));
    J[0 * 4 + 2] = 1.0;
    J[1 * 4 + 3] = 1.0;
    J[2 * 4 + 0] = q1 * q1 * k - g;
    J[2 * 4 + 1] = off;
    J[3 * 4 + 0] = off;
    J[3 * 4 + 1] = q2 * q2 * k - g;
}

static int problem;          /* loop-invariant: the branches below are perfectly predicted */

static inline void f_(const double *y, const double *c, double *out)
{
    if (problem == KEPLER)
        f_kepler(y, c, out);
    else
        f_pendulum(y, out);
}

static inline void jac_(const double *y, const double *c, double *J)
{
    if (problem == KEPLER)
        jac_kepler(y, c, J);
    else
        jac_pendulum(y, J);
}

/* ---- the loop -------------------------------------------------------------------------- */

/* LU with partial pivoting in place, M n x n row-major; 1 when singular */
static int lu_factor_(double *M, int n, int *piv)
{
    for (int k = 0; k < n; k++) {
        int p = k;
        double big = fabs(M[k * n + k]);
        for (int i = k + 1; i < n; i++)
            if (fabs(M[i * n + k]) > big) {
                big = fabs(M[i * n + k]);
                p = i;
            }
        piv[k] = p;
        if (big == 0.0)
            return 1;
        if (p != k)
            for (int j = 0; j < n; j++) {
                double tmp = M[k * n + j];
                M[k * n + j] = M[p * n + j];
                M[p * n + j] = tmp;
            }
        double inv = 1.0 / M[k * n + k];
        for (int i = k + 1; i < n; i++) {
            double m = M[i * n + k] * inv;
            M[i * n + k] = m;
            if (m != 0.0)
                for (int j = k + 1; j < n; j++)
                    M[i * n + j] -= m * M[k * n + j];
        }
    }
    return 0;
}

static void lu_solve_(const double *M, int n, const int *piv, double *b)
{
    for (int k = 0; k < n; k++) {
        int p = piv[k];
        if (p != k) {
            double tmp = b[k];
            b[k] = b[p];
            b[p] = tmp;
        }
    }
    for (int i = 0; i < n; i++) {
        double acc = b[i];
        for (int j = 0; j < i; j++)
            acc -= M[i * n + j] * b[j];
        b[i] = acc;
    }
    for (int i = n - 1; i >= 0; i--) {
        double acc = b[i];
        for (int j = i + 1; j < n; j++)
            acc -= M[i * n + j] * b[j];
        b[i] = acc / M[i * n + i];
    }
}

static int converged_(double size, double prev, double tol, double floor_)
{
    if (size <= tol)
        return 1;
    if (prev <= 0.0)
        return 0;
    double theta = size / prev;
    return (theta < 1.0 && theta / (1.0 - theta) * size <= tol) || (theta >= 0.9 && size <= floor_);
}

/* the method and run constants (the arrays of kernels._Pack) */
typedef struct {
    int s, r, d;
    double h, eps, hA;
    long flags[5];          /* explicit, has_E, has_inv, compensated, have_prev */
    double c[16];
    int nc;
    double Aq[MAXS * MAXS], Ap[MAXS * MAXS], U[MAXS * MAXR];
    double Bq[MAXR * MAXS], Bp[MAXR * MAXS], V[MAXR * MAXR];
    double mq[MAXD], mp[MAXD];
    double E[MAXS * MAXS], Aqi[MAXS * MAXS], Api[MAXS * MAXS];
} Pack;

/* work arrays: allocated once (static), never per step */
typedef struct {
    double Ubar[MAXS * MAXD], F[MAXS * MAXD], Z[MAXS * MAXD], W[MAXS * MAXD], Fprev[MAXS * MAXD];
    double Yst[MAXD], J[MAXD * MAXD], M[MAXSD * MAXSD], R[MAXSD];
    int piv[MAXSD];
    double Yout[MAXR * MAXD], inc[MAXD], comp[MAXD];
    long nfev, newton;
} Work;

/* out = h (Aq F o mq + Ap F o mp), s x d */
static void rhs_(double h, const double *Aq, const double *Ap, const double *mq, const double *mp, int s, int d,
                 const double *F, double *out)
{
    for (int i = 0; i < s; i++)
        for (int l = 0; l < d; l++) {
            double aq = 0.0, ap = 0.0;
            for (int j = 0; j < s; j++) {
                aq += Aq[i * s + j] * F[j * d + l];
                ap += Ap[i * s + j] * F[j * d + l];
            }
            out[i * d + l] = h * (aq * mq[l] + ap * mp[l]);
        }
}

static int newton_(Pack *P, Work *w)
{
    const int s = P->s, d = P->d, sd = s * d;
    const double h = P->h, eps = P->eps;
    const double *c = P->c;
    double *Ubar = w->Ubar, *F = w->F, *Z = w->Z, *W = w->W, *Yst = w->Yst, *J = w->J, *M = w->M,
           *R = w->R;
    jac_(Ubar, c, J);
    double jmax = 0.0;
    for (int k = 0; k < d * d; k++)
        jmax = MAX(jmax, fabs(J[k]));
    const double amp = 1.0 + P->hA * jmax;
    double scale = 0.0;
    for (int k = 0; k < sd; k++)
        scale = MAX(scale, fabs(Ubar[k]));
    scale += 1.0;
    for (int a = 0; a < sd; a++)
        for (int b = 0; b < sd; b++)
            M[a * sd + b] = a == b ? 1.0 : 0.0;
    for (int i = 0; i < s; i++)
        for (int j = 0; j < s; j++) {
            double aq = P->Aq[i * s + j], ap = P->Ap[i * s + j];
            if (aq != 0.0 || ap != 0.0)
                for (int k = 0; k < d; k++) {
                    double wk = h * (aq * P->mq[k] + ap * P->mp[k]);
                    for (int l = 0; l < d; l++)
                        M[(i * d + k) * sd + j * d + l] -= wk * J[k * d + l];
                }
        }
    if (lu_factor_(M, sd, w->piv) != 0)
        return 1;
    const int predicted = P->flags[1] == 1 && P->flags[4] == 1;
    for (int attempt = 0; attempt < (predicted ? 2 : 1); attempt++) {
        if (attempt == 0 && predicted) {
            for (int i = 0; i < s; i++)
                for (int l = 0; l < d; l++) {
                    double acc = 0.0;
                    for (int j = 0; j < s; j++)
                        acc += P->E[i * s + j] * w->Fprev[j * d + l];
                    W[i * d + l] = acc;
                }
            rhs_(h, P->Aq, P->Ap, P->mq, P->mp, s, d, W, Z);
        } else {
            for (int k = 0; k < sd; k++)
                Z[k] = 0.0;
        }
        double prev = -1.0;
        for (int it = 0; it < 60; it++) {
            for (int i = 0; i < s; i++) {
                for (int l = 0; l < d; l++)
                    Yst[l] = Ubar[i * d + l] + Z[i * d + l];
                f_(Yst, c, F + i * d);
            }
            w->nfev += s;
            rhs_(h, P->Aq, P->Ap, P->mq, P->mp, s, d, F, W);
            for (int k = 0; k < sd; k++)
                R[k] = W[k] - Z[k];
            lu_solve_(M, sd, w->piv, R);
            w->newton += 1;
            double size = 0.0, zn = 0.0;
            int finite = 1;
            for (int k = 0; k < sd; k++) {
                double dz = R[k];
                if (!isfinite(dz))
                    finite = 0;
                Z[k] += dz;
                size = MAX(size, fabs(dz));
                zn = MAX(zn, fabs(Z[k]));
            }
            if (!finite)
                break;
            if (converged_(size, prev, eps * zn, 1000.0 * eps * scale * amp)) {
                if (P->flags[2] == 1) {         /* F = A^-1 Z / h */
                    rhs_(1.0 / h, P->Aqi, P->Api, P->mq, P->mp, s, d, Z, F);
                } else {
                    for (int i = 0; i < s; i++) {
                        for (int l = 0; l < d; l++)
                            Yst[l] = Ubar[i * d + l] + Z[i * d + l];
                        f_(Yst, c, F + i * d);
                    }
                    w->nfev += s;
                }
                memcpy(w->Fprev, F, (size_t)sd * sizeof(double));
                P->flags[4] = 1;
                return 0;
            }
            if (prev >= 0.0 && it > 3 && size > prev)
                break;
            prev = size;
        }
    }
    return 1;
}

/* steps 1..steps from Y (r x d, updated in place); 0 when done, 1 (Newton failed) or
 * 2 (non-finite state) with *failed the step */
static int run_(Pack *P, Work *w, double *Y, long steps, long *failed)
{
    const int s = P->s, r = P->r, d = P->d;
    const double h = P->h;
    const double *c = P->c;
    double *Ubar = w->Ubar, *F = w->F, *Yst = w->Yst, *Yout = w->Yout, *inc = w->inc, *comp = w->comp;
    for (long n = 1; n <= steps; n++) {
        for (int i = 0; i < s; i++)
            for (int l = 0; l < d; l++) {
                double acc = 0.0;
                for (int k = 0; k < r; k++)
                    acc += P->U[i * r + k] * Y[k * d + l];
                Ubar[i * d + l] = acc;
            }
        if (P->flags[0] == 1) {
            for (int i = 0; i < s; i++) {
                for (int l = 0; l < d; l++)
                    Yst[l] = Ubar[i * d + l];
                for (int j = 0; j < i; j++) {
                    double aq = P->Aq[i * s + j], ap = P->Ap[i * s + j];
                    if (aq != 0.0 || ap != 0.0)
                        for (int l = 0; l < d; l++)
                            Yst[l] += h * (aq * P->mq[l] + ap * P->mp[l]) * F[j * d + l];
                }
                f_(Yst, c, F + i * d);
            }
            w->nfev += s;
        } else if (newton_(P, w) != 0) {
            P->flags[4] = 0;
            *failed = n;
            return 1;
        }
        for (int k = 0; k < r; k++)
            for (int l = 0; l < d; l++) {
                double acc = 0.0;
                for (int j = 0; j < r; j++)
                    acc += P->V[k * r + j] * Y[j * d + l];
                double bq = 0.0, bp = 0.0;
                for (int j = 0; j < s; j++) {
                    bq += P->Bq[k * s + j] * F[j * d + l];
                    bp += P->Bp[k * s + j] * F[j * d + l];
                }
                double x = h * (bq * P->mq[l] + bp * P->mp[l]);
                if (k == 0)
                    inc[l] = x;
                Yout[k * d + l] = acc + x;
            }
        if (P->flags[3] == 1)
            for (int l = 0; l < d; l++) {
                double x = inc[l] + comp[l];
                double y1 = Y[l] + x;
                comp[l] = (Y[l] - y1) + x;
                Yout[l] = y1;
            }
        memcpy(Y, Yout, (size_t)(r * d) * sizeof(double));
        for (int k = 0; k < r * d; k++)
            if (!isfinite(Y[k])) {
                *failed = n;
                return 2;
            }
    }
    return 0;
}

/* ---- input, repetitions, output ------------------------------------------------------- */

static void die(const char *msg, const char *what)
{
    fprintf(stderr, "glm_loop: %s%s\n", msg, what ? what : "");
    exit(2);
}

static void read_into(FILE *fp, const char *key, double *dst, int n, int want)
{
    if (n != want) {
        fprintf(stderr, "glm_loop: %s: %d values, expected %d\n", key, n, want);
        exit(2);
    }
    for (int i = 0; i < n; i++) {
        char tok[64];
        if (fscanf(fp, "%63s", tok) != 1)
            die("unexpected end of input in ", key);
        dst[i] = strtod(tok, NULL);
    }
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static Pack P0;
static Work work;

int main(int argc, char **argv)
{
    if (argc != 2)
        die("usage: glm_loop INPUT", NULL);
    FILE *fp = fopen(argv[1], "r");
    if (!fp)
        die("cannot open ", argv[1]);
    double dims[4] = {0, 0, 0, 1}, tmp[64], Y0[MAXR * MAXD];
    long steps = 0;
    int mode = 0, have_dims = 0;
    char key[64];
    problem = -1;
    while (fscanf(fp, "%63s", key) == 1) {
        if (strcmp(key, "problem") == 0) {
            char name[64];
            if (fscanf(fp, "%63s", name) != 1)
                die("missing problem name", NULL);
            if (strcmp(name, "pendulum") == 0)
                problem = PENDULUM;
            else if (strcmp(name, "kepler") == 0)
                problem = KEPLER;
            else
                die("unknown problem ", name);
            continue;
        }
        int n;
        if (fscanf(fp, "%d", &n) != 1)
            die("missing count after ", key);
        const int s = P0.s, r = P0.r, d = P0.d;
        if (strcmp(key, "dims") == 0) {
            read_into(fp, key, dims, n, 4);
            P0.s = (int)dims[0];
            P0.r = (int)dims[1];
            P0.d = (int)dims[2];
            if (P0.s < 1 || P0.s > MAXS || P0.r < 1 || P0.r > MAXR || P0.d < 1 || P0.d > MAXD)
                die("sizes out of range (s, r, d <= 8)", NULL);
            if (dims[3] < 1 || dims[3] > MAXREPS)
                die("reps out of range", NULL);
            have_dims = 1;
            continue;
        }
        if (!have_dims)
            die("dims must come first", NULL);
        if (strcmp(key, "steps") == 0) {
            read_into(fp, key, tmp, n, 1);
            steps = (long)tmp[0];
        } else if (strcmp(key, "mode") == 0) {
            read_into(fp, key, tmp, n, 1);
            mode = (int)tmp[0];
        } else if (strcmp(key, "h") == 0)
            read_into(fp, key, &P0.h, n, 1);
        else if (strcmp(key, "eps") == 0)
            read_into(fp, key, &P0.eps, n, 1);
        else if (strcmp(key, "hA") == 0)
            read_into(fp, key, &P0.hA, n, 1);
        else if (strcmp(key, "flags") == 0) {
            read_into(fp, key, tmp, n, 5);
            for (int i = 0; i < 5; i++)
                P0.flags[i] = (long)tmp[i];
        } else if (strcmp(key, "c") == 0) {
            if (n > 16)
                die("too many constants", NULL);
            read_into(fp, key, P0.c, n, n);
            P0.nc = n;
        } else if (strcmp(key, "Aq") == 0)
            read_into(fp, key, P0.Aq, n, s * s);
        else if (strcmp(key, "Ap") == 0)
            read_into(fp, key, P0.Ap, n, s * s);
        else if (strcmp(key, "U") == 0)
            read_into(fp, key, P0.U, n, s * r);
        else if (strcmp(key, "Bq") == 0)
            read_into(fp, key, P0.Bq, n, r * s);
        else if (strcmp(key, "Bp") == 0)
            read_into(fp, key, P0.Bp, n, r * s);
        else if (strcmp(key, "V") == 0)
            read_into(fp, key, P0.V, n, r * r);
        else if (strcmp(key, "mq") == 0)
            read_into(fp, key, P0.mq, n, d);
        else if (strcmp(key, "mp") == 0)
            read_into(fp, key, P0.mp, n, d);
        else if (strcmp(key, "E") == 0)
            read_into(fp, key, P0.E, n, s * s);
        else if (strcmp(key, "Aqi") == 0)
            read_into(fp, key, P0.Aqi, n, s * s);
        else if (strcmp(key, "Api") == 0)
            read_into(fp, key, P0.Api, n, s * s);
        else if (strcmp(key, "Y") == 0)
            read_into(fp, key, Y0, n, r * d);
        else
            die("unknown key ", key);
    }
    fclose(fp);
    if (problem < 0 || !have_dims)
        die("input needs problem and dims", NULL);
    if ((problem == PENDULUM && P0.d != 2) || (problem == KEPLER && (P0.d != 4 || P0.nc < 2)))
        die("dimension or constants do not fit the problem", NULL);
    const int r = P0.r, d = P0.d;

    if (mode == 1) {                 /* f and J at each row of Y: to check the hand-written J */
        for (int k = 0; k < r; k++) {
            double f[MAXD], J[MAXD * MAXD];
            f_(Y0 + k * d, P0.c, f);
            jac_(Y0 + k * d, P0.c, J);
            printf("f %d", d);
            for (int i = 0; i < d; i++)
                printf(" %.17g", f[i]);
            printf("\njac %d", d * d);
            for (int i = 0; i < d * d; i++)
                printf(" %.17g", J[i]);
            printf("\n");
        }
        return 0;
    }

    const int reps = (int)dims[3];
    double seconds[MAXREPS], Y[MAXR * MAXD];
    int status = 0;
    long failed = 0;
    for (int rep = 0; rep < reps; rep++) {
        Pack P = P0;                                /* have_prev as given (0): a fresh run */
        memset(&work, 0, sizeof work);              /* comp, Fprev, counters */
        memcpy(Y, Y0, sizeof(double) * (size_t)(r * d));
        double t0 = now();
        status = run_(&P, &work, Y, steps, &failed);
        seconds[rep] = now() - t0;
    }
    double sorted[MAXREPS];
    memcpy(sorted, seconds, sizeof(double) * (size_t)reps);
    qsort(sorted, (size_t)reps, sizeof(double), cmp_double);
    double median = reps % 2 ? sorted[reps / 2] : 0.5 * (sorted[reps / 2 - 1] + sorted[reps / 2]);
    printf("status %d\n", status);
    printf("completed %ld\n", status == 0 ? steps : failed - 1);
    printf("nfev %ld\n", work.nfev);
    printf("newton %ld\n", work.newton);
    printf("seconds %.9g\n", median);
    printf("seconds_all %d", reps);
    for (int i = 0; i < reps; i++)
        printf(" %.9g", seconds[i]);
    printf("\nfinal %d", r * d);
    for (int k = 0; k < r * d; k++)
        printf(" %.17g", Y[k]);
    printf("\n");
    return 0;
}
