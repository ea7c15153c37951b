"""A second route to the Peters-He rotor model (tests only): every Peters-He state in
its own variable ``alpha`` (no base model, no appended blocks), the shape functions
from scipy's associated Legendre functions (``phi = P_n^m(nu)/nu``, normalised
numerically), the gain ``L = int_0^1 P_j P_n r dr`` by adaptive quadrature, the
pressure and flap integrals by a fresh quadrature at the given ``mu``.  Only the
paper's flap matrices (``physics.flapping``, section 2) come from the library.

Used by ``tests/test_peters_he.py`` (the effects equal this) and for records no
generator of the project made."""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy import integrate, special

from inflowsim.channels import input_scale
from inflowsim.physics import flapping as fl


def states_of(power):
    """(kind, m, n): cos/sin, harmonic, radial index; the three lowest first."""
    low = [("c", 0, 1), ("c", 1, 2), ("s", 1, 2)]
    rest = [(k, m, n) for m in range(power + 1) for n in range(m + 1, power + 2, 2)
            for k in (("c",) if m == 0 else ("c", "s")) if (k, m, n) not in low]
    return low + rest


@lru_cache(maxsize=None)
def _norm(m, n):
    val, _ = integrate.quad(lambda nu: special.lpmv(m, n, nu) ** 2, 0.0, 1.0,
                            epsabs=0, epsrel=1e-13, limit=200)
    sign = np.sign(special.lpmv(m, n, math.sqrt(1 - 1e-6)))   # r -> 0: phi ~ +r^m
    return sign / math.sqrt(val)


def pbar(m, n, nu):
    return _norm(m, n) * special.lpmv(m, n, nu)


def shape(m, n, r):
    """``phi_n^m(r) = P_n^m(nu)/nu``."""
    nu = np.sqrt(1.0 - np.asarray(r, float) ** 2)
    return pbar(m, n, nu) / nu


@lru_cache(maxsize=None)
def _axial_gain(power):
    st = states_of(power)
    out = np.zeros((len(st), len(st)))
    for a, (ka, m, j) in enumerate(st):
        for b, (kb, mm, n) in enumerate(st):
            if ka == kb and m == mm:
                out[a, b] = integrate.quad(
                    lambda r: pbar(m, j, math.sqrt(1 - r * r)) * pbar(m, n, math.sqrt(1 - r * r))
                    * r, 0.0, 1.0, epsabs=0, epsrel=1e-12, limit=200)[0]
    return out


def _hnm(n, m):
    num = math.prod(range(n + m - 1, 0, -2)) * math.prod(range(n - m - 1, 0, -2))
    return num / (math.prod(range(n + m, 0, -2)) * math.prod(range(n - m, 0, -2)))


def gain(power, x=0.0):
    """Peters-He's inflow gain at wake skew ``x = tan(chi/2)``: between harmonics
    ``r`` (row) and ``m`` (column) of one kind the factor ``x^m`` (``r = 0``) or
    ``x^|m-r| +- (-1)^min(r,m) x^(m+r)`` (cosine +, sine -) times ``Gamma_jn^rm``:
    for ``r = m`` the quadrature ``int P_j P_n r dr`` above, otherwise the published
    closed forms (Peters & He 1995), written out here again: ``r + m`` even,
    ``(-1)^((n+j)/2 - r) 2 sqrt((2n+1)(2j+1)) / (sqrt(H_n^m H_j^r) (n+j)(n+j+2)
    ((n-j)^2-1))``; odd, ``j = n +- 1``: ``+-(pi/2) / (sqrt(H_n^m H_j^r) sqrt((2n+1)
    (2j+1)))``, the sign of ``r - m``; else 0.  (The closed forms are checked against
    the pressure potential's quadrature in ``tests/test_peters_he.py``.)"""
    st = states_of(power)
    out = _axial_gain(power).copy()
    for a, (ka, r, j) in enumerate(st):
        for b, (kb, m, n) in enumerate(st):
            if ka != kb:
                continue
            if r == 0:
                factor = x ** m
            else:
                second = (-1) ** min(r, m) * x ** (m + r)
                factor = x ** abs(m - r) + (second if ka == "c" else -second)
            if r == m:
                out[a, b] *= factor
                continue
            den = math.sqrt(_hnm(n, m) * _hnm(j, r))
            if (r + m) % 2 == 0:
                g = ((-1) ** ((n + j) // 2 - r) * 2 * math.sqrt((2 * n + 1) * (2 * j + 1))
                     / (den * (n + j) * (n + j + 2) * ((n - j) ** 2 - 1)))
            elif abs(n - j) == 1:
                g = math.copysign(math.pi / 2, r - m) / (den * math.sqrt((2 * n + 1) * (2 * j + 1)))
            else:
                g = 0.0
            out[a, b] = factor * g
    return out


def trim_skew(mu, a0s, v, theta, beta, muz):
    """``X = tan(chi/2)`` of the trim: the three-state momentum model's steady inflow
    (``lambda0 = C_T/(2V)``, ``lambda1c,s = -2 C_mc,s / V``) with the blade-element
    loads of the trim pitch ``theta``, flap ``beta`` (multiblade, steady) and ``muz``
    by quadrature, linear in the inflow; ``tan chi = mu / (lambda0 - muz)``."""
    r, wr, psi = _grid()
    R, P = np.meshgrid(r, psi, indexing="ij")
    W = np.outer(wr, np.ones_like(psi)) / len(psi)
    c, s = np.cos(P), np.sin(P)
    ut = R + mu * s

    def loads(lam):
        th = theta[0] + theta[1] * c + theta[2] * s
        b = beta[0] + beta[1] * c + beta[2] * s
        rate = beta[2] * c - beta[1] * s
        li = lam[0] + R * (lam[1] * c + lam[2] * s)
        f = th * ut * ut + (muz - li - R * rate - mu * b * c) * ut
        return 0.5 * np.array([np.sum(W * f), -np.sum(W * f * R * c), -np.sum(W * f * R * s)])

    gain_m = a0s * np.array([0.5, -2.0, -2.0]) / v
    c0 = loads(np.zeros(3))
    g = np.array([loads(e) - c0 for e in np.eye(3)]).T
    lam = np.linalg.solve(np.eye(3) - gain_m[:, None] * g, gain_m * c0)
    return math.tan(math.atan2(mu, lam[0] - muz) / 2)


def mass(power):
    st = states_of(power)
    h = [math.prod(range(n + m - 1, 0, -2)) * math.prod(range(n - m - 1, 0, -2))
         / (math.prod(range(n + m, 0, -2)) * math.prod(range(n - m, 0, -2)))
         for _, m, n in st]
    return np.diag(2.0 / math.pi * np.array(h))


def _grid(nr=40, npsi=72):
    x, w = np.polynomial.legendre.leggauss(nr)
    return (x + 1) / 2, w / 2, 2 * np.pi * np.arange(npsi) / npsi


def model(power, mu, n_beta, lambda_beta2, a0s, v, omega, gain=None):
    """``(E, A, B, C)``: azimuth-time descriptor, states ``(beta, alpha)``, inputs the
    eight azimuth-unit inputs, ``C`` the six recorded outputs (flap, and the
    least-squares linear inflow ``lambda0, lambda1c, lambda1s``).  ``gain``: the
    inflow-gain matrix ``L`` (default Peters-He's in axial flow, by quadrature;
    :func:`gain` at the trim's :func:`trim_skew` for forward flight)."""
    st = states_of(power)
    n = len(st)
    r, wr, psi = _grid()
    R, P = np.meshgrid(r, psi, indexing="ij")
    W = np.outer(wr, np.ones_like(psi)) / len(psi)
    c, s = np.cos(P), np.sin(P)
    ut = R + mu * s
    shapes = [shape(m, j, R) * (np.cos(m * P) if k == "c" else np.sin(m * P))
              for k, m, j in st]
    # U_P per variable: beta (3), beta' (3) [descriptor], theta (U_T^2, 3), nu (3), alpha
    up = {"b0": -mu * c, "b1c": R * s - mu * c * c, "b1s": -R * c - mu * s * c,
          "db0": -R + 0 * P, "db1c": -R * c, "db1s": -R * s,
          "muz": 1 + 0 * R, "q": R * c, "p": R * s}
    fb = [up[x] * ut for x in ("b0", "b1c", "b1s")]
    fdb = [up[x] * ut for x in ("db0", "db1c", "db1s")]
    fth = [ut * ut, ut * ut * c, ut * ut * s]
    fnu = [up[x] * ut for x in ("muz", "q", "p")]
    fal = [-g * ut for g in shapes]

    def pressure(g, f):
        return 0.5 * np.sum(W * g * f)

    wm = np.array([0.5 if m == 0 else 1.0 for _, m, _ in st])
    half = a0s / 2.0 * wm
    tq = lambda fs: np.array([[half[i] * pressure(g, f) for f in fs]
                              for i, g in enumerate(shapes)])
    linv = np.linalg.inv(globals()['gain'](power) if gain is None else gain)
    k = mass(power)
    # flap: C beta' + D beta = H_alpha alpha + H_theta theta + H_nu nu + H_eta eta
    flw = [R, 2 * R * c, 2 * R * s]
    h_al = 4 * n_beta * np.array([[np.sum(W * t * f) for f in fal] for t in flw])
    e = np.zeros((3 + n, 3 + n))
    a = np.zeros((3 + n, 3 + n))
    b = np.zeros((3 + n, 8))
    e[:3, :3] = fl.flap_c(mu, n_beta)
    a[:3, :3] = -fl.flap_d(mu, n_beta, lambda_beta2)
    a[:3, 3:] = h_al
    b[:3] = np.hstack([fl.flap_h_theta(mu, n_beta), fl.flap_h_nu(mu, n_beta), fl.flap_h_eta()])
    # inflow: K alpha' + V L^-1 alpha = tau/2
    e[3:, 3:] = k
    e[3:, :3] = -tq(fdb)
    a[3:, :3] = tq(fb)
    a[3:, 3:] = -v * linv + tq(fal)
    b[3:, :3] = tq(fth)
    b[3:, 3:6] = tq(fnu)
    cm = np.zeros((6, 3 + n))
    cm[:3, :3] = np.eye(3)
    for i, (kk, m, j) in enumerate(st):
        if m == 0:
            cm[3, 3 + i] = np.sum(wr * shape(0, j, r) * r) / 0.5
        elif m == 1:
            cm[4 if kk == "c" else 5, 3 + i] = np.sum(wr * shape(1, j, r) * r * r) / 0.25
    return e, a, b, cm


def frequency_response(desc, f_hz, omega):
    """``H(j w)`` (6, 8, n_f) in SI inputs, as ``Model.frequency_response``."""
    e, a, b, cm = desc
    scale = input_scale(omega)[:8]
    out = []
    for f in np.atleast_1d(f_hz):
        s = 2j * np.pi * f / omega
        out.append(cm @ np.linalg.solve(s * e - a, b * scale))
    return np.moveaxis(np.array(out), 0, -1)


def state_space(desc, omega):
    """SI ``(a, b, c)`` of the descriptor (seconds, SI inputs)."""
    e, a, b, cm = desc
    scale = input_scale(omega)[:8]
    return omega * np.linalg.solve(e, a), omega * np.linalg.solve(e, b) * scale, cm


def steady_loads(desc, x, u, power, mu, a0s, omega):
    """``(C_T, C_mc, C_ms)`` at a steady state ``x`` (no flap rate) and SI inputs ``u``:
    ``a0 s (1/2) avg int F (1, -r cos psi, -r sin psi) dr`` by quadrature."""
    st = states_of(power)
    r, wr, psi = _grid()
    R, P = np.meshgrid(r, psi, indexing="ij")
    W = np.outer(wr, np.ones_like(psi)) / len(psi)
    c, s = np.cos(P), np.sin(P)
    ua = np.asarray(u, float)[:8] * input_scale(omega)[:8]
    b0, b1c, b1s = x[:3]
    lam = sum(x[3 + i] * shape(m, j, R) * (np.cos(m * P) if k == "c" else np.sin(m * P))
              for i, (k, m, j) in enumerate(st))
    ut = R + mu * s
    th = ua[0] + ua[1] * c + ua[2] * s
    # single-blade flap and rate at steady multiblade state (beta' = 0)
    beta = b0 + b1c * c + b1s * s
    rate = b1s * c - b1c * s
    up = ua[3] - lam - R * rate - mu * beta * c + R * (ua[5] * s + ua[4] * c)
    f = th * ut * ut + up * ut
    return a0s * 0.5 * np.array([np.sum(W * f), -np.sum(W * f * R * c), -np.sum(W * f * R * s)])
