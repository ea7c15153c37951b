"""Rotor loads out of a model (issue #10 part 1): the aerodynamic thrust and hub moment
coefficients of Eq. (4) and the hub moments the flap springs pass to the shaft.

Both are linear in the model's state and input, so they are output matrices beside the
flap and inflow outputs: ``loads = c_loads x + d_loads u`` (SI inputs, as ``Model.b``).

- Aerodynamic (``model.md`` section 3): ``(C_T, C_mc, C_ms) = a0 s (G_dbeta beta' +
  G_beta beta + G_theta theta + G_nu nu + G_lambda lambda)``, with the multiblade flap
  rate ``beta'`` taken from the model's own dynamics (``x' = (a x + b u) / Omega``), so
  every structure's flap equation is honoured; with ``azimuth-bias`` the true (not the
  recorded) cyclic pitch. ``C_mc`` pitch nose up, ``C_ms`` roll starboard down, as in
  Eq. (4).
- Hub moments from flap, centre-spring form: the spring stiffness that makes the
  normalised flap frequency ``lambda_beta2`` gives, over the ``N_b`` blades,
  ``(C_mc_hub, C_ms_hub) = -a0 s (lambda_beta2 - 1) / (16 n_beta) (beta1c, beta1s)``
  (``C_M = M / (rho pi R^2 (Omega R)^2 R)``, ``n_beta = gamma/8``); in steady flight it
  equals the aerodynamic moment (the flap equation's moment balance, tested).

With ``second-harmonic-flap`` the aerodynamic loads carry the 2/rev flap's own term
``G_beta2 beta2`` (quasi-steady, as the effect's flap equation has it; ``model.md``
extensions).

Coefficients are perturbations about trim, like every model output. Not included: the
in-plane velocity terms (``mux, muy``) of the loads, which the paper's Eq. (4) does not
carry; structures that add them to the flap equation still give their flap rates here.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..channels import CONTROLS, FLAP, INFLOW, INPUTS, LOADS, input_scale
from ..errors import InputError
from ..physics import loads as ld
from .build import _frozen
from .effects import CATALOGUE
from .effects import second_harmonic_flap as shf
from .effects import lead_lag as llg
from .equations import rotation

#: The aerodynamic loads, then the flap-spring hub moments (``channels.LOADS``).
AERO = LOADS[:3]
HUB = LOADS[3:]


@dataclass(frozen=True, eq=False)
class LoadMatrices:
    """``loads = c x + d u`` for a model's SI state ``x`` and SI inputs ``u``.

    Attributes
    ----------
    names : tuple of str
        ``CT, C_mc, C_ms, C_mc_hub, C_ms_hub`` (``channels.LOADS``).
    c : ndarray, shape (5, n)
    d : ndarray, shape (5, m)
    """

    names: tuple
    c: np.ndarray
    d: np.ndarray

    def __call__(self, x, u) -> np.ndarray:
        return self.c @ np.asarray(x, float) + self.d @ np.asarray(u, float)


def load_matrices(model) -> LoadMatrices:
    """The load output matrices of ``model`` (a :class:`~inflowsim.model.Model`).

    Returns
    -------
    LoadMatrices
        Rows ``CT, C_mc, C_ms`` (Eq. (4), times ``a0 s``) and ``C_mc_hub, C_ms_hub``
        (centre-spring hub moments from flap) [-].
    """
    c, d = load_rows(model.a, model.b, model.structure.effects, model.parameters,
                     model.constants, model.measurement.azimuth_bias, model.states,
                     model.inputs)
    return LoadMatrices(tuple(LOADS), _frozen(c), _frozen(d))


def load_rows(a, b, effects, p, k, azimuth_bias, states, inputs):
    """``(c, d)`` of :func:`load_matrices` from the SI state space ``a, b`` (states
    ``states``, inputs ``inputs``), the structure's ``effects``, parameters ``p``,
    constants ``k`` (``mu``, ``omega``, ``a0s``) and the azimuth bias [rad].

    Runs on numbers or on sympy symbols: the FMU's C loads are this function
    printed (:mod:`inflowsim.fmu.codegen`), so nothing is assigned into float
    arrays.
    """
    mu, om, a0s = k.mu, k.omega, k.a0s
    states, inputs = list(states), list(inputs)
    n, m = a.shape[0], b.shape[1]
    pb = _select(states, FLAP, n)
    pl = _select(states, INFLOW, n)
    # azimuth-time flap rates from the model's own dynamics
    dbeta_x = pb @ a / om
    dbeta_u = pb @ b / om
    scale = input_scale(om, inputs)
    # a control a servo actuator's state stands for (Effect.replaces_inputs): the
    # blade pitch is that state, not the recorded command
    through = {i: x for e in effects if e in CATALOGUE
               for i, x in CATALOGUE[e].replaces_inputs}
    th = _select(inputs, [c if c not in through else None for c in CONTROLS], m)
    th_x = _select(states, [through.get(c) for c in CONTROLS], n)
    # recorded cyclic pitch is the true one rotated by the azimuth bias (model.md 6);
    # the loads, like the flap dynamics, follow the true pitch
    th = np.vstack([th[:1], rotation(-azimuth_bias) @ th[1:3]])
    th_x = np.vstack([th_x[:1], rotation(-azimuth_bias) @ th_x[1:3]])
    nu = _select(inputs, ("muz", "q", "p"), m) * scale
    c = a0s * (ld.g_dbeta(mu) @ dbeta_x + ld.g_beta(mu) @ pb + ld.g_lambda(mu) @ pl)
    if through:
        c = c + a0s * (ld.g_theta(mu) @ th_x)
    d = a0s * (ld.g_dbeta(mu) @ dbeta_u + ld.g_theta(mu) @ th + ld.g_nu(mu) @ nu)
    if shf.NAME in effects:
        # the 2/rev flap's own term, quasi-steady as the effect's flap equation has it
        w = shf.in_loads(p, k)
        u8 = _select(inputs, INPUTS[:8], m) * scale
        c = c + a0s * (w[:, :3] @ dbeta_x + w[:, 3:6] @ pb + w[:, 6:9] @ pl)
        d = d + a0s * (w[:, :3] @ dbeta_u + w[:, 9:] @ u8)
    if llg.NAME in effects:
        # the lag's own term: its rate and displacement change the blades' airspeed
        # and move their lift; and the steady lag's share of the base columns
        w = llg.in_loads(p, k)
        c = c + a0s * (w[:, 15:21] @ _select(states, llg.STATES, n) + w[:, 0:3] @ pb
                       + w[:, 3:6] @ dbeta_x + w[:, 6:9] @ pl)
        if through:
            c = c + a0s * (w[:, 9:12] @ th_x)
        d = d + a0s * (w[:, 3:6] @ dbeta_u + w[:, 9:12] @ th + w[:, 12:15] @ nu)
    for e in effects:
        eff = CATALOGUE.get(e)
        if eff is not None and eff.loads is not None:
            # an effect's appended states' own loads (higher inflow states)
            c = c + a0s * (eff.loads(p, k) @ _select(states, eff.states, n))
    spring = -a0s * (p["lambda_beta2"] - 1.0) / (16.0 * p["n_beta"])
    c_hub = spring * pb[1:3]
    return np.vstack([c, c_hub]), np.vstack([d, np.zeros((2, m))])


def dimensional_loads(coefficients, constants, density: float) -> dict:
    """Thrust [N] and hub moments [N m] from load coefficients.

    ``T = C_T rho pi R^2 (Omega R)^2`` and ``M = C_M rho pi R^2 (Omega R)^2 R`` with the
    rotor radius ``constants.radius`` [m] and air ``density`` [kg/m^3]. Keys ``T,
    M_pitch, M_roll, M_pitch_hub, M_roll_hub`` (pitch nose up, roll starboard down).
    """
    r = constants.radius
    if r is None:
        raise InputError("dimensional loads need the rotor radius (constants radius, "
                         "'# radius:' in a record)")
    if not (math.isfinite(density) and 0.01 <= density <= 2.0):
        raise InputError(f"density = {density:g} kg/m^3: need an air density in "
                         "[0.01, 2] kg/m^3")
    q = density * math.pi * r**2 * (constants.omega * r) ** 2
    cf = np.asarray(coefficients, float)
    return {"T": cf[..., 0] * q, "M_pitch": cf[..., 1] * q * r,
            "M_roll": cf[..., 2] * q * r, "M_pitch_hub": cf[..., 3] * q * r,
            "M_roll_hub": cf[..., 4] * q * r}


def _select(names, wanted, n) -> np.ndarray:
    s = np.zeros((len(wanted), n))
    for i, w in enumerate(wanted):
        if w is not None and w in names:
            s[i, list(names).index(w)] = 1.0
    return s


__all__ = ["AERO", "HUB", "LoadMatrices", "load_matrices", "load_rows", "dimensional_loads"]
