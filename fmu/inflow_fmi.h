/*
 * The FMI shim: every call the FMI 2.0 and FMI 3.0 layers (inflow_fmi2.c,
 * inflow_fmi3.c) serve alike, once.  A layer's function is one line over these:
 * its instance (an IfsInstance first; NULL is refused with IFS_ERROR, nothing
 * logged), its own name for messages (fn), its status cast from the numbers both
 * versions share (inflow_slave.h).  What one version alone has stays in its layer:
 * FMI 2.0's status queries, FMI 3.0's independent variable "time", its array
 * counts and variable dependencies, and each version's instantiation, logger and
 * allocator.
 *
 * Inline: a layer's get, set and state call costs what it cost when the layer
 * called the slave itself (one call, none more).
 */
#ifndef INFLOW_FMI_H
#define INFLOW_FMI_H

#include "inflow_slave.h"

/* An error for a call this FMU does not serve, what its message (NULL instance:
 * an error, nothing logged). */
static inline int ifs_fmi_refuse(void *inst, const char *what)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_log(&c->log, IFS_ERROR, "%s", what);
}

/* Get or set of a type this FMU has no variables of (what: "variables of this
 * type", "Boolean variables"): an empty call is fine, anything else an error. */
static inline int ifs_fmi_no_such_type(void *inst, const char *fn, const char *what,
                                       const unsigned int vr[], size_t nvr)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    if (nvr == 0) return IFS_OK;
    return ifs_log(&c->log, IFS_ERROR, "%s: %u: this FMU has no %s", fn, vr ? vr[0] : 0u,
                   what);
}

/* --- life cycle --- */

static inline int ifs_fmi_set_debug_logging(void *inst, int on)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    c->log.debug = on;
    return IFS_OK;
}

static inline void ifs_fmi_free_instance(void *inst)
{
    if (inst) ifs_instance_free((IfsInstance *)inst);
}

/* The start and stop time (FMI 2.0's fmi2SetupExperiment; FMI 3.0's
 * fmi3EnterInitializationMode before ifs_fmi_enter_init). */
static inline int ifs_fmi_setup(void *inst, const char *fn, double start, int stop_defined,
                                double stop)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_slave_set_start_time(&c->s, &c->log, fn, start, stop_defined, stop);
}

static inline int ifs_fmi_enter_init(void *inst, const char *fn)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_slave_enter_init(&c->s, &c->log, fn);
}

static inline int ifs_fmi_exit_init(void *inst, const char *fn)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_slave_exit_init(&c->s, &c->log, fn);
}

static inline int ifs_fmi_terminate(void *inst)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    c->s.phase = IFS_PH_TERMINATED;
    ifs_slave_refresh(&c->s);
    return IFS_OK;
}

static inline int ifs_fmi_reset(void *inst)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    ifs_slave_init(&c->s);
    return IFS_OK;
}

/* --- get / set --- */

static inline int ifs_fmi_get_reals(void *inst, const char *fn, const unsigned int vr[],
                                    size_t nvr, double value[])
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_slave_get_reals(&c->s, &c->log, fn, vr, nvr, value);
}

/* A new mu alone inline (ifs_slave_set_mu), anything else the general set. */
static inline int ifs_fmi_set_reals(void *inst, const char *fn, const unsigned int vr[],
                                    size_t nvr, const double value[])
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    if (ifs_slave_set_mu(&c->s, vr, nvr, value)) return IFS_OK;
    return ifs_slave_set_reals(&c->s, &c->log, fn, vr, nvr, value);
}

static inline int ifs_fmi_get_ints(void *inst, const char *fn, const unsigned int vr[],
                                   size_t nvr, int value[])
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_slave_get_ints(&c->s, &c->log, fn, vr, nvr, value);
}

static inline int ifs_fmi_set_ints(void *inst, const char *fn, const unsigned int vr[],
                                   size_t nvr, const int value[])
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_slave_set_ints(&c->s, &c->log, fn, vr, nvr, value);
}

static inline int ifs_fmi_directional(void *inst, const char *fn, const unsigned int unknown[],
                                      size_t nu, const unsigned int known[], size_t nk,
                                      const double dknown[], double dunknown[])
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_slave_directional(&c->s, &c->log, fn, unknown, nu, known, nk, dknown,
                                 dunknown);
}

/* --- FMU state: allocated and freed by the instance's allocator --- */

static inline int ifs_fmi_get_state(void *inst, const char *fn, void **state)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_state_get(&c->s, &c->log, fn, state, ifs_instance_calloc, c);
}

static inline int ifs_fmi_set_state(void *inst, const char *fn, const void *state)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_state_set(&c->s, &c->log, fn, state);
}

static inline int ifs_fmi_free_state(void *inst, void **state)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c || !state) return IFS_ERROR;
    if (*state) c->release(c->mem, *state);
    *state = NULL;
    return IFS_OK;
}

static inline int ifs_fmi_state_size(void *inst, size_t *size)
{
    if (!inst || !size) return IFS_ERROR;
    *size = sizeof(IfsSavedState);
    return IFS_OK;
}

static inline int ifs_fmi_serialize(void *inst, const char *fn, const void *state,
                                    unsigned char bytes[], size_t size)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_state_serialize(&c->log, fn, state, bytes, size);
}

static inline int ifs_fmi_deserialize(void *inst, const char *fn, const unsigned char bytes[],
                                      size_t size, void **state)
{
    IfsInstance *c = (IfsInstance *)inst;
    if (!c) return IFS_ERROR;
    return ifs_state_deserialize(&c->log, fn, bytes, size, state, ifs_instance_calloc, c);
}

#endif
