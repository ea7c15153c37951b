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
exactly nested, not on a boundary).  Linearised about the forward-flight trim
(``Constants.trim``, ``about_trim``; ``model.md`` 9.1, "The forward-flight trim"):
the trim's pitch and flap with their cyclics, the structure's trim inflow (the basic
model's, or Eq. (14)'s with ``momentum-speed``, as ``advance-ratio-perturbation``'s)
moved by the steady lag's share of the trim's loads, and the steady lag the trim's
drag and Coriolis moment hold (:func:`steady_lag`, from ``nu_zeta``, ``zeta_lag``,
``n_beta``: no parameter of its own).  The steady lag also has a share of the base
flap and inflow rows' own columns (the blades meet the free stream and the inflow,
and their lift acts, at ``psi - zeta``), scaled by ``k_flap_lag`` with the rest of
the lag's action.  The in-plane velocity inputs are not carried.

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

from ._effect import Effect, RuntimeLinear, RuntimePolynomials
from .advance_ratio_perturbation import true_trim, true_trim_state
from .second_harmonic_flap import condensed
from ..equations import StateBlock, rotation
from ..params import ParameterSpec
from ..recent import Recent
from ...physics import lead_lag as ll
from ...physics import loads as ld

NAME = "lead-lag"
#: Appended states: the multiblade lag [rad], then its azimuth rates.
STATES = ("zeta0", "zeta1c", "zeta1s", "zeta0_prime", "zeta1c_prime", "zeta1s_prime")
#: Theory lag frequency [per rev] by hub (``Constants.hub``; articulated by default).
NU_THEORY = {"articulated": 0.25, "hingeless": 0.65, "bearingless": 0.65}


def _trim(p, k):
    """``(theta, beta, muz, lam)``: the true trim pitch (3) and flap with its 2/rev
    part (5, :func:`trim_flap2`), ``muz`` and the rigid blades' trim inflow of the
    structure (3)."""
    true_trim_state(k, 0.0, NAME)           # refused naming this effect without a trim
    # with momentum-speed the structure's trim inflow is Eq. (14)'s (as
    # advance-ratio-perturbation's)
    th, b, muz, lam = true_trim(k, p.get("azimuth_bias", 0.0), p.get("k_V"))
    return th, (*b, *trim_flap2(p, k, (th, b, muz, lam))), muz, lam


def trim_flap2(p, k, trim=None):
    """The trim's 2/rev flap ``(beta2c, beta2s)`` [rad]: the rigid blades' periodic
    coefficients force it from the trim's flap, inflow and pitch
    (:func:`inflowsim.model.effects.second_harmonic_flap.condensed`, its
    quasi-static balance at theory, whether or not that effect is in the structure:
    it is the trim's, not a perturbation's).  The lag's Coriolis moment ``-2 beta
    beta'`` and ``2 beta zeta'`` carry it into the steady lag and the couplings
    (``model.md`` 9.1); ``trim``: :func:`true_trim` at ``p``, ``k`` if known."""
    th, b, muz, lam = true_trim(k, p.get("azimuth_bias", 0.0), p.get("k_V")) \
        if trim is None else trim
    _, s_b, s_l, s_u = condensed(k.mu, p["n_beta"], p["lambda_beta2"])
    o = 0 * muz
    return s_b @ np.asarray(b) + s_l @ np.asarray(lam) + s_u @ np.array(
        [*th, muz, o, o, o, o])


def coefficients(p, k):
    """``(zeta_t, flap, lag, loads, lam_t)`` of
    :func:`inflowsim.physics.lead_lag.coefficients` at the structure's trim (its
    inflow moved by the steady lag's share of the trim's loads), for parameters
    ``p`` (``n_beta``, ``nu_zeta``, ``zeta_lag``) and constants ``k``."""
    th, b, muz, lam = _trim(p, k)
    args = (k.mu, p["n_beta"], ll.CD0 / k.a0, tuple(th), tuple(b), muz, tuple(lam),
            p["nu_zeta"], p["zeta_lag"])
    if all(isinstance(x, float) for x in args[:3] + args[3] + args[4] + args[5:6]
           + args[6] + args[7:]) and isinstance(k.a0s, float) \
            and isinstance(k.flow_speed, float):
        key = (*(float(x) for x in args[:3]), tuple(float(x) for x in args[3]),
               tuple(float(x) for x in args[4]), float(muz), tuple(float(x) for x in lam),
               *(float(x) for x in args[7:]), float(k.a0s), float(k.flow_speed))
        return _COEFFICIENTS.get(key, lambda: _read_only(_coefficients(args, k)))
    return _coefficients(args, k)


def _coefficients(args, k):
    return ll.coefficients(*args, ld.momentum_l(k.mu, k.a0s, k.flow_speed),
                           ld.g_lambda(k.mu), getattr(k, "numeric", None))


def _read_only(out):
    for x in out:
        x.flags.writeable = False
    return out


#: Coefficients remembered (:func:`coefficients`, a pure function of its
#: arguments), most recent last.
_COEFFICIENTS = Recent(16)


def steady_lag(p, k):
    """The steady lag ``(zeta0, zeta1c, zeta1s)`` [rad] the effect is linearised
    about (:func:`inflowsim.physics.lead_lag.steady_lag`)."""
    return coefficients(p, k)[0]


def in_loads(p, k):
    """``(C_T, C_mc, C_ms) / (a0 s)`` per the columns of
    :data:`inflowsim.physics.lead_lag_terms.COLS`: the lag's (its rate and
    displacement change the blades' airspeed and move their lift) and the steady
    lag's share of the base states' and inputs', scaled by ``k_flap_lag`` [-]."""
    return p["k_flap_lag"] * coefficients(p, k)[3]


def _bias(m, p):
    """The pitch columns (9:12 of ``COLS``) of ``m`` taken from the recorded cyclic
    pitch: true = ``R(-dpsi)`` recorded."""
    if "azimuth_bias" not in p:
        return m[:, 9:15]
    return np.hstack([m[:, 9:10], m[:, 10:12] @ rotation(-p["azimuth_bias"]), m[:, 12:15]])


def block(p, k, n_inputs: int = 10, coeffs=None) -> StateBlock:
    """The lag's :class:`StateBlock` for parameters ``p`` and constants ``k``
    (``coeffs``: :func:`coefficients` at them, if known)."""
    _, flap, lag, loads, _ = coefficients(p, k) if coeffs is None else coeffs
    kf = p["k_flap_lag"]
    s_x = ll.lag_structure(p["nu_zeta"], p["zeta_lag"])
    a_z, a_x, a_u = lag[:, ll.Z_COLS], lag[:, ll.X_COLS], _bias(lag, p)
    z3, i3 = np.zeros((3, 3)), np.eye(3)
    a = np.vstack([np.hstack([z3, i3]), s_x + a_x])
    az = np.vstack([np.zeros((3, 9)), a_z])
    b_u = np.vstack([np.zeros((3, n_inputs)),
                     np.hstack([a_u, np.zeros((3, n_inputs - 6))])])
    f_x = kf * flap[:, ll.X_COLS]
    l_x = kf * (ld.momentum_l(k.mu, k.a0s, k.flow_speed) @ loads[:, ll.X_COLS])
    return StateBlock(effect=NAME, states=STATES, e=np.eye(6), a=a, a_z=az, b=b_u,
                      f_x=f_x, l_x=l_x)


def _base_terms(eq, p, k, coeffs):
    """The steady lag's share of the base equations' state and input columns (the
    blades meet the free stream, the inflow and the body rates at ``psi - zeta_t``,
    and the lag rate of the trim's cyclic lag acts in the Coriolis moment), scaled
    by ``k_flap_lag`` (neutral 0: the base equations unchanged); ``coeffs`` the
    :func:`coefficients`."""
    _, flap, _, loads, _ = coeffs
    kf = p["k_flap_lag"]
    lm = kf * ld.momentum_l(k.mu, k.a0s, k.flow_speed)
    fl = kf * flap
    zu = np.zeros((3, eq.h_u.shape[1] - 6))
    return eq.with_(
        d=eq.d - fl[:, ll.BETA], c=eq.c - fl[:, ll.DBETA],
        h_lambda=eq.h_lambda + fl[:, ll.LAMBDA],
        h_u=eq.h_u + np.hstack([_bias(fl, p), zu]),
        p_beta=eq.p_beta + lm @ loads[:, ll.BETA],
        p_dbeta=eq.p_dbeta + lm @ loads[:, ll.DBETA],
        p_lambda=eq.p_lambda + lm @ loads[:, ll.LAMBDA],
        p_u=eq.p_u + np.hstack([lm @ _bias(loads, p), zu]))


def _runtime():
    """What the FMU computes at run time (:func:`inflowsim.physics.lead_lag.
    coefficients` traced): the lag's 3 x 3 systems (the steady lag, the trim
    inflow), a :class:`RuntimeLinear` of twelve arguments, the matrix row by row,
    then the right-hand side; and the trim polynomials of
    :mod:`~inflowsim.physics.lead_lag_terms` (calls ``lead-lag/<table>``), each a
    :class:`RuntimePolynomials`."""
    from ...physics import lead_lag_terms as lt     # read when a lag FMU is made
    return {NAME: RuntimeLinear(
        n_args=12, matrix=lambda arg: np.array(arg[:9], dtype=object).reshape(3, 3),
        rhs=lambda arg: np.array(arg[9:12], dtype=object).reshape(3, 1))} | {
        f"{NAME}/{name}": RuntimePolynomials(t) for name, t in lt.TABLES.items()}


def _equations(eq, p, k):
    c = coefficients(p, k)
    eq = _base_terms(eq, p, k, c)
    return eq.with_(blocks=eq.blocks + (block(p, k, eq.h_u.shape[1], c),))


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
    parts_in_order=True,
    states=STATES,
    runtime=lambda: _runtime(),
)


__all__ = ["NAME", "STATES", "NU_THEORY", "coefficients", "steady_lag", "trim_flap2",
           "in_loads", "block", "EFFECT"]
