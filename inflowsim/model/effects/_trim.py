"""The trim every effect linearised about the trim starts from (``Effect.about_trim``).

Shared by ``advance-ratio-perturbation``, ``momentum-speed`` and ``lead-lag``; its
own module so that neither effect module imports the other's (issue #40: no import
circle between ``advance_ratio_perturbation`` and ``momentum_speed``).
"""
from ...physics import bladeelement as be
from ..equations import rotation


def true_trim_state(k, azimuth_bias: float, effect: str):
    """Trim ``(theta, beta, muz)`` of constants ``k`` (one line naming ``effect``
    if missing), cyclic components rotated from recorded to true by
    ``R(-azimuth_bias)``: what every effect linearised about the trim starts from.

    Parameters
    ----------
    k : Constants
        Constants holding the trim totals (``k.trim``) [rad, -].
    azimuth_bias : float
        Azimuth bias [rad]: the recorded cyclics are rotated by ``R(-azimuth_bias)``.
    effect : str
        Name of the effect asking, for the error message when the trim is missing.
    """
    theta, beta, muz = be.trim_state(k.trim, effect)
    if azimuth_bias:
        r = rotation(-azimuth_bias)
        theta[1:3] = r @ theta[1:3]
        beta[1:3] = r @ beta[1:3]
    return theta, beta, muz


__all__ = ["true_trim_state"]
