/*
 * Times fmi2DoStep of a co-simulation FMU binary directly (dlopen, no importer):
 *
 *   fmu_driver INFLOWSIM_SO GUID ONESTATE_SO [N [INFLOWSIM_FMI3_SO]]
 *
 * Prints one line per case: name, ns per step (best of REPEATS runs of N steps).
 * Cases: the one-state reference (DoStep; SetReal + DoStep + GetReal), inflowsim
 * glauert at fixed mu (the same two), and inflowsim with mu changed every step
 * (SetReal mu + DoStep: each step rebuilds and rediscretises the matrices); with an
 * FMI 3.0 binary also its fmi3DoStep and SetFloat64 + DoStep + GetFloat64.
 */
#define _POSIX_C_SOURCE 199309L
#include "fmu_load.h"
#include "fmi3Functions.h"

#define REPEATS 5

static fmi2Component start(const Api *a, const char *guid)
{
    static const fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = a->instantiate("bench", fmi2CoSimulation, guid, "", &cb, fmi2False,
                                     fmi2False);
    if (!c || a->setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
        a->enter_init(c) != fmi2OK || a->exit_init(c) != fmi2OK) {
        fprintf(stderr, "initialisation failed\n");
        exit(1);
    }
    return c;
}

/* mode 0: DoStep only; 1: SetReal inputs + DoStep + GetReal outputs; 2: SetReal mu + DoStep;
 * 3: DoStep with h = 1/60 s +- 2 % varying every frame (internal dt 0.01 s: one whole
 * step and a new remainder each frame); 4: DoStep with a constant h = 1/60 s */
static double run(const Api *a, const char *guid, long n, int mode, const fmi2ValueReference *in,
                  size_t nin, const fmi2ValueReference *out, size_t nout, fmi2ValueReference mu)
{
    double best = 1e30, sink = 0.0;
    int r;
    for (r = 0; r < REPEATS; r++) {
        fmi2Component c = start(a, guid);
        double u[16] = {0.0}, y[16], t0, t1;
        long k;
        size_t i;
        for (i = 0; i < nin; i++) u[i] = 1e-3 * (double)(i + 1);
        a->set_real(c, in, nin, u);
        double t = 0.0;
        if (mode == 2) {     /* one mu change before timing: the table is built once per
                              * parameter set (reported apart), not per step */
            double m = 0.3;
            a->set_real(c, &mu, 1, &m);
            if (a->do_step(c, 0.0, 0.01, fmi2True) != fmi2OK) exit(1);
            t = 0.01;
        }
        t0 = now();
        for (k = 0; k < n; k++) {
            double h = 0.01;
            if (mode == 3) h = (1.0 / 60.0) * (1.0 + 0.02 * (double)((k * 7919L) % 201 - 100)
                                                        / 100.0);
            else if (mode == 4) h = 1.0 / 60.0;
            if (mode == 1) {
                u[0] = 1e-3 * (double)(k & 7);
                a->set_real(c, in, nin, u);
            } else if (mode == 2) {
                double m = 0.249 + 1e-4 * (double)(k & 1);
                a->set_real(c, &mu, 1, &m);
            }
            if (a->do_step(c, mode >= 2 ? t : (double)k * 0.01, h, fmi2True) != fmi2OK) {
                fprintf(stderr, "fmi2DoStep failed\n");
                exit(1);
            }
            t += h;
            if (mode == 1) a->get_real(c, out, nout, y);
        }
        t1 = now();
        a->get_real(c, out, nout, y);
        sink += y[0];
        a->free_instance(c);
        if ((t1 - t0) / n < best) best = (t1 - t0) / n;
    }
    if (sink != sink) fprintf(stderr, "non-finite output\n");
    return best * 1e9;
}

/* --- FMI 3.0: the same two fixed-mu cases --- */

static void logger3(fmi3InstanceEnvironment env, fmi3Status st, fmi3String cat,
                    fmi3String msg)
{
    (void)env; (void)cat;
    fprintf(stderr, "[%d] %s\n", (int)st, msg);
}

static double run3(const char *path, const char *guid, long n, int mode)
{
    void *lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    fmi3InstantiateCoSimulationTYPE *instantiate;
    fmi3FreeInstanceTYPE *free_instance;
    fmi3EnterInitializationModeTYPE *enter_init;
    fmi3ExitInitializationModeTYPE *exit_init;
    fmi3SetFloat64TYPE *set;
    fmi3GetFloat64TYPE *get;
    fmi3DoStepTYPE *do_step;
    static const fmi3ValueReference in[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    static const fmi3ValueReference out[6] = {11, 12, 13, 14, 15, 16};
    double best = 1e30, sink = 0.0;
    int r;
    if (!lib) { fprintf(stderr, "%s\n", dlerror()); exit(1); }
    *(void **)&instantiate = sym(lib, "fmi3InstantiateCoSimulation");
    *(void **)&free_instance = sym(lib, "fmi3FreeInstance");
    *(void **)&enter_init = sym(lib, "fmi3EnterInitializationMode");
    *(void **)&exit_init = sym(lib, "fmi3ExitInitializationMode");
    *(void **)&set = sym(lib, "fmi3SetFloat64");
    *(void **)&get = sym(lib, "fmi3GetFloat64");
    *(void **)&do_step = sym(lib, "fmi3DoStep");
    for (r = 0; r < REPEATS; r++) {
        fmi3Instance c = instantiate("bench", guid, "", fmi3False, fmi3False, fmi3False,
                                     fmi3False, NULL, 0, NULL, logger3, NULL);
        double u[10], y[6], t0, t1, last;
        fmi3Boolean ev, term, early;
        long k;
        int i;
        if (!c || enter_init(c, fmi3False, 0.0, 0.0, fmi3False, 0.0) != fmi3OK ||
            exit_init(c) != fmi3OK) {
            fprintf(stderr, "FMI 3.0 initialisation failed\n");
            exit(1);
        }
        for (i = 0; i < 10; i++) u[i] = 1e-3 * (double)(i + 1);
        set(c, in, 10, u, 10);
        t0 = now();
        for (k = 0; k < n; k++) {
            if (mode == 1) {
                u[0] = 1e-3 * (double)(k & 7);
                set(c, in, 10, u, 10);
            }
            if (do_step(c, (double)k * 0.01, 0.01, fmi3True, &ev, &term, &early, &last) !=
                fmi3OK) {
                fprintf(stderr, "fmi3DoStep failed\n");
                exit(1);
            }
            if (mode == 1) get(c, out, 6, y, 6);
        }
        t1 = now();
        get(c, out, 6, y, 6);
        sink += y[0];
        free_instance(c);
        if ((t1 - t0) / n < best) best = (t1 - t0) / n;
    }
    if (sink != sink) fprintf(stderr, "non-finite output\n");
    return best * 1e9;
}

int main(int argc, char **argv)
{
    /* value references: see inflowsim/fmu/variables.py (inputs 0..9, mu 10, outputs 11..16) */
    static const fmi2ValueReference in10[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    static const fmi2ValueReference out6[6] = {11, 12, 13, 14, 15, 16};
    static const fmi2ValueReference in1[1] = {0}, out1[1] = {1};
    long n = argc > 4 ? atol(argv[4]) : 2000000L;
    Api fmu, one;
    if (argc < 4) {
        fprintf(stderr, "usage: %s INFLOWSIM_SO GUID ONESTATE_SO [N]\n", argv[0]);
        return 2;
    }
    load(&fmu, argv[1]);
    load(&one, argv[3]);
    printf("onestate_dostep %.2f\n", run(&one, "", n, 0, in1, 1, out1, 1, 0));
    printf("onestate_set_dostep_get %.2f\n", run(&one, "", n, 1, in1, 1, out1, 1, 0));
    printf("glauert_dostep %.2f\n", run(&fmu, argv[2], n, 0, in10, 10, out6, 6, 10));
    printf("glauert_set_dostep_get %.2f\n", run(&fmu, argv[2], n, 1, in10, 10, out6, 6, 10));
    printf("glauert_mu_every_step %.2f\n", run(&fmu, argv[2], n / 100 + 1, 2, in10, 10, out6, 6, 10));
    printf("glauert_varying_step %.2f\n", run(&fmu, argv[2], n / 10 + 1, 3, in10, 10, out6, 6, 10));
    printf("glauert_constant_step_1_60 %.2f\n", run(&fmu, argv[2], n / 10 + 1, 4, in10, 10, out6, 6, 10));
    if (argc > 5) {
        printf("fmi3_glauert_dostep %.2f\n", run3(argv[5], argv[2], n, 0));
        printf("fmi3_glauert_set_dostep_get %.2f\n", run3(argv[5], argv[2], n, 1));
    }
    return 0;
}
