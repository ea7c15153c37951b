"""``pitch-flap-coupling``: a user effect, written only through inflowsim's public
effect interface (``docs/workflow.md``, "Writing your own effect").

Pitch-flap coupling (delta-3): the pitch-link geometry makes a blade that flaps up
lose pitch, ``theta_blade = theta - k3 beta`` with ``k3 = tan(delta3)``.  For each
multiblade component the flap equation (1) and the loads (4) then see the pitch
``theta - k3 beta`` wherever they see the pitch: with ``H`` and ``P`` the pitch
columns of the flap and inflow equations (every effect applied before this one
included), the flap equation gains ``-k3 H beta`` and the inflow equation
``-k3 P beta``.  Where the structure has ``azimuth-bias`` the model's pitch columns
take the *recorded* pitch; the coupling acts on the true pitch, so the columns are
turned back to true-pitch ones first (``R(dpsi)``).

Use it::

    inflowsim ladder RECORD.csv --model basic+glauert \\
        --effect-file examples/effects/pitch_flap_coupling.py
    inflowsim identify RECORD.csv --model basic+glauert+pitch-flap-coupling \\
        --effect-file examples/effects/pitch_flap_coupling.py
"""
import numpy as np

from inflowsim.model.effects import Effect, ParameterSpec
from inflowsim.model.equations import rotation


def true_pitch_columns(block, azimuth_bias):
    """The pitch columns of an input block, per *true* pitch (recorded cyclic pitch
    is the true one rotated by ``R(azimuth_bias)``)."""
    cols = np.array(block[:, 0:3], dtype=float)
    cols[:, 1:3] = cols[:, 1:3] @ rotation(azimuth_bias)
    return cols


def equations(eq, p, k):
    """``theta -> theta - k3 beta`` in the flap and inflow equations (pure)."""
    k3 = p["k3"]
    dpsi = p.get("azimuth_bias", 0.0)
    h_theta = true_pitch_columns(eq.h_u, dpsi)
    p_theta = true_pitch_columns(eq.p_u, dpsi)
    # C beta' + D beta = H (theta - k3 beta) + ...: the flap term moves into D
    return eq.with_(d=eq.d + k3 * h_theta, p_beta=eq.p_beta - k3 * p_theta)


EFFECT = Effect(
    name="pitch-flap-coupling",
    physics="Pitch-flap coupling (delta-3): a blade flapping up loses pitch, "
            "theta - k3 beta per multiblade component, an aerodynamic spring on the "
            "flap and a flap-driven change of the rotor loads.",
    paper="extension: the paper's blade has no pitch-flap coupling",
    parameters=("k3",),
    theory=lambda k: {"k3": 0.0},
    neutral=lambda k: {"k3": 0.0},
    equations=equations,
    specs=(ParameterSpec("k3", "-", "pitch-flap coupling tan(delta3): blade pitch "
                         "theta - k3 beta", -2.0, 2.0,
                         plausible=(-0.2, 1.0, "delta-3 angles of 0 to 45 deg give "
                                               "tan(delta3) from 0 to 1")),),
)
