"""How much of a residual the inputs explain, measured without a noise floor.

Under coloured sensor noise the floor measured above the band is far below the
noise in it (:mod:`inflowsim.diagnose.lpm`), so a residual's excess over that
floor is mostly noise and the share of it a candidate removes says little.  A
model error, though, is the inputs seen through a wrong frequency response:
``dH(f) U(f)`` with ``dH`` smooth, plus a smooth transient.  Regressing each
channel's residual on those terms (each input's transform times Legendre
polynomials of degree < :data:`DEGREES` in frequency over the band, and the
polynomials alone) splits it into the part the inputs explain and the rest; the
rest, per degree of freedom, is the channel's noise level in the band, whatever
its colour.  The *input-correlated excess* is the explained part's power over
that level, summed over the channels: for noise alone its mean is
``r (nf - r) / (nf - r - 1)`` per channel (``r`` the regression's rank, an F
law) less what the fit took from it (:func:`expected_for_noise`: half a
dimension for every real parameter fitted, model and end effects, whose
directions lie in the span), and a model error raises it.  The candidate tests
(:mod:`inflowsim.diagnose.candidates`) use it in place of the deviance when a
record's noise is coloured.
"""
from __future__ import annotations

import numpy as np

#: Polynomials per input (degrees 0 .. DEGREES - 1) of the smooth response error.
DEGREES = 3


def project(e: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """Rows of ``e`` projected on the span of ``Q``'s orthonormal columns."""
    return (e @ Q.conj()) @ Q.T


def smooth_input_basis(ra) -> np.ndarray:
    """Orthonormal basis ``(nf, r)`` of the smooth input-correlated residuals of a
    :class:`~inflowsim.diagnose.failures.ResidualAnalysis`."""
    f = ra.f_hz
    x = 2 * (f - f.min()) / max(f.max() - f.min(), np.finfo(float).tiny) - 1
    L = np.polynomial.legendre.legvander(x, DEGREES - 1)
    U = np.zeros((f.size, 0)) if ra.U is None else ra.U
    scale = np.abs(U).max(axis=0) if U.size else np.zeros(0)
    U = U[:, scale > 0] / scale[scale > 0]
    X = np.hstack([L] + [U[:, [i]] * L for i in range(U.shape[1])])
    Q, s, _ = np.linalg.svd(X, full_matrices=False)
    return Q[:, :int(np.sum(s > 1e-8 * s[0]))]


def noise_levels(ra, Q) -> np.ndarray:
    """Per channel, the residual power per bin the basis ``Q`` leaves ``(3,)``."""
    e = ra.error
    rest = e - project(e, Q)
    return np.sum(np.abs(rest) ** 2, axis=1) / (e.shape[1] - Q.shape[1])


def input_excess(ra, Q, levels) -> float:
    """The power of the residual in ``Q``'s span over ``levels``, summed over the
    channels."""
    return float(np.sum(np.sum(np.abs(project(ra.error, Q)) ** 2, axis=1) / levels))


def expected_for_noise(nf: int, r: int, fitted: int = 0) -> float:
    """Mean of :func:`input_excess` for noise alone, all three channels.

    ``fitted``: real parameters the residual was fitted with (model and end-effect
    nuisance).  Their directions (responses to the inputs, smooth transients) lie
    in the basis's span and each takes half a complex dimension's power from the
    noise there: the bound where all of them lie in it."""
    return (3.0 * r - 0.5 * fitted) * (nf - r) / (nf - r - 1)


__all__ = ["DEGREES", "project", "smooth_input_basis", "noise_levels", "input_excess",
           "expected_for_noise"]
