/*
 * What the FMI 2.0 benchmark drivers (fmu_driver.c, fmu_frame.c) share: loading a
 * co-simulation binary with dlopen, the logger it is given and the clock.  Define
 * _POSIX_C_SOURCE 199309L (clock_gettime) before including it.
 */
#ifndef FMU_LOAD_H
#define FMU_LOAD_H

#include <dlfcn.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "fmi2Functions.h"

/* the FMI 2.0 functions the drivers call */
typedef struct {
    fmi2InstantiateTYPE *instantiate;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter_init;
    fmi2ExitInitializationModeTYPE *exit_init;
    fmi2SetRealTYPE *set_real;
    fmi2GetRealTYPE *get_real;
    fmi2DoStepTYPE *do_step;
} Api;

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status st,
                   fmi2String cat, fmi2String msg, ...)
{
    va_list ap;
    (void)env; (void)cat;
    va_start(ap, msg);
    fprintf(stderr, "[%s %d] ", name, (int)st);
    vfprintf(stderr, msg, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* the symbol, or exit naming it */
static void *sym(void *lib, const char *name)
{
    void *p = dlsym(lib, name);
    if (!p) { fprintf(stderr, "missing %s\n", name); exit(1); }
    return p;
}

/* the binary at path opened and its FMI 2.0 functions in *a, or exit */
static void load(Api *a, const char *path)
{
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) { fprintf(stderr, "%s\n", dlerror()); exit(1); }
    *(void **)&a->instantiate = sym(lib, "fmi2Instantiate");
    *(void **)&a->free_instance = sym(lib, "fmi2FreeInstance");
    *(void **)&a->setup = sym(lib, "fmi2SetupExperiment");
    *(void **)&a->enter_init = sym(lib, "fmi2EnterInitializationMode");
    *(void **)&a->exit_init = sym(lib, "fmi2ExitInitializationMode");
    *(void **)&a->set_real = sym(lib, "fmi2SetReal");
    *(void **)&a->get_real = sym(lib, "fmi2GetReal");
    *(void **)&a->do_step = sym(lib, "fmi2DoStep");
}

/* seconds of this process's CPU time (not wall time: other processes on the
 * machine do not count) */
static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

#endif
