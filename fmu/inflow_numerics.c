/*
 * The FMU's numerics (inflow_numerics.h): dense LU and the other primitives of the
 * generated algorithms (inflow_algorithms.c: the matrix exponential, the Taylor step
 * of a remainder and its term count, the table's segment ends, fit, check, segment
 * finding and evaluation), the table in mu bound to them.
 * Nothing here knows the rotor; the model's equations are in inflow_equations.c
 * (generated) and inflow_model.c.
 */
#include <math.h>

#include "inflow_numerics.h"

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

/* --- the primitives of the generated algorithms (inflow_algorithms.c, from
 * inflowsim.simulate.algorithms, whose class P is their NumPy form) --- */

double ifs_absmax(const double *x, int size)
{
    double m = 0.0;
    int i;
    for (i = 0; i < size; i++)
        if (fabs(x[i]) > m) m = fabs(x[i]);
    return m;
}

/* NaN once a difference is */
double ifs_absdiffmax(const double *x, const double *y, int size)
{
    double m = 0.0;
    int i;
    for (i = 0; i < size; i++) {
        const double d = fabs(x[i] - y[i]);
        if (d > m || d != d) m = d;
        if (m != m) break;
    }
    return m;
}

/* The largest column sum of |A| (rows x cols, row-major); NaN if an entry is NaN */
double ifs_norm1(const double *A, int rows, int cols)
{
    double norm = 0.0;
    int i, j;
    for (j = 0; j < cols; j++) {
        double col = 0.0;
        for (i = 0; i < rows; i++) col += fabs(A[i * cols + j]);
        if (col > norm || col != col) norm = col;
        if (norm != norm) break;
    }
    return norm;
}

/* --- the table in mu --- */

/* The segment ends: lo q^s, q = (hi/lo)^(1/SEG), and the knots of a parameter
 * schedule (its range's ends, where the held values make a kink;
 * inflowsim.simulate.mutable.knot_edges chose them), merged in ascending order
 * (ifs_mu_edges, inflow_algorithms.c: inflowsim.simulate.mutable.edges). */
static void mu_edges(double e[IFS_MU_NSEG + 1])
{
#if IFS_MU_N_KNOTS
    static const double knots[IFS_MU_N_KNOTS] = IFS_MU_KNOTS;
    ifs_mu_edges(IFS_MU_LO, IFS_MU_HI, knots, IFS_MU_N_KNOTS, e);
#else
    ifs_mu_edges(IFS_MU_LO, IFS_MU_HI, NULL, 0, e);
#endif
}

void ifs_mu_table_eval(const IfsMuTable *t, double mu, int half, double *out)
{
    if (half == 0)             /* the parts (the same numbers as ifs_mu_table_apply) */
        ifs_mu_eval(t->pstart, t->pmid, t->pscale, t->guess, &t->q[0][0][0], mu, out);
    else
        ifs_mu_eval_coarse(t->edge, t->pstart, t->guess, &t->p[0][0][0], mu, IFS_MU_HALF0,
                           IFS_MU_HALF, out);
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

/* The table's values at mu (both halves: half 0 from the parts, what a mu change
 * reads; the callback of ifs_mu_check) */
static int table_values(void *t, double mu, double out[IFS_MU_NTAB])
{
    ifs_mu_table_eval((const IfsMuTable *)t, mu, 0, out);
    ifs_mu_table_eval((const IfsMuTable *)t, mu, 1, out + IFS_MU_HALF0);
    return 0;
}

int ifs_mu_table_fit(IfsMuTable *t, IfsMuEntries entries, void *ctx)
{
    double worst = 0.0;
    t->state = -1;
    t->err = 0.0;
    t->fma = cpu_fma();
    mu_edges(t->edge);
    ifs_mu_parts(t->edge, IFS_MU_NSEG, t->pstart, t->pmid, t->pscale, t->guess);
    /* the segments' and their parts' coefficients (inflow_algorithms.c) */
    if (ifs_mu_fit(t->edge, IFS_MU_NSEG, entries, ctx, &t->p[0][0][0], &t->q[0][0][0]) != 0)
        return t->state;
    /* the check between the nodes (inflow_algorithms.c) */
    worst = ifs_mu_check(t->edge, IFS_MU_NSEG, entries, ctx, table_values, t, IFS_MU_HALF0);
    if (worst < 0.0) return t->state;
    t->err = worst;
    t->state = worst <= IFS_MU_TOL ? 1 : -1;     /* (NaN: -1) */
    return t->state;
}
