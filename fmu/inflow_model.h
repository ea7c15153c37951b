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
#define IFS_XB ((IFS_NX + 3) / 4)          /* blocks of four holding a state */

typedef struct {
    /* First what the step reads, each a whole number of 32-byte vectors from the
     * start, which the slave keeps 64-byte aligned (IfsSlave, the FMI layers'
     * instances): a four-wide load or store across a 64-byte cache line costs more
     * (bench/fmu.md). */
    /* [phi gam] at the internal step dt as the step reads it (IFS_PG_AT): up to 16
     * states by columns, column j at pg + j IFS_LD, its IFS_NX rows then zeros, so
     * that each x_j and u_k multiplies a column four rows at a time; beyond, by rows
     * (IFS_RL each: one new state a dot product with [x; u]; see ifs_step) */
    double pg[IFS_PG_N];
    /* [x; u; 0]: the state (IFS_NX), then the inputs held (IFS_NU, a copy of the
     * slave's, written when they are set: the step reads them beside the state),
     * then zeros to whole vectors of four */
    double x[IFS_RL];
    /* g = gam u, the inputs' part of the step, while g_ok (ifs_step_held) */
    double g[IFS_LD];
    /* A mu change with the inputs held (the column step; ifs_mu_table_apply, with
     * pg, x and g: ifs_mu_eval_held): the power coefficients of g = gam u on a
     * segment of the mu table for the inputs held; gq_seg: s + 1, gq made for
     * segment s and pg's gam columns not yet those at gam_mu, the last change's mu
     * (g is; ifs_mu_table_gam brings them before anything reads them, and negates
     * gq_seg); -(s + 1), gq made for s, gam as g; IFS_GQ_NONE (0): none made since
     * the inputs were set; IFS_GQ_NEXT: none, the inputs held through a change;
     * IFS_GQ_STALE: none (new inputs), gam stale */
    double gq[(IFS_MU_DEG + 1) * IFS_LD];
    double gq_seg, gam_mu, gq_pad_[2];
#if IFS_COLUMN_STEP
    /* The look-ahead of the step with the inputs and [phi gam] held (g_ok 3,
     * ifs_step_ahead): x_(k+1) = phi^2 x_(k-1) + c, c = phi g + g, so that the chain
     * from a state to the one computed from it spans two calls.  p2: phi^2 by
     * columns (as pg's phi: IFS_LD each, rows past IFS_NX zero), unless stale
     * (IFS_STALE_P2: set where phi changes, ifs_build, ifs_mu_table_apply); c2: c for
     * the g and phi held; xs: the last two states, xs + ahead_i (0 or IFS_LD) the one
     * before the last step (the next step's), the other the state now (as x) */
    double p2[IFS_NX * IFS_LD];
    double c2[IFS_LD];
    double xs[2 * IFS_LD];
    long long ahead_i, ahead_pad_[3];   /* (what follows as it was: 32-byte aligned) */
#endif
    /* continuous SI state space, row-major */
    double a[IFS_NX * IFS_NX];
    double b[IFS_NX * IFS_NU];
    /* outputs y = c x: identity but the recorded flap rotated by the azimuth bias */
    double cos_bias, sin_bias;
    /* loads = lc x + ld u (inflowsim.model.loads: Eq. (4) times a0 s, the flap rate
     * from the dynamics, the true pitch; the flap springs' hub moments), row-major */
    double lc[IFS_NL * IFS_NX];
    double ld[IFS_NL * IFS_NU];
    double dt;
    /* cached [phi gam] (as pg) of a remainder step (h not n dt) */
    double pg_rem[IFS_PG_N];
    double rem;                    /* its length [s]; 0 = no cache */
    /* the remainder asked for by the previous call under the same matrices (0: none).
     * The second remainder in a row is cached; a later one that differs from the
     * cached one by d is the cached step followed by the Taylor series of the state
     * over d (of either sign), or over the whole remainder when that takes fewer
     * terms (ifs_advance) */
    double rem_prev;
    /* [a b] stored by columns (IFS_LD each: the Taylor remainder's matrix-vector
     * products, two rows at a time), and by rows (IFS_RL each: its first product,
     * with the inputs, ifs_rows) */
    double abc[IFS_NA * IFS_LD];
    double abr[IFS_NX * IFS_RL];
    /* the 1-norms |a| and |[a b]| [1/s]: the Taylor series' term bounds (abc, abr and
     * these from ifs_taylor_prepare, generated from algorithms.taylor_prepare) */
    double norms[2];
    /* what is not yet for the matrices now: IFS_STALE_AB a, b, lc, ld and the norms
     * (a mu change applied from the table updates [phi gam] first, the rest when
     * asked); IFS_STALE_P2 phi^2 (p2, the look-ahead's: where phi changes) */
    int stale;
    /* the kept g = gam u and the look-ahead: 0 none (cleared where the inputs or
     * [phi gam] change: the slave's input sets, ifs_slave_refresh, a mu change);
     * 1 g for the inputs and [phi gam] held, no step yet with them (a mu change with
     * the inputs held: g from the table, ifs_mu_table_apply); 2 (IFS_G_STEPPED) g, and
     * the last step x <- phi x + g with them; 3 (IFS_G_AHEAD) the look-ahead, p2, c2
     * and xs for them (the column step) */
    int g_ok;
    /* cached split of the last communication step h = n dt + rem */
    double h_last;
    long long n_last;
    double rem_last;
} IfsModel;
#define IFS_STALE_AB 1
#define IFS_STALE_P2 2
#define IFS_G_STEPPED 2
#define IFS_G_AHEAD 3
#define IFS_GQ_NONE 0.0
#define IFS_GQ_NEXT (-1.0 - IFS_MU_NSEG)
#define IFS_GQ_STALE (2.0 + IFS_MU_NSEG)   /* gam stale, no gq (new inputs) */
/* [phi gam], [x; u], g and gq one after the other (ifs_mu_eval_held's block) */
typedef char ifs_held_block_is_contiguous[
    offsetof(IfsModel, x) == IFS_PG_N * sizeof(double) &&
    offsetof(IfsModel, g) == offsetof(IfsModel, x) + IFS_RL * sizeof(double) &&
    offsetof(IfsModel, gq) == offsetof(IfsModel, g) + IFS_LD * sizeof(double) &&
    offsetof(IfsModel, gq_seg) == offsetof(IfsModel, gq) + sizeof(((IfsModel *)0)->gq) &&
    offsetof(IfsModel, gam_mu) == offsetof(IfsModel, gq_seg) + sizeof(double) ? 1 : -1];

/* The discrete matrices tabulated in mu for one set of parameters (IfsMuTable,
 * inflow_numerics.h): a flight condition changing every step costs a polynomial
 * evaluation instead of a rebuild and a matrix exponential.  [phi gam] (at dt, by
 * columns) and [a b] (row-major) are analytic in mu on [IFS_MU_LO, IFS_MU_HI], their
 * only singularity mu = 0 (L ~ 1/mu).  Built on the first mu change after a parameter
 * change; else mu changes rebuild exactly. */
/* Build the table for the parameters in v (mu ignored); returns t->state. */
int ifs_mu_table_build(IfsMuTable *t, const IfsVariables *v);
/* Set m's [phi gam] at dt for v->mu from a valid table (ifs_mu_eval: its part and
 * Horner's rule, generated from inflowsim.simulate.algorithms.mu_eval, straight into
 * m->pg, whose order the table's half 0 is stored in; with the CPU's fused
 * multiply-adds where it has them, t->fma, else the C library's fma: one rounding
 * each, the same numbers), and mark a, b and the loads stale (m->stale): the step
 * at dt needs only [phi gam].  With the inputs held since the last mu change (g
 * kept, g_ok, and gq_seg not IFS_GQ_NONE) and the step by columns,
 * ifs_mu_eval_held: phi alone and the step's g = gam u from the segment's
 * coefficients of gam u (gq, made once per segment), gam left stale (gq_seg > 0)
 * until ifs_mu_table_gam (nine in ten of the column step's [phi gam] entries are
 * gam's for six states).  Inline: the FMI layers' set of mu calls it (a call less
 * per mu change). */
static inline void ifs_mu_table_apply(const IfsMuTable *t, const IfsVariables *v,
                                      IfsModel *m)
{
    m->rem = 0.0;          /* the remainder caches belong to the old matrices */
    m->rem_prev = 0.0;
    m->stale = IFS_STALE_AB | IFS_STALE_P2;   /* (phi is new: phi^2 with it) */
#if IFS_COLUMN_STEP
    if (m->g_ok && m->gq_seg != IFS_GQ_NONE) {
        m->g_ok = 1;       /* g for the new phi (below), no step yet with them */
        IFS_MU_CALL(t, ifs_mu_eval_held, t->edge, &t->q[0][0][0], &t->p[0][0][0], v->mu,
                    m->pg);
        return;
    }
    /* the inputs held through this change: ifs_mu_eval_held at the next */
    m->gq_seg = m->g_ok ? IFS_GQ_NEXT : IFS_GQ_NONE;
#endif
    m->g_ok = 0;           /* gam is new: the inputs' part g = gam u with it */
    IFS_MU_CALL(t, ifs_mu_eval, t->pstart, t->pmid, t->pscale, t->guess, &t->q[0][0][0],
                v->mu, m->pg);
}
/* gam at the mu of the last change (gam_mu) where ifs_mu_eval_held left it stale
 * (gq_seg > 0; the table t valid: a table is dropped only with the matrices,
 * ifs_build, which clears gq_seg), the same numbers as ifs_mu_eval's: before
 * anything reads gam (a step after new inputs, the general step, a saved state). */
static inline void ifs_mu_table_gam(const IfsMuTable *t, IfsModel *m)
{
    IFS_MU_CALL(t, ifs_mu_eval_range, t->pstart, &t->q[0][0][0], m->gam_mu, IFS_MU_NPHI,
                IFS_MU_HALF0 - IFS_MU_NPHI, m->pg);
    m->gq_seg = -m->gq_seg;
}
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
 * a, b (inflowsim.model.loads.load_rows: lc 5 x NX, ld 5 x NU, row-major). */
void ifs_descriptor_of(const IfsVariables *v, double V, double *e, double *a, double *b);
double ifs_bias_of(const IfsVariables *v);
void ifs_flap_delays_of(const IfsVariables *v, double d[3]);
void ifs_loads_of(const IfsVariables *v, const double *a, const double *b, double *lc,
                  double *ld);
/* the speed through the disc from inflow_speed, mu, ct (inflowsim.physics.loads.flow_speed,
 * generated into inflow_algorithms.c) */
double ifs_flow_speed(int inflow_speed, double mu, double ct);
#if IFS_N_SCHEDULED
/* Generated from a parameter schedule (inflowsim fmu build --schedule): the
 * scheduled parameters (local variables) in v at v->mu, held beyond the schedule's
 * range (inflowsim.model.schedule.Schedule.__call__, the same operations). */
void ifs_schedule_apply(IfsVariables *v);
#endif

/* [phi gam] for a step h [s]: exp([[a, b], [0, 0]] h), top rows, stored as the
 * step reads it (element (i, j) at pg[IFS_PG_AT(i, j)], padding zero: IfsModel.pg). */
int ifs_discretize(const IfsModel *m, double h, double pg[IFS_PG_N]);

/* Advance the state over h [s] with the inputs held (m->x after the state): whole
 * internal steps dt and one exact remainder step.  Returns 0, or -1 if the
 * remainder discretisation failed. */
int ifs_advance(IfsModel *m, double h);

/* y = c x: the recorded flap is the true one rotated by the azimuth bias. */
IFS_INLINE void ifs_outputs(const IfsModel *m, double y[IFS_NX])
{
    const double *x = m->x;
#define IFS_X_NOW(i) x
    IFS_OUTPUT_MAP(y, IFS_X_NOW, m->cos_bias, m->sin_bias);   /* inflow_vars.h */
#undef IFS_X_NOW
}

/* out = the pairwise sum of the K terms term(j_) (K < 64): the tree whose blocks are
 * aligned at powers of two, evaluated streaming (partial sums of whole blocks kept
 * by size, as a binary counter), so only a few values are live at once.  The
 * association is fixed by K alone, so every width (double, pairs, fours) rounds
 * alike. */
#define IFS_TREE_SUM(T, K, first, term, out)                                           \
    do {                                                                               \
        T s_[6], c_;                                                                   \
        int j_, l_, have_ = 0;                                                         \
        IFS_UNROLL                                                                     \
        for (j_ = 0; j_ < (K); j_++) {                                                 \
            if (j_ == 0)                                                               \
                c_ = first;                                                            \
            else                                                                       \
                c_ = term;                                                             \
            IFS_UNROLL                                                                 \
            for (l_ = 0; l_ < 6; l_++) {                                               \
                if ((j_ >> l_) & 1) {                                                  \
                    c_ = s_[l_] + c_;                                                  \
                } else {                                                               \
                    s_[l_] = c_;                                                       \
                    break;                                                             \
                }                                                                      \
            }                                                                          \
        }                                                                              \
        IFS_UNROLL                                                                     \
        for (l_ = 0; l_ < 6; l_++)                                                     \
            if (((K) >> l_) & 1) {                                                     \
                if (have_)                                                             \
                    c_ = s_[l_] + c_;                                                  \
                else                                                                   \
                    c_ = s_[l_];                                                       \
                have_ = 1;                                                             \
            }                                                                          \
        out = c_;                                                                      \
    } while (0)

/*
 * [a b] z by rows ([a b] by rows, IFS_RL each, z = [x; u; 0]), for the Taylor step
 * (ifs_taylor_first): each row's dot product with z in blocks of four, lane l of the
 * row the pairwise sum over the blocks (the last block first), then the lanes
 * (l0 + l1) + (l2 + l3); the same order in pairs and in plain C.
 */
/* the k-th block of the sum (the last block first) */
#define IFS_BLK(k) (IFS_ZB - 1 - (k))
/* lanes off .. off + width of row r's products with z, summed over the blocks */
#define IFS_ROW_LANES(T, r, off, out)                                                  \
    IFS_TREE_SUM(T, IFS_ZB,                                                            \
                 *(const T *)(pg + (r) * IFS_RL + 4 * IFS_BLK(0) + (off)) *            \
                     *(const T *)(z + 4 * IFS_BLK(0) + (off)),                         \
                 *(const T *)(pg + (r) * IFS_RL + 4 * IFS_BLK(j_) + (off)) *           \
                     *(const T *)(z + 4 * IFS_BLK(j_) + (off)),                        \
                 out)

/* y = [a b] z by rows (pg: IFS_NX rows, IFS_RL apart) */
IFS_INLINE void ifs_rows(const double *pg, const double *z, double y[IFS_NX])
{
    int r;
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
    IFS_UNROLL
    for (r = 0; r < IFS_NX; r++) {
        ifs_v2 lo, hi;
        IFS_ROW_LANES(ifs_v2, r, 0, lo);
        IFS_ROW_LANES(ifs_v2, r, 2, hi);
        y[r] = (lo[0] + lo[1]) + (hi[0] + hi[1]);
    }
#else
    for (r = 0; r < IFS_NX; r++) {
        double l[4];
        int k;
        for (k = 0; k < 4; k++) IFS_ROW_LANES(double, r, k, l[k]);
        y[r] = (l[0] + l[1]) + (l[2] + l[3]);
    }
#endif
}

#if IFS_COLUMN_STEP
/*
 * x <- phi x + gam u: one step, the simulator loop's hot path, inline so that it is
 * compiled for the caller's target.  pg is IfsModel.pg ([phi gam] by columns,
 * IFS_LD each), z = [x; u; 0] (IfsModel.x).  New state i is
 *
 *     x_i <- pairwise sum of (g_i, phi_i0 x_0, phi_i1 x_1, ..., phi_i,NX-1 x_NX-1)
 *     g_i  = pairwise sum of (gam_i0 u_0, ..., gam_i,NU-1 u_NU-1)
 *
 * (IFS_TREE_SUM): each x_j and u_k broadcast and multiplied by its column, four rows
 * a vector, nothing summed across lanes.  The chain from one step's state to the
 * next is short: the broadcasts of x_j (loads of the last step's stores), one
 * multiply, a tree of depth ceil(log2(NX + 1)).  g, the inputs' part, does not wait
 * for the state and enters first, beside phi_i0 x_0: the products cannot all start
 * at once (two multiplies a cycle), so the last ones to arrive go into the tree's
 * shallower half (with g last, the last products waited for g's add: 2-4 % of the
 * step with the inputs held, bench/fmu_states.md).  The step on the model
 * (ifs_step_held, ifs_step_wide) keeps g (IfsModel.g) while the inputs and [phi gam]
 * stay as they were (g_ok, cleared by whatever changes them: the slave's input and mu
 * sets, ifs_slave_refresh), so a step with the inputs held takes the NX^2 products of
 * phi x alone.  The same operations in the same order on every path: GNU vectors of
 * two (the baseline x86-64 code), plain C, and the four-wide step of the AVX2 DoStep
 * (ifs_step_wide), so the same numbers, provided the compiler does not contract
 * a * b + c into a fused multiply-add (inflowsim builds with -ffp-contract=off;
 * clang is told in inflow_numerics.h).
 */
/* rows r0 .. r0 + width of g: column IFS_NX + k times X(IFS_NX + k), X(j) z_j (a
 * double, or z_j in every lane of a T) */
#define IFS_GAM_TERMS(T, r0, X, out)                                                   \
    IFS_TREE_SUM(T, IFS_NU, *(const T *)(pg + IFS_NX * IFS_LD + (r0)) * X(IFS_NX),     \
                 *(const T *)(pg + (IFS_NX + j_) * IFS_LD + (r0)) * X(IFS_NX + j_), out)
/* rows r0 .. r0 + width of g + phi x, g0 their g (the terms g, then phi_i0 x_0 ...) */
#define IFS_PHI_TERMS(T, r0, g0, X, out)                                               \
    IFS_TREE_SUM(T, IFS_NX + 1, (T)(g0),                                               \
                 (T)(*(const T *)(pg + (j_ - 1) * IFS_LD + (r0)) * X(j_ - 1)), out)
#define IFS_Z(j) z[j]

/* g[0 .. IFS_NX) = gam u */
IFS_INLINE void ifs_gam_rows(const double *pg, const double *z, double *g)
{
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
    int p;
    IFS_UNROLL
    for (p = 0; p < IFS_NX / 2; p++) {
        ifs_v2 v;
        IFS_GAM_TERMS(ifs_v2, 2 * p, IFS_Z, v);
        *(ifs_v2 *)(g + 2 * p) = v;
    }
#if IFS_NX % 2
    IFS_GAM_TERMS(double, IFS_NX - 1, IFS_Z, g[IFS_NX - 1]);
#endif
#else
    int i;
    for (i = 0; i < IFS_NX; i++) IFS_GAM_TERMS(double, i, IFS_Z, g[i]);
#endif
}

/* z[0 .. IFS_NX) <- phi x + g, every sum before any store (each reads all of x); the
 * new state stored in x2 too where it is not NULL */
IFS_INLINE void ifs_phi_step_to(const double *pg, const double *g, double *z, double *x2)
{
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
    ifs_v2 y[IFS_NX / 2];
    int p;
    IFS_UNROLL
    for (p = 0; p < IFS_NX / 2; p++)
        IFS_PHI_TERMS(ifs_v2, 2 * p, *(const ifs_v2 *)(g + 2 * p), IFS_Z, y[p]);
#if IFS_NX % 2
    double y1;
    IFS_PHI_TERMS(double, IFS_NX - 1, g[IFS_NX - 1], IFS_Z, y1);
#endif
    IFS_UNROLL
    for (p = 0; p < IFS_NX / 2; p++) {
        *(ifs_v2 *)(z + 2 * p) = y[p];
        if (x2) *(ifs_v2 *)(x2 + 2 * p) = y[p];
    }
#if IFS_NX % 2
    z[IFS_NX - 1] = y1;
    if (x2) x2[IFS_NX - 1] = y1;
#endif
#else
    double y[IFS_NX];
    int i;
    for (i = 0; i < IFS_NX; i++) IFS_PHI_TERMS(double, i, g[i], IFS_Z, y[i]);
    memcpy(z, y, sizeof y);
    if (x2) memcpy(x2, y, sizeof y);
#endif
}

IFS_INLINE void ifs_phi_step(const double *pg, const double *g, double *z)
{
    ifs_phi_step_to(pg, g, z, NULL);
}

/* the step on [phi gam] pg and z = [x; u; 0] */
IFS_INLINE void ifs_step(const double *pg, double z[IFS_RL])
{
    double g[IFS_LD];
    ifs_gam_rows(pg, z, g);
    ifs_phi_step(pg, g, z);
}

/*
 * The look-ahead (m->g_ok IFS_G_AHEAD).  With the inputs and [phi gam] held, g = gam u
 * is constant, so two steps are one with phi^2 (the standard look-ahead of an IIR
 * filter's recurrence):
 *
 *     x_(k+1) = phi^2 x_(k-1) + c,    c = phi g + g
 *
 * each step computed from the state before the last one (m->xs, the two last states
 * one after the other): the chain from a state to the one computed from it spans two
 * calls, so that consecutive calls overlap in the machine instead of each waiting for
 * the last one's state (bench/fmu_states.md); the same NX^2 products a step.  The
 * numbers differ from the one-step recurrence's by rounding alone (two interleaved
 * recurrences of phi^2; phi^2 and c rounded once).  The sums as the step's (g first,
 * IFS_PHI_TERMS), so every build gives the same numbers.  Started by
 * ifs_ahead_start at the second step with the same g and phi (g_ok IFS_G_STEPPED):
 * that step is x <- phi x + g, then phi^2 where phi is new and c.
 */
void ifs_ahead_start(IfsModel *m);

/* the look-ahead step: xs_b <- phi^2 xs_b + c (xs_b the state before the last step),
 * stored as the state x too */
IFS_INLINE void ifs_step_ahead(IfsModel *m)
{
    double *z = m->xs + m->ahead_i;
    ifs_phi_step_to(m->p2, m->c2, z, m->x);
    m->ahead_i ^= IFS_LD;
}

/* The step on the model (its [phi gam] at dt and [x; u]), with g kept (and the
 * look-ahead where g and phi were held through the last step).  Returns 1, nothing
 * done, where the look-ahead starts (g_ok IFS_G_STEPPED): the caller's
 * ifs_ahead_start then takes the step, out of line. */
IFS_INLINE int ifs_step_held(IfsModel *m)
{
    if (!m->g_ok) {
        ifs_gam_rows(m->pg, m->x, m->g);
    } else if (m->g_ok & IFS_G_STEPPED) {
        if (m->g_ok == IFS_G_STEPPED) return 1;
        ifs_step_ahead(m);
        return 0;
    }
    m->g_ok = IFS_G_STEPPED;
    ifs_phi_step(m->pg, m->g, m->x);
    return 0;
}

/* The same step on the model four rows at a time, for the AVX2 variant of DoStep
 * (IFS_WIDE_STEP; the slave picks it at load time where the CPU has AVX2: 256-bit
 * vectors on the baseline x86-64 code are split badly, so that keeps the pairs):
 * the rows in vectors of four, the last ones in a pair and one alone, each x_j and
 * u_k broadcast once for all; the new states stored in 16-byte halves (the next
 * step's broadcasts each load from one store, forwarded a cycle sooner from a
 * 16-byte store than from a 32-byte one on AMD Zen 4).  The same operations in the
 * same order as ifs_step_held, so the same numbers. */
#if defined(IFS_HOT_CLONES) && !defined(IFS_SCALAR_STEP)
#define IFS_WIDE_STEP 1
#include <immintrin.h>
/* z_j in every lane, for x_j: a load that broadcasts (of one of the last step's
 * stores; its four-wide, two-wide and scalar uses share it) */
#define IFS_BX4(j) ((ifs_v4)_mm256_broadcast_sd(z + (j)))
#define IFS_BX2(j) ((ifs_v2)_mm256_castpd256_pd128(_mm256_broadcast_sd(z + (j))))
#define IFS_BX1(j) _mm256_cvtsd_f64(_mm256_broadcast_sd(z + (j)))
/* ... and for u_k: the inputs' whole blocks of four loaded once each (as the input
 * set stored them), the lane permuted across (the simulator loop's frame took 2-3 ns
 * longer with a broadcast load of each input); in the block shared with the state a
 * broadcast load (the block's lanes come from more than one store after a step) */
#define IFS_BU(j)                                                                      \
    ((j) / 4 == IFS_NX / 4 ? _mm256_broadcast_sd(z + (j))                              \
                           : _mm256_permute4x64_pd(*(const __m256d *)(z + (j) / 4 * 4),  \
                                                   ((j) % 4) * 0x55))
#define IFS_BU4(j) ((ifs_v4)IFS_BU(j))
#define IFS_BU2(j) ((ifs_v2)_mm256_castpd256_pd128(IFS_BU(j)))
#define IFS_BU1(j) _mm256_cvtsd_f64(IFS_BU(j))
/* the locals of the four-wide step: g (g4, g2, g1) and the new state (y4, y2, y1) */
#if IFS_NX >= 4
#define IFS_WIDE_4(d) d
#else
#define IFS_WIDE_4(d)
#endif
#if IFS_NX % 4 >= 2
#define IFS_WIDE_2(d) d
#else
#define IFS_WIDE_2(d)
#endif
#if IFS_NX % 2
#define IFS_WIDE_1(d) d
#else
#define IFS_WIDE_1(d)
#endif
#define IFS_WIDE_LOCALS                                                                \
    IFS_WIDE_4(ifs_v4 g4[IFS_NX / 4]; ifs_v4 y4[IFS_NX / 4];)                          \
    IFS_WIDE_2(ifs_v2 g2; ifs_v2 y2;)                                                  \
    IFS_WIDE_1(double g1; double y1;)                                                  \
    int q
/* g's rows from memory (gm) */
#define IFS_WIDE_LOAD_G(gm)                                                            \
    do {                                                                               \
        IFS_UNROLL                                                                     \
        for (q = 0; q < IFS_NX / 4; q++)                                               \
            IFS_WIDE_4(g4[q] = *(const ifs_v4 *)((gm) + 4 * q));                       \
        IFS_WIDE_2(g2 = *(const ifs_v2 *)((gm) + IFS_NX / 4 * 4));                     \
        IFS_WIDE_1(g1 = (gm)[IFS_NX - 1]);                                             \
    } while (0)
/* the new state from pg's first IFS_NX columns, g and the state at z, stored at z
 * and, unless NULL, at x2 (in 16-byte halves) */
#define IFS_WIDE_PHI(x2)                                                               \
    do {                                                                               \
        IFS_UNROLL                                                                     \
        for (q = 0; q < IFS_NX / 4; q++)                                               \
            IFS_WIDE_4(IFS_PHI_TERMS(ifs_v4, 4 * q, g4[q], IFS_BX4, y4[q]));           \
        IFS_WIDE_2(IFS_PHI_TERMS(ifs_v2, IFS_NX / 4 * 4, g2, IFS_BX2, y2));            \
        IFS_WIDE_1(IFS_PHI_TERMS(double, IFS_NX - 1, g1, IFS_BX1, y1));                \
        IFS_UNROLL                                                                     \
        for (q = 0; q < IFS_NX / 4; q++) {                                             \
            IFS_WIDE_4(_mm_storeu_pd(z + 4 * q,                                        \
                                     _mm256_castpd256_pd128((__m256d)y4[q]));          \
                       _mm_storeu_pd(z + 4 * q + 2,                                    \
                                     _mm256_extractf128_pd((__m256d)y4[q], 1));        \
                       if (x2) {                                                       \
                           _mm_storeu_pd((x2) + 4 * q,                                 \
                                         _mm256_castpd256_pd128((__m256d)y4[q]));      \
                           _mm_storeu_pd((x2) + 4 * q + 2,                             \
                                         _mm256_extractf128_pd((__m256d)y4[q], 1));    \
                       })                                                              \
        }                                                                              \
        IFS_WIDE_2(*(ifs_v2 *)(z + IFS_NX / 4 * 4) = y2;                               \
                   if (x2) *(ifs_v2 *)((x2) + IFS_NX / 4 * 4) = y2;)                   \
        IFS_WIDE_1(z[IFS_NX - 1] = y1; if (x2) (x2)[IFS_NX - 1] = y1;)                  \
    } while (0)
/* the look-ahead step four rows at a time (ifs_step_ahead) */
static inline __attribute__((target("avx2"), always_inline)) void
ifs_step_ahead_wide(IfsModel *m)
{
    const double *pg = m->p2;
    double *z = m->xs + m->ahead_i;
    IFS_WIDE_LOCALS;
    IFS_WIDE_LOAD_G(m->c2);
    IFS_WIDE_PHI(m->x);
    m->ahead_i ^= IFS_LD;
}
static inline __attribute__((target("avx2"), always_inline)) int ifs_step_wide(IfsModel *m)
{
    const double *pg = m->pg;
    double *z = m->x;
    double *g = m->g;
    IFS_WIDE_LOCALS;
    if (!m->g_ok) {
        IFS_UNROLL
        for (q = 0; q < IFS_NX / 4; q++)
            IFS_WIDE_4(IFS_GAM_TERMS(ifs_v4, 4 * q, IFS_BU4, g4[q]));
        IFS_WIDE_2(IFS_GAM_TERMS(ifs_v2, IFS_NX / 4 * 4, IFS_BU2, g2));
        IFS_WIDE_1(IFS_GAM_TERMS(double, IFS_NX - 1, IFS_BU1, g1));
        IFS_UNROLL
        for (q = 0; q < IFS_NX / 4; q++) IFS_WIDE_4(*(ifs_v4 *)(g + 4 * q) = g4[q]);
        IFS_WIDE_2(*(ifs_v2 *)(g + IFS_NX / 4 * 4) = g2);
        IFS_WIDE_1(g[IFS_NX - 1] = g1);
    } else if (m->g_ok & IFS_G_STEPPED) {   /* (2 or 3; 1: g, no step yet with it) */
        if (m->g_ok == IFS_G_STEPPED) return 1;
        ifs_step_ahead_wide(m);
        return 0;
    } else {
        IFS_WIDE_LOAD_G(g);
    }
    m->g_ok = IFS_G_STEPPED;
    IFS_WIDE_PHI((double *)NULL);
    return 0;
}
#endif

#else /* the row step */

/*
 * Beyond 16 states (IFS_COLUMN_STEP 0) the row step: [phi gam] = pg by rows (IFS_RL
 * each), each new state the dot product of its row with z = [x; u; 0] in blocks of
 * four (ifs_rows: lane l the pairwise sum over the blocks, the last first, so the
 * inputs' products are summed before the state's; then (l0 + l1) + (l2 + l3)).
 * Every product of [phi gam] [x; u] is taken once in whole vectors of four, the
 * padding 0 * 0; the same operations in the same order on every path.
 */
IFS_INLINE void ifs_step(const double *pg, double z[IFS_RL])
{
    /* every sum before any store (each reads all of x) */
    double y[IFS_NX];
    ifs_rows(pg, z, y);
    memcpy(z, y, sizeof y);
}

IFS_INLINE int ifs_step_held(IfsModel *m)
{
    ifs_step(m->pg, m->x);
    return 0;
}

/* The same step four lanes at a time, for the AVX2 variant of DoStep (IFS_WIDE_STEP;
 * the slave picks it at load time where the CPU has AVX2: 256-bit vectors on the
 * baseline x86-64 code are split badly, so that keeps the pairs), on m's [phi gam] at
 * dt.  Four rows' lanes are added in two horizontal adds ((l0 + l1), (l2 + l3)) and
 * one vertical one, giving the four new states as one vector; the block holding the
 * last states and the first inputs is stored whole (the inputs as they were), so
 * that the next step loads every block from one store.  The same operations in the
 * same order as ifs_step, so the same numbers. */
#if defined(IFS_HOT_CLONES) && !defined(IFS_SCALAR_STEP)
#define IFS_WIDE_STEP 1
#include <immintrin.h>
/* the four rows from 4 g (k of them) reduced to one vector [x_4g ...]: in the lanes
 * past k the block's inputs as they were */
#define IFS_WIDE_GROUP(g, k, out)                                                      \
    do {                                                                               \
        ifs_v4 r0_, r1_, r2_, r3_;                                                     \
        __m256d t0_, v_;                                                               \
        IFS_ROW_LANES(ifs_v4, 4 * (g), 0, r0_);                                        \
        if ((k) > 1) IFS_ROW_LANES(ifs_v4, 4 * (g) + 1, 0, r1_);                       \
        else r1_ = r0_;                                                                \
        if ((k) > 2) IFS_ROW_LANES(ifs_v4, 4 * (g) + 2, 0, r2_);                       \
        else r2_ = r0_;                                                                \
        if ((k) > 3) IFS_ROW_LANES(ifs_v4, 4 * (g) + 3, 0, r3_);                       \
        else r3_ = r2_;                                                                \
        /* r0 01, r1 01, r0 23, r1 23 */                                               \
        t0_ = _mm256_hadd_pd((__m256d)r0_, (__m256d)r1_);                              \
        if ((k) > 2) {                                                                 \
            const __m256d t1_ = _mm256_hadd_pd((__m256d)r2_, (__m256d)r3_);            \
            v_ = _mm256_add_pd(_mm256_permute2f128_pd(t0_, t1_, 0x20),                 \
                               _mm256_permute2f128_pd(t0_, t1_, 0x31));                \
        } else {                                                                       \
            v_ = _mm256_castpd128_pd256(_mm_add_pd(_mm256_castpd256_pd128(t0_),        \
                                                   _mm256_extractf128_pd(t0_, 1)));    \
        }                                                                              \
        out = v_;                                                                      \
    } while (0)
static inline __attribute__((target("avx2"), always_inline)) int ifs_step_wide(IfsModel *m)
{
    const double *pg = m->pg;
    double *z = m->x;
    __m256d y[IFS_XB];
    int g;
    IFS_UNROLL
    for (g = 0; g < IFS_NX / 4; g++) IFS_WIDE_GROUP(g, 4, y[g]);
#if IFS_NX % 4
    IFS_WIDE_GROUP(IFS_NX / 4, IFS_NX % 4, y[IFS_NX / 4]);
    y[IFS_NX / 4] = _mm256_blend_pd(y[IFS_NX / 4], *(const __m256d *)(z + IFS_NX / 4 * 4),
                                    (0xF << (IFS_NX % 4)) & 0xF);
#endif
    IFS_UNROLL
    for (g = 0; g < IFS_XB; g++) *(__m256d *)(z + 4 * g) = y[g];
    return 0;
}
#endif
#endif /* IFS_COLUMN_STEP */


/*
 * The primitives of the Taylor step (inflowsim.simulate.algorithms.taylor_step,
 * generated into ifs_taylor_step; P.taylor_first and P.taylor_term there):
 *
 * w = ([a b] z) r: [a b] by rows (n rows rl apart, as pg), z = [x; u] (rl rows of
 * cols columns); for the model (cols 1, n IFS_NX, rl IFS_RL) the rows'
 * dot products (ifs_rows), then the scaling.
 */
IFS_INLINE void ifs_taylor_first(const double *ab, const double *z, double r, double *w,
                                 int n, int rl, int cols)
{
    int i, j, c;
    if (cols == 1 && n == IFS_NX && rl == IFS_RL) {
        ifs_rows(ab, z, w);
        for (i = 0; i < IFS_NX; i++) w[i] *= r;
        return;
    }
    for (i = 0; i < n; i++)
        for (c = 0; c < cols; c++) {
            double t = 0.0;
            for (j = 0; j < rl; j++) t += ab[i * rl + j] * z[j * cols + c];
            w[i * cols + c] = t * r;
        }
}

/*
 * w_next = (a w) s and acc += w_next: a the first n columns of [a b] stored by
 * columns (column j at ab + j ld; ld at least n rounded up to even, the rows past n
 * zero), w, w_next and acc n x cols.  The terms depend on each other, so for one
 * column each sum is two chains (even and odd columns) to halve its latency, two rows
 * at a time where the compiler has GNU vectors (the scalar version adds in the same
 * order).
 */
IFS_INLINE void ifs_taylor_term(const double *ab, const double *w, double s,
                                double *w_next, double *acc, int n, int ld, int cols)
{
    int r, j;
    if (cols != 1) {
        int c;
        for (r = 0; r < n; r++)
            for (c = 0; c < cols; c++) {
                double t = 0.0;
                for (j = 0; j < n; j++) t += ab[j * ld + r] * w[j * cols + c];
                t *= s;
                w_next[r * cols + c] = t;
                acc[r * cols + c] += t;
            }
        return;
    }
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
    IFS_UNROLL
    for (r = 0; r < (n + 1) / 2; r++) {
        ifs_v2 t = *(const ifs_v2 *)(ab + 2 * r) * w[0];
        ifs_v2 t1 = *(const ifs_v2 *)(ab + ld + 2 * r) * w[1];
        IFS_UNROLL
        for (j = 2; j < n; j += 2) {
            t += *(const ifs_v2 *)(ab + j * ld + 2 * r) * w[j];
            if (j + 1 < n) t1 += *(const ifs_v2 *)(ab + (j + 1) * ld + 2 * r) * w[j + 1];
        }
        t = (t + t1) * s;
        *(ifs_v2 *)(w_next + 2 * r) = t;
        *(ifs_v2 *)(acc + 2 * r) += t;
    }
#else
    for (r = 0; r < n; r++) {
        double t = ab[r] * w[0], t1 = ab[ld + r] * w[1];
        for (j = 2; j < n; j += 2) {
            t += ab[j * ld + r] * w[j];
            if (j + 1 < n) t1 += ab[(j + 1) * ld + r] * w[j + 1];
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
