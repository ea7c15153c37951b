"""``lead-lag``: the regressing lag mode in multiblade coordinates, coupled to flap.

Every real rotor's blades also move in the plane of the disc (lead-lag).  The cyclic
lag ``zeta1c, zeta1s`` (the rotor's centre of mass whirling, the regressing lag mode
at ``(1 - nu_zeta)`` per rev in the fixed frame) couples to the flap through the
Coriolis moment (``2 beta_t``: flapping up makes a blade lead) and through the
aerodynamics (a lag rate changes the blade's dynamic pressure and its induced and
profile drag), ``model.md`` section 9.1, :mod:`inflowsim.physics.lead_lag`.  Six
appended states (:class:`~inflowsim.model.equations.StateBlock`): ``zeta0, zeta1c,
zeta1s`` and their azimuth rates::

    x'' = (lag structure, Coriolis) + k-free aerodynamic lag moments
    flap rows  += k_flap_lag (Coriolis + aerodynamic flap moments of the lag) x
    inflow rows += k_flap_lag L dc/dx x          (the lag's share of the loads)

The collective lag ``zeta0`` is kept, against a hub turning at the constant
rotor speed this model holds (a governed rotor on a stiff drive train; the drive
train's torsion and the engine governor are not modelled): in forward flight the
cyclic inputs excite it through the ``mu`` terms and its rate changes the thrust,
and leaving it out made the lag's share of the flap response several times too
small against the four-blade route at ``mu = 0.25`` (``model.md`` 9.1).

Parameters: ``nu_zeta`` [per rev] the rotating lag frequency, ``zeta_lag`` [-] the
lag damper's damping ratio (``C_zeta = 2 zeta_lag nu_zeta``), ``k_flap_lag`` [-]
a scale on the lag's action on flap and inflow (theory 1; neutral 0: the lag
states are then driven but drive nothing, so the structure without the effect is
exactly nested, not on a boundary).  Linearised about the trim (``Constants.trim``,
``about_trim``): collective, coning and the trim up-flow ``muz - lambda0`` (the
basic model's trim inflow, as ``advance-ratio-perturbation``'s); the cyclic trim and
the in-plane velocity inputs are not carried in the lag's terms.

Two parts (``Effect.parts``): the coupling ``k_flap_lag``, then the frequency and the
damper.  Where ``k_flap_lag = 0`` the lag's frequency and damper act on nothing (they
are not identified under the null: Davies' problem), so a likelihood-ratio test of
all three is not chi-square with 3 degrees of freedom: on 96 null records it gave
p < 0.05 in 35 and p < 1e-3 in 3 (``bench/rotor-physics.md``).  The diagnosis therefore
tests the coupling alone, the frequency and the damper held at their theory values (a
chi-square law with one degree of freedom), and the frequency and the damper as a
second part once the coupling is in, where they are identified.
"""
import numpy as np

from ._effect import Effect
from .advance_ratio_perturbation import true_trim, true_trim_state
from ..equations import StateBlock, rotation
from ..params import ParameterSpec
from ...physics import lead_lag as ll
from ...physics import loads as ld

NAME = "lead-lag"
#: Appended states: the multiblade lag [rad], then its azimuth rates.
STATES = ("zeta0", "zeta1c", "zeta1s", "zeta0_prime", "zeta1c_prime", "zeta1s_prime")
#: Theory lag frequency [per rev] by hub (``Constants.hub``; articulated by default).
NU_THEORY = {"articulated": 0.25, "hingeless": 0.65, "bearingless": 0.65}


def _trim(p, k):
    """``(theta_t, beta_t, u)``: collective, coning and trim up-flow ``muz - lambda0``."""
    true_trim_state(k, 0.0, NAME)           # refused naming this effect without a trim
    # with momentum-speed the structure's trim inflow is Eq. (14)'s (as
    # advance-ratio-perturbation's)
    theta, beta, muz, lam = true_trim(k, p.get("azimuth_bias", 0.0), p.get("k_V"))
    return theta[0], beta[0], muz - lam[0]


def in_loads(p, k):
    """``(C_T, C_mc, C_ms) / (a0 s)`` per the lag states ``STATES`` (the lag rate's
    and the lag's change of the blades' airspeed, scaled by ``k_flap_lag``) [-]."""
    th, b, u = _trim(p, k)
    return p["k_flap_lag"] * ll.load_coupling(k.mu, th, b, u)


def block(p, k, n_inputs: int = 10) -> StateBlock:
    """The lag's :class:`StateBlock` for parameters ``p`` and constants ``k``."""
    th, b, u = _trim(p, k)
    mu, nb = k.mu, p["n_beta"]
    kf = p["k_flap_lag"]
    s_z, s_x = ll.lag_structure(p["nu_zeta"], p["zeta_lag"], b)
    a_z, a_x, a_u = ll.lag_aero(mu, nb, th, b, u, ll.CD0 / k.a0)
    if "azimuth_bias" in p:
        # the model takes the recorded cyclic pitch: true = R(-dpsi) recorded
        a_u = np.hstack([a_u[:, :1], a_u[:, 1:3] @ rotation(-p["azimuth_bias"]),
                         a_u[:, 3:]])
    z3, i3 = np.zeros((3, 3)), np.eye(3)
    a = np.vstack([np.hstack([z3, i3]), s_x + a_x])
    az = np.vstack([np.zeros((3, 9)), s_z + a_z])
    b_u = np.vstack([np.zeros((3, n_inputs)),
                     np.hstack([a_u, np.zeros((3, n_inputs - 6))])])
    f_x = kf * ll.flap_coupling(mu, nb, th, b, u)
    l_x = kf * (ld.momentum_l(mu, k.a0s, k.flow_speed) @ ll.load_coupling(mu, th, b, u))
    return StateBlock(effect=NAME, states=STATES, e=np.eye(6), a=a, a_z=az, b=b_u,
                      f_x=f_x, l_x=l_x)


def _equations(eq, p, k):
    return eq.with_(blocks=eq.blocks + (block(p, k, eq.h_u.shape[1]),))


def _theory(k):
    return {"nu_zeta": NU_THEORY.get(k.hub, NU_THEORY["articulated"]), "zeta_lag": 0.2,
            "k_flap_lag": 1.0}


EFFECT = Effect(
    name=NAME,
    physics="The blades' lead-lag: the regressing lag mode (cyclic lag, rotating "
            "frequency nu_zeta, damper zeta_lag) couples to the flap through the "
            "Coriolis moment and the lag rate's change of the blades' airspeed.",
    paper="extension: rigid flap-lag blades (Johnson, Helicopter Theory ch. 9, 12; "
          "Rotorcraft Aeromechanics ch. 16-17)",
    parameters=("nu_zeta", "zeta_lag", "k_flap_lag"),
    theory=_theory,
    neutral=lambda k: _theory(k) | {"k_flap_lag": 0.0},
    equations=_equations,
    specs=(ParameterSpec("nu_zeta", "-", "rotating lag frequency over the rotor speed (per rev)", 0.05, 1.5,
                         plausible=(0.15, 0.85, "lag frequency of an articulated "
                                    "(0.2-0.35) or soft-inplane (0.5-0.8) rotor"),
                         plausible_by_hub=(
                             ("articulated", (0.15, 0.4, "an articulated rotor's lag "
                                              "hinge offset gives 0.2-0.35 per rev")),
                             ("hingeless", (0.45, 0.85, "a soft-inplane hingeless "
                                            "rotor's lag frequency lies at 0.5-0.8 per "
                                            "rev")),
                             ("bearingless", (0.45, 0.85, "a soft-inplane bearingless "
                                              "rotor's lag frequency lies at 0.5-0.8 "
                                              "per rev")))),
           ParameterSpec("zeta_lag", "-", "lag damper's damping ratio (of critical, "
                         "rotating frame)", 0.0, 3.0,
                         plausible=(0.02, 0.6, "a lag damper gives 0.05-0.5 of "
                                    "critical; without one a few per cent")),
           ParameterSpec("k_flap_lag", "-", "scale of the lag's coupling into flap and "
                         "inflow (theory 1, neutral 0)", -10.0, 10.0,
                         plausible=(0.5, 1.5, "the Coriolis and blade-element coupling "
                                    "follow from the trim: theory 1"))),
    about_trim=True,
    theory_start=True,
    parts=(("k_flap_lag",), ("nu_zeta", "zeta_lag")),
    states=STATES,
    offered=False,
)


__all__ = ["NAME", "STATES", "NU_THEORY", "in_loads", "block", "EFFECT"]
