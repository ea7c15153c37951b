"""The averaged multiblade system of the individual-blade truth, by finite differences.

An independent route to the multiblade matrices: the truth's own right-hand side
(:meth:`inflowsim.flighttest.bladesim.BladeRotor.rhs`, each blade's flap equation
and the inflow states) is evaluated with the blade flap written as harmonics
``0..K`` of its azimuth, ``beta_i = beta0 + sum_n beta_nc cos n psi_i + beta_ns
sin n psi_i``; each blade's acceleration is projected back on the harmonics with
the rotating-frame terms removed, and the result averaged over the azimuth.  With
``speed="mu"`` (``V = mu``) and the hub fixed the truth is linear in the flap, the
inflow and the inputs, so one-sided differences are exact to rounding.

``K = 1`` gives the catalogue's model with flap inertia (``model.md`` section 2);
``K = 2`` keeps the blades' 2/rev flap (:mod:`inflowsim.physics.harmonics`).
Used by the tests of both and by ``bench/harmonic_flap.py``.
"""
from __future__ import annotations

import numpy as np

#: inputs of the averaged system: the first eight of ``INPUTS_AZ``
N_INPUTS = 8


def averaged_system(rotor, K: int, n_psi: int = 12, step: float = 1e-6):
    """``(A, B)`` in azimuth time, ``x' = A x + B u``.

    Parameters
    ----------
    rotor : BladeRotor
        The truth (use many blades, e.g. 16, so that the average over ``n_psi``
        azimuths is exact for the harmonics kept).
    K : int
        Highest flap harmonic kept.
    n_psi : int
        Azimuths averaged over.
    step : float
        Finite-difference step [rad, -].

    Returns
    -------
    A : ndarray, shape (n, n)
        States: the ``2K+1`` flap harmonics ``(beta0, beta1c, beta1s, beta2c,
        beta2s, ...)``, their rates, then the three inflow states; ``n = 2(2K+1)+3``.
    B : ndarray, shape (n, 8)
        Inputs ``theta0, theta1c, theta1s, muz, qbar, pbar, qbar', pbar'`` (azimuth
        units, as ``INPUTS_AZ``).
    """
    nb = rotor.nb
    nh = 2 * K + 1
    n = 2 * nh + 3
    weights = np.array([1.0] + [2.0] * (nh - 1)) / nb

    def deriv(psi, z, u):
        b, db, lam = z[:nh], z[nh:2 * nh], z[2 * nh:]
        ang = psi + rotor.offsets
        basis, dbasis = [np.ones(nb)], [np.zeros(nb)]
        for k in range(1, K + 1):
            basis += [np.cos(k * ang), np.sin(k * ang)]
            dbasis += [-k * np.sin(k * ang), k * np.cos(k * ang)]
        basis, dbasis = np.array(basis), np.array(dbasis)       # (nh, nb)
        x = np.concatenate([b @ basis, db @ basis + b @ dbasis, lam])
        uu = np.zeros(10)
        uu[:N_INPUTS] = u
        uu[8] = rotor.spec.constants.mu       # the truth's total advance ratio
        f = rotor.rhs(psi, x, uu)
        proj = (basis @ f[nb:2 * nb]) * weights
        dd = proj.copy()
        for k in range(1, K + 1):             # remove the rotating frame's terms
            c, s = 2 * k - 1, 2 * k
            dd[c] = proj[c] - 2 * k * db[s] + k * k * b[c]
            dd[s] = proj[s] + 2 * k * db[c] + k * k * b[s]
        return np.concatenate([db, dd, f[2 * nb:]])

    A = np.zeros((n, n))
    B = np.zeros((n, N_INPUTS))
    zx, zu = np.zeros(n), np.zeros(N_INPUTS)
    for psi in np.linspace(0, 2 * np.pi, n_psi, endpoint=False):
        f0 = deriv(psi, zx, zu)
        for j in range(n):
            e = zx.copy()
            e[j] = step
            A[:, j] += (deriv(psi, e, zu) - f0) / step
        for j in range(N_INPUTS):
            e = zu.copy()
            e[j] = step
            B[:, j] += (deriv(psi, zx, e) - f0) / step
    return A / n_psi, B / n_psi


def condense(A, B, fast):
    """``(A, B)`` with the states ``fast`` quasi-steady (their rows set to zero and
    solved for them): ``A_ss - A_sf A_ff^-1 A_fs``, ``B_s - A_sf A_ff^-1 B_f``."""
    fast = list(fast)
    slow = [i for i in range(A.shape[0]) if i not in fast]
    a_ff = A[np.ix_(fast, fast)]
    a_sf = A[np.ix_(slow, fast)]
    a = A[np.ix_(slow, slow)] - a_sf @ np.linalg.solve(a_ff, A[np.ix_(fast, slow)])
    b = B[slow] - a_sf @ np.linalg.solve(a_ff, B[fast])
    return a, b


__all__ = ["averaged_system", "condense", "N_INPUTS"]
