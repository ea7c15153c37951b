/*
 * FMI 3.0 co-simulation interface of the inflowsim rotor flap / inflow model: a
 * thin layer over the FMI shim (inflow_fmi.h) and the slave in inflow_slave.[ch],
 * the same ones the FMI 2.0 layer uses, so both FMUs step identically.  Co-simulation only, no event mode, no
 * clocks; the real variables are Float64, the structure Int32, and "time" is the
 * independent variable (read-only).  No global mutable state.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "inflow_fmi.h"

typedef struct {
    IfsInstance i;             /* first, 64-byte aligned (see instantiate) */
    fmi3LogMessageCallback log_message;
    fmi3InstanceEnvironment env;
} Instance;

/* FMI 3.0 logMessage behind IfsLog; the instance name leads the message */
static void emit(void *env, int status, const char *category, const char *message)
{
    Instance *c = (Instance *)env;
    char buf[768];
    snprintf(buf, sizeof buf, "%s: %s", c->i.name, message);
    c->log_message(c->env, (fmi3Status)status, category, buf);
}

#define ERR(c, ...) ((fmi3Status)ifs_log(&(c)->i.log, IFS_ERROR, __VA_ARGS__))

static fmi3Status refuse(fmi3Instance inst, const char *what)
{
    return (fmi3Status)ifs_fmi_refuse(inst, what);
}

/* --- common functions --- */

IFS_EXPORT const char *fmi3GetVersion(void) { return fmi3Version; }

IFS_EXPORT fmi3Status fmi3SetDebugLogging(fmi3Instance inst, fmi3Boolean on, size_t n,
                                          const fmi3String categories[])
{
    (void)n;
    (void)categories;
    return (fmi3Status)ifs_fmi_set_debug_logging(inst, on);
}

/* the C library's allocator behind IfsCalloc */
static void *alloc(void *ctx, size_t n)
{
    (void)ctx;
    return calloc(1, n);
}

static void release(void *ctx, void *p)
{
    (void)ctx;
    free(p);
}

static Instance *instantiate(fmi3String name, fmi3String token, fmi3Boolean logging_on,
                             fmi3InstanceEnvironment env, fmi3LogMessageCallback log_message,
                             const char *refusal)
{
    Instance *c = (Instance *)ifs_instance_alloc(sizeof(Instance), alloc, release, NULL,
                                                 name, logging_on);
    if (!c) return NULL;
    c->log_message = log_message;
    c->env = env;
    c->i.log.emit = log_message ? emit : NULL;
    c->i.do_step = "fmi3DoStep";
    if (ifs_instance_start(&c->i, refusal, "instantiation token", token) != 0) return NULL;
    return c;
}

IFS_EXPORT fmi3Instance fmi3InstantiateModelExchange(
    fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
    fmi3Boolean logging_on, fmi3InstanceEnvironment env, fmi3LogMessageCallback log_message)
{
    (void)resources;
    (void)visible;
    return instantiate(name, token, logging_on, env, log_message,
                       "only co-simulation is provided");
}

IFS_EXPORT fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
    fmi3Boolean logging_on, fmi3Boolean event_mode_used, fmi3Boolean early_return_allowed,
    const fmi3ValueReference required[], size_t n_required, fmi3InstanceEnvironment env,
    fmi3LogMessageCallback log_message, fmi3IntermediateUpdateCallback intermediate_update)
{
    (void)resources;
    (void)visible;
    (void)early_return_allowed;        /* never returns early */
    (void)required;
    (void)n_required;
    (void)intermediate_update;         /* providesIntermediateUpdate is false */
    return instantiate(name, token, logging_on, env, log_message,
                       event_mode_used ? "event mode is not provided (hasEventMode is "
                                         "false): instantiate with eventModeUsed false"
                                       : NULL);
}

IFS_EXPORT fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
    fmi3Boolean logging_on, fmi3InstanceEnvironment env, fmi3LogMessageCallback log_message,
    fmi3ClockUpdateCallback clock_update, fmi3LockPreemptionCallback lock,
    fmi3UnlockPreemptionCallback unlock)
{
    (void)resources;
    (void)visible;
    (void)clock_update;
    (void)lock;
    (void)unlock;
    return instantiate(name, token, logging_on, env, log_message,
                       "only co-simulation is provided");
}

IFS_EXPORT void fmi3FreeInstance(fmi3Instance inst)
{
    ifs_fmi_free_instance(inst);
}

IFS_EXPORT fmi3Status fmi3EnterInitializationMode(fmi3Instance inst, fmi3Boolean tol_defined,
                                                  fmi3Float64 tol, fmi3Float64 start,
                                                  fmi3Boolean stop_defined, fmi3Float64 stop)
{
    const char *fn = "fmi3EnterInitializationMode";
    (void)tol_defined;
    (void)tol;
    if (ifs_fmi_setup(inst, fn, start, stop_defined != fmi3False, stop) != IFS_OK)
        return fmi3Error;
    return (fmi3Status)ifs_fmi_enter_init(inst, fn);
}

IFS_EXPORT fmi3Status fmi3ExitInitializationMode(fmi3Instance inst)
{
    return (fmi3Status)ifs_fmi_exit_init(inst, "fmi3ExitInitializationMode");
}

IFS_EXPORT fmi3Status fmi3EnterEventMode(fmi3Instance inst)
{
    return refuse(inst, "fmi3EnterEventMode: event mode is not provided");
}

IFS_EXPORT fmi3Status fmi3Terminate(fmi3Instance inst)
{
    return (fmi3Status)ifs_fmi_terminate(inst);
}

IFS_EXPORT fmi3Status fmi3Reset(fmi3Instance inst)
{
    return (fmi3Status)ifs_fmi_reset(inst);
}

/* --- get / set --- */

/* 1 if there are as many values as value references; 0 (an error, logged) if
 * not, or for a null instance */
static int counts_ok(fmi3Instance inst, const char *fn, size_t nvr, size_t nv)
{
    Instance *c = (Instance *)inst;
    if (!c) return 0;
    if (nv == nvr) return 1;
    ERR(c, "%s: %u values for %u value references (every variable is a scalar)", fn,
        (unsigned)nv, (unsigned)nvr);
    return 0;
}

IFS_EXPORT fmi3Status fmi3GetFloat64(fmi3Instance inst, const fmi3ValueReference vr[],
                                     size_t nvr, fmi3Float64 values[], size_t nv)
{
    Instance *c = (Instance *)inst;
    const char *fn = "fmi3GetFloat64";
    size_t i;
    if (!counts_ok(inst, fn, nvr, nv)) return fmi3Error;
    if (nvr > 0 && (!vr || !values)) return ERR(c, "%s: null array", fn);
    for (i = 0; i < nvr && vr[i] != IFS_VR_time; i++) {}
    if (i == nvr)
        return (fmi3Status)ifs_slave_get_reals(&c->i.s, &c->i.log, fn, vr, nvr, values);
    for (i = 0; i < nvr; i++) {       /* time among them: one at a time */
        if (vr[i] == IFS_VR_time) {
            values[i] = ifs_slave_time(&c->i.s);
        } else if (ifs_slave_get_reals(&c->i.s, &c->i.log, fn, vr + i, 1, values + i) != IFS_OK) {
            return fmi3Error;
        }
    }
    return fmi3OK;
}

IFS_EXPORT fmi3Status fmi3SetFloat64(fmi3Instance inst, const fmi3ValueReference vr[],
                                     size_t nvr, const fmi3Float64 values[], size_t nv)
{
    Instance *c = (Instance *)inst;
    const char *fn = "fmi3SetFloat64";
    size_t i;
    if (!counts_ok(inst, fn, nvr, nv)) return fmi3Error;
    if (ifs_slave_set_mu(&c->i.s, vr, nvr, values)) return fmi3OK;
    for (i = 0; vr && i < nvr; i++)
        if (vr[i] == IFS_VR_time)
            return ERR(c, "%s: time is the independent variable; fmi3DoStep advances it", fn);
    return (fmi3Status)ifs_slave_set_reals(&c->i.s, &c->i.log, fn, vr, nvr, values);
}

IFS_EXPORT fmi3Status fmi3GetInt32(fmi3Instance inst, const fmi3ValueReference vr[],
                                   size_t nvr, fmi3Int32 values[], size_t nv)
{
    if (!counts_ok(inst, "fmi3GetInt32", nvr, nv)) return fmi3Error;
    return (fmi3Status)ifs_fmi_get_ints(inst, "fmi3GetInt32", vr, nvr, values);
}

IFS_EXPORT fmi3Status fmi3SetInt32(fmi3Instance inst, const fmi3ValueReference vr[],
                                   size_t nvr, const fmi3Int32 values[], size_t nv)
{
    if (!counts_ok(inst, "fmi3SetInt32", nvr, nv)) return fmi3Error;
    return (fmi3Status)ifs_fmi_set_ints(inst, "fmi3SetInt32", vr, nvr, values);
}

/* Types this FMU has no variables of: an empty call is fine, anything else an error. */
static fmi3Status no_such_type(fmi3Instance inst, const char *fn, const fmi3ValueReference vr[],
                               size_t nvr)
{
    return (fmi3Status)ifs_fmi_no_such_type(inst, fn, "variables of this type", vr, nvr);
}

#define NO_SUCH_TYPE(fn, T)                                                                \
    IFS_EXPORT fmi3Status fn(fmi3Instance inst, const fmi3ValueReference vr[], size_t nvr, \
                             T values[], size_t nv)                                        \
    {                                                                                      \
        (void)values;                                                                      \
        (void)nv;                                                                          \
        return no_such_type(inst, #fn, vr, nvr);                                           \
    }

NO_SUCH_TYPE(fmi3GetFloat32, fmi3Float32)
NO_SUCH_TYPE(fmi3GetInt8, fmi3Int8)
NO_SUCH_TYPE(fmi3GetUInt8, fmi3UInt8)
NO_SUCH_TYPE(fmi3GetInt16, fmi3Int16)
NO_SUCH_TYPE(fmi3GetUInt16, fmi3UInt16)
NO_SUCH_TYPE(fmi3GetUInt32, fmi3UInt32)
NO_SUCH_TYPE(fmi3GetInt64, fmi3Int64)
NO_SUCH_TYPE(fmi3GetUInt64, fmi3UInt64)
NO_SUCH_TYPE(fmi3GetBoolean, fmi3Boolean)
NO_SUCH_TYPE(fmi3GetString, fmi3String)
NO_SUCH_TYPE(fmi3SetFloat32, const fmi3Float32)
NO_SUCH_TYPE(fmi3SetInt8, const fmi3Int8)
NO_SUCH_TYPE(fmi3SetUInt8, const fmi3UInt8)
NO_SUCH_TYPE(fmi3SetInt16, const fmi3Int16)
NO_SUCH_TYPE(fmi3SetUInt16, const fmi3UInt16)
NO_SUCH_TYPE(fmi3SetUInt32, const fmi3UInt32)
NO_SUCH_TYPE(fmi3SetInt64, const fmi3Int64)
NO_SUCH_TYPE(fmi3SetUInt64, const fmi3UInt64)
NO_SUCH_TYPE(fmi3SetBoolean, const fmi3Boolean)
NO_SUCH_TYPE(fmi3SetString, const fmi3String)

IFS_EXPORT fmi3Status fmi3GetBinary(fmi3Instance inst, const fmi3ValueReference vr[],
                                    size_t nvr, size_t sizes[], fmi3Binary values[], size_t nv)
{
    (void)sizes;
    (void)values;
    (void)nv;
    return no_such_type(inst, "fmi3GetBinary", vr, nvr);
}

IFS_EXPORT fmi3Status fmi3SetBinary(fmi3Instance inst, const fmi3ValueReference vr[],
                                    size_t nvr, const size_t sizes[],
                                    const fmi3Binary values[], size_t nv)
{
    (void)sizes;
    (void)values;
    (void)nv;
    return no_such_type(inst, "fmi3SetBinary", vr, nvr);
}

IFS_EXPORT fmi3Status fmi3GetClock(fmi3Instance inst, const fmi3ValueReference vr[],
                                   size_t nvr, fmi3Clock values[])
{
    (void)values;
    return no_such_type(inst, "fmi3GetClock", vr, nvr);
}

IFS_EXPORT fmi3Status fmi3SetClock(fmi3Instance inst, const fmi3ValueReference vr[],
                                   size_t nvr, const fmi3Clock values[])
{
    (void)values;
    return no_such_type(inst, "fmi3SetClock", vr, nvr);
}

/* --- dependencies: the outputs read the state only (no direct feedthrough) --- */

static int is_output(fmi3ValueReference vr)
{
    return vr < IFS_N_REALS && ifs_real_vars[vr].kind == IFS_OUTPUT;
}

IFS_EXPORT fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance inst,
                                                          fmi3ValueReference vr, size_t *n)
{
    Instance *c = (Instance *)inst;
    if (!c || !n) return fmi3Error;
    if (!is_output(vr))
        return ERR(c, "fmi3GetNumberOfVariableDependencies: %u is not an output", vr);
    *n = 0;
    return fmi3OK;
}

IFS_EXPORT fmi3Status fmi3GetVariableDependencies(
    fmi3Instance inst, fmi3ValueReference dependent, size_t element_dependent[],
    fmi3ValueReference independents[], size_t element_independents[],
    fmi3DependencyKind kinds[], size_t n)
{
    Instance *c = (Instance *)inst;
    (void)element_dependent;
    (void)independents;
    (void)element_independents;
    (void)kinds;
    if (!c) return fmi3Error;
    if (!is_output(dependent) || n != 0)
        return ERR(c, "fmi3GetVariableDependencies: %u is not an output, or n = %u is not "
                   "its number of dependencies (0)", dependent, (unsigned)n);
    return fmi3OK;
}

/* --- FMU state --- */

IFS_EXPORT fmi3Status fmi3GetFMUState(fmi3Instance inst, fmi3FMUState *state)
{
    return (fmi3Status)ifs_fmi_get_state(inst, "fmi3GetFMUState", state);
}

IFS_EXPORT fmi3Status fmi3SetFMUState(fmi3Instance inst, fmi3FMUState state)
{
    return (fmi3Status)ifs_fmi_set_state(inst, "fmi3SetFMUState", state);
}

IFS_EXPORT fmi3Status fmi3FreeFMUState(fmi3Instance inst, fmi3FMUState *state)
{
    return (fmi3Status)ifs_fmi_free_state(inst, state);
}

IFS_EXPORT fmi3Status fmi3SerializedFMUStateSize(fmi3Instance inst, fmi3FMUState state,
                                                 size_t *size)
{
    (void)state;
    return (fmi3Status)ifs_fmi_state_size(inst, size);
}

IFS_EXPORT fmi3Status fmi3SerializeFMUState(fmi3Instance inst, fmi3FMUState state,
                                            fmi3Byte bytes[], size_t size)
{
    return (fmi3Status)ifs_fmi_serialize(inst, "fmi3SerializeFMUState", state, bytes, size);
}

IFS_EXPORT fmi3Status fmi3DeserializeFMUState(fmi3Instance inst, const fmi3Byte bytes[],
                                              size_t size, fmi3FMUState *state)
{
    return (fmi3Status)ifs_fmi_deserialize(inst, "fmi3DeserializeFMUState", bytes, size, state);
}

/* --- derivatives (exact zeros: no direct feedthrough); not provided: adjoints,
 * configuration, clocks, model exchange --- */

IFS_EXPORT fmi3Status fmi3GetDirectionalDerivative(
    fmi3Instance inst, const fmi3ValueReference unknowns[], size_t nu,
    const fmi3ValueReference knowns[], size_t nk, const fmi3Float64 seed[], size_t ns,
    fmi3Float64 sensitivity[], size_t nsens)
{
    Instance *c = (Instance *)inst;
    const char *fn = "fmi3GetDirectionalDerivative";
    if (!c) return fmi3Error;
    if (ns != nk || nsens != nu)
        return (fmi3Status)ifs_log(&c->i.log, IFS_ERROR, "%s: %lu seeds for %lu knowns, %lu "
                                   "sensitivities for %lu unknowns", fn, (unsigned long)ns,
                                   (unsigned long)nk, (unsigned long)nsens,
                                   (unsigned long)nu);
    return (fmi3Status)ifs_fmi_directional(inst, fn, unknowns, nu, knowns, nk, seed,
                                           sensitivity);
}

IFS_EXPORT fmi3Status fmi3GetAdjointDerivative(
    fmi3Instance inst, const fmi3ValueReference unknowns[], size_t nu,
    const fmi3ValueReference knowns[], size_t nk, const fmi3Float64 seed[], size_t ns,
    fmi3Float64 sensitivity[], size_t nsens)
{
    (void)unknowns; (void)nu; (void)knowns; (void)nk; (void)seed; (void)ns;
    (void)sensitivity; (void)nsens;
    return refuse(inst, "fmi3GetAdjointDerivative: not provided "
                  "(providesAdjointDerivatives is false)");
}

IFS_EXPORT fmi3Status fmi3EnterConfigurationMode(fmi3Instance inst)
{
    return refuse(inst, "fmi3EnterConfigurationMode: there are no structural parameters");
}

IFS_EXPORT fmi3Status fmi3ExitConfigurationMode(fmi3Instance inst)
{
    return refuse(inst, "fmi3ExitConfigurationMode: there are no structural parameters");
}

#define NO_CLOCKS "this FMU has no clocks"

IFS_EXPORT fmi3Status fmi3GetIntervalDecimal(fmi3Instance inst, const fmi3ValueReference vr[],
                                             size_t n, fmi3Float64 intervals[],
                                             fmi3IntervalQualifier qualifiers[])
{
    (void)vr; (void)n; (void)intervals; (void)qualifiers;
    return refuse(inst, "fmi3GetIntervalDecimal: " NO_CLOCKS);
}

IFS_EXPORT fmi3Status fmi3GetIntervalFraction(fmi3Instance inst, const fmi3ValueReference vr[],
                                              size_t n, fmi3UInt64 counters[],
                                              fmi3UInt64 resolutions[],
                                              fmi3IntervalQualifier qualifiers[])
{
    (void)vr; (void)n; (void)counters; (void)resolutions; (void)qualifiers;
    return refuse(inst, "fmi3GetIntervalFraction: " NO_CLOCKS);
}

IFS_EXPORT fmi3Status fmi3GetShiftDecimal(fmi3Instance inst, const fmi3ValueReference vr[],
                                          size_t n, fmi3Float64 shifts[])
{
    (void)vr; (void)n; (void)shifts;
    return refuse(inst, "fmi3GetShiftDecimal: " NO_CLOCKS);
}

IFS_EXPORT fmi3Status fmi3GetShiftFraction(fmi3Instance inst, const fmi3ValueReference vr[],
                                           size_t n, fmi3UInt64 counters[],
                                           fmi3UInt64 resolutions[])
{
    (void)vr; (void)n; (void)counters; (void)resolutions;
    return refuse(inst, "fmi3GetShiftFraction: " NO_CLOCKS);
}

IFS_EXPORT fmi3Status fmi3SetIntervalDecimal(fmi3Instance inst, const fmi3ValueReference vr[],
                                             size_t n, const fmi3Float64 intervals[])
{
    (void)vr; (void)n; (void)intervals;
    return refuse(inst, "fmi3SetIntervalDecimal: " NO_CLOCKS);
}

IFS_EXPORT fmi3Status fmi3SetIntervalFraction(fmi3Instance inst, const fmi3ValueReference vr[],
                                              size_t n, const fmi3UInt64 counters[],
                                              const fmi3UInt64 resolutions[])
{
    (void)vr; (void)n; (void)counters; (void)resolutions;
    return refuse(inst, "fmi3SetIntervalFraction: " NO_CLOCKS);
}

IFS_EXPORT fmi3Status fmi3SetShiftDecimal(fmi3Instance inst, const fmi3ValueReference vr[],
                                          size_t n, const fmi3Float64 shifts[])
{
    (void)vr; (void)n; (void)shifts;
    return refuse(inst, "fmi3SetShiftDecimal: " NO_CLOCKS);
}

IFS_EXPORT fmi3Status fmi3SetShiftFraction(fmi3Instance inst, const fmi3ValueReference vr[],
                                           size_t n, const fmi3UInt64 counters[],
                                           const fmi3UInt64 resolutions[])
{
    (void)vr; (void)n; (void)counters; (void)resolutions;
    return refuse(inst, "fmi3SetShiftFraction: " NO_CLOCKS);
}

IFS_EXPORT fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance inst)
{
    return refuse(inst, "fmi3EvaluateDiscreteStates: event mode is not provided");
}

IFS_EXPORT fmi3Status fmi3UpdateDiscreteStates(fmi3Instance inst, fmi3Boolean *need_update,
                                               fmi3Boolean *terminate,
                                               fmi3Boolean *nominals_changed,
                                               fmi3Boolean *values_changed,
                                               fmi3Boolean *next_defined, fmi3Float64 *next)
{
    (void)need_update; (void)terminate; (void)nominals_changed; (void)values_changed;
    (void)next_defined; (void)next;
    return refuse(inst, "fmi3UpdateDiscreteStates: event mode is not provided");
}

#define CS_ONLY "this FMU is co-simulation only"

IFS_EXPORT fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance inst)
{
    return refuse(inst, "fmi3EnterContinuousTimeMode: " CS_ONLY);
}

IFS_EXPORT fmi3Status fmi3CompletedIntegratorStep(fmi3Instance inst, fmi3Boolean no_set,
                                                  fmi3Boolean *enter_event,
                                                  fmi3Boolean *terminate)
{
    (void)no_set; (void)enter_event; (void)terminate;
    return refuse(inst, "fmi3CompletedIntegratorStep: " CS_ONLY);
}

IFS_EXPORT fmi3Status fmi3SetTime(fmi3Instance inst, fmi3Float64 time)
{
    (void)time;
    return refuse(inst, "fmi3SetTime: " CS_ONLY);
}

IFS_EXPORT fmi3Status fmi3SetContinuousStates(fmi3Instance inst, const fmi3Float64 x[],
                                              size_t n)
{
    (void)x; (void)n;
    return refuse(inst, "fmi3SetContinuousStates: " CS_ONLY);
}

IFS_EXPORT fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance inst, fmi3Float64 dx[],
                                                        size_t n)
{
    (void)dx; (void)n;
    return refuse(inst, "fmi3GetContinuousStateDerivatives: " CS_ONLY);
}

IFS_EXPORT fmi3Status fmi3GetEventIndicators(fmi3Instance inst, fmi3Float64 z[], size_t n)
{
    (void)z; (void)n;
    return refuse(inst, "fmi3GetEventIndicators: " CS_ONLY);
}

IFS_EXPORT fmi3Status fmi3GetContinuousStates(fmi3Instance inst, fmi3Float64 x[], size_t n)
{
    (void)x; (void)n;
    return refuse(inst, "fmi3GetContinuousStates: " CS_ONLY);
}

IFS_EXPORT fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance inst,
                                                        fmi3Float64 nominals[], size_t n)
{
    (void)nominals; (void)n;
    return refuse(inst, "fmi3GetNominalsOfContinuousStates: " CS_ONLY);
}

IFS_EXPORT fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance inst, size_t *n)
{
    (void)n;
    return refuse(inst, "fmi3GetNumberOfEventIndicators: " CS_ONLY);
}

IFS_EXPORT fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance inst, size_t *n)
{
    (void)n;
    return refuse(inst, "fmi3GetNumberOfContinuousStates: " CS_ONLY);
}

IFS_EXPORT fmi3Status fmi3ActivateModelPartition(fmi3Instance inst, fmi3ValueReference clock,
                                                 fmi3Float64 time)
{
    (void)clock; (void)time;
    return refuse(inst, "fmi3ActivateModelPartition: scheduled execution is not provided");
}

/* --- co-simulation --- */

IFS_EXPORT fmi3Status fmi3EnterStepMode(fmi3Instance inst)
{
    return refuse(inst, "fmi3EnterStepMode: event mode is not provided; "
                  "fmi3ExitInitializationMode enters step mode");
}

IFS_EXPORT fmi3Status fmi3GetOutputDerivatives(fmi3Instance inst, const fmi3ValueReference vr[],
                                               size_t nvr, const fmi3Int32 orders[],
                                               fmi3Float64 values[], size_t nv)
{
    (void)vr; (void)nvr; (void)orders; (void)values; (void)nv;
    return refuse(inst, "fmi3GetOutputDerivatives: not provided (maxOutputDerivativeOrder "
                  "is 0)");
}

IFS_EXPORT fmi3Status fmi3DoStep(fmi3Instance inst, fmi3Float64 t, fmi3Float64 h,
                                 fmi3Boolean no_set_prior, fmi3Boolean *event_needed,
                                 fmi3Boolean *terminate, fmi3Boolean *early_return,
                                 fmi3Float64 *last_successful_time)
{
    Instance *c = (Instance *)inst;
    int st;
    (void)no_set_prior;
    if (!c) return fmi3Error;
    if (!event_needed || !terminate || !early_return || !last_successful_time)
        return ERR(c, "fmi3DoStep: null output argument");
    st = ifs_do_step(&c->i, t, h);     /* the slave's, as fmi2DoStep */
    *event_needed = fmi3False;
    *terminate = fmi3False;
    *early_return = fmi3False;
    *last_successful_time = ifs_slave_time(&c->i.s);
    return (fmi3Status)st;
}
