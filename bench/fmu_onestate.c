/*
 * Reference for the FMU benchmark: the smallest useful FMI 2.0 co-simulation
 * slave, one state x' = -x + u stepped with a precomputed exact ZOH (x <- a x + b u).
 * Only the functions the driver calls; built with the same flags as inflowsim.so.
 */
#include <math.h>
#include <string.h>

#include "fmi2Functions.h"

#define EXPORT __attribute__((visibility("default")))

typedef struct {
    fmi2CallbackFunctions cb;
    double x, u, a, b, dt;
} One;

EXPORT fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid,
                                     fmi2String res, const fmi2CallbackFunctions *cb,
                                     fmi2Boolean visible, fmi2Boolean logging)
{
    One *c;
    (void)name; (void)type; (void)guid; (void)res; (void)visible; (void)logging;
    c = (One *)cb->allocateMemory(1, sizeof(One));
    if (!c) return NULL;
    c->cb = *cb;
    c->dt = 0.01;
    c->a = exp(-c->dt);
    c->b = 1.0 - c->a;
    return c;
}

EXPORT void fmi2FreeInstance(fmi2Component comp) { ((One *)comp)->cb.freeMemory(comp); }

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean a, fmi2Real b, fmi2Real t,
                                      fmi2Boolean d, fmi2Real e)
{
    (void)c; (void)a; (void)b; (void)t; (void)d; (void)e;
    return fmi2OK;
}

EXPORT fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
EXPORT fmi2Status fmi2ExitInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }

EXPORT fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t n,
                              const fmi2Real v[])
{
    One *c = (One *)comp;
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] != 0) return fmi2Error;
        c->u = v[i];
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t n,
                              fmi2Real v[])
{
    One *c = (One *)comp;
    size_t i;
    for (i = 0; i < n; i++) {
        if (vr[i] != 1) return fmi2Error;
        v[i] = c->x;
    }
    return fmi2OK;
}

EXPORT fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h, fmi2Boolean nos)
{
    One *c = (One *)comp;
    (void)t; (void)nos;
    if (h != c->dt) return fmi2Error;
    c->x = c->a * c->x + c->b * c->u;
    return fmi2OK;
}
