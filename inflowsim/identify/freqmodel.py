"""Exact sampled-data frequency response of a model to a record's held inputs.

Virtual and simulated records are the zero-order-hold replay ``x_{n+1} = phi x_n +
gam u_n`` of the linear model at the record's step ``dt`` (:mod:`inflowsim.simulator`).
With the DFT ``X = sum_{n=0}^{N-1} x_n z^-n`` (:mod:`.transform`) this recursion
gives, at ANY frequency,

    ``(z I - phi) X = gam U + z x_0 - z^(1-N) x_N``

(on the record's own grid ``z^N = 1`` and the end terms reduce to ``z (x_0 - x_N)``).
The initial state ``x_0`` and the state ``x_N`` one step after the end are the
*end effects*: the record neither starts nor ends at rest.  They enter linearly,
so they are nuisance parameters, eliminated by linear least squares inside every
cost evaluation (variable projection, :mod:`.estimator`); with them the model of a
noise-free ZOH record is exact, with no windowing.

Flap outputs ``Y = C X`` (``C`` includes the azimuth-bias rotation).  A delay
``(m + f) dt`` on a flap channel reads, as the simulator does, ``y_n = C s_{n-q}``
with ``s_j = phi_f x_j + gam_f u_j`` (maps over ``(1 - f) dt``) and ``q = m + 1``
for ``f > 0``, or ``s_j = x_j`` and ``q = m`` for ``f = 0``; before ``q`` samples
the channel holds the initial output ``C x_0``.  Its transform is exactly

    ``Y = C [z^-q (S - sum_{j=N-q}^{N-1} s_j z^-j) + x_0 sum_{n<q} z^-n]``

where the last ``q`` states come from ``x_{N-Q}`` (the state ``Q`` steps before the
end, ``Q`` the largest ``q``) and the known last inputs.  The nuisance vector is
therefore ``nu = (x_0, x_{N-Q})`` (``2 n`` real numbers per record); where the data
determine only a combination of them (no delay, own grid: ``x_0 - x_N``) the
least squares take the minimum-norm solution, which leaves the fit unchanged.
"""
from __future__ import annotations

import numpy as np



def _expm(x):
    """Matrix exponential by scaling and squaring of a degree-16 Taylor series.

    Equal to ``scipy.linalg.expm`` to rounding for the small, well-scaled
    matrices of one sample step, and only matrix products: scipy's Pade solver
    is tens of times slower on a loaded multi-core machine (threaded LAPACK on
    16x16 matrices), and the fit evaluates it thousands of times.
    """
    nrm = np.abs(x).sum(axis=1).max()
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


def zoh(a, b, dt):
    """``(phi, gam)`` of the zero-order hold over ``dt`` (as
    :func:`inflowsim.discrete.zoh`)."""
    n, m = b.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n] = a
    aug[:n, n:] = b
    e = _expm(aug * dt)
    return e[:n, :n], e[:n, n:]


def delay_groups(delays, dt: float):
    """``[(rows, q, f), ...]`` for the flap channels, the simulator's split of each
    delay into whole steps and a fraction (``rows`` index ``beta0 beta1c beta1s``)."""
    delays = np.asarray(delays, dtype=float)[:3]
    out = []
    for d in np.unique(delays):
        rows = np.flatnonzero(delays == d)
        if d <= 0:
            out.append((rows, 0, 0.0))
            continue
        steps = d / dt
        m = int(np.floor(steps + 1e-12))
        f = steps - m
        if f < 1e-12:
            f = 0.0
        out.append((rows, m + 1 if f > 0 else m, f))
    return out


def _powers(z_exp, f_hz, dt):
    """``z^p`` computed from the phase directly (no accumulated rounding)."""
    return np.exp(2j * np.pi * np.asarray(f_hz) * dt * z_exp)


def flap_response(model, sp):
    """Predicted flap transforms, affine in the end-effect nuisance.

    Parameters
    ----------
    model : Model
        SI state space (``a, b, c, delays``).
    sp : Spectra
        The record's transforms and its time inputs (for the end terms).

    Returns
    -------
    y_u : ndarray, complex ``(nf, 3)``
        Response to the record's inputs (with the input part of the end terms).
    y_nu : ndarray, complex ``(nf, 3, 2 n)``
        Response to ``nu = (x_0, x_{N-Q})``: the flap transforms are
        ``y_u + y_nu @ nu``.
    q_max : int
        ``Q``, the delay depth (0 without delays).
    """
    a, b = model.a, model.b
    n = a.shape[0]
    dt, N, f = sp.dt, sp.n_samples, sp.f_hz
    nf = f.size
    phi, gam = zoh(a, b, dt)
    groups = delay_groups(model.delays, dt)
    Q = max(q for _, q, _ in groups)
    u = sp.u_time
    # last Q states from x_{N-Q}: x_{N-Q+l} = phi^l x_tail + v_l
    pw, v = [np.eye(n)], [np.zeros(n)]
    for l in range(Q):
        pw.append(phi @ pw[-1])
        v.append(phi @ v[-1] + gam @ u[N - Q + l])
    z = _powers(1, f, dt)
    zend = _powers(1 - N, f, dt)
    eye = np.eye(n)
    M = z[:, None, None] * eye - phi
    rhs = np.empty((nf, n, 1 + 2 * n), dtype=complex)
    rhs[:, :, 0] = sp.U @ gam.T - zend[:, None] * v[Q]
    rhs[:, :, 1:1 + n] = z[:, None, None] * eye
    rhs[:, :, 1 + n:] = -zend[:, None, None] * pw[Q]
    sol = np.linalg.solve(M, rhs)                         # (nf, n, 1 + 2n)
    C = model.c[:3]
    y_u = np.empty((nf, 3), dtype=complex)
    y_nu = np.empty((nf, 3, 2 * n), dtype=complex)
    for rows, q, frac in groups:
        if frac > 0:
            phf, gaf = zoh(a, b, (1 - frac) * dt)
            s = np.einsum("ij,fjk->fik", phf, sol)
            s[:, :, 0] += sp.U @ gaf.T
        else:
            phf, gaf = eye, np.zeros_like(gam)
            s = sol.copy()
        if q > 0:
            # s_j, j = N-q .. N-1, affine in x_tail; subtract their transform
            for j in range(N - q, N):
                l = j - (N - Q)
                zj = _powers(-j, f, dt)
                s[:, :, 0] -= zj[:, None] * (phf @ v[l] + gaf @ u[j])
                s[:, :, 1 + n:] -= zj[:, None, None] * (phf @ pw[l])
            s *= _powers(-q, f, dt)[:, None, None]
            head = sum(_powers(-k, f, dt) for k in range(q))
            s[:, :, 1:1 + n] += head[:, None, None] * eye
        cr = C[rows]
        y = np.einsum("ij,fjk->fik", cr, s)
        y_u[:, rows] = y[:, :, 0]
        y_nu[:, rows] = y[:, :, 1:]
    return y_u, y_nu, Q
