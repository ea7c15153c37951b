"""Second-harmonic (2/rev) blade flapping: the terms the multiblade model (1) drops.

The paper's Eq. (1) expands each blade's flap in the harmonics ``0`` and ``1`` of
its azimuth.  Keeping the next harmonic,
``beta_i = beta0 + beta1c cos psi_i + beta1s sin psi_i + beta2c cos 2 psi_i +
beta2s sin 2 psi_i``, and projecting the same single-blade equation
(``model.md`` sections 2-3: ``beta_i'' + lambda_beta2 beta_i = 4 n_beta int_0^1 r F
dr`` plus the hub's inertial terms, ``F = theta U_T^2 + U_P U_T``,
``U_T = r + mu sin psi``, ``U_P = muz - lambda_i - r beta' - mu beta cos psi +
r (qbar cos psi + pbar sin psi)``) on ``1, 2 cos psi, 2 sin psi, 2 cos 2psi,
2 sin 2psi`` gives the three rows of Eq. (1) unchanged plus

* in the rows of Eq. (1), the forcing ``N beta2 + N_dot beta2'`` by the 2/rev flap
  (:func:`flap2_into_flap`), order ``mu`` (``mu^2`` in the coning row);
* in the loads of Eq. (4), ``G_beta2 beta2 + G_dbeta2 beta2'``
  (:func:`flap2_into_loads`), order ``mu`` (``mu^2`` in the thrust);
* two new rows ``C2 beta2' + D2 beta2 = F_dbeta beta' + F_beta beta + F_lambda
  lambda + F_u u`` (:func:`flap2_c`, :func:`flap2_d`, :func:`flap2_forcing`), in
  which the first-harmonic flap, inflow and pitch force the 2/rev flap at order
  ``mu`` (the periodic coefficients ``mu sin psi``, ``mu cos psi`` shift harmonic
  1 to 2).

The round trip, harmonic 1 to 2 and back, is order ``mu^2``: about 1 % of the
cyclic flap at ``mu = 0.25``.  The first two rows' projections were derived
symbolically (sympy, trigonometric integrals over ``psi`` and ``r``); with the
2/rev flap left out they reproduce ``C, D, H_*`` of ``model.md`` section 2 and
``G_*`` of section 3 term by term, which ``tests/test_harmonics.py`` checks, and
against the individual-blade truth's own right-hand side (finite differences,
averaged over the azimuth) every entry is checked too.

Azimuth time (``' = d/dpsi``), flap [rad], inputs as ``INPUTS_AZ`` (the first
eight: ``theta0, theta1c, theta1s, muz, qbar, pbar, qbar', pbar'``).  The
in-plane velocity inputs ``mux, muy`` (a trim-dependent forcing) are not carried
into the 2/rev rows.  All functions are pure and polynomial in ``mu``.
"""
from __future__ import annotations

import numpy as np

#: the 2/rev flap coordinates (the states a dynamic form would add)
FLAP2 = ("beta2c", "beta2s")


def flap2_c(n_beta: float) -> np.ndarray:
    """Coefficient of ``beta2'`` in the 2/rev rows, ``C2`` [-] (damping and the
    rotating frame's ``4 beta2s'``, ``-4 beta2c'``)."""
    return np.array([[n_beta, 4.0], [-4.0, n_beta]])


def flap2_d(n_beta: float, lambda_beta2: float) -> np.ndarray:
    """Coefficient of ``beta2`` in the 2/rev rows, ``D2`` [-].

    ``lambda_beta2 - 4`` (the rotating frame's ``-4 beta2``) and the damping term's
    ``2 n_beta`` cross coupling.  No ``mu``: the ``mu^2`` stiffness terms of the
    2/rev rows couple ``beta2`` with ``beta0`` and harmonic 4 only.
    """
    return np.array([[lambda_beta2 - 4.0, 2.0 * n_beta],
                     [-2.0 * n_beta, lambda_beta2 - 4.0]])


def flap2_forcing(mu: float, n_beta: float):
    """``(F_dbeta, F_beta, F_lambda, F_u)``: the first-harmonic flap rate, flap,
    inflow and inputs forcing the 2/rev rows.

    Returns
    -------
    F_dbeta, F_beta, F_lambda : ndarray, shape (2, 3)
        Columns ``beta0, beta1c, beta1s`` (rates), ``lambda0, lambda1c, lambda1s``.
    F_u : ndarray, shape (2, 8)
        Columns ``theta0, theta1c, theta1s, muz, qbar, pbar, qbar', pbar'``.
    """
    m = mu * n_beta
    f_dbeta = np.array([[0.0, 0.0, 2.0 / 3.0 * m],
                        [0.0, -2.0 / 3.0 * m, 0.0]])
    f_beta = np.array([[0.0, -4.0 / 3.0 * m, 0.0],
                       [-mu * m, 0.0, -4.0 / 3.0 * m]])
    f_lambda = np.array([[0.0, 0.0, 2.0 / 3.0 * m],
                         [0.0, -2.0 / 3.0 * m, 0.0]])
    f_u = np.array([[-mu * m, 0.0, -4.0 / 3.0 * m, 0.0, 0.0, -2.0 / 3.0 * m, 0.0, 0.0],
                    [0.0, 4.0 / 3.0 * m, 0.0, 0.0, 2.0 / 3.0 * m, 0.0, 0.0, 0.0]])
    return f_dbeta, f_beta, f_lambda, f_u


def flap2_into_flap(mu: float, n_beta: float):
    """``(N, N_dot)``: forcing of the rows of Eq. (1) by ``beta2`` and ``beta2'``,
    shape (3, 2) each, columns ``beta2c, beta2s`` (right-hand side)."""
    m = mu * n_beta
    n = np.array([[0.0, -mu * m / 2.0],
                  [2.0 / 3.0 * m, 0.0],
                  [0.0, 2.0 / 3.0 * m]])
    n_dot = np.array([[0.0, 0.0],
                      [0.0, -2.0 / 3.0 * m],
                      [2.0 / 3.0 * m, 0.0]])
    return n, n_dot


def flap2_into_loads(mu: float):
    """``(G_beta2, G_dbeta2)``: the 2/rev flap in ``c = (C_T, C_mc, C_ms)/(a0 s)`` of
    Eq. (4), shape (3, 2) each, columns ``beta2c, beta2s``."""
    g = np.array([[0.0, -mu**2 / 8.0],
                  [-mu / 24.0, 0.0],
                  [0.0, -mu / 24.0]])
    g_dot = np.array([[0.0, 0.0],
                      [0.0, mu / 24.0],
                      [-mu / 24.0, 0.0]])
    return g, g_dot


__all__ = ["FLAP2", "flap2_c", "flap2_d", "flap2_forcing", "flap2_into_flap",
           "flap2_into_loads"]
