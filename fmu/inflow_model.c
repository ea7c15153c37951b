/*
 * Rotor flap and dynamic inflow: matrices from parameters (model.md Eq. 1-4, 13,
 * 19-20, section 6), exact zero-order-hold discretisation, one step.  The
 * equations themselves (descriptor, loads, the speed through the disc) are
 * generated from the Python model into inflow_equations.c (inflowsim.fmu.codegen);
 * the stepping algorithms the Simulator runs too (the exponential, the Taylor step
 * of a remainder, the mu table's fit, segment search and evaluation) are generated
 * into inflow_algorithms.c from inflowsim.simulate.algorithms, their primitives and
 * the table's storage in inflow_numerics.[ch].  This file does the SI state space
 * of inflowsim.model.build_model and binds the model to them: discretisation,
 * whole steps and remainders, the table's exact entries.  The tests check the two
 * agree to rounding.  Knows nothing of FMI.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "inflow_model.h"

#define NX IFS_NX
#define NU IFS_NU
#define NA IFS_NA

/* --- the model's matrices --- */

/* loads = lc x + ld u (SI state and inputs): generated from
 * inflowsim.model.loads.load_rows (Eq. (4) times a0 s with beta' from the
 * dynamics, the true pitch under an azimuth bias, the 2/rev flap's term, the
 * centre-spring hub moments), which the tests compare. */
static void build_loads(IfsModel *n, const IfsVariables *v)
{
    ifs_loads_of(v, n->a, n->b, n->lc, n->ld);
}

void ifs_descriptor(const IfsVariables *v, double e[NX * NX], double a[NX * NX],
                    double b[NX * NU])
{
    ifs_descriptor_of(v, ifs_flow_speed(v->inflow_speed, v->mu, v->ct), e, a, b);
}

int ifs_discretize(const IfsModel *m, double h, double pg[IFS_PG_N])
{
    double M[NA * NA];
    int i, j;
    memset(M, 0, sizeof M);
    for (i = 0; i < NX; i++) {
        for (j = 0; j < NX; j++) M[i * NA + j] = m->a[i * NX + j] * h;
        for (j = 0; j < NU; j++) M[i * NA + NX + j] = m->b[i * NU + j] * h;
    }
    if (ifs_expm(M) != 0) return -1;
    for (i = 0; i < NX * NA; i++)
        if (!isfinite(M[i])) return -1;
    memset(pg, 0, sizeof(double) * IFS_PG_N);
    for (i = 0; i < NX; i++)                    /* top NX rows, in the step's order */
        for (j = 0; j < NA; j++) pg[IFS_PG_AT(i, j)] = M[i * NA + j];
    return 0;
}

static int taylor_count(const IfsModel *m, double r)
{
    return ifs_taylor_count(m->norms[0], m->norms[1], r);
}

/* The azimuth bias: the outputs' rotation (recorded flap = true one rotated) and the
 * loads' true pitch. */
static void set_bias(IfsModel *m, const IfsVariables *v)
{
    const double bias = ifs_bias_of(v);
    m->cos_bias = cos(bias);
    m->sin_bias = sin(bias);
    build_loads(m, v);
}

/* What the remainder's Taylor series needs from a and b ([a b] by rows and by
 * columns, the 1-norms |a| and |[a b]| that bound its terms): generated from
 * inflowsim.simulate.algorithms.taylor_prepare, the Simulator's TaylorZoh's too. */
static void set_taylor(IfsModel *n)
{
    ifs_taylor_prepare(n->a, n->b, n->abr, n->abc, n->norms);
}

int ifs_build(IfsModel *m, const IfsVariables *v, char *msg, size_t msg_len)
{
    IfsModel n = *m;
    double e[NX * NX], a[NX * NX], b[NX * NU], rhs[NX * NA];
    const double om = v->omega;
    /* inputs in SI -> azimuth units: qbar = q/Omega, qbar' = qdot/Omega^2 */
    static const int omega_power[NU] = IFS_INPUT_OMEGA_POWERS;
    double in_scale[NU];
    int i, j;

    if (v->inflow_speed == 0 && !(v->mu >= IFS_MU_LO && v->mu <= IFS_MU_HI)) {
        snprintf(msg, msg_len, "mu = %g is outside the allowed range " IFS_MU_RANGE
                 " with inflow_speed 0: " IFS_HOVER_HINT, v->mu);
        return -1;
    }
    if (v->inflow_speed == 1 && !IFS_MASS_FLOW_OK(v->mu, v->ct)) {
        snprintf(msg, msg_len, "mu = %g, ct = %g: the mass-flow speed needs "
                 IFS_MASS_FLOW_NEEDS, v->mu, v->ct);
        return -1;
    }
    if (v->structure < 0 || v->structure >= IFS_N_STRUCTURES) {
        snprintf(msg, msg_len, "structure = %d is outside the allowed range [0, %d] (%s)",
                 v->structure, IFS_N_STRUCTURES - 1, IFS_STRUCTURE_NAMES);
        return -1;
    }
    for (j = 0; j < NU; j++) {
        double s = 1.0;
        for (i = 0; i < omega_power[j]; i++) s *= om;
        in_scale[j] = 1 / s;
    }
    ifs_descriptor(v, e, a, b);
    for (i = 0; i < NX; i++) {
        for (j = 0; j < NX; j++) rhs[i * NA + j] = a[i * NX + j];
        for (j = 0; j < NU; j++) rhs[i * NA + NX + j] = b[i * NU + j];
    }
    if (ifs_lu_solve(NX, e, NA, rhs, 1e-12) != 0) {
        snprintf(msg, msg_len, "the descriptor matrix E is singular for these parameters "
                 "(those of the structure's rate terms: its x' coefficients)");
        return -1;
    }
    for (i = 0; i < NX; i++) {
        for (j = 0; j < NX; j++) n.a[i * NX + j] = om * rhs[i * NA + j];
        for (j = 0; j < NU; j++) n.b[i * NU + j] = om * rhs[i * NA + NX + j] * in_scale[j];
    }
    n.stale = IFS_STALE_P2;   /* (phi^2, the look-ahead's, when asked) */
    set_bias(&n, v);
    n.dt = v->dt;
    if (ifs_discretize(&n, n.dt, n.pg) != 0) {
        snprintf(msg, msg_len, "the discretisation at dt = %g s failed (non-finite "
                 "matrices)", n.dt);
        return -1;
    }
    n.rem = 0.0;          /* remainder cache belongs to the old matrices */
    n.rem_prev = 0.0;
    n.h_last = -1.0;
    n.g_ok = 0;           /* ... and the kept g = gam u (as ifs_mu_table_apply's) */
    n.gq_seg = IFS_GQ_NONE;
    set_taylor(&n);
    *m = n;
    return 0;
}

/* (static: a clone's ifunc resolver of a global function would be exported) */
static IFS_HOT int advance(IfsModel *m, double h)
{
    long long k;
    if (h != m->h_last) {
        /* h = n dt + rem; a remainder within 1e-9 dt of zero or dt is rounding.  The
         * caller keeps h / dt far below the range of long long. */
        double r = h / m->dt;
        long long n = (long long)floor(r + 1e-9);
        double rem = h - (double)n * m->dt;
        if (fabs(rem) <= 1e-9 * m->dt) rem = 0.0;
        m->n_last = n;
        m->rem_last = rem;
        m->h_last = h;
    }
    for (k = 0; k < m->n_last; k++) ifs_step(m->pg, m->x);
    if (m->rem_last > 0.0) {
        const double r = m->rem_last;
        /* the second remainder in a row under the same matrices is cached (one
         * exponential); a constant communication step then costs one step */
        if (r != m->rem && m->rem_prev > 0.0 && (r == m->rem_prev || m->rem == 0.0)) {
            if (ifs_discretize(m, r, m->pg_rem) != 0) return -1;
            m->rem = r;
        }
        m->rem_prev = r;
        if (r == m->rem) {
            ifs_step(m->pg_rem, m->x);
        } else {
            /* a remainder that changes from frame to frame: the Taylor series over
             * the whole remainder, or the cached step and the series over the
             * difference d = r - rem (a few terms for h = 1/60 s +- 2 %), whichever
             * needs fewer matrix-vector products (the cached step costs about one) */
            const int nk = taylor_count(m, r);
            const int nd = m->rem > 0.0 ? taylor_count(m, r - m->rem) : 0;
            if (nd > 0 && (nk == 0 || nd + 1 < nk)) {
                ifs_step(m->pg_rem, m->x);
                ifs_taylor_step(m->abr, m->abc, nd, r - m->rem, m->x);
            } else if (nk > 0) {
                ifs_taylor_step(m->abr, m->abc, nk, r, m->x);
            } else {                                /* a stiff model: the exponential */
                if (ifs_discretize(m, r, m->pg_rem) != 0) return -1;
                m->rem = r;
                ifs_step(m->pg_rem, m->x);
            }
        }
    }
    return 0;
}

int ifs_advance(IfsModel *m, double h)
{
    return advance(m, h);
}

#if IFS_COLUMN_STEP
/* The step x <- phi x + g that starts the look-ahead (ifs_step_ahead), the state
 * before it and after it kept (m->xs), phi^2 where phi is new (stale) and c = phi g
 * + g: once per change of the inputs or the matrices held, out of line (plain C
 * where it is not the step: each sum in one order in every build). */
void ifs_ahead_start(IfsModel *m)
{
    const double *pg = m->pg;
    double *before = m->xs + m->ahead_i;
    int i, j;
    memcpy(before, m->x, NX * sizeof(double));
    ifs_phi_step_to(pg, m->g, m->x, m->xs + (m->ahead_i ^ IFS_LD));
    if (m->stale & IFS_STALE_P2) {
        /* column j of phi^2: phi times phi's column j (phi_ik at pg[k IFS_LD + i]) */
        memset(m->p2, 0, sizeof m->p2);
        for (j = 0; j < NX; j++)
            for (i = 0; i < NX; i++)
                IFS_TREE_SUM(double, NX, pg[i] * pg[j * IFS_LD],
                             pg[j_ * IFS_LD + i] * pg[j * IFS_LD + j_],
                             m->p2[j * IFS_LD + i]);
        m->stale &= ~IFS_STALE_P2;
    }
    memset(m->c2, 0, sizeof m->c2);
    memcpy(m->c2, m->g, NX * sizeof(double));
    ifs_phi_step(pg, m->g, m->c2);             /* c = phi g + g (the step's sums) */
    m->g_ok = IFS_G_AHEAD;
}
#endif

/* --- mu table --- */

static void mu_entries(IfsModel *m, double out[IFS_MU_NTAB])
{
    int i, j, e;
    memset(out, 0, sizeof(double) * IFS_MU_NTAB);      /* the padding */
    /* half 0: [phi gam] as the step reads it (its zero padding too) */
    for (e = 0; e < IFS_MU_HALF0; e++) out[e] = m->pg[e];
    for (i = 0; i < NX; i++)
        for (j = 0; j < NA; j++)
            out[IFS_MU_HALF0 + i * NA + j] = j < NX ? m->a[i * NX + j] : m->b[i * NU + j - NX];
}

/* The table's exact entries at mu: an exact build's [phi gam] by columns (unpadded)
 * and [a b] row-major (the callback of ifs_mu_table_fit). */
typedef struct {
    IfsVariables v;
    IfsModel m;
} MuBuild;

static int mu_build_entries(void *ctx, double mu, double out[IFS_MU_NTAB])
{
    MuBuild *b = (MuBuild *)ctx;
    char msg[8];
    b->v.mu = mu;
#if IFS_N_SCHEDULED
    ifs_schedule_apply(&b->v);          /* the parameters follow mu: tabulated with it */
#endif
    if (ifs_build(&b->m, &b->v, msg, sizeof msg) != 0) return -1;
    mu_entries(&b->m, out);
    return 0;
}

int ifs_mu_table_build(IfsMuTable *t, const IfsVariables *v)
{
    MuBuild b;
    memset(&b, 0, sizeof b);
    b.v = *v;
    /* the mass-flow speed too: its branch points (mu = +-i lambda_hover, where
     * momentum theory's inflow turns) are as far from the table's segments as mu = 0
     * (the Simulator's check of the same table: 5e-14 to 7e-14 for ct 0.004-0.015);
     * below IFS_MU_LO, on the way to hover, the slave rebuilds exactly */
    return ifs_mu_table_fit(t, mu_build_entries, &b);
}

void ifs_mu_table_apply_ab(const IfsMuTable *t, const IfsVariables *v, IfsModel *m)
{
    double f[IFS_MU_HALF];
    int i, j;
    ifs_mu_table_eval(t, v->mu, 1, f);
    for (i = 0; i < NX; i++)
        for (j = 0; j < NA; j++) {
            if (j < NX) m->a[i * NX + j] = f[i * NA + j];
            else m->b[i * NU + j - NX] = f[i * NA + j];
        }
    build_loads(m, v);
    set_taylor(m);
    m->stale &= ~IFS_STALE_AB;
}
