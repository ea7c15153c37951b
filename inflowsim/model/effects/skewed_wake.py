"""``skewed-wake``: Pitt-Peters wake-skew coupling between ``lambda0`` and ``lambda1c``.

The paper's local-momentum gain ``L = diag(a0 s/(2 mu), -2 a0 s/mu, -2 a0 s/mu)``
(``model.md`` section 3) is diagonal.  Pitt and Peters' gain matrix (wake skew
angle ``chi`` from the disc normal, ``tan chi = mu/(lambda0 - muz)`` at trim) adds
the off-diagonal pair ``15 pi/64 tan(chi/2) / V`` between the mean inflow and the
longitudinal gradient.  With ``V ~ mu`` as in the paper's ``L``, this effect makes

``L -> L + k_skew (a0 s/mu) [[0, 1, 0], [1, 0, 0], [0, 0, 0]]``

so every ``L c`` term of the inflow equation (Eq. 2, through ``G_beta'``,
``G_beta``, ``G_theta``, ``G_nu``, ``G_lambda``) gains ``dL c``, with
``c = (C_T, C_mc, C_ms)/(a0 s)``.

Signs, in this model's conventions (``psi = 0`` aft, ``lambda_i = lambda0 +
lambda1c r cos psi + lambda1s r sin psi``, down positive; ``C_mc`` pitch nose up):

* ``lambda1c += k_skew C_T / mu``.  Uniform loading in edgewise flight gives more
  downwash at the rear of the disc (Glauert, Coleman): ``lambda1c / lambda0 =
  (15 pi/32) tan(chi/2) > 0`` with ``psi = 0`` aft, which is this row with
  ``lambda0 = C_T/(2 mu)``.
* ``lambda0 += k_skew C_mc / mu``.  A loading element's wake is swept aft, so it
  induces more downwash downstream of itself than upstream.  A nose-up moment
  (``C_mc > 0``) loads the front of the disc, whose wake then passes under the
  rear: the mean downwash rises.  Pitt-Peters write the pair symmetrically in
  ``(C_T, C_M)`` with ``C_M`` nose up, the same sign.  (In pressure-conjugate
  variables, ``C_T`` and the aft-loading moment ``-C_mc``, the pair is
  antisymmetric: the wake skew makes the influence non-reciprocal.)

Only the off-diagonal pair is added: the diagonal stays the paper's local momentum
(``V ~ mu``) so that ``k_skew = 0`` is exactly the structure without the effect.
The Peters-He effects (``peters-he-6/10/15``) carry this pair themselves, in their
forward-flight gain ``L(X)`` with the higher states' skew: they are alternatives of
this effect (``model.md`` 9.4).

Parameter ``k_skew`` [-]: the coupling gain itself, neutral 0.  Theory value
``15 pi/64 tan(chi/2)``: with the record's trim (``Constants.trim``) ``chi`` uses
the trim inflow of :func:`inflowsim.physics.bladeelement.trim_inflow` and the trim
``muz``; without it, ``chi = 90 deg``, the edgewise limit the paper's ``V ~ mu``
already assumes (``k_skew = 15 pi/64 = 0.736``).  For the Puma at 100 kt with the
virtual trim (``theta0 = 0.17 rad``, ``muz = 0``) ``chi = 84.7 deg`` and
``k_skew = 0.672``.
"""
import math

import numpy as np

from ._effect import Effect
from ...physics import bladeelement as be
from ...physics import loads as ld
from ..equations import rotation
from ..params import ParameterSpec


#: Where the coupling sits in L: (lambda0, C_mc) and (lambda1c, C_T).
SKEW = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])


def skew_l(k_skew: float, v: float, a0s: float) -> np.ndarray:
    """The added gain ``dL = k_skew (a0 s/V) SKEW`` [-], ``V`` the speed through the
    disc of the base model's ``L`` (``mu``, or the mass-flow speed)."""
    return k_skew * a0s / v * SKEW


def _equations(eq, p, k):
    mu = k.mu
    dl = skew_l(p["k_skew"], k.flow_speed, k.a0s)
    p_u = eq.p_u.copy()
    gt = dl @ ld.g_theta(mu)
    # effects apply in catalogue order, after azimuth-bias: its pitch rotation
    # (true pitch = R(-dpsi) recorded) must reach this effect's theta columns too
    if "azimuth_bias" in p:
        gt[:, 1:3] = gt[:, 1:3] @ rotation(-p["azimuth_bias"])
    p_u[:, 0:3] += gt
    p_u[:, 3:6] += dl @ ld.g_nu(mu)
    return eq.with_(p_dbeta=eq.p_dbeta + dl @ ld.g_dbeta(mu),
                    p_beta=eq.p_beta + dl @ ld.g_beta(mu),
                    p_lambda=eq.p_lambda + dl @ ld.g_lambda(mu), p_u=p_u)


def theory_skew(k) -> float:
    """``15 pi/64 tan(chi/2)`` for constants ``k`` (trim if given, else 90 deg)."""
    if k.trim is None or any(n not in k.trim for n in be.TRIM_KEYS):
        return be.pitt_peters_skew_gain(math.pi / 2)
    theta, beta, muz = be.trim_state(k.trim, EFFECT.name)
    lam = be.trim_inflow(k.mu, k.a0s, theta, beta, muz, k.flow_speed)
    return be.pitt_peters_skew_gain(be.wake_skew_angle(k.mu, lam[0], muz))


EFFECT = Effect.of_one(
    name="skewed-wake",
    physics="The wake is swept aft in forward flight: thrust raises the inflow at the "
            "rear of the disc and a nose-up moment raises the mean inflow (Pitt-Peters "
            "coupling of lambda0 and lambda1c).",
    paper="extension (Pitt-Peters gain matrix)",
    theory=theory_skew,
    neutral=0.0,
    equations=_equations,
    spec=ParameterSpec("k_skew", "-", "Pitt-Peters wake-skew coupling 15 pi/64 "
                       "tan(chi/2) between lambda0 and lambda1c", -10.0, 10.0,
                       plausible=(0.0, 1.5, "Pitt-Peters 15 pi/64 tan(chi/2) is positive "
                                            "and below 15 pi/64")),
)


__all__ = ["SKEW", "skew_l", "theory_skew", "EFFECT"]
