/*
 * The co-simulation slave shared by the FMI 2.0 and 3.0 layers: checks, the
 * variable table, rebuilds and the general step.  See inflow_slave.h.
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "inflow_slave.h"

#define MSG_LEN 512
#define IFS_MAX_STEPS_PER_CALL 1e9

#if defined(__GNUC__)
#define IFS_COLD __attribute__((noinline, cold))
#else
#define IFS_COLD
#endif

int ifs_log(const IfsLog *lg, int status, const char *fmt, ...)
{
    char buf[MSG_LEN];
    va_list ap;
    if (!lg || !lg->emit || (status == IFS_OK && !lg->debug)) return status;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    lg->emit(lg->env, status, status == IFS_ERROR     ? "logStatusError"
                              : status == IFS_WARNING ? "logStatusWarning"
                                                      : "logAll", buf);
    return status;
}

void ifs_slave_init(IfsSlave *s)
{
    IfsMuTable *tab = s->tab;      /* the FMI layer's: kept across a reset */
    int i;
    memset(s, 0, sizeof *s);
    s->tab = tab;
    if (tab) tab->state = 0;
    for (i = 0; i < IFS_N_REALS; i++)
        *(double *)((char *)&s->v + ifs_real_vars[i].offset) = ifs_real_vars[i].start;
    for (i = 0; i < IFS_N_INTEGERS; i++)
        *(int *)((char *)&s->v + ifs_integer_vars[i].offset) = ifs_integer_vars[i].start;
#if IFS_N_SCHEDULED
    ifs_schedule_apply(&s->v);
#endif
    s->phase = IFS_PH_INSTANTIATED;
    s->dirty = 1;
    s->m.h_last = -1.0;
    s->t_stop = INFINITY;
}

int ifs_slave_set_start_time(IfsSlave *s, const IfsLog *lg, const char *fn, double start,
                             int stop_defined, double stop)
{
    if (s->phase != IFS_PH_INSTANTIATED)
        return ifs_log(lg, IFS_ERROR, "%s: only allowed after instantiation or reset", fn);
    if (!isfinite(start)) return ifs_log(lg, IFS_ERROR, "%s: start time must be finite", fn);
    if (stop_defined && !(isfinite(stop) && stop >= start))
        return ifs_log(lg, IFS_ERROR, "%s: stop time %g must be finite and not before the "
                       "start time %g", fn, stop, start);
    s->t_start = s->t_base = start;
    /* the same relative tolerance as the communication points */
    s->t_stop = stop_defined ? stop + 1e-9 * (1.0 + fabs(stop)) : INFINITY;
    return IFS_OK;
}

int ifs_slave_enter_init(IfsSlave *s, const IfsLog *lg, const char *fn)
{
    if (s->phase != IFS_PH_INSTANTIATED)
        return ifs_log(lg, IFS_ERROR, "%s: only allowed after instantiation", fn);
    s->phase = IFS_PH_INIT;
    return IFS_OK;
}

/* The delays' whole steps, fractions and partial-step matrices for m (after a
 * build); d the flap channels' delays of the structure (ifs_flap_delays_of). */
static int delay_tables(IfsSlave *s, const IfsLog *lg, const double d[3])
{
    IfsDelay *dl = &s->delay;
    int i;
    dl->active = 0;
    for (i = 0; i < 3; i++) {
        const double steps = d[i] / s->m.dt;
        dl->d[i] = d[i];
        dl->mm[i] = 0;
        dl->f[i] = 0.0;
        if (!(d[i] > 0.0)) continue;
        if (steps > IFS_DELAY_MAX_STEPS)
            return ifs_log(lg, IFS_ERROR, "flap channel %d's delay %g s is more than %d "
                           "internal steps dt = %g s: use a larger dt", i, d[i],
                           IFS_DELAY_MAX_STEPS, s->m.dt);
        dl->mm[i] = (int)floor(steps + 1e-12);
        dl->f[i] = steps - dl->mm[i];
        if (dl->f[i] < 1e-12) dl->f[i] = 0.0;
        if (dl->f[i] > 0.0 &&
            ifs_discretize(&s->m, (1.0 - dl->f[i]) * s->m.dt, dl->pg_frac[i]) != 0)
            return ifs_log(lg, IFS_ERROR, "the delay's partial step failed to discretise");
        dl->active = 1;
    }
    return IFS_OK;
}

static int rebuild(IfsSlave *s, const IfsLog *lg)
{
    char msg[MSG_LEN];
    double d[3];
#if IFS_N_SCHEDULED
    /* the scheduled parameters at the new mu (a few polynomials: the tabulated path
     * stays cheap); the table itself was built with them */
    ifs_schedule_apply(&s->v);
#endif
    ifs_flap_delays_of(&s->v, d);
    if (d[0] < 0.0 || d[1] < 0.0 || d[2] < 0.0)
        return ifs_log(lg, IFS_ERROR, "a flap delay is negative (a lead): the FMU steps "
                       "causally and applies lags only");
    if (d[0] > 0.0 || d[1] > 0.0 || d[2] > 0.0) {
        /* exact matrices: the delays' partial steps need them */
        if (ifs_build(&s->m, &s->v, msg, sizeof msg) != 0)
            return ifs_log(lg, IFS_ERROR, "%s", msg);
        s->params_changed = 0;
        s->dirty = 0;
        return delay_tables(s, lg, d);
    }
    s->delay.active = 0;
    if (s->tab && !s->params_changed && s->tab->state == 0 && s->phase == IFS_PH_STEP) {
        /* only mu changed, after initialization: tabulate once for these parameters */
        ifs_mu_table_build(s->tab, &s->v);
    }
    if (s->tab && !s->params_changed && s->tab->state == 1 && s->phase == IFS_PH_STEP &&
        s->v.mu >= IFS_MU_LO && s->v.mu <= IFS_MU_HI) {
        ifs_mu_table_apply(s->tab, &s->v, &s->m);
#if IFS_SCHEDULED_BIAS
        {   /* the outputs' rotation follows the scheduled azimuth bias: both of its
             * copies (ifs_outputs reads cos_bias, sin_bias; the four-wide step of
             * eight states or more reads rot, as set_bias in inflow_model.c sets them) */
            const double bias = ifs_bias_of(&s->v);
            s->m.cos_bias = cos(bias);
            s->m.sin_bias = sin(bias);
            s->m.rot[0] = s->m.cos_bias;
            s->m.rot[1] = s->m.sin_bias;
            s->m.rot[2] = -s->m.sin_bias;
            s->m.rot[3] = s->m.cos_bias;
        }
#endif
        s->dirty = 0;
        return IFS_OK;
    }
    if (ifs_build(&s->m, &s->v, msg, sizeof msg) != 0)
        return ifs_log(lg, IFS_ERROR, "%s", msg);
    if (s->params_changed && s->tab) s->tab->state = 0;   /* the table is for old ones */
    s->params_changed = 0;
    s->dirty = 0;
    return IFS_OK;
}

int ifs_slave_exit_init(IfsSlave *s, const IfsLog *lg, const char *fn)
{
    if (s->phase != IFS_PH_INIT)
        return ifs_log(lg, IFS_ERROR, "%s: not in initialization mode", fn);
    if (rebuild(s, lg) != IFS_OK) return IFS_ERROR;
    {   /* the delay line starts empty: before t0 + delay the flap shows the start state */
        int i;
        s->delay.k = 0;
        memcpy(s->delay.x0, s->m.x, sizeof s->delay.x0);
        for (i = 0; i < IFS_DELAY_DEPTH; i++) s->delay.hk[i] = -1;
    }
    ifs_slave_update_outputs(s);
    s->phase = IFS_PH_STEP;
    return IFS_OK;
}

/* a, b and the loads for the current mu, after a mu change taken from the table
 * (which updates [phi gam] only); from an exact build if the table is gone (a
 * restored state).  Returns 1, for use inside conditions. */
static int fresh_ab(IfsSlave *s)
{
    char msg[8];
    if (!s->m.ab_stale) return 1;
    if (s->tab && s->tab->state == 1)
        ifs_mu_table_apply_ab(s->tab, &s->v, &s->m);
    else if (ifs_build(&s->m, &s->v, msg, sizeof msg) == 0)
        s->dirty = 0;
    return 1;
}

/* --- reals --- */

static int real_ok(const IfsRealVar *var, double x)
{
    return isfinite(x) && x >= var->lower && x <= var->upper &&
           !(var->lower_open && x == var->lower);
}

/* Why value x for value reference vr is refused. */
static IFS_COLD int refuse_real(const IfsSlave *s, const IfsLog *lg, const char *fn,
                                unsigned int vr, double x)
{
    const IfsRealVar *var;
    if (vr >= IFS_N_REALS)
        return ifs_log(lg, IFS_ERROR, "%s: %u is not the value reference of a Real", fn,
                       vr);
    var = &ifs_real_vars[vr];
    if (var->kind == IFS_OUTPUT)
        return ifs_log(lg, IFS_ERROR, "%s: %s is an output", fn, var->name);
    if (var->kind == IFS_LOCAL)
        return ifs_log(lg, IFS_ERROR, "%s: %s follows the parameter schedule (computed "
                       "from mu, read-only)", fn, var->name);
    if (var->kind == IFS_FIXED && s->phase != IFS_PH_INSTANTIATED && s->phase != IFS_PH_INIT)
        return ifs_log(lg, IFS_ERROR, "%s: %s is fixed after initialization", fn, var->name);
    if (!isfinite(x))
        return ifs_log(lg, IFS_ERROR, "%s = %g refused: must be finite%s", var->name, x,
                       var->kind == IFS_INPUT ? " (state untouched)" : "");
    return ifs_log(lg, IFS_ERROR, "%s = %g is outside the allowed range %c%g, %g]",
                   var->name, x, var->lower_open ? '(' : '[', var->lower, var->upper);
}

int ifs_slave_get_reals(IfsSlave *s, const IfsLog *lg, const char *fn,
                        const unsigned int vr[], size_t n, double value[])
{
    size_t i;
    if (n > 0 && (!vr || !value)) return ifs_log(lg, IFS_ERROR, "%s: null array", fn);
    for (i = 0; i < n; i++) {
        if (vr[i] - IFS_VR_beta0 < 6u) {        /* flap and inflow: stored at each step */
            value[i] = (&s->v.beta0)[vr[i] - IFS_VR_beta0];
            continue;
        }
        if (vr[i] >= IFS_N_REALS)
            return ifs_log(lg, IFS_ERROR, "%s: %u is not the value reference of a Real", fn,
                           vr[i]);
        if (vr[i] >= IFS_VR_CT && vr[i] <= IFS_VR_C_ms_hub && fresh_ab(s))
            /* the loads depend on the inputs held now: computed when read */
            value[i] = s->phase == IFS_PH_STEP
                           ? ifs_load(&s->m, (int)(vr[i] - IFS_VR_CT), ifs_slave_inputs(s))
                           : 0.0;
        else
            value[i] = *(const double *)((const char *)&s->v + ifs_real_vars[vr[i]].offset);
    }
    return IFS_OK;
}

/* value references 0 .. IFS_NU - 1 are the inputs theta0 .. muy, in the struct's
 * order (ifs_slave_inputs), each declared within +-IFS_INPUT_LIMIT; the six outputs
 * beta0 .. lambda1s are contiguous too */
typedef char ifs_inputs_are_vr_0_to_nu[IFS_VR_theta0 == 0 && IFS_VR_muy == IFS_NU - 1
                                       ? 1 : -1];
typedef char ifs_outputs_are_contiguous[
    IFS_VR_lambda1s - IFS_VR_beta0 == 5 &&
    offsetof(IfsVariables, lambda1s) - offsetof(IfsVariables, beta0) == 5 * sizeof(double)
    ? 1 : -1];

int ifs_slave_set_reals(IfsSlave *s, const IfsLog *lg, const char *fn,
                        const unsigned int vr[], size_t n, const double value[])
{
    const int fixed_ok = s->phase == IFS_PH_INSTANTIATED || s->phase == IFS_PH_INIT;
    IfsVariables before;
    int parameters = 0;
    size_t i;
    if (n > 0 && (!vr || !value)) return ifs_log(lg, IFS_ERROR, "%s: null array", fn);
    if (ifs_slave_set_mu(s, vr, n, value)) return IFS_OK;
    /* the simulator loop's frame: inputs only, each within its declared range (NaN
     * fails the test), which need no rebuild: stored at once.  The general checks
     * below cost half again as much per value (bench/fmu.md). */
    /* mu as well, within the table's range with no other parameter pending: a
     * flight condition changing every step (stored; the step applies it) */
    for (i = 0; i < n; i++)
        if (vr[i] < IFS_NU ? !(fabs(value[i]) <= IFS_INPUT_LIMIT)
                           : (vr[i] != IFS_VR_mu || s->params_changed ||
                              !(value[i] >= IFS_MU_LO && value[i] <= IFS_MU_HI) ||
                              !real_ok(&ifs_real_vars[IFS_VR_mu], value[i])))
            break;
    if (i == n) {
        double *in = (double *)ifs_slave_inputs(s);
        for (i = 0; i < n; i++) {
            if (vr[i] < IFS_NU) {
                in[vr[i]] = value[i];
            } else {
                if (s->v.mu != value[i]) s->dirty = 1;
                s->v.mu = value[i];
            }
        }
        return IFS_OK;
    }
    /* check everything first: a refused call changes nothing */
    for (i = 0; i < n; i++) {
        const IfsRealVar *var = &ifs_real_vars[vr[i] < IFS_N_REALS ? vr[i] : 0];
        if (vr[i] >= IFS_N_REALS || var->kind == IFS_OUTPUT || var->kind == IFS_LOCAL ||
            (var->kind == IFS_FIXED && !fixed_ok) || !real_ok(var, value[i]))
            return refuse_real(s, lg, fn, vr[i], value[i]);
        if (vr[i] == IFS_VR_mu && s->v.inflow_speed == 0 && value[i] < IFS_MU_LO)
            return ifs_log(lg, IFS_ERROR, "mu = %g is outside the allowed range " IFS_MU_RANGE " "
                           "with inflow_speed 0 (V ~ mu needs forward flight); set "
                           "inflow_speed 1 and ct first to reach hover", value[i]);
        parameters |= var->kind != IFS_INPUT;
    }
    /* the copy to restore if the model refuses a new parameter (half a kilobyte):
     * only when parameters are set, never in the simulator loop's input frame, which
     * it made a third slower (bench/fmu.md) */
    if (parameters) before = s->v;
    for (i = 0; i < n; i++) {
        const IfsRealVar *var = &ifs_real_vars[vr[i]];
        double *slot = (double *)((char *)&s->v + var->offset);
        /* inputs other than mu enter the step as they are; the rest rebuild */
        if ((var->kind != IFS_INPUT || vr[i] == IFS_VR_mu) && *slot != value[i]) {
            s->dirty = 1;
            if (vr[i] != IFS_VR_mu) s->params_changed = 1;
        }
        *slot = value[i];
    }
    /* a new parameter between steps takes effect at once: the outputs (the azimuth
     * bias rotates them) and the loads (their flap rate comes from the dynamics) are
     * those of the new model, as after Simulator.set_model; a mu change alone waits
     * for the step (the tabulated path).  A set the model refuses changes nothing. */
    if (s->phase == IFS_PH_STEP && s->params_changed) {
        if (rebuild(s, lg) != IFS_OK) {   /* the model was left as it was */
            if (parameters) s->v = before;
            return IFS_ERROR;
        }
        ifs_slave_update_outputs(s);
    }
    return IFS_OK;
}

/* --- integers --- */

static const IfsIntegerVar *integer_var(unsigned int vr)
{
    int k;
    for (k = 0; k < IFS_N_INTEGERS; k++)
        if (ifs_integer_vars[k].vr == vr) return &ifs_integer_vars[k];
    return NULL;
}

int ifs_slave_get_ints(const IfsSlave *s, const IfsLog *lg, const char *fn,
                       const unsigned int vr[], size_t n, int value[])
{
    size_t i;
    if (n > 0 && (!vr || !value)) return ifs_log(lg, IFS_ERROR, "%s: null array", fn);
    for (i = 0; i < n; i++) {
        const IfsIntegerVar *var = integer_var(vr[i]);
        if (!var)
            return ifs_log(lg, IFS_ERROR, "%s: %u is not the value reference of an Integer",
                           fn, vr[i]);
        value[i] = *(const int *)((const char *)&s->v + var->offset);
    }
    return IFS_OK;
}

int ifs_slave_set_ints(IfsSlave *s, const IfsLog *lg, const char *fn,
                       const unsigned int vr[], size_t n, const int value[])
{
    size_t i;
    if (n > 0 && (!vr || !value)) return ifs_log(lg, IFS_ERROR, "%s: null array", fn);
    for (i = 0; i < n; i++) {
        const IfsIntegerVar *var = integer_var(vr[i]);
        if (!var)
            return ifs_log(lg, IFS_ERROR, "%s: %u is not the value reference of an Integer",
                           fn, vr[i]);
        if (var->kind == IFS_FIXED && s->phase != IFS_PH_INSTANTIATED &&
            s->phase != IFS_PH_INIT)
            return ifs_log(lg, IFS_ERROR, "%s: %s is fixed after initialization", fn,
                           var->name);
        if (value[i] < var->lower || value[i] > var->upper)
            return ifs_log(lg, IFS_ERROR, "%s = %d is outside the allowed range [%d, %d]",
                           var->name, value[i], var->lower, var->upper);
    }
    for (i = 0; i < n; i++) {
        *(int *)((char *)&s->v + integer_var(vr[i])->offset) = value[i];
        s->dirty = 1;
        s->params_changed = 1;
    }
    return IFS_OK;
}

/* --- directional derivatives --- */

int ifs_slave_directional(IfsSlave *s, const IfsLog *lg, const char *fn,
                          const unsigned int unknown[], size_t nu,
                          const unsigned int known[], size_t nk, const double dknown[],
                          double dunknown[])
{
    size_t i;
    if (s->phase != IFS_PH_INIT && s->phase != IFS_PH_STEP)
        return ifs_log(lg, IFS_ERROR, "%s: only in initialization or step mode", fn);
    if ((nu > 0 && (!unknown || !dunknown)) || (nk > 0 && (!known || !dknown)))
        return ifs_log(lg, IFS_ERROR, "%s: null array", fn);
    for (i = 0; i < nu; i++)
        if (unknown[i] >= IFS_N_REALS || ifs_real_vars[unknown[i]].kind != IFS_OUTPUT)
            return ifs_log(lg, IFS_ERROR, "%s: unknown %u is not an output", fn, unknown[i]);
    for (i = 0; i < nk; i++)
        if (known[i] >= IFS_N_REALS || ifs_real_vars[known[i]].kind != IFS_INPUT)
            return ifs_log(lg, IFS_ERROR, "%s: known %u is not an input", fn, known[i]);
    fresh_ab(s);
    for (i = 0; i < nu; i++) {
        double d = 0.0;
        if (unknown[i] >= IFS_VR_CT && unknown[i] <= IFS_VR_C_ms_hub) {
            /* the loads: exactly ld (Eq. (4) is linear in the held inputs) */
            const int row = (int)(unknown[i] - IFS_VR_CT);
            size_t j;
            for (j = 0; j < nk; j++) {
                if (known[j] == IFS_VR_mu)
                    return ifs_log(lg, IFS_ERROR, "%s: the loads' derivative with respect "
                                   "to mu is not provided (mu enters nonlinearly)", fn);
                d += s->m.ld[row * IFS_NU + known[j]] * dknown[j];
            }
        }
        dunknown[i] = d;
    }
    return IFS_OK;
}

/* --- the time-delay line --- */

/* state at step j from the ring: x_j = phi x_(j-1) + gam u_(j-1), or the start state */
static void ring_state(const IfsSlave *s, long long j, double x[IFS_NX])
{
    const IfsDelay *d = &s->delay;
    const int slot = (int)((j - 1) % IFS_DELAY_DEPTH);
    if (j <= 0 || d->hk[slot] != j - 1) {
        memcpy(x, d->x0, sizeof d->x0);
        return;
    }
    memcpy(x, d->hx[slot], sizeof d->hx[slot]);
    ifs_step(s->m.pg, x, d->hu[slot]);
}

void ifs_slave_delayed_state(const IfsSlave *s, int i, double x[IFS_NX])
{
    const IfsDelay *d = &s->delay;
    const long long k = d->k;
    if (d->f[i] == 0.0) {
        if (d->mm[i] == 0) memcpy(x, s->m.x, sizeof s->m.x);
        else ring_state(s, k - d->mm[i], x);
    } else {
        const long long j = k - d->mm[i] - 1;
        const int slot = (int)(j % IFS_DELAY_DEPTH);
        if (j < 0 || d->hk[slot] != j) {
            memcpy(x, d->x0, sizeof d->x0);
            return;
        }
        memcpy(x, d->hx[slot], sizeof d->hx[slot]);
        ifs_step(d->pg_frac[i], x, d->hu[slot]);
    }
}

/* n whole internal steps, each remembered in the ring */
static void delayed_advance(IfsSlave *s, long long n)
{
    IfsDelay *d = &s->delay;
    const double *u = ifs_slave_inputs(s);
    long long i;
    for (i = 0; i < n; i++) {
        const int slot = (int)(d->k % IFS_DELAY_DEPTH);
        memcpy(d->hx[slot], s->m.x, sizeof s->m.x);
        memcpy(d->hu[slot], u, sizeof d->hu[slot]);
        d->hk[slot] = d->k;
        ifs_step(s->m.pg, s->m.x, u);
        d->k++;
    }
}

/* --- stepping --- */

IFS_COLD int ifs_slave_step(IfsSlave *s, const IfsLog *lg, const char *fn, double t,
                            double h)
{
    double now;
    int status = IFS_OK;
    if (s->phase != IFS_PH_STEP)
        return ifs_log(lg, IFS_ERROR, "%s: not in step mode (initialization not finished)",
                       fn);
    if (!(h >= 0.0) || !isfinite(h))
        return ifs_log(lg, IFS_ERROR, "%s: communication step %g must be finite and >= 0",
                       fn, h);
    if (!isfinite(t))
        return ifs_log(lg, IFS_ERROR, "%s: communication point %g must be finite", fn, t);
    now = ifs_slave_time(s);
    if (fabs(t - now) > 1e-9 * (1.0 + fabs(now)) && !s->warned_time) {
        s->warned_time = 1;
        status = ifs_log(lg, IFS_WARNING, "%s: communication point %.17g differs from the "
                         "FMU's time %.17g (the FMU keeps its own; warned once)", fn, t, now);
    }
    if (now + h > s->t_stop)
        return ifs_log(lg, IFS_ERROR, "%s: the step from %.17g s by %g s ends after the "
                       "experiment's stop time %.17g s (fmi2SetupExperiment / "
                       "fmi3EnterInitializationMode)", fn, now, h,
                       s->t_stop - 1e-9 * (1.0 + fabs(s->t_stop)));
    if (s->dirty && rebuild(s, lg) != IFS_OK) return IFS_ERROR;
    /* whole internal steps are counted in a long long and taken one by one */
    if (h > IFS_MAX_STEPS_PER_CALL * s->m.dt)
        return ifs_log(lg, IFS_ERROR, "%s: communication step %g s is more than %g internal "
                       "steps dt = %g s: use a larger dt or shorter steps", fn, h,
                       IFS_MAX_STEPS_PER_CALL, s->m.dt);
    if (s->delay.active) {
        /* the delay line holds whole internal steps: a remainder would leave it */
        const double r = h / s->m.dt;
        const long long n = (long long)floor(r + 0.5);
        if (fabs(r - (double)n) > 1e-9 * (r > 1.0 ? r : 1.0))
            return ifs_log(lg, IFS_ERROR, "%s: with a flap delay the communication step "
                           "must be a whole number of internal steps dt = %g s, not %g s",
                           fn, s->m.dt, h);
        delayed_advance(s, n);
    } else {
        if (h != s->m.dt) fresh_ab(s);
        if (ifs_advance(&s->m, ifs_slave_inputs(s), h) != 0)
            return ifs_log(lg, IFS_ERROR, "%s: the discretisation of step %g s failed", fn,
                           h);
    }
    if (h != s->h_comm) {           /* a new communication step: restart the counter */
        s->t_base = now;
        s->h_comm = h;
        s->n_comm = 0;
    }
    s->n_comm++;
    ifs_slave_update_outputs(s);
    return status;
}

/* After a change of mu alone (s->dirty): [phi gam] from the mu table, as rebuild
 * takes it, if the table is valid for the parameters and holds mu (then 1, and
 * s->dirty cleared); else 0 and nothing done (the general step rebuilds).  The
 * caller checked that no delay is active. */
IFS_INLINE int ifs_slave_mu_from_table(IfsSlave *s)
{
#if IFS_N_SCHEDULED || IFS_SCHEDULED_BIAS
    (void)s;
    return 0;
#else
    if (s->params_changed || !s->tab || s->tab->state != 1 || s->phase != IFS_PH_STEP ||
        !(s->v.mu >= IFS_MU_LO && s->v.mu <= IFS_MU_HI))
        return 0;
    ifs_mu_table_apply(s->tab, &s->v, &s->m);
    s->dirty = 0;
    return 1;
#endif
}

IFS_INLINE int ifs_slave_step_mu(IfsSlave *s, double t, double h)
{
    IFS_STEP_FAST_BODY(s, t, h, ifs_slave_mu_from_table(s), IFS_STEP_NARROW(s));
}

/* (static: a global function's clones export their resolver) */
static IFS_HOT int step_rest(IfsSlave *s, const IfsLog *lg, const char *fn, double t,
                             double h)
{
    if (s->dirty && ifs_slave_step_mu(s, t, h)) return IFS_OK;
    return ifs_slave_step(s, lg, fn, t, h);
}

int ifs_slave_step_rest(IfsSlave *s, const IfsLog *lg, const char *fn, double t, double h)
{
    return step_rest(s, lg, fn, t, h);
}

#ifdef IFS_WIDE_STEP
static inline __attribute__((target("avx2"), always_inline)) int
ifs_slave_step_mu_wide(IfsSlave *s, double t, double h)
{
    IFS_STEP_FAST_BODY(s, t, h, ifs_slave_mu_from_table(s),
                       ifs_step_wide(&s->m, ifs_slave_inputs(s), ifs_slave_outputs(s)));
}

__attribute__((target("avx2"))) int ifs_slave_step_rest_wide(IfsSlave *s, const IfsLog *lg,
                                                              const char *fn, double t,
                                                              double h)
{
    if (s->dirty && ifs_slave_step_mu_wide(s, t, h)) return IFS_OK;
    return ifs_slave_step(s, lg, fn, t, h);
}
#endif

/* --- FMU state --- */

static int is_state(const void *p, size_t n)
{
    IfsSavedState st;
    if (!p || n != sizeof st) return 0;
    memcpy(&st, p, sizeof st);
    return st.magic == IFS_STATE_MAGIC && st.size == sizeof st &&
           strncmp(st.guid, IFS_GUID, sizeof st.guid) == 0;
}

int ifs_state_get(const IfsSlave *s, const IfsLog *lg, const char *fn, void **state,
                  IfsAlloc alloc, void *ctx)
{
    IfsSavedState *st;
    if (!state) return ifs_log(lg, IFS_ERROR, "%s: null state pointer", fn);
    st = (IfsSavedState *)*state;
    if (!st) {
        st = (IfsSavedState *)alloc(ctx, sizeof(IfsSavedState));
        if (!st) return ifs_log(lg, IFS_ERROR, "%s: out of memory", fn);
    }
    st->magic = IFS_STATE_MAGIC;
    st->size = (unsigned int)sizeof(IfsSavedState);
    memset(st->guid, 0, sizeof st->guid);
    strncpy(st->guid, IFS_GUID, sizeof st->guid - 1);
    st->s = *s;
    *state = st;
    return IFS_OK;
}

int ifs_state_set(IfsSlave *s, const IfsLog *lg, const char *fn, const void *state)
{
    if (!is_state(state, sizeof(IfsSavedState)))
        return ifs_log(lg, IFS_ERROR, "%s: not a state of this FMU", fn);
    IfsMuTable *tab = s->tab;      /* this instance's table, not the saved pointer */
    *s = ((const IfsSavedState *)state)->s;
    s->tab = tab;
    if (tab) tab->state = 0;       /* the saved parameters may differ */
    s->params_changed = 1;         /* the next mu change rebuilds exactly */
    return IFS_OK;
}

int ifs_state_serialize(const IfsLog *lg, const char *fn, const void *state,
                        unsigned char bytes[], size_t size)
{
    if (!state || !bytes || size < sizeof(IfsSavedState))
        return ifs_log(lg, IFS_ERROR, "%s: need a state and %u bytes", fn,
                       (unsigned)sizeof(IfsSavedState));
    memcpy(bytes, state, sizeof(IfsSavedState));
    return IFS_OK;
}

int ifs_state_deserialize(const IfsLog *lg, const char *fn, const unsigned char bytes[],
                          size_t size, void **state, IfsAlloc alloc, void *ctx)
{
    if (!state) return ifs_log(lg, IFS_ERROR, "%s: null state pointer", fn);
    if (!is_state(bytes, size))
        return ifs_log(lg, IFS_ERROR, "%s: %u bytes are not a state of this FMU", fn,
                       (unsigned)size);
    if (!*state) {
        *state = alloc(ctx, sizeof(IfsSavedState));
        if (!*state) return ifs_log(lg, IFS_ERROR, "%s: out of memory", fn);
    }
    memcpy(*state, bytes, sizeof(IfsSavedState));
    return IFS_OK;
}

/* --- an FMI instance --- */

IfsInstance *ifs_instance_alloc(size_t size, IfsCalloc alloc, IfsRelease release, void *mem,
                                const char *name, int logging_on)
{
    /* the instance holds the delay line (no large stack copy), and is allocated
     * before any check so that refusals can be logged through it */
    void *block;
    IfsInstance *c = (IfsInstance *)ifs_align64(alloc(mem, size + 64), &block);
    if (!c) return NULL;
    memset(c, 0, size);
    c->block = block;
    c->alloc = alloc;
    c->release = release;
    c->mem = mem;
    c->log.env = c;
    c->log.debug = logging_on;
    snprintf(c->name, sizeof c->name, "%s", name ? name : "inflowsim");
    return c;
}

int ifs_instance_start(IfsInstance *c, const char *refusal, const char *what,
                       const char *token)
{
    if (refusal || !token || strcmp(token, IFS_GUID) != 0) {
        if (refusal)
            ifs_log(&c->log, IFS_ERROR, "%s", refusal);
        else
            ifs_log(&c->log, IFS_ERROR, "%s %s does not match this binary's %s", what,
                    token ? token : "(null)", IFS_GUID);
        c->release(c->mem, c->block);
        return -1;
    }
    ifs_slave_init(&c->s);
    c->s.tab = (IfsMuTable *)c->alloc(c->mem, sizeof(IfsMuTable));
    return 0;
}

void ifs_instance_free(IfsInstance *c)
{
    if (c->s.tab) c->release(c->mem, c->s.tab);
    c->release(c->mem, c->block);
}

void *ifs_instance_calloc(void *ctx, size_t n)
{
    const IfsInstance *c = (const IfsInstance *)ctx;
    return c->alloc(c->mem, n);
}
