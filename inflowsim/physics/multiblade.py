"""Multiblade coordinates from individual blades, as a flight-test system extracts them.

For ``Nb`` blades at azimuths ``psi_i = psi + 2 pi i / Nb`` (blade 0 at ``psi``;
``psi = 0`` blade aft, ``model.md`` section 1) the multiblade flap is

``beta0 = (1/Nb) sum beta_i``,
``beta1c = (2/Nb) sum beta_i cos psi_i``,
``beta1s = (2/Nb) sum beta_i sin psi_i``.

A flight-test system uses its *recorded* azimuth ``psi + dpsi``; a bias ``dpsi``
then rotates the recorded cyclic components (``model.md`` section 6):
``beta1c_m = beta1c cos dpsi - beta1s sin dpsi``,
``beta1s_m = beta1c sin dpsi + beta1s cos dpsi``.
With an even number of blades the reactionless (differential) mode
``beta_d = (1/Nb) sum (-1)^i beta_i`` is invisible in the three coordinates.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError


def blade_azimuths(psi, n_blades: int) -> np.ndarray:
    """Azimuth of each blade [rad], shape ``psi.shape + (n_blades,)``."""
    _check_blades(n_blades)
    psi = np.asarray(psi, dtype=float)
    return psi[..., None] + 2.0 * np.pi * np.arange(n_blades) / n_blades


def multiblade(beta_blades, psi) -> np.ndarray:
    """``(beta0, beta1c, beta1s)`` from blade flap angles.

    Parameters
    ----------
    beta_blades : array_like, shape (..., Nb)
        Flap angle of each blade [rad] (up positive).
    psi : array_like, shape (...)
        Azimuth of blade 0 as the system knows it [rad]: the recorded azimuth,
        i.e. the true one plus any azimuth bias.

    Returns
    -------
    ndarray, shape (..., 3)
        Multiblade flap [rad].
    """
    b = np.asarray(beta_blades, dtype=float)
    nb = b.shape[-1]
    ang = blade_azimuths(psi, nb)
    return np.stack([b.mean(axis=-1),
                     2.0 / nb * np.sum(b * np.cos(ang), axis=-1),
                     2.0 / nb * np.sum(b * np.sin(ang), axis=-1)], axis=-1)


def reactionless(beta_blades) -> np.ndarray:
    """Differential mode ``beta_d = (1/Nb) sum (-1)^i beta_i`` [rad] (even ``Nb``)."""
    b = np.asarray(beta_blades, dtype=float)
    nb = b.shape[-1]
    if nb % 2:
        raise InputError(f"n_blades = {nb}: the reactionless mode needs an even number")
    return np.sum(b * (-1.0) ** np.arange(nb), axis=-1) / nb


def blade_angles(beta_mb, psi, n_blades: int) -> np.ndarray:
    """Blade flap angles ``beta0 + beta1c cos psi_i + beta1s sin psi_i`` [rad].

    The inverse of :func:`multiblade` for a rotor with no reactionless motion.
    """
    m = np.asarray(beta_mb, dtype=float)
    ang = blade_azimuths(psi, n_blades)
    return m[..., 0:1] + m[..., 1:2] * np.cos(ang) + m[..., 2:3] * np.sin(ang)


def multiblade_rates(beta_mb, dbeta_blades, psi) -> np.ndarray:
    """Multiblade flap rates ``(beta0', beta1c', beta1s')`` [rad/azimuth rad].

    The blade rates project onto ``beta1c' + beta1s`` and ``beta1s' - beta1c``
    (the rotating-frame terms of ``model.md`` section 2).
    """
    p = multiblade(dbeta_blades, psi)
    m = np.asarray(beta_mb, dtype=float)
    return np.stack([p[..., 0], p[..., 1] - m[..., 2], p[..., 2] + m[..., 1]], axis=-1)


def _check_blades(n_blades):
    if int(n_blades) != n_blades or n_blades < 3:
        raise InputError(f"n_blades = {n_blades}: multiblade coordinates need a whole "
                         "number of at least 3 blades")


__all__ = ["blade_azimuths", "multiblade", "reactionless", "blade_angles",
           "multiblade_rates"]
