"""Blade-element coefficients about a trim state, in closed form.

Helpers of the effects linearised about trim (``advance-ratio-perturbation``,
``skewed-wake``).  Velocities and integrands are those of ``model.md`` section 3
with the in-plane perturbations of ``workflow.md``:

``U_T = r + (mu + mux) sin psi + muy cos psi``,
``U_P = muz - lambda_i - r beta' - (mu + mux) beta cos psi + muy beta sin psi``,

lift per unit span proportional to ``F = theta U_T^2 + U_P U_T``.  The formulas
below were derived symbolically (``d F / d mux``, ``d F / d muy`` at
``mux = muy = 0``, integrated over ``r`` in [0, 1] and averaged over ``psi``) and
are checked in ``tests/test_effects_new_inplane.py`` against Gauss-Legendre /
uniform-azimuth quadrature and a finite difference of the full integrals.

Trim vectors are true (not azimuth-biased) multiblade values: ``theta = (theta0,
theta1c, theta1s)`` [rad], ``beta = (beta0, beta1c, beta1s)`` [rad], ``muz`` [-],
``lam = (lambda0, lambda1c, lambda1s)`` [-].
"""
from __future__ import annotations

import math
from typing import Mapping

import numpy as np

from . import loads as ld
from ..channels import CONTROLS, FLAP
from ..errors import InputError

#: Trim totals (record columns) an effect linearised about trim needs.
TRIM_KEYS = CONTROLS + FLAP + ("muz",)


def trim_state(trim: Mapping[str, float] | None, effect: str):
    """``(theta, beta, muz)`` from ``Constants.trim``, or one-line :class:`InputError`.

    Parameters
    ----------
    trim : mapping or None
        Trim totals by record column name [rad, -].
    effect : str
        Name of the effect asking, for the error message.
    """
    missing = [k for k in TRIM_KEYS if trim is None or k not in trim]
    if missing:
        raise InputError(f"effect {effect} needs the trim totals {', '.join(missing)} "
                         "in the constants (Constants.with_trim, e.g. from find_trim of "
                         "the record)")
    theta = np.array([_real(trim["theta0"]), _real(trim["theta1c"]), _real(trim["theta1s"])])
    beta = np.array([_real(trim["beta0"]), _real(trim["beta1c"]), _real(trim["beta1s"])])
    return theta, beta, _real(trim["muz"])


def _real(x):
    """``float(x)``, but a symbol stays one (:func:`inflowsim.physics.loads.is_number`)."""
    return float(x) if ld.is_number(x) else x


def _solve(a, b):
    """``a^-1 b``: LAPACK for numbers, sympy's LU for symbols."""
    if a.dtype != object and np.asarray(b).dtype != object:
        return np.linalg.solve(a, b)
    import sympy
    return np.array(sympy.Matrix(a).LUsolve(sympy.Matrix(b)), dtype=object).reshape(-1)


def trim_inflow(mu: float, a0s: float, theta, beta, muz: float, v=None) -> np.ndarray:
    """Trim induced inflow: the steady state of the basic inflow model, Eq. (2).

    ``lambda = L c`` with the blade-element loads ``c = G_theta theta + G_beta beta
    + G_nu (muz, 0, 0) + G_lambda lambda`` (exact at fixed ``mu``: the loads are
    linear in these), so ``(I - L G_lambda) lambda = L (G_theta theta + G_beta beta
    + G_nu[:, 0] muz)``.  Its first row is the momentum balance
    ``lambda0 = C_T/(2 mu)`` solved with the blade-element ``C_T`` at trim.

    ``v``: the speed through the disc in ``L`` (default ``mu``, forward flight only;
    the model's ``Constants.flow_speed``, so that with the mass-flow speed the trim
    is the steady state of the same model down to hover).

    Returns
    -------
    ndarray, shape (3,)
        ``(lambda0, lambda1c, lambda1s)`` [-].
    """
    lm = ld.momentum_l(mu, a0s, v)
    theta, beta = (np.array([_real(x) for x in v]) for v in (theta, beta))
    rhs = lm @ (ld.g_theta(mu) @ theta + ld.g_beta(mu) @ beta + ld.g_nu(mu)[:, 0] * muz)
    return _solve(np.eye(3) - lm @ ld.g_lambda(mu), rhs)


def inplane_load_derivatives(mu, theta, beta, muz, lam) -> np.ndarray:
    """``d c / d(mux, muy)`` at trim, ``c = (C_T, C_mc, C_ms)/(a0 s)``, shape (3, 2).

    Rows ``C_T, C_mc`` (pitch, nose up +), ``C_ms`` (roll, starboard down +);
    columns ``mux, muy`` [per unit advance ratio].
    """
    t0, t1c, t1s = theta
    b0, b1c, b1s = beta
    l0, l1c, l1s = lam
    return np.array([
        [mu * t0 / 2 + t1s / 4 - l1s / 8,
         t1c / 4 - l1c / 8],
        [b0 / 12 + mu * b1s / 16 - mu * t1c / 16,
         mu * b1c / 16 + l0 / 8 - mu * t1s / 16 - muz / 8 - t0 / 6],
        [mu * b1c / 16 + l0 / 8 - 3 * mu * t1s / 16 - muz / 8 - t0 / 6,
         -b0 / 12 - mu * b1s / 16 - mu * t1c / 16],
    ])


def inplane_flap_derivatives(mu, theta, beta, muz, lam) -> np.ndarray:
    """Flap forcing per ``n_beta`` by ``(mux, muy)`` at trim, shape (3, 2).

    The single-blade aerodynamic moment ``4 n_beta int_0^1 r F dr`` (``gamma/2 =
    4 n_beta``) differentiated in ``mux, muy`` and projected on the multiblade rows
    ``(1/2pi) int d psi``, ``(1/pi) int cos psi d psi``, ``(1/pi) int sin psi d psi``,
    divided by ``n_beta``: the ``mux, muy`` columns of ``H_u / n_beta`` in Eq. (1).
    """
    t0, t1c, t1s = theta
    b0, b1c, b1s = beta
    l0, l1c, l1s = lam
    return np.array([
        [2 * mu * t0 + 4 * t1s / 3 - 2 * l1s / 3,
         4 * t1c / 3 - 2 * l1c / 3],
        [-4 * b0 / 3 - mu * b1s + mu * t1c,
         -mu * b1c - 2 * l0 + mu * t1s + 2 * muz + 8 * t0 / 3],
        [-mu * b1c - 2 * l0 + 3 * mu * t1s + 2 * muz + 8 * t0 / 3,
         4 * b0 / 3 + mu * b1s + mu * t1c],
    ])


def wake_skew_angle(mu: float, lambda0: float, muz: float) -> float:
    """Wake skew angle ``chi`` [rad] from the disc normal: ``tan chi = mu /
    (lambda0 - muz)`` (flow down through the disc ``lambda0 - muz``)."""
    return math.atan2(mu, lambda0 - muz)


def pitt_peters_skew_gain(chi: float) -> float:
    """Pitt-Peters wake-skew coupling ``15 pi/64 tan(chi/2)`` [-]."""
    return 15 * math.pi / 64 * math.tan(chi / 2)


__all__ = ["TRIM_KEYS", "trim_state", "trim_inflow", "inplane_load_derivatives",
           "inplane_flap_derivatives", "wake_skew_angle", "pitt_peters_skew_gain"]
