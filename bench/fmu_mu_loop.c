/*
 * The simulator loop under valgrind's callgrind, for instruction counts
 * (bench/fmu_mu_callgrind.sh): load the FMU's library and take one fmi2DoStep of
 * 0.01 s n times, in mode
 *   0  mu fixed;
 *   1  a new mu every step (fmi2SetReal of mu first: the table's evaluation);
 *   2  a step varying +-2 % from frame to frame (the Taylor step of the remainder);
 *   3  the frame: fmi2SetReal of the ten inputs, the step, fmi2GetReal of the six
 *      outputs;
 *   4  a new mu every step, each in another of the table's parts (steps of 1e-3
 *      across parts of 3.3e-4 to 1.5e-3: with the inputs held, the part's
 *      coefficients of gam u made again at nearly every step).
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
    fmi2GetRealTYPE *getr = (fmi2GetRealTYPE *)dlsym(lib, "fmi2GetReal");
    fmi2DoStepTYPE *step = (fmi2DoStepTYPE *)dlsym(lib, "fmi2DoStep");
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = inst("b", fmi2CoSimulation, argv[2], "", &cb, fmi2False, fmi2False);
    fmi2ValueReference mu = 10;     /* IFS_VR_mu */
    static const fmi2ValueReference in[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    static const fmi2ValueReference out[6] = {11, 12, 13, 14, 15, 16};
    double m = 0.25, t = 0.0, h = 0.01, u[10], y[6], sink = 0.0;
    if (!c) return 1;
    setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
    ein(c);
    xin(c);
    setr(c, &mu, 1, &m);            /* the first change builds the table */
    step(c, t, 0.01, fmi2True);
    t += 0.01;
    for (k = 0; k < 10; k++) u[k] = 1e-3 * (k + 1);
    setr(c, in, 10, u);
    const int new_mu = mode == 1 || mode == 4;
    const double mu0 = mode == 4 ? 0.2 : 0.25, dmu = mode == 4 ? 1e-3 : 1e-6;
    for (k = 0; k < n; k++) {
        if (new_mu) {                /* (one test: mode 0 counts as it did alone) */
            m = mu0 + dmu * (k % 100);
            setr(c, &mu, 1, &m);
        } else if (mode == 2) {
            h = 0.01 * (1.0 + 0.02 * ((k % 7) - 3) / 3.0);
        } else if (mode == 3) {
            u[k % 10] = 1e-3 * (k % 13);
            setr(c, in, 10, u);
        }
        if (step(c, t, h, fmi2True) != fmi2OK) return 1;
        if (mode == 3) {
            getr(c, out, 6, y);
            sink += y[0];
        }
        t += h;
    }
    printf("done %g %g\n", t, sink);
    return 0;
}
