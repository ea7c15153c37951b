/*
 * The co-simulation slave shared by the FMI 2.0 and 3.0 layers: checks, the
 * variable table, rebuilds and the general step.  See inflow_slave.h.
 */
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "inflow_slave.h"

#define MSG_LEN 512
#define IFS_MAX_STEPS_PER_CALL 1e9

#if defined(__GNUC__)
#define IFS_COLD __attribute__((noinline, cold))
#define IFS_NOINLINE __attribute__((noinline))
#else
#define IFS_COLD
#define IFS_NOINLINE
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
    {   /* the table's range and mu's declared one (an open end of it inside the
         * table's: none; mu then always waits for the step) */
        const IfsRealVar *var = &ifs_real_vars[IFS_VR_mu];
        const int open = var->lower_open && var->lower >= IFS_MU_LO;
        s->mu_range[0] = open ? INFINITY : var->lower > IFS_MU_LO ? var->lower : IFS_MU_LO;
        s->mu_range[1] = open ? -INFINITY : var->upper < IFS_MU_HI ? var->upper : IFS_MU_HI;
    }
    s->phase = IFS_PH_INSTANTIATED;
    s->dirty = 1;
    s->m.h_last = -1.0;
    s->t_stop = INFINITY;
    ifs_slave_hold_inputs(s);
    ifs_slave_refresh(s);
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
    ifs_slave_refresh(s);
    return IFS_OK;
}

int ifs_slave_enter_init(IfsSlave *s, const IfsLog *lg, const char *fn)
{
    if (s->phase != IFS_PH_INSTANTIATED)
        return ifs_log(lg, IFS_ERROR, "%s: only allowed after instantiation", fn);
    s->phase = IFS_PH_INIT;
    ifs_slave_refresh(s);
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

static int rebuild_model(IfsSlave *s, const IfsLog *lg)
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
        {   /* the outputs' rotation follows the scheduled azimuth bias (ifs_outputs
             * reads cos_bias, sin_bias, as set_bias in inflow_model.c sets them) */
            const double bias = ifs_bias_of(&s->v);
            s->m.cos_bias = cos(bias);
            s->m.sin_bias = sin(bias);
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

/* The model for the variables (a change of mu alone from the table where it can),
 * the delay line's tables; the outputs are then stale. */
static int rebuild(IfsSlave *s, const IfsLog *lg)
{
    const int status = rebuild_model(s, lg);
    s->y_stale = 1;
    ifs_slave_refresh(s);
    return status;
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
    s->y_stale = 1;
    s->phase = IFS_PH_STEP;
    ifs_slave_refresh(s);
    return IFS_OK;
}

/* a, b and the loads for the current mu, after a mu change taken from the table
 * (which updates [phi gam] only); from an exact build if the table is gone (a
 * restored state).  Returns 1, for use inside conditions. */
static int fresh_ab(IfsSlave *s)
{
    char msg[8];
    if (!(s->m.stale & IFS_STALE_AB)) return 1;
    if (s->tab && s->tab->state == 1)
        ifs_mu_table_apply_ab(s->tab, &s->v, &s->m);
    else if (ifs_build(&s->m, &s->v, msg, sizeof msg) == 0)
        s->dirty = 0;
    ifs_slave_refresh(s);
    return 1;
}

void ifs_slave_fresh_gam(IfsSlave *s)
{
    if (s->tab && s->tab->state == 1) {
        ifs_mu_table_gam(s->tab, &s->m);
    } else {           /* (never: the table is dropped with the matrices) an exact build */
        s->m.gq_seg = IFS_GQ_NONE;
        s->dirty = 1;
        s->fast_h = NAN;
    }
}

/* --- reals --- */

static int real_ok(const IfsRealVar *var, double x)
{
    return isfinite(x) && x >= var->lower && x <= var->upper &&
           !(var->lower_open && x == var->lower);
}

/* The inputs held beside the state where the step reads them (IfsModel.x), each
 * block of four written whole: a load that needs more than one store waits for the
 * stores to reach the cache (written value by value, the simulator loop's SetReal +
 * DoStep + GetReal took half as long again).  The inputs are read back one by one
 * from the slave's (just stored: each load from one store).  The step's inputs'
 * part (IfsModel.g) is then stale, and the look-ahead with it (even for inputs set
 * again to the values held: a comparison cost the frame 11 instructions, and
 * 1.0 ns with twelve states, bench/fmu_states.md). */
static IFS_HOT void hold_blocks(IfsSlave *s)
{
    /* (volatile: one load per value; two values in one load would need two stores) */
    const volatile double *in = ifs_slave_inputs(s);
    double *z = s->m.x;
    int b;
    /* g dropped (ifs_slave_drop_g) but gam, if stale, brought by the next step, the
     * general one (slave_step): a call here would give the input frame a stack
     * frame */
    if (s->m.gq_seg != IFS_GQ_NONE) {
        if (s->m.gq_seg > 0.0) {    /* gam stale: still, without gq */
            s->fast_h = NAN;
            s->m.gq_seg = IFS_GQ_STALE;
        } else {
            s->m.gq_seg = IFS_GQ_NONE;
        }
    }
    s->m.g_ok = 0;
    IFS_UNROLL
    for (b = IFS_NX / 4; b < IFS_ZB; b++) {
#if defined(__GNUC__) && !defined(IFS_SCALAR_STEP)
        double lane[4];
        int l;
        IFS_UNROLL
        for (l = 0; l < 4; l++) {
            const int k = 4 * b + l;
            lane[l] = k < IFS_NX ? z[k] : k < IFS_NA ? in[k - IFS_NX] : 0.0;
        }
        *(ifs_v4 *)(z + 4 * b) = (ifs_v4){lane[0], lane[1], lane[2], lane[3]};
#else
        int l;
        for (l = 0; l < 4; l++)
            if (4 * b + l >= IFS_NX && 4 * b + l < IFS_NA) z[4 * b + l] = in[4 * b + l - IFS_NX];
#endif
    }
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

/* The simulator loop's frame: the flap and inflow outputs only (1; else 0, the
 * others left to the general loop), without a stack frame; the outputs of the state
 * now (without a delay line, from the state at once: ifs_slave_update_outputs's
 * first part). */
static int get_outputs(IfsSlave *s, const unsigned int vr[], size_t n, double value[])
{
    size_t i;
    if (s->y_stale) {
        if (s->delay.active) {
            ifs_slave_update_outputs(s);
        } else {
            double y[IFS_NX];
            ifs_outputs(&s->m, y);
            memcpy(&s->v.beta0, y, 6 * sizeof(double));
            s->y_stale = 0;
        }
    }
    for (i = 0; i < n; i++) {
        if (vr[i] - IFS_VR_beta0 >= 6u) return 0;
        value[i] = (&s->v.beta0)[vr[i] - IFS_VR_beta0];
    }
    return 1;
}

int ifs_slave_get_reals(IfsSlave *s, const IfsLog *lg, const char *fn,
                        const unsigned int vr[], size_t n, double value[])
{
    size_t i;
    if (n > 0 && (!vr || !value)) return ifs_log(lg, IFS_ERROR, "%s: null array", fn);
    if (get_outputs(s, vr, n, value)) return IFS_OK;
    if (s->y_stale) ifs_slave_update_outputs(s);   /* the outputs of the state now */
    for (i = 0; i < n; i++) {
        if (vr[i] - IFS_VR_beta0 < 6u) {        /* flap and inflow */
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

/* The simulator loop's frame: inputs only, each within its declared range (NaN
 * fails the test), which need no rebuild: stored at once (1; else 0, nothing done).
 * The general checks (set_reals) cost half again as much per value (bench/fmu.md);
 * apart from them, this needs no stack frame (about 20 instructions of the frame).
 * mu as well, within the table's range with no other parameter pending: a flight
 * condition changing every step (stored; the step applies it). */
static int set_inputs(IfsSlave *s, const unsigned int vr[], size_t n, const double value[])
{
    size_t i;
    for (i = 0; i < n; i++)
        if (vr[i] < IFS_NU ? !(fabs(value[i]) <= IFS_INPUT_LIMIT)
                           : (vr[i] != IFS_VR_mu || s->params_changed ||
                              !(value[i] >= IFS_MU_LO && value[i] <= IFS_MU_HI) ||
                              !real_ok(&ifs_real_vars[IFS_VR_mu], value[i])))
            break;
    if (i == n) {
        double *in = (double *)ifs_slave_inputs(s);
        int inputs = 0;
        for (i = 0; i < n; i++) {
            if (vr[i] < IFS_NU) {
                in[vr[i]] = value[i];
                inputs = 1;
            } else {
                if (s->v.mu != value[i]) {
                    s->dirty = 1;
                    s->fast_h = NAN;
                }
                s->v.mu = value[i];
            }
        }
        if (inputs) hold_blocks(s);
        return 1;
    }
    return 0;
}

static IFS_NOINLINE int set_reals(IfsSlave *s, const IfsLog *lg, const char *fn,
                                  const unsigned int vr[], size_t n, const double value[])
{
    const int fixed_ok = s->phase == IFS_PH_INSTANTIATED || s->phase == IFS_PH_INIT;
    IfsVariables before;
    int parameters = 0;
    size_t i;
    /* check everything first: a refused call changes nothing */
    for (i = 0; i < n; i++) {
        const IfsRealVar *var = &ifs_real_vars[vr[i] < IFS_N_REALS ? vr[i] : 0];
        if (vr[i] >= IFS_N_REALS || var->kind == IFS_OUTPUT || var->kind == IFS_LOCAL ||
            (var->kind == IFS_FIXED && !fixed_ok) || !real_ok(var, value[i]))
            return refuse_real(s, lg, fn, vr[i], value[i]);
        if (vr[i] == IFS_VR_mu && s->v.inflow_speed == 0 && value[i] < IFS_MU_LO)
            return ifs_log(lg, IFS_ERROR, "mu = %g is outside the allowed range " IFS_MU_RANGE
                           " with inflow_speed 0: " IFS_HOVER_HINT, value[i]);
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
    ifs_slave_hold_inputs(s);
    ifs_slave_refresh(s);
    if (s->phase == IFS_PH_STEP && s->params_changed) {
        if (rebuild(s, lg) != IFS_OK) {   /* the model was left as it was */
            if (parameters) s->v = before;
            ifs_slave_hold_inputs(s);
            return IFS_ERROR;
        }
    }
    return IFS_OK;
}

int ifs_slave_set_reals(IfsSlave *s, const IfsLog *lg, const char *fn,
                        const unsigned int vr[], size_t n, const double value[])
{
    if (n > 0 && (!vr || !value)) return ifs_log(lg, IFS_ERROR, "%s: null array", fn);
    if (ifs_slave_set_mu(s, vr, n, value) || set_inputs(s, vr, n, value)) return IFS_OK;
    return set_reals(s, lg, fn, vr, n, value);
}

/* --- integers --- */

static const IfsIntegerVar *integer_var(unsigned int vr)
{
    int k;
    for (k = 0; k < IFS_N_INTEGERS; k++)
        if (ifs_integer_vars[k].vr == vr) return &ifs_integer_vars[k];
    return NULL;
}

/* The Integer of value reference vr, or NULL with the error logged (fn's) */
static const IfsIntegerVar *integer_or_log(const IfsLog *lg, const char *fn, unsigned int vr)
{
    const IfsIntegerVar *var = integer_var(vr);
    if (!var)
        ifs_log(lg, IFS_ERROR, "%s: %u is not the value reference of an Integer", fn, vr);
    return var;
}

int ifs_slave_get_ints(const IfsSlave *s, const IfsLog *lg, const char *fn,
                       const unsigned int vr[], size_t n, int value[])
{
    size_t i;
    if (n > 0 && (!vr || !value)) return ifs_log(lg, IFS_ERROR, "%s: null array", fn);
    for (i = 0; i < n; i++) {
        const IfsIntegerVar *var = integer_or_log(lg, fn, vr[i]);
        if (!var) return IFS_ERROR;
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
        const IfsIntegerVar *var = integer_or_log(lg, fn, vr[i]);
        if (!var) return IFS_ERROR;
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
    ifs_slave_refresh(s);
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

/* x = [phi gam] [x0; u] (pg as IfsModel.pg) */
static void ring_step(const double *pg, const double x0[IFS_NX], const double u[IFS_NU],
                      double x[IFS_NX])
{
    double z[IFS_RL] = {0.0};
    memcpy(z, x0, IFS_NX * sizeof(double));
    memcpy(z + IFS_NX, u, IFS_NU * sizeof(double));
    ifs_step(pg, z);
    memcpy(x, z, IFS_NX * sizeof(double));
}

/* state at step j from the ring: x_j = phi x_(j-1) + gam u_(j-1), or the start state */
static void ring_state(const IfsSlave *s, long long j, double x[IFS_NX])
{
    const IfsDelay *d = &s->delay;
    const int slot = (int)((j - 1) % IFS_DELAY_DEPTH);
    if (j <= 0 || d->hk[slot] != j - 1) {
        memcpy(x, d->x0, sizeof d->x0);
        return;
    }
    ring_step(s->m.pg, d->hx[slot], d->hu[slot], x);
}

void ifs_slave_delayed_state(const IfsSlave *s, int i, double x[IFS_NX])
{
    const IfsDelay *d = &s->delay;
    const long long k = d->k;
    if (d->f[i] == 0.0) {
        if (d->mm[i] == 0) memcpy(x, s->m.x, IFS_NX * sizeof(double));
        else ring_state(s, k - d->mm[i], x);
    } else {
        const long long j = k - d->mm[i] - 1;
        const int slot = (int)(j % IFS_DELAY_DEPTH);
        if (j < 0 || d->hk[slot] != j) {
            memcpy(x, d->x0, sizeof d->x0);
            return;
        }
        ring_step(d->pg_frac[i], d->hx[slot], d->hu[slot], x);
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
        memcpy(d->hx[slot], s->m.x, sizeof d->hx[slot]);
        memcpy(d->hu[slot], u, sizeof d->hu[slot]);
        d->hk[slot] = d->k;
        ifs_step(s->m.pg, s->m.x);    /* the inputs u beside the state */
        d->k++;
    }
}

/* --- the fast step's condition --- */

/* a step of h_comm from step n ends within the stop time: the general step's test */
static int ends_in_time(const IfsSlave *s, long long n)
{
    return (s->t_base + (double)n * s->h_comm) + s->h_comm <= s->t_stop;
}

/* The mu a set of mu alone takes from the table at once (IfsSlave.mu_lo, mu_hi):
 * mu_range where rebuild_model would take it from the table with nothing else to
 * do (a schedule's parameters and bias follow mu there: not here), else none */
static inline void mu_window(IfsSlave *s)
{
    const int table = !(IFS_N_SCHEDULED || IFS_SCHEDULED_BIAS) && s->phase == IFS_PH_STEP &&
                      !s->dirty && !s->delay.active && !s->params_changed && s->tab &&
                      s->tab->state == 1;
    s->mu_lo = table ? s->mu_range[0] : INFINITY;
    s->mu_hi = table ? s->mu_range[1] : -INFINITY;
}

/* ifs_slave_refresh but for the mu window: after a step, which changes none of its
 * terms (a rebuild or fresh_ab in it refreshed all) */
static void refresh_time(IfsSlave *s)
{
    s->m.g_ok = 0;                 /* [phi gam] or the inputs may have changed */
    s->now = s->t_base + (double)s->n_comm * s->h_comm;
    s->fast_h = s->phase == IFS_PH_STEP && !s->dirty && !s->delay.active &&
                s->h_comm == s->m.dt && s->h_comm > 0.0 ? s->h_comm : NAN;
    s->n_stop = LLONG_MAX;
    if (s->fast_h == s->fast_h && isfinite(s->t_stop)) {
        /* the first n that does not end in time (t_base + n h grows with n) */
        const double f = floor((s->t_stop - s->t_base) / s->h_comm);
        long long n = f > 0.0 ? (f < 4e18 ? (long long)f : (long long)4e18) : 0;
        while (n > 0 && !ends_in_time(s, n - 1)) n--;
        while (n < LLONG_MAX && ends_in_time(s, n)) n++;
        s->n_stop = n;
    }
    /* g dropped, so gam at once if stale (last: a call with nothing after it; gq,
     * kept with the inputs, is dropped where they change, ifs_slave_drop_g) */
    if (s->m.gq_seg > 0.0) ifs_slave_fresh_gam(s);
}

void ifs_slave_refresh(IfsSlave *s)
{
    mu_window(s);
    refresh_time(s);
}

/* --- outputs --- */

void ifs_slave_update_outputs(IfsSlave *s)
{
    double y[IFS_NX];
    if (s->delay.active) {         /* the recorded flap, from the delayed states */
        double xd[IFS_N_FLAP][IFS_NX];
        int i;
        for (i = 0; i < IFS_N_FLAP; i++) {   /* once per delay (time-delay: one for all) */
            if (i > 0 && s->delay.d[i] == s->delay.d[i - 1])
                memcpy(xd[i], xd[i - 1], sizeof xd[i]);
            else
                ifs_slave_delayed_state(s, i, xd[i]);
        }
#define IFS_X_DELAYED(i) ((i) < IFS_N_FLAP ? xd[(i) < IFS_N_FLAP ? (i) : 0] : s->m.x)
        IFS_OUTPUT_MAP(y, IFS_X_DELAYED, s->m.cos_bias, s->m.sin_bias);   /* inflow_vars.h */
#undef IFS_X_DELAYED
    } else {
        ifs_outputs(&s->m, y);
    }
    IFS_STORE_OUTPUTS(&s->v, y);
    s->y_stale = 0;
}

/* --- stepping --- */

static int slave_step(IfsSlave *s, const IfsLog *lg, const char *fn, double t, double h)
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
    if (s->m.gq_seg > 0.0) ifs_slave_fresh_gam(s);    /* the steps read gam */
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
        if (ifs_advance(&s->m, h) != 0)
            return ifs_log(lg, IFS_ERROR, "%s: the discretisation of step %g s failed", fn,
                           h);
    }
    if (h != s->h_comm) {           /* a new communication step: restart the counter */
        s->t_base = now;
        s->h_comm = h;
        s->n_comm = 0;
    }
    s->n_comm++;
    s->y_stale = 1;
    return status;
}

IFS_COLD int ifs_slave_step(IfsSlave *s, const IfsLog *lg, const char *fn, double t,
                            double h)
{
    const int status = slave_step(s, lg, fn, t, h);
    refresh_time(s);
    return status;
}

/* On time for a step of h at t from now, within the stop time (t == now first: a
 * loop's usual t is the FMU's time to the bit) */
#define ON_TIME(s, t, h)                                                               \
    (((t) == (s)->now || fabs((t) - (s)->now) <= 1e-9 * (1.0 + fabs((s)->now))) &&     \
     (s)->now + (h) <= (s)->t_stop)

/* t within 2^22 units in the last place of now (the same sign, |t - now| <= 2^-30
 * |now|, about 9.3e-10 |now|: inside the general step's tolerance); a loop summing
 * its steps, t += h, stays within it for millions of steps */
static inline int near_now(double t, double now)
{
    uint64_t a, b;
    memcpy(&a, &t, sizeof a);
    memcpy(&b, &now, sizeof b);
    return a - b + (UINT64_C(1) << 22) <= (UINT64_C(2) << 22);
}

/* The simulator loop's usual step: h the last one and the internal step with nothing
 * to rebuild (fast_h), t the FMU's time (near_now; else the general step, with the
 * tolerance), ending within the stop time (n_stop) */
#define FAST_OK(s, t, h) ((h) == (s)->fast_h && near_now(t, (s)->now) && (s)->n_comm < (s)->n_stop)

/* After the step: the counter, the time; the outputs are those of the old state */
#define STEPPED(s)                                                                     \
    do {                                                                               \
        (s)->n_comm++;                                                                 \
        (s)->now = (s)->t_base + (double)(s)->n_comm * (s)->h_comm;                    \
        (s)->y_stale = 1;                                                              \
    } while (0)

/* The step that starts the look-ahead (the model's step returned 1: g and [phi gam]
 * held through the last step; ifs_ahead_start), out of line: once per change of
 * the inputs or the matrices held */
#if IFS_COLUMN_STEP
#define AHEAD_START(m) ifs_ahead_start(m)
#else
#define AHEAD_START(m) ((void)(m))
#endif
static IFS_NOINLINE int ahead_start(IfsSlave *s)
{
    AHEAD_START(&s->m);
    STEPPED(s);
    return IFS_OK;
}

/* DoStep (ifs_do_step) with the step STEP (ifs_step_held on the model, or its
 * four-wide twin: 1 where the look-ahead starts, ahead_start) and REST for the
 * other steps */
#define DO_STEP(instance, t, h, STEP, REST)                                            \
    do {                                                                               \
        IfsInstance *c_ = (IfsInstance *)(instance);                                   \
        IfsSlave *s_;                                                                  \
        if (!c_) return IFS_ERROR;                                                     \
        s_ = &c_->s;                                                                   \
        if (FAST_OK(s_, t, h)) {                                                       \
            if (STEP) return ahead_start(s_);                                          \
            STEPPED(s_);                                                               \
            return IFS_OK;                                                             \
        }                                                                              \
        return REST(c_, t, h);                                                         \
    } while (0)

/* The steps other than the fast one, out of line (a call in DoStep's fast path gave
 * it a stack frame: 25 instructions of the fixed-mu step): after a change of mu
 * alone the fast step with [phi gam] from the mu table (as rebuild takes it) if the
 * table is valid for the parameters and holds mu (the caller of a fast step
 * checked that no delay is active), else the general step. */
#if IFS_N_SCHEDULED || IFS_SCHEDULED_BIAS
#define REST_BODY(c, t, h, STEP) return ifs_slave_step(&(c)->s, &(c)->log, (c)->do_step, t, h)
#else
#define REST_BODY(c, t, h, STEP)                                                       \
    do {                                                                               \
        IfsSlave *s_ = &(c)->s;                                                        \
        if (s_->dirty && !s_->params_changed && s_->tab && s_->tab->state == 1 &&      \
            s_->phase == IFS_PH_STEP && !s_->delay.active && (h) == s_->h_comm &&      \
            (h) == s_->m.dt && s_->v.mu >= IFS_MU_LO && s_->v.mu <= IFS_MU_HI &&       \
            ON_TIME(s_, t, h)) {                                                       \
            ifs_mu_table_apply(s_->tab, &s_->v, &s_->m);                               \
            s_->dirty = 0;                                                             \
            mu_window(s_);                                                             \
            if (STEP) AHEAD_START(&s_->m);                                             \
            STEPPED(s_);                                                               \
            s_->fast_h = s_->h_comm;                                                   \
            return IFS_OK;                                                             \
        }                                                                              \
        return ifs_slave_step(s_, &(c)->log, (c)->do_step, t, h);                      \
    } while (0)
#endif

static IFS_NOINLINE int rest_base(IfsInstance *c, double t, double h)
{
    REST_BODY(c, t, h, ifs_step_held(&s_->m));
}

static int do_step_base(void *instance, double t, double h)
{
    DO_STEP(instance, t, h, ifs_step_held(&s_->m), rest_base);
}

#ifdef IFS_WIDE_STEP
/* Two functions, one chosen when the library is loaded (GNU ifunc, as target_clones
 * does), so that the AVX2 one has the four-wide step inline and no baseline step
 * beside it (a clone of one function kept both and chose at each step: a call and
 * a 32-byte aligned stack frame, about 1.2 ns of the nine-state step) */
static __attribute__((target("avx2"), noinline)) int rest_wide(IfsInstance *c, double t,
                                                                double h)
{
    REST_BODY(c, t, h, ifs_step_wide(&s_->m));
}

static __attribute__((target("avx2"))) int do_step_wide(void *instance, double t, double h)
{
    DO_STEP(instance, t, h, ifs_step_wide(&s_->m), rest_wide);
}

IfsDoStep *ifs_do_step_choose(void)
{
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") ? do_step_wide : do_step_base;
}

/* (the resolver's name as a string after inflow_names.h's prefix) */
#define STR_(n) #n
#define STR(n) STR_(n)
int ifs_do_step(void *instance, double t, double h)
    __attribute__((ifunc(STR(ifs_do_step_choose))));
#else
int ifs_do_step(void *instance, double t, double h)
{
    return do_step_base(instance, t, h);
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

int ifs_state_get(IfsSlave *s, const IfsLog *lg, const char *fn, void **state,
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
    if (s->m.gq_seg > 0.0) ifs_slave_fresh_gam(s);   /* a state: all [phi gam] */
    st->s = *s;
    *state = st;
    return IFS_OK;
}

int ifs_state_set(IfsSlave *s, const IfsLog *lg, const char *fn, const void *state)
{
    if (!is_state(state, sizeof(IfsSavedState)))
        return ifs_log(lg, IFS_ERROR, "%s: not a state of this FMU", fn);
    IfsMuTable *tab = s->tab;      /* this instance's table, not the saved pointer */
    int g_ok;
    *s = ((const IfsSavedState *)state)->s;
    s->tab = tab;
    if (tab) tab->state = 0;       /* the saved parameters may differ */
    s->params_changed = 1;         /* the next mu change rebuilds exactly */
    g_ok = s->m.g_ok;              /* g, [phi gam] and the inputs are the state's */
    ifs_slave_refresh(s);
    s->m.g_ok = g_ok;
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
