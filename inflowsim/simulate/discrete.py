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


def lifted_replay(phi, gam, u, x0, block: int | None = None):
    """All states ``x[0..N-1]`` of ``x[k+1] = phi x[k] + gam u[k]``.

    Block-lifted recursion with blocks of ``block`` samples (default
    ``sqrt(N)``): the block-end sums and then the states inside the blocks are
    built by ``block`` steps of the plain recursion vectorised over all blocks,
    and only the block starts (``x <- phi^block x + w``) loop over blocks, so
    Python runs about ``2 sqrt(N)`` small iterations and the work is
    ``O(N n (n + m))``.  Same arithmetic as the sample loop inside a block; the
    block starts differ from it by rounding only (a few ulps).
    """
    u = np.asarray(u, dtype=float)
    nsamp, m = u.shape
    n = phi.shape[0]
    L = max(1, min(int(block) if block else int(np.sqrt(nsamp)), nsamp))
    nb = -(-nsamp // L)
    pad = np.zeros((nb * L, m))
    pad[:nsamp] = u
    ub = pad.reshape(nb, L, m)                       # [block, step in block, input]
    phit, gamt = phi.T, gam.T
    w = np.zeros((nb, n))                            # sum_i phi^(L-1-i) gam u[bL+i]
    for j in range(L):
        w = w @ phit + ub[:, j, :] @ gamt
    phil = np.linalg.matrix_power(phi, L)
    starts = np.empty((nb, n))
    x = np.asarray(x0, dtype=float).copy()
    for k in range(nb):
        starts[k] = x
        x = phil @ x + w[k]
    xs = np.empty((nb, L, n))
    xb = starts
    for j in range(L):
        xs[:, j, :] = xb
        xb = xb @ phit + ub[:, j, :] @ gamt
    return xs.reshape(nb * L, n)[:nsamp]
