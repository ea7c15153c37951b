"""``servo-actuators``: second-order swashplate servo dynamics between each recorded
control and the blade pitch.

A helicopter's recorded controls are the servo *commands* (or the pilot's stick);
the blades follow through the swashplate servo actuators.  With identical servos,
each multiblade pitch (a fixed linear combination of the three servo positions)
follows its command through the same dynamics (``model.md`` section 9.2)::

    T^2 theta_a'' + 2 zeta T theta_a' + theta_a = theta_cmd        (seconds)

with ``T = 1/omega_n`` the servo's time constant [s] and ``zeta`` its damping [-];
the flap and inflow equations and the loads see ``theta_a`` where the basic model
saw the recorded pitch.  In azimuth time ``T_az = T Omega``.  The states appended
(:class:`~inflowsim.model.equations.StateBlock`): ``theta0_a, theta1c_a,
theta1s_a`` and their azimuth rates.

At low frequency the servo is a pure delay of ``2 zeta T`` (the phase
``-2 zeta T omega``); its gain droop ``1 - (1 - 2 zeta^2) (T omega)^2`` and the
curvature of its phase tell it apart from :mod:`.time_delay` only where the
record's band reaches ``omega T ~ 0.3`` or so; the diagnosis says where they are
indistinguishable (``workflow.md``).

Parameter ``servo_tau`` [s]: ``1/omega_n``; the structure without the effect is its
boundary ``servo_tau -> 0`` (``FLOOR``, 5 us: at 5 Hz a phase lag of 2e-4 rad), as
``flap-inertia``'s, so the likelihood-ratio test is nested with the 50:50
chi-square mixture.  Theory (typical hydraulic main-rotor servos, Tischler &
Remple, *Aircraft and Rotorcraft System Identification*, 2nd ed., ch. 11: second
order, ``omega_n`` 30-60 rad/s, ``zeta`` about 0.7): ``servo_tau = 0.02`` s,
``servo_zeta = 0.7``.  ``servo_zeta`` is a separate part: a record whose band
leaves it undetermined still tests ``servo_tau`` with it held at 0.7; it acts
only through ``servo_tau`` (nothing at the floor), so the diagnosis tries it once
``servo_tau`` is in (``Effect.parts_in_order``).
"""
import numpy as np

from ._effect import Effect
from ..equations import StateBlock
from ..params import ParameterSpec

NAME = "servo-actuators"
#: The smallest servo time constant a model is built with [s]: the direct limit.
FLOOR = 5e-6
#: Appended states: the servos' output pitch, then its azimuth rates.
STATES = ("theta0_a", "theta1c_a", "theta1s_a",
          "theta0_a_prime", "theta1c_a_prime", "theta1s_a_prime")


def block(servo_tau, servo_zeta, omega, n_inputs: int = 10) -> StateBlock:
    """The servos' :class:`StateBlock` (azimuth time) for ``servo_tau`` [s],
    ``servo_zeta`` [-] and rotor speed ``omega`` [rad/s]."""
    t = servo_tau * omega
    z3, i3 = np.zeros((3, 3)), np.eye(3)
    e = np.block([[i3, z3], [z3, t * t * i3]])
    a = np.block([[z3, i3], [-i3, -2.0 * servo_zeta * t * i3]])
    b = np.vstack([np.zeros((3, n_inputs)),
                   np.hstack([i3, np.zeros((3, n_inputs - 3))])])
    zero = np.zeros((3, 6))
    return StateBlock(effect=NAME, states=STATES, e=e, a=a, a_z=np.zeros((6, 9)), b=b,
                      f_x=zero, l_x=zero, through=((0, 0), (1, 1), (2, 2)))


def _equations(eq, p, k):
    bl = block(p["servo_tau"], p["servo_zeta"], k.omega, eq.h_u.shape[1])
    return eq.with_(blocks=eq.blocks + (bl,))


EFFECT = Effect(
    name=NAME,
    physics="The swashplate servo actuators lag the recorded controls: the blades' "
            "pitch follows each command through second-order dynamics (natural "
            "frequency 1/servo_tau, damping servo_zeta).",
    paper="extension (servo actuators between the recorded control and the blade pitch)",
    parameters=("servo_tau", "servo_zeta"),
    theory=lambda k: {"servo_tau": 0.02, "servo_zeta": 0.7},
    neutral=lambda k: {"servo_tau": FLOOR, "servo_zeta": 0.7},
    equations=_equations,
    specs=(ParameterSpec("servo_tau", "s", "servo actuators' time constant 1/omega_n",
                         FLOOR, 1.0, plausible=(0.004, 0.1, "hydraulic main-rotor "
                         "servos: omega_n 10-250 rad/s")),
           ParameterSpec("servo_zeta", "-", "servo actuators' damping ratio", 0.05, 5.0,
                         plausible=(0.3, 2.0, "a servo loop is neither near "
                                    "oscillation nor an overdamped crawl"))),
    boundary=("servo_tau",),
    parts=(("servo_tau",), ("servo_zeta",)),
    parts_in_order=True,
    # asked for by name (--also) until a detection study of its own has passed
    states=STATES,
    replaces_inputs=(("theta0", "theta0_a"), ("theta1c", "theta1c_a"),
                     ("theta1s", "theta1s_a")),
)


__all__ = ["NAME", "FLOOR", "STATES", "block", "EFFECT"]
