"""``advance-ratio-perturbation``: in-plane velocity acts on the blades directly.

The paper holds ``mu`` constant: in-plane velocity perturbations ``mux``, ``muy``
reach the model only through the inflow (``hub-velocity-coupling``, ``glauert``).
But they change the blade velocities themselves (``workflow.md``):
``U_T = r + (mu + mux) sin psi + muy cos psi`` and ``- beta ((mu + mux) cos psi -
muy sin psi)`` in ``U_P``.  Linearising the flap equation (1) and the loads (4)
about the trim state gives new ``mux, muy`` input columns in BOTH

* the flap rows: ``H_u[:, mux:muy] += k_mu n_beta H_mu`` with ``H_mu`` of
  :func:`inflowsim.physics.bladeelement.inplane_flap_derivatives`, and
* the inflow forcing: ``P_u[:, mux:muy] += k_mu L dc/dmu_xy`` with ``dc/dmu_xy`` of
  :func:`inflowsim.physics.bladeelement.inplane_load_derivatives`.

The coefficients depend on the trim state: pitch and flap totals and ``muz`` from
the record (``Constants.trim``, record-column names; without them the model is
refused with one line).  Where the structure has ``azimuth-bias`` the recorded
cyclic trim is rotated to the true one (``R(-dpsi)``, as the effect does for the
pitch inputs).  The trim inflow is not measured: it is the steady state of the
basic inflow model (2) at that trim, whose first row is the momentum balance
``lambda0 = C_T/(2 mu)`` with the blade-element ``C_T``
(:func:`inflowsim.physics.bladeelement.trim_inflow`); in a structure with
``momentum-speed`` it moves by ``k_V`` to Eq. (14)'s, the trim that effect
linearises about (:func:`inflowsim.model.effects.momentum_speed.trim_inflow`; at
``k_V = 0`` the structure without it, so the two stay nested):
on the Eq. (14) truth at mu 0.10 the basic model's is 17 % high in ``lambda0``, the
inflow rows' ``mux, muy`` columns 2 % of their row off (``bench/amplitude.md``,
"High mu").  The change of ``L`` itself with the
speed (mass flow, ``V ~ mu``) is left out: that is inflow physics, what
``glauert`` / ``hub-velocity-coupling`` describe.

Parameter ``k_mu`` [-]: a scale on the whole set of terms, theory value 1 (the
blade-element linearisation), neutral 0 (the paper's constant ``mu``).  The terms
follow from theory, but the scale gives the significance test its one degree of
freedom and lets identification say how much of the direct forcing the record
supports.

Not an alternative to ``glauert`` or ``hub-velocity-coupling``: they add free gains
on the inflow rows only, while ``k_mu`` also scales the flap rows' ``mux, muy``
columns, which no other effect touches; the information matrix of the combined
structure stays regular (checked in the tests).
"""

import numpy as np

from ._effect import Effect
from ._trim import true_trim_state
from .momentum_speed import EFFECT as SPEED
from .momentum_speed import trim_inflow
from ...physics import bladeelement as be
from ...physics import loads as ld
from ..params import ParameterSpec
from ..recent import Recent

NAME = "advance-ratio-perturbation"
MUX = 8   # first in-plane input column (mux, muy) of INPUTS_AZ



#: Trims remembered (:func:`true_trim`, a pure function of its arguments): every
#: model a fit builds of a structure with this effect or ``lead-lag`` asks for the
#: same one (0.1 ms of blade-element trim inflow each), most recent last.
_TRIMS = Recent(16)


def true_trim(k, azimuth_bias: float = 0.0, k_v=None):
    """Trim ``(theta, beta, muz, lam)`` of constants ``k``: :func:`true_trim_state`
    and the structure's trim inflow: the basic model's, or, in a structure with
    ``momentum-speed`` (its scale ``k_v``), the basic model's moved ``k_v`` of the
    way to Eq. (14)'s, the one that effect linearises about.  The effect's terms
    are linear in the trim inflow, so ``k_v = 1`` is exactly Eq. (14)'s trim and
    ``k_v = 0`` the structure without ``momentum-speed``: the two stay nested.
    Read-only arrays, remembered for the last few arguments of plain numbers."""
    if type(azimuth_bias) is float and (k_v is None or type(k_v) is float):
        return _TRIMS.get((k, azimuth_bias, k_v),
                          lambda: _read_only(_true_trim(k, azimuth_bias, k_v)))
    return _true_trim(k, azimuth_bias, k_v)


def _read_only(trim):
    for x in trim:
        if isinstance(x, np.ndarray):
            x.flags.writeable = False
    return trim


def _true_trim(k, azimuth_bias, k_v):
    theta, beta, muz = true_trim_state(k, azimuth_bias, NAME)
    lam = be.trim_inflow(k.mu, k.a0s, theta, beta, muz, k.flow_speed)
    if k_v is not None:
        lam = lam + k_v * (trim_inflow(k, azimuth_bias) - lam)
    return theta, beta, muz, lam


def _equations(eq, p, k):
    # with momentum-speed (its parameter among the structure's) the structure's trim
    # inflow is Eq. (14)'s
    k_v = p[SPEED.parameters[0]] if SPEED.parameters[0] in p else None
    theta, beta, muz, lam = true_trim(k, p.get("azimuth_bias", 0.0), k_v)
    h_u, p_u = eq.h_u.copy(), eq.p_u.copy()
    h_u[:, MUX:MUX + 2] += p["k_mu"] * p["n_beta"] * be.inplane_flap_derivatives(
        k.mu, theta, beta, muz, lam)
    # the base model's gain: V = mu, or the mass-flow speed down to hover
    p_u[:, MUX:MUX + 2] += p["k_mu"] * ld.momentum_l(k.mu, k.a0s, k.flow_speed) @ \
        be.inplane_load_derivatives(k.mu, theta, beta, muz, lam)
    return eq.with_(h_u=h_u, p_u=p_u)


EFFECT = Effect.of_one(
    name=NAME,
    physics="In-plane velocity perturbations change the blades' own airspeed and the "
            "flap-induced normal velocity, forcing flap and rotor loads directly, not "
            "only through the inflow.",
    paper="extension: the paper holds mu constant",
    theory=1.0,
    neutral=0.0,
    equations=_equations,
    spec=ParameterSpec("k_mu", "-", "scale of the direct in-plane velocity forcing of "
                       "flap and loads (theory 1, neutral 0)", -10.0, 10.0,
                       plausible=(0.5, 1.5, "the blade-element linearisation is exact "
                                            "for small perturbations: theory 1")),
    uses_inplane=True,
    about_trim=True,
)


__all__ = ["NAME", "MUX", "true_trim_state", "true_trim", "EFFECT"]
