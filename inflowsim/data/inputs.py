"""Pilot input shapes for flight tests: doublet and 3-2-1-1.

A pilot's input is a continuous signal: each switch of a pulse train is a smooth
step with a 10-90 % rise time ``rise`` [s] (a Gaussian-smoothed step,
``0.5 (1 + erf(t / (sqrt 2 sigma)))`` with ``sigma = rise / 2.5631``), so the
signal and all its derivatives are continuous and its spectrum falls like
``exp(-(2 pi f sigma)^2 / 2)``: far below the noise beyond a few Hz.  With
``rise = 0`` the switches are sharp (a held signal switching on sample boundaries
when the switch times are multiples of the step).

Each shape returns the perturbation [rad] at times ``t`` [s].
"""
from __future__ import annotations

import numpy as np
from scipy.special import erf

#: 10-90 % rise time of a Gaussian-smoothed step, in units of its sigma.
RISE_PER_SIGMA = 2.0 * 1.2815515655446004


def smooth_step(t, t0: float, rise: float) -> np.ndarray:
    """0 before ``t0``, 1 after, with a Gaussian-smoothed switch of 10-90 % rise
    time ``rise`` [s] centred on ``t0`` (sharp for ``rise = 0``)."""
    t = np.asarray(t, dtype=float)
    if rise <= 0:
        eps = 1e-9 * max(1.0, abs(t0))
        return (t >= t0 - eps).astype(float)
    sigma = rise / RISE_PER_SIGMA
    return 0.5 * (1.0 + erf((t - t0) / (np.sqrt(2.0) * sigma)))


def _pulses(t, t_start, widths, signs, amplitude, rise):
    t = np.asarray(t, dtype=float)
    out = np.zeros_like(t)
    edge, level = t_start, 0.0
    for w, s in zip(widths, signs):
        out += (s - level) * amplitude * smooth_step(t, edge, rise)
        level = s
        edge += w
    return out - level * amplitude * smooth_step(t, edge, rise)


def doublet(t, t_start: float, width: float, amplitude: float, rise: float = 0.0):
    """``+amplitude`` for ``width`` s from ``t_start``, then ``-amplitude`` for ``width`` s."""
    return _pulses(t, t_start, (width, width), (1, -1), amplitude, rise)


def input_3211(t, t_start: float, unit: float, amplitude: float, rise: float = 0.0):
    """3-2-1-1: pulses of 3, 2, 1, 1 ``unit`` s with alternating sign."""
    return _pulses(t, t_start, (3 * unit, 2 * unit, unit, unit), (1, -1, 1, -1),
                   amplitude, rise)


SHAPES = {"doublet": doublet, "3211": input_3211}
