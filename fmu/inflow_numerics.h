/*
 * The FMU's numerics, apart from the model's equations: dense LU solves and the
 * other primitives, the matrix exponential, the Taylor series of a remainder step
 * and the table in mu (fit, check and evaluation).  The algorithms themselves (the
 * exponential, the Taylor step and its term count, the table's segment ends, fit,
 * check, segment finding and evaluation) are generated (inflow_algorithms.c, from
 * inflowsim.simulate.algorithms, which the Python Simulator runs); here are their
 * primitives and the table's storage.  Knows nothing of rotors: the
 * model (inflow_model.c) gives the table its exact entries through a callback.  The
 * table's and the Taylor rule's constants (IFS_MU_LO ... IFS_KMAX) are generated
 * into inflow_vars.h from inflowsim.simulate.mutable.
 */
#ifndef INFLOW_NUMERICS_H
#define INFLOW_NUMERICS_H

#include <math.h>
#include <stddef.h>

#include "inflow_vars.h"

#define IFS_NU IFS_N_INPUTS        /* 10: theta0 .. muy */
#define IFS_NA (IFS_NX + IFS_NU)   /* augmented [x; u] */
#define IFS_LD ((IFS_NX + 3) / 4 * 4)   /* stored column length: whole vectors of 4 */
#define IFS_ZB ((IFS_NA + 3) / 4)   /* blocks of four of [x; u] (the last zero-padded) */
#define IFS_RL (4 * IFS_ZB)          /* a stored row of [a b]: [x; u]'s length, padded */
/* The step's [phi gam] (IfsModel.pg, inflow_model.h), element (i, j) at
 * IFS_PG_AT(i, j): up to 16 states by columns, IFS_LD each (rows past IFS_NX zero:
 * the column step, short from one state to the next), beyond by rows, IFS_RL each
 * (the row step: fewer operations, which a step of more states is bound by;
 * bench/fmu_states.md) */
#define IFS_COLUMN_STEP (IFS_NX <= 16)
#if IFS_COLUMN_STEP
#define IFS_PG_N (IFS_NA * IFS_LD)
#define IFS_PG_AT(i, j) ((j) * IFS_LD + (i))
#else
#define IFS_PG_N (IFS_NX * IFS_RL)
#define IFS_PG_AT(i, j) ((i) * IFS_RL + (j))
#endif

/* The DoStep functions, the mu table's evaluation and the stepping of whole
 * communication intervals (ifs_advance: substeps, the Taylor remainder) are
 * compiled twice where the loader can pick one at load time (GNU ifunc, glibc):
 * for AVX2 and for the baseline (IFS_HOT; with the four-wide step, IFS_WIDE_STEP in
 * inflow_model.h, the slave writes DoStep's two functions and their resolver
 * itself: ifs_do_step in inflow_slave.c).  The step does the same
 * operations in the same order in both, so both give the same numbers (a test
 * checks this bit for bit; build without floating-point contraction,
 * -ffp-contract=off, as inflowsim does).  -DIFS_NO_CLONES turns it off. */
#if defined(__has_attribute)
#if __has_attribute(target_clones) && defined(__x86_64__) && defined(__GLIBC__) && \
    !defined(IFS_NO_CLONES) && !(defined(__clang__) && __clang_major__ < 18)
/* (clang before 18 exports the clone dispatcher under another name) */
#define IFS_HOT __attribute__((target_clones("avx2", "default")))
#define IFS_HOT_CLONES 1
#endif
#endif
#ifndef IFS_HOT
#define IFS_HOT
#endif

#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif
/* unroll the loop that follows (its trip count is a compile-time constant): gcc -O2
 * keeps short inner loops rolled, and their counting costs as much as their work */
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 8
#define IFS_UNROLL _Pragma("GCC unroll 32")
#else
#define IFS_UNROLL
#endif

/* a generated algorithm in the step's hot path inlines every call in it
 * (inflowsim.simulate.algorithms.ATTRIBUTES) */
#if defined(__GNUC__)
#define IFS_FLATTEN __attribute__((flatten))
#else
#define IFS_FLATTEN
#endif

#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
/* unaligned, aliasing-safe views of 4 and 2 doubles */
typedef double ifs_v4 __attribute__((vector_size(32), aligned(8), may_alias));
typedef double ifs_v2 __attribute__((vector_size(16), aligned(8), may_alias));
#define IFS_INLINE static inline __attribute__((always_inline))
#else
#define IFS_INLINE static inline
#endif

/* The primitives the generated algorithms call most (inflow_algorithms.c, from
 * inflowsim.simulate.algorithms.P): inline, so a constant size unrolls.
 * dst = src, x *= alpha, y += alpha x (sizes in doubles), C = A B (n x n; C
 * neither A nor B; each row summed in the order of k), C = A B (rows x inner times
 * inner x cols, the rows of B ldb and of C ldc apart), Horner's rule for the
 * polynomials of degree deg in the columns of p at nx points (the rows of out ldo
 * apart). */
IFS_INLINE void ifs_copy(double *dst, const double *src, int size)
{
    int i;
    for (i = 0; i < size; i++) dst[i] = src[i];
}
IFS_INLINE void ifs_scale(double *x, double alpha, int size)
{
    int i;
    for (i = 0; i < size; i++) x[i] *= alpha;
}
IFS_INLINE void ifs_axpy(double *y, double alpha, const double *x, int size)
{
    int i;
    for (i = 0; i < size; i++) y[i] += alpha * x[i];
}
IFS_INLINE void ifs_gemm(const double *A, const double *B, double *C, int rows, int inner,
                         int cols, int ldb, int ldc)
{
    int i, j, k;
    for (i = 0; i < rows; i++) {
        double *row = C + i * ldc;
        for (j = 0; j < cols; j++) row[j] = 0.0;
        for (k = 0; k < inner; k++) {
            const double aik = A[i * inner + k];
            if (aik == 0.0) continue;
            for (j = 0; j < cols; j++) row[j] += aik * B[k * ldb + j];
        }
    }
}
/* the square case of ifs_gemm (n x n, rows n apart) */
IFS_INLINE void ifs_matmul(const double *A, const double *B, double *C, int n)
{
    ifs_gemm(A, B, C, n, n, n, n, n);
}
IFS_INLINE void ifs_horner(const double *p, int deg, const double *x, int nx, double *out,
                           int cols, int ldp, int ldo)
{
    int i, e, k;
    for (i = 0; i < nx; i++)
        for (e = 0; e < cols; e++) {
            double acc = p[deg * ldp + e];
            for (k = deg - 1; k >= 0; k--) acc = acc * x[i] + p[k * ldp + e];
            out[i * ldo + e] = acc;
        }
}

/* The mu table's evaluation (inflowsim.simulate.algorithms.mu_eval) with the CPU's
 * AVX2 and FMA where it has them and this build can (IFS_MU_FMA4; ifs_mu_eval_fma,
 * chosen at run time); else with the C library's fma, the same numbers. */
#if defined(__GNUC__) && defined(__x86_64__) && !defined(IFS_SCALAR_STEP) && \
    !defined(IFS_NO_CLONES)
#define IFS_MU_FMA4 1
#include <immintrin.h>
#endif

/* out[e] = sum_k q[k ld + e] y^k for e < cols, k = 0 .. deg: Horner's rule with
 * fused multiply-adds (one rounding each: every path gives the same numbers), four
 * entries a vector (the table's [phi gam], cols a multiple of four, straight into
 * the model's matrix). */
IFS_INLINE void ifs_fhorner(const double *q, int deg, double y, double *out, int cols,
                            int ld)
{
    int e, k;
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
    if (cols % 4 == 0) {
        IFS_UNROLL
        for (e = 0; e < cols; e += 4) {
            ifs_v4 acc = *(const ifs_v4 *)(q + deg * ld + e);
            IFS_UNROLL
            for (k = deg - 1; k >= 0; k--) {
                const ifs_v4 c = *(const ifs_v4 *)(q + k * ld + e);
                acc = (ifs_v4){fma(acc[0], y, c[0]), fma(acc[1], y, c[1]),
                               fma(acc[2], y, c[2]), fma(acc[3], y, c[3])};
            }
            *(ifs_v4 *)(out + e) = acc;
        }
        return;
    }
#endif
    for (e = 0; e < cols; e++) {
        double acc = q[deg * ld + e];
        for (k = deg - 1; k >= 0; k--) acc = fma(acc, y, q[k * ld + e]);
        out[e] = acc;
    }
}
/* y[r] = sum_c a[c lda + r] x[c] for r < rows (a by columns): the columns' multiples
 * summed in order (no fused multiply-add: every path gives the same numbers), four
 * rows a vector where rows is a multiple of four. */
IFS_INLINE void ifs_gemv_cols(const double *a, const double *x, double *y, int rows, int cols,
                              int lda)
{
    int r, c;
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
    if (rows % 4 == 0) {
        IFS_UNROLL
        for (r = 0; r < rows; r += 4) {
            ifs_v4 acc = *(const ifs_v4 *)(a + r) * x[0];
            IFS_UNROLL
            for (c = 1; c < cols; c++) acc += *(const ifs_v4 *)(a + c * lda + r) * x[c];
            *(ifs_v4 *)(y + r) = acc;
        }
        return;
    }
#endif
    for (r = 0; r < rows; r++) {
        double acc = a[r] * x[0];
        for (c = 1; c < cols; c++) acc += a[c * lda + r] * x[c];
        y[r] = acc;
    }
}
#ifdef IFS_MU_FMA4
/* ... the CPU's four fused multiply-adds at once (inside a function for AVX2 and FMA) */
static inline __attribute__((target("avx2,fma"), always_inline)) void
ifs_fhorner_fma(const double *q, int deg, double y, double *out, int cols, int ld)
{
    const __m256d yv = _mm256_set1_pd(y);
    int e, k;
    if (cols % 4) {
        ifs_fhorner(q, deg, y, out, cols, ld);
        return;
    }
    IFS_UNROLL
    for (e = 0; e < cols; e += 4) {
        __m256d acc = _mm256_loadu_pd(q + deg * ld + e);
        IFS_UNROLL
        for (k = deg - 1; k >= 0; k--)
            acc = _mm256_fmadd_pd(acc, yv, _mm256_loadu_pd(q + k * ld + e));
        _mm256_storeu_pd(out + e, acc);
    }
}
#endif


/* Solve A X = B in place (A n x n destroyed, B n x nrhs overwritten by X), LU with
 * partial pivoting.  -1 if a pivot is below tol times the largest |A| entry. */
int ifs_lu_solve(int n, double *A, int nrhs, double *B, double tol);

/* The other primitives of the generated algorithms (inflowsim.simulate.algorithms.P):
 * the largest |x| and |x - y| (NaN once a difference is), the 1-norm (NaN if an
 * entry is).  Sizes in doubles. */
double ifs_absmax(const double *x, int size);
double ifs_absdiffmax(const double *x, const double *y, int size);
double ifs_norm1(const double *A, int rows, int cols);

/* Generated from inflowsim.simulate.algorithms into inflow_algorithms.c (the
 * Simulator runs the same functions in Python):
 *
 * exp(A) of an IFS_NA x IFS_NA matrix (row-major), overwritten by the result:
 * scaling and squaring with the diagonal [13/13] Pade approximant, scaled to 1-norm
 * <= 5.37 (backward error below the unit roundoff, Higham 2005).  -1 if A is not
 * finite or the solve fails. */
int ifs_expm(double *A);

/* Terms of the Taylor series of a step of length |r| [s] for x' = a x + b u with
 * 1-norms norm_a = |a| and norm_ab = |[a b]|: the first k whose next term is
 * bounded by IFS_TAYLOR_TOL |[x; u]|; 0 if more than IFS_KMAX would be needed. */
int ifs_taylor_count(double norm_a, double norm_ab, double r);
/* [a b] (a IFS_NX x IFS_NX, b IFS_NX x IFS_NU, row-major) by rows into abr and by
 * columns into abc (IfsModel's layout, padding zero), norms = {|a|, |[a b]|}. */
void ifs_taylor_prepare(const double *a, const double *b, double *abr, double *abc,
                        double *norms);
/* z[0 .. IFS_NX) <- the state after r [s] for [x; u] = z held, by nk terms of that
 * series: abr [a b] by rows (IFS_RL apart), abc by columns (IFS_LD apart;
 * IfsModel's). */
void ifs_taylor_step(const double *abr, const double *abc, int nk, double r, double *z);

/* Chebyshev interpolation at n nodes: ch (n x n) gives the Chebyshev coefficients
 * sum_j ch[k][j] f_j of the polynomial through f_j at the Chebyshev-Gauss nodes
 * cos(pi (j + 1/2) / n), tt (n x n) the power coefficients tt[i][k] of T_k(x). */
void ifs_cheb_matrices(int n, double *ch, double *tt);
/* out = tt (ch f): the power coefficients (n rows of cols, ldo apart) of the
 * polynomials through the values f (n rows of cols, ldf apart) at the nodes; work
 * n x cols. */
void ifs_power_fit(int n, const double *ch, const double *tt, const double *f, int cols,
                   int ldf, double *work, double *out, int ldo);

/*
 * A matrix-valued function of mu tabulated on [IFS_MU_LO, IFS_MU_HI] (for the FMU:
 * [phi gam] at dt and [a b]): IFS_MU_SEG segments growing geometrically with mu
 * (and IFS_MU_N_KNOTS more where a parameter schedule has kinks: IFS_MU_NSEG),
 * on each a polynomial of degree IFS_MU_DEG in the local variable x in [-1, 1]
 * through exact values at the Chebyshev-Gauss nodes, stored as power coefficients
 * (Horner's rule).  Two halves, each checked at every segment's midpoint against
 * an exact value relative to the half's largest entry; the table is used only if
 * that is within IFS_MU_TOL.  Half 0 ([phi gam], IFS_MU_HALF0 entries) is stored in
 * the order the step reads it, so a mu change evaluates it straight into the
 * model's matrices (ifs_mu_table_apply, inflow_model.h): IfsModel.pg's order
 * (IFS_PG_AT, zero-padded to whole vectors of four).  Half 1 ([a b], row-major,
 * IFS_MU_HALF entries) is read rarely (a remainder step, a load).
 *
 * What a mu change evaluates, and the check checks, of half 0 is a finer table made
 * from the first without another exact value: each segment cut into IFS_MU_SPLIT
 * equal parts of x, on each the segment's polynomial interpolated again at the
 * part's IFS_MU_FDEG + 1 Chebyshev-Gauss nodes (local variable y in [-1, 1]),
 * evaluated by Horner's rule with fused multiply-adds (fma: one rounding, on every
 * path, so every build gives the same numbers): inflowsim.simulate.algorithms.mu_eval,
 * which the Simulator's table (inflowsim.simulate.mutable.MuTable) runs too.  The
 * part holding mu is the one its cell of IFS_MU_NGUESS equal cells starts in, or
 * the next (mu_part); y = (mu - pmid[j]) pscale[j].
 */
#define IFS_MU_HALF ((IFS_NX * IFS_NA + 3) / 4 * 4)
#define IFS_MU_HALF0 IFS_PG_N
/* half 0's first entries, phi's columns in the column step (ifs_mu_eval_held) */
#define IFS_MU_NPHI (IFS_NX * IFS_LD)
#define IFS_MU_NTAB (IFS_MU_HALF0 + IFS_MU_HALF)
#define IFS_MU_NPART (IFS_MU_NSEG * IFS_MU_SPLIT)
typedef struct {
    /* the parts' power coefficients of half 0 (IfsMuTable's comment): what a mu
     * change reads */
    double q[IFS_MU_NPART][IFS_MU_FDEG + 1][IFS_MU_HALF0];
    int state;                 /* 0 not built, 1 valid, -1 not accurate enough */
    int fma;                   /* 1: evaluate with the CPU's AVX2 and FMA (IFS_MU_FMA4) */
    double err;                /* the largest relative error found by the check */
    double edge[IFS_MU_NSEG + 1];                        /* segment ends */
    /* the parts (ifs_mu_parts): their starts (then +inf), the midpoints and scales
     * of their local variables; the part holding the start of cell c of
     * IFS_MU_NGUESS equal cells */
    double pstart[IFS_MU_NPART + 1];
    double pmid[IFS_MU_NPART];
    double pscale[IFS_MU_NPART];
    double guess[IFS_MU_NGUESS];
    double p[IFS_MU_NSEG][IFS_MU_DEG + 1][IFS_MU_NTAB];  /* power coefficients */
} IfsMuTable;
/* edge, pstart, pmid, pscale, guess one after the other (ifs_mu_eval_held's parts) */
typedef char ifs_mu_parts_are_contiguous[
    offsetof(IfsMuTable, pstart) == offsetof(IfsMuTable, edge) + (IFS_MU_NSEG + 1) * 8 &&
    offsetof(IfsMuTable, pmid) == offsetof(IfsMuTable, pstart) + (IFS_MU_NPART + 1) * 8 &&
    offsetof(IfsMuTable, pscale) == offsetof(IfsMuTable, pmid) + IFS_MU_NPART * 8 &&
    offsetof(IfsMuTable, guess) == offsetof(IfsMuTable, pscale) + IFS_MU_NPART * 8 ? 1 : -1];

/* The exact entries at mu (both halves, IFS_MU_NTAB values); 0, or -1 if there are
 * none there. */
typedef int (*IfsMuEntries)(void *ctx, double mu, double out[IFS_MU_NTAB]);

/* The segment ends lo (hi/lo)^(s/IFS_MU_SEG) and the nknots knots, merged
 * ascending (IFS_MU_SEG + nknots + 1 of them; inflow_algorithms.c, from
 * inflowsim.simulate.algorithms.mu_edges). */
void ifs_mu_edges(double lo, double hi, const double *knots, int nknots, double *e);

/* The segments' power coefficients p ([IFS_MU_NSEG][IFS_MU_DEG + 1][IFS_MU_NTAB]) and
 * their parts' q of half 0 ([IFS_MU_NPART][IFS_MU_FDEG + 1][IFS_MU_HALF0]) from the
 * exact entries (generated into inflow_algorithms.c from
 * inflowsim.simulate.algorithms.mu_fit); -1 where entries has none. */
int ifs_mu_fit(const double *edge, int nseg, IfsMuEntries entries, void *ctx, double *p,
               double *q);

/* The largest difference between the table's values (table, tctx) and the exact
 * entries at the segments' midpoints, relative to the largest exact value of each
 * half (entries [0, split) and [split, IFS_MU_NTAB)); NaN once a difference is; -1
 * where entries has none (inflow_algorithms.c, from
 * inflowsim.simulate.algorithms.mu_check). */
double ifs_mu_check(const double *edge, int nseg, IfsMuEntries entries, void *ctx,
                    IfsMuEntries table, void *tctx, int split);

/* The parts' starts, midpoints and scales, the cells' parts (guess, IFS_MU_NGUESS);
 * the part holding mu; the table's [phi gam] at mu from the parts q (IFS_MU_HALF0
 * entries into out; _fma with the CPU's AVX2 and FMA); entries first .. first +
 * size - 1 of the segments' p at mu (inflow_algorithms.c, from
 * inflowsim.simulate.algorithms: mu_parts, mu_part, mu_eval, mu_eval_coarse, which
 * the Simulator runs). */
void ifs_mu_parts(const double *edge, int nseg, double *pstart, double *pmid, double *pscale,
                  double *guess);
int ifs_mu_part(const double *pstart, const double *guess, double mu);
void ifs_mu_eval(const double *pstart, const double *pmid, const double *pscale,
                 const double *guess, const double *q, double mu, double *out);
#ifdef IFS_MU_FMA4
void ifs_mu_eval_fma(const double *pstart, const double *pmid, const double *pscale,
                     const double *guess, const double *q, double mu, double *out);
#endif
/* A change of mu with the inputs held (the column step): in m, the model's [phi gam],
 * [x; u], g, gq, gq_seg and gam_mu one after the other (IfsModel): phi, and g = gam
 * u from gq, the power coefficients of gam u on the segment holding mu, made again
 * where that is not the segment |gq_seg| - 1 (mu_eval_held; parts: the table's
 * edge, pstart, pmid, pscale and guess one after the other, IfsMuTable).  Entries
 * first .. first + size - 1 of ifs_mu_eval's into out's (mu_eval_range: gam when it
 * is read; parts from pstart). */
void ifs_mu_eval_held(const double *parts, const double *q, const double *p, double mu,
                      double *m);
void ifs_mu_eval_range(const double *parts, const double *q, double mu, int first, int size,
                       double *out);
#ifdef IFS_MU_FMA4
void ifs_mu_eval_held_fma(const double *parts, const double *q, const double *p, double mu,
                          double *m);
void ifs_mu_eval_range_fma(const double *parts, const double *q, double mu, int first,
                           int size, double *out);
/* f (the arguments ...) with the CPU's AVX2 and FMA where t->fma (f_fma), else f */
#define IFS_MU_CALL(t, f, ...) ((t)->fma ? f##_fma(__VA_ARGS__) : f(__VA_ARGS__))
#else
#define IFS_MU_CALL(t, f, ...) f(__VA_ARGS__)
#endif
void ifs_mu_eval_coarse(const double *edge, const double *pstart, const double *guess,
                        const double *p, double mu, int first, int size, double *out);

/* Fit and check the table; returns t->state (1 valid, -1 not). */
int ifs_mu_table_fit(IfsMuTable *t, IfsMuEntries entries, void *ctx);
/* Half 0 (IFS_MU_HALF0 entries, from the parts) or 1 (IFS_MU_HALF) of the
 * interpolant at mu (within the table's range). */
void ifs_mu_table_eval(const IfsMuTable *t, double mu, int half, double *out);

#endif
