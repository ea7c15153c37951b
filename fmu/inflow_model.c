/*
 * Rotor flap and dynamic inflow: matrices from parameters (model.md Eq. 1-4, 13,
 * 19-20, section 6), exact zero-order-hold discretisation, one step.  The
 * equations themselves (descriptor, loads' blade-element matrices) are generated
 * from the Python model into inflow_equations.c (inflowsim.fmu.codegen); this file
 * does the SI state space, discretisation and stepping of inflowsim.model.build_model
 * and inflowsim.discrete.zoh.  The tests check the two agree to rounding.  Knows
 * nothing of FMI.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "inflow_model.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define NX IFS_NX
#define NU IFS_NU
#define NA IFS_NA

/* --- small dense linear algebra (row-major, fixed sizes, no allocation) --- */

/* Solve A X = B in place (A n x n destroyed, B n x nrhs overwritten by X), LU with
 * partial pivoting.  -1 if a pivot is below tol times the largest |A| entry. */
static int lu_solve(int n, double *A, int nrhs, double *B, double tol)
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
static int expm(double *A)
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
    if (lu_solve(NA, T, NA, A, 1e-300) != 0) return -1;   /* (V - U)^-1 (V + U) */
    for (; s > 0; s--) { matmul(A, A, T); memcpy(A, T, sizeof T); }
    return 0;
}

/* --- the model's matrices --- */

/* Speed through the disc over Omega R in the momentum gains: the paper's V ~ mu, or
 * (inflow_speed 1) the momentum mass-flow parameter with the trim inflow of level
 * flight, V = (mu^2 + 2 l^2) / sqrt(mu^2 + l^2), l solving 4 l^2 (mu^2 + l^2) = ct^2
 * by Newton's method from sqrt(ct/2) -- the same operations, in the same order, as
 * inflowsim.physics.loads.momentum_inflow and mass_flow_parameter. */
static double flow_speed(const IfsVariables *v)
{
    const double mu = v->mu, ct = v->ct;
    double lam;
    int k;
    if (v->inflow_speed == 0) return mu;
    lam = sqrt(ct / 2.0);
    for (k = 0; k < 100; k++) {
        const double f = 4 * lam * lam * (mu * mu + lam * lam) - ct * ct;
        const double step = f / (8 * lam * mu * mu + 16 * lam * lam * lam);
        lam -= step;
        if (fabs(step) <= 1e-15 * lam) break;
    }
    return (mu * mu + 2 * lam * lam) / hypot(mu, lam);
}

/* second-harmonic-flap: the quasi-steady 2/rev flap's own term in the aerodynamic
 * loads, by beta' (from the dynamics), beta, lambda and the inputs (azimuth units:
 * qbar = q / Omega, qbar' = qdot / Omega^2); inflowsim.model.loads does the same. */
static void add_harmonic_loads(IfsModel *n, const IfsVariables *v)
{
    double w[3 * 17];
    const double a0s = v->a0 * v->solidity, om = v->omega;
    const double scale[8] = {1.0, 1.0, 1.0, 1.0, 1.0 / om, 1.0 / om, 1.0 / (om * om),
                             1.0 / (om * om)};
    int r, i, j;
    if (!ifs_harmonic_loads_of(v, w)) return;
    for (r = 0; r < 3; r++) {
        const double *wr = w + 17 * r;
        for (j = 0; j < NX; j++) {
            double s = 0.0;
            for (i = 0; i < 3; i++) s += wr[i] * n->a[i * NX + j];
            s /= om;
            if (j < 3) s += wr[3 + j];
            else if (j < 6) s += wr[6 + j - 3];
            n->lc[r * NX + j] += a0s * s;
        }
        for (j = 0; j < NU; j++) {
            double s = 0.0;
            for (i = 0; i < 3; i++) s += wr[i] * n->b[i * NU + j];
            s /= om;
            if (j < 8) s += wr[9 + j] * scale[j];
            n->ld[r * NU + j] += a0s * s;
        }
    }
}

/* loads = lc x + ld u (SI state and inputs): Eq. (4) times a0 s with beta' from the
 * dynamics (x' = (a x + b u)/Omega), the true pitch under an azimuth bias, and the
 * centre-spring hub moments -a0 s (lambda_beta2 - 1)/(16 n_beta) (beta1c, beta1s);
 * inflowsim.model.loads.load_matrices, which the tests compare. */
static void build_loads(IfsModel *n, const IfsVariables *v)
{
    double Gdb[3][3], Gb[3][3], Gl[3][3], Gu[3][6];
    const double a0s = v->a0 * v->solidity, om = v->omega;
    const double cb = n->cos_bias, sb = n->sin_bias;   /* set by set_bias */
    int r, i, j;
    ifs_load_matrices(v->mu, Gdb, Gb, Gl, Gu);
    memset(n->lc, 0, sizeof n->lc);
    memset(n->ld, 0, sizeof n->ld);
    for (r = 0; r < 3; r++) {
        for (j = 0; j < NX; j++) {
            double s = 0.0;
            for (i = 0; i < 3; i++) s += Gdb[r][i] * n->a[i * NX + j];
            s /= om;
            if (j < 3) s += Gb[r][j];
            else if (j < 6) s += Gl[r][j - 3];   /* flap rates (flap-inertia): none */
            n->lc[r * NX + j] = a0s * s;
        }
        for (j = 0; j < NU; j++) {
            double s = 0.0;
            for (i = 0; i < 3; i++) s += Gdb[r][i] * n->b[i * NU + j];
            n->ld[r * NU + j] = a0s * s / om;
        }
        /* recorded pitch: true = R(-bias) recorded, as the flap equation takes it */
        n->ld[r * NU + 0] += a0s * Gu[r][0];
        n->ld[r * NU + 1] += a0s * (Gu[r][1] * cb - Gu[r][2] * sb);
        n->ld[r * NU + 2] += a0s * (Gu[r][1] * sb + Gu[r][2] * cb);
        n->ld[r * NU + 3] += a0s * Gu[r][3];               /* muz */
        n->ld[r * NU + 4] += a0s * Gu[r][4] / om;          /* q: qbar = q / Omega */
        n->ld[r * NU + 5] += a0s * Gu[r][5] / om;          /* p */
    }
    add_harmonic_loads(n, v);
    n->lc[3 * NX + 1] = -a0s * (v->lambda_beta2 - 1.0) / (16.0 * v->n_beta);
    n->lc[4 * NX + 2] = n->lc[3 * NX + 1];
}

void ifs_descriptor(const IfsVariables *v, double e[NX * NX], double a[NX * NX],
                    double b[NX * NU])
{
    ifs_descriptor_of(v, flow_speed(v), e, a, b);
}

int ifs_discretize(const IfsModel *m, double h, double pg[NA * IFS_LD])
{
    double M[NA * NA];
    int i, j;
    memset(M, 0, sizeof M);
    for (i = 0; i < NX; i++) {
        for (j = 0; j < NX; j++) M[i * NA + j] = m->a[i * NX + j] * h;
        for (j = 0; j < NU; j++) M[i * NA + NX + j] = m->b[i * NU + j] * h;
    }
    if (expm(M) != 0) return -1;
    for (i = 0; i < NX * NA; i++)
        if (!isfinite(M[i])) return -1;
    memset(pg, 0, sizeof(double) * NA * IFS_LD);
    for (i = 0; i < NX; i++)                    /* top NX rows, by columns */
        for (j = 0; j < NA; j++) pg[j * IFS_LD + i] = M[i * NA + j];
    return 0;
}

/* Terms of the Taylor series of a step of length |r| needed: the first k whose next
 * term is bounded by 1e-17 |[x; u]| (term k is at most (|a| r)^(k-1) |[a b]| r / k!
 * |[x; u]|, 1-norms).  0 if more than IFS_KMAX would be needed. */
static int taylor_count(const IfsModel *m, double r)
{
    double bound = m->norm_ab * fabs(r), q = m->norm_a * fabs(r);
    int k;
    for (k = 1; k <= IFS_KMAX; k++) {
        if (bound * q / (k + 1) <= 1e-17) return k;
        bound *= q / (k + 1);
    }
    return 0;
}

/* x <- x(r) for u held over r (r of either sign), by the Taylor series of the
 * solution: x(r) = x + sum_k w_k with w_1 = r (a x + b u) and w_k = (r / k) a w_(k-1)
 * (the k-th derivative times r^k / k!).  nk matrix-vector products of a, no matrix
 * exponential: the step of a communication interval that changes from frame to
 * frame.  Every term is bounded by the one before (taylor_count), so nothing
 * overflows. */
static IFS_HOT void taylor_step(const IfsModel *m, int nk, double r, double x[NX],
                                const double u[NU])
{
    double w[2][IFS_LD], acc[IFS_LD];
    int i, k;
    memset(w, 0, sizeof w);
    memcpy(w[0], x, sizeof(double) * NX);
    ifs_step(m->abc, w[0], u);                       /* a x + b u */
    for (i = 0; i < NX; i++) w[0][i] *= r;
    memcpy(acc, w[0], sizeof acc);
    for (k = 2; k <= nk; k++)
        ifs_taylor_term(m->abc, w[k & 1], r / (double)k, w[(k + 1) & 1], acc);
    for (i = 0; i < NX; i++) x[i] += acc[i];
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

/* What the remainder's Taylor series needs from a and b: [a b] by columns, and the
 * 1-norms of a and [a b] that bound its terms. */
static void set_taylor(IfsModel *n)
{
    int i, j;
    memset(n->abc, 0, sizeof n->abc);
    for (i = 0; i < NX; i++) {
        for (j = 0; j < NX; j++) n->abc[j * IFS_LD + i] = n->a[i * NX + j];
        for (j = 0; j < NU; j++) n->abc[(NX + j) * IFS_LD + i] = n->b[i * NU + j];
    }
    n->norm_a = n->norm_ab = 0.0;
    for (j = 0; j < NA; j++) {
        double col = 0.0;
        for (i = 0; i < NX; i++)
            col += fabs(j < NX ? n->a[i * NX + j] : n->b[i * NU + j - NX]);
        if (j < NX && col > n->norm_a) n->norm_a = col;
        if (col > n->norm_ab) n->norm_ab = col;
    }
}

int ifs_build(IfsModel *m, const IfsVariables *v, char *msg, size_t msg_len)
{
    IfsModel n = *m;
    double e[NX * NX], a[NX * NX], b[NX * NU], rhs[NX * NA];
    const double om = v->omega;
    /* inputs in SI -> azimuth units: qbar = q/Omega, qbar' = qdot/Omega^2 */
    const double in_scale[NU] = {1, 1, 1, 1, 1 / om, 1 / om, 1 / (om * om),
                                 1 / (om * om), 1, 1};
    int i, j;

    if (v->inflow_speed == 0 && !(v->mu >= IFS_MU_LO && v->mu <= IFS_MU_HI)) {
        snprintf(msg, msg_len, "mu = %g is outside the allowed range [0.1, 0.5]: "
                 "forward-flight local momentum (V ~ mu) needs fast forward flight; "
                 "inflow_speed = 1 (mass flow, with ct) reaches hover", v->mu);
        return -1;
    }
    if (v->inflow_speed == 1 && !(v->mu >= 0.0 && v->mu <= 0.5 && v->ct > 0.0)) {
        snprintf(msg, msg_len, "mu = %g, ct = %g: the mass-flow speed needs mu in "
                 "[0, 0.5] and a trim thrust coefficient ct > 0", v->mu, v->ct);
        return -1;
    }
    if (v->structure < 0 || v->structure >= IFS_N_STRUCTURES) {
        snprintf(msg, msg_len, "structure = %d is outside the allowed range [0, %d] (%s)",
                 v->structure, IFS_N_STRUCTURES - 1, IFS_STRUCTURE_NAMES);
        return -1;
    }
    ifs_descriptor(v, e, a, b);
    for (i = 0; i < NX; i++) {
        for (j = 0; j < NX; j++) rhs[i * NA + j] = a[i * NX + j];
        for (j = 0; j < NU; j++) rhs[i * NA + NX + j] = b[i * NU + j];
    }
    if (lu_solve(NX, e, NA, rhs, 1e-12) != 0) {
        snprintf(msg, msg_len, "the descriptor matrix E is singular for these parameters "
                 "(n_beta, the time constants, k0p, kc, ks, flap_inertia)");
        return -1;
    }
    for (i = 0; i < NX; i++) {
        for (j = 0; j < NX; j++) n.a[i * NX + j] = om * rhs[i * NA + j];
        for (j = 0; j < NU; j++) n.b[i * NU + j] = om * rhs[i * NA + NX + j] * in_scale[j];
    }
    n.ab_stale = 0;
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
    set_taylor(&n);
    *m = n;
    return 0;
}

/* (static: a clone's ifunc resolver of a global function would be exported) */
static IFS_HOT int advance(IfsModel *m, const double u[NU], double h)
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
    for (k = 0; k < m->n_last; k++) ifs_step(m->pg, m->x, u);
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
            ifs_step(m->pg_rem, m->x, u);
        } else {
            /* a remainder that changes from frame to frame: the Taylor series over
             * the whole remainder, or the cached step and the series over the
             * difference d = r - rem (a few terms for h = 1/60 s +- 2 %), whichever
             * needs fewer matrix-vector products (the cached step costs about one) */
            const int nk = taylor_count(m, r);
            const int nd = m->rem > 0.0 ? taylor_count(m, r - m->rem) : 0;
            if (nd > 0 && (nk == 0 || nd + 1 < nk)) {
                ifs_step(m->pg_rem, m->x, u);
                taylor_step(m, nd, r - m->rem, m->x, u);
            } else if (nk > 0) {
                taylor_step(m, nk, r, m->x, u);
            } else {                                /* a stiff model: the exponential */
                if (ifs_discretize(m, r, m->pg_rem) != 0) return -1;
                m->rem = r;
                ifs_step(m->pg_rem, m->x, u);
            }
        }
    }
    return 0;
}

int ifs_advance(IfsModel *m, const double u[NU], double h)
{
    return advance(m, u, h);
}

/* --- mu table --- */

static void mu_entries(const IfsModel *m, double out[IFS_MU_NTAB])
{
    int i, j;
    memset(out, 0, sizeof(double) * IFS_MU_NTAB);      /* the padding */
    for (i = 0; i < NX; i++)
        for (j = 0; j < NA; j++) {
            out[j * NX + i] = m->pg[j * IFS_LD + i];    /* by columns, unpadded */
            out[IFS_MU_HALF + i * NA + j] =
                j < NX ? m->a[i * NX + j] : m->b[i * NU + j - NX];
        }
}

/* Segment s covers [lo q^s, lo q^(s+1)], q = (hi/lo)^(1/SEG). */
static double mu_edge(int seg)
{
    return IFS_MU_LO * pow(IFS_MU_HI / IFS_MU_LO, (double)seg / IFS_MU_SEG);
}

/* The table's interpolant at mu: [phi gam] (half 0, by columns) or [a b] (half 1,
 * row-major).  Horner's rule on four entries at a time, the degrees innermost so
 * the sums stay in registers; each entry gets the same operations in the same
 * order in the vector and the scalar code.  (IFS_HOT: the AVX2 clone does four
 * doubles a vector; the same numbers.) */
static IFS_HOT void mu_eval_half(const IfsMuTable *t, double mu, int half,
                                 double out[IFS_MU_HALF])
{
    const int first = half * IFS_MU_HALF;
    int seg = (int)(IFS_MU_SEG * 0.5 * (mu - IFS_MU_LO) / (IFS_MU_HI - IFS_MU_LO));
    double lo, hi, x;
    int k, e;
    /* a guess below the true segment (segments narrow toward mu_lo), then walk up */
    if (seg < 0) seg = 0;
    if (seg >= IFS_MU_SEG) seg = IFS_MU_SEG - 1;
    while (seg > 0 && mu < t->edge[seg]) seg--;
    while (seg < IFS_MU_SEG - 1 && mu >= t->edge[seg + 1]) seg++;
    lo = t->edge[seg];
    hi = t->edge[seg + 1];
    x = (2.0 * mu - lo - hi) / (hi - lo);
    for (e = 0; e < IFS_MU_HALF; e += 4) {
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
        ifs_v4 acc = *(const ifs_v4 *)(t->p[seg][IFS_MU_DEG] + first + e);
        IFS_UNROLL
        for (k = IFS_MU_DEG - 1; k >= 0; k--)
            acc = acc * x + *(const ifs_v4 *)(t->p[seg][k] + first + e);
        *(ifs_v4 *)(out + e) = acc;
#else
        int i;
        for (i = e; i < e + 4; i++) {
            double acc = t->p[seg][IFS_MU_DEG][first + i];
            for (k = IFS_MU_DEG - 1; k >= 0; k--) acc = acc * x + t->p[seg][k][first + i];
            out[i] = acc;
        }
#endif
    }
}

int ifs_mu_table_build(IfsMuTable *t, const IfsVariables *v)
{
    const int N = IFS_MU_DEG + 1;
    double f[IFS_MU_DEG + 1][IFS_MU_NTAB];   /* 12 kB of stack, during a build */
    double T[IFS_MU_DEG + 1][IFS_MU_DEG + 1];        /* T_k(x) = sum_i T[k][i] x^i */
    IfsVariables vn = *v;
    IfsModel m;
    char msg[8];
    int seg, j, k, i, e;
    double worst = 0.0;
    memset(&m, 0, sizeof m);
    memset(T, 0, sizeof T);
    T[0][0] = 1.0;
    T[1][1] = 1.0;
    for (k = 2; k < N; k++)
        for (i = 0; i < N; i++)
            T[k][i] = (i > 0 ? 2.0 * T[k - 1][i - 1] : 0.0) - T[k - 2][i];
    t->state = -1;
    t->err = 0.0;
    /* the mass-flow speed has branch points near mu = 0 in the complex plane (where
     * momentum theory's inflow turns), too close for this table: exact rebuilds */
    if (v->inflow_speed != 0) return t->state;
    for (seg = 0; seg <= IFS_MU_SEG; seg++) t->edge[seg] = mu_edge(seg);
    for (seg = 0; seg < IFS_MU_SEG; seg++) {
        const double lo = t->edge[seg], hi = t->edge[seg + 1];
        for (j = 0; j < N; j++) {
            const double xj = cos(M_PI * (j + 0.5) / N);
            vn.mu = 0.5 * (lo + hi) + 0.5 * (hi - lo) * xj;
            if (ifs_build(&m, &vn, msg, sizeof msg) != 0) return t->state;
            mu_entries(&m, f[j]);
        }
        for (e = 0; e < IFS_MU_NTAB; e++) {
            double c[IFS_MU_DEG + 1];
            for (k = 0; k < N; k++) {             /* Chebyshev coefficients */
                double acc = 0.0;
                for (j = 0; j < N; j++) acc += f[j][e] * cos(M_PI * k * (j + 0.5) / N);
                c[k] = (k == 0 ? 1.0 : 2.0) * acc / N;
            }
            for (i = 0; i < N; i++) {             /* to powers of x */
                double acc = 0.0;
                for (k = i; k < N; k++) acc += c[k] * T[k][i];
                t->p[seg][i][e] = acc;
            }
        }
    }
    for (seg = 0; seg < IFS_MU_SEG; seg++) {       /* check between the nodes */
        double got[IFS_MU_NTAB], want[IFS_MU_NTAB], scale[2] = {0.0, 0.0};
        vn.mu = 0.5 * (mu_edge(seg) + mu_edge(seg + 1));
        if (ifs_build(&m, &vn, msg, sizeof msg) != 0) return t->state;
        mu_entries(&m, want);
        mu_eval_half(t, vn.mu, 0, got);
        mu_eval_half(t, vn.mu, 1, got + IFS_MU_HALF);
        for (e = 0; e < IFS_MU_NTAB; e++)
            if (fabs(want[e]) > scale[e >= IFS_MU_HALF])
                scale[e >= IFS_MU_HALF] = fabs(want[e]);
        for (e = 0; e < IFS_MU_NTAB; e++) {
            const double r = fabs(got[e] - want[e]) / scale[e >= IFS_MU_HALF];
            if (!(r <= worst)) worst = r;       /* NaN-safe */
        }
    }
    t->err = worst;
    t->state = worst <= 1e-11 ? 1 : -1;
    return t->state;
}

void ifs_mu_table_apply(const IfsMuTable *t, const IfsVariables *v, IfsModel *m)
{
    double f[IFS_MU_HALF];
    int j;
    mu_eval_half(t, v->mu, 0, f);
    for (j = 0; j < NA; j++) memcpy(m->pg + j * IFS_LD, f + j * NX, sizeof(double) * NX);
    m->rem = 0.0;          /* the remainder caches belong to the old matrices */
    m->rem_prev = 0.0;
    m->ab_stale = 1;
}

void ifs_mu_table_apply_ab(const IfsMuTable *t, const IfsVariables *v, IfsModel *m)
{
    double f[IFS_MU_HALF];
    int i, j;
    mu_eval_half(t, v->mu, 1, f);
    for (i = 0; i < NX; i++)
        for (j = 0; j < NA; j++) {
            if (j < NX) m->a[i * NX + j] = f[i * NA + j];
            else m->b[i * NU + j - NX] = f[i * NA + j];
        }
    build_loads(m, v);
    set_taylor(m);
    m->ab_stale = 0;
}
