"""Fourier transforms of a record's perturbations on a frequency grid.

Convention (no scaling): ``X(f) = sum_{n=0}^{N-1} c_n x_n z^-n`` with
``z = exp(j 2 pi f dt)``.  For held inputs (``zoh``, ``foh``) ``c_n = 1``: the DFT,
whose relation to the model is exact for the hold.  For continuous records
``c_n`` are Gregory's end-corrected trapezoid weights
(:func:`inflowsim.simulate.sampled.gregory_weights`): the sum is then the finite Fourier
integral ``(1/dt) int_0^T x(t) e^{-j w t} dt`` of the continuous signals to
aliasing accuracy, which the continuous transfer function relates exactly
(:mod:`.freqmodel`).  On the record's own grid ``f = k / (N dt)`` (resolution
``1/duration``) the sum is ``numpy.fft.rfft`` of ``c x``; any other chosen grid
is a direct sum at those frequencies (no windowing or interpolation).

Trim: the quiet lead-in mean of every channel (:func:`inflowsim.data.record.find_trim`)
is subtracted before transforming, so the model sees perturbations about trim.
The DC bin is never in a band (``f1 > 0``).  End effects (the record not starting
and ending at rest) are not windowed away: they are modelled exactly by the
frequency model's initial and final states (see :mod:`.freqmodel`).
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..defaults import DEFAULT_BAND  # the paper's band (model.md section 7) [Hz]
from ..errors import InputError, RecordError
from ..model.params import Constants
from ..data.record import (FLAP_COLUMNS, Record, find_trim, perturbations, read_record,
                           require_control_movement)
from ..simulate.sampled import gregory_weights

#: A band limit may sit this fraction of a bin outside the asked band (the paper
#: quotes 0.2256 Hz for the bin at 6/26.6 = 0.22556 Hz); never more.
SNAP_TOLERANCE = 0.01


def snap_band(n_samples: int, dt: float, band_hz) -> tuple[np.ndarray, tuple]:
    """Grid bins ``k`` of the band and the snapped band [Hz].

    Each limit snaps to the nearest grid frequency ``k / (N dt)`` that does not
    widen the band (by more than ``SNAP_TOLERANCE`` of a bin: rounding of a quoted
    limit), so a band never silently grows; it keeps every bin between them,
    never the DC bin, and must hold at least 3.

    Parameters
    ----------
    n_samples : int
        Record length ``N`` [samples].
    dt : float
        Sample step [s].
    band_hz : (float, float)
        The band asked for [Hz].

    Returns
    -------
    k : ndarray of int
    band : (float, float)
        The snapped limits [Hz].
    """
    f1, f2 = (float(b) for b in band_hz)
    df = 1.0 / (n_samples * dt)
    k1 = max(1, int(np.floor(f1 / df + 0.5)))
    if k1 * df < f1 - SNAP_TOLERANCE * df:
        k1 += 1
    k2 = min(n_samples // 2, int(np.floor(f2 / df + 0.5)))
    if k2 * df > f2 + SNAP_TOLERANCE * df:
        k2 -= 1
    if k2 - k1 < 2:
        raise InputError(f"band {f1:g}-{f2:g} Hz holds {max(k2 - k1 + 1, 0)} transform "
                         f"frequencies at the record's resolution {df:.4g} Hz (1/duration), "
                         f"fewer than 3: widen the band to at least {3 * df:.3g} Hz or use "
                         f"a record longer than {3 / max(f2 - f1, 1e-12):.3g} s")
    k = np.arange(k1, k2 + 1)
    return k, (k1 * df, k2 * df)


def dft(x: np.ndarray, dt: float, f_hz: np.ndarray, on_grid: bool,
        weights=None) -> np.ndarray:
    """``sum_n c_n x_n exp(-j 2 pi f n dt)`` along axis 0 of ``x`` (``(N, c)``);
    ``c_n = weights`` (default 1)."""
    x = np.asarray(x, dtype=float)
    n = x.shape[0]
    w = None if weights is None else np.asarray(weights, dtype=float)
    # the weights applied a column or a block at a time (the same products): a long
    # record never holds a weighted copy of all its columns
    if on_grid:
        k = np.rint(np.asarray(f_hz) * n * dt).astype(int)
        # a column at a time: only the band's bins are kept, so a long record never
        # holds the whole (N/2, c) transform
        out = np.empty((k.size, x.shape[1]), dtype=complex)
        for c in range(x.shape[1]):
            out[:, c] = np.fft.rfft(x[:, c] if w is None else x[:, c] * w)[k]
        return out
    out = np.zeros((np.size(f_hz), x.shape[1]), dtype=complex)
    for i in range(0, n, _DFT_BLOCK):      # bounded (nf, block) phase matrix
        m = np.arange(i, min(i + _DFT_BLOCK, n))
        xm = x[m] if w is None else x[m] * w[m, None]
        out += np.exp(-2j * np.pi * np.outer(f_hz, m) * dt) @ xm
    return out


#: Samples per block of the direct DFT on a chosen grid.
_DFT_BLOCK = 65536


@dataclass(frozen=True, eq=False)
class Spectra:
    """One record's transformed perturbations over the band.

    Attributes
    ----------
    source : str
    constants : Constants
    dt : float
        Sample step [s].
    n_samples : int
    f_hz : ndarray
        Frequencies [Hz], shape ``(nf,)``.
    on_grid : bool
        ``f_hz`` are bins of the record's own grid ``k / (N dt)``.
    inputs : tuple of str
        Input names (record columns) of ``U``.
    U : ndarray, complex ``(nf, m)``
        Input transforms.
    Z : ndarray, complex ``(nf, 3)``
        Measured flap transforms ``beta0 beta1c beta1s``.
    u_time : ndarray ``(N, m)``
        Input perturbations in time (the exact end-effect terms need the last
        few samples).
    z_time : ndarray ``(N, 3)``
        Flap perturbations in time (for the time-domain reconstruction).
    trim : Mapping
        Trim values subtracted [SI].
    trim_method : str
        How trim was found (one line).
    hold : str
        Intersample behaviour the transforms and the model assume
        (``continuous``, ``zoh``, ``foh``).
    """

    source: str
    constants: Constants
    dt: float
    n_samples: int
    f_hz: np.ndarray
    on_grid: bool
    inputs: tuple
    U: np.ndarray
    Z: np.ndarray
    u_time: np.ndarray
    z_time: np.ndarray
    trim: Mapping
    trim_method: str
    hold: str = "zoh"

    @property
    def z(self) -> np.ndarray:
        """``exp(j 2 pi f dt)`` per frequency."""
        return np.exp(2j * np.pi * self.f_hz * self.dt)

    @property
    def band_hz(self) -> tuple:
        return float(self.f_hz[0]), float(self.f_hz[-1])


def as_record(rec) -> Record:
    """A :class:`Record` from a record or a path."""
    if isinstance(rec, Record):
        return rec
    return read_record(rec)


def transform_weights(n_samples: int, hold: str):
    """``c_n`` of the transform for a record's hold (``None``: all ones)."""
    return gregory_weights(n_samples) if hold == "continuous" else None


def record_spectra(rec, inputs, band_hz=DEFAULT_BAND, grid_hz=None, hold=None,
                   require_motion=True, keep=True) -> Spectra:
    """Transform a record's input and flap perturbations over a band.

    Parameters
    ----------
    rec : Record or path
    inputs : sequence of str
        Model input names (record columns), e.g. ``Structure.inputs``.
    band_hz : (float, float)
        Band [Hz]; snaps to the record's grid ``k / (N dt)``.
    grid_hz : array_like, optional
        Chosen frequencies [Hz] instead (direct DFT); only those inside
        ``band_hz`` are kept, ``band_hz`` is not snapped.
    hold : str, optional
        Overrides the record's intersample behaviour (``# hold:``).
    require_motion : bool
        Refuse a record whose controls do not move (one line naming it).
    keep : bool
        Remember the spectra for the record's later calls (``False``: made for one
        use and not kept, as a long record's floor band, 27 MB for 2 hours at
        64 Hz; taken from the record's remembered ones all the same).
    """
    rec = as_record(rec)
    hold = rec.hold_or(hold)
    key = (tuple(inputs), tuple(float(b) for b in band_hz), None if grid_hz is None else
           tuple(np.asarray(grid_hz, dtype=float).ravel().tolist()), hold, require_motion)
    cache = _SPECTRA.setdefault(rec, {})
    if key in cache:
        return cache[key]
    sp = _record_spectra(rec, inputs, band_hz, grid_hz, hold, require_motion)
    if keep:
        cache[key] = sp
    return sp


#: Per record, its spectra by (inputs, band, grid, hold): a diagnosis transforms a
#: record for every fit and every analysis; once is enough (a 2-hour record's
#: transforms are a few seconds each).  Spectra are immutable, their arrays
#: read-only.
_SPECTRA: "weakref.WeakKeyDictionary[Record, dict]" = weakref.WeakKeyDictionary()


def _record_spectra(rec, inputs, band_hz, grid_hz, hold, require_motion):
    rec.require(tuple(inputs) + FLAP_COLUMNS)
    rec.require_measured(FLAP_COLUMNS)
    require_control_movement(rec)
    k_const = rec.constants
    n, dt = len(rec), rec.dt
    if grid_hz is None:
        rec.check_band(band_hz)
        k, _ = snap_band(n, dt, band_hz)
        f = k / (n * dt)
        on_grid = True
    else:
        f = np.sort(np.asarray(grid_hz, dtype=float).ravel())
        f = f[(f >= band_hz[0]) & (f <= band_hz[1])]
        if f.size < 3 or f[0] <= 0 or f[-1] > 0.5 / dt:
            raise InputError(f"chosen grid: need at least 3 frequencies inside the band "
                             f"{band_hz[0]:g}-{band_hz[1]:g} Hz, above 0 and below the "
                             f"Nyquist frequency {0.5 / dt:g} Hz")
        on_grid = False
    trim = find_trim(rec)
    u = perturbations(rec, trim, inputs)
    y = perturbations(rec, trim, FLAP_COLUMNS)
    c = transform_weights(n, hold)
    U = dft(u, dt, f, on_grid, c)
    Z = dft(y, dt, f, on_grid, c)
    if require_motion and not np.any(np.abs(Z) > 0):
        raise RecordError(f"{rec.source}: the flap channels do not move in the band "
                          f"{f[0]:.4g}-{f[-1]:.4g} Hz; nothing to fit")
    for a in (f, U, Z):
        a.flags.writeable = False
    return Spectra(rec.source, k_const, dt, n, f, on_grid, tuple(inputs), U, Z, u, y,
                   trim.values, trim.describe(), hold)


__all__ = ["SNAP_TOLERANCE", "snap_band", "dft", "Spectra", "as_record",
           "transform_weights", "record_spectra"]
