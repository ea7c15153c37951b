/*
 * FMI 2.0 co-simulation interface of the inflowsim rotor flap / inflow model.
 *
 * The equations live in inflow_model.c; the variables (names, value references,
 * start values, ranges) in the generated table inflow_vars.[ch].  No global
 * mutable state: every instance owns its data.  Inputs and outputs are
 * perturbations about trim (SI); mu is the total trim advance ratio.
 *
 * Convention (the same as inflowsim.Simulator.step): fmi2DoStep holds the inputs
 * set before it over [t, t + h) and leaves the outputs at t + h.
 */
#include <math.h>
#include <stddef.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "fmi2Functions.h"
#include "inflow_model.h"

#if defined(__GNUC__)
#define IFS_EXPORT __attribute__((visibility("default")))
#else
#define IFS_EXPORT
#endif

/* fmi2DoStep is compiled twice where the loader can pick one at load time (GNU
 * ifunc, glibc): for AVX2 and for the baseline.  The step does the same
 * operations in the same order in both, so both give the same numbers (a test
 * checks this bit for bit).  -DIFS_NO_CLONES turns it off. */
#if defined(__has_attribute)
#if __has_attribute(target_clones) && defined(__x86_64__) && defined(__GLIBC__) && \
    !defined(IFS_NO_CLONES)
#define IFS_HOT __attribute__((target_clones("avx2", "default")))
#endif
#endif
#ifndef IFS_HOT
#define IFS_HOT
#endif

#if defined(__GNUC__)
#define IFS_COLD __attribute__((noinline, cold))
#else
#define IFS_COLD
#endif

#define MSG_LEN 512

typedef enum { PH_INSTANTIATED, PH_INIT, PH_STEP, PH_TERMINATED, PH_ERROR } Phase;

/* Everything an FMU state must hold: plain data, copied with memcpy. */
typedef struct {
    IfsVariables v;
    IfsModel m;
    Phase phase;
    int dirty;                 /* parameters or mu changed since the last build */
    /* time = t_base + n_comm h_comm: a step counter, never a running sum */
    double t_start, t_base, h_comm;
    long long n_comm;
    int warned_time;           /* the time-mismatch warning is given once */
} Data;

typedef struct {
    Data d;
    fmi2CallbackFunctions cb;
    fmi2Boolean logging_on;
    char name[128];
} Instance;

#define STATE_MAGIC 0x49465331u   /* "IFS1" */
typedef struct {
    unsigned int magic;
    unsigned int size;
    Data d;
} SavedState;

/* --- logging --- */

static void logf_(Instance *c, fmi2Status st, const char *cat, const char *fmt, ...)
{
    char buf[MSG_LEN];
    va_list ap;
    if (!c || !c->cb.logger) return;
    if (st == fmi2OK && !c->logging_on) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    c->cb.logger(c->cb.componentEnvironment, c->name, st, cat, "%s", buf);
}

#define ERR(c, ...) (logf_((c), fmi2Error, "logStatusError", __VA_ARGS__), fmi2Error)

static double time_now(const Data *d)
{
    return d->t_base + (double)d->n_comm * d->h_comm;
}

static void update_outputs(Data *d)
{
    double y[IFS_NX];
    ifs_outputs(&d->m, y);
    d->v.beta0 = y[0];
    d->v.beta1c = y[1];
    d->v.beta1s = y[2];
    d->v.lambda0 = y[3];
    d->v.lambda1c = y[4];
    d->v.lambda1s = y[5];
}

/* the inputs theta0 .. muy in order: the generated struct keeps them contiguous */
typedef char ifs_inputs_are_contiguous[offsetof(IfsVariables, muy) -
                                       offsetof(IfsVariables, theta0) ==
                                       (IFS_NU - 1) * sizeof(double) ? 1 : -1];

static const double *inputs(const Data *d)
{
    return (const double *)((const char *)&d->v + offsetof(IfsVariables, theta0));
}

static void set_start(Data *d)
{
    int i;
    memset(d, 0, sizeof *d);
    for (i = 0; i < IFS_N_REALS; i++)
        *(double *)((char *)&d->v + ifs_real_vars[i].offset) = ifs_real_vars[i].start;
    for (i = 0; i < IFS_N_INTEGERS; i++)
        *(int *)((char *)&d->v + ifs_integer_vars[i].offset) = ifs_integer_vars[i].start;
    d->phase = PH_INSTANTIATED;
    d->dirty = 1;
    d->m.h_last = -1.0;
}

static fmi2Status rebuild(Instance *c)
{
    char msg[MSG_LEN];
    if (ifs_build(&c->d.m, &c->d.v, msg, sizeof msg) != 0)
        return ERR(c, "%s", msg);
    c->d.dirty = 0;
    return fmi2OK;
}

static int real_ok(const IfsRealVar *var, double x)
{
    return isfinite(x) && x >= var->lower && x <= var->upper &&
           !(var->lower_open && x == var->lower);
}

/* Why fmi2SetReal refuses value x for value reference vr: logged, fmi2Error. */
static IFS_COLD fmi2Status refuse_real(Instance *c, fmi2ValueReference vr, double x)
{
    const IfsRealVar *var;
    if (vr >= IFS_N_REALS)
        return ERR(c, "fmi2SetReal: %u is not the value reference of a Real", vr);
    var = &ifs_real_vars[vr];
    if (var->kind == IFS_OUTPUT) return ERR(c, "fmi2SetReal: %s is an output", var->name);
    if (var->kind == IFS_FIXED && c->d.phase != PH_INSTANTIATED && c->d.phase != PH_INIT)
        return ERR(c, "fmi2SetReal: %s is fixed after initialization", var->name);
    if (!isfinite(x))
        return ERR(c, "%s = %g refused: must be finite%s", var->name, x,
                   var->kind == IFS_INPUT ? " (state untouched)" : "");
    return ERR(c, "%s = %g is outside the allowed range %c%g, %g]", var->name, x,
               var->lower_open ? '(' : '[', var->lower, var->upper);
}

/* --- common functions --- */

IFS_EXPORT const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
IFS_EXPORT const char *fmi2GetVersion(void) { return fmi2Version; }

IFS_EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean on, size_t n,
                                          const fmi2String categories[])
{
    Instance *c = (Instance *)comp;
    (void)n;
    (void)categories;
    if (!c) return fmi2Error;
    c->logging_on = on;
    return fmi2OK;
}

IFS_EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                         fmi2String resources,
                                         const fmi2CallbackFunctions *cb,
                                         fmi2Boolean visible, fmi2Boolean logging_on)
{
    Instance *c;
    Instance tmp;
    (void)resources;
    (void)visible;
    if (!cb || !cb->allocateMemory || !cb->freeMemory) return NULL;
    memset(&tmp, 0, sizeof tmp);
    tmp.cb = *cb;
    snprintf(tmp.name, sizeof tmp.name, "%s", name ? name : "inflowsim");
    if (type != fmi2CoSimulation) {
        logf_(&tmp, fmi2Error, "logStatusError", "only co-simulation is provided");
        return NULL;
    }
    if (!guid || strcmp(guid, IFS_GUID) != 0) {
        logf_(&tmp, fmi2Error, "logStatusError", "GUID %s does not match this binary's %s",
              guid ? guid : "(null)", IFS_GUID);
        return NULL;
    }
    c = (Instance *)cb->allocateMemory(1, sizeof(Instance));
    if (!c) return NULL;
    memcpy(c, &tmp, sizeof tmp);
    c->logging_on = logging_on;
    set_start(&c->d);
    return c;
}

IFS_EXPORT void fmi2FreeInstance(fmi2Component comp)
{
    Instance *c = (Instance *)comp;
    if (c) c->cb.freeMemory(c);
}

IFS_EXPORT fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean tol_defined,
                                          fmi2Real tol, fmi2Real start,
                                          fmi2Boolean stop_defined, fmi2Real stop)
{
    Instance *c = (Instance *)comp;
    (void)tol_defined;
    (void)tol;
    (void)stop_defined;
    (void)stop;
    if (!c) return fmi2Error;
    if (c->d.phase != PH_INSTANTIATED)
        return ERR(c, "fmi2SetupExperiment: only allowed after instantiation or reset");
    if (!isfinite(start)) return ERR(c, "fmi2SetupExperiment: start time must be finite");
    c->d.t_start = c->d.t_base = start;
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component comp)
{
    Instance *c = (Instance *)comp;
    if (!c) return fmi2Error;
    if (c->d.phase != PH_INSTANTIATED)
        return ERR(c, "fmi2EnterInitializationMode: only allowed after instantiation");
    c->d.phase = PH_INIT;
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component comp)
{
    Instance *c = (Instance *)comp;
    fmi2Status st;
    if (!c) return fmi2Error;
    if (c->d.phase != PH_INIT)
        return ERR(c, "fmi2ExitInitializationMode: not in initialization mode");
    st = rebuild(c);
    if (st != fmi2OK) return st;
    update_outputs(&c->d);
    c->d.phase = PH_STEP;
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2Terminate(fmi2Component comp)
{
    Instance *c = (Instance *)comp;
    if (!c) return fmi2Error;
    c->d.phase = PH_TERMINATED;
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2Reset(fmi2Component comp)
{
    Instance *c = (Instance *)comp;
    if (!c) return fmi2Error;
    set_start(&c->d);
    return fmi2OK;
}

/* --- get / set --- */

IFS_EXPORT fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[],
                                  size_t nvr, fmi2Real value[])
{
    Instance *c = (Instance *)comp;
    size_t i;
    if (!c) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return ERR(c, "fmi2GetReal: null array");
    for (i = 0; i < nvr; i++) {
        if (vr[i] >= IFS_N_REALS)
            return ERR(c, "fmi2GetReal: %u is not the value reference of a Real", vr[i]);
        value[i] = *(const double *)((const char *)&c->d.v + ifs_real_vars[vr[i]].offset);
    }
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[],
                                  size_t nvr, const fmi2Real value[])
{
    Instance *c = (Instance *)comp;
    const int fixed_ok = c && (c->d.phase == PH_INSTANTIATED || c->d.phase == PH_INIT);
    size_t i;
    if (!c) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return ERR(c, "fmi2SetReal: null array");
    /* check everything first: a refused call changes nothing */
    for (i = 0; i < nvr; i++) {
        const IfsRealVar *var = &ifs_real_vars[vr[i] < IFS_N_REALS ? vr[i] : 0];
        if (vr[i] >= IFS_N_REALS || var->kind == IFS_OUTPUT ||
            (var->kind == IFS_FIXED && !fixed_ok) || !real_ok(var, value[i]))
            return refuse_real(c, vr[i], value[i]);
    }
    for (i = 0; i < nvr; i++) {
        const IfsRealVar *var = &ifs_real_vars[vr[i]];
        double *slot = (double *)((char *)&c->d.v + var->offset);
        /* inputs other than mu enter the step as they are; the rest rebuild */
        if ((var->kind != IFS_INPUT || vr[i] == IFS_VR_mu) && *slot != value[i])
            c->d.dirty = 1;
        *slot = value[i];
    }
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2GetInteger(fmi2Component comp, const fmi2ValueReference vr[],
                                     size_t nvr, fmi2Integer value[])
{
    Instance *c = (Instance *)comp;
    size_t i;
    int k;
    if (!c) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        for (k = 0; k < IFS_N_INTEGERS && ifs_integer_vars[k].vr != vr[i]; k++) {}
        if (k == IFS_N_INTEGERS)
            return ERR(c, "fmi2GetInteger: %u is not the value reference of an Integer",
                       vr[i]);
        value[i] = *(const int *)((const char *)&c->d.v + ifs_integer_vars[k].offset);
    }
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2SetInteger(fmi2Component comp, const fmi2ValueReference vr[],
                                     size_t nvr, const fmi2Integer value[])
{
    Instance *c = (Instance *)comp;
    size_t i;
    int k;
    if (!c) return fmi2Error;
    for (i = 0; i < nvr; i++) {
        const IfsIntegerVar *var;
        for (k = 0; k < IFS_N_INTEGERS && ifs_integer_vars[k].vr != vr[i]; k++) {}
        if (k == IFS_N_INTEGERS)
            return ERR(c, "fmi2SetInteger: %u is not the value reference of an Integer",
                       vr[i]);
        var = &ifs_integer_vars[k];
        if (var->kind == IFS_FIXED && c->d.phase != PH_INSTANTIATED && c->d.phase != PH_INIT)
            return ERR(c, "fmi2SetInteger: %s is fixed after initialization", var->name);
        if (value[i] < var->lower || value[i] > var->upper)
            return ERR(c, "%s = %d is outside the allowed range [%d, %d]", var->name,
                       value[i], var->lower, var->upper);
    }
    for (i = 0; i < nvr; i++) {
        for (k = 0; ifs_integer_vars[k].vr != vr[i]; k++) {}
        *(int *)((char *)&c->d.v + ifs_integer_vars[k].offset) = value[i];
        c->d.dirty = 1;
    }
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2GetBoolean(fmi2Component comp, const fmi2ValueReference vr[],
                                     size_t nvr, fmi2Boolean value[])
{
    (void)value;
    if (nvr == 0) return fmi2OK;
    return ERR((Instance *)comp, "fmi2GetBoolean: %u: this FMU has no Boolean variables",
               vr ? vr[0] : 0u);
}

IFS_EXPORT fmi2Status fmi2SetBoolean(fmi2Component comp, const fmi2ValueReference vr[],
                                     size_t nvr, const fmi2Boolean value[])
{
    (void)value;
    if (nvr == 0) return fmi2OK;
    return ERR((Instance *)comp, "fmi2SetBoolean: %u: this FMU has no Boolean variables",
               vr ? vr[0] : 0u);
}

IFS_EXPORT fmi2Status fmi2GetString(fmi2Component comp, const fmi2ValueReference vr[],
                                    size_t nvr, fmi2String value[])
{
    (void)value;
    if (nvr == 0) return fmi2OK;
    return ERR((Instance *)comp, "fmi2GetString: %u: this FMU has no String variables",
               vr ? vr[0] : 0u);
}

IFS_EXPORT fmi2Status fmi2SetString(fmi2Component comp, const fmi2ValueReference vr[],
                                    size_t nvr, const fmi2String value[])
{
    (void)value;
    if (nvr == 0) return fmi2OK;
    return ERR((Instance *)comp, "fmi2SetString: %u: this FMU has no String variables",
               vr ? vr[0] : 0u);
}

/* --- FMU state --- */

IFS_EXPORT fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *state)
{
    Instance *c = (Instance *)comp;
    SavedState *s;
    if (!c || !state) return fmi2Error;
    s = (SavedState *)*state;
    if (!s) {
        s = (SavedState *)c->cb.allocateMemory(1, sizeof(SavedState));
        if (!s) return ERR(c, "fmi2GetFMUstate: out of memory");
    }
    s->magic = STATE_MAGIC;
    s->size = (unsigned int)sizeof(SavedState);
    s->d = c->d;
    *state = s;
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state)
{
    Instance *c = (Instance *)comp;
    const SavedState *s = (const SavedState *)state;
    if (!c) return fmi2Error;
    if (!s || s->magic != STATE_MAGIC || s->size != sizeof(SavedState))
        return ERR(c, "fmi2SetFMUstate: not a state of this FMU");
    c->d = s->d;
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state)
{
    Instance *c = (Instance *)comp;
    if (!c || !state) return fmi2Error;
    if (*state) c->cb.freeMemory(*state);
    *state = NULL;
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state,
                                                 size_t *size)
{
    (void)state;
    if (!comp || !size) return fmi2Error;
    *size = sizeof(SavedState);
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state,
                                            fmi2Byte bytes[], size_t size)
{
    Instance *c = (Instance *)comp;
    if (!c) return fmi2Error;
    if (!state || !bytes || size < sizeof(SavedState))
        return ERR(c, "fmi2SerializeFMUstate: need %u bytes", (unsigned)sizeof(SavedState));
    memcpy(bytes, state, sizeof(SavedState));
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte bytes[],
                                              size_t size, fmi2FMUstate *state)
{
    Instance *c = (Instance *)comp;
    SavedState s;
    if (!c || !state) return fmi2Error;
    if (!bytes || size != sizeof(SavedState))
        return ERR(c, "fmi2DeSerializeFMUstate: %u bytes is not a state of this FMU",
                   (unsigned)size);
    memcpy(&s, bytes, sizeof s);
    if (s.magic != STATE_MAGIC || s.size != sizeof(SavedState))
        return ERR(c, "fmi2DeSerializeFMUstate: not a state of this FMU");
    if (!*state) {
        *state = c->cb.allocateMemory(1, sizeof(SavedState));
        if (!*state) return ERR(c, "fmi2DeSerializeFMUstate: out of memory");
    }
    memcpy(*state, &s, sizeof s);
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2GetDirectionalDerivative(
    fmi2Component comp, const fmi2ValueReference unknown[], size_t nu,
    const fmi2ValueReference known[], size_t nk, const fmi2Real dknown[], fmi2Real dunknown[])
{
    (void)unknown; (void)nu; (void)known; (void)nk; (void)dknown; (void)dunknown;
    return ERR((Instance *)comp, "fmi2GetDirectionalDerivative: not provided "
               "(providesDirectionalDerivative is false)");
}

/* --- co-simulation --- */

IFS_EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component comp,
                                                  const fmi2ValueReference vr[], size_t nvr,
                                                  const fmi2Integer order[],
                                                  const fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    return ERR((Instance *)comp, "fmi2SetRealInputDerivatives: inputs are held over a "
               "step (canInterpolateInputs is false)");
}

IFS_EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component comp,
                                                   const fmi2ValueReference vr[], size_t nvr,
                                                   const fmi2Integer order[],
                                                   fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    return ERR((Instance *)comp, "fmi2GetRealOutputDerivatives: not provided "
               "(maxOutputDerivativeOrder is 0)");
}

/* Any step but the loop's usual one: checks, rebuild, substeps and remainder. */
static IFS_COLD fmi2Status do_step(Instance *c, double t, double h)
{
    Data *d = &c->d;
    double now;
    if (d->phase != PH_STEP)
        return ERR(c, "fmi2DoStep: not in step mode (call fmi2ExitInitializationMode)");
    if (!(h >= 0.0) || !isfinite(h))
        return ERR(c, "fmi2DoStep: communication step %g must be finite and >= 0", h);
    now = time_now(d);
    if (fabs(t - now) > 1e-9 * (1.0 + fabs(now)) && !d->warned_time++)
        logf_(c, fmi2Warning, "logStatusWarning", "fmi2DoStep: communication point %.17g "
              "differs from the FMU's time %.17g", t, now);
    if (d->dirty && rebuild(c) != fmi2OK) return fmi2Error;
    if (ifs_advance(&d->m, inputs(d), h) != 0)
        return ERR(c, "fmi2DoStep: the discretisation of step %g s failed", h);
    if (h != d->h_comm) {           /* a new communication step: restart the counter */
        d->t_base = now;
        d->h_comm = h;
        d->n_comm = 0;
    }
    d->n_comm++;
    update_outputs(d);
    return fmi2OK;
}

IFS_EXPORT IFS_HOT fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h,
                                         fmi2Boolean no_set_prior)
{
    Instance *c = (Instance *)comp;
    Data *d;
    (void)no_set_prior;
    if (!c) return fmi2Error;
    d = &c->d;
    /* the simulator loop: same step as before, one internal step, nothing to
     * rebuild, on time */
    if (d->phase == PH_STEP && !d->dirty && h == d->h_comm && h == d->m.dt) {
        const double now = time_now(d);
        if (fabs(t - now) <= 1e-9 * (1.0 + fabs(now))) {
            ifs_step(d->m.pg, d->m.x, inputs(d));
            d->n_comm++;
            update_outputs(d);
            return fmi2OK;
        }
    }
    return do_step(c, t, h);
}

IFS_EXPORT fmi2Status fmi2CancelStep(fmi2Component comp)
{
    return ERR((Instance *)comp, "fmi2CancelStep: fmi2DoStep is synchronous");
}

IFS_EXPORT fmi2Status fmi2GetStatus(fmi2Component comp, const fmi2StatusKind s,
                                    fmi2Status *value)
{
    (void)s;
    if (!comp || !value) return fmi2Error;
    *value = fmi2OK;
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind s,
                                        fmi2Real *value)
{
    Instance *c = (Instance *)comp;
    if (!c || !value) return fmi2Error;
    if (s != fmi2LastSuccessfulTime)
        return ERR(c, "fmi2GetRealStatus: only fmi2LastSuccessfulTime is provided");
    *value = time_now(&c->d);
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component comp, const fmi2StatusKind s,
                                           fmi2Integer *value)
{
    (void)s; (void)value;
    return ERR((Instance *)comp, "fmi2GetIntegerStatus: no integer status is provided");
}

IFS_EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component comp, const fmi2StatusKind s,
                                           fmi2Boolean *value)
{
    Instance *c = (Instance *)comp;
    if (!c || !value) return fmi2Error;
    if (s != fmi2Terminated)
        return ERR(c, "fmi2GetBooleanStatus: only fmi2Terminated is provided");
    *value = fmi2False;
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2GetStringStatus(fmi2Component comp, const fmi2StatusKind s,
                                          fmi2String *value)
{
    (void)s; (void)value;
    return ERR((Instance *)comp, "fmi2GetStringStatus: no string status is provided");
}
