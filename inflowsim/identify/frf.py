"""Non-parametric frequency responses from flight-test records (issue #25).

What a flight-test engineer reads before any model: each output's response to each
input, with its coherence and its random error, from one or several records of one
flight condition.

Method
------
1. **Perturbations.**  Each record's channels minus its trim
   (:func:`inflowsim.data.record.find_trim`), as identification sees them.
2. **Spectral averages per window length.**  For each window length ``T_w`` the
   records are cut into Hann-windowed segments overlapping by ``overlap`` (75 % by
   default); the segments' Fourier transforms give the averaged auto- and
   cross-spectral matrix ``G = [[Gxx, Gxy], [Gyx, Gyy]]`` (one-sided, [unit^2/Hz])
   on the composite frequency grid (log-spaced).  The transforms are evaluated
   directly at the grid's frequencies (a real matrix product of the windowed
   segments with cosines and sines) rather than on each window's own FFT bins:
   the windows' estimates must meet at common frequencies, and interpolating
   between bins biases a high-coherence estimate by more than its random error.
   A window contributes only from ``K_MIN / T_w`` up (three bins: the Hann main lobe
   is two bins wide each side, so leakage from below the band is small there).
3. **Multi-input conditioning.**  At each frequency, ``H = Gxx^-1 Gxy`` (Bendat &
   Piersol, *Random Data*, ch. 7): each output's response to each input with the
   other inputs' correlated part removed.  With ``Gnn = Gyy - Gxy^H Gxx^-1 Gxy`` the
   part of the output no input explains, the multiple coherence is ``1 - Gnn /
   Gyy`` and the partial coherence of input ``i`` is ``|H_i|^2 G_ii.x /
   (Gnn + |H_i|^2 G_ii.x)`` with ``G_ii.x = 1 / [Gxx^-1]_ii`` the input's
   autospectrum conditioned on the others.  With one input these are the
   ordinary ``H = Gxy / Gxx`` and ``gamma^2 = |Gxy|^2 / (Gxx Gyy)``.
4. **Random error.**  The normalised random error of ``|H|`` (equal to the
   standard deviation of the phase in radians) is Bendat & Piersol's
   ``eps = sqrt(1 - gamma^2) / (|gamma| sqrt(2 (n_d - q + 1)))`` with ``gamma^2`` the
   partial coherence, ``q`` the number of inputs (``q = 1``: the single-input
   formula) and ``n_d`` the *effective* number of independent averages: overlapped
   Hann segments are correlated, and ``n_d = n / (1 + 2 sum_j (1 - j/n) rho_j)``
   with ``rho_j`` the squared normalised overlap of segments ``j`` hops apart
   (Welch 1967), summed over the records.
5. **Composite.**  At each frequency and response pair the window estimates are
   combined with weights ``1 / eps_w^2`` (inverse random-error variance, CIFER's
   idea without its optimisation); a window with fewer than ``MIN_DOF``
   degrees of freedom ``n_d - q + 1`` there is left out (its coherence is biased
   towards 1).  The windows' estimates come from the same data, so the composite's
   error is stated conservatively as the weighted mean of the windows' ``eps``
   (exact for fully correlated estimates, an upper bound otherwise), not the
   independent-estimates ``(sum 1/eps_w^2)^-1/2``.  Coherences are combined with the
   same weights.
6. **Bias.**  Windows of different length carry different resolution and leakage
   bias; their spread about the composite is reported as ``bias_error`` (a
   relative error per component, like ``eps``), and a point is read as a response
   (:meth:`FrequencyResponse.valid`) only where coherence ``>= 0.6`` and two or
   more windows serve it: one window alone shows no spread, and at the low end,
   which the longest window serves alone, its resolution bias can exceed its
   random error many times.  The stated error of a point is
   ``sqrt(eps^2 + bias^2)``.

Phases are returned as complex numbers; :func:`frequency_response_plot` draws them
unwrapped (the axis says so; ``unwrap=False``, ``frf --wrap``: wrapped to +-180 deg).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..channels import CONTROLS, FLAP
from ..errors import InputError
from ..frozen import readonly

#: Default band [Hz] of the composite grid.
DEFAULT_FRF_BAND = (0.1, 5.0)
#: Grid points per decade of frequency.
POINTS_PER_DECADE = 50
#: Default overlap of consecutive segments (fraction of a window).
OVERLAP = 0.75
#: Number of window lengths of the composite by default.
N_WINDOWS = 5
#: Longest window by default, as a fraction of the shortest record.
LONGEST = 0.5
#: Shortest window by default, as a fraction of the longest.
SHORTEST = 1.0 / 6.0
#: A window serves frequencies from this many of its bins ``1 / T_w`` up.
K_MIN = 3.0
#: Least degrees of freedom ``n_d - q + 1`` for a window to contribute.
MIN_DOF = 2.0
#: An input whose coherence with the others exceeds this is reported as collinear.
COLLINEAR = 0.95
#: Coherence (squared) from which a point is read as a valid response (CIFER's).
COHERENCE_OK = 0.6


@dataclass(frozen=True, eq=False)
class FrequencyResponse:
    """Composite non-parametric frequency responses (see module doc).

    Arrays are indexed ``[output, input, frequency]``:

    ``h`` complex response [output unit / input unit]; ``coherence`` partial
    coherence ``gamma^2`` [-] (ordinary with one input); ``random_error``
    normalised random error ``eps`` [-] of ``|h|`` (and the phase's standard
    deviation [rad]); ``ordinary_coherence`` ``|Gxy|^2 / (Gxx Gyy)`` of the pair
    alone.  ``multiple_coherence`` ``[output, frequency]``.  ``windows_s`` the
    window lengths [s], ``n_averages`` their effective independent averages
    ``n_d``; ``window_weight`` ``[window, output, input, frequency]`` each
    window's share of the composite (0 where it does not contribute).
    ``bias_error`` the spread of the windows' estimates about the composite,
    relative, per component (``sqrt(sum share |H_w - H|^2 / 2) / |H|``): windows of
    different length have different resolution and leakage bias, so their
    disagreement beyond their random error shows it.
    """

    inputs: tuple
    outputs: tuple
    frequency_hz: np.ndarray
    h: np.ndarray
    coherence: np.ndarray
    random_error: np.ndarray
    bias_error: np.ndarray
    multiple_coherence: np.ndarray
    ordinary_coherence: np.ndarray
    windows_s: tuple
    n_averages: tuple
    overlap: float
    band_hz: tuple
    dt: float
    sources: tuple
    window_weight: np.ndarray = field(repr=False)
    notes: tuple = ()

    def index(self, output: str, input: str) -> tuple:
        """``(i_output, i_input)`` of a pair, refusing unknown names."""
        if output not in self.outputs:
            raise InputError(f"output {output!r}: the responses have "
                             f"{', '.join(self.outputs)}")
        if input not in self.inputs:
            raise InputError(f"input {input!r}: the responses have {', '.join(self.inputs)}")
        return self.outputs.index(output), self.inputs.index(input)

    def pair(self, output: str, input: str) -> dict:
        """One response's arrays by name: ``h``, ``coherence``, ``random_error``."""
        o, i = self.index(output, input)
        return {"h": self.h[o, i], "coherence": self.coherence[o, i],
                "random_error": self.random_error[o, i]}

    @property
    def n_windows(self) -> np.ndarray:
        """Windows contributing to each point ``[output, input, frequency]``."""
        return np.sum(self.window_weight > 0, axis=0)

    def valid(self, threshold: float = COHERENCE_OK) -> np.ndarray:
        """Where a point is read as a response: coherence ``>= threshold``, a finite
        error, and at least two windows (one window alone shows no spread, so its
        resolution bias, largest at the low end a single long window serves, would
        go unstated)."""
        return ((self.coherence >= threshold) & np.isfinite(self.random_error)
                & (self.n_windows >= 2))

    def to_json(self) -> dict:
        resp = []
        for o, out in enumerate(self.outputs):
            for i, inp in enumerate(self.inputs):
                h = self.h[o, i]
                resp.append({
                    "input": inp, "output": out,
                    "frequency_hz": self.frequency_hz.tolist(),
                    "real": h.real.tolist(), "imag": h.imag.tolist(),
                    "magnitude_db": (20 * np.log10(np.abs(h))).tolist(),
                    "phase_deg": np.degrees(np.angle(h)).tolist(),
                    "coherence": self.coherence[o, i].tolist(),
                    "random_error": self.random_error[o, i].tolist(),
                    "ordinary_coherence": self.ordinary_coherence[o, i].tolist(),
                    "multiple_coherence": self.multiple_coherence[o].tolist()})
        return {"responses": resp, "inputs": list(self.inputs),
                "outputs": list(self.outputs), "band_hz": list(self.band_hz),
                "windows_s": list(self.windows_s),
                "n_averages": list(self.n_averages), "overlap": self.overlap,
                "window": "hann", "composite": "inverse random-error variance",
                "coherence_threshold": COHERENCE_OK, "dt": self.dt,
                "records": list(self.sources), "notes": list(self.notes)}


# -- helpers ---------------------------------------------------------------------------
def _as_records(records):
    from ..data.record import Record, read_record
    if isinstance(records, (Record, str)) or hasattr(records, "__fspath__"):
        records = [records]
    out = [r if isinstance(r, Record) else read_record(r) for r in records]
    if not out:
        raise InputError("frequency response: give at least one record")
    return out


def moving_inputs(records, candidates=CONTROLS) -> tuple:
    """The controls that move in any of ``records`` (the default inputs)."""
    from ..data.record import find_trim
    moving = []
    for c in candidates:
        for rec in records:
            if c in rec.channels and np.ptp(rec[c] - find_trim(rec).values[c]) > 0:
                moving.append(c)
                break
    return tuple(moving)


def effective_averages(n_seg: int, window: np.ndarray, hop: int) -> float:
    """Effective number of independent averages of ``n_seg`` segments ``hop``
    samples apart (Welch 1967): ``n / (1 + 2 sum_j (1 - j/n) rho_j)``."""
    if n_seg <= 0:
        return 0.0
    w2 = float(np.sum(window ** 2))
    s = 0.0
    for j in range(1, n_seg):
        lag = j * hop
        if lag >= window.size:
            break
        rho = (float(np.dot(window[:-lag], window[lag:])) / w2) ** 2
        s += (1 - j / n_seg) * rho
    return n_seg / (1 + 2 * s)


def default_windows(shortest_record_s: float, band_hz, n: int = N_WINDOWS) -> tuple:
    """Window lengths [s]: ``n`` geometrically spaced from ``LONGEST`` of the shortest
    record down to ``SHORTEST`` of that (each at least ``K_MIN`` periods of the
    band's top)."""
    t_max = LONGEST * shortest_record_s
    t_min = max(SHORTEST * t_max, K_MIN / band_hz[1])
    if t_min >= t_max:
        return (t_max,)
    return tuple(float(x) for x in np.geomspace(t_max, t_min, n))


def _grid(band_hz, per_decade):
    f1, f2 = band_hz
    n = max(2, int(round(per_decade * np.log10(f2 / f1))) + 1)
    return np.geomspace(f1, f2, n)


def _spectra(series, dt, length, overlap, f_hz):
    """Averaged one-sided spectral matrices ``(nf, nch, nch)`` of the channels of
    every record in ``series`` (list of ``(N, nch)``), Hann windows of ``length``
    samples; and the effective number of averages."""
    # the periodic Hann window (scipy.signal.get_window("hann", length), whose
    # import would cost more than the whole estimate: 1.7-2.3 s measured under the
    # shared machine's load).  Not scipy.signal.csd either: the composite reads the
    # spectra at log-spaced frequencies between the FFT bins; on the bins it is
    # csd's Hann-window estimate to 1e-13 (tests/test_library_equivalence.py)
    w = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(length) / length)
    hop = max(1, int(round(length * (1 - overlap))))
    n = np.arange(length) * dt
    arg = 2 * np.pi * np.outer(n, f_hz)
    cos, sin = np.cos(arg), np.sin(arg)
    nch = series[0].shape[1]
    acc = np.zeros((f_hz.size, nch, nch), dtype=complex)
    n_seg, n_eff = 0, 0.0
    for x in series:
        if x.shape[0] < length:
            continue
        seg = np.lib.stride_tricks.sliding_window_view(x, length, axis=0)[::hop]
        k = seg.shape[0]                                   # (k, nch, length)
        flat = (seg * w).reshape(k * nch, length)
        X = (flat @ cos - 1j * (flat @ sin)).reshape(k, nch, f_hz.size)
        acc += np.einsum("kif,kjf->fij", X.conj(), X)
        n_seg += k
        n_eff += effective_averages(k, w, hop)
    if n_seg == 0:
        return None, 0.0
    scale = 2 * dt / float(np.sum(w ** 2))
    return acc * (scale / n_seg), n_eff


def _conditioned(G, q, n_eff):
    """``H (p, q, nf)``, partial and ordinary coherence, eps, multiple coherence from
    spectral matrices ``G (nf, q+p, q+p)`` (inputs first)."""
    gxx, gxy = G[:, :q, :q], G[:, :q, q:]
    gyy = np.real(np.einsum("fii->fi", G[:, q:, q:]))
    gxx_diag = np.real(np.einsum("fii->fi", gxx))
    with np.errstate(all="ignore"):
        inv = np.linalg.inv(gxx)                                   # (nf, q, q)
        hT = inv @ gxy                                             # (nf, q, p)
        explained = np.real(np.einsum("fip,fij,fjp->fp", gxy.conj(), inv, gxy))
        gnn = np.maximum(gyy - explained, 0.0)                     # (nf, p)
        mult = 1 - gnn / gyy
        gii = 1.0 / np.real(np.einsum("fii->fi", inv))             # (nf, q)
        sig = np.abs(hT) ** 2 * gii[:, :, None]                    # (nf, q, p)
        part = sig / (gnn[:, None, :] + sig)
        ordinary = np.abs(gxy) ** 2 / (gxx_diag[:, :, None] * gyy[:, None, :])
        dof = n_eff - q + 1
        eps = np.sqrt((1 - part) / (part * 2 * dof)) if dof > 0 else \
            np.full(part.shape, np.inf)
        collinear = 1 - gii / gxx_diag            # input's coherence with the others
    tr = (2, 1, 0)                          # (nf, q, p) -> (p, q, nf)
    return (np.transpose(hT, tr), np.transpose(part, tr), np.transpose(eps, tr),
            np.transpose(ordinary, tr), mult.T, collinear.T)


# -- the response --------------------------------------------------------------------
def frequency_response(records, inputs=None, outputs=FLAP, band_hz=DEFAULT_FRF_BAND,
                       windows_s=None, overlap: float = OVERLAP,
                       points_per_decade: int = POINTS_PER_DECADE) -> FrequencyResponse:
    """Composite multi-input frequency responses of ``outputs`` to ``inputs``.

    Parameters
    ----------
    records : Record, path, or a sequence of them
        One flight condition: equal sample steps; each record's own trim is
        subtracted (:func:`~inflowsim.data.record.find_trim`).
    inputs : sequence of str, optional
        Input channels (default: the controls that move in any record).  Inputs
        must not be linear functions of each other (the conditioning solves with
        their spectral matrix); a record's hub motion driven by the controls alone
        is such a function of them.
    outputs : sequence of str
        Output channels (default the measured flap ``beta0 beta1c beta1s`` [rad]).
    band_hz : (float, float)
        Composite grid's band [Hz], log-spaced ``points_per_decade`` a decade.
    windows_s : sequence of float, optional
        Window lengths [s] (default :func:`default_windows`).
    overlap : float
        Overlap of consecutive segments [-], in [0, 0.95].

    Returns
    -------
    FrequencyResponse
        Composite responses, coherences and random errors (see module doc for the
        method: inverse random-error variance weighting of the windows).
    """
    from ..data.record import find_trim, perturbations
    recs = _as_records(records)
    dt = recs[0].dt
    for r in recs[1:]:
        if abs(r.dt - dt) > 1e-6 * dt:
            raise InputError(f"{r.source}: sample step {r.dt:g} s differs from "
                             f"{recs[0].source}'s {dt:g} s; resample to one rate")
    inputs = tuple(inputs) if inputs is not None else moving_inputs(recs)
    if not inputs:
        raise InputError("frequency response: no control moves in the records; "
                         "name the inputs")
    outputs = tuple(outputs)
    _check_channels(inputs, outputs)
    series = []
    for r in recs:
        x = perturbations(r, find_trim(r), inputs + outputs)
        for j, c in enumerate(inputs):
            if np.ptp(x[:, j]) == 0 and len(recs) == 1:
                raise InputError(f"{r.source}: input {c} does not move: no response "
                                 "to it can be measured")
        series.append(x)
    return response_of_series(series, dt, inputs, outputs, band_hz, windows_s, overlap,
                              points_per_decade, tuple(r.source for r in recs))


def _check_channels(inputs, outputs):
    if not outputs:
        raise InputError("frequency response: give at least one output")
    both = [c for c in inputs if c in outputs]
    if both or len(set(inputs)) < len(inputs) or len(set(outputs)) < len(outputs):
        raise InputError(f"channel {(both or inputs)[0]!r} given twice (inputs and "
                         "outputs must be distinct)")


def response_of_series(series, dt, inputs, outputs, band_hz=DEFAULT_FRF_BAND,
                       windows_s=None, overlap: float = OVERLAP,
                       points_per_decade: int = POINTS_PER_DECADE,
                       sources=("<memory>",)) -> FrequencyResponse:
    """:func:`frequency_response` of perturbation arrays: ``series`` a list of
    ``(N, len(inputs) + len(outputs))`` arrays (inputs first), step ``dt`` [s]."""
    inputs, outputs = tuple(inputs), tuple(outputs)
    _check_channels(inputs, outputs)
    f1, f2 = (float(x) for x in band_hz)
    if not (np.isfinite(f1) and np.isfinite(f2) and 0 < f1 < f2):
        raise InputError(f"band {f1:g}-{f2:g} Hz: need 0 < F1 < F2")
    if f2 > 0.5 / dt:
        raise InputError(f"band upper limit {f2:g} Hz is above the Nyquist frequency "
                         f"{0.5 / dt:g} Hz")
    if not 0 <= overlap <= 0.95:
        raise InputError(f"overlap {overlap:g}: choose a fraction in [0, 0.95]")
    series = [np.asarray(x, dtype=float) for x in series]
    shortest = min(len(x) for x in series) * dt
    if windows_s is None:
        windows_s = default_windows(shortest, (f1, f2))
    windows_s = tuple(float(w) for w in windows_s)
    longest = max(len(x) for x in series) * dt
    for w in windows_s:
        if not (np.isfinite(w) and 8 * dt <= w <= longest):
            raise InputError(f"window {w:g} s: must lie between 8 samples and the "
                             f"longest record ({longest:g} s)")
    f = _grid((f1, f2), points_per_decade)
    q, p, nf, nw = len(inputs), len(outputs), f.size, len(windows_s)
    hs = np.full((nw, p, q, nf), np.nan, dtype=complex)
    part = np.full((nw, p, q, nf), np.nan)
    ordn = np.full((nw, p, q, nf), np.nan)
    eps = np.full((nw, p, q, nf), np.inf)
    mult = np.full((nw, p, nf), np.nan)
    n_avg = []
    collinear = np.zeros(q)
    for k, tw in enumerate(windows_s):
        length = int(round(tw / dt))
        use = f >= K_MIN / (length * dt)
        if not use.any():
            n_avg.append(0.0)
            continue
        G, n_eff = _spectra(series, dt, length, overlap, f[use])
        n_avg.append(float(n_eff))
        if G is None or n_eff - q + 1 < MIN_DOF:
            continue
        h_k, part_k, eps_k, ord_k, mult_k, col_k = _conditioned(G, q, n_eff)
        collinear = np.maximum(collinear, np.nanmedian(col_k, axis=1))
        hs[k][..., use], part[k][..., use] = h_k, part_k
        eps[k][..., use], ordn[k][..., use] = eps_k, ord_k
        mult[k][:, use] = mult_k
    ok = np.isfinite(eps) & (eps > 0) & np.isfinite(hs.real)
    wgt = np.where(ok, 1.0 / np.where(ok, eps, 1.0) ** 2, 0.0)
    tot = wgt.sum(axis=0)
    with np.errstate(all="ignore"):
        share = np.where(tot > 0, wgt / tot, 0.0)
        h = np.where(tot > 0, np.nansum(share * np.nan_to_num(hs), axis=0), np.nan)
        coh = np.where(tot > 0, np.sum(share * np.nan_to_num(part), axis=0), np.nan)
        err = np.where(tot > 0, np.sum(share * np.where(ok, eps, 0.0), axis=0), np.inf)
        och = np.where(tot > 0, np.sum(share * np.nan_to_num(ordn), axis=0), np.nan)
        dev = np.abs(np.nan_to_num(hs) - h) ** 2
        spread = np.sqrt(np.sum(share * dev, axis=0) / 2) / np.abs(h)
        ws = share.mean(axis=2)                                    # (nw, p, nf)
        mc = np.where(ws.sum(axis=0) > 0, np.sum(ws * np.nan_to_num(mult), axis=0),
                      np.nan)
    notes = [f"input {c} is nearly a linear function of the other inputs (median "
             f"coherence {collinear[j]:.3f} with them): its conditioned responses are "
             "ill-determined; leave it or them out" for j, c in enumerate(inputs)
             if q > 1 and collinear[j] > COLLINEAR]
    low = ~np.any(tot > 0, axis=(0, 1))
    if low.any():
        notes.append(f"{int(low.sum())} of {nf} frequencies ({f[low].min():.3g}-"
                     f"{f[low].max():.3g} Hz) have no window with enough averages for "
                     f"{q} input(s): the records are too short there")
    return FrequencyResponse(
        inputs=inputs, outputs=outputs, frequency_hz=readonly(f), h=readonly(h, complex),
        coherence=readonly(coh), random_error=readonly(err), bias_error=readonly(spread),
        multiple_coherence=readonly(mc),
        ordinary_coherence=readonly(och), windows_s=windows_s,
        n_averages=tuple(n_avg), overlap=float(overlap), band_hz=(f1, f2), dt=dt,
        sources=tuple(sources), window_weight=readonly(share),
        notes=tuple(notes))


# -- model against measurement: Tischler's cost ---------------------------------------
#: Tischler's weights: magnitude [1/dB^2] and phase [1/deg^2] (1 dB ~ 7.57 deg).
W_GAIN, W_PHASE = 1.0, 0.01745
#: Guideline bands of ``J`` for one response pair: acceptable, good.
J_ACCEPTABLE, J_GOOD = 100.0, 50.0


def tischler_cost(fr: FrequencyResponse, model_h, output: str, input: str,
                  threshold: float = COHERENCE_OK) -> float:
    """Tischler's cost of a model response against a measured one (Tischler and
    Remple, *Aircraft and Rotorcraft System Identification*, 2nd ed., Eq. 10.18):
    ``J = 20/n sum W_gamma [W_g (|T_c| - |T|)^2 + W_p (angle T_c - angle T)^2]``,
    magnitudes in dB, phases in deg, over the ``n`` points with coherence ``>=
    threshold``; ``W_gamma = (1.58 (1 - exp(-gamma^2)))^2``.  ``J <= 100``: the model
    is acceptable for the pair, ``<= 50`` good.  ``model_h`` shaped like ``fr.h``.
    NaN when no point is coherent."""
    o, i = fr.index(output, input)
    v = fr.valid(threshold)[o, i]
    if not v.any():
        return float("nan")
    hm, h = np.asarray(model_h)[o, i][v], fr.h[o, i][v]
    g2 = fr.coherence[o, i][v]
    wg = (1.58 * (1 - np.exp(-g2))) ** 2
    dmag = 20 * np.log10(np.abs(hm) / np.abs(h))
    dph = np.degrees(np.angle(hm / h))                  # the wrapped difference
    return float(20.0 / v.sum() * np.sum(wg * (W_GAIN * dmag ** 2 + W_PHASE * dph ** 2)))



__all__ = ["FrequencyResponse", "frequency_response", "response_of_series", "effective_averages",
           "default_windows", "moving_inputs", "tischler_cost", "COHERENCE_OK",
           "DEFAULT_FRF_BAND"]
