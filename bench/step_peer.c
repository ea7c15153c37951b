/*
 * The latency-bound peer of the FMU's step: the best plain loop for the recurrence
 * x <- [phi gam] [x; u] at NX states and 10 inputs, no FMI around it, for
 * bench/fmu_states.py (compiled with -DNX=...):
 *
 *   step_peer [STEPS]
 *
 * Prints "peer_reg_ns T", "peer_mem_ns T" and "peer_held_ns T": the time of one step
 * [ns], process CPU, best of 7 runs of STEPS steps: the state held in registers from
 * one step to the next (each x_j permuted across the lanes); the state stored and
 * loaded again at every step (each x_j a broadcast load of the last step's store:
 * what a step behind a function call, as the FMU's, must do); and, the state in
 * registers, with the inputs held (gam u once: the NX^2 products of phi x and its
 * chain alone, as the FMU's step with its inputs held).  Both take the column form of
 * the FMU's step (inflow_model.h: each x_j and u_k multiplies its column, four rows a
 * vector, the terms of each row, g first, summed in a pairwise tree), every product
 * of [phi gam] [x; u] at every step in the first two (the inputs read from a table of
 * eight, which the compiler cannot hoist), no fused multiply-add (-ffp-contract=off: the FMU's
 * rounding), four-wide (AVX2).  A recurrence's time is bound by the larger of its
 * throughput (the products at the machine's rate: bench/fp_rate.c) and the latency
 * of its chain from one state to the next; this loop meets both as far as plain code
 * can, the floor the FMU's step is compared with beside the throughput bound.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#ifndef NX
#define NX 6
#endif
#define NU 10
#define G ((NX + 3) / 4)           /* vectors of four rows */
#define LD (4 * G)

typedef double v4 __attribute__((vector_size(32)));

#if defined(__GNUC__) && !defined(__clang__)
#define UNROLL _Pragma("GCC unroll 64")
#else
#define UNROLL
#endif

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* out = the pairwise sum of the K terms TERM(j_), streaming (as the FMU's
 * IFS_TREE_SUM) */
#define TREE(K, TERM, out)                                                             \
    do {                                                                               \
        v4 s_[6], c_;                                                                  \
        int j_, l_, have_ = 0;                                                         \
        UNROLL                                                                         \
        for (j_ = 0; j_ < (K); j_++) {                                                 \
            c_ = TERM;                                                                 \
            UNROLL                                                                     \
            for (l_ = 0; l_ < 6; l_++) {                                               \
                if ((j_ >> l_) & 1) {                                                  \
                    c_ = s_[l_] + c_;                                                  \
                } else {                                                               \
                    s_[l_] = c_;                                                       \
                    break;                                                             \
                }                                                                      \
            }                                                                          \
        }                                                                              \
        UNROLL                                                                         \
        for (l_ = 0; l_ < 6; l_++)                                                     \
            if (((K) >> l_) & 1) {                                                     \
                c_ = have_ ? s_[l_] + c_ : s_[l_];                                     \
                have_ = 1;                                                             \
            }                                                                          \
        out = c_;                                                                      \
    } while (0)

/* column j of [phi gam], rows 4 q .. 4 q + 3 */
#define COL(j, q) (*(const v4 *)(pg + (j) * LD + 4 * (q)))

/* the state in registers: x_j permuted across the lanes of its vector (where it is
 * used: the permutes kept apart ran out of registers) */
#define BX(j)                                                                          \
    __builtin_shuffle(x[(j) / 4], (long long __attribute__((vector_size(32)))){        \
                                      (j) % 4, (j) % 4, (j) % 4, (j) % 4})
__attribute__((target("avx2"), noinline)) static double run_reg(const double *pg,
                                                               const double *us, long n,
                                                               double *x0)
{
    v4 x[G], y[G], g[G];
    long k;
    int q;
    for (q = 0; q < G; q++) x[q] = *(const v4 *)(x0 + 4 * q);
    for (k = 0; k < n; k++) {
        const double *u = us + NU * (k & 7);
        __asm__("" : "+r"(pg));        /* the columns read as operands, not hoisted */
        UNROLL
        for (q = 0; q < G; q++) TREE(NU, COL(NX + j_, q) * u[j_], g[q]);
        UNROLL
        for (q = 0; q < G; q++) TREE(NX + 1, j_ == 0 ? g[q] : COL(j_ - 1, q) * BX(j_ - 1),
                                 y[q]);
        UNROLL
        for (q = 0; q < G; q++) x[q] = y[q];
    }
    for (q = 0; q < G; q++) *(v4 *)(x0 + 4 * q) = x[q];
    return x[0][0];
}

/* the state in registers, the inputs held: gam u once, then phi x + g at every step
 * (the FMU's step with its inputs held, which keeps g) */
__attribute__((target("avx2"), noinline)) static double run_held(const double *pg,
                                                                const double *u, long n,
                                                                double *x0)
{
    v4 x[G], y[G], g[G];
    long k;
    int q;
    for (q = 0; q < G; q++) x[q] = *(const v4 *)(x0 + 4 * q);
    UNROLL
    for (q = 0; q < G; q++) TREE(NU, COL(NX + j_, q) * u[j_], g[q]);
    for (k = 0; k < n; k++) {
        __asm__("" : "+r"(pg));
        UNROLL
        for (q = 0; q < G; q++) TREE(NX + 1, j_ == 0 ? g[q] : COL(j_ - 1, q) * BX(j_ - 1),
                                 y[q]);
        UNROLL
        for (q = 0; q < G; q++) x[q] = y[q];
    }
    for (q = 0; q < G; q++) *(v4 *)(x0 + 4 * q) = x[q];
    return x[0][0];
}

/* the state stored and loaded again at every step: x_j a broadcast load */
__attribute__((target("avx2"), noinline)) static double run_mem(const double *pg,
                                                               const double *us, long n,
                                                               double *x)
{
    v4 y[G], g[G];
    long k;
    int q;
    for (k = 0; k < n; k++) {
        const double *u = us + NU * (k & 7);
        __asm__("" : "+r"(pg));
        UNROLL
        for (q = 0; q < G; q++) TREE(NU, COL(NX + j_, q) * u[j_], g[q]);
        UNROLL
        for (q = 0; q < G; q++) TREE(NX + 1, j_ == 0 ? g[q] : COL(j_ - 1, q) * x[j_ - 1],
                                 y[q]);
        UNROLL
        for (q = 0; q < G; q++) *(v4 *)(x + 4 * q) = y[q];
        __asm__ volatile("" ::: "memory");     /* the next step loads x again */
    }
    return x[0];
}

int main(int argc, char **argv)
{
    const long n = argc > 1 ? atol(argv[1]) : 2000000L;
    static double pg[(NX + NU) * LD] __attribute__((aligned(64)));
    static double us[8 * NU];
    static double x[LD] __attribute__((aligned(64)));
    double best[3] = {1e30, 1e30, 1e30}, sink = 0.0;
    int i, j, r;
    /* a stable [phi gam]: phi = 0.9 I + small couplings, padding rows zero */
    for (j = 0; j < NX + NU; j++)
        for (i = 0; i < NX; i++)
            pg[j * LD + i] = j < NX ? (i == j ? 0.9 : 0.01 / (1 + i + j)) : 0.001 * (i - j);
    for (i = 0; i < 8 * NU; i++) us[i] = 1e-3 * (i % 7);
    for (r = 0; r < 7; r++) {
        double t0;
        for (i = 0; i < LD; i++) x[i] = 0.0;
        t0 = now();
        sink += run_reg(pg, us, n, x);
        t0 = now() - t0;
        if (t0 < best[0]) best[0] = t0;
        for (i = 0; i < LD; i++) x[i] = 0.0;
        t0 = now();
        sink += run_mem(pg, us, n, x);
        t0 = now() - t0;
        if (t0 < best[1]) best[1] = t0;
        for (i = 0; i < LD; i++) x[i] = 0.0;
        t0 = now();
        sink += run_held(pg, us, n, x);
        t0 = now() - t0;
        if (t0 < best[2]) best[2] = t0;
    }
    printf("peer_reg_ns %.3f\npeer_mem_ns %.3f\npeer_held_ns %.3f\n", best[0] * 1e9 / n,
           best[1] * 1e9 / n, best[2] * 1e9 / n);
    return sink != sink;
}
