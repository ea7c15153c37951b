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


def momentum_l(mu: float, a0s: float) -> np.ndarray:
    """Local-momentum gain ``L`` with ``V/(Omega R) ~ mu`` (Eq. 19).

    ``L = diag(a0 s/(2 mu), -2 a0 s/mu, -2 a0 s/mu)``.  Singular at ``mu = 0``:
    refused below ``MU_MIN`` rather than returning infinities.
    """
    if not np.isfinite(mu) or mu < MU_MIN:
        raise InputError(f"mu = {mu:g} is too small for the forward-flight momentum L "
                         f"(V ~ mu): need mu >= {MU_MIN:g}")
    return np.diag([a0s / (2 * mu), -2 * a0s / mu, -2 * a0s / mu])
