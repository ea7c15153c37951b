"""The lag modes coupled to flap, in multiblade coordinates (``model.md`` 9.1).

Rigid blade, flap and lag about a central hinge with equivalent springs (the lag
frequency ``nu_zeta`` [per rev] holds a lag hinge offset's centrifugal stiffness),
lag angle ``zeta`` positive *against* the rotation (aft, Johnson's convention),
azimuth time (``' = d/dpsi``), moments over ``I_b Omega^2``.  Single blade, linear
about an axisymmetric trim (collective ``theta_t``, coning ``beta_t``, trim up-flow
``u = muz_t - lambda0_t``)::

    beta'' + lambda_beta2 beta - 2 beta_t zeta'             = 4 n_beta int r (theta U_T^2 + U_P U_T) dr
    zeta'' + C_zeta zeta' + nu_zeta^2 zeta + 2 beta_t beta' = 4 n_beta int r (-(theta U_T U_P + U_P^2) + delta U_T^2) dr

with ``U_T = r (1 - zeta') + mu sin(psi - zeta)``, ``U_P = muz - lambda_i - r beta'
- mu beta cos(psi - zeta) + r (pbar sin psi + qbar cos psi)`` (the base model's,
section 1, with the blade's azimuth ``psi - zeta``), ``delta = c_d0 / a0`` the profile
drag over the lift slope, ``C_zeta = 2 zeta_lag nu_zeta`` the lag damper.  The
``2 beta_t`` terms are the Coriolis coupling (a blade flapping up comes nearer the
shaft and, keeping its angular momentum, leads: ``zeta'' = -2 beta_t beta'``).

Projected on ``(1, 2 cos psi, 2 sin psi)`` and averaged over the azimuth (the base
model's constant-coefficient approximation), with ``zeta = zeta0 + zeta1c cos psi
+ zeta1s sin psi``.  The functions return the averaged coefficients; columns ``x =
(zeta0, zeta1c, zeta1s, zeta0', zeta1c', zeta1s')``.  Derived with sympy
(``bench/lead_lag_derivation.py``); checked against the individual-blade equations
integrated blade by blade (``tests/test_lead_lag.py``).  Pure functions of numbers
or of sympy symbols (the FMU's C is generated from them).
"""
from __future__ import annotations

import numpy as np

#: Blade section profile drag coefficient ``c_d0`` [-] (NACA 0012 at the small
#: angles of a trimmed rotor; Johnson, *Helicopter Theory*, uses 0.01).
CD0 = 0.01


def _arr(rows):
    try:
        return np.array(rows, dtype=float)
    except TypeError:                # symbols: the FMU's generator
        return np.array(rows, dtype=object)


def flap_lag_aero(mu, nb, th, b, u):
    """Aerodynamic flap moments of the lag, multiblade flap rows ``(beta0, beta1c,
    beta1s)`` by ``x = (zeta0, zeta1c, zeta1s, zeta0', zeta1c', zeta1s')`` [-] (the
    Coriolis terms are not in it: :func:`flap_coupling`)."""
    o = 0 * mu
    return _arr([
        [o, -mu * nb * u, o, -2 * nb * (3 * th + 2 * u) / 3, 2 * b * mu * nb / 3,
         -4 * mu * nb * th / 3],
        [-2 * mu * nb * (4 * th + 3 * u) / 3, b * mu**2 * nb,
         -nb * (3 * mu**2 * th + 6 * th + 4 * u) / 3, 4 * b * mu * nb / 3,
         -2 * nb * (3 * th + 2 * u) / 3, o],
        [-4 * b * mu * nb / 3, nb * (-3 * mu**2 * th + 6 * th + 4 * u) / 3,
         -b * mu**2 * nb, -8 * mu * nb * th / 3, o, -2 * nb * (3 * th + 2 * u) / 3]])


def flap_coupling(mu, nb, th, b, u):
    """Everything the lag adds to the flap rows' right-hand side: the aerodynamic
    moments and the Coriolis ``+2 beta_t zeta'`` projected, ``2 beta_t zeta0'``,
    ``2 beta_t (zeta1c' + zeta1s)`` and ``2 beta_t (zeta1s' - zeta1c)`` [-]."""
    o = 0 * b
    cor = _arr([[o, o, o, 2 * b, o, o],
                [o, o, 2 * b, o, 2 * b, o],
                [o, -2 * b, o, o, o, 2 * b]])
    return flap_lag_aero(mu, nb, th, b, u) + cor


def load_coupling(mu, th, b, u):
    """``(C_T, C_mc, C_ms) / (a0 s)`` per ``x = (zeta0, zeta1c, zeta1s, zeta0',
    zeta1c', zeta1s')`` (section 3's loads with the lag's ``U_T``, each blade's
    lift acting on the hub where the blade is, at ``psi - zeta``) [-].

    The hub moments' displacement columns hold both the lag's change of the lift
    and the lift's displacement with the blade; a collective lag (the whole rotor
    turned in azimuth about an axisymmetric trim) leaves them unchanged, the
    cyclic lag moves the centre of lift: ``C_mc`` per ``zeta1s`` is ``theta (2 -
    mu^2) / 32`` (``model.md`` 9.1; the blade truth's ``lag_terms``)."""
    o = 0 * mu
    return _arr([
        [o, -mu * u / 4, o, -(4 * th + 3 * u) / 12, b * mu / 8, -mu * th / 4],
        [o, -b * mu**2 / 32, th * (2 - mu**2) / 32, -b * mu / 12,
         (3 * th + 2 * u) / 24, o],
        [o, -th * (2 - 3 * mu**2) / 32, b * mu**2 / 32,
         mu * th / 6, o, (3 * th + 2 * u) / 24]])


def lag_aero(mu, nb, th, b, u, dl):
    """Aerodynamic lag moments, rows ``(zeta0, zeta1c, zeta1s)`` of the projected lag
    equation, as ``(z, x, inputs)``: per ``z = (beta, lambda, beta')`` (3 x 9), per
    the lag's own ``x`` (3 x 6) and per the azimuth-unit inputs ``(theta0, theta1c,
    theta1s, muz, qbar, pbar)`` (3 x 6) [-]; ``dl = c_d0 / a0``."""
    o = 0 * mu
    k = nb * (3 * th + 8 * u) / 3
    z = _arr([
        [-2 * b * mu**2 * nb, 2 * mu * nb * u, -4 * b * mu * nb / 3,
         4 * nb * (th + 3 * u) / 3, -4 * b * mu * nb / 3, 2 * mu * nb * th / 3,
         k, -4 * b * mu * nb / 3, 2 * mu * nb * th / 3],
        [4 * mu * nb * (th + 3 * u) / 3, -3 * b * mu**2 * nb,
         nb * (3 * mu**2 * th + 6 * th + 16 * u) / 6,
         -4 * b * mu * nb, k, o,
         -8 * b * mu * nb / 3, k, o],
        [o, -nb * (-3 * mu**2 * th + 6 * th + 16 * u) / 6, -b * mu**2 * nb,
         2 * mu * nb * th, o, k,
         4 * mu * nb * th / 3, o, k]])
    d = 2 * nb * (2 * th * u - 3 * dl) / 3
    x = _arr([
        [o, mu * nb * th * u, 2 * b * mu * nb * u, d, -2 * b * mu * nb * th / 3,
         -4 * dl * mu * nb / 3],
        [2 * mu * nb * (3 * th * u - 4 * dl) / 3, -b * mu**2 * nb * th,
         nb * (-3 * b**2 * mu**2 - 3 * dl * mu**2 - 6 * dl + 4 * th * u) / 3,
         -4 * b * mu * nb * th / 3, d, o],
        [4 * b * mu * nb * (th + 3 * u) / 3,
         -nb * (3 * b**2 * mu**2 + 3 * dl * mu**2 - 6 * dl + 4 * th * u) / 3,
         b * mu**2 * nb * th, -8 * dl * mu * nb / 3, o, d]])
    inputs = _arr([
        [-4 * nb * u / 3, 2 * b * mu * nb / 3, -mu * nb * u, -4 * nb * (th + 3 * u) / 3,
         4 * b * mu * nb / 3, -2 * mu * nb * th / 3],
        [4 * b * mu * nb / 3, -4 * nb * u / 3, b * mu**2 * nb / 2, 4 * b * mu * nb, -k, o],
        [-2 * mu * nb * u, b * mu**2 * nb / 2, -4 * nb * u / 3, -2 * mu * nb * th, o, -k]])
    return z, x, inputs


def lag_structure(nu_zeta, zeta_lag, b):
    """The projected lag equation's structural and inertial part moved to the
    right-hand side, rows ``(zeta0, zeta1c, zeta1s)``: ``(per z, per x)`` (3 x 9,
    3 x 6) [-].

    ``zeta0'' = -nu^2 zeta0 - C zeta0' - 2 beta_t beta0'``,
    ``zeta1c'' = -(nu^2 - 1) zeta1c - C zeta1s - C zeta1c' - 2 zeta1s'
    - 2 beta_t (beta1c' + beta1s)`` and ``zeta1s'' = -(nu^2 - 1) zeta1s + C zeta1c
    - C zeta1s' + 2 zeta1c' - 2 beta_t (beta1s' - beta1c)``, ``C = 2 zeta_lag nu``."""
    c = 2 * zeta_lag * nu_zeta
    k0 = nu_zeta**2
    k = k0 - 1
    o = 0 * b
    x = _arr([[-k0, o, o, -c, o, o],
              [o, -k, -c, o, -c, -2 + o],
              [o, c, -k, o, 2 + o, -c]])
    z = _arr([[o, o, o, o, o, o, -2 * b, o, o],
              [o, o, -2 * b, o, o, o, o, -2 * b, o],
              [o, 2 * b, o, o, o, o, o, o, -2 * b]])
    return z, x


__all__ = ["flap_lag_aero", "flap_coupling", "load_coupling", "lag_aero", "lag_structure"]
