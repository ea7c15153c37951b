"""Validation: replay a record's measured inputs through a model and compare flap.

Workflow step 1 of ``workflow.md`` (the paper's Figures 1-5): time-domain
reconstruction of the measured multiblade flap, per-channel fit figures, and
frequency responses estimated from the record compared with the model's over a
band.

Conventions
-----------
* Trim is :func:`inflowsim.data.record.find_trim` (mean of the quiet lead-in before
  the first control movement) unless given; every channel is used as a
  perturbation about it, and ``ValidationResult.trim`` says how it was taken.
* The prediction is :func:`inflowsim.simulate.replay.replay` of the measured input
  perturbations at the record's step ``dt`` with the record's intersample
  behaviour (``# hold:``, or ``hold=``: exact for held or linear inputs, local
  cubics for continuous records; the model's time shifts included), from rest
  in trim.
* Frequency responses are ratios of DFTs at the record's own transform
  frequencies ``k / (N dt)``: measured flap over the reference input, and the
  *predicted* flap over the same input DFT, so measured and model responses see
  the same input spectrum (leakage and multi-input effects cancel in the
  comparison).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..errors import InputError
from ..frozen import FrozenDict
from ..identify.transform import DEFAULT_BAND, dft, snap_band
from ..data.record import (CONTROL_COLUMNS, FLAP_COLUMNS, Record, Trim, find_trim, perturbations,
                           require_control_movement)
from ..simulate.replay import replay

#: The paper's identification band [Hz] (the one default, :mod:`inflowsim.identify.transform`).
PAPER_BAND_HZ = DEFAULT_BAND


@dataclass(frozen=True)
class ChannelFit:
    """Fit figures of one flap channel.

    Attributes
    ----------
    rms : float
        RMS of the error ``z - y`` [rad].
    tic : float
        Theil inequality coefficient
        ``sqrt(mean(e^2)) / (sqrt(mean(y^2)) + sqrt(mean(z^2)))`` [-]; 0 is a
        perfect fit, 1 the worst.
    fit_percent : float
        :func:`inflowsim.identify.results.fit_percent` [%]: in :func:`validate`,
        over the band's transforms with the end states estimated, exactly the
        figure ``identify`` reports for the same model on the same record; from
        :func:`fit_metrics` on time series alone, over the whole record about its
        mean.  100 is a perfect fit.
    """

    rms: float
    tic: float
    fit_percent: float


@dataclass(frozen=True, eq=False)
class FrequencyComparison:
    """Measured and model frequency responses of the flap to one reference input.

    Attributes
    ----------
    f_hz : ndarray, shape (nf,)
        Transform frequencies in the band [Hz].
    reference_input : str
        Input column the responses are ratios to.
    input_dft : ndarray, shape (nf,)
        DFT of the reference input perturbation (``dt`` times the FFT) [unit s].
    measured_dft, predicted_dft : ndarray, shape (3, nf)
        DFT of measured and predicted flap perturbations [rad s].
    measured, model : ndarray, shape (3, nf)
        Responses ``measured_dft / input_dft`` and ``predicted_dft / input_dft``;
        NaN at a frequency where the input has no power
        (:func:`input_has_power`): no response is defined there.
    """

    f_hz: np.ndarray
    reference_input: str
    input_dft: np.ndarray
    measured_dft: np.ndarray
    predicted_dft: np.ndarray
    measured: np.ndarray
    model: np.ndarray

    @staticmethod
    def magnitude_db(h) -> np.ndarray:
        """``20 log10 |h|`` [dB]; NaN where ``h`` is zero or undefined."""
        a = np.abs(np.asarray(h))
        out = np.full(a.shape, np.nan)
        ok = np.isfinite(a) & (a > 0)
        out[ok] = 20.0 * np.log10(a[ok])
        return out

    @staticmethod
    def phase_deg(h) -> np.ndarray:
        """Phase unwrapped along frequency [deg] (over the defined frequencies; NaN
        where ``h`` is undefined)."""
        h = np.asarray(h)
        rows = h.reshape(-1, h.shape[-1])
        out = np.full(rows.shape, np.nan)
        for i, row in enumerate(rows):
            ok = np.isfinite(row)
            out[i, ok] = np.degrees(np.unwrap(np.angle(row[ok])))
        return out.reshape(h.shape)

    @property
    def magnitude_error_db(self) -> np.ndarray:
        """``20 log10 |measured / model|`` per channel and frequency [dB]; NaN where
        either response is zero or undefined."""
        return self.magnitude_db(self._ratio())

    @property
    def phase_error_deg(self) -> np.ndarray:
        """Phase of ``measured / model``, wrapped to (-180, 180] [deg]; NaN where
        either response is zero or undefined."""
        return np.degrees(np.angle(self._ratio()))

    def _ratio(self) -> np.ndarray:
        ok = (np.isfinite(self.measured) & np.isfinite(self.model) & (self.model != 0)
              & (self.measured != 0))
        out = np.full(self.measured.shape, np.nan + 0j)
        out[ok] = self.measured[ok] / self.model[ok]
        return out


@dataclass(frozen=True, eq=False)
class ValidationResult:
    """Measured against predicted flap, in time and frequency.

    Attributes
    ----------
    structure : str
        Name of the model's structure.
    source : str
        The record's file (or ``<memory>``).
    trim : Trim
        Trim subtracted from every channel (``trim.describe()`` says how).
    hold : str
        Intersample behaviour the replay assumed (``continuous``, ``zoh``, ``foh``).
    t : ndarray, shape (N,)
        Time [s].
    inputs : tuple of str
        Model input columns, the order of ``u``.
    u : ndarray, shape (N, m)
        Measured input perturbations [SI].
    measured, predicted : ndarray, shape (N, 3)
        Flap perturbations ``beta0, beta1c, beta1s`` [rad].
    channels : mapping
        :class:`ChannelFit` by flap channel name.
    band_hz : tuple of float
        Band actually used: first and last transform frequency [Hz].
    frequency : FrequencyComparison
    magnitude_rms_db, phase_rms_deg : mapping
        RMS over the band of the magnitude error [dB] and phase error [deg] per
        channel.
    """

    structure: str
    source: str
    trim: Trim
    hold: str
    t: np.ndarray
    inputs: tuple
    u: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    channels: Mapping[str, ChannelFit]
    band_hz: tuple
    frequency: FrequencyComparison
    magnitude_rms_db: Mapping[str, float]
    phase_rms_deg: Mapping[str, float]

    @property
    def error(self) -> np.ndarray:
        """Measured minus predicted flap [rad], shape (N, 3)."""
        return self.measured - self.predicted

    def to_json(self) -> dict:
        """The ``validate --json`` document (``interface.md``), plus extras."""
        return {
            "structure": self.structure,
            "record": self.source,
            "hold": self.hold,
            "channels": {c: {"rms": _num(f.rms), "tic": _num(f.tic),
                             "fit_percent": _num(f.fit_percent),
                             "magnitude_rms_db": _num(self.magnitude_rms_db[c]),
                             "phase_rms_deg": _num(self.phase_rms_deg[c])}
                         for c, f in self.channels.items()},
            "band_hz": list(self.band_hz),
            "n_frequencies": int(self.frequency.f_hz.size),
            "reference_input": self.frequency.reference_input,
            "trim": {"description": self.trim.describe(),
                     "values": {c: self.trim.values[c]
                                for c in (*self.inputs, *FLAP_COLUMNS)}},
        }


def _num(x):
    """JSON has no NaN: an undefined figure is ``null``."""
    return float(x) if np.isfinite(x) else None


def fit_metrics(measured, predicted) -> ChannelFit:
    """Time-domain fit figures of one channel.

    Parameters
    ----------
    measured : array_like
        Measured ``z`` [rad].
    predicted : array_like
        Predicted ``y`` [rad], same length.

    Returns
    -------
    ChannelFit
        ``tic`` is NaN when both signals are identically zero, ``fit_percent``
        (:func:`~inflowsim.identify.results.fit_percent` of ``z - mean(z)`` and
        ``y - mean(z)``) NaN when ``z`` is constant.
    """
    z = np.asarray(measured, dtype=float)
    y = np.asarray(predicted, dtype=float)
    # TIC and fit are scale-free: work on scaled signals so squares never underflow
    scale = float(max(np.max(np.abs(z), initial=0.0), np.max(np.abs(y), initial=0.0)))
    if scale == 0.0:
        return ChannelFit(0.0, float("nan"), float("nan"))
    z, y = z / scale, y / scale
    e = z - y
    rms = float(np.sqrt(np.mean(e**2)))
    den = float(np.sqrt(np.mean(y**2)) + np.sqrt(np.mean(z**2)))
    tic = rms / den
    fit = 100.0 * (1.0 - _norm_ratio(e, z - np.mean(z)))
    return ChannelFit(rms * scale, tic, fit)


def _norm_ratio(a, b) -> float:
    """``||a|| / ||b||`` without underflow when the two differ by hundreds of decades
    (NaN when ``b`` is zero)."""
    sa, sb = float(np.max(np.abs(a))), float(np.max(np.abs(b)))
    if sb == 0.0:
        return float("nan")
    if sa == 0.0:
        return 0.0
    return (sa / sb) * float(np.linalg.norm(a / sa) / np.linalg.norm(b / sb))


def dft_bins(record: Record, band_hz=None) -> np.ndarray:
    """Transform bin indices ``k`` (frequency ``k / (N dt)``) of the band, snapped as
    identification snaps it (:func:`inflowsim.identify.transform.snap_band`).

    ``band_hz`` defaults to :data:`PAPER_BAND_HZ`; the band is checked against the
    record (:meth:`Record.check_band`).
    """
    band = PAPER_BAND_HZ if band_hz is None else tuple(float(f) for f in band_hz)
    if len(band) != 2:
        raise InputError(f"band {band}: give two frequencies F1 F2 in Hz")
    record.check_band(band)
    return snap_band(len(record), record.dt, band)[0]


def _dft(x, bins, dt):
    """``dt * sum x_n exp(-2 pi j k n / N)`` at ``bins``, along axis 0 (the
    identification's transform on the record's grid, scaled to [unit s])."""
    return dt * dft(x, dt, bins / (len(x) * dt), True)


def reference_input(u_dft, inputs) -> str:
    """The pilot control (``theta0, theta1c, theta1s``) with most in-band energy.

    Controls share a unit (rad), so their energies compare; only when no control
    moves in the band is the input with most in-band energy (in its own SI unit)
    taken.
    """
    energy = np.sum(np.abs(u_dft) ** 2, axis=0)
    ctl = [i for i, n in enumerate(inputs) if n in CONTROL_COLUMNS and energy[i] > 0]
    pool = ctl or [i for i in range(len(inputs)) if energy[i] > 0]
    if not pool:
        raise InputError("no input moves in the band: nothing to compare responses to")
    return inputs[max(pool, key=lambda i: energy[i])]


def validate(record: Record, model, trim: Trim | None = None, band_hz=None,
             reference_input: str | None = None, hold: str | None = None
             ) -> ValidationResult:
    """Compare ``model`` with the measured flap of ``record``.

    Parameters
    ----------
    record : Record
        Totals as recorded (``record-format.md``); must hold the model's inputs
        and ``beta0, beta1c, beta1s``.
    model : Model
        Built at the record's flight condition (``record.constants``).
    trim : Trim, optional
        Default :func:`~inflowsim.data.record.find_trim` of the record.
    band_hz : (float, float), optional
        Frequency band [Hz], default :data:`PAPER_BAND_HZ`, snapped to the
        record's transform frequencies ``k / (N dt)``.
    reference_input : str, optional
        Input column the responses are ratios to; default the pilot control
        with most in-band energy (:func:`reference_input`).
    hold : {"continuous", "zoh", "foh"}, optional
        Intersample behaviour of the inputs; default the record's (``# hold:``).

    Returns
    -------
    ValidationResult

    Raises
    ------
    RecordError
        The record lacks a column the model needs, no control moves in it, or it
        is too short for the band.
    """
    record.require((*model.inputs, *FLAP_COLUMNS))
    record.require_measured(FLAP_COLUMNS)
    require_control_movement(record)
    bins = dft_bins(record, band_hz)
    trim = find_trim(record) if trim is None else trim
    u = perturbations(record, trim, model.inputs)
    z = perturbations(record, trim, FLAP_COLUMNS)
    dt = record.dt
    hold = record.hold_or(hold)
    y = replay(model, u, dt, hold)[:, :3]

    u_dft = _dft(u, bins, dt)
    if reference_input is None:
        ref = _reference(u_dft, model.inputs)
    elif reference_input not in model.inputs:
        raise InputError(f"reference input {reference_input!r} is not an input of the "
                         f"model (inputs: {', '.join(model.inputs)})")
    else:
        ref = reference_input
    x = u_dft[:, model.inputs.index(ref)]
    powered = input_has_power(x)
    if not powered.any():
        raise InputError(f"reference input {ref} has no energy in the band")
    z_dft = _dft(z, bins, dt).T
    y_dft = _dft(y, bins, dt).T
    # a ratio to an input without power is rounding noise over rounding noise (a
    # long record of repeated manoeuvres is periodic: between its harmonics the
    # input's DFT is 1e-18 of its peak, or 0, and the ratio 100 dB off or inf)
    xs = np.where(powered, x, 1.0)
    fc = FrequencyComparison(f_hz=bins / record.duration, reference_input=ref,
                             input_dft=x, measured_dft=z_dft, predicted_dft=y_dft,
                             measured=np.where(powered, z_dft / xs, np.nan),
                             model=np.where(powered, y_dft / xs, np.nan))
    band_fit = _band_fit(record, model, bins, hold)
    fits = {}
    for i, c in enumerate(FLAP_COLUMNS):
        f = fit_metrics(z[:, i], y[:, i])
        band = band_fit.get(c)
        fits[c] = ChannelFit(f.rms, f.tic, float("nan") if band is None else band)
    mag_rms = {c: _rms(v) for c, v in zip(FLAP_COLUMNS, fc.magnitude_error_db)}
    ph_rms = {c: _rms(v) for c, v in zip(FLAP_COLUMNS, fc.phase_error_deg)}
    return ValidationResult(
        structure=model.structure.name, source=record.source, trim=trim, hold=hold,
        t=record.t,
        inputs=tuple(model.inputs), u=u, measured=z, predicted=y,
        channels=FrozenDict(fits), band_hz=(float(fc.f_hz[0]), float(fc.f_hz[-1])),
        frequency=fc, magnitude_rms_db=FrozenDict(mag_rms),
        phase_rms_deg=FrozenDict(ph_rms))


#: A band frequency where the input's DFT is this far below its peak in the band
#: (-180 dB: rounding, not excitation) has no power: no response is defined there.
NO_POWER = 1e-9


def input_has_power(x) -> np.ndarray:
    """Mask of the band frequencies where the input DFT ``x`` has power: above
    :data:`NO_POWER` times its largest magnitude in the band."""
    a = np.abs(np.asarray(x))
    peak = float(np.max(a, initial=0.0))
    return (a > NO_POWER * peak) if peak > 0 and np.isfinite(peak) else np.zeros(a.shape, bool)


def _rms(v) -> float:
    """RMS over the defined (finite) entries; NaN when there are none (no response
    above noise to compare)."""
    v = np.asarray(v, dtype=float)
    v = v[np.isfinite(v)]
    return float(np.sqrt(np.mean(v ** 2))) if v.size else float("nan")


def _band_fit(record, model, bins, hold) -> dict:
    """Per flap channel, :func:`~inflowsim.identify.results.fit_percent` of the model
    over the band computed as ``identify`` computes it (the record's own transforms,
    the end states estimated, :func:`inflowsim.identify.estimator.evaluate`), so one
    model on one record reads the same in ``identify``, ``validate``, the ladder and
    every report.  The replay from rest differs from it by its end effects only
    (0.15 points on the demo's basic fit); that difference is no second fit figure.
    ``{}`` (the figure undefined) when the flap does not move in the band."""
    from ..errors import RecordError
    from ..identify.estimator import evaluate
    band = (bins[0] / record.duration, bins[-1] / record.duration)
    try:
        ev = evaluate([record], model.structure, dict(model.parameters), band_hz=band,
                      hold=hold)
    except RecordError:
        return {}
    return {c: ev.fit[c]["fit_percent"] for c in FLAP_COLUMNS}


_reference = reference_input     # the parameter of validate() shadows the function

__all__ = ["PAPER_BAND_HZ", "NO_POWER", "input_has_power", "ChannelFit",
           "FrequencyComparison", "ValidationResult", "fit_metrics", "dft_bins",
           "reference_input", "validate"]
