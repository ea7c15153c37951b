"""``wake-distortion``: the wake bent by the rotor's pitch and roll rate (``K_R``).

A rotor pitching or rolling sheds each part of its wake from the tip-path plane it
had at that moment; the induced velocity carries it away along that plane's normal,
so the older wake lags behind the disc's rotation and the wake curves (Keller 1996,
JAHS 41(4); Krothapalli, Prasad and Peters 2001, JAHS 46(2); Zhao, Prasad and
Peters 2004, JAHS 49(4)).  A nose-up rate bends it aft and raises the inflow at the
rear of the disc, a roll to starboard bends it to starboard.  Keller's form adds
to the quasi-steady inflow a gradient proportional to the tip-path plane's rate:

``D_tau lambda' + lambda = ... + K_R (0, q_tpp, p_tpp)``,
``q_tpp = qbar - beta1c'``, ``p_tpp = pbar - beta1s'``

(``model.md``, *Wake distortion*; azimuth time, rates over ``Omega``).  With
``psi = 0`` aft and down positive, ``K_R > 0``.  The rates are the tip-path plane's
(the wake leaves the blade tips): ``beta1c > 0`` tilts the disc nose down, so its
nose-up rate is ``qbar - beta1c'``; ``beta1s > 0`` tilts it to port, so its roll rate
is ``pbar - beta1s'`` (Zhao et al.; at low frequency the plane follows the shaft).

The term is part of Glauert's ``k0 (q* - lambda1c)``, ``k0 (p* - lambda1s)`` (Eq. 19:
``q* = qbar - beta1c' - beta1s + theta1c``), not a multiple of it: Glauert's adds the
blade's angle of attack in the tip-path plane (``theta1c - beta1s - lambda1c``),
which the flap equation ties to the other axis's rate.  The two are estimated
together (``tests/test_wake_distortion.py`` measures their correlation).

Parameter ``K_R`` [-], neutral 0.  Theory ``K_R(chi)``: the vortex-tube value of the
kinematic wake above (1.49 in hover, Keller's 1.5), falling with the wake skew
angle ``chi`` as :data:`SKEW_TABLE` (``tan chi = mu / (lambda0 - muz)`` from the
record's trim as ``skewed-wake`` takes it, or from the mass-flow momentum inflow
with ``ct``; without either the edgewise limit ``chi = 90 deg``, where the induced
transport and the curvature vanish: ``K_R = 0``).
"""
import math

import numpy as np

from ._effect import Effect
from ...physics import bladeelement as be
from ...physics import loads as ld
from ..params import ParameterSpec

#: Keller's hover wake-curvature gain (1996); the vortex-tube computation of this
#: project's ``tests/test_wake_distortion.py`` gives 1.49.
KELLER_HOVER = 1.5

#: ``(chi [deg], K_R)``: the wake-curvature gain of the kinematic vortex tube at wake
#: skew ``chi``, the mean of its pitch (``lambda1c`` per ``q_tpp``) and roll
#: (``lambda1s`` per ``p_tpp``) gains (``model.md``, *Wake distortion*, where both are
#: tabulated; ``tests/test_wake_distortion.py`` recomputes them).  Beyond 75 deg the
#: mean is within 0.06 of zero (-0.05 at 85 deg): held at 0, the edgewise limit.
SKEW_TABLE = ((0.0, 1.49), (15.0, 1.30), (30.0, 0.84), (40.0, 0.51), (50.0, 0.25),
              (65.0, 0.04), (75.0, 0.0), (90.0, 0.0))

# state / input column indices (azimuth units)
B1C, B1S, L1C, L1S = 1, 2, 1, 2
QBAR, PBAR = 4, 5


def _equations(eq, p, k):
    kr = p["K_R"]
    p_dbeta, p_u = eq.p_dbeta.copy(), eq.p_u.copy()
    p_u[L1C, QBAR] += kr
    p_u[L1S, PBAR] += kr
    p_dbeta[L1C, B1C] -= kr
    p_dbeta[L1S, B1S] -= kr
    return eq.with_(p_dbeta=p_dbeta, p_u=p_u)


def skew_angle(k) -> float:
    """Wake skew angle ``chi`` [rad] of constants ``k``: from the trim (as
    ``skewed-wake``), else from the mass-flow momentum inflow, else 90 deg."""
    if k.trim is not None and all(n in k.trim for n in be.TRIM_KEYS):
        theta, beta, muz = be.trim_state(k.trim, EFFECT.name)
        lam = be.trim_inflow(k.mu, k.a0s, theta, beta, muz, k.flow_speed)
        return be.wake_skew_angle(k.mu, float(lam[0]), muz)
    if k.ct is not None:
        return be.wake_skew_angle(k.mu, ld.momentum_inflow(k.mu, k.ct), 0.0)
    return math.pi / 2


def keller_gain(chi: float) -> float:
    """``K_R`` [-] at wake skew ``chi`` [rad] (:data:`SKEW_TABLE`, linear between)."""
    deg, val = np.array(SKEW_TABLE).T
    return float(np.interp(min(abs(math.degrees(chi)), 90.0), deg, val))


EFFECT = Effect.of_one(
    name="wake-distortion",
    physics="The rotor's pitch and roll rate bend its wake (each part shed from the "
            "tip-path plane of its moment), which adds an inflow gradient along the "
            "rate: nose-up raises the inflow at the rear of the disc (Keller's K_R).",
    paper="extension (Keller 1996; Krothapalli, Prasad and Peters 2001; Zhao, Prasad "
          "and Peters 2004)",
    theory=lambda k: keller_gain(skew_angle(k)),
    neutral=0.0,
    equations=_equations,
    # offered by default: the detection study of bench/wake.md
    offered=True,
    spec=ParameterSpec("K_R", "-", "wake-curvature gain: cyclic inflow per tip-path "
                       "plane pitch and roll rate (Keller)", -20.0, 20.0,
                       plausible=(0.0, 2.5, "the kinematic wake's vortex tube gives "
                                            "1.5 in hover (Keller), less as the wake "
                                            "skews; correlations with flight data "
                                            "use 1-2")),
)


__all__ = ["KELLER_HOVER", "SKEW_TABLE", "skew_angle", "keller_gain", "EFFECT"]
