/*
 * The simulator-loop frame of FMI 2.0 co-simulation binaries side by side:
 *
 *   fmu_frame N ROUNDS LABEL1 SO1 GUID1 [LABEL2 SO2 GUID2 ...]
 *
 * Each round times, for every binary in turn (so the machine's load hits all
 * alike), N steps of fmi2DoStep alone (h = dt = 0.01 s) and N frames of fmi2SetReal
 * (the ten inputs theta0 .. muy, value references 0-9) + fmi2DoStep + fmi2GetReal
 * (the six outputs, 11-16).  Prints per binary the best and the median over the
 * rounds, ns per step or frame:  LABEL dostep BEST MEDIAN / LABEL frame BEST MEDIAN.
 */
#define _POSIX_C_SOURCE 199309L
#include "fmu_load.h"

#define MAX_LIBS 8
#define MAX_ROUNDS 64

typedef struct {
    const char *label, *guid;
    Api api;
} Lib;

/* ns per step: mode 0 DoStep only, mode 1 SetReal + DoStep + GetReal */
static double run(const Lib *lib, long n, int mode, double *sink)
{
    const Api *a = &lib->api;
    static const fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    static const fmi2ValueReference in[10] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
    static const fmi2ValueReference out[6] = {11, 12, 13, 14, 15, 16};
    fmi2Component c = a->instantiate("bench", fmi2CoSimulation, lib->guid, "", &cb,
                                     fmi2False, fmi2False);
    double u[10], y[6], t0, t1;
    long k;
    int i;
    if (!c || a->setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
        a->enter_init(c) != fmi2OK || a->exit_init(c) != fmi2OK) {
        fprintf(stderr, "%s: initialisation failed\n", lib->label);
        exit(1);
    }
    for (i = 0; i < 10; i++) u[i] = 1e-3 * (double)(i + 1);
    a->set_real(c, in, 10, u);
    t0 = now();
    for (k = 0; k < n; k++) {
        if (mode == 1) {
            u[0] = 1e-3 * (double)(k & 7);
            a->set_real(c, in, 10, u);
        }
        if (a->do_step(c, (double)k * 0.01, 0.01, fmi2True) != fmi2OK) {
            fprintf(stderr, "%s: fmi2DoStep failed\n", lib->label);
            exit(1);
        }
        if (mode == 1) a->get_real(c, out, 6, y);
    }
    t1 = now();
    a->get_real(c, out, 6, y);
    *sink += y[0];
    a->free_instance(c);
    return (t1 - t0) / n * 1e9;
}

static int cmp(const void *x, const void *y)
{
    const double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

int main(int argc, char **argv)
{
    Lib libs[MAX_LIBS];
    double t[MAX_LIBS][2][MAX_ROUNDS], sink = 0.0;
    long n;
    int rounds, nl = 0, r, l, mode;
    if (argc < 6 || (argc - 3) % 3 != 0) {
        fprintf(stderr, "usage: %s N ROUNDS LABEL SO GUID [LABEL SO GUID ...]\n", argv[0]);
        return 2;
    }
    n = atol(argv[1]);
    rounds = atoi(argv[2]);
    if (rounds < 1 || rounds > MAX_ROUNDS || n < 1) return 2;
    for (l = 3; l + 2 < argc && nl < MAX_LIBS; l += 3, nl++) {
        libs[nl].label = argv[l];
        libs[nl].guid = argv[l + 2];
        load(&libs[nl].api, argv[l + 1]);
    }
    for (r = 0; r < rounds; r++)
        for (l = 0; l < nl; l++)
            for (mode = 0; mode < 2; mode++) t[l][mode][r] = run(&libs[l], n, mode, &sink);
    for (l = 0; l < nl; l++)
        for (mode = 0; mode < 2; mode++) {
            qsort(t[l][mode], (size_t)rounds, sizeof(double), cmp);
            printf("%s %s %.2f %.2f\n", libs[l].label, mode ? "frame" : "dostep",
                   t[l][mode][0], t[l][mode][rounds / 2]);
        }
    if (sink != sink) fprintf(stderr, "non-finite output\n");
    return 0;
}
