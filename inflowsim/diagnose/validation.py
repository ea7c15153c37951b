"""Validation: replay a record's measured inputs through a model and compare flap.

Workflow step 1 of ``workflow.md`` (the paper's Figures 1-5): time-domain
reconstruction of the measured multiblade flap, per-channel fit figures, and the
measured frequency responses, each conditioned on the other inputs, with the
model's analytic responses on top and Tischler's cost per response pair.

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
* Fit percent is over the band's transforms at the record's own frequencies
  ``k / (N dt)`` with the end states estimated: exactly the figure ``identify``
  reports for the same model on the same record
  (:func:`inflowsim.identify.estimator.evaluate`).
* Frequency responses are :func:`inflowsim.identify.frf.response_of_series` of the
  record over the band: composite Hann windows, each output's response to each
  moving control conditioned on the other moving controls, with partial coherence
  and random error.  The model's response to the same inputs is analytic
  (:meth:`Model.frequency_response`, time shifts included, times the hold's factor:
  1 for continuous records, ``exp(-j w dt/2) sinc(w dt/2)`` for ``zoh``,
  ``sinc^2(w dt/2)`` for ``foh``, to aliasing accuracy); the model inputs that
  move but are not conditioned on (the hub motion the controls drive) are closed
  through their own measured responses to the conditioning inputs:
  ``H_c + H_hub T_hub``.  That is the response the model would have shown on this
  aircraft, with the hub moving as it did.
* Response errors (``magnitude_rms_db``, ``phase_rms_deg``) and Tischler's ``J``
  (:func:`inflowsim.identify.frf.tischler_cost`) are taken where a response is read
  (:meth:`FrequencyResponse.valid`: coherence ``>= 0.6`` and two windows or more).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..errors import InputError
from ..frozen import FrozenDict, readonly
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
    """Measured frequency responses of the flap and the model's on top.

    Attributes
    ----------
    measured : FrequencyResponse
        Composite responses of ``beta0, beta1c, beta1s`` to the conditioning inputs
        (:mod:`inflowsim.identify.frf`), with coherence and random error.
    model : ndarray, shape (3, q, nf)
        The model's analytic responses at ``measured.frequency_hz``, hold factor
        included, hub path closed through the measured hub responses (module doc)
        [rad / input unit].
    paths : tuple of str
        Moving model inputs not conditioned on, closed through their measured
        responses to the inputs (empty when only the inputs move).
    cost : mapping
        Tischler's ``J`` by ``(output, input)`` (NaN where no point is read).
    """

    measured: object
    model: np.ndarray
    paths: tuple
    cost: Mapping

    @property
    def f_hz(self) -> np.ndarray:
        """Grid frequencies [Hz]."""
        return self.measured.frequency_hz

    @property
    def inputs(self) -> tuple:
        """Input columns the responses are to (each conditioned on the others)."""
        return self.measured.inputs

    @property
    def valid(self) -> np.ndarray:
        """Where a measured point is read as a response, ``[output, input, f]``."""
        return self.measured.valid()

    @property
    def magnitude_error_db(self) -> np.ndarray:
        """``20 log10 |measured / model|`` per pair and frequency [dB]; NaN where
        either response is zero or undefined (never inf)."""
        r = self._ratio()
        out = np.full(r.shape, np.nan)
        ok = np.isfinite(r)
        out[ok] = 20.0 * np.log10(np.abs(r[ok]))
        return out

    @property
    def phase_error_deg(self) -> np.ndarray:
        """Phase of ``measured / model``, wrapped to (-180, 180] [deg]; NaN where
        either response is zero or undefined."""
        return np.degrees(np.angle(self._ratio()))

    def _ratio(self) -> np.ndarray:
        h, m = np.asarray(self.measured.h), np.asarray(self.model)
        ok = np.isfinite(h) & np.isfinite(m) & (h != 0) & (m != 0)
        out = np.full(np.broadcast(h, m).shape, np.nan + 0j)
        out[ok] = h[ok] / m[ok]
        return out

    @property
    def overall_cost(self) -> float:
        """Mean ``J`` over the pairs with points read (NaN if none)."""
        js = [j for j in self.cost.values() if np.isfinite(j)]
        return float(np.mean(js)) if js else float("nan")


def cost_verdict(j: float) -> str:
    """Tischler's guideline for ``J``: ``good`` (<= 50), ``acceptable`` (<= 100),
    ``poor``; ``-`` when undefined."""
    from ..identify.frf import J_ACCEPTABLE, J_GOOD
    if not np.isfinite(j):
        return "-"
    return "good" if j <= J_GOOD else "acceptable" if j <= J_ACCEPTABLE else "poor"


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
    dft_f_hz : ndarray, shape (nf,)
        The band's transform frequencies ``k / (N dt)`` [Hz].
    measured_dft, predicted_dft : ndarray, shape (3, nf)
        Transforms of the measured flap and of the replay from rest there [rad s]
        (their ``fit_percent`` differs from the reported one, which estimates the
        end states, by the replay's end effects only).
    frequency : FrequencyComparison
        Conditioned measured responses over the band and the model's.
    magnitude_rms_db, phase_rms_deg : mapping
        Per flap channel, RMS of the magnitude error [dB] and phase error [deg] of
        its responses to every input, over the points read (NaN if none).
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
    dft_f_hz: np.ndarray
    measured_dft: np.ndarray
    predicted_dft: np.ndarray
    frequency: FrequencyComparison
    magnitude_rms_db: Mapping[str, float]
    phase_rms_deg: Mapping[str, float]

    @property
    def error(self) -> np.ndarray:
        """Measured minus predicted flap [rad], shape (N, 3)."""
        return self.measured - self.predicted

    def to_json(self) -> dict:
        """The ``validate --json`` document (``interface.md``), plus extras: the
        responses as ``frf --json`` gives them with the model's (``model_real``,
        ``model_imag``) and ``J`` per pair, and the overall cost."""
        fc = self.frequency
        doc = fc.measured.to_json()
        for r in doc["responses"]:
            o, i = fc.measured.index(r["output"], r["input"])
            r["model_real"] = fc.model[o, i].real.tolist()
            r["model_imag"] = fc.model[o, i].imag.tolist()
            r["J"] = _num(fc.cost[(r["output"], r["input"])])
        overall = fc.overall_cost
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
            "n_frequencies": int(self.dft_f_hz.size),
            "inputs": list(fc.inputs),
            "hub_paths": list(fc.paths),
            # Tischler's guideline rating, not a verdict (one vocabulary: interface.md)
            "cost": {"overall": _num(overall), "guideline": cost_verdict(overall),
                     "per_pair": [{"output": o, "input": i, "J": _num(j),
                                   "guideline": cost_verdict(j)}
                                  for (o, i), j in fc.cost.items()]},
            "responses": doc["responses"],
            "response_grid": {k: doc[k] for k in ("windows_s", "n_averages", "overlap",
                                                  "window", "composite",
                                                  "coherence_threshold", "notes")},
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


def response_inputs(u, inputs) -> tuple:
    """The pilot controls (``theta0, theta1c, theta1s``) that move in ``u`` (columns
    ``inputs``), the default inputs of the responses."""
    moving = [c for c in CONTROL_COLUMNS if c in inputs
              and np.ptp(u[:, list(inputs).index(c)]) > 0]
    if not moving:
        raise InputError("no control moves: no frequency response to compare")
    return tuple(moving)


def hold_factor(hold: str, f_hz, dt: float) -> np.ndarray:
    """What the record's intersample behaviour does to a response, to aliasing
    accuracy: 1 (continuous), ``exp(-j w dt/2) sinc(w dt/2)`` (``zoh``: each sample
    held over its step), ``sinc^2(w dt/2)`` (``foh``: linear between samples)."""
    x = np.asarray(f_hz, dtype=float) * dt            # np.sinc(x) = sin(pi x)/(pi x)
    if hold == "zoh":
        return np.exp(-1j * np.pi * x) * np.sinc(x)
    if hold == "foh":
        return np.sinc(x) ** 2 + 0j
    return np.ones_like(x, dtype=complex)


def model_responses(model, fr_paths, inputs, paths, f_hz, hold, dt) -> np.ndarray:
    """The model's flap responses to ``inputs``, shape ``(3, q, nf)``:
    ``H[:, inputs] + H[:, paths] T`` with ``T`` (``fr_paths``, ``(len(paths), q,
    nf)``) the measured responses of the path channels to the inputs, times the
    hold's factor (:func:`hold_factor`)."""
    h = model.frequency_response(f_hz)[:3]
    cols = [model.inputs.index(c) for c in inputs]
    out = h[:, cols]
    if paths:
        pc = [model.inputs.index(c) for c in paths]
        out = out + np.einsum("ojf,jif->oif", h[:, pc], fr_paths)
    return out * hold_factor(hold, f_hz, dt)


def validate(record: Record, model, trim: Trim | None = None, band_hz=None,
             inputs=None, hold: str | None = None) -> ValidationResult:
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
        record's transform frequencies ``k / (N dt)``; the responses' grid spans
        the snapped band.
    inputs : sequence of str, optional
        Model inputs the responses are to, each conditioned on the others;
        default the controls that move (:func:`response_inputs`).
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
    InputError
        An input is not one of the model's or does not move.
    """
    from ..identify.frf import response_of_series, tischler_cost
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

    if inputs is None:
        inputs = response_inputs(u, model.inputs)
    inputs = tuple(inputs)
    for c in inputs:
        if c not in model.inputs:
            raise InputError(f"input {c!r} is not an input of the model (inputs: "
                             f"{', '.join(model.inputs)})")
        if np.ptp(u[:, model.inputs.index(c)]) == 0:
            raise InputError(f"input {c} does not move: no response to it can be measured")
    paths = tuple(c for j, c in enumerate(model.inputs)
                  if c not in inputs and np.ptp(u[:, j]) > 0)
    f_band = bins / record.duration
    cols = [model.inputs.index(c) for c in inputs + paths]
    fr_all = response_of_series([np.hstack([u[:, cols], z])], dt, inputs,
                                paths + tuple(FLAP_COLUMNS),
                                (float(f_band[0]), float(f_band[-1])),
                                sources=(record.source,))
    fr = _outputs(fr_all, FLAP_COLUMNS)
    h_model = model_responses(model, fr_all.h[:len(paths)], inputs, paths,
                              fr.frequency_hz, hold, dt)
    cost = {(o, i): tischler_cost(fr, h_model, o, i) for o in FLAP_COLUMNS for i in inputs}
    fc = FrequencyComparison(measured=fr, model=readonly(h_model, complex), paths=paths,
                             cost=FrozenDict(cost))

    z_dft = _dft(z, bins, dt).T
    y_dft = _dft(y, bins, dt).T
    # one definition of fit everywhere: over the band, as identify reports it
    band_fit = _band_fit(record, model, bins, hold)
    fits = {}
    for i, c in enumerate(FLAP_COLUMNS):
        f = fit_metrics(z[:, i], y[:, i])
        band = band_fit.get(c)
        fits[c] = ChannelFit(f.rms, f.tic, float("nan") if band is None else band)
    valid = fc.valid
    mag, ph = fc.magnitude_error_db, fc.phase_error_deg
    mag_rms = {c: _rms(mag[o][valid[o]]) for o, c in enumerate(FLAP_COLUMNS)}
    ph_rms = {c: _rms(ph[o][valid[o]]) for o, c in enumerate(FLAP_COLUMNS)}
    return ValidationResult(
        structure=model.structure.name, source=record.source, trim=trim, hold=hold,
        t=record.t,
        inputs=tuple(model.inputs), u=u, measured=z, predicted=y,
        channels=FrozenDict(fits), band_hz=(float(f_band[0]), float(f_band[-1])),
        dft_f_hz=f_band, measured_dft=z_dft, predicted_dft=y_dft,
        frequency=fc, magnitude_rms_db=FrozenDict(mag_rms),
        phase_rms_deg=FrozenDict(ph_rms))


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


def _outputs(fr, outputs):
    """``fr`` restricted to ``outputs`` (the flap, without the path channels)."""
    from dataclasses import replace
    rows = [fr.outputs.index(c) for c in outputs]
    return replace(fr, outputs=tuple(outputs), h=readonly(fr.h[rows], complex),
                   coherence=readonly(fr.coherence[rows]),
                   random_error=readonly(fr.random_error[rows]),
                   bias_error=readonly(fr.bias_error[rows]),
                   multiple_coherence=readonly(fr.multiple_coherence[rows]),
                   ordinary_coherence=readonly(fr.ordinary_coherence[rows]),
                   window_weight=readonly(fr.window_weight[:, rows]))



__all__ = ["PAPER_BAND_HZ", "ChannelFit", "FrequencyComparison", "ValidationResult",
           "fit_metrics", "dft_bins", "response_inputs", "hold_factor",
           "model_responses", "cost_verdict", "validate"]
