"""Sampled data of a continuous-time model: what happens between the samples.

A record holds samples ``u_n = u(t_n)``, ``t_n = t_0 + n dt``; the model is the
continuous ``x' = a x + b u``.  How the samples relate depends on the *intersample
behaviour* of the inputs (``record-format.md``, ``# hold:``):

``zoh``
    Inputs held over each sample interval (a digital controller, or the project's
    own fixed-step simulator).  Exact: ``x_{n+1} = phi x_n + gam u_n``.
``foh``
    Inputs linear between samples.  Exact: ``x_{n+1} = phi x_n + G_0 u_n + G_1 u_{n+1}``.
``continuous``
    Samples of smooth continuous signals, as measured flight data are (the default).
    Identification uses the continuous transfer function with the finite Fourier
    transform of the samples (:func:`gregory_weights`, :mod:`inflowsim.identify.freqmodel`);
    a time-domain replay interpolates the inputs by local cubics (4-point
    Lagrange, error ``O(dt^4 u'''')``), integrated exactly between samples.

Every hold is written as an *interpolation basis* on one sample interval,
``u(t_i + s dt) = sum_k u_{i + o_k} l_k(s)`` for ``s`` in ``[0, 1]``, and
:func:`shift_taps` integrates the model exactly over an interval for that input:
the state sampled at shifted times ``xi_n = x(t_n - d)`` (a time shift ``d``: a
delay for ``d > 0``, a lead for ``d < 0``) obeys

``xi_{n+1} = phi xi_n + sum_o G_o u_{n+o}``

with taps ``G_o`` built from the partial-interval integrals of
:func:`interval_integrals`.  Samples outside the record (``u_{-1}``, ``u_N`` ...)
are taken equal to the first and last sample (the record starts and ends in
steady flight: ``find_trim`` assumes the first; the last is the least-assumption
continuation).  Pure functions, no state.
"""
from __future__ import annotations

import math

import numpy as np

from ..defaults import HOLDS  # record-format.md '# hold:'
from ..errors import InputError

#: What a record without a ``# hold:`` line is: samples of continuous signals.
DEFAULT_HOLD = "continuous"
#: One phrase per hold, for reports.
HOLD_TEXT = {"continuous": "samples of continuous signals, identified with the "
                           "continuous transfer function, replayed with local cubics",
             "zoh": "inputs held over each sample, exact",
             "foh": "inputs linear between samples, exact"}

#: Interpolation bases: sample offsets ``o_k`` and polynomial coefficients of
#: ``l_k(s) = sum_p coef[k, p] s^p`` on ``s`` in ``[0, 1]``.
BASES = {
    "zoh": ((0,), np.array([[1.0]])),
    "foh": ((0, 1), np.array([[1.0, -1.0], [0.0, 1.0]])),
    # 4-point Lagrange through s = -1, 0, 1, 2
    "continuous": ((-1, 0, 1, 2), np.array([
        [0.0, -1 / 3, 1 / 2, -1 / 6],     # -s (s-1)(s-2)/6
        [1.0, -1 / 2, -1.0, 1 / 2],       # (s+1)(s-1)(s-2)/2
        [0.0, 1.0, 1 / 2, -1 / 2],        # -(s+1) s (s-2)/2
        [0.0, -1 / 6, 0.0, 1 / 6],        # (s+1) s (s-1)/6
    ])),
}


def check_hold(hold) -> str:
    """``hold`` if it is one of :data:`HOLDS`, else :class:`InputError`."""
    if hold not in HOLDS:
        raise InputError(f"hold {hold!r}: choose {', '.join(HOLDS)}")
    return hold


def expm(x: np.ndarray) -> np.ndarray:
    """Matrix exponential by scaling and squaring of a degree-16 Taylor series.

    Equal to ``scipy.linalg.expm`` to rounding for the small, well-scaled
    matrices of one sample step (2e-15 relative), and only matrix products.  A fit
    of a held record (``zoh``, ``foh``: :func:`shift_taps`) evaluates it about a
    thousand times, a replay once per shift; a continuous record's fit not at all.

    Kept beside the FMU's generated exponential
    (:func:`inflowsim.simulate.algorithms.expm`, Pade [13/13], which
    :func:`inflowsim.simulate.discrete.zoh` runs) because that one, run through its
    NumPy primitives (about 35 calls and two LAPACK factorisations), is slower here.
    Measured on the 1055 16 x 16 matrices of the zoh record's glauert+time-delay fit
    of ``bench/check_same_fits.py`` (CPU time, best of 5, load 8-10 on 2 cores): 63
    us a call against 111 us (scipy's 17 us with one BLAS thread, 2.0 ms with
    OpenBLAS's default threads); in the fits (interleaved, best of 9, load 12-15)
    held-record fits 20-30 % slower with it, continuous ones unchanged (no call).
    Its fits agree: ``check_same_fits.py --ladder`` moves only the zoh record's
    estimates, by at most 7e-8 of their bounds, every decision the same; the ladder
    from ``basic`` on that record takes the same rungs (estimates within 2e-7 of
    their bounds), 13 % more CPU.
    """
    nrm = np.abs(x).sum(axis=1).max() if x.size else 0.0
    s = max(0, int(np.ceil(np.log2(nrm / 0.5)))) if nrm > 0.5 else 0
    y = x / 2.0 ** s
    e = np.eye(x.shape[0])
    t = np.eye(x.shape[0])
    for k in range(1, 17):
        t = t @ y / k
        e = e + t
    for _ in range(s):
        e = e @ e
    return e


def interval_integrals(a, b, dt, s0, s1, degree):
    """``e^{a dt (s1 - s0)}`` and ``P_p = int_{s0}^{s1} e^{a dt (s1 - s)} b dt s^p ds``.

    Normalised time ``s`` (one sample interval is ``[0, 1]``), ``p = 0 .. degree``:
    the state change over ``[s0, s1]`` of ``x' = a x + b u`` for an input
    ``u = s^p``.  One augmented matrix exponential (a chain of integrators
    generating the powers ``tau^i / i!`` of the time since ``s0``).

    Returns
    -------
    phi : ndarray (n, n)
    P : list of ndarray (n, m)
    """
    a, b = np.asarray(a, float), np.asarray(b, float)
    n, m = b.shape
    L = float(s1 - s0)
    q = degree + 1
    size = n + m * q
    aug = np.zeros((size, size))
    aug[:n, :n] = a * dt
    aug[:n, n:n + m] = b * dt
    for i in range(degree):
        aug[n + i * m:n + (i + 1) * m, n + (i + 1) * m:n + (i + 2) * m] = np.eye(m)
    e = expm(aug * L)
    phi = e[:n, :n]
    # F_i = int_0^L e^{A (L - tau)} B tau^i / i! dtau
    F = [e[:n, n + i * m:n + (i + 1) * m] for i in range(q)]
    P = []
    for p in range(q):
        acc = np.zeros((n, m))
        for i in range(p + 1):
            acc += math.comb(p, i) * s0 ** (p - i) * math.factorial(i) * F[i]
        P.append(acc)
    return phi, P


def shift_taps(a, b, dt, hold, shifts=None):
    """Exact one-step map of the state sampled at shifted times.

    Parameters
    ----------
    a, b : ndarray
        Continuous model ``x' = a x + b u`` [SI].
    dt : float
        Sample step [s].
    hold : str
        Intersample behaviour of the inputs (:data:`HOLDS`; ``continuous`` uses
        the local-cubic interpolation).
    shifts : array_like, optional
        Per input column, the time shift ``d_j`` [s] between the recorded input
        and the sampled state: ``xi_n = x(t_n - d)`` driven by recorded input ``j``
        delayed by ``d_j`` (output delay minus input delay).  Default all zero.

    Returns
    -------
    phi : ndarray (n, n)
        ``e^{a dt}``.
    taps : dict
        ``{offset o: G_o (n, m)}`` with ``xi_{n+1} = phi xi_n + sum_o G_o u_{n+o}``.
    """
    b = np.asarray(b, float)
    n, m = b.shape
    offsets, coef = BASES[check_hold(hold)]
    degree = coef.shape[1] - 1
    shifts = np.zeros(m) if shifts is None else np.asarray(shifts, float)
    phi = None
    taps: dict[int, np.ndarray] = {}

    def add(o, j, g):
        taps.setdefault(o, np.zeros((n, m)))[:, j] += g

    for d in np.unique(shifts):
        cols = np.flatnonzero(shifts == d)
        steps = d / dt
        mm = int(math.floor(steps + 1e-12))
        f = steps - mm
        if f < 1e-12:
            f = 0.0
        bc = b[:, cols]
        if f == 0.0:
            ph, P = interval_integrals(a, bc, dt, 0.0, 1.0, degree)
            for k, o in enumerate(offsets):
                g = sum(coef[k, p] * P[p] for p in range(degree + 1))
                for jj, j in enumerate(cols):
                    add(-mm + o, j, g[:, jj])
        else:
            # [t_n - d, t_{n+1} - d]: the end s in [1-f, 1] of interval n-m-1, then
            # the start s in [0, 1-f] of interval n-m
            e1, P1 = interval_integrals(a, bc, dt, 1.0 - f, 1.0, degree)
            e2, P2 = interval_integrals(a, bc, dt, 0.0, 1.0 - f, degree)
            ph = e2 @ e1
            for k, o in enumerate(offsets):
                g1 = e2 @ sum(coef[k, p] * P1[p] for p in range(degree + 1))
                g2 = sum(coef[k, p] * P2[p] for p in range(degree + 1))
                for jj, j in enumerate(cols):
                    add(-mm - 1 + o, j, g1[:, jj])
                    add(-mm + o, j, g2[:, jj])
        phi = ph
    if phi is None:                           # no input columns
        phi = expm(np.asarray(a, float) * dt)
    return phi, taps


def extended(u: np.ndarray, lo: int, hi: int) -> np.ndarray:
    """``u`` (``(N, m)``) padded with ``lo`` copies of its first and ``hi`` copies
    of its last sample (the record's continuation before and after)."""
    u = np.asarray(u, float)
    return np.vstack([np.repeat(u[:1], max(lo, 0), axis=0), u,
                      np.repeat(u[-1:], max(hi, 0), axis=0)])


def tapped_inputs(u: np.ndarray, taps: dict) -> tuple[np.ndarray, np.ndarray]:
    """Stack ``[u_{n+o}]`` over the taps' offsets and the matching ``[G_o]``, so
    that ``sum_o G_o u_{n+o} = G @ v_n`` for ``n = 0 .. N-1``."""
    offs = sorted(taps)
    lo, hi = max(0, -min(offs)), max(0, max(offs))
    ue = extended(u, lo, hi)
    N = len(u)
    v = np.hstack([ue[lo + o:lo + o + N] for o in offs])
    G = np.hstack([taps[o] for o in offs])
    return v, G


#: ``B_0 .. B_7`` as ``scipy.special.bernoulli`` gives them (a float recurrence:
#: ``B_4`` and ``B_6`` lie 1.7e-12 and 5.8e-14 relative off -1/30 and 1/42), for
#: :func:`gregory_weights` up to 6 ends: the weights every continuous record's
#: transform has used, bit for bit, without importing SciPy's special functions.
#: (The exact numbers, :func:`bernoulli`, move the weights by 1e-14, and fits
#: within their convergence tolerance: bench/check_same_fits.py then differs.)
_GREGORY_B = (1.0, -0.5, 0.16666666666666666, 0.0, -0.033333333333275914, 0.0,
              0.02380952380952236, 0.0)


def bernoulli(n: int) -> list:
    """Bernoulli numbers ``B_0 .. B_n`` (``B_1 = -1/2``), each the float nearest the
    exact rational: ``B_m = -1/(m+1) sum_{k<m} C(m+1, k) B_k`` in fractions."""
    from fractions import Fraction
    from math import comb
    b = [Fraction(1)]
    for m in range(1, int(n) + 1):
        b.append(-sum(comb(m + 1, k) * b[k] for k in range(m)) / (m + 1))
    return [float(x) for x in b]


def gregory_weights(n_samples: int, ends: int = 6) -> np.ndarray:
    """Weights ``c_n`` with ``dt sum c_n g(t_n) = int_{t_0}^{t_{N-1}} g dt`` exactly for
    polynomials of degree ``< ends``, whatever the record's length (Gregory's
    end-corrected trapezoid rule).

    The Euler-Maclaurin formula writes the error of the plain sum as terms at
    each end, ``f(0)/2 - sum_k B_2k/(2k)! f^(2k-1)(0)`` at the left; the ``ends``
    corrections ``delta_i`` at the first samples cancel them for every monomial
    of degree ``< ends`` (a Vandermonde system), the last samples mirror them.
    ``c_n = 1`` elsewhere; with 6 ends the weights are 0.316, 1.392, 0.624,
    1.244, 0.910, 1.014.  For smooth signals the remaining error is aliasing
    only, so the weighted transform of a record of smooth signals is their
    finite Fourier integral to high accuracy, whatever the record's ends do.
    """
    N = int(n_samples)
    K = min(int(ends), max(1, N // 2))
    B = _GREGORY_B if K + 1 < len(_GREGORY_B) else bernoulli(K + 1)
    rhs = np.zeros(K)
    rhs[0] = -0.5
    for m in range(1, K, 2):
        rhs[m] = B[m + 1] / (m + 1)
    V = np.vander(np.arange(K, dtype=float), K, increasing=True).T
    delta = np.linalg.solve(V, rhs)
    c = np.ones(N)
    c[:K] += delta
    c[N - K:] += delta[::-1]
    return c


__all__ = ["DEFAULT_HOLD", "HOLD_TEXT", "BASES", "check_hold", "expm",
           "interval_integrals", "shift_taps", "extended", "tapped_inputs",
           "gregory_weights"]
