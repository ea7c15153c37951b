"""Pilot input shapes for flight tests: doublet and 3-2-1-1.

Each returns the perturbation [rad] at times ``t`` [s]; values are exact at
the samples (a piecewise-constant signal switching on sample boundaries when the
switch times are multiples of the step).
"""
from __future__ import annotations

import numpy as np


def _pulses(t, t_start, widths, signs, amplitude):
    t = np.asarray(t, dtype=float)
    out = np.zeros_like(t)
    edge = t_start
    eps = 1e-9 * max(1.0, abs(t_start))
    for w, s in zip(widths, signs):
        out[(t >= edge - eps) & (t < edge + w - eps)] = s * amplitude
        edge += w
    return out


def doublet(t, t_start: float, width: float, amplitude: float) -> np.ndarray:
    """``+amplitude`` for ``width`` s from ``t_start``, then ``-amplitude`` for ``width`` s."""
    return _pulses(t, t_start, (width, width), (1, -1), amplitude)


def input_3211(t, t_start: float, unit: float, amplitude: float) -> np.ndarray:
    """3-2-1-1: pulses of 3, 2, 1, 1 ``unit`` s with alternating sign."""
    return _pulses(t, t_start, (3 * unit, 2 * unit, unit, unit), (1, -1, 1, -1), amplitude)


SHAPES = {"doublet": doublet, "3211": input_3211}
