"""Rotor loads from blade-element theory, Eq. (4), and local momentum, Eq. (2).

``c = (C_T, C_mc, C_ms)/(a0 s) = G_dbeta beta' + G_beta beta + G_theta theta
+ G_nu nu + G_lambda lambda``  (``model.md`` section 3).

Pure functions of the advance ratio ``mu`` [-].  The tests check every entry
against numerical quadrature of the blade-element integrals, an independent
route to the same numbers.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError

#: Forward-flight local momentum theory (V ~ mu) is only meaningful above this
#: advance ratio; the basic ``L`` matrix is singular at ``mu = 0``.
MU_MIN = 0.1


def g_dbeta(mu: float) -> np.ndarray:
    """Loads per flap rate ``beta'``, ``G_beta'`` of Eq. (4)."""
    return np.array([[-1 / 6, 0.0, -mu / 8],
                     [0.0, 1 / 16, 0.0],
                     [mu / 12, 0.0, 1 / 16]])


def g_beta(mu: float) -> np.ndarray:
    """Loads per flap ``beta``, ``G_beta`` of Eq. (4)."""
    return np.array([[0.0, 0.0, 0.0],
                     [mu / 12, 0.0, 1 / 16 + mu**2 / 32],
                     [0.0, -1 / 16 + mu**2 / 32, 0.0]])


def g_theta(mu: float) -> np.ndarray:
    """Loads per blade pitch ``theta``, ``G_theta`` of Eq. (4)."""
    return np.array([[1 / 6 + mu**2 / 4, 0.0, mu / 4],
                     [0.0, -1 / 16 - mu**2 / 32, 0.0],
                     [-mu / 6, 0.0, -1 / 16 - 3 * mu**2 / 32]])


def g_nu(mu: float) -> np.ndarray:
    """Loads per hub motion ``nu = (muz, qbar, pbar)``, ``G_nu`` of Eq. (4)."""
    return np.array([[1 / 4, 0.0, mu / 8],
                     [0.0, -1 / 16, 0.0],
                     [-mu / 8, 0.0, -1 / 16]])


def g_lambda(mu: float) -> np.ndarray:
    """Loads per induced inflow ``lambda``, ``G_lambda`` of Eq. (4)."""
    return np.array([[-1 / 4, 0.0, -mu / 8],
                     [0.0, 1 / 16, 0.0],
                     [mu / 8, 0.0, 1 / 16]])


def momentum_l(mu: float, a0s: float, v: float | None = None) -> np.ndarray:
    """Local-momentum gain ``L`` (Eq. 19): ``diag(a0 s/(2 V), -2 a0 s/V, -2 a0 s/V)``.

    ``v`` the speed through the disc over ``Omega R``; default the paper's forward-
    flight ``V ~ mu``, singular at ``mu = 0`` and refused below ``MU_MIN`` rather than
    returning infinities.  :func:`mass_flow_parameter` gives a ``V`` that stays finite
    down to hover.
    """
    if v is None:
        if isinstance(mu, (int, float, np.number)) and (not np.isfinite(mu) or mu < MU_MIN):
            raise InputError(f"mu = {mu:g} is too small for the forward-flight momentum "
                             f"L (V ~ mu): need mu >= {MU_MIN:g}, or the mass-flow "
                             "speed (inflow_speed='mass-flow' with a trim ct)")
        v = mu
    # a symbol (the FMU's code generator) has no value to check
    if isinstance(v, (int, float, np.number)) and not (np.isfinite(v) and v > 0):
        raise InputError(f"speed through the disc V = {v:g}: must be finite and > 0")
    return np.diag([a0s / (2 * v), -2 * a0s / v, -2 * a0s / v])


def momentum_inflow(mu: float, ct: float) -> float:
    """Trim induced inflow ``lambda_m`` over ``Omega R`` of momentum theory in level
    flight: ``lambda_m = C_T / (2 sqrt(mu^2 + lambda_m^2))`` (Glauert's formula; hover
    ``sqrt(C_T / 2)``, fast flight ``C_T / (2 mu)``).  Solved by Newton's method on
    ``f(l) = 4 l^2 (mu^2 + l^2) - C_T^2`` from above, where it converges monotonically.
    """
    if not (np.isfinite(ct) and ct > 0):
        raise InputError(f"ct = {ct:g}: the trim thrust coefficient must be > 0")
    lam = float(np.sqrt(ct / 2.0))   # the hover root, never below the root at any mu
    for _ in range(100):
        # products written out, in the FMU's C order (fmu/inflow_model.c, flow_speed)
        f = 4 * lam * lam * (mu * mu + lam * lam) - ct * ct
        step = f / (8 * lam * mu * mu + 16 * lam * lam * lam)
        lam -= step
        if abs(step) <= 1e-15 * lam:
            break
    return float(lam)


def mass_flow_parameter(mu: float, ct: float) -> float:
    """Momentum mass-flow parameter ``V = (mu^2 + lambda (lambda + lambda_m)) / V_T``,
    ``V_T = sqrt(mu^2 + lambda^2)``, with the trim inflow ``lambda = lambda_m``
    (:func:`momentum_inflow`, level flight): the speed that linearised momentum
    theory gives perturbations (Pitt and Peters 1981; Peters and HaQuang 1988).
    ``2 sqrt(C_T/2)`` in hover, ``mu`` in fast flight."""
    lam = momentum_inflow(mu, ct)
    return float((mu * mu + 2 * lam * lam) / np.hypot(mu, lam))
