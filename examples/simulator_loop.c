/*
 * A simulator loop in C: a rigid airframe flown on the inflowsim FMU's rotor loads from
 * hover to forward flight (issue #10 part 6).  The C twin of simulator_loop.py.
 *
 *   cc -std=c99 -O2 -I UNZIPPED/sources -o simulator_loop examples/simulator_loop.c -ldl -lm
 *   ./simulator_loop BINARY.so GUID [OUT.csv]
 *
 * BINARY.so is binaries/linux64/inflowsim.so of an unzipped FMU (inflowsim fmu build),
 * GUID its modelDescription's guid; the value references come from the FMU's
 * sources/inflow_vars.h (IFS_VR_*, -I UNZIPPED/sources), as a simulator's FMU import
 * would generate them from its modelDescription.xml.
 *
 * Every frame (60 Hz): the airframe gives the FMU its hub motion and the autopilot's
 * controls (fmi2SetReal), the FMU steps (fmi2DoStep) and gives back the flap and the
 * loads (fmi2GetReal: CT and the flap springs' hub moments), and the airframe
 * integrates them.  The flight condition mu follows the airspeed every frame, with the
 * mass-flow speed through the disc (inflow_speed 1, ct), so one rotor flies in hover
 * and at speed (the autopilot asks for 55 m/s).
 *
 * The same loop as simulator_loop.py: the same airframe, autopilot and simplifications
 * (Puma mass and inertias, hub 2.16 m above the centre of mass, heading held, shaft
 * vertical, rotor force along the tip-path plane), the same 60 Hz frame and 45 s, and
 * the same rotor: simulator_loop_fmu.py builds the FMU from simulator_loop.py's
 * rotor_model() (glauert at its theory values, hover CT, mass-flow speed), whose
 * parameters and constants become the FMU's start values, and compiles this file
 * against that FMU's own sources/inflow_vars.h.  The two logs agree to rounding
 * (tests/test_simulator_loops.py).  On an FMU built with other parameters (the
 * default FMU carries the paper's Table 3 values) the same program flies that rotor.
 */
#define _POSIX_C_SOURCE 200809L
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "fmi2Functions.h"
#include "inflow_vars.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

#define G 9.81
#define RHO 1.225
#define MASS 5805.0
#define IXX 9638.0
#define IYY 33240.0
#define HUB 2.157
#define DRAG_AREA 2.5
#define R 7.5
#define OMEGA 27.5
#define FRAME (1.0 / 60.0)
#define V_TARGET 55.0

static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status,
                   fmi2String category, fmi2String message, ...)
{
    va_list ap;
    (void)env;
    (void)category;
    if (status == fmi2OK) return;
    va_start(ap, message);
    fprintf(stderr, "%s: ", name);
    vfprintf(stderr, message, ap);
    fprintf(stderr, "\n");
    va_end(ap);
}

static void *sym(void *lib, const char *name)
{
    void *p = dlsym(lib, name);
    if (!p) {
        fprintf(stderr, "missing %s\n", name);
        exit(2);
    }
    return p;
}

static double clip(double x, double lo, double hi) { return x < lo ? lo : x > hi ? hi : x; }

int main(int argc, char **argv)
{
    fmi2InstantiateTYPE *instantiate;
    fmi2SetupExperimentTYPE *setup;
    fmi2EnterInitializationModeTYPE *enter_init;
    fmi2ExitInitializationModeTYPE *exit_init;
    fmi2SetRealTYPE *set_real;
    fmi2SetIntegerTYPE *set_int;
    fmi2GetRealTYPE *get_real;
    fmi2DoStepTYPE *do_step;
    fmi2FreeInstanceTYPE *free_instance;
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    const fmi2ValueReference in[8] = {IFS_VR_theta0, IFS_VR_theta1c, IFS_VR_theta1s,
                                      IFS_VR_muz, IFS_VR_q, IFS_VR_p, IFS_VR_qdot,
                                      IFS_VR_pdot};
    const fmi2ValueReference out[5] = {IFS_VR_beta1c, IFS_VR_beta1s, IFS_VR_CT,
                                       IFS_VR_C_mc_hub, IFS_VR_C_ms_hub};
    const fmi2ValueReference vr_mu = IFS_VR_mu, vr_ct = IFS_VR_ct;
    const fmi2ValueReference vr_speed = IFS_VR_inflow_speed;
    const double qdyn = RHO * M_PI * R * R * (OMEGA * R) * (OMEGA * R);
    const double ct = MASS * G / qdyn;
    double u = 0, v = 0, w = 0, p = 0, q = 0, phi = 0, theta = 0, z = 0, wi = 0, ax = 0;
    double pdot = 0, qdot = 0, max_dz = 0, max_phi = 0, speed = 0, mu = 0;
    const int one = 1;
    long k, frames = (long)(45.0 / FRAME + 0.5);
    fmi2Component c;
    FILE *csv = NULL;
    void *lib;

    if (argc < 3) {
        fprintf(stderr, "usage: %s BINARY.so GUID [OUT.csv]\n", argv[0]);
        return 2;
    }
    lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        fprintf(stderr, "%s\n", dlerror());
        return 2;
    }
    *(void **)&instantiate = sym(lib, "fmi2Instantiate");
    *(void **)&setup = sym(lib, "fmi2SetupExperiment");
    *(void **)&enter_init = sym(lib, "fmi2EnterInitializationMode");
    *(void **)&exit_init = sym(lib, "fmi2ExitInitializationMode");
    *(void **)&set_real = sym(lib, "fmi2SetReal");
    *(void **)&set_int = sym(lib, "fmi2SetInteger");
    *(void **)&get_real = sym(lib, "fmi2GetReal");
    *(void **)&do_step = sym(lib, "fmi2DoStep");
    *(void **)&free_instance = sym(lib, "fmi2FreeInstance");
    if (argc > 3 && !(csv = fopen(argv[3], "w"))) {
        perror(argv[3]);
        return 2;
    }
    c = instantiate("loop", fmi2CoSimulation, argv[2], "", &cb, fmi2False, fmi2False);
    if (!c || setup(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) != fmi2OK ||
        enter_init(c) != fmi2OK || set_int(c, &vr_speed, 1, &one) != fmi2OK ||
        set_real(c, &vr_ct, 1, &ct) != fmi2OK || set_real(c, &vr_mu, 1, &mu) != fmi2OK ||
        exit_init(c) != fmi2OK) {
        fprintf(stderr, "FMU initialisation failed\n");
        return 1;
    }
    if (csv) fprintf(csv, "t,airspeed,mu,height,pitch,roll,theta0,theta1c,theta1s,"
                          "beta1c,beta1s,thrust,pitch_moment,roll_moment\n");
    for (k = 0; k < frames; k++) {
        const double t = k * FRAME;           /* time from the frame counter */
        const double speed_cmd = t < 2.0 ? 0.0 : fmin(V_TARGET, 2.5 * (t - 2.0));
        const double pitch_cmd = clip(-0.03 * (speed_cmd - u) + 0.004 * ax, -0.17, 0.1);
        double ctl[8], y[5], thrust, fx, fy, fz, m_pitch, m_roll, drag, ay, az, vz;
        ctl[0] = clip(0.02 * w + 0.004 * z + 0.01 * wi, -0.25, 0.25);
        ctl[1] = clip(0.5 * phi + 0.15 * p, -0.25, 0.25);    /* + rolls to port */
        ctl[2] = clip(-0.6 * (theta - pitch_cmd) - 0.25 * q, -0.25, 0.25);  /* + nose up */
        ctl[3] = w / (OMEGA * R);
        ctl[4] = q;
        ctl[5] = p;
        ctl[6] = qdot;
        ctl[7] = pdot;
        speed = hypot(u, v);
        mu = fmin(speed / (OMEGA * R), 0.5);
        if (set_real(c, &vr_mu, 1, &mu) != fmi2OK || set_real(c, in, 8, ctl) != fmi2OK ||
            do_step(c, t, FRAME, fmi2True) > fmi2Warning ||
            get_real(c, out, 5, y) != fmi2OK) {
            fprintf(stderr, "FMU step failed at t = %g s\n", t);
            return 1;
        }
        thrust = MASS * G + y[2] * qdyn;
        fx = thrust * y[0];                  /* tip-path plane tilt, body axes, z down */
        fy = -thrust * y[1];
        fz = -thrust;
        m_pitch = y[3] * qdyn * R - HUB * fx;
        m_roll = y[4] * qdyn * R + HUB * fy;
        drag = 0.5 * RHO * DRAG_AREA * speed;
        ax = fx / MASS - G * sin(theta) - drag * u / MASS - q * w;
        ay = fy / MASS + G * sin(phi) * cos(theta) - drag * v / MASS + p * w;
        az = fz / MASS + G * cos(phi) * cos(theta) + q * u - p * v;
        qdot = m_pitch / IYY;
        pdot = m_roll / IXX;
        u += ax * FRAME;
        v += ay * FRAME;
        w += az * FRAME;
        q += qdot * FRAME;
        p += pdot * FRAME;
        theta += q * cos(phi) * FRAME;
        phi += (p + q * sin(phi) * tan(theta)) * FRAME;
        vz = -u * sin(theta) + w * cos(theta) * cos(phi);
        z += vz * FRAME;
        wi += z * FRAME;
        if (fabs(z) > max_dz) max_dz = fabs(z);
        if (fabs(phi) > max_phi) max_phi = fabs(phi);
        if (csv)
            fprintf(csv, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
                         "%.17g,%.17g,%.17g,%.17g\n", t + FRAME, speed, mu, -z, theta,
                    phi, ctl[0], ctl[1], ctl[2], y[0], y[1], thrust, m_pitch, m_roll);
    }
    free_instance(c);
    if (csv) fclose(csv);
    printf("frames: %ld at %.0f Hz\n", frames, 1.0 / FRAME);
    printf("final airspeed %.1f m/s (mu %.3f), height change %+.1f m, pitch %+.1f deg, "
           "roll %+.1f deg\n", speed, mu, -z, theta * 180 / M_PI, phi * 180 / M_PI);
    printf("largest height excursion %.1f m, largest roll %.1f deg\n", max_dz,
           max_phi * 180 / M_PI);
    return 0;
}
