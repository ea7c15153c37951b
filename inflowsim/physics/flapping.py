"""First-order multiblade flapping, the paper's Eq. (1).

``C beta' + D beta = H_lambda lambda + H_theta theta + H_nu nu + H_eta eta``

Azimuth time (``' = d/dpsi``), states ``beta = (beta0, beta1c, beta1s)`` [rad].
Matrices as restated in ``model.md`` section 2 (the scan drops several ``/2``).
All functions are pure: numbers in, new arrays out.
"""
from __future__ import annotations

import numpy as np


def flap_c(mu: float, n_beta: float) -> np.ndarray:
    """Coefficient of ``beta'``, ``C`` of Eq. (1) [-]."""
    return np.array([[n_beta, 0.0, 2.0 / 3.0 * mu * n_beta],
                     [0.0, n_beta, 2.0],
                     [4.0 / 3.0 * mu * n_beta, -2.0, n_beta]])


def flap_d(mu: float, n_beta: float, lambda_beta2: float) -> np.ndarray:
    """Coefficient of ``beta``, ``D`` of Eq. (1) [-]."""
    return np.array([[lambda_beta2, 0.0, 0.0],
                     [4.0 / 3.0 * mu * n_beta, lambda_beta2 - 1.0, n_beta * (1 + mu**2 / 2)],
                     [0.0, -n_beta * (1 - mu**2 / 2), lambda_beta2 - 1.0]])


def flap_h_theta(mu: float, n_beta: float) -> np.ndarray:
    """Pitch forcing ``H_theta`` of Eq. (1), columns ``(theta0, theta1c, theta1s)``."""
    return n_beta * np.array([[1 + mu**2, 0.0, 4.0 / 3.0 * mu],
                              [0.0, 1 + mu**2 / 2, 0.0],
                              [8.0 / 3.0 * mu, 0.0, 1 + 1.5 * mu**2]])


def flap_h_nu(mu: float, n_beta: float) -> np.ndarray:
    """Hub-motion forcing ``H_nu`` of Eq. (1), columns ``(muz, qbar, pbar)``."""
    return np.array([[4.0 / 3.0 * n_beta, 0.0, 2.0 / 3.0 * mu * n_beta],
                     [0.0, n_beta, 2.0],
                     [2.0 * mu * n_beta, -2.0, n_beta]])


def flap_h_eta() -> np.ndarray:
    """Hub-acceleration forcing ``H_eta`` of Eq. (1), columns ``(qbar', pbar')``."""
    return np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])


def flap_h_lambda(mu: float, n_beta: float) -> np.ndarray:
    """Inflow forcing ``H_lambda`` of Eq. (1), columns ``(lambda0, lambda1c, lambda1s)``."""
    return -n_beta * np.array([[4.0 / 3.0, 0.0, 2.0 / 3.0 * mu],
                               [0.0, 1.0, 0.0],
                               [2.0 * mu, 0.0, 1.0]])


__all__ = ["flap_c", "flap_d", "flap_h_theta", "flap_h_nu", "flap_h_eta", "flap_h_lambda"]
