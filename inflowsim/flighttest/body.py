"""A simple, documented body-motion model for virtual flight tests.

Not a flight model: decoupled low-order responses to the cyclic and collective
perturbations, with the kinematics that turn attitude into in-plane speed, so
that the rotor sees the hub motion (``p, q, pdot, qdot, muz, mux, muy``) a real
doublet produces.  Per axis (perturbations, SI):

- pitch: ``q_dot = M_q q + M_att th + M_th theta1s``, attitude ``th_dot = q``,
  forward speed ``u_dot = X_u u - g th``;
- roll:  ``p_dot = L_p p + L_att ph + L_th theta1c``, attitude ``ph_dot = p``,
  side speed ``v_dot = Y_v v + g ph``;
- heave: ``w_dot = Z_w w + Z_th theta0``.

``M_att``, ``L_att`` stand for the attitude-holding of a stability augmentation
system (or the pilot): without them a 3-2-1-1, whose pitch rate does not
integrate to zero, would leave the aircraft at a new attitude and its speed
would run away (``X_u`` alone is a phugoid of minutes).  Every mode is stable.

``mux = u/(Omega R)``, ``muy = v/(Omega R)``, and
``muz = (w - mu Omega R th)/(Omega R)`` (down positive: a nose-up attitude turns
part of the trim speed into flow up through the disc).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..channels import INPUTS
from ..simulate.discrete import hold

G = 9.81


def zoh(a: np.ndarray, b: np.ndarray, dt: float):
    """The body's zero-order hold for the virtual records: scipy's matrix
    exponential in :func:`inflowsim.simulate.discrete.hold`.  Not the Simulator's
    (:func:`inflowsim.simulate.discrete.zoh`, the same to rounding): a record's
    samples rounded otherwise move a fit on it (``bench/check_same_fits.py``: up to
    2e-5 of a correlation on the held record), so every study's records stay
    the same numbers.  Kept on purpose: the truth generator's exponential is
    independent of the code under test."""
    from scipy.linalg import expm        # (imported here: see simulate.discrete)
    return hold(a, b, dt, expm)


#: Hub channels the body model produces (the model inputs after the controls, in
#: their order), the rows of :meth:`BodyModel.hub_matrices`.
HUB = INPUTS[3:]


#: Steps of the free response taken at once (:meth:`BodyModel.response`).
FREE_BLOCK = 1024


@dataclass(frozen=True)
class BodyModel:
    """Derivatives [1/s, 1/s^2] and control gains [m/s^2 or rad/s^2 per rad]."""

    m_q: float = -1.2
    m_att: float = -1.0
    m_theta: float = -10.0
    x_u: float = -0.05
    l_p: float = -5.0
    l_att: float = -2.0
    l_theta: float = 25.0
    y_v: float = -0.05
    z_w: float = -0.7
    z_theta: float = -60.0

    def matrices(self):
        """``x_dot = a x + b c``: states ``q th u p ph v w``, controls
        ``theta0 theta1c theta1s``."""
        a = np.zeros((7, 7))
        b = np.zeros((7, 3))
        a[0, 0], a[0, 1], b[0, 2] = self.m_q, self.m_att, self.m_theta
        a[1, 0] = 1.0
        a[2, 1], a[2, 2] = -G, self.x_u
        a[3, 3], a[3, 4], b[3, 1] = self.l_p, self.l_att, self.l_theta
        a[4, 3] = 1.0
        a[5, 4], a[5, 5] = G, self.y_v
        a[6, 6], b[6, 0] = self.z_w, self.z_theta
        return a, b

    def hub_matrices(self, omega_r: float, mu: float = 0.0):
        """Hub motion ``h = C x + D c`` (channels :data:`HUB`) of the body state and
        controls [SI]."""
        a, b = self.matrices()
        c = np.zeros((7, 7))
        d = np.zeros((7, 3))
        row = {h: i for i, h in enumerate(HUB)}
        c[row["muz"], 6], c[row["muz"], 1] = 1.0 / omega_r, -mu
        c[row["p"], 3] = 1.0
        c[row["q"], 0] = 1.0
        c[row["pdot"]], d[row["pdot"]] = a[3], b[3]
        c[row["qdot"]], d[row["qdot"]] = a[0], b[0]
        c[row["mux"], 2] = 1.0 / omega_r
        c[row["muy"], 5] = 1.0 / omega_r
        return c, d

    def response(self, controls: np.ndarray, dt: float, omega_r: float,
                 mu: float = 0.0) -> dict:
        """Hub motion for control perturbations ``(N, 3)`` (theta0, theta1c,
        theta1s) held over each sample (exact zero-order hold)."""
        a, b = self.matrices()
        phi, gam = zoh(a, b, dt)
        controls = np.asarray(controls, dtype=float)
        n = len(controls)
        x = np.zeros((n, 7))
        moving = np.flatnonzero(np.any(controls != 0, axis=1))
        last = min(int(moving[-1]) + 1 if moving.size else 0, n - 1)
        # a long free response after the last control movement (a 2-hour record's
        # standard manoeuvre: 460 000 steps, 1.4 s each in this loop) in blocks of
        # phi's powers; a normal record's few seconds step by step, as always
        tail = n - 1 - last
        stop = last if tail > FREE_BLOCK * 4 else n - 1
        for k in range(stop):
            x[k + 1] = phi @ x[k] + gam @ controls[k]
        if stop < n - 1:
            powers = np.empty((FREE_BLOCK, 7, 7))
            powers[0] = phi
            for j in range(1, FREE_BLOCK):
                powers[j] = phi @ powers[j - 1]
            k = stop
            while k < n - 1:
                m = min(FREE_BLOCK, n - 1 - k)
                x[k + 1:k + 1 + m] = powers[:m] @ x[k]
                k += m
        c, d = self.hub_matrices(omega_r, mu)
        h = x @ c.T + np.asarray(controls) @ d.T
        return {name: h[:, i] for i, name in enumerate(HUB)}


__all__ = ["G", "HUB", "BodyModel"]
