/*
 * How many 4-wide double multiplies and adds this machine retires per nanosecond,
 * the floor of an arithmetic-bound FMU step:
 *
 *   fp_rate
 *
 * Twelve independent chains of vmulpd (then of vaddpd), each far longer than the
 * operation's latency, so the loop is bound by throughput; best of 7 runs.  Prints
 * "mul_per_ns R" and "add_per_ns R".  Then the latencies of a step's chain from one
 * state to the next [ns]: "mul_lat_ns" and "add_lat_ns", one chain of 4-wide
 * multiplies (adds); "store_load_ns", a 16-byte store of a state and the broadcast
 * load of one of its doubles (as the FMU's step, which keeps its state in memory from
 * one call to the next), one after the other.  Compiled like the FMU (-O2
 * -ffp-contract=off), for AVX2 (the shipped binary's fast step).
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <time.h>

typedef double v4 __attribute__((vector_size(32)));

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);  /* CPU time */
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* the empty asm keeps each chain in a register and the factor opaque, so nothing is
 * folded or hoisted: one operation per chain per iteration */
#define KEEP(a, b, c, d) __asm__ volatile("" : "+x"(a), "+x"(b), "+x"(c), "+x"(d))
#define RATE(OP, K)                                                                    \
    do {                                                                               \
        v4 a0 = one, a1 = one, a2 = one, a3 = one, a4 = one, a5 = one;                 \
        v4 a6 = one, a7 = one, a8 = one, a9 = one, a10 = one, a11 = one, k = K;        \
        double best = 1e30;                                                            \
        long i;                                                                        \
        int r;                                                                         \
        for (r = 0; r < 7; r++) {                                                      \
            const double t0 = now();                                                   \
            for (i = 0; i < n; i++) {                                                  \
                KEEP(a0, a1, a2, a3);                                                  \
                KEEP(a4, a5, a6, a7);                                                  \
                KEEP(a8, a9, a10, a11);                                                \
                __asm__ volatile("" : "+x"(k));                                        \
                a0 = a0 OP k; a1 = a1 OP k; a2 = a2 OP k; a3 = a3 OP k;                \
                a4 = a4 OP k; a5 = a5 OP k; a6 = a6 OP k; a7 = a7 OP k;                \
                a8 = a8 OP k; a9 = a9 OP k; a10 = a10 OP k; a11 = a11 OP k;            \
            }                                                                          \
            if (now() - t0 < best) best = now() - t0;                                  \
        }                                                                              \
        sink += (a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7 + a8 + a9 + a10 + a11)[0];      \
        rate = 12.0 * (double)n / (best * 1e9);                                        \
    } while (0)

__attribute__((target("avx2"), noinline)) static double rates(double out[2])
{
    const v4 one = {1.0, 1.0, 1.0, 1.0};
    const v4 mul = {1.0000001, 1.0000001, 1.0000001, 1.0000001};
    const v4 add = {1e-9, 1e-9, 1e-9, 1e-9};
    const long n = 5000000;
    double sink = 0.0, rate;
    RATE(*, mul);
    out[0] = rate;
    RATE(+, add);
    out[1] = rate;
    return sink;
}

/* ns per operation of one chain of OP (each waits for the last) */
#define LATENCY(OP, K)                                                                 \
    do {                                                                               \
        v4 a = one, k = K;                                                             \
        double best = 1e30;                                                            \
        long i;                                                                        \
        int r;                                                                         \
        for (r = 0; r < 7; r++) {                                                      \
            const double t0 = now();                                                   \
            for (i = 0; i < n; i++) {                                                  \
                __asm__ volatile("" : "+x"(k));                                        \
                a = a OP k; a = a OP k; a = a OP k; a = a OP k;                        \
            }                                                                          \
            if (now() - t0 < best) best = now() - t0;                                  \
        }                                                                              \
        sink += a[0];                                                                  \
        lat = best * 1e9 / (4.0 * (double)n);                                          \
    } while (0)

__attribute__((target("avx2"), noinline)) static double latencies(double out[3])
{
    const v4 one = {1.0, 1.0, 1.0, 1.0};
    const v4 mul = {1.0000001, 1.0000001, 1.0000001, 1.0000001};
    const v4 add = {1e-9, 1e-9, 1e-9, 1e-9};
    const long n = 5000000;
    double sink = 0.0, lat, best = 1e30;
    static double x[4] __attribute__((aligned(64)));
    long i;
    int r;
    LATENCY(*, mul);
    out[0] = lat;
    LATENCY(+, add);
    out[1] = lat;
    /* the 16-byte store and the broadcast load that reads it back, in a chain */
    for (r = 0; r < 7; r++) {
        const double t0 = now();
        for (i = 0; i < n; i++)
            __asm__ volatile("vbroadcastsd 8(%0), %%ymm0\n\tvmovupd %%xmm0, (%0)"
                             :
                             : "r"(x)
                             : "memory", "xmm0");
        if (now() - t0 < best) best = now() - t0;
    }
    out[2] = best * 1e9 / (double)n;
    return sink;
}

int main(void)
{
    double r[2], l[3];
    const double sink = rates(r) + latencies(l);
    printf("mul_per_ns %.2f\nadd_per_ns %.2f\n", r[0], r[1]);
    printf("mul_lat_ns %.3f\nadd_lat_ns %.3f\nstore_load_ns %.3f\n", l[0], l[1], l[2]);
    return sink != sink;
}
