"""Pilot input shapes for flight tests: doublet, 3-2-1-1, log sweep, multisine.

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

import math
from functools import lru_cache

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


# -- frequency-rich inputs: sweeps and multisines -------------------------------------
def fade(t, t_start: float, length: float, fade_s: float) -> np.ndarray:
    """Raised-cosine envelope: 0 before ``t_start``, rising over ``fade_s`` [s] to 1,
    1 until ``fade_s`` before ``t_start + length``, falling to 0 at its end (value
    and slope continuous: a pilot's input starts and ends without a jolt)."""
    t = np.asarray(t, dtype=float)
    tau = t - t_start
    inside = ((tau >= 0) & (tau <= length)).astype(float)
    if fade_s <= 0:
        return inside
    f = min(fade_s, 0.5 * length)
    up = np.clip(tau / f, 0.0, 1.0)
    down = np.clip((length - tau) / f, 0.0, 1.0)
    return inside * 0.25 * (1 - np.cos(np.pi * up)) * (1 - np.cos(np.pi * down))


def fade_scalar(tau: float, length: float, fade_s: float) -> float:
    """:func:`fade` at one time ``tau`` [s] after the start (the ODE solver's path)."""
    if tau < 0 or tau > length:
        return 0.0
    if fade_s <= 0:
        return 1.0
    f = min(fade_s, 0.5 * length)
    up, down = min(tau / f, 1.0), min((length - tau) / f, 1.0)
    return 0.25 * (1 - math.cos(math.pi * up)) * (1 - math.cos(math.pi * down))


def log_sweep(t, t_start: float, length: float, f1: float, f2: float,
              amplitude: float, fade_s: float = 1.0) -> np.ndarray:
    """Exponential (logarithmic) frequency sweep [rad] from ``f1`` to ``f2`` [Hz] over
    ``length`` [s] starting at ``t_start``: instantaneous frequency
    ``f1 (f2/f1)^(tau/length)``, equal time per octave, peak ``amplitude``, faded in
    and out over ``fade_s`` [s] (:func:`fade`)."""
    # scipy.signal.chirp(tau, f1, length, f2, method="logarithmic", phi=-90) is the
    # same sweep to 1e-15 (tests/test_library_equivalence.py); importing
    # scipy.signal, which nothing else on this path loads, costs 1.7-2.3 s (measured
    # under the shared machine's load) against microseconds for these two lines: they
    # stay (issue #39)
    t = np.asarray(t, dtype=float)
    tau = np.clip(t - t_start, 0.0, length)
    r = np.log(f2 / f1)
    phase = 2 * np.pi * f1 * length / r * np.expm1(tau * r / length)
    return amplitude * fade(t, t_start, length, fade_s) * np.sin(phase)


def interleaved_harmonics(n_channels: int, k_min: int, k_max: int) -> list[tuple]:
    """Harmonic numbers for ``n_channels`` controls moved at once: channel ``i`` gets
    ``k_min + i, k_min + i + n, ...`` up to ``k_max``, so no two channels share a
    frequency and every channel spans the whole band (mutually orthogonal over
    whole periods)."""
    if n_channels < 1 or k_min < 1 or k_max < k_min + n_channels - 1:
        raise ValueError(f"harmonics {k_min}-{k_max} cannot give {n_channels} "
                         "channel(s) one each")
    return [tuple(range(k_min + i, k_max + 1, n_channels)) for i in range(n_channels)]


def schroeder_phases(power) -> np.ndarray:
    """Schroeder's phases [rad] for harmonics of relative powers ``power`` (a
    sequence summing to anything > 0): ``phi_k = -2 pi sum_{l<k} (k - l) p_l`` with
    ``p`` normalised to sum 1 (Schroeder 1970): the sum of cosines has a low peak
    factor (about 1.5-1.7 for a flat spectrum against sqrt(2 K) for zero phases)."""
    p = np.asarray(power, dtype=float)
    p = p / p.sum()
    k = np.arange(p.size)
    return np.array([-2 * np.pi * np.sum((kk - k[:kk]) * p[:kk]) for kk in k])


def multisine_unit(tau, base_hz: float, harmonics, weights=None, phases=None):
    """``sum_k w_k cos(2 pi k base_hz tau + phi_k)`` at times ``tau`` [s] from the start
    (unit weights and Schroeder phases unless given)."""
    h = np.asarray(harmonics, dtype=float)
    w = np.ones(h.size) if weights is None or not len(weights) else np.asarray(weights, float)
    ph = schroeder_phases(w ** 2) if phases is None or not len(phases) else \
        np.asarray(phases, float)
    tau = np.asarray(tau, dtype=float)
    out = np.zeros(tau.shape)
    for hk, wk, pk in zip(h, w, ph):
        if wk:
            out += wk * np.cos(2 * np.pi * hk * base_hz * tau + pk)
    return out


def multisine_peak(base_hz: float, harmonics, weights=None, phases=None,
                   n_grid: int = 4096) -> float:
    """Peak of :func:`multisine_unit` over one period (dense grid)."""
    k_max = max(harmonics)
    n = max(n_grid, 16 * int(k_max))
    tau = np.arange(n) / (n * base_hz)
    return float(np.max(np.abs(multisine_unit(tau, base_hz, harmonics, weights, phases))))


@lru_cache(maxsize=256)
def multisine_plan(base_hz: float, harmonics: tuple, weights: tuple, phases: tuple):
    w = weights or None
    ph = phases or None
    h = np.asarray(harmonics, dtype=float)
    w_ = np.ones(h.size) if w is None else np.asarray(w, float)
    ph_ = schroeder_phases(w_ ** 2) if ph is None else np.asarray(ph, float)
    return w_, ph_, multisine_peak(base_hz, harmonics, w_, ph_)


def multisine(t, t_start: float, length: float, base_hz: float, harmonics,
              amplitude: float, weights=None, phases=None, fade_s: float = 1.0):
    """A multisine [rad] of peak ``amplitude`` over the steady part: the harmonics
    ``k base_hz`` [Hz] with relative amplitudes ``weights`` (default equal) and
    ``phases`` (default Schroeder's, :func:`schroeder_phases`), from ``t_start`` for
    ``length`` s, faded in and out over ``fade_s`` s.  ``length`` a whole number of
    periods ``1 / base_hz`` keeps the channels of :func:`interleaved_harmonics`
    exactly orthogonal between the fades."""
    t = np.asarray(t, dtype=float)
    w, ph, peak = multisine_plan(float(base_hz), tuple(harmonics), tuple(weights or ()),
                        tuple(phases or ()))
    env = fade(t, t_start, length, fade_s)
    s = multisine_unit(t - t_start, base_hz, harmonics, w, ph) if np.any(env) else 0.0
    return amplitude / peak * env * s


def peak_factor(x) -> float:
    """Peak over root-mean-square of a signal (sqrt 2 for a sine)."""
    x = np.asarray(x, dtype=float)
    return float(np.max(np.abs(x)) / np.sqrt(np.mean(x * x)))


__all__ = ["RISE_PER_SIGMA", "smooth_step", "doublet", "input_3211", "SHAPES", "fade",
           "fade_scalar", "log_sweep", "interleaved_harmonics", "schroeder_phases",
           "multisine_unit", "multisine_peak", "multisine_plan", "multisine", "peak_factor"]
