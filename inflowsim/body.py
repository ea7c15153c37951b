"""A simple, documented body-motion model for virtual flight tests.

Not a flight model: decoupled first-order rate responses to the cyclic and
collective perturbations, with the kinematics that turn attitude into in-plane
speed, so that the rotor sees the hub motion (``p, q, pdot, qdot, muz, mux,
muy``) a real doublet produces.  Per axis (perturbations, SI):

- pitch: ``q_dot = M_q q + M_th theta1s``, attitude ``th_dot = q``,
  forward speed ``u_dot = -g th``;
- roll:  ``p_dot = L_p p + L_th theta1c``, attitude ``ph_dot = p``,
  side speed ``v_dot = g ph``;
- heave: ``w_dot = Z_w w + Z_th theta0``.

``mux = u/(Omega R)``, ``muy = v/(Omega R)``, and
``muz = (w - mu Omega R th)/(Omega R)`` (down positive: a nose-up attitude turns
part of the trim speed into flow up through the disc).
Integrated exactly for inputs held over each sample (zero-order hold).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .discrete import zoh

G = 9.81


@dataclass(frozen=True)
class BodyModel:
    """Derivatives [1/s] and control gains [m/s^2 or rad/s^2 per rad]."""

    m_q: float = -1.2
    m_theta: float = -10.0
    l_p: float = -5.0
    l_theta: float = 25.0
    z_w: float = -0.7
    z_theta: float = -60.0

    def matrices(self):
        # states: q, th, u, p, ph, v, w ; inputs: theta0, theta1c, theta1s
        a = np.zeros((7, 7))
        b = np.zeros((7, 3))
        a[0, 0], b[0, 2] = self.m_q, self.m_theta
        a[1, 0] = 1.0
        a[2, 1] = -G
        a[3, 3], b[3, 1] = self.l_p, self.l_theta
        a[4, 3] = 1.0
        a[5, 4] = G
        a[6, 6], b[6, 0] = self.z_w, self.z_theta
        return a, b

    def response(self, controls: np.ndarray, dt: float, omega_r: float,
                 mu: float = 0.0) -> dict:
        """Hub motion for control perturbations ``(N, 3)`` (theta0, theta1c, theta1s)."""
        a, b = self.matrices()
        phi, gam = zoh(a, b, dt)
        n = len(controls)
        x = np.zeros((n, 7))
        for k in range(n - 1):
            x[k + 1] = phi @ x[k] + gam @ controls[k]
        xdot = x @ a.T + controls @ b.T
        return {"q": x[:, 0], "p": x[:, 3], "qdot": xdot[:, 0], "pdot": xdot[:, 3],
                "mux": x[:, 2] / omega_r, "muy": x[:, 5] / omega_r,
                "muz": (x[:, 6] - mu * omega_r * x[:, 1]) / omega_r}
