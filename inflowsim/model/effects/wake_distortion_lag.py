"""``wake-distortion-lag``: the wake's curvature follows the disc's rates with a lag
(Zhao, Prasad and Peters 2004, JAHS 49(4): dynamic wake distortion).

``wake-distortion`` bends the wake at once: the cyclic inflow gains ``K_R (q_tpp,
p_tpp)`` with the tip-path plane's rates ``q_tpp = qbar - beta1c'``, ``p_tpp = pbar
- beta1s'``.  A wake cannot bend faster than it is carried away: Zhao et al. let the
curvature follow the rates through a first-order lag.  With this effect the
gradient is ``K_R (kappa_q, kappa_p)``, two appended states
(:class:`~inflowsim.model.equations.StateBlock`, azimuth time)::

    tau_w kappa_q' + kappa_q = qbar - beta1c'
    tau_w kappa_p' + kappa_p = pbar - beta1s'

and ``wake-distortion``'s direct term is taken out (``model.md``, *Wake
distortion*).  It acts only beside ``wake-distortion`` (it needs ``K_R``); alone its
states are driven and reach nothing.

Parameter ``tau_w`` [azimuth rad]: the curvature's lag; the structure without the
effect is its boundary ``tau_w -> 0`` (:data:`FLOOR`), so the test is nested with
the 50:50 chi-square mixture, as ``flap-inertia``'s.  Theory: the time the wake
takes to travel one radius, ``1 / V_T`` with ``V_T = sqrt(mu^2 + (lambda0 -
muz)^2)`` at the trim (as ``wake-distortion``'s skew angle; with neither trim nor
``ct``, ``1 / mu``): an order of magnitude, not a published value.
"""
import math

import numpy as np

from ._effect import Effect
from . import wake_distortion as wd
from ..equations import StateBlock
from ..params import ParameterSpec

NAME = "wake-distortion-lag"
#: The smallest lag a model is built with [azimuth rad]: the direct limit (1e-6 rad
#: of phase per unit rate at 1/rev).
FLOOR = 1e-6
#: Appended states: the rates the wake's curvature has reached [rad / azimuth rad].
STATES = ("wake_kappa_q", "wake_kappa_p")


def block(tau_w, k_r, n_inputs: int = 10) -> StateBlock:
    """The curvature lag's :class:`StateBlock` for ``tau_w`` [azimuth rad] and the
    gain ``k_r`` into the cyclic inflow rows (0: the states reach nothing)."""
    e = tau_w * np.eye(2)
    a = -np.eye(2)
    a_z = np.zeros((2, 9))                     # z = (beta, lambda, beta')
    a_z[0, 7] = -1.0                           # - beta1c'
    a_z[1, 8] = -1.0                           # - beta1s'
    b = np.zeros((2, n_inputs))
    b[0, wd.QBAR] = 1.0
    b[1, wd.PBAR] = 1.0
    l_x = np.array([[0 * k_r, 0 * k_r], [k_r, 0 * k_r], [0 * k_r, k_r]])
    return StateBlock(effect=NAME, states=STATES, e=e, a=a, a_z=a_z, b=b,
                      f_x=np.zeros((3, 2)), l_x=l_x)


def _equations(eq, p, k):
    kr = p.get("K_R", 0.0)
    if "K_R" in p:
        # wake-distortion's direct term (applied before: catalogue order) moves into
        # the lagged states
        p_dbeta, p_u = eq.p_dbeta.copy(), eq.p_u.copy()
        p_u[wd.L1C, wd.QBAR] -= kr
        p_u[wd.L1S, wd.PBAR] -= kr
        p_dbeta[wd.L1C, wd.B1C] += kr
        p_dbeta[wd.L1S, wd.B1S] += kr
        eq = eq.with_(p_dbeta=p_dbeta, p_u=p_u)
    return eq.with_(blocks=eq.blocks + (block(p["tau_w"], kr, eq.h_u.shape[1]),))


def transport_speed(k) -> float:
    """``V_T = sqrt(mu^2 + (lambda0 - muz)^2)`` [-] at the trim (or the mass-flow
    momentum inflow); ``mu`` where neither is known."""
    chi = wd.skew_angle(k)
    if k.mu > 0:
        return k.mu / max(math.sin(chi), 1e-12)
    from ...physics import loads as ld
    return ld.momentum_inflow(0.0, k.ct) if k.ct is not None else 1.0


EFFECT = Effect.of_one(
    name=NAME,
    physics="The wake's curvature lags the disc's pitch and roll rate (it cannot bend "
            "faster than it is carried away): wake-distortion's gradient through a "
            "first-order lag tau_w (with wake-distortion).",
    paper="extension (Zhao, Prasad and Peters 2004, dynamic wake distortion)",
    theory=lambda k: 1.0 / transport_speed(k),
    neutral=FLOOR,
    equations=_equations,
    offered=False,
    boundary=("tau_w",),
    spec=ParameterSpec("tau_w", "azimuth rad", "wake curvature's lag (Zhao et al.)",
                       FLOOR, 1e3, plausible=(0.0, 1.5, "the wake's transport over "
                                              "about a radius: under 1 s for "
                                              "full-scale rotors"),
                       plausible_seconds=True),
    states=STATES,
)


__all__ = ["NAME", "FLOOR", "STATES", "block", "transport_speed", "EFFECT"]
