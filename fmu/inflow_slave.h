/*
 * The co-simulation slave behind both FMI layers (inflow_fmi2.c, inflow_fmi3.c):
 * variables, model, phase and the step counter, with the checks and the stepping
 * they share.  Knows no FMI types: statuses are the numbers FMI 2.0 and 3.0 share
 * (0 OK, 1 warning, 3 error), value references are unsigned ints.
 *
 * IfsSlave is plain data (an FMU state is a copy of it).  Inputs and outputs are
 * perturbations about trim (SI); mu is the total trim advance ratio.  A step holds
 * the inputs set before it over [t, t + h) and leaves the outputs at t + h (the
 * convention of inflowsim.Simulator.step).
 */
#ifndef INFLOW_SLAVE_H
#define INFLOW_SLAVE_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "inflow_model.h"

enum { IFS_OK = 0, IFS_WARNING = 1, IFS_ERROR = 3 };

typedef enum { IFS_PH_INSTANTIATED, IFS_PH_INIT, IFS_PH_STEP, IFS_PH_TERMINATED } IfsPhase;

/* Time shifts of the recorded flap (time-delay's delay, the delay-beta0 ..
 * effects' per-channel ones): channel i is the rotor's at t - d_i, exactly (as
 * inflowsim's Simulator): d_i = mm dt + f dt; the delayed state is a stored state
 * (f = 0) or a stored state and input carried over (1 - f) dt by pg_frac.  A ring
 * of the last IFS_DELAY_DEPTH internal steps' states and inputs, shared by the
 * three channels. */
#define IFS_DELAY_MAX_STEPS 256
#define IFS_DELAY_DEPTH (IFS_DELAY_MAX_STEPS + 2)
typedef struct {
    int active;                    /* some channel is delayed */
    double d[3];                   /* each flap channel's delay [s] */
    int mm[3];                     /* whole internal steps of each */
    double f[3];                   /* the fraction of a step left, 0 or in (0, 1) */
    double pg_frac[3][IFS_PG_N];    /* [phi gam] over (1 - f) dt, as IfsModel.pg */
    long long k;                   /* internal steps taken since initialization */
    double x0[IFS_NX];             /* the state at step 0 (before the record) */
    double hx[IFS_DELAY_DEPTH][IFS_NX];
    double hu[IFS_DELAY_DEPTH][IFS_NU];
    long long hk[IFS_DELAY_DEPTH]; /* which step each slot holds, -1 none */
} IfsDelay;

typedef struct {
    IfsVariables v;
    /* the model 64-byte aligned from an aligned slave (IfsModel's first fields) */
    char pad_[64 - sizeof(IfsVariables) % 64];
    IfsModel m;
    /* what the simulator loop's step checks (ifs_do_step), kept by the calls that
     * change what it depends on (ifs_slave_refresh): the current time now = t_base +
     * n_comm h_comm; fast_h, the
     * communication step h_comm while it is the internal step dt, in step mode, with
     * nothing to rebuild and no delay line, else NaN (no h equals it); n_stop, the
     * first n_comm from which a step of h_comm would end after the stop time */
    double now;
    double fast_h;
    long long n_stop;
    IfsPhase phase;
    int dirty;                 /* parameters or mu changed since the last build */
    int params_changed;        /* ... and something other than mu did */
    /* 1: the outputs (beta0 .. lambda1s) are not yet those of the state: computed
     * when read (ifs_slave_get_reals), not at every step */
    int y_stale;
    /* the FMI layer's mu table (never part of a saved state: restored instances keep
     * their own and rebuild it); NULL: mu changes always rebuild exactly */
    IfsMuTable *tab;
    /* the mu a set of mu alone takes from the table at once (ifs_slave_set_mu):
     * mu_range, the table's and mu's declared range, while the table is valid for
     * the parameters, in step mode, with nothing else to rebuild and no delay line;
     * else none (+inf, -inf); kept by ifs_slave_refresh */
    double mu_lo, mu_hi;
    double mu_range[2];
    /* time = t_base + n_comm h_comm: a step counter, never a running sum */
    double t_start, t_base, h_comm;
    long long n_comm;
    /* the experiment's stop time with the time tolerance added; +inf when none given */
    double t_stop;
    int warned_time;           /* the time-mismatch warning is given once (0 or 1) */
    /* last: the delay line (tens of kilobytes) would put the fields the fast step
     * reads (phase ... t_stop) pages away from the model's state */
    IfsDelay delay;
} IfsSlave;

/* The first multiple of 64 at or after p (an allocation 64 bytes longer than the
 * slave's holder, which the FMI layers keep 64-byte aligned: IfsModel), with
 * *block = p to free; NULL for NULL. */
static inline void *ifs_align64(void *p, void **block)
{
    *block = p;
    return p ? (void *)((char *)p + (64 - (uintptr_t)p % 64) % 64) : NULL;
}

/* Where messages go: the FMI layer's logger behind one function.  Messages with
 * status IFS_OK are dropped unless debug is set. */
typedef struct {
    void (*emit)(void *env, int status, const char *category, const char *message);
    void *env;
    int debug;
} IfsLog;

/* Log a printf-style message; returns status, so `return ifs_log(...)` works. */
int ifs_log(const IfsLog *lg, int status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Start values, phase "instantiated", state zero. */
void ifs_slave_init(IfsSlave *s);
/* The start and stop time (only right after instantiation or reset); stop_defined
 * false leaves the run open-ended.  A step past the stop time is refused. */
int ifs_slave_set_start_time(IfsSlave *s, const IfsLog *lg, const char *fn, double start,
                             int stop_defined, double stop);
int ifs_slave_enter_init(IfsSlave *s, const IfsLog *lg, const char *fn);
/* Build the model from the variables and compute the initial outputs. */
int ifs_slave_exit_init(IfsSlave *s, const IfsLog *lg, const char *fn);

/* Reals by value reference.  A refused set changes nothing. */
int ifs_slave_get_reals(IfsSlave *s, const IfsLog *lg, const char *fn,
                        const unsigned int vr[], size_t n, double value[]);
int ifs_slave_set_reals(IfsSlave *s, const IfsLog *lg, const char *fn,
                        const unsigned int vr[], size_t n, const double value[]);
/* A new mu alone (n == 1), the flight condition of a simulator changing speed every
 * step, inline in the FMI layers' set functions: within [s->mu_lo, s->mu_hi] (the
 * table valid, ifs_slave_refresh) the table's [phi gam] at once (ifs_mu_table_apply:
 * the next step is the fixed-mu step, and the loads read before it are those of the
 * new mu, as the Simulator's set_mu); else, within the table's range and mu's
 * declared one with no other parameter change pending, it is stored (the step takes
 * it from the table or builds the table: ifs_slave_step_rest); then 1 returned, as
 * ifs_slave_set_reals would (the general call cost 70 instructions more, a quarter
 * of the mu step, bench/fmu.md); else 0 and nothing done. */
static inline int ifs_slave_set_mu(IfsSlave *s, const unsigned int vr[], size_t n,
                                   const double value[])
{
    if (n == 1 && vr && value && vr[0] == IFS_VR_mu) {
        const double mu = value[0];
        if (mu >= s->mu_lo && mu <= s->mu_hi) {
            if (s->v.mu != mu) {
                s->v.mu = mu;
                ifs_mu_table_apply(s->tab, &s->v, &s->m);
            }
            return 1;
        }
        if (!s->params_changed && mu >= IFS_MU_LO && mu <= IFS_MU_HI &&
            mu >= ifs_real_vars[IFS_VR_mu].lower && mu <= ifs_real_vars[IFS_VR_mu].upper &&
            !(ifs_real_vars[IFS_VR_mu].lower_open && mu == ifs_real_vars[IFS_VR_mu].lower)) {
            if (s->v.mu != mu) {
                s->dirty = 1;
                s->fast_h = NAN;
            }
            s->v.mu = mu;
            return 1;
        }
    }
    return 0;
}
/* Integers (the structure) by value reference. */
int ifs_slave_get_ints(const IfsSlave *s, const IfsLog *lg, const char *fn,
                       const unsigned int vr[], size_t n, int value[]);
int ifs_slave_set_ints(IfsSlave *s, const IfsLog *lg, const char *fn,
                       const unsigned int vr[], size_t n, const int value[]);

/* Partial derivatives of outputs (unknown) with respect to inputs (known) at the
 * current communication point, exact: dunknown[i] = sum_j d y_i / d u_j dknown[j].
 * Flap and inflow read the state only (zero); the loads are linear in the held
 * inputs (their ld row).  Refuses value references of other kinds, and mu for the
 * loads. */
int ifs_slave_directional(IfsSlave *s, const IfsLog *lg, const char *fn,
                          const unsigned int unknown[], size_t nu,
                          const unsigned int known[], size_t nk, const double dknown[],
                          double dunknown[]);

/* Any step: checks, rebuild, internal steps and an exact remainder. */
int ifs_slave_step(IfsSlave *s, const IfsLog *lg, const char *fn, double t, double h);

/* The current time (from the step counter). */
static inline double ifs_slave_time(const IfsSlave *s)
{
    return s->now;
}

/* The time and the fast step's condition (IfsSlave.fast_h) after a change of what
 * they depend on: every call that changes the phase, the step counter, dt, the
 * delay line or clears dirty ends with it. */
void ifs_slave_refresh(IfsSlave *s);

/* what the step reads on whole vectors from an aligned slave (IfsModel) */
typedef char ifs_model_is_aligned[offsetof(IfsSlave, m) % 64 == 0 &&
                                  offsetof(IfsModel, x) % 32 == 0 ? 1 : -1];

/* the inputs theta0 .. muy in order: the generated struct keeps them contiguous */
typedef char ifs_inputs_are_contiguous[offsetof(IfsVariables, muy) -
                                       offsetof(IfsVariables, theta0) ==
                                       (IFS_NU - 1) * sizeof(double) ? 1 : -1];

static inline const double *ifs_slave_inputs(const IfsSlave *s)
{
    return (const double *)((const char *)&s->v + offsetof(IfsVariables, theta0));
}

/* gam at the last mu where a mu change with the inputs held left it stale
 * (IfsModel.gq_seg > 0, ifs_mu_table_apply), before the step's kept g = gam u is
 * dropped (g_ok cleared) or anything else reads gam; the coefficients of gam u (gq)
 * dropped with g.  Called where g_ok is cleared but by a mu change. */
void ifs_slave_fresh_gam(IfsSlave *s);
static inline void ifs_slave_drop_g(IfsSlave *s)
{
    if (s->m.gq_seg > 0.0) ifs_slave_fresh_gam(s);
    s->m.gq_seg = IFS_GQ_NONE;
    s->m.g_ok = 0;
}

/* The inputs held (theta0 .. muy) copied beside the state, where the step reads
 * them (IfsModel.x): after any change of the slave's inputs but one value's. */
static inline void ifs_slave_hold_inputs(IfsSlave *s)
{
    ifs_slave_drop_g(s);
    memcpy(s->m.x + IFS_NX, ifs_slave_inputs(s), IFS_NU * sizeof(double));
}

/* The state delayed by flap channel i's time shift. */
void ifs_slave_delayed_state(const IfsSlave *s, int i, double x[IFS_NX]);

/* The outputs (beta0 .. lambda1s) from the state, the delay line and the azimuth
 * bias (y_stale cleared): when they are read after a change. */
void ifs_slave_update_outputs(IfsSlave *s);

/* --- an FMI instance: what both layers' instances start with --- */

/* n zeroed bytes (NULL if there are none), and their release: the layer's allocator */
typedef void *(*IfsCalloc)(void *ctx, size_t n);
typedef void (*IfsRelease)(void *ctx, void *p);
typedef struct {
    IfsSlave s;                /* first, 64-byte aligned (IfsModel) */
    IfsLog log;
    char name[128];
    void *block;               /* what alloc returned, the instance inside it */
    IfsCalloc alloc;
    IfsRelease release;
    void *mem;                 /* their context */
    const char *do_step;       /* the layer's DoStep, for messages: "fmi2DoStep" */
} IfsInstance;

/* A zeroed instance of size bytes (the layer's, an IfsInstance first), 64-byte
 * aligned, named (default "inflowsim"), logging at debug level if logging_on; NULL if
 * the memory is not there.  The layer sets its own fields and c->log.emit, then calls
 * ifs_instance_start. */
IfsInstance *ifs_instance_alloc(size_t size, IfsCalloc alloc, IfsRelease release, void *mem,
                                const char *name, int logging_on);
/* Refuse the instance (log refusal if not NULL, else a token other than IFS_GUID,
 * naming it what; free it; -1), or start it: the start values, and the mu table
 * allocated apart (without it mu changes rebuild exactly); 0. */
int ifs_instance_start(IfsInstance *c, const char *refusal, const char *what,
                       const char *token);
void ifs_instance_free(IfsInstance *c);

/* DoStep of both FMI layers: instance an IfsInstance (NULL refused), a step of h
 * from the communication point t.  The simulator loop's usual step (the same h as
 * last time, equal to the internal step, nothing to rebuild, on time: three
 * comparisons, IfsSlave.fast_h) is the step alone, inline; the rest out of line: a
 * new mu taken from the table (a flight condition changing every step), else the
 * general step (ifs_slave_step).  Where the loader picks a function at load time
 * (GNU ifunc: IFS_WIDE_STEP) it is one of two, the AVX2 one with the four-wide step
 * inline (ifs_step_wide) and the baseline one: ifs_do_step_choose picks, and the
 * FMI 2.0 layer's fmi2DoStep is the chosen one itself (its first three arguments
 * are these; no_set_prior is not read). */
typedef int IfsDoStep(void *instance, double t, double h);
int ifs_do_step(void *instance, double t, double h);
#ifdef IFS_WIDE_STEP
#if defined(__GNUC__)
__attribute__((visibility("hidden")))
#endif
IfsDoStep *ifs_do_step_choose(void);
#endif
/* n zeroed bytes from the instance's allocator (ctx: the IfsInstance): a saved state */
void *ifs_instance_calloc(void *ctx, size_t n);

/* --- FMU state: a tagged copy of the slave; the layers differ only in allocation --- */

#define IFS_STATE_MAGIC 0x49465332u   /* "IFS2" */
typedef struct {
    unsigned int magic;
    unsigned int size;
    char guid[40];             /* IFS_GUID: a state of this model and variable layout */
    IfsSlave s;
} IfsSavedState;

typedef void *(*IfsAlloc)(void *ctx, size_t n);

/* Copy the slave into *state, allocating it with alloc(ctx, n) if it is NULL; gam
 * brought up to date first where a mu change left it stale (the slave's too, so that
 * it steps on as the state restored will: the same numbers). */
int ifs_state_get(IfsSlave *s, const IfsLog *lg, const char *fn, void **state,
                  IfsAlloc alloc, void *ctx);
/* Restore the slave from a state of this FMU, its kept g and look-ahead with it
 * (IfsModel.g_ok: the steps after a restore give the numbers they gave after the
 * state was taken). */
int ifs_state_set(IfsSlave *s, const IfsLog *lg, const char *fn, const void *state);
int ifs_state_serialize(const IfsLog *lg, const char *fn, const void *state,
                        unsigned char bytes[], size_t size);
int ifs_state_deserialize(const IfsLog *lg, const char *fn, const unsigned char bytes[],
                          size_t size, void **state, IfsAlloc alloc, void *ctx);

/* --- what both FMI layers declare --- */

#if defined(_WIN32) && !defined(FMI2_FUNCTION_PREFIX) && !defined(FMI3_FUNCTION_PREFIX)
#define IFS_EXPORT __declspec(dllexport)
#elif defined(__GNUC__)
#define IFS_EXPORT __attribute__((visibility("default")))
#else
#define IFS_EXPORT
#endif

/* IFS_HOT (the DoStep functions compiled for AVX2 and the baseline): inflow_model.h */

#endif
