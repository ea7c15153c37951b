"""The speed through the disc of Eq. (14), linearised about the trim over the whole disc.

Local momentum theory (Eq. 5 with ``T = int 2 rho v_i V dA``) gives the loads the
inflow balances:

``c_mom = 4/(a0 s) avg_psi int_0^1 (1, -r cos psi, -r sin psi) lambda_i V r dr``,
``lambda_i = lambda0 + (lambda1c cos psi + lambda1s sin psi) r``,

with, in Eq. (14), ``V = sqrt(mux^2 + muy^2 + (w - lambda_i)^2)`` and ``w`` the blade
normal velocity of Eq. (15) at each point of the tip-path plane (flap, flap rate,
pitch, hub rates, ``muz``).  With ``V = mu`` the loads are ``L^-1 lambda`` exactly and
the inflow equation is the basic model (2); the paper's Glauert augmentation
(Eqs. 16-20) keeps, of Eq. (14)'s perturbations, the first-harmonic normal
velocity ``nu_lambda`` and the in-plane speed.  Linearised exactly, Eq. (14) also
changes the mass flow of every inflow harmonic (the self-terms ``V - mu`` and
``lambda_i dV/dlambda``), couples the mean inflow to the mean normal velocity
(``muz``, ``theta0``, ``beta0'``) and the harmonics to each other.

:func:`momentum_loads` evaluates ``c_mom`` on a disc quadrature (uniform in
azimuth, Gauss-Legendre in radius) from multiblade values, the same sums as the
individual-blade truth (:meth:`inflowsim.flighttest.bladesim.BladeRotor.
momentum_loads`); :func:`speed_coupling` differentiates it by complex steps at the
trim and returns what Eq. (14) adds to the inflow equation's right-hand side;
:func:`eq14_trim_inflow` is the trim inflow with that speed.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from . import loads as ld

#: Disc quadrature: azimuths (uniform) and radial Gauss-Legendre points.  The
#: integrand is smooth (the square root stays away from zero in forward flight), so
#: 24 x 6 points change the coupling by less than 1e-6 of its size from 48 x 12.
N_PSI, N_R = 24, 6
#: Complex step [-]: exact derivatives to rounding, no subtraction.
STEP = 1e-30


@lru_cache(maxsize=8)
def _disc(n_psi: int, n_r: int):
    x, w = np.polynomial.legendre.leggauss(int(n_r))
    r, wr = 0.5 * (x + 1.0), 0.5 * w
    psi = 2.0 * np.pi * np.arange(n_psi) / n_psi
    c, s = np.cos(psi), np.sin(psi)
    basis = np.column_stack([np.ones_like(psi), c, s, c * c, s * s, c * s])
    rr = np.vstack([np.ones_like(r), r])
    # (1, -r cos, -r sin) lambda_i V r over the disc, times 1/n_psi and the r weights
    w_disc = np.column_stack([wr * r, wr * r * r]) / n_psi
    return basis, rr, w_disc


def speed_integrand(z, u, c, s, r, speed: str = "eq14", sqrt=np.sqrt):
    """``lambda_i V`` [-] at one point of the disc: azimuth ``(cos psi, sin psi) =
    (c, s)``, radius ``r`` [-].

    The one description of the integrand: :func:`momentum_loads` sums it over the
    disc, and the FMU's C is generated from it (:mod:`inflowsim.fmu.codegen`, with
    ``sqrt`` sympy's).  Elementwise: the arguments broadcast (numbers, arrays,
    complex steps or symbols).

    Parameters
    ----------
    z : sequence of 9
        ``beta0, beta1c, beta1s`` [rad], their azimuth derivatives [rad/rad],
        ``lambda0, lambda1c, lambda1s`` [-].
    u : sequence of 10
        Totals in azimuth units, ``channels.INPUTS_AZ`` order.
    c, s, r : float or array_like
        Cosine and sine of the azimuth, radius over ``R``.
    speed : {"eq14", "mu"}
        Eq. (14)'s ``V``, or ``V = mux``.
    """
    b0, b1c, b1s, db0, db1c, db1s, lam0, lam1c, lam1s = z
    th0, th1c, th1s, muz, qb, pb, _, _, mux, muy = u
    lam_i = lam0 + (lam1c * c + lam1s * s) * r
    if speed == "mu":
        return lam_i * mux
    # multiblade coordinates of the blades' flap rates (rotating-frame terms)
    d0, d1c, d1s = db0, db1c + b1s, db1s - b1c
    # w = A0 + A1 r, the harmonic products of Eq. (15) as in the blade truth
    a0 = (muz + c * (th0 * muy - b0 * mux) + s * (th0 * mux + b0 * muy)
          + c * c * (th1c * muy - b1c * mux) + s * s * (th1s * mux + b1s * muy)
          + c * s * (th1c * mux + b1c * muy + th1s * muy - b1s * mux))
    a1 = (th0 - d0) + c * (th1c - d1c + qb) + s * (th1s - d1s + pb)
    wl = a0 + a1 * r - lam_i
    return lam_i * sqrt(mux * mux + muy * muy + wl * wl)


def disc_points(n_psi: int = N_PSI, n_r: int = N_R):
    """The disc quadrature as points: ``(c, s, r, w0, w1)``, each of ``n_psi n_r``,
    with ``c_mom = 4/(a0 s) (sum w0 q, -sum c w1 q, -sum s w1 q)`` for ``q`` the
    :func:`speed_integrand` at the points (azimuth-major)."""
    basis, rr, w_disc = _disc(n_psi, n_r)
    c, s = (np.repeat(basis[:, i], n_r) for i in (1, 2))
    return (c, s, *(np.tile(x, n_psi) for x in (rr[1], w_disc[:, 0], w_disc[:, 1])))


def momentum_loads(z, u, a0s: float, speed: str = "eq14", n_psi: int = N_PSI,
                   n_r: int = N_R) -> np.ndarray:
    """Local-momentum loads ``c_mom`` [-] of the multiblade state ``z`` and inputs ``u``.

    Parameters
    ----------
    z : array_like, shape (9,) or (9, m)
        ``beta0, beta1c, beta1s`` [rad], their azimuth derivatives [rad/rad],
        ``lambda0, lambda1c, lambda1s`` [-] (complex allowed: complex steps).
    u : array_like, shape (10,) or (10, m)
        Totals in azimuth units, ``channels.INPUTS_AZ`` order (``theta0 theta1c
        theta1s muz qbar pbar qbar' pbar' mux muy``).
    a0s : float
        Lift slope times solidity [-].
    speed : {"eq14", "mu"}
        Eq. (14)'s ``V``, or ``V = mux`` (then ``c_mom = L^-1 lambda``).

    Returns
    -------
    ndarray, shape (3,) or (3, m)
        ``(C_T, C_mc, C_ms)/(a0 s)`` of local momentum.
    """
    z, u = np.asarray(z), np.asarray(u)
    basis, rr, w_disc = _disc(n_psi, n_r)
    # (azimuth, [m], radius): the state's elements gain the radius axis, the
    # azimuth functions the others
    extra = (1,) * (max(z.ndim, u.ndim) - 1) + (1,)
    c, s = (basis[:, i].reshape((-1,) + extra) for i in (1, 2))
    q = speed_integrand([x[..., None] for x in z], [x[..., None] for x in u], c, s,
                        rr[1], speed)
    m = np.tensordot(basis[:, :3].T, q @ w_disc, axes=1) * (4.0 / a0s)   # (3, ..., 2)
    return np.array([m[0, ..., 0], -m[1, ..., 1], -m[2, ..., 1]])


#: Newton's method for the trim inflow: at most this many steps, stopping at a step
#: below this size (the FMU's C is generated with the same).
NEWTON_STEPS = 30
NEWTON_TOL = 1e-13


def eq14_trim_inflow(mu: float, a0s: float, theta, beta, muz: float,
                     lam_start=None, tol: float = NEWTON_TOL, v=None) -> np.ndarray:
    """Trim inflow ``(lambda0, lambda1c, lambda1s)`` [-] with Eq. (14)'s speed: the
    blade-element loads (linear in ``lambda`` at fixed ``mu``) equal the momentum
    loads, by Newton's method from the basic model's trim inflow (with ``v`` its
    speed through the disc, :func:`inflowsim.physics.bladeelement.trim_inflow`)."""
    from .bladeelement import trim_inflow
    theta, beta = np.asarray(theta, dtype=float), np.asarray(beta, dtype=float)
    lam = trim_inflow(mu, a0s, theta, beta, muz, v) if lam_start is None else \
        np.asarray(lam_start, dtype=float)
    blade = ld.g_theta(mu) @ theta + ld.g_beta(mu) @ beta + ld.g_nu(mu)[:, 0] * muz
    u = np.array([*theta, muz, 0.0, 0.0, 0.0, 0.0, mu, 0.0])
    for _ in range(NEWTON_STEPS):
        z = np.concatenate([beta, np.zeros(3), lam])
        f = blade + ld.g_lambda(mu) @ lam - momentum_loads(z, u, a0s)
        zc = z[:, None] + 1j * STEP * np.vstack([np.zeros((6, 3)), np.eye(3)])
        jac = ld.g_lambda(mu) - momentum_loads(zc, u[:, None] * np.ones(3), a0s).imag / STEP
        step = np.linalg.solve(jac, f)
        lam = lam - step
        if np.max(np.abs(step)) < tol:
            break
    return lam


def speed_coupling(mu: float, a0s: float, theta, beta, muz: float, lam,
                   n_psi: int = N_PSI, n_r: int = N_R, v=None) -> tuple:
    """What Eq. (14)'s speed adds to the inflow equation's right-hand side
    (``D_tau lambda' + lambda = ... - J (z, u)``), linearised at the trim.

    ``J = L dc_mom/d(z, u) - [0 0 I 0]``: the momentum loads' derivatives with the
    base model's part (``L^-1 lambda``) taken out, ``L`` the base model's gain at
    ``mu`` with its speed through the disc ``v`` (default ``mu``, the paper's).
    Whatever that speed, the inflow rows' loads become Eq. (14)'s linearised ones
    (only the apparent mass stays scaled by ``L``), so with the mass-flow speed the
    effect reaches hover.

    Returns
    -------
    (ndarray (3, 9), ndarray (3, 10))
        ``-J`` on the states ``(beta, beta', lambda)`` and on the inputs (azimuth
        units, ``INPUTS_AZ`` order): add them to ``p_beta, p_dbeta, p_lambda, p_u``.
    """
    z0 = np.concatenate([np.asarray(beta, float), np.zeros(3), np.asarray(lam, float)])
    u0 = np.array([*np.asarray(theta, float), muz, 0.0, 0.0, 0.0, 0.0, mu, 0.0])
    w0 = np.concatenate([z0, u0])
    wc = w0[:, None] + 1j * STEP * np.eye(w0.size)
    dc = momentum_loads(wc[:9], wc[9:], a0s, "eq14", n_psi, n_r).imag / STEP
    j = ld.momentum_l(mu, a0s, v) @ dc
    j[:, 6:9] -= np.eye(3)
    return -j[:, :9], -j[:, 9:]


__all__ = ["speed_integrand", "disc_points", "momentum_loads", "eq14_trim_inflow",
           "speed_coupling", "N_PSI", "N_R", "NEWTON_STEPS", "NEWTON_TOL"]
