/*
 * The FMU's numerics (inflow_numerics.h): dense LU, the matrix exponential, the
 * Taylor rule of a remainder step, the table in mu.  Nothing here knows the rotor;
 * the model's equations are in inflow_equations.c (generated) and inflow_model.c.
 */
#include <math.h>
#include <string.h>

#include "inflow_numerics.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define NX IFS_NX
#define NA IFS_NA

/* --- small dense linear algebra (row-major, fixed sizes, no allocation) --- */

/* Solve A X = B in place (A n x n destroyed, B n x nrhs overwritten by X), LU with
 * partial pivoting.  -1 if a pivot is below tol times the largest |A| entry. */
int ifs_lu_solve(int n, double *A, int nrhs, double *B, double tol)
{
    double amax = 0.0;
    int i, j, k;
    for (i = 0; i < n * n; i++)
        if (fabs(A[i]) > amax) amax = fabs(A[i]);
    if (!(amax > 0.0) || !isfinite(amax)) return -1;
    for (k = 0; k < n; k++) {
        int p = k;
        for (i = k + 1; i < n; i++)
            if (fabs(A[i * n + k]) > fabs(A[p * n + k])) p = i;
        if (!(fabs(A[p * n + k]) > tol * amax)) return -1;
        if (p != k) {
            for (j = 0; j < n; j++) { double t = A[k*n+j]; A[k*n+j] = A[p*n+j]; A[p*n+j] = t; }
            for (j = 0; j < nrhs; j++) {
                double t = B[k*nrhs+j]; B[k*nrhs+j] = B[p*nrhs+j]; B[p*nrhs+j] = t;
            }
        }
        for (i = k + 1; i < n; i++) {
            double f = A[i * n + k] / A[k * n + k];
            if (f == 0.0) continue;
            for (j = k + 1; j < n; j++) A[i * n + j] -= f * A[k * n + j];
            for (j = 0; j < nrhs; j++) B[i * nrhs + j] -= f * B[k * nrhs + j];
        }
    }
    for (k = n - 1; k >= 0; k--)
        for (j = 0; j < nrhs; j++) {
            double s = B[k * nrhs + j];
            for (i = k + 1; i < n; i++) s -= A[k * n + i] * B[i * nrhs + j];
            B[k * nrhs + j] = s / A[k * n + k];
        }
    return 0;
}

static void matmul(const double *A, const double *B, double *C)   /* NA x NA */
{
    int i, j, k;
    for (i = 0; i < NA; i++) {
        double row[NA] = {0.0};
        for (k = 0; k < NA; k++) {
            double aik = A[i * NA + k];
            if (aik == 0.0) continue;
            for (j = 0; j < NA; j++) row[j] += aik * B[k * NA + j];
        }
        memcpy(C + i * NA, row, sizeof row);
    }
}

/* exp(A) of an NA x NA matrix: scaling and squaring with the diagonal [6/6] Pade
 * approximant, scaled to 1-norm <= 0.5 (backward error below the unit roundoff,
 * Higham 2005).  A is overwritten by the result. */
int ifs_expm(double *A)
{
    static const double c[7] = {1.0, 0.5, 5.0 / 44.0, 1.0 / 66.0, 1.0 / 792.0,
                                1.0 / 15840.0, 1.0 / 665280.0};
    double X2[NA * NA], X4[NA * NA], X6[NA * NA], U[NA * NA], V[NA * NA], T[NA * NA];
    double norm = 0.0, scale;
    int i, j, s = 0;
    for (j = 0; j < NA; j++) {
        double col = 0.0;
        for (i = 0; i < NA; i++) col += fabs(A[i * NA + j]);
        if (col > norm) norm = col;
    }
    if (!isfinite(norm)) return -1;
    while (norm > 0.5 && s < 64) { norm *= 0.5; s++; }
    scale = ldexp(1.0, -s);
    for (i = 0; i < NA * NA; i++) A[i] *= scale;
    matmul(A, A, X2);
    matmul(X2, X2, X4);
    matmul(X4, X2, X6);
    for (i = 0; i < NA * NA; i++) {
        T[i] = c[3] * X2[i] + c[5] * X4[i];
        V[i] = c[2] * X2[i] + c[4] * X4[i] + c[6] * X6[i];
    }
    for (i = 0; i < NA; i++) { T[i * NA + i] += c[1]; V[i * NA + i] += c[0]; }
    matmul(A, T, U);                                 /* odd part */
    for (i = 0; i < NA * NA; i++) { T[i] = V[i] - U[i]; A[i] = V[i] + U[i]; }
    if (ifs_lu_solve(NA, T, NA, A, 1e-300) != 0) return -1;   /* (V - U)^-1 (V + U) */
    for (; s > 0; s--) { matmul(A, A, T); memcpy(A, T, sizeof T); }
    return 0;
}

/* --- the Taylor rule of a step of another length --- */

int ifs_taylor_count(double norm_a, double norm_ab, double r)
{
    double bound = norm_ab * fabs(r), q = norm_a * fabs(r);
    int k;
    for (k = 1; k <= IFS_KMAX; k++) {
        if (bound * q / (k + 1) <= IFS_TAYLOR_TOL) return k;
        bound *= q / (k + 1);
    }
    return 0;
}

/* --- the table in mu --- */

/* Segment s covers [lo q^s, lo q^(s+1)], q = (hi/lo)^(1/SEG). */
static double mu_edge(int seg)
{
    return IFS_MU_LO * pow(IFS_MU_HI / IFS_MU_LO, (double)seg / IFS_MU_SEG);
}

/* The segment ends: mu_edge's, and the knots of a parameter schedule (its range's
 * ends, where the held values make a kink; inflowsim.simulate.mutable.knot_edges
 * chose them), merged in ascending order: inflowsim.simulate.mutable.edges, the
 * same doubles. */
static void mu_edges(double e[IFS_MU_NSEG + 1])
{
#if IFS_MU_N_KNOTS
    static const double knots[IFS_MU_N_KNOTS] = IFS_MU_KNOTS;
    int g = 0, k = 0, i;
    for (i = 0; i <= IFS_MU_NSEG; i++)
        e[i] = (k < IFS_MU_N_KNOTS && (g > IFS_MU_SEG || knots[k] < mu_edge(g)))
                   ? knots[k++] : mu_edge(g++);
#else
    int i;
    for (i = 0; i <= IFS_MU_SEG; i++) e[i] = mu_edge(i);
#endif
}

/* Entries first .. first + n - 1 (n a multiple of four) of the coarse interpolant
 * at mu, four at a time.  (IFS_HOT: the AVX2 clone does four doubles a vector; the
 * same numbers.) */
static IFS_HOT void mu_eval_range(const IfsMuTable *t, double mu, int first, int n,
                                  double *out)
{
    double x;
    const int seg = ifs_mu_table_locate(t, mu, &x);
    int e;
    for (e = 0; e < n; e += 4) {
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
        IFS_MU_HORNER4(t, seg, x, first + e, *(ifs_v4 *)(out + e));
#else
        int i;
        for (i = e; i < e + 4; i++) out[i] = ifs_mu_horner(t, seg, x, first + i);
#endif
    }
}

void ifs_mu_table_eval(const IfsMuTable *t, double mu, int half, double *out)
{
    if (half == 0) {           /* the parts (the same numbers as ifs_mu_table_apply) */
        double x, y;
        const int seg = ifs_mu_table_locate(t, mu, &x);
        const int prt = ifs_mu_table_part(seg, x, &y);
        int e;
        for (e = 0; e < IFS_MU_HALF0; e++) out[e] = ifs_mu_fhorner(t, prt, y, e);
    } else {
        mu_eval_range(t, mu, IFS_MU_HALF0, IFS_MU_HALF, out);
    }
}

/* 1 if this CPU has AVX2 and FMA and this build evaluates the table with them */
static int cpu_fma(void)
{
#ifdef IFS_MU_FMA4
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
    return 0;
#endif
}

/* Chebyshev interpolation at N <= IFS_MU_DEG + 1 nodes as a matrix: the power
 * coefficients c[i] = sum_j w[i][j] f_j of the polynomial through f_j at the
 * Chebyshev-Gauss nodes cos(pi (j + 1/2) / N) (Chebyshev coefficients, then the
 * Chebyshev polynomials' power coefficients; inflowsim.simulate.mutable.
 * _power_coefficients) */
static void cheb_power_matrix(int N, double w[IFS_MU_DEG + 1][IFS_MU_DEG + 1])
{
    double T[IFS_MU_DEG + 1][IFS_MU_DEG + 1];        /* T_k(x) = sum_i T[k][i] x^i */
    double ch[IFS_MU_DEG + 1][IFS_MU_DEG + 1];       /* Chebyshev coefficient k of f_j */
    int k, i, j;
    memset(T, 0, sizeof T);
    T[0][0] = 1.0;
    T[1][1] = 1.0;
    for (k = 2; k < N; k++)
        for (i = 0; i < N; i++)
            T[k][i] = (i > 0 ? 2.0 * T[k - 1][i - 1] : 0.0) - T[k - 2][i];
    for (k = 0; k < N; k++)
        for (j = 0; j < N; j++)
            ch[k][j] = cos(M_PI * k * (j + 0.5) / N) * (k == 0 ? 1.0 : 2.0) / N;
    for (i = 0; i < N; i++)
        for (j = 0; j < N; j++) {
            double acc = 0.0;
            for (k = i; k < N; k++) acc += T[k][i] * ch[k][j];
            w[i][j] = acc;
        }
}

int ifs_mu_table_fit(IfsMuTable *t, IfsMuEntries entries, void *ctx)
{
    const int N = IFS_MU_DEG + 1, NF = IFS_MU_FDEG + 1;
    double f[IFS_MU_DEG + 1][IFS_MU_NTAB];   /* 12 kB of stack, during a build */
    double w[IFS_MU_DEG + 1][IFS_MU_DEG + 1], wf[IFS_MU_DEG + 1][IFS_MU_DEG + 1];
    int seg, j, i, e, c;
    double worst = 0.0;
    cheb_power_matrix(N, w);
    cheb_power_matrix(NF, wf);
    t->state = -1;
    t->err = 0.0;
    t->fma = cpu_fma();
    mu_edges(t->edge);
    for (c = seg = 0; c < IFS_MU_NGUESS; c++) {
        const double at = IFS_MU_LO + (IFS_MU_HI - IFS_MU_LO) * c / IFS_MU_NGUESS;
        while (seg < IFS_MU_NSEG - 1 && at >= t->edge[seg + 1]) seg++;
        t->guess[c] = (unsigned char)seg;
    }
    for (seg = 0; seg < IFS_MU_NSEG; seg++) {
        const double lo = t->edge[seg], hi = t->edge[seg + 1];
        for (j = 0; j < N; j++) {
            const double xj = cos(M_PI * (j + 0.5) / N);
            if (entries(ctx, 0.5 * (lo + hi) + 0.5 * (hi - lo) * xj, f[j]) != 0)
                return t->state;
        }
        for (e = 0; e < IFS_MU_NTAB; e++)
            for (i = 0; i < N; i++) {
                double acc = 0.0;
                for (j = 0; j < N; j++) acc += w[i][j] * f[j][e];
                t->p[seg][i][e] = acc;
            }
        /* the parts: the segment's polynomial at each part's nodes, again */
        for (c = 0; c < IFS_MU_SPLIT; c++) {
            for (j = 0; j < NF; j++) {
                const double x = (2 * c + 1 + cos(M_PI * (j + 0.5) / NF)) / IFS_MU_SPLIT - 1.0;
                for (e = 0; e < IFS_MU_HALF0; e++) f[j][e] = ifs_mu_horner(t, seg, x, e);
            }
            for (e = 0; e < IFS_MU_HALF0; e++)
                for (i = 0; i < NF; i++) {
                    double acc = 0.0;
                    for (j = 0; j < NF; j++) acc += wf[i][j] * f[j][e];
                    t->q[seg * IFS_MU_SPLIT + c][i][e] = acc;
                }
        }
    }
    for (seg = 0; seg < IFS_MU_NSEG; seg++) {      /* check between the nodes */
        double got[IFS_MU_NTAB], want[IFS_MU_NTAB], scale[2] = {0.0, 0.0};
        const double mu = 0.5 * (t->edge[seg] + t->edge[seg + 1]);
        if (entries(ctx, mu, want) != 0) return t->state;
        ifs_mu_table_eval(t, mu, 0, got);
        ifs_mu_table_eval(t, mu, 1, got + IFS_MU_HALF0);
        for (e = 0; e < IFS_MU_NTAB; e++)
            if (fabs(want[e]) > scale[e >= IFS_MU_HALF0])
                scale[e >= IFS_MU_HALF0] = fabs(want[e]);
        for (e = 0; e < IFS_MU_NTAB; e++) {
            const double r = fabs(got[e] - want[e]) / scale[e >= IFS_MU_HALF0];
            if (!(r <= worst)) worst = r;       /* NaN-safe */
        }
    }
    t->err = worst;
    t->state = worst <= IFS_MU_TOL ? 1 : -1;
    return t->state;
}
