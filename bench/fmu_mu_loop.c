/*
 * The simulator loop with a new mu every step, for instruction counts under
 * valgrind's callgrind (bench/fmu_mu_callgrind.sh): load the FMU's library, set mu
 * (mode 1; mode 0 leaves it fixed) and take one fmi2DoStep, n times.
 *
 *   fmu_mu_loop LIBRARY GUID N MODE
 */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>

#include "fmi2Functions.h"

static void logger(fmi2ComponentEnvironment e, fmi2String i, fmi2Status s, fmi2String c,
                   fmi2String m, ...)
{
    (void)e; (void)i; (void)s; (void)c;
    fprintf(stderr, "%s\n", m);
}

int main(int argc, char **argv)
{
    void *lib;
    int n, mode, k;
    if (argc != 5 || !(lib = dlopen(argv[1], RTLD_NOW))) {
        fprintf(stderr, "usage: fmu_mu_loop LIBRARY GUID N MODE (%s)\n", dlerror());
        return 2;
    }
    n = atoi(argv[3]);
    mode = atoi(argv[4]);
    fmi2InstantiateTYPE *inst = (fmi2InstantiateTYPE *)dlsym(lib, "fmi2Instantiate");
    fmi2SetupExperimentTYPE *setup = (fmi2SetupExperimentTYPE *)dlsym(lib, "fmi2SetupExperiment");
    fmi2EnterInitializationModeTYPE *ein =
        (fmi2EnterInitializationModeTYPE *)dlsym(lib, "fmi2EnterInitializationMode");
    fmi2ExitInitializationModeTYPE *xin =
        (fmi2ExitInitializationModeTYPE *)dlsym(lib, "fmi2ExitInitializationMode");
    fmi2SetRealTYPE *setr = (fmi2SetRealTYPE *)dlsym(lib, "fmi2SetReal");
    fmi2DoStepTYPE *step = (fmi2DoStepTYPE *)dlsym(lib, "fmi2DoStep");
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = inst("b", fmi2CoSimulation, argv[2], "", &cb, fmi2False, fmi2False);
    fmi2ValueReference mu = 10;     /* IFS_VR_mu */
    double m = 0.25, t = 0.0;
    if (!c) return 1;
    setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
    ein(c);
    xin(c);
    setr(c, &mu, 1, &m);            /* the first change builds the table */
    step(c, t, 0.01, fmi2True);
    t += 0.01;
    for (k = 0; k < n; k++) {
        if (mode) {
            m = 0.25 + 1e-6 * (k % 100);
            setr(c, &mu, 1, &m);
        }
        step(c, t, 0.01, fmi2True);
        t += 0.01;
    }
    printf("done %g\n", t);
    return 0;
}
