/*
 * Rotor flap and dynamic inflow, after "Glauert augmentation of rotor inflow
 * dynamics" (ERF 1989): equations, exact zero-order-hold discretisation, one step.
 *
 * Knows nothing of FMI.  No global mutable state: everything lives in IfsModel,
 * which is plain data (copyable with memcpy, so an FMU state is a copy).
 *
 * Inputs u (IFS_NU = 10, SI perturbations about trim, the record columns):
 *   theta0 theta1c theta1s [rad] muz [-] q p [rad/s] qdot pdot [rad/s^2] mux muy [-]
 * States x = outputs before the azimuth-bias rotation:
 *   beta0 beta1c beta1s [rad] lambda0 lambda1c lambda1s [-]
 *   (then the flap rates beta0_prime beta1c_prime beta1s_prime [rad/s] with
 *   flap-inertia: IFS_NX 9)
 * Continuous:  x_dot = a x + b u,   y = c x   (seconds, model.md Eq. 8-9, 13, 19-20)
 * Discrete:    x_{k+1} = phi x_k + gam u_k   (u held over the step)
 */
#ifndef INFLOW_MODEL_H
#define INFLOW_MODEL_H

#include <string.h>

#include "inflow_numerics.h"   /* inflow_vars.h; IFS_NU, IFS_NA, IFS_LD; IFS_HOT ... */

/* IFS_NX (6, or 9 with flap-inertia), IFS_N_STRUCTURES and IFS_STRUCTURE_NAMES come
 * from the generated inflow_vars.h: the structures this FMU was generated for */
#define IFS_NL 5                   /* loads: CT C_mc C_ms C_mc_hub C_ms_hub */

/* Rows past the last whole group of four (nine states: row 8) are summed row by row
 * in the generic step (see ifs_step): the products of a row are taken in vectors of
 * four over [x; u] (IFS_ZB blocks, x and u each padded with zeros to whole blocks),
 * not in a quarter-used vector per column.  The six-state step keeps its own sums. */
#define IFS_NG4 (IFS_NX / 4)               /* whole groups of four rows */
#define IFS_NLEFT (IFS_NX % 4)             /* the rows after them */
#define IFS_XB ((IFS_NX + 3) / 4)          /* blocks of four of x */
#define IFS_ZB (IFS_XB + (IFS_NU + 3) / 4) /* ... of [x; u] */
#define IFS_RL (4 * IFS_ZB)                /* a packed row's length */
#if IFS_NX != 6 && IFS_NLEFT > 0
#define IFS_ROW_STEP 1
#endif


typedef struct {
    /* First what the step reads, each a whole number of 32-byte vectors from the
     * start, which the slave keeps 64-byte aligned (IfsSlave, the FMI layers'
     * instances): a four-wide load or store across a 64-byte cache line costs more
     * (the nine-state step took about 2 ns longer at an unlucky heap address, and
     * 0.6 ns longer with x across a line, bench/fmu.md). */
    /* [phi gam] at the internal step dt, stored by columns (IFS_NA columns of
     * IFS_LD, rows NX.. zero) so one step is a sum of scaled columns, four and
     * two rows at a time (see ifs_step) */
    double pg[IFS_NA * IFS_LD];
    /* state (x_pad_: whole vectors, see above) */
    double x[IFS_NX];
    double x_pad_[IFS_LD - IFS_NX + 4];
#ifdef IFS_ROW_STEP
    /* the last IFS_NX % 4 rows of pg again, row by row (IFS_RL each: the x part and
     * the u part each padded with zeros to whole vectors of four), so the four-wide
     * step (ifs_step_wide) loads four of their coefficients at a time; refreshed
     * with pg (pack_rows in inflow_model.c) */
    double prow[IFS_NLEFT * IFS_RL];
#endif
    /* continuous SI state space, row-major */
    double a[IFS_NX * IFS_NX];
    double b[IFS_NX * IFS_NU];
    /* outputs y = c x: identity but the recorded flap rotated by the azimuth bias */
    double cos_bias, sin_bias;
    /* the same rotation by columns: cos, sin | -sin, cos (the four-wide step's
     * outputs, two at a time) */
    double rot[4];
    /* loads = lc x + ld u (inflowsim.model.loads: Eq. (4) times a0 s, the flap rate
     * from the dynamics, the true pitch; the flap springs' hub moments), row-major */
    double lc[IFS_NL * IFS_NX];
    double ld[IFS_NL * IFS_NU];
    double dt;
    /* cached [phi gam] (by columns) of a remainder step (h not n dt) */
    double pg_rem[IFS_NA * IFS_LD];
    double rem;                    /* its length [s]; 0 = no cache */
    /* the remainder asked for by the previous call under the same matrices (0: none).
     * The second remainder in a row is cached; a later one that differs from the
     * cached one by d is the cached step followed by the Taylor series of the state
     * over d (of either sign), or over the whole remainder when that takes fewer
     * terms (ifs_advance) */
    double rem_prev;
    /* [a b] stored by columns like pg (the Taylor remainder's matrix-vector
     * products, two rows at a time) */
    double abc[IFS_NA * IFS_LD];
    /* 1-norms of a and of [a b] [1/s]: the Taylor series' term bounds */
    double norm_a, norm_ab;
    /* 1: a, b, lc, ld and the norms are not yet for the current mu (a mu change
     * applied from the table updates [phi gam] first, the rest when asked) */
    int ab_stale;
    /* cached split of the last communication step h = n dt + rem */
    double h_last;
    long long n_last;
    double rem_last;
} IfsModel;

/* The discrete matrices tabulated in mu for one set of parameters (IfsMuTable,
 * inflow_numerics.h): a flight condition changing every step costs a polynomial
 * evaluation instead of a rebuild and a matrix exponential.  [phi gam] (at dt, by
 * columns) and [a b] (row-major) are analytic in mu on [IFS_MU_LO, IFS_MU_HI], their
 * only singularity mu = 0 (L ~ 1/mu).  Built on the first mu change after a parameter
 * change; else mu changes rebuild exactly. */
/* Build the table for the parameters in v (mu ignored); returns t->state. */
int ifs_mu_table_build(IfsMuTable *t, const IfsVariables *v);
/* Set m's [phi gam] at dt for v->mu from a valid table, and mark a, b and the loads
 * stale (m->ab_stale): the step at dt needs only [phi gam]. */
void ifs_mu_table_apply(const IfsMuTable *t, const IfsVariables *v, IfsModel *m);
/* Bring a, b, the loads and the Taylor bounds up to date after ifs_mu_table_apply
 * (a remainder step or a load read needs them). */
void ifs_mu_table_apply_ab(const IfsMuTable *t, const IfsVariables *v, IfsModel *m);

/* Build a, b, c (and [phi gam] at v->dt) from the variables (parameters, constants,
 * mu, structure).  The state x is kept.  Returns 0, or -1 with a one-line reason in
 * msg; on failure *m is unchanged. */
int ifs_build(IfsModel *m, const IfsVariables *v, char *msg, size_t msg_len);

/* Descriptor matrices in azimuth time, model.md Eq. (8): E x' = A x + B u_az,
 * u_az the inputs in azimuth units (qbar = q/Omega, qbar' = qdot/Omega^2 ...). */
void ifs_descriptor(const IfsVariables *v, double e[IFS_NX * IFS_NX],
                    double a[IFS_NX * IFS_NX], double b[IFS_NX * IFS_NU]);

/* Generated from the Python model (inflow_equations.c, inflowsim.fmu.codegen), for
 * v->structure: the descriptor at the speed V through the disc, the azimuth bias
 * [rad], the flap channels' time shifts [s], the loads' rows from the SI state space
 * a, b (inflowsim.model.loads.load_rows: lc 5 x NX, ld 5 x NU, row-major); and the
 * speed through the disc (inflowsim.physics.loads: mu, or the mass-flow parameter). */
void ifs_descriptor_of(const IfsVariables *v, double V, double *e, double *a, double *b);
double ifs_bias_of(const IfsVariables *v);
void ifs_flap_delays_of(const IfsVariables *v, double d[3]);
void ifs_loads_of(const IfsVariables *v, const double *a, const double *b, double *lc,
                  double *ld);
double ifs_flow_speed(const IfsVariables *v);
#if IFS_N_SCHEDULED
/* Generated from a parameter schedule (inflowsim fmu build --schedule): the
 * scheduled parameters (local variables) in v at v->mu, held beyond the schedule's
 * range (inflowsim.model.schedule.Schedule.__call__, the same operations). */
void ifs_schedule_apply(IfsVariables *v);
#endif

/* [phi gam] for a step h [s]: exp([[a, b], [0, 0]] h), top rows, stored by columns
 * (element (i, j) at pg[j * IFS_LD + i], padding rows zero). */
int ifs_discretize(const IfsModel *m, double h, double pg[IFS_NA * IFS_LD]);

/* Advance the state over h [s] with u held: whole internal steps dt and one exact
 * remainder step.  Returns 0, or -1 if the remainder discretisation failed. */
int ifs_advance(IfsModel *m, const double u[IFS_NU], double h);

/* y = c x: the recorded flap is the true one rotated by the azimuth bias. */
IFS_INLINE void ifs_outputs(const IfsModel *m, double y[IFS_NX])
{
    const double *x = m->x;
    y[0] = x[0];
    y[1] = m->cos_bias * x[1] - m->sin_bias * x[2];
    y[2] = m->sin_bias * x[1] + m->cos_bias * x[2];
    y[3] = x[3];
    y[4] = x[4];
    y[5] = x[5];
}

/*
 * x <- phi x + gam u with [phi gam] = pg: one step, the simulator loop's hot path,
 * inline so that it is compiled for the caller's target (see IFS_HOT in
 * inflow_slave.h).  The sum is a fixed tree: gam u (independent of x) first, then
 * six products of x, so the chain from x to the new x is one multiply and three
 * adds.  Rows 0-3 and 4-5 go as vectors of four and two where the compiler has
 * GNU vector types; otherwise scalar, in the same order, so the rounding is the
 * same on every path, provided the compiler does not contract a * b + c into a fused
 * multiply-add (inflowsim builds with -ffp-contract=off; clang is told below).
 */
/* the new rows r.. of x as one value of type T (double, or a vector of doubles) */
#define IFS_C(T, j) (*(const T *)(pg + (r_) + (j) * IFS_LD))
#define IFS_STEP_ROWS(T, r, s)                                                         \
    do {                                                                               \
        const int r_ = (r);                                                            \
        const T g_ = ((IFS_C(T, 6) * u[0] + IFS_C(T, 7) * u[1]) +                      \
                      (IFS_C(T, 8) * u[2] + IFS_C(T, 9) * u[3])) +                     \
                     ((IFS_C(T, 10) * u[4] + IFS_C(T, 11) * u[5]) +                    \
                      (IFS_C(T, 12) * u[6] + IFS_C(T, 13) * u[7])) +                   \
                     (IFS_C(T, 14) * u[8] + IFS_C(T, 15) * u[9]);                      \
        s = ((g_ + IFS_C(T, 0) * x[0]) + (IFS_C(T, 1) * x[1] + IFS_C(T, 2) * x[2])) +  \
            ((IFS_C(T, 3) * x[3] + IFS_C(T, 4) * x[4]) + IFS_C(T, 5) * x[5]);          \
    } while (0)

#if IFS_NX == 6
IFS_INLINE void ifs_step(const double *pg, double x[IFS_NX], const double u[IFS_NU])
{
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
    ifs_v4 top;
    ifs_v2 bottom;
    IFS_STEP_ROWS(ifs_v4, 0, top);
    IFS_STEP_ROWS(ifs_v2, 4, bottom);
    *(ifs_v4 *)x = top;
    *(ifs_v2 *)(x + 4) = bottom;
#else
    double y[IFS_NX];
    int i;
    for (i = 0; i < IFS_NX; i++) IFS_STEP_ROWS(double, i, y[i]);
    memcpy(x, y, sizeof y);
#endif
}
#else
/* other state counts (flap-inertia's nine): each new row is gam u and phi x, each
 * summed as a fixed pairwise tree ((gam u) + phi_0 x_0 first), so the chain from x
 * to the new x is one multiply and four adds for nine states and gam u's ten terms
 * no longer make a chain of ten adds.  Whole groups of four rows go two rows at a
 * time (native on every x86-64, SSE2, so the baseline code is fast too), four in the
 * AVX2 DoStep (ifs_step_wide below), one in plain C; the rows after them (nine
 * states: row 8) row by row, four products at a time (ifs_row_sum): a column-wise
 * vector would carry one useful lane of four, and every vector operation and load
 * counts in the step.  The same operations per row in the same order on every path,
 * so the same numbers. */
/* out = the pairwise sum of the K terms term(j_) (K < 32): the tree whose blocks are
 * aligned at powers of two, evaluated streaming (partial sums of whole blocks kept
 * by size, as a binary counter), so only a few values are live at once: the terms
 * all at once spilled registers.  The association is fixed by K alone, so every
 * width (double, pairs, fours) rounds alike. */
#define IFS_TREE_SUM(T, K, first, term, out)                                           \
    do {                                                                               \
        T s_[5], c_;                                                                   \
        int j_, l_, have_ = 0;                                                         \
        IFS_UNROLL                                                                     \
        for (j_ = 0; j_ < (K); j_++) {                                                 \
            if (j_ == 0)                                                               \
                c_ = first;                                                            \
            else                                                                       \
                c_ = term;                                                             \
            IFS_UNROLL                                                                 \
            for (l_ = 0; l_ < 5; l_++) {                                               \
                if ((j_ >> l_) & 1) {                                                  \
                    c_ = s_[l_] + c_;                                                  \
                } else {                                                               \
                    s_[l_] = c_;                                                       \
                    break;                                                             \
                }                                                                      \
            }                                                                          \
        }                                                                              \
        IFS_UNROLL                                                                     \
        for (l_ = 0; l_ < 5; l_++)                                                     \
            if (((K) >> l_) & 1) {                                                     \
                if (have_)                                                             \
                    c_ = s_[l_] + c_;                                                  \
                else                                                                   \
                    c_ = s_[l_];                                                       \
                have_ = 1;                                                             \
            }                                                                          \
        out = c_;                                                                      \
    } while (0)
/* the new rows at c (column j at c + j * IFS_LD) as one T (double or a vector):
 * (gam u) and then (gam u + phi_0 x_0) + phi_1 x_1 ... each a tree */
#define IFS_COL(T, c, j) (*(const T *)((c) + (j) * IFS_LD))
#define IFS_GROUP(T, c, out)                                                           \
    do {                                                                               \
        T g_;                                                                          \
        IFS_TREE_SUM(T, IFS_NU, IFS_COL(T, c, IFS_NX) * u[0],                          \
                     IFS_COL(T, c, IFS_NX + j_) * u[j_], g_);                          \
        IFS_TREE_SUM(T, IFS_NX, g_ + IFS_COL(T, c, 0) * x[0], IFS_COL(T, c, j_) * x[j_],  \
                     out);                                                             \
    } while (0)

#ifdef IFS_ROW_STEP
/* A row after the whole groups of four (ifs_step, ifs_step_wide): lane l of block b
 * of [x; u] is coefficient * entry, or 0 * 0 in the padding, exactly as the four-wide
 * step multiplies a packed row (m->prow) by the zero-padded blocks.  Each lane
 * is a pairwise tree over the blocks, the u blocks first (gam u), then the lanes
 * (l0 + l2) + (l1 + l3) (two vector adds from four lanes): the same operations in
 * the same order on every path. */
#define IFS_RBLOCK(k) (((k) + IFS_XB) % IFS_ZB)
#define IFS_RTERM(b, l)                                                                \
    ((b) < IFS_XB                                                                      \
         ? (4 * (b) + (l) < IFS_NX ? pg[(4 * (b) + (l)) * IFS_LD + i] * x[4 * (b) + (l)] \
                                   : 0.0 * 0.0)                                        \
         : (4 * ((b) - IFS_XB) + (l) < IFS_NU                                          \
                ? pg[(IFS_NX + 4 * ((b) - IFS_XB) + (l)) * IFS_LD + i] *               \
                      u[4 * ((b) - IFS_XB) + (l)]                                      \
                : 0.0 * 0.0))
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
/* lanes 2h, 2h + 1 of block b as a pair (the baseline code's vectors; 0 * 0 in the
 * padding as above): lanes 0, 1 and 2, 3 summed apart, then added, are
 * (l0 + l2, l1 + l3) */
#define IFS_RCOEF(b, l)                                                                \
    ((b) < IFS_XB ? (4 * (b) + (l) < IFS_NX ? pg[(4 * (b) + (l)) * IFS_LD + i] : 0.0)   \
                  : (4 * ((b) - IFS_XB) + (l) < IFS_NU                                 \
                         ? pg[(IFS_NX + 4 * ((b) - IFS_XB) + (l)) * IFS_LD + i]        \
                         : 0.0))
#define IFS_RZ(b, l)                                                                   \
    ((b) < IFS_XB ? (4 * (b) + (l) < IFS_NX ? x[4 * (b) + (l)] : 0.0)                  \
                  : (4 * ((b) - IFS_XB) + (l) < IFS_NU ? u[4 * ((b) - IFS_XB) + (l)] : 0.0))
#define IFS_RPROD(b, h)                                                                \
    ((ifs_v2){IFS_RCOEF(b, 2 * (h)), IFS_RCOEF(b, 2 * (h) + 1)} *                      \
     (ifs_v2){IFS_RZ(b, 2 * (h)), IFS_RZ(b, 2 * (h) + 1)})
IFS_INLINE double ifs_row_sum(const double *pg, int i, const double *x, const double *u)
{
    ifs_v2 lo, hi, h;
    IFS_TREE_SUM(ifs_v2, IFS_ZB, IFS_RPROD(IFS_RBLOCK(0), 0), IFS_RPROD(IFS_RBLOCK(j_), 0), lo);
    IFS_TREE_SUM(ifs_v2, IFS_ZB, IFS_RPROD(IFS_RBLOCK(0), 1), IFS_RPROD(IFS_RBLOCK(j_), 1), hi);
    h = lo + hi;
    return h[0] + h[1];
}
#else
IFS_INLINE double ifs_row_sum(const double *pg, int i, const double *x, const double *u)
{
    double p[4];
    int l;
    IFS_UNROLL
    for (l = 0; l < 4; l++)
        IFS_TREE_SUM(double, IFS_ZB, IFS_RTERM(IFS_RBLOCK(0), l),
                     IFS_RTERM(IFS_RBLOCK(j_), l), p[l]);
    return (p[0] + p[2]) + (p[1] + p[3]);
}
#endif
#endif

IFS_INLINE void ifs_step(const double *pg, double x[IFS_NX], const double u[IFS_NU])
{
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
    /* every sum before any store (each reads all of x), then straight into x: a
     * copy through a buffer stalls store forwarding every step */
    ifs_v2 y[IFS_NG4 > 0 ? 2 * IFS_NG4 : 1];
    int r;
#ifdef IFS_ROW_STEP
    double tail[IFS_NLEFT];
#endif
    IFS_UNROLL
    for (r = 0; r < 2 * IFS_NG4; r++) IFS_GROUP(ifs_v2, pg + 2 * r, y[r]);
#ifdef IFS_ROW_STEP
    IFS_UNROLL
    for (r = 0; r < IFS_NLEFT; r++) tail[r] = ifs_row_sum(pg, 4 * IFS_NG4 + r, x, u);
#endif
    IFS_UNROLL
    for (r = 0; r < 2 * IFS_NG4; r++) *(ifs_v2 *)(x + 2 * r) = y[r];
#ifdef IFS_ROW_STEP
    IFS_UNROLL
    for (r = 0; r < IFS_NLEFT; r++) x[4 * IFS_NG4 + r] = tail[r];
#endif
#else
    double y[IFS_NX];
    int i;
    for (i = 0; i < 4 * IFS_NG4; i++) IFS_GROUP(double, pg + i, y[i]);
#ifdef IFS_ROW_STEP
    for (i = 4 * IFS_NG4; i < IFS_NX; i++) y[i] = ifs_row_sum(pg, i, x, u);
#endif
    memcpy(x, y, sizeof y);
#endif
}

/* The same step four rows at a time, for the AVX2 variant of the DoStep functions
 * (IFS_WIDE_STEP; the FMI layers pick it at load time where the CPU has AVX2:
 * 256-bit vectors on the baseline x86-64 code are split badly, so that keeps the
 * pairs), on m's [phi gam] at dt: the whole groups of four rows by columns, two
 * groups side by side (IFS_TREE_SUM2: each x_j and u_j broadcast once for both, and
 * few values live at once: one group after the other kept 19 broadcasts live and
 * spilled them), the rows after them from the packed rows (m->prow) four products
 * at a time.  It also leaves the six outputs (ifs_outputs: beta0 .. lambda1s) in
 * out, from the new rows in registers (read back from x, they waited for the
 * stores), with in-lane shuffles only.  The same operations in the same order as
 * ifs_step, so the same numbers. */
#if defined(IFS_HOT_CLONES) && !defined(IFS_SCALAR_STEP)
#define IFS_WIDE_STEP 1
#include <immintrin.h>
/* IFS_TREE_SUM of two sums term by term: the same tree for each */
#define IFS_TREE_SUM2(T, K, first0, first1, term0, term1, out0, out1)                  \
    do {                                                                               \
        T a_[5], b_[5], c_, d_;                                                        \
        int j_, l_, have_ = 0;                                                         \
        IFS_UNROLL                                                                     \
        for (j_ = 0; j_ < (K); j_++) {                                                 \
            if (j_ == 0) {                                                             \
                c_ = first0;                                                           \
                d_ = first1;                                                           \
            } else {                                                                   \
                c_ = term0;                                                            \
                d_ = term1;                                                            \
            }                                                                          \
            IFS_UNROLL                                                                 \
            for (l_ = 0; l_ < 5; l_++) {                                               \
                if ((j_ >> l_) & 1) {                                                  \
                    c_ = a_[l_] + c_;                                                  \
                    d_ = b_[l_] + d_;                                                  \
                } else {                                                               \
                    a_[l_] = c_;                                                       \
                    b_[l_] = d_;                                                       \
                    break;                                                             \
                }                                                                      \
            }                                                                          \
        }                                                                              \
        IFS_UNROLL                                                                     \
        for (l_ = 0; l_ < 5; l_++)                                                     \
            if (((K) >> l_) & 1) {                                                     \
                if (have_) {                                                           \
                    c_ = a_[l_] + c_;                                                  \
                    d_ = b_[l_] + d_;                                                  \
                } else {                                                               \
                    c_ = a_[l_];                                                       \
                    d_ = b_[l_];                                                       \
                }                                                                      \
                have_ = 1;                                                             \
            }                                                                          \
        out0 = c_;                                                                     \
        out1 = d_;                                                                     \
    } while (0)
/* IFS_GROUP for the groups at c and c + 4 side by side */
#define IFS_GROUP2(c, out0, out1)                                                      \
    do {                                                                               \
        ifs_v4 g0_, g1_;                                                               \
        IFS_TREE_SUM2(ifs_v4, IFS_NU, IFS_COL(ifs_v4, c, IFS_NX) * u[0],               \
                      IFS_COL(ifs_v4, (c) + 4, IFS_NX) * u[0],                         \
                      IFS_COL(ifs_v4, c, IFS_NX + j_) * u[j_],                         \
                      IFS_COL(ifs_v4, (c) + 4, IFS_NX + j_) * u[j_], g0_, g1_);        \
        IFS_TREE_SUM2(ifs_v4, IFS_NX, g0_ + IFS_COL(ifs_v4, c, 0) * x[0],              \
                      g1_ + IFS_COL(ifs_v4, (c) + 4, 0) * x[0],                        \
                      IFS_COL(ifs_v4, c, j_) * x[j_],                                  \
                      IFS_COL(ifs_v4, (c) + 4, j_) * x[j_], out0, out1);               \
    } while (0)
static inline __attribute__((target("avx2"), always_inline)) void
ifs_step_wide(IfsModel *m, const double u[IFS_NU], double out[6])
{
    const double *pg = m->pg;
    double *x = m->x;
    ifs_v4 y[IFS_NG4 > 0 ? IFS_NG4 : 1];
    int g;
#ifdef IFS_ROW_STEP
    double tail[IFS_NLEFT];
    ifs_v4 z[IFS_ZB];
    int b, l;
    IFS_UNROLL
    for (b = 0; b < IFS_ZB; b++) {     /* [x; u] in blocks of four, zero-padded */
        const double *src = b < IFS_XB ? x + 4 * b : u + 4 * (b - IFS_XB);
        const int n = b < IFS_XB ? IFS_NX - 4 * b : IFS_NU - 4 * (b - IFS_XB);
        if (n >= 4) {
            z[b] = *(const ifs_v4 *)src;
        } else if (n >= 2) {       /* one 16-byte load, the upper half zero */
            const ifs_v2 h = *(const ifs_v2 *)src;
            const ifs_v4 t = {h[0], h[1], n == 3 ? src[2] : 0.0, 0.0};
            z[b] = t;
        } else {
            const ifs_v4 t = {src[0], 0.0, 0.0, 0.0};
            z[b] = t;
        }
    }
#endif
    IFS_UNROLL
    for (g = 0; g + 1 < IFS_NG4; g += 2) IFS_GROUP2(pg + 4 * g, y[g], y[g + 1]);
#if IFS_NG4 % 2
    IFS_GROUP(ifs_v4, pg + 4 * (IFS_NG4 - 1), y[IFS_NG4 - 1]);
#endif
#ifdef IFS_ROW_STEP
    IFS_UNROLL
    for (l = 0; l < IFS_NLEFT; l++) {
        const double *c = m->prow + l * IFS_RL;
        ifs_v4 p;
        IFS_TREE_SUM(ifs_v4, IFS_ZB, *(const ifs_v4 *)(c + 4 * IFS_RBLOCK(0)) * z[IFS_RBLOCK(0)],
                     *(const ifs_v4 *)(c + 4 * IFS_RBLOCK(j_)) * z[IFS_RBLOCK(j_)], p);
        {
            /* (l0 + l2, l1 + l3), then their sum: the lanes as ifs_row_sum adds them */
            const __m128d h = _mm_add_pd(_mm256_castpd256_pd128((__m256d)p),
                                         _mm256_extractf128_pd((__m256d)p, 1));
            tail[l] = _mm_cvtsd_f64(_mm_add_sd(h, _mm_unpackhi_pd(h, h)));
        }
    }
#endif
    IFS_UNROLL
    for (g = 0; g < IFS_NG4; g++) *(ifs_v4 *)(x + 4 * g) = y[g];
#ifdef IFS_ROW_STEP
    IFS_UNROLL
    for (l = 0; l < IFS_NLEFT; l++) x[4 * IFS_NG4 + l] = tail[l];
#endif
#if IFS_NG4 >= 2
    {
        /* [c x1 + (-s) x2, s x1 + c x2]: ifs_outputs' c x1 - s x2 and s x1 + c x2,
         * exactly (a - b is a + (-b) in IEEE arithmetic); x1 and x2 paired in their
         * own halves of the vector (a lane-crossing permute per value cost 0.8 ns) */
        const __m128d lo = _mm256_castpd256_pd128((__m256d)y[0]);
        const __m128d hi = _mm256_extractf128_pd((__m256d)y[0], 1);
        const __m128d x1 = _mm_unpackhi_pd(lo, lo), x2 = _mm_movedup_pd(hi);
        const __m128d r = _mm_add_pd(_mm_mul_pd(x1, _mm_loadu_pd(m->rot)),
                                     _mm_mul_pd(x2, _mm_loadu_pd(m->rot + 2)));
        _mm_storel_pd(out, lo);
        _mm_storeu_pd(out + 1, r);
        _mm_storeh_pd(out + 3, hi);
        _mm_storeu_pd(out + 4, _mm256_castpd256_pd128((__m256d)y[1]));
    }
#else
    ifs_outputs(m, out);
#endif
}
#endif
#endif
#undef IFS_C
#undef IFS_STEP_ROWS



/*
 * One term of the remainder's Taylor series (ifs_advance): w_next = (a w) s with a
 * the first IFS_NX columns of ab (stored like pg), and acc += w_next.  The terms
 * depend on each other, so each sum is two chains (even and odd columns) to halve
 * its latency.  Two rows at a time where the compiler has GNU vectors; the scalar
 * version adds in the same order.
 */
IFS_INLINE void ifs_taylor_term(const double *ab, const double w[IFS_LD], double s,
                                double w_next[IFS_LD], double acc[IFS_LD])
{
    int r, j;
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
    IFS_UNROLL
    for (r = 0; r < (IFS_NX + 1) / 2; r++) {
        ifs_v2 t = *(const ifs_v2 *)(ab + 2 * r) * w[0];
        ifs_v2 t1 = *(const ifs_v2 *)(ab + IFS_LD + 2 * r) * w[1];
        IFS_UNROLL
        for (j = 2; j < IFS_NX; j += 2) {
            t += *(const ifs_v2 *)(ab + j * IFS_LD + 2 * r) * w[j];
            if (j + 1 < IFS_NX) t1 += *(const ifs_v2 *)(ab + (j + 1) * IFS_LD + 2 * r) * w[j + 1];
        }
        t = (t + t1) * s;
        *(ifs_v2 *)(w_next + 2 * r) = t;
        *(ifs_v2 *)(acc + 2 * r) += t;
    }
#else
    for (r = 0; r < IFS_NX; r++) {
        double t = ab[r] * w[0], t1 = ab[IFS_LD + r] * w[1];
        for (j = 2; j < IFS_NX; j += 2) {
            t += ab[j * IFS_LD + r] * w[j];
            if (j + 1 < IFS_NX) t1 += ab[(j + 1) * IFS_LD + r] * w[j + 1];
        }
        t = (t + t1) * s;
        w_next[r] = t;
        acc[r] += t;
    }
#endif
}

/* Load i (0 CT, 1 C_mc, 2 C_ms, 3 C_mc_hub, 4 C_ms_hub) for the state and the inputs
 * held now. */
static inline double ifs_load(const IfsModel *m, int i, const double u[IFS_NU])
{
    double s = 0.0;
    int j;
    for (j = 0; j < IFS_NX; j++) s += m->lc[i * IFS_NX + j] * m->x[j];
    for (j = 0; j < IFS_NU; j++) s += m->ld[i * IFS_NU + j] * u[j];
    return s;
}

#endif
