"""Where a model fails on a record: residual spectra, structure across frequency,
correlation with the inputs, implausible or poorly determined estimates
(``workflow.md`` step 2).

Everything works from the residual of the frequency-domain fit itself (measured
minus predicted flap transform over the band, end effects eliminated, with the
record's intersample behaviour), so the diagnosis judges exactly what the fit
minimised, on the same frequencies:

* **Level.**  Each bin's residual power over the sensor-noise floor.  The floor is
  measured from the record, well above the rotor's response (from
  ``max(5 f2, 5 Hz)`` to 0.8 Nyquist, where the model predicts essentially
  nothing; the numbers are :class:`~inflowsim.diagnose.rule.Rule`'s), on the same residual (the fitted model and end states) at those
  frequencies; that assumes white sensor noise.  The assumption is checked: the
  noise in the band, estimated without a model (:mod:`inflowsim.diagnose.lpm`), at
  three times that floor or more is reported as coloured.  Coloured noise lies above
  the floor in the band; the structure tests below tell it from model error.  For white noise each
  bin's ratio is exponential with mean 1, so ``2 sum ratio ~ chi2(2 nf)``.
* **Structure.**  Model error is smooth in frequency (a transfer function error
  times the input spectrum), noise is not: a white or *coloured* noise gives
  independent bins.  The correlation of the residual with itself across ``j``
  neighbouring bins, ``rho_j``, is tested like Ljung-Box in the frequency index:
  ``Q = 2 nf sum_{j<=L} |rho_j|^2 ~ chi2(2 L)`` for independent bins.
* **Input dependence.**  The residual regressed on the inputs' transforms over
  the band, an F test (:func:`input_regression`).

A residual well above the floor that is not both smooth across frequency and
correlated with an input is reported as coloured sensor noise, not as a model
failure: the level test alone cannot tell the two apart.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.special import digamma

from ..data.record import FLAP_COLUMNS, find_trim, model_inputs, perturbations
from ..model.build import build_model
from ..identify.transform import DEFAULT_BAND
from .lpm import in_band_noise
from .rule import DEFAULT_RULE, Rule
from .tails import chi2_sf, f_sf
from ..model.params import SPECS
from ..simulate.replay import replay


@dataclass(frozen=True)
class Failure:
    """One finding: ``kind`` is ``spectrum``, ``whiteness``, ``input-correlation``,
    ``coloured-noise``, ``implausible``, ``undetermined``, ``correlated``,
    ``unexplained`` or ``estimation``."""

    kind: str
    subject: str
    message: str
    detail: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {"kind": self.kind, "subject": self.subject, "message": self.message,
                **self.detail}


@dataclass(frozen=True, eq=False)
class ResidualAnalysis:
    """A fit's residual over the band against the noise floor, per flap channel.

    ``measured``, ``predicted`` ``(3, nf)`` flap transforms at ``f_hz``; ``floor``
    ``(3, nf)`` noise power per bin; ``ratio`` ``(3, nf)`` residual power over it;
    ``U`` ``(nf, m)`` the inputs' transforms (``inputs``); ``residual`` ``(N, 3)``
    the time-domain residual of the replay from the fitted initial state
    (replayed when asked for: the diagnosis itself works in the band).
    """

    f_hz: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    floor: np.ndarray
    ratio: np.ndarray
    replay_of: "TimeResidual" = field(repr=False)
    floor_band_hz: tuple
    inputs: tuple = ()
    U: np.ndarray | None = None
    hold: str = "continuous"
    #: per channel, the noise in the band estimated without a model over the
    #: floor (``()`` where it could not be estimated); far above 1: coloured noise
    in_band_over_floor: tuple = ()

    @property
    def residual(self) -> np.ndarray:
        """Measured minus replayed flap in time ``(N, 3)`` [rad]."""
        return self.replay_of()

    @property
    def whitened(self) -> np.ndarray:
        """The residual over the square root of the floor, ``(3, nf)``."""
        return self.error / np.sqrt(self.floor)

    @property
    def error(self) -> np.ndarray:
        """``measured - predicted`` ``(3, nf)``."""
        return self.measured - self.predicted

    @property
    def excess(self) -> np.ndarray:
        """Mean in-band residual power over the floor, per channel."""
        return self.ratio.mean(axis=1)


@dataclass(frozen=True, eq=False)
class TimeResidual:
    """The record replayed through the model from ``x0`` (its own hold), minus
    the measured flap: ``(N, 3)`` when called.  Kept as the recipe, not the
    array, so a long record's analyses do not each hold a full-length copy."""

    record: object
    model: object
    trim: object
    hold: str
    x0: np.ndarray | None

    def __call__(self) -> np.ndarray:
        u = model_inputs(self.record, self.model, self.trim)
        with np.errstate(all="ignore"):  # an unstable fitted model replays unbounded
            y = replay(self.model, u, self.record.dt, self.hold, self.x0)[:, :3]
        return perturbations(self.record, self.trim, FLAP_COLUMNS) - y


def floor_band(record, band_hz, rule: Rule = DEFAULT_RULE):
    """The band [Hz] where the noise floor is measured: ``max(5 f2, 5 Hz)`` to 0.8
    Nyquist, or ``None`` where it holds fewer than 20 transform bins (the numbers:
    ``rule.floor_over_band``, ``floor_min_hz``, ``nyquist_share``,
    ``floor_min_bins``)."""
    lo = max(rule.floor_over_band * band_hz[1], rule.floor_min_hz)
    hi = rule.nyquist_share * 0.5 / record.dt
    return (lo, hi) if (hi - lo) * record.duration >= rule.floor_min_bins else None


def noise_floor(record, model, band_hz, hold, f_band, in_band=None, check_colour=True,
                rule: Rule = DEFAULT_RULE):
    """Sensor-noise power per transform bin ``(3, nf)`` at the band's frequencies
    ``f_band``, the band it was measured in [Hz], and per channel the noise in the
    band estimated without a model (:mod:`inflowsim.diagnose.lpm`) over that floor
    (empty where it could not be estimated or ``check_colour`` is false).

    The residual of ``model`` (the frequency model, valid whether or not the
    fitted model is stable) over :func:`floor_band`, where the rotor barely
    answers, with its own end states there (those of the band fit are poorly
    determined in directions that grow at high frequency).  Its level is the
    median over ``rule.floor_subbands`` sub-bands (rotor harmonics in a few of
    them do not raise it) of each sub-band's median bin power over ``ln 2``,
    carried into the band as white noise: the assumption of a white sensor noise,
    stated in every report (and checked: a channel whose in-band noise is
    ``rule.coloured`` times the floor or more is reported as coloured,
    :func:`spectrum_failures`).  Without a floor band, the quietest
    quartile of the in-band residual ``in_band`` ``(nf, 3)``.
    """
    from ..identify.freqmodel import flap_response
    from ..identify.transform import record_spectra
    fb = floor_band(record, band_hz, rule)
    nf = np.size(f_band)
    if fb is None:
        p = np.abs(np.asarray(in_band)) ** 2
        floor = np.quantile(p, 0.25, axis=0) / np.log(4 / 3)
        floor = np.repeat(np.maximum(floor, np.finfo(float).tiny)[:, None], nf, axis=1)
        return floor, (float(band_hz[0]), float(band_hz[1])), ()
    # made for this floor alone (a diagnosis measures one: its candidates are held
    # against the base's, :func:`residual_analysis`)
    sp = record_spectra(record, model.inputs, fb, hold=hold, require_motion=False,
                        keep=False)
    if sp.f_hz.size <= STREAM_BINS:
        y_u, y_nu, _ = flap_response(model, sp)
        e = sp.Z - y_u
        coef = _end_states(y_nu, e)
        p = np.abs(e - y_nu @ coef) ** 2
    else:
        p = _floor_power_streamed(model, sp)
    chunks = np.array_split(np.arange(len(p)), rule.floor_subbands)
    level = np.median([np.median(p[c], axis=0) for c in chunks], axis=0) / np.log(2)
    floor = np.repeat(np.maximum(level, np.finfo(float).tiny)[:, None], nf, axis=1)
    inside = in_band_noise(record, model.inputs, band_hz, hold, f_band, rule) \
        if check_colour else None
    ratio = () if inside is None else tuple(
        float(inside[c].mean() / floor[c].mean()) for c in range(3))
    return floor, (float(fb[0]), float(fb[1])), ratio


#: Floor-band bins above which the end states are solved block by block (a
#: 2-hour record's floor band holds 150 000 bins).
STREAM_BINS = 16384


def _qr_update(R, c, y_nu, e):
    """The QR factor ``R`` and rotated right side ``c`` of :func:`_end_states`'s
    least squares with the bins of one more block ``y_nu`` ``(nb, 3, q)``,
    ``e`` ``(nb, 3)`` appended."""
    a = y_nu.reshape(-1, y_nu.shape[2])
    b = e.ravel()
    Q, R = np.linalg.qr(np.vstack([R, a.real, a.imag]))
    return R, Q.T @ np.concatenate([c, b.real, b.imag])


def _floor_power_streamed(model, sp):
    """``|e - y_nu coef|^2`` ``(nf, 3)`` of :func:`noise_floor` for a floor band
    of more than :data:`STREAM_BINS` bins, block by block: the end-state responses
    ``y_nu`` (86 MB for a 2-hour record's floor band) are never held whole, each
    block's computed once for the least squares and again for its residual.  The
    blocks are :func:`~inflowsim.identify.freqmodel.flap_response`'s own and
    :func:`_end_states`'s, so every number is the one of the whole arrays."""
    from dataclasses import replace
    from ..identify.freqmodel import flap_response
    nf = sp.f_hz.size
    blocks = [slice(i, min(i + STREAM_BINS, nf)) for i in range(0, nf, STREAM_BINS)]

    def part(blk):
        return flap_response(model, replace(sp, f_hz=sp.f_hz[blk], U=sp.U[blk],
                                            Z=sp.Z[blk]))
    e = np.empty(sp.Z.shape, dtype=complex)
    R, c = None, np.zeros(0)
    for blk in blocks:
        y_u, y_nu, _ = part(blk)
        e[blk] = sp.Z[blk] - y_u
        if R is None:
            R = np.zeros((0, y_nu.shape[2]))
        R, c = _qr_update(R, c, y_nu, e[blk])
        del y_u, y_nu
    coef, *_ = np.linalg.lstsq(R, c, rcond=None)
    p = np.empty(e.shape)
    for blk in blocks:
        _, y_nu, _ = part(blk)
        p[blk] = np.abs(e[blk] - y_nu @ coef) ** 2
        del y_nu
    return p


def _end_states(y_nu, e):
    """Real ``coef`` minimising ``|e - y_nu coef|`` over every bin and channel:
    ``lstsq`` on the stacked real system, or for a long record the same least
    squares by a QR factor updated block by block (no full stacked copy)."""
    nf, _, q = y_nu.shape
    if nf <= STREAM_BINS:
        a = y_nu.reshape(-1, q)
        coef, *_ = np.linalg.lstsq(np.vstack([a.real, a.imag]),
                                   np.concatenate([e.ravel().real, e.ravel().imag]),
                                   rcond=None)
        return coef
    R, c = np.zeros((0, q)), np.zeros(0)
    for i in range(0, nf, STREAM_BINS):
        R, c = _qr_update(R, c, y_nu[i:i + STREAM_BINS], e[i:i + STREAM_BINS])
    coef, *_ = np.linalg.lstsq(R, c, rcond=None)
    return coef


def residual_analysis(record, model, band_hz=DEFAULT_BAND, trim=None, hold=None,
                      fit=None, check_colour=True,
                      rule: Rule = DEFAULT_RULE, floor_of=None) -> ResidualAnalysis:
    """The residual of ``model`` on ``record`` over the band, against the floor.

    ``fit``: the record's :class:`~inflowsim.identify.RecordFit` of an
    identification with this model; its residual and initial state are used.
    Without it the model is evaluated on the record (:func:`inflowsim.identify.evaluate`:
    the same residual, end effects eliminated, for given parameters).
    ``check_colour``: estimate the noise in the band (``in_band_over_floor``); it
    does not depend on the model, so the candidate tests skip it.  ``rule``: the
    floor band's numbers (:class:`~inflowsim.diagnose.rule.Rule`).  ``floor_of``:
    another fit's analysis of this record over the same frequencies, whose noise
    floor, floor band and in-band noise are taken instead of measured (and its
    input transforms, for the same inputs and hold): line 4's measure
    (:func:`.excess.judge`) holds every candidate against the base fit's floors,
    so a candidate's own floor, a second pass over a long record's floor band,
    would go unused.
    """
    from ..identify import evaluate
    from ..identify.transform import dft, transform_weights
    record.check_band(band_hz)
    trim = trim or find_trim(record)
    hold = record.hold_or(hold) if fit is None else fit.hold
    u = model_inputs(record, model, trim)
    if fit is None:
        ev = evaluate(record, model.structure, dict(model.parameters), band_hz, hold=hold)
        f, Z, Y, x0 = ev.f_hz[0], ev.Z[0], ev.Y[0], None
    else:
        f, Z, Y, x0 = fit.f_hz, fit.Z, fit.Y, fit.x0
    e_t = TimeResidual(record, model, trim, hold, x0)
    given = floor_of is not None and np.array_equal(floor_of.f_hz, f)
    if given:
        floor, fb = floor_of.floor, floor_of.floor_band_hz
        colour = floor_of.in_band_over_floor if check_colour else ()
    else:
        floor, fb, colour = noise_floor(record, model, band_hz, hold, f, Z - Y,
                                        check_colour, rule)
    ratio = (np.abs(Z - Y) ** 2).T / floor
    if given and floor_of.U is not None and floor_of.inputs == tuple(model.inputs) \
            and floor_of.hold == hold:
        U = floor_of.U
    else:
        on_grid = np.allclose(f * len(record) * record.dt,
                              np.rint(f * len(record) * record.dt), atol=1e-6)
        U = dft(u, record.dt, f, on_grid, transform_weights(len(record), hold))
    return ResidualAnalysis(f, Z.T, Y.T, floor, ratio, e_t, fb, tuple(model.inputs), U,
                            hold, colour)


def _as_list(records):
    return list(records) if isinstance(records, (list, tuple)) else [records]


def analyses_of(records, fit, band_hz, check_colour=True, rule: Rule = DEFAULT_RULE,
                floors_of=None):
    """The fit's residual analysis on each record (its own residual and initial
    state, each record's own flight condition and trim).

    Parameters
    ----------
    records : Record, path or list of them
        The flight-test records (each with its own flight condition and trim).
    fit : FitResult
        The fitted structure.
    band_hz : (float, float)
        Analysis band [Hz].
    check_colour : bool
        Also test the residual's whiteness (coloured noise) [-].
    rule : Rule
        The settings: the floor band's numbers
        (:class:`~inflowsim.diagnose.rule.Rule`).
    floors_of : list of ResidualAnalysis, optional
        Another fit's analyses of the same records over the same band, whose noise
        floors are taken instead of measured (``residual_analysis``'s
        ``floor_of``).
    """
    recs = _as_list(records)
    given = [None] * len(recs) if floors_of is None else list(floors_of)
    out = []
    for rec, data, ra in zip(recs, fit.data, given):
        m = build_model(fit.structure, fit.parameters, rec.constants)
        out.append(residual_analysis(rec, m, band_hz, fit=data, check_colour=check_colour,
                                     rule=rule, floor_of=ra))
    return out


def _segments(f, mask):
    out, start = [], None
    for i, m in enumerate(mask):
        if m and start is None:
            start = i
        if (not m or i == len(mask) - 1) and start is not None:
            end = i if m else i - 1
            out.append((start, end))
            start = None
    return [(float(f[a]), float(f[b]), a, b) for a, b in out]


def frequency_whiteness(e: np.ndarray, max_lag: int = DEFAULT_RULE.max_lag):
    """``(Q, p, rho_1)`` of one channel's complex residual across the band's bins:
    ``Q = 2 nf sum_{j=1..L} |rho_j|^2``, chi-square with ``2 L`` degrees of freedom
    for independent bins (white or coloured noise); model error, smooth in
    frequency, makes neighbouring bins alike."""
    e = np.asarray(e, dtype=complex)
    nf = e.size
    L = int(min(max_lag, max(1, nf // 4)))
    den = float(np.sum(np.abs(e) ** 2))
    if den == 0.0 or nf < 4:
        return 0.0, 1.0, 0.0
    rho = np.array([np.sum(e[j:] * np.conj(e[:nf - j])) / den for j in range(1, L + 1)])
    q = float(2 * nf * np.sum(np.abs(rho) ** 2 * nf / (nf - np.arange(1, L + 1))))
    return q, float(chi2_sf(q, 2 * L)), float(np.abs(rho[0]))


def structure_statistic(ra: ResidualAnalysis, floors=None,
                        max_lag: int = DEFAULT_RULE.max_lag) -> float:
    """How much structure across frequency the residual keeps, in units of the
    noise: ``sum_c 2 nf sum_j |gamma_j|^2 nf / (nf - j)`` with ``gamma_j`` the
    autocovariance over ``j`` bins of the residual divided by the root of the
    noise floor (``floors`` ``(3, nf)``: default the analysis's own).  Unlike
    :func:`frequency_whiteness` it is not normalised by the residual's own power,
    so removing model error lowers it; for noise alone it is about ``2 L`` per
    channel.  Smaller is whiter."""
    fl = ra.floor if floors is None else np.asarray(floors)
    total = 0.0
    for c in range(3):
        w = ra.error[c] / np.sqrt(fl[c])
        nf = w.size
        L = int(min(max_lag, max(1, nf // 4)))
        g = np.array([np.sum(w[j:] * np.conj(w[:nf - j])) / nf for j in range(1, L + 1)])
        total += float(2 * nf * np.sum(np.abs(g) ** 2 * nf / (nf - np.arange(1, L + 1))))
    return total


def floor_deviance(ra: ResidualAnalysis, floors=None) -> float:
    """How far the residual spectrum is from white noise at the floor:
    ``sum_c sum_k (r - 1 - ln r)``, ``r = |e_k|^2 / floor`` (``floors`` ``(3, nf)``,
    default the analysis's own).  Zero only for a residual exactly at the floor;
    for white noise at the floor its mean is ``0.5772`` a bin (Euler's constant),
    and it grows with any excess (model error) and any deficit (a fit of the
    noise).  The rule (:mod:`inflowsim.diagnose.rule`) asks a candidate to lower it."""
    fl = ra.floor if floors is None else np.asarray(floors)
    r = np.maximum(np.abs(ra.error) ** 2 / fl, 1e-300)
    return float(np.sum(r - 1.0 - np.log(r)))


#: Mean of ``r - 1 - ln r`` for a bin of white noise at its floor (Euler's constant).
WHITE_DEVIANCE = 0.5772156649015329


def level_deviance(ra: ResidualAnalysis, floors=None) -> float:
    """How far each channel's residual *level* is from the floor:
    ``sum_c nf (m_c - 1 - ln m_c)``, ``m_c`` the channel's mean power over the
    floor in the band.  Twice it is the likelihood-ratio statistic of "white noise
    at the floor" against "white noise at its own level" (``chi2`` with one degree
    of freedom a channel for noise at the floor; mean :func:`white_level_deviance`).
    It is the part of :func:`floor_deviance` that sees a level: the rest,
    ``-sum ln(r / m)``, is how unevenly the power falls on the bins, which for
    noise scatters by ``sqrt(nf pi^2 / 6)`` and hides a model error spread over
    the band."""
    fl = ra.floor if floors is None else np.asarray(floors)
    m = np.maximum(np.mean(np.abs(ra.error) ** 2 / fl, axis=1), 1e-300)
    return float(ra.error.shape[1] * np.sum(m - 1.0 - np.log(m)))


def white_level_deviance(nf: int, channels: int = 3) -> float:
    """Mean of :func:`level_deviance` for white noise at the floor over ``nf``
    bins: ``nf (ln nf - psi(nf))`` a channel (``m`` is Gamma(nf, 1/nf)), about 1/2."""
    return float(channels * nf * (np.log(nf) - digamma(nf)))


def level_p_value(ra: ResidualAnalysis, c: int) -> float:
    """p-value of channel ``c``'s in-band residual power against the floor
    (``2 sum r ~ chi2(2 nf)`` for noise at the floor)."""
    r = ra.ratio[c]
    return float(chi2_sf(2 * r.sum(), 2 * r.size))


def input_regression(ra: ResidualAnalysis, c: int, rank_tol: float = 1e-6):
    """Does channel ``c``'s residual depend on the inputs over the band?

    The residual (over the root of the floor) is regressed on the inputs'
    transforms, one complex gain each (the numerically independent ones: rank
    ``r``); ``F = (|P e|^2 / r) / (|e - P e|^2 / (nf - r))`` is ``F(2r, 2(nf - r))``
    for a residual independent of the inputs, whatever its colour.  Returns
    ``(F, p, r, best)``: ``best`` the input most correlated with it alone.
    """
    e = ra.error[c] / np.sqrt(ra.floor[c])
    nf = e.size
    if ra.U is None or not np.any(e):
        return 0.0, 1.0, 0, None
    U = ra.U / np.sqrt(ra.floor[c])[:, None]
    scale = np.abs(U).max(axis=0)
    keep = scale > 0
    if not keep.any():
        return 0.0, 1.0, 0, None
    U = U[:, keep] / scale[keep]
    names = [n for n, k in zip(ra.inputs, keep) if k]
    Q, s, _ = np.linalg.svd(U, full_matrices=False)
    r = int(np.sum(s > rank_tol * s[0]))
    if r == 0 or r >= nf:
        return 0.0, 1.0, r, None
    Q = Q[:, :r]
    pe = Q @ (Q.conj().T @ e)
    num = float(np.sum(np.abs(pe) ** 2)) / r
    den = float(np.sum(np.abs(e - pe) ** 2)) / (nf - r)
    F = num / den if den > 0 else np.inf
    corr = [abs(np.sum(e * np.conj(U[:, j]))) ** 2 / float(np.sum(np.abs(U[:, j]) ** 2))
            for j in range(U.shape[1])]
    return F, float(f_sf(F, 2 * r, 2 * (nf - r))), r, names[int(np.argmax(corr))]


def channel_structure(ra: ResidualAnalysis, c: int, alpha=None,
                      rule: Rule = DEFAULT_RULE) -> dict:
    """Whether channel ``c``'s residual is structured: smooth across frequency
    (:func:`frequency_whiteness`, ``rule.max_lag``) *and* dependent on the inputs
    (:func:`input_regression`), each at ``alpha`` (default ``rule.alpha``).
    Coloured noise can pass the first (leakage makes neighbouring bins alike) but
    not the second; model error fails both."""
    alpha = rule.alpha if alpha is None else alpha
    q, p, rho1 = frequency_whiteness(ra.whitened[c], rule.max_lag)
    F, p_in, r, best = input_regression(ra, c)
    return {"q": q, "p_value": p, "lag1": rho1, "input": best, "input_f": F,
            "input_rank": r, "input_p_value": p_in,
            "structured": bool(p < alpha and p_in < alpha)}


def spectrum_failures(ra: ResidualAnalysis, alpha=None,
                      rule: Rule = DEFAULT_RULE) -> list[Failure]:
    """Per channel: is the in-band residual above the noise floor (at ``alpha``,
    default ``rule.alpha``), where, and is the disagreement mostly magnitude or
    phase?  Unstructured excess, and in-band noise ``rule.coloured`` times the
    floor or more, are reported as coloured noise."""
    alpha = rule.alpha if alpha is None else alpha
    out = []
    thr = -np.log(alpha)
    for c, k in enumerate(ra.in_band_over_floor):
        if k < rule.coloured:
            continue
        ch = FLAP_COLUMNS[c]
        out.append(Failure(
            "coloured-noise", ch,
            f"{ch}: sensor noise in the band is about {k:.3g}x the floor measured above "
            f"it ({ra.floor_band_hz[0]:.3g}-{ra.floor_band_hz[1]:.3g} Hz; local "
            "polynomial estimate): coloured. Levels over the floor overstate the model "
            "error there; the candidate tests measure the residual's input-correlated "
            "excess instead",
            {"in_band_over_floor": k}))
    for c, ch in enumerate(FLAP_COLUMNS):
        r = ra.ratio[c]
        nb = r.size
        p = level_p_value(ra, c)
        if p >= alpha:
            continue
        excess = float(r.mean())
        st = channel_structure(ra, c, alpha, rule)
        if not st["structured"]:
            out.append(Failure(
                "coloured-noise", ch,
                f"{ch}: in-band residual {excess:.3g}x the (white) noise floor, but not "
                f"recognisably model error (structure across frequency p = "
                f"{st['p_value']:.2g}, dependence on the inputs p = "
                f"{st['input_p_value']:.2g}): coloured sensor noise, or an error no "
                "input explains linearly",
                {"p_value": p, "excess_power": excess, "structure_p_value": st["p_value"]}))
            continue
        Z, Y = ra.measured[c], ra.predicted[c]
        mag_db = 20 * np.log10(np.maximum(np.abs(Z), 1e-300) / np.maximum(np.abs(Y), 1e-300))
        ph_deg = np.degrees(np.angle(Z * np.conj(Y)))
        mag_part = (np.abs(Z) - np.abs(Y)) ** 2
        ph_part = 2 * np.abs(Z) * np.abs(Y) * (1 - np.cos(np.radians(ph_deg)))
        flagged = r > thr
        segs = _segments(ra.f_hz, flagged) or [(float(ra.f_hz[0]), float(ra.f_hz[-1]), 0, nb - 1)]
        parts = []
        for f1, f2, a, b in segs:
            sl = slice(a, b + 1)
            kind = "phase" if ph_part[sl].sum() > mag_part[sl].sum() else "magnitude"
            # rms, not mean: a signed phase error that leads and lags in turn
            # averages to "-0 deg"
            parts.append({"f1_hz": f1, "f2_hz": f2, "mostly": kind,
                          "n_frequencies": b - a + 1,
                          "magnitude_error_db": float(np.mean(mag_db[sl])),
                          "phase_error_deg": float(np.mean(ph_deg[sl])),
                          "magnitude_rms_db": float(np.sqrt(np.mean(mag_db[sl] ** 2))),
                          "phase_rms_deg": float(np.sqrt(np.mean(ph_deg[sl] ** 2)))})
        where = ", ".join(
            (f"{s['f1_hz']:.3g} Hz" if s["n_frequencies"] == 1 else
             f"{s['f1_hz']:.3g}-{s['f2_hz']:.3g} Hz") +
            f" (mostly {s['mostly']}: {s['magnitude_rms_db']:.1f} dB rms, "
            f"{s['phase_rms_deg']:.1f} deg rms)" for s in parts)
        out.append(Failure("spectrum", ch,
                           f"{ch}: model and measurement part at {where}; in-band residual "
                           f"power {excess:.3g}x the noise floor",
                           {"p_value": p, "excess_power": excess, "segments": parts,
                            "peak_hz": float(ra.f_hz[int(np.argmax(r))]),
                            "peak_excess": float(r.max())}))
    return out


def residual_tests(ra: ResidualAnalysis, record=None, model=None, alpha=None,
                   rule: Rule = DEFAULT_RULE) -> list[Failure]:
    """Structure left in each channel's residual over the band: correlation across
    frequency (``whiteness``) and with the inputs (``input-correlation``), at
    ``alpha`` (default ``rule.alpha``).  ``record`` and ``model`` are accepted for
    compatibility and not needed."""
    alpha = rule.alpha if alpha is None else alpha
    out = []
    for c, ch in enumerate(FLAP_COLUMNS):
        st = channel_structure(ra, c, alpha, rule)
        if st["p_value"] < alpha:
            out.append(Failure("whiteness", ch,
                               f"{ch}: residual is structured across frequency (Q = "
                               f"{st['q']:.1f} over {min(rule.max_lag, ra.f_hz.size // 4)} bin "
                               f"lags, p = {st['p_value']:.2g}, neighbour correlation "
                               f"{st['lag1']:.2f}): a smooth model error left in the band",
                               {"q": st["q"], "p_value": st["p_value"], "lag1": st["lag1"]}))
        if st["input_p_value"] < alpha:
            out.append(Failure("input-correlation", f"{ch}~{st['input']}",
                               f"{ch}: residual depends on the inputs over the band (F = "
                               f"{st['input_f']:.3g} on {st['input_rank']} inputs, p = "
                               f"{st['input_p_value']:.2g}; most on {st['input']}): the "
                               f"model misses part of the response to them",
                               {"input": st["input"], "f": st["input_f"],
                                "p_value": st["input_p_value"]}))
    return out


def above_floor(analyses, alpha=None, rule: Rule = DEFAULT_RULE) -> list:
    """``(record index, channel index, level p-value, structure)`` of every channel,
    over the records, whose in-band residual is above the floor (level test at
    ``alpha``, default ``rule.alpha``), ``structure`` its :func:`channel_structure`:
    measured once, split by it into the structured excess (:func:`excess_channels`)
    and the rest (:func:`inflowsim.diagnose.verdict.uncorrelated_excess`)."""
    alpha = rule.alpha if alpha is None else alpha
    out = []
    for i, ra in enumerate(analyses):
        for c in range(len(FLAP_COLUMNS)):
            p = level_p_value(ra, c)
            if p < alpha:
                out.append((i, c, p, channel_structure(ra, c, alpha, rule)))
    return out


def excess_channels(analyses, alpha=None, rule: Rule = DEFAULT_RULE,
                    above=None) -> list:
    """``(channel, peak_hz, peak ratio, mean ratio)`` of every channel, over the
    records, whose residual keeps excess over the floor (level test at ``alpha``,
    default ``rule.alpha``) that is structured (:func:`channel_structure`): the
    verdict's ``where`` and the ``unexplained`` findings both come from here.
    ``above``: :func:`above_floor` of the same, where already measured."""
    if above is None:
        above = above_floor(analyses, alpha, rule)
    out = []
    for i, c, _, st in above:
        if not st["structured"]:
            continue
        ra, r = analyses[i], analyses[i].ratio[c]
        k = int(np.argmax(r))
        out.append((FLAP_COLUMNS[c], float(ra.f_hz[k]), float(r[k]), float(r.mean())))
    return out


def unexplained(analyses, alpha=None, rule: Rule = DEFAULT_RULE) -> list[Failure]:
    """The structured excess no candidate explains (:func:`excess_channels`), in one
    line per channel: ``unexplained residual: X times the noise floor at F Hz in
    beta1s``."""
    return [Failure(
        "unexplained", ch,
        f"unexplained residual: {mean:.3g} times the noise floor over the band, "
        f"{peak:.3g} at {f:.3g} Hz in {ch}; outside the candidate catalogue (no "
        "structure of candidate effects is accepted)",
        {"excess_power": mean, "peak_hz": f, "peak_excess": peak})
        for ch, f, peak, mean in excess_channels(analyses, alpha, rule)]


def parameter_failures(parameters, sigma, correlation=None, names=None, omega=None,
                       rel_sigma=0.5, corr_limit=0.95, hub=None) -> list[Failure]:
    """Estimates outside their physically plausible range (``ParameterSpec.plausible``,
    for the rotor's ``hub`` where the range depends on it; time constants judged in
    seconds) by more than 1 sigma, poorly determined (``sigma/|estimate| >
    rel_sigma``) or undetermined (no bound), or strongly correlated pairs."""
    out = []
    for name, est in parameters.items():
        s = sigma.get(name)
        spec = SPECS.get(name)
        rng = spec.plausible_for(hub) if spec is not None else None
        if rng is not None and (omega or not spec.plausible_seconds):
            # the parameter's own facts (inflowsim.model.params / each effect)
            lo, hi, why = rng
            scale = 1.0 / omega if spec.plausible_seconds else 1.0
            v, sv = est * scale, (s or 0.0) * scale
            if v - sv > hi or v + sv < lo:
                unit = " s" if scale != 1.0 else ""
                out.append(Failure("implausible", name,
                                   f"{name} = {v:.4g}{unit} (1-sigma {sv:.2g}) is outside "
                                   f"[{lo:g}, {hi:g}]{unit}: {why}; the structure is "
                                   "probably missing an effect that this parameter absorbs",
                                   {"estimate": est, "sigma": s, "range": [lo, hi]}))
        if name in sigma and s is None:
            out.append(Failure("undetermined", name,
                               f"{name} = {est:.4g} is not determined by the data (no "
                               "bound): fix it at a theory value, tie it, widen the band "
                               "or add excitation", {"estimate": est, "sigma": None}))
        elif s is not None and est != 0 and s / abs(est) > rel_sigma:
            out.append(Failure("undetermined", name,
                               f"{name} = {est:.4g} +- {s:.2g} ({100 * s / abs(est):.0f} %) "
                               "is poorly determined: fix it at a theory value, tie it, "
                               "widen the band or add excitation",
                               {"estimate": est, "sigma": s}))
    if correlation is not None and names is not None:
        c = np.asarray(correlation)
        for i in range(len(names)):
            for j in range(i + 1, len(names)):
                if abs(c[i, j]) > corr_limit:
                    out.append(Failure("correlated", f"{names[i]}~{names[j]}",
                                       f"{names[i]} and {names[j]} are correlated "
                                       f"({c[i, j]:+.3f}): the data cannot separate them; "
                                       "fix or tie one of them",
                                       {"correlation": float(c[i, j])}))
    return out


__all__ = ["Failure", "ResidualAnalysis", "residual_analysis", "analyses_of", "spectrum_failures",
           "residual_tests", "parameter_failures", "unexplained", "noise_floor",
           "frequency_whiteness", "structure_statistic", "channel_structure",
           "floor_deviance", "level_deviance", "white_level_deviance", "level_p_value",
           "WHITE_DEVIANCE", "input_regression", "above_floor", "excess_channels"]
