"""A simulator loop: a rigid airframe flown with inflowsim's rotor loads from hover to
forward flight (issue #10 part 6, Python).

    python examples/simulator_loop.py [OUTDIR]

Every frame (60 Hz) the airframe gives the rotor its hub motion and the pilot's controls,
the rotor (``Simulator``: Glauert inflow, Puma theory values) steps once and gives back
its loads (``Simulator.loads()``: thrust and the flap springs' hub moments), and the
airframe integrates them. The flight condition follows the airspeed every frame
(``set_mu``) with the mass-flow speed through the disc, so the same rotor flies in hover
and at 55 m/s. Writes ``OUTDIR/simulator_loop.png`` (default ``inflowsim-simulator-loop`` in the
system's temporary folder).

``simulator_loop.c`` is the same loop in C on the FMU: ``simulator_loop_fmu.py`` builds
the FMU from :func:`rotor_model` and runs it; same inputs, model, step and duration,
and the two logs agree to rounding (``tests/test_simulator_loops.py``).

The airframe is deliberately simple, and says so: Puma mass and inertias (Padfield,
*Helicopter Flight Dynamics*, Puma data), rotor hub 2.16 m above the centre of mass, a
fuselage flat-plate drag area of 2.5 m^2, heading held (no yaw), shaft vertical in body
axes; the rotor force is the thrust tilted with the tip-path plane (``beta1c, beta1s``).
The rotor model is linear about the hover trim (thrust equal to weight, no trim
flapping); its perturbations carry the manoeuvre. A simple autopilot flies it: altitude
on collective, pitch attitude from a speed command on longitudinal cyclic, wings level
on lateral cyclic.
"""
from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

import numpy as np

from inflowsim.model.build import build_model
from inflowsim.model.loads import dimensional_loads
from inflowsim.model.params import Constants
from inflowsim.model.presets import theory_parameters
from inflowsim.report.plots import new_figure, save_png
from inflowsim.simulate.simulator import Simulator

G, RHO = 9.81, 1.225
MASS, IXX, IYY = 5805.0, 9638.0, 33240.0     # kg, kg m^2 (Puma)
HUB = 2.157                                  # hub above the centre of mass [m]
DRAG_AREA = 2.5                              # fuselage flat-plate area [m^2]
R, OMEGA = 7.5, 27.5
FRAME = 1.0 / 60.0
V_TARGET = 55.0                              # [m/s], mu = 0.27


def rotor_model():
    """The rotor both loops fly: ``glauert`` at its theory values, hover thrust
    coefficient, mass-flow speed through the disc (``simulator_loop_fmu.py`` builds
    the FMU from this same model)."""
    ct = MASS * G / (RHO * math.pi * R**2 * (OMEGA * R) ** 2)
    k = Constants(mu=0.0, a0=5.73, solidity=0.0917, omega=OMEGA, radius=R, ct=ct,
                  inflow_speed="mass-flow").check()
    return build_model("glauert", theory_parameters("glauert", k), k)


def rotor():
    return Simulator(rotor_model(), FRAME)


def autopilot(s, t):
    """Controls [rad] from the airframe state: altitude hold, speed to pitch attitude,
    wings level."""
    speed_cmd = 0.0 if t < 2.0 else min(V_TARGET, 2.5 * (t - 2.0))
    pitch_cmd = float(np.clip(-0.03 * (speed_cmd - s["u"]) + 0.004 * s["ax"], -0.17, 0.1))
    theta0 = 0.02 * s["w"] + 0.004 * (s["z"] - 0.0) + 0.01 * s["wi"]
    # positive theta1s tilts the disc back (nose up); positive theta1c rolls to port
    theta1s = -0.6 * (s["theta"] - pitch_cmd) - 0.25 * s["q"]
    theta1c = 0.5 * s["phi"] + 0.15 * s["p"]
    return np.clip([theta0, theta1c, theta1s], -0.25, 0.25)


def fly(duration=45.0):
    sim = rotor()
    s = dict(u=0.0, v=0.0, w=0.0, p=0.0, q=0.0, phi=0.0, theta=0.0, z=0.0, wi=0.0,
             ax=0.0, pdot=0.0, qdot=0.0)
    thrust0 = MASS * G
    log = []
    for k in range(int(round(duration / FRAME))):
        t = k * FRAME                              # time from the frame counter
        speed = math.hypot(s["u"], s["v"])
        sim.set_mu(min(speed / (OMEGA * R), 0.5))
        ctl = autopilot(s, t)
        u = np.zeros(sim.m)
        names = sim.model.inputs
        u[names.index("theta0")], u[names.index("theta1c")], u[names.index("theta1s")] = ctl
        u[names.index("muz")] = s["w"] / (OMEGA * R)
        u[names.index("q")], u[names.index("p")] = s["q"], s["p"]
        u[names.index("qdot")], u[names.index("pdot")] = s["qdot"], s["pdot"]
        y = sim.step(u)
        loads = dimensional_loads(sim.loads(), sim.model.constants, RHO)
        thrust = thrust0 + loads["T"]
        b1c, b1s = y[1], y[2]
        fx, fy, fz = thrust * b1c, -thrust * b1s, -thrust   # body axes, z down
        m_pitch = loads["M_pitch_hub"] - HUB * fx
        m_roll = loads["M_roll_hub"] + HUB * fy
        # airframe (heading held): translational and rotational, body axes
        drag = 0.5 * RHO * DRAG_AREA * speed
        ax = fx / MASS - G * math.sin(s["theta"]) - drag * s["u"] / MASS - s["q"] * s["w"]
        ay = (fy / MASS + G * math.sin(s["phi"]) * math.cos(s["theta"])
              - drag * s["v"] / MASS + s["p"] * s["w"])
        az = (fz / MASS + G * math.cos(s["phi"]) * math.cos(s["theta"])
              + s["q"] * s["u"] - s["p"] * s["v"])
        s["qdot"], s["pdot"] = m_pitch / IYY, m_roll / IXX
        s["u"] += ax * FRAME
        s["v"] += ay * FRAME
        s["w"] += az * FRAME
        s["q"] += s["qdot"] * FRAME
        s["p"] += s["pdot"] * FRAME
        s["theta"] += s["q"] * math.cos(s["phi"]) * FRAME
        s["phi"] += (s["p"] + s["q"] * math.sin(s["phi"]) * math.tan(s["theta"])) * FRAME
        vz = (-s["u"] * math.sin(s["theta"]) + s["w"] * math.cos(s["theta"])
              * math.cos(s["phi"]))                       # down, earth axes
        s["z"] += vz * FRAME
        s["wi"] += s["z"] * FRAME
        s["ax"] = ax
        log.append((t + FRAME, speed, sim.model.constants.mu, -s["z"], s["theta"],
                    s["phi"], *ctl, b1c, b1s, thrust, m_pitch, m_roll))
    return np.array(log)


def plot(log, path):
    """The flight, one quantity per axis: speed and height; attitudes and controls
    [deg]; flap [deg]; thrust [kN]; hub moments [kN m] (thrust and moments apart:
    they differ in unit and size)."""
    fig, ax = new_figure(5, 1, size=(8.0, 12.0))
    t = log[:, 0]
    ax[0, 0].plot(t, log[:, 1], label="airspeed [m/s]")
    ax[0, 0].plot(t, 100 * log[:, 2], label="mu x 100 [-]")
    ax[0, 0].plot(t, log[:, 3], label="height change [m]")
    ax[0, 0].set_ylabel("speed [m/s], height [m]")
    ax[1, 0].plot(t, np.degrees(log[:, 4]), label="pitch attitude")
    ax[1, 0].plot(t, np.degrees(log[:, 5]), label="roll attitude")
    for j, n in enumerate(("theta0", "theta1c", "theta1s")):
        ax[1, 0].plot(t, np.degrees(log[:, 6 + j]), "--", label=n)
    ax[1, 0].set_ylabel("attitude, control [deg]")
    ax[2, 0].plot(t, np.degrees(log[:, 9]), label="beta1c")
    ax[2, 0].plot(t, np.degrees(log[:, 10]), label="beta1s")
    ax[2, 0].set_ylabel("flap [deg]")
    ax[3, 0].plot(t, log[:, 11] / 1e3, color="k", label="thrust")
    ax[3, 0].set_ylabel("thrust [kN]")
    ax[4, 0].plot(t, log[:, 12] / 1e3, label="pitch moment")
    ax[4, 0].plot(t, log[:, 13] / 1e3, label="roll moment")
    ax[4, 0].set_ylabel("hub moment [kN m]")
    ax[4, 0].set_xlabel("time [s]")
    for a in ax[:, 0]:
        a.grid(True, alpha=0.3)
        a.legend(fontsize="small", loc="best")
    fig.suptitle("Hover to forward flight: airframe flown with inflowsim's rotor loads")
    return save_png(fig, path)


def main(argv):
    # default: a temporary folder, never the repository (issue #39)
    out = Path(argv[1] if len(argv) > 1 else Path(tempfile.gettempdir()) / "inflowsim-simulator-loop")
    out.mkdir(parents=True, exist_ok=True)
    log = fly()
    path = plot(log, out / "simulator_loop.png")
    end = log[-1]
    print(f"frames: {len(log)} at {1 / FRAME:.0f} Hz")
    print(f"final airspeed {end[1]:.1f} m/s (mu {end[2]:.3f}), height change "
          f"{end[3]:+.1f} m, pitch {math.degrees(end[4]):+.1f} deg, "
          f"roll {math.degrees(end[5]):+.1f} deg")
    print(f"largest height excursion {np.max(np.abs(log[:, 3])):.1f} m, "
          f"largest roll {math.degrees(np.max(np.abs(log[:, 5]))):.1f} deg")
    print(f"plot: {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
