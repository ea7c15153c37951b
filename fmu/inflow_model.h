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
 * Continuous:  x_dot = a x + b u,   y = c x   (seconds, model.md Eq. 8-9, 13, 19-20)
 * Discrete:    x_{k+1} = phi x_k + gam u_k   (u held over the step)
 */
#ifndef INFLOW_MODEL_H
#define INFLOW_MODEL_H

#include "inflow_vars.h"

#define IFS_NX 6
#define IFS_NU 10
#define IFS_NA (IFS_NX + IFS_NU)   /* augmented [x; u] */

enum { IFS_BASIC = 0, IFS_EMPIRICAL = 1, IFS_GLAUERT = 2 };

typedef struct {
    /* continuous SI state space, row-major */
    double a[IFS_NX * IFS_NX];
    double b[IFS_NX * IFS_NU];
    /* outputs y = c x: identity but the recorded flap rotated by the azimuth bias */
    double cos_bias, sin_bias;
    /* [phi gam] at the internal step dt, stored by columns (IFS_NA columns of
     * IFS_NX) so one step is a sum of scaled columns the compiler vectorises */
    double pg[IFS_NA * IFS_NX];
    double dt;
    /* cached [phi gam] (by columns) of the last remainder step (h not n dt) */
    double pg_rem[IFS_NA * IFS_NX];
    double rem;                    /* its length [s]; 0 = no cache */
    /* cached split of the last communication step h = n dt + rem */
    double h_last;
    long n_last;
    double rem_last;
    /* state */
    double x[IFS_NX];
} IfsModel;

/* Build a, b, c (and [phi gam] at v->dt) from the variables (parameters, constants,
 * mu, structure).  The state x is kept.  Returns 0, or -1 with a one-line reason in
 * msg; on failure *m is unchanged. */
int ifs_build(IfsModel *m, const IfsVariables *v, char *msg, size_t msg_len);

/* Descriptor matrices in azimuth time, model.md Eq. (8): E x' = A x + B u_az,
 * u_az the inputs in azimuth units (qbar = q/Omega, qbar' = qdot/Omega^2 ...). */
void ifs_descriptor(const IfsVariables *v, double e[IFS_NX * IFS_NX],
                    double a[IFS_NX * IFS_NX], double b[IFS_NX * IFS_NU]);

/* [phi gam] for a step h [s]: exp([[a, b], [0, 0]] h), top rows, stored by columns
 * (element (i, j) at pg[j * IFS_NX + i]). */
int ifs_discretize(const IfsModel *m, double h, double pg[IFS_NA * IFS_NX]);

/* Advance the state over h [s] with u held: whole internal steps dt and one exact
 * remainder step.  Returns 0, or -1 if the remainder discretisation failed. */
int ifs_advance(IfsModel *m, const double u[IFS_NU], double h);

/* y = c x. */
void ifs_outputs(const IfsModel *m, double y[IFS_NX]);

#endif
