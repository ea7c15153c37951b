"""Fixed-step discretisation of ``x_dot = a x + b u`` with inputs held over a step.

Pure functions: ``(a, b, dt) -> (phi, gam)`` with ``x[k+1] = phi x[k] + gam u[k]``.
"""
from __future__ import annotations

import numpy as np
from scipy.linalg import expm

METHODS = ("zoh", "rk4")


def zoh(a: np.ndarray, b: np.ndarray, dt: float):
    """Exact zero-order-hold discretisation (matrix exponential of the augmented
    system ``[[a, b], [0, 0]] dt``)."""
    n, m = b.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n] = a
    aug[:n, n:] = b
    e = expm(aug * dt)
    return e[:n, :n], e[:n, n:]


def rk4(a: np.ndarray, b: np.ndarray, dt: float):
    """Classical fourth-order Runge-Kutta with the input held over the step.

    For a linear system one RK4 step is the matrix polynomial below (the four
    stages multiplied out), so it is stored as ``(phi, gam)`` like ZOH.
    """
    n = a.shape[0]
    h = dt
    ha = h * a
    i = np.eye(n)
    ha2 = ha @ ha
    ha3 = ha2 @ ha
    phi = i + ha + ha2 / 2 + ha3 / 6 + ha3 @ ha / 24
    gam = h * (i + ha / 2 + ha2 / 6 + ha3 / 24) @ b
    return phi, gam


def discretize(a, b, dt: float, method: str = "zoh"):
    if method == "zoh":
        return zoh(a, b, dt)
    if method == "rk4":
        return rk4(a, b, dt)
    raise ValueError(f"method must be one of {', '.join(METHODS)}, not {method!r}")


def lifted_replay(phi, gam, u, x0, block: int = 24):
    """All states ``x[0..N-1]`` of ``x[k+1] = phi x[k] + gam u[k]``.

    Block-lifted recursion: a short Python loop over block starts, then every
    state inside the blocks from one matrix product.  Same arithmetic as the
    sample loop up to rounding (a few ulps times the block length).
    """
    u = np.asarray(u, dtype=float)
    nsamp, m = u.shape
    n = phi.shape[0]
    L = max(1, min(block, nsamp))
    nb = -(-nsamp // L)
    pad = np.zeros((nb * L, m))
    pad[:nsamp] = u
    ub = pad.reshape(nb, L * m).T                       # (L m, nb), block b in column b
    powers = [np.eye(n)]
    for _ in range(L):
        powers.append(phi @ powers[-1])
    # in-block response: x[bL + j] = phi^j x[bL] + sum_{i<j} phi^(j-1-i) gam u[bL+i]
    P = np.vstack(powers[:L])                           # (L n, n)
    T = np.zeros((L * n, L * m))
    for j in range(1, L):
        for i in range(j):
            T[j * n:(j + 1) * n, i * m:(i + 1) * m] = powers[j - 1 - i] @ gam
    gl = np.hstack([powers[L - 1 - i] @ gam for i in range(L)])   # (n, L m)
    w = gl @ ub                                          # (n, nb)
    phil = powers[L]
    starts = np.empty((n, nb))
    x = np.asarray(x0, dtype=float).copy()
    for k in range(nb):
        starts[:, k] = x
        x = phil @ x + w[:, k]
    xs = P @ starts + T @ ub                             # (L n, nb)
    return xs.T.reshape(nb * L, n)[:nsamp]
