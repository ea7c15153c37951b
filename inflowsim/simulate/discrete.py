"""Fixed-step discretisation of ``x_dot = a x + b u`` with inputs held over a step.

Pure functions: ``(a, b, dt) -> (phi, gam)`` with ``x[k+1] = phi x[k] + gam u[k]``.
"""
from __future__ import annotations

import numpy as np

from .algorithms import expm, taylor_count, taylor_prepare, taylor_step

METHODS = ("zoh", "rk4")


def hold(a: np.ndarray, b: np.ndarray, dt: float, exponential):
    """``(phi, gam)`` of the zero-order hold over ``dt`` [s]: ``exponential`` of the
    augmented ``[[a, b], [0, 0]] dt`` (a fresh array it may overwrite), its top rows
    (views of the result).  One construction for every exponential: :func:`zoh`'s,
    the virtual flight test's body model (scipy's, :mod:`inflowsim.flighttest.body`)."""
    n, m = b.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n] = a
    aug[:n, n:] = b
    e = exponential(aug * dt)
    return e[:n, :n], e[:n, n:]


def _pade(x: np.ndarray) -> np.ndarray:
    """:func:`inflowsim.simulate.algorithms.expm` of ``x`` in place; NaN where it
    fails (a non-finite ``x``)."""
    if expm(x.reshape(-1), len(x)) != 0:
        x[:] = np.nan
    return x


def zoh(a: np.ndarray, b: np.ndarray, dt: float):
    """Exact zero-order-hold discretisation: the matrix exponential of the augmented
    system ``[[a, b], [0, 0]] dt`` (:func:`hold`) by
    :func:`inflowsim.simulate.algorithms.expm` (Pade [13/13], scaling and squaring:
    the FMU's, generated from it).  NaN where that fails (a non-finite ``a`` or
    ``b``)."""
    phi, gam = hold(a, b, dt, _pade)
    return phi.copy(), gam.copy()


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


class TaylorZoh:
    """:func:`zoh` of one ``(a, b)`` at any step ``h`` by the Taylor series of the
    solution: :func:`inflowsim.simulate.algorithms.taylor_step` (the FMU's step of a
    communication remainder, generated from it) on the columns of the identity, so
    that column ``j`` of ``[phi gam](h)`` is the step of ``[x; u] = e_j``.  As many
    terms as the FMU's rule asks (:func:`inflowsim.simulate.algorithms.taylor_count`:
    the next term below 1e-17 of the result's scale, every term bounded by the one
    before); the matrix exponential where that would need more than
    ``TAYLOR_MAX_TERMS``."""

    def __init__(self, a: np.ndarray, b: np.ndarray):
        self.a, self.b = a, b
        n, m = b.shape
        na = n + m
        # [a b] by rows and by columns (unpadded: rows n + m apart, columns n apart),
        # the 1-norms |a| and |[a b]|: the FMU's preparation (taylor_prepare)
        self._abr, self._abc, norms = np.empty(n * na), np.empty(na * n), np.empty(2)
        taylor_prepare(np.ascontiguousarray(a, float).ravel(),
                       np.ascontiguousarray(b, float).ravel(), self._abr, self._abc, norms,
                       n, m, na, n)
        self.norm_a, self.norm_ab = float(norms[0]), float(norms[1])
        self._n, self._na = n, na

    def pg(self, h: float):
        """``[phi gam]`` at step ``h`` [s]; None where the series would need too
        many terms."""
        k = taylor_count(self.norm_a, self.norm_ab, h)
        if k == 0 or not np.isfinite(self.norm_ab):
            return None
        n, na = self._n, self._na
        z = np.eye(na).ravel()
        taylor_step(self._abr, self._abc, k, h, z, n, na, n, na)
        return z[:n * na].reshape(n, na)

    def __call__(self, h: float):
        """``(phi, gam)`` at step ``h`` [s]."""
        pg = self.pg(h)
        if pg is None:
            return zoh(self.a, self.b, h)
        return pg[:, :self._n], pg[:, self._n:]


#: RK4's stability polynomial ``R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24``: a step is
#: stable where ``|R(h lambda)| <= 1`` for every eigenvalue (2.785 on the real axis).
_RK4_R = (1 / 24, 1 / 6, 1 / 2, 1.0, 1.0)


def rk4_max_step(eigenvalues) -> float:
    """Largest step [s] at which classical RK4 is stable for a linear system with
    these eigenvalues [1/s]: the least, over the eigenvalues in the closed left
    half-plane, of the first ``h`` where ``|R(h lambda)|`` leaves 1 (a fine scan of
    ``|h lambda|`` up to 4 then bisection; 2.785 / |lambda| for a real one).
    ``inf`` if none limits it (an unstable mode is unstable at any step; the
    step does not make it so)."""
    lam = np.asarray(eigenvalues, dtype=complex).ravel()
    lam = lam[(lam.real <= 0) & (np.abs(lam) > 0)]
    if lam.size == 0:
        return float("inf")
    r = np.linspace(0.0, 4.0, 4001)[1:]              # |h lambda|
    z = r[None, :] * (lam / np.abs(lam))[:, None]
    grow = np.abs(np.polyval(_RK4_R, z)) > 1.0 + 1e-15
    hmax = np.inf
    for i, row in enumerate(grow):
        j = int(np.argmax(row)) if row.any() else None
        if j is None:
            continue
        lo, hi = (r[j - 1] if j > 0 else 0.0), r[j]
        d = lam[i] / abs(lam[i])
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            if abs(np.polyval(_RK4_R, mid * d)) > 1.0 + 1e-15:
                hi = mid
            else:
                lo = mid
        hmax = min(hmax, lo / abs(lam[i]))
    return float(hmax)


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


__all__ = ["METHODS", "hold", "zoh", "rk4", "TaylorZoh", "rk4_max_step", "discretize",
           "lifted_replay"]
