/*
 * FMI 2.0 co-simulation interface of the inflowsim rotor flap / inflow model: a
 * thin layer over the FMI shim (inflow_fmi.h: the calls both versions serve alike)
 * and the slave in inflow_slave.[ch] (the checks and the stepping).  No global
 * mutable state: every instance owns its data.
 */
#include <stdio.h>
#include <string.h>

#include "fmi2Functions.h"
#include "inflow_fmi.h"

typedef struct {
    IfsInstance i;             /* first, 64-byte aligned (see fmi2Instantiate) */
    fmi2CallbackFunctions cb;
} Instance;

/* FMI 2.0 logger behind IfsLog */
static void emit(void *env, int status, const char *category, const char *message)
{
    Instance *c = (Instance *)env;
    c->cb.logger(c->cb.componentEnvironment, c->i.name, (fmi2Status)status, category, "%s",
                 message);
}

#define ERR(c, ...) ((fmi2Status)ifs_log(&(c)->i.log, IFS_ERROR, __VA_ARGS__))

/* An error for a call this FMU does not serve; a null component is an error too. */
#define REFUSE(comp, what) ((fmi2Status)ifs_fmi_refuse(comp, what))

/* --- common functions --- */

IFS_EXPORT const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
IFS_EXPORT const char *fmi2GetVersion(void) { return fmi2Version; }

IFS_EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean on, size_t n,
                                          const fmi2String categories[])
{
    (void)n;
    (void)categories;
    return (fmi2Status)ifs_fmi_set_debug_logging(comp, on);
}

/* the FMI 2.0 allocator behind IfsCalloc (ctx: the callback functions) */
static void *alloc(void *ctx, size_t n)
{
    return ((const fmi2CallbackFunctions *)ctx)->allocateMemory(1, n);
}

static void release(void *ctx, void *p)
{
    ((const fmi2CallbackFunctions *)ctx)->freeMemory(p);
}

IFS_EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                         fmi2String resources,
                                         const fmi2CallbackFunctions *cb,
                                         fmi2Boolean visible, fmi2Boolean logging_on)
{
    Instance *c;
    (void)resources;
    (void)visible;
    if (!cb || !cb->allocateMemory || !cb->freeMemory) return NULL;
    c = (Instance *)ifs_instance_alloc(sizeof(Instance), alloc, release, (void *)cb, name,
                                       logging_on);
    if (!c) return NULL;
    c->cb = *cb;
    c->i.mem = &c->cb;         /* the instance's copy from now on */
    c->i.log.emit = cb->logger ? emit : NULL;
    c->i.do_step = "fmi2DoStep";
    if (ifs_instance_start(&c->i, type != fmi2CoSimulation ? "only co-simulation is "
                           "provided" : NULL, "GUID", guid) != 0)
        return NULL;
    return c;
}

IFS_EXPORT void fmi2FreeInstance(fmi2Component comp)
{
    ifs_fmi_free_instance(comp);
}

IFS_EXPORT fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean tol_defined,
                                          fmi2Real tol, fmi2Real start,
                                          fmi2Boolean stop_defined, fmi2Real stop)
{
    (void)tol_defined;
    (void)tol;
    return (fmi2Status)ifs_fmi_setup(comp, "fmi2SetupExperiment", start,
                                     stop_defined != fmi2False, stop);
}

IFS_EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component comp)
{
    return (fmi2Status)ifs_fmi_enter_init(comp, "fmi2EnterInitializationMode");
}

IFS_EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component comp)
{
    return (fmi2Status)ifs_fmi_exit_init(comp, "fmi2ExitInitializationMode");
}

IFS_EXPORT fmi2Status fmi2Terminate(fmi2Component comp)
{
    return (fmi2Status)ifs_fmi_terminate(comp);
}

IFS_EXPORT fmi2Status fmi2Reset(fmi2Component comp)
{
    return (fmi2Status)ifs_fmi_reset(comp);
}

/* --- get / set --- */

IFS_EXPORT fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[],
                                  size_t nvr, fmi2Real value[])
{
    return (fmi2Status)ifs_fmi_get_reals(comp, "fmi2GetReal", vr, nvr, value);
}

IFS_EXPORT fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[],
                                  size_t nvr, const fmi2Real value[])
{
    return (fmi2Status)ifs_fmi_set_reals(comp, "fmi2SetReal", vr, nvr, value);
}

IFS_EXPORT fmi2Status fmi2GetInteger(fmi2Component comp, const fmi2ValueReference vr[],
                                     size_t nvr, fmi2Integer value[])
{
    return (fmi2Status)ifs_fmi_get_ints(comp, "fmi2GetInteger", vr, nvr, value);
}

IFS_EXPORT fmi2Status fmi2SetInteger(fmi2Component comp, const fmi2ValueReference vr[],
                                     size_t nvr, const fmi2Integer value[])
{
    return (fmi2Status)ifs_fmi_set_ints(comp, "fmi2SetInteger", vr, nvr, value);
}

/* Types this FMU has no variables of: an empty call is fine (even with a null
 * component, as FMI 2.0's layer always answered), anything else an error. */
#define NO_SUCH_TYPE(fn, T, what)                                                          \
    IFS_EXPORT fmi2Status fn(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, \
                             T value[])                                                    \
    {                                                                                      \
        (void)value;                                                                       \
        if (nvr == 0) return fmi2OK;                                                       \
        return (fmi2Status)ifs_fmi_no_such_type(comp, #fn, what, vr, nvr);                 \
    }

NO_SUCH_TYPE(fmi2GetBoolean, fmi2Boolean, "Boolean variables")
NO_SUCH_TYPE(fmi2SetBoolean, const fmi2Boolean, "Boolean variables")
NO_SUCH_TYPE(fmi2GetString, fmi2String, "String variables")
NO_SUCH_TYPE(fmi2SetString, const fmi2String, "String variables")

/* --- FMU state --- */

IFS_EXPORT fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *state)
{
    return (fmi2Status)ifs_fmi_get_state(comp, "fmi2GetFMUstate", state);
}

IFS_EXPORT fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state)
{
    return (fmi2Status)ifs_fmi_set_state(comp, "fmi2SetFMUstate", state);
}

IFS_EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state)
{
    return (fmi2Status)ifs_fmi_free_state(comp, state);
}

IFS_EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state,
                                                 size_t *size)
{
    (void)state;
    return (fmi2Status)ifs_fmi_state_size(comp, size);
}

IFS_EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state,
                                            fmi2Byte bytes[], size_t size)
{
    return (fmi2Status)ifs_fmi_serialize(comp, "fmi2SerializeFMUstate", state,
                                         (unsigned char *)bytes, size);
}

IFS_EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte bytes[],
                                              size_t size, fmi2FMUstate *state)
{
    return (fmi2Status)ifs_fmi_deserialize(comp, "fmi2DeSerializeFMUstate",
                                           (const unsigned char *)bytes, size, state);
}

IFS_EXPORT fmi2Status fmi2GetDirectionalDerivative(
    fmi2Component comp, const fmi2ValueReference unknown[], size_t nu,
    const fmi2ValueReference known[], size_t nk, const fmi2Real dknown[], fmi2Real dunknown[])
{
    return (fmi2Status)ifs_fmi_directional(comp, "fmi2GetDirectionalDerivative", unknown, nu,
                                           known, nk, dknown, dunknown);
}

/* --- co-simulation --- */

IFS_EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component comp,
                                                  const fmi2ValueReference vr[], size_t nvr,
                                                  const fmi2Integer order[],
                                                  const fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    return REFUSE(comp, "fmi2SetRealInputDerivatives: inputs are held over a "
               "step (canInterpolateInputs is false)");
}

IFS_EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component comp,
                                                   const fmi2ValueReference vr[], size_t nvr,
                                                   const fmi2Integer order[],
                                                   fmi2Real value[])
{
    (void)vr; (void)nvr; (void)order; (void)value;
    return REFUSE(comp, "fmi2GetRealOutputDerivatives: not provided "
               "(maxOutputDerivativeOrder is 0)");
}

/* the slave's DoStep (ifs_do_step): where the loader picks it at load time, the
 * chosen function itself (its first three arguments are fmi2DoStep's) */
#ifdef IFS_WIDE_STEP
static fmi2DoStepTYPE *resolve_do_step(void)
{
    /* (through void (*)(void): the one cast between function types C compilers
     * accept without a warning) */
    return (fmi2DoStepTYPE *)(void (*)(void))ifs_do_step_choose();
}

IFS_EXPORT fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h,
                                 fmi2Boolean no_set_prior)
    __attribute__((ifunc("resolve_do_step")));
#else
IFS_EXPORT fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h,
                                 fmi2Boolean no_set_prior)
{
    (void)no_set_prior;
    return (fmi2Status)ifs_do_step(comp, t, h);
}
#endif

IFS_EXPORT fmi2Status fmi2CancelStep(fmi2Component comp)
{
    return REFUSE(comp, "fmi2CancelStep: fmi2DoStep is synchronous");
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
    *value = ifs_slave_time(&c->i.s);
    return fmi2OK;
}

IFS_EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component comp, const fmi2StatusKind s,
                                           fmi2Integer *value)
{
    (void)s; (void)value;
    return REFUSE(comp, "fmi2GetIntegerStatus: no integer status is provided");
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
    return REFUSE(comp, "fmi2GetStringStatus: no string status is provided");
}
