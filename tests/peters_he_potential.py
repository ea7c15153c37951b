"""A first-principles route to Peters-He's inflow gain in a skewed wake (tests only).

Linearised actuator-disc theory: the pressure ``Delta p = P_n^m(nu) cos m psi`` (or
``sin``) on the disc has Kinner's acceleration potential, in oblate spheroidal
coordinates (``x = sqrt(1-nu^2) sqrt(1+eta^2) cos psi``, ``y = .. sin psi``,
``z = nu eta``; ``nu = sqrt(1 - r^2)``, ``eta = 0`` on the disc)::

    Phi = -(1/2) P_n^m(nu) Q_n^m(i eta)/Q_n^m(i 0) cos m psi    (z > 0, Phi = p/rho)

and the linearised momentum equation along the free stream, ``V d v/d s = -grad Phi``,
gives the induced inflow (down positive) at a disc point by integrating upstream along
the skewed free stream (direction ``(-sin chi, 0, cos chi)``, ``x`` aft, ``psi = 0``
aft, ``chi`` the wake skew from the disc normal)::

    V lambda(P) = int_0^inf dPhi/dz (P + s (-sin chi, 0, cos chi)) ds

(``chi = 0``: ``-Phi`` on the disc, ``Delta p / 2``, local momentum).  The gain is
then the projection with the pressure functions as test functions,
``L_jn^rm = 2 V (1/(pi e_r)) int int lambda P_j^r(nu) cos r psi r dr dpsi``
(``e_0 = 2``, else 1), Peters-He's ``alpha = L tau / (2V)``.

Nothing here comes from the library: ``P_n^m`` are scipy's associated Legendre
functions, normalised numerically; ``Q_n^m(i eta)`` is built from them by the
Wronskian (``Q = P int_eta^inf dt / ((1+t^2) P(it)^2)``, regularised at 0); the
integrals are Gauss quadratures.  Accuracy about 1e-4 (the upstream integral near
the disc's edge).
"""
from __future__ import annotations

import math
import warnings
from functools import lru_cache

import numpy as np
from scipy import integrate, special
from scipy.interpolate import CubicSpline

PP = np.polynomial.polynomial


@lru_cache(maxsize=None)
def _pnorm(m, n):
    val, _ = integrate.quad(lambda nu: special.lpmv(m, n, nu) ** 2, 0.0, 1.0,
                            epsabs=0, epsrel=1e-13, limit=200)
    return np.sign(special.lpmv(m, n, math.sqrt(1 - 1e-6))) / math.sqrt(val)


def pbar(m, n, nu):
    """Normalised ``P_n^m(nu)`` (``int_0^1 P^2 dnu = 1``, ``P/nu ~ +r^m`` at the centre)."""
    return _pnorm(m, n) * special.lpmv(m, n, nu)


def _dpbar(m, n, nu):
    # (nu^2 - 1) dP_n^m/dnu = n nu P_n^m - (n + m) P_{n-1}^m
    return _pnorm(m, n) * (n * nu * special.lpmv(m, n, nu)
                           - (n + m) * special.lpmv(m, n - 1, nu)) / (nu * nu - 1)


@lru_cache(maxsize=None)
def _qbar(m, n):
    """Splines of ``Q_n^m(i eta)/Q_n^m(i 0)`` and its ``eta``-derivative in
    ``u = eta/(1 + eta)``."""
    leg = np.zeros(n + 1)
    leg[n] = 1.0
    pm = PP.polyder(np.polynomial.legendre.leg2poly(leg), m)
    g = np.array([(1j ** k * c).imag for k, c in enumerate(pm)])   # P^(m)(i eta) = i g
    c1 = g[1]

    def f(t):
        return 1.0 / ((1 + t * t) ** (m + 1) * PP.polyval(t, g) ** 2)

    def f_reg(t):                     # f - 1/(c1 t)^2, bounded at 0
        t = max(t, 1e-3)
        return f(t) - 1.0 / (c1 * c1 * t * t)

    u = np.linspace(0.0, 1.0, 1201)[:-1]
    eta = u / (1 - u)
    # I(eta) = int_eta^inf f dt: summed from the tail where eta >= 1/2 (no
    # cancellation), 1/(c1^2 eta) + int_eta^inf (f - 1/(c1 t)^2) dt below (bounded)
    big = eta >= 0.5
    i_big = eta[big]
    tail = integrate.quad(f, i_big[-1], np.inf, epsabs=0, epsrel=1e-12)[0]
    seg = [integrate.quad(f, a, b, epsabs=0, epsrel=1e-12)[0]
           for a, b in zip(i_big[:-1], i_big[1:])]
    ib = np.concatenate([np.cumsum(seg[::-1])[::-1], [0.0]]) + tail
    small = eta[~big]
    e0 = i_big[0]
    j0 = ib[0] - 1 / (c1 * c1 * e0)
    with warnings.catch_warnings():        # roundoff near 0: the value is exact enough
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        seg = [integrate.quad(f_reg, a, b, epsabs=0, epsrel=1e-12)[0]
               for a, b in zip(small, np.append(small[1:], e0))]
    js = np.cumsum(seg[::-1])[::-1] + j0
    e = eta[1:]
    total = np.concatenate([1 / (c1 * c1 * small[1:]) + js[1:], ib])
    gg, dg = PP.polyval(e, g), PP.polyval(e, PP.polyder(g))
    w, dw = (1 + e * e) ** (m / 2), m * e * (1 + e * e) ** (m / 2 - 1)
    q = np.concatenate([[1.0], c1 * gg * w * total])
    dq = c1 * ((dg * w + gg * dw) * total - gg * w * f(e))
    dq = np.concatenate([[dq[0]], dq])
    return CubicSpline(u, q), CubicSpline(u, dq)


def dphi_dz(kind, m, n, x, y, z):
    """``dPhi/dz`` of the pressure ``P_n^m cos (sin) m psi`` at ``z > 0``."""
    a = x * x + y * y + z * z - 1
    eta = np.sqrt((a + np.sqrt(a * a + 4 * z * z)) / 2)
    nu = z / eta
    psi = np.arctan2(y, x)
    trig = np.cos(m * psi) if kind == "c" else np.sin(m * psi)
    nu_z = eta * (1 - nu * nu) / (eta * eta + nu * nu)
    eta_z = nu * (1 + eta * eta) / (eta * eta + nu * nu)
    q, dq = _qbar(m, n)
    u = eta / (1 + eta)
    return -0.5 * trig * (_dpbar(m, n, nu) * q(u) * nu_z + pbar(m, n, nu) * dq(u) * eta_z)


def _grid(chi, nr, npsi, ns):
    """Gauss-Legendre radii ``r`` (weights ``wr``), equally spaced azimuths ``psi``, and
    the points ``(X, Y, Z)`` upstream along the skewed path ``s`` in ``[0, inf)``
    (weights ``ws``: ``s = t / (1 - t)``) from every disc point."""
    xr, wr = np.polynomial.legendre.leggauss(nr)
    r, wr = (xr + 1) / 2, wr / 2
    psi = 2 * np.pi * np.arange(npsi) / npsi
    xt, wt = np.polynomial.legendre.leggauss(ns)
    t, wt = (xt + 1) / 2, wt / 2
    s, ws = t / (1 - t), wt / (1 - t) ** 2
    R, PS, S = np.meshgrid(r, psi, s, indexing="ij")
    return r, wr, psi, (R * np.cos(PS) - S * math.sin(chi), R * np.sin(PS),
                        S * math.cos(chi)), ws


def gain(states, chi, nr=20, npsi=40, ns=60):
    """``L(chi)`` of ``states`` (``(kind, m, n)``) by quadrature, wake skew ``chi``
    [rad] (below 90 deg: the upstream path then leaves the disc's plane)."""
    r, wr, psi, (X, Y, Z), ws = _grid(chi, nr, npsi, ns)
    v_lam = [np.sum(dphi_dz(k, m, n, X, Y, Z) * ws, axis=2) for k, m, n in states]
    out = np.zeros((len(states), len(states)))
    for a, (ka, rr, j) in enumerate(states):
        test = pbar(rr, j, np.sqrt(1 - r * r))[:, None] * (
            np.cos(rr * psi) if ka == "c" else np.sin(rr * psi))[None, :]
        e_r = 2.0 if rr == 0 else 1.0
        for b in range(len(states)):
            out[a, b] = 2 * np.sum(wr[:, None] * r[:, None] * test * v_lam[b]) * (
                2 * np.pi / npsi) / (np.pi * e_r)
    return out


def least_squares_inflow(state, chi, nr=20, npsi=40, ns=60):
    """``(lambda0, lambda1c, lambda1s)`` times ``V``: the area-weighted least-squares
    fit of ``lambda0 + r (lambda1c cos + lambda1s sin)`` to the inflow of the pressure
    ``state`` (Pitt and Peters' Galerkin projection)."""
    r, wr, psi, xyz, ws = _grid(chi, nr, npsi, ns)
    k, m, n = state
    lam = np.sum(dphi_dz(k, m, n, *xyz) * ws, axis=2)
    w = wr[:, None] * r[:, None] * (2 * np.pi / npsi)
    return np.array([np.sum(w * lam) / np.pi,
                     np.sum(w * lam * r[:, None] * np.cos(psi)) / (np.pi / 4),
                     np.sum(w * lam * r[:, None] * np.sin(psi)) / (np.pi / 4)])
