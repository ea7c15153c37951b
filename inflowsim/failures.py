"""Where a model fails on a record: residual spectra, whiteness, input correlation,
implausible or poorly determined estimates (``workflow.md`` step 2).

The residual is measured minus predicted flap (perturbations about trim), the
prediction being the exact ZOH replay of the record's inputs.  Its periodogram is
compared, bin by bin over the analysis band, with the sensor-noise floor measured
from the same residual well above the rotor's response (where the model predicts
essentially nothing, so the residual there is noise).  For white noise each bin's
power over the floor is exponential with mean 1, so a bin is flagged where the
ratio exceeds ``-ln(alpha)``; a channel fails where the sum over the band is
significant (``2 sum ratio ~ chi2(2 n)``).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from .record import FLAP_COLUMNS, find_trim, model_inputs, perturbations
from .simulator import Simulator

DEFAULT_BAND = (0.2256, 1.58)
ALPHA = 1e-3

#: Plausible ranges from physics, with the reason shown to the user.  Time
#: constants in seconds (the paper judged tau0 = 0.59 s and tau_cs = 1.16 s
#: "rather larger than might be expected", and tau_cs = 0.78 s satisfactory).
PLAUSIBLE = {
    "lambda_beta2": (0.95, 1.2, "flap frequency squared of articulated or hingeless "
                                 "rotors lies near 1.0-1.2 (Puma theory 1.06)"),
    "n_beta": (0.5, 1.5, "inertia number gamma/8 for Lock numbers 4-12 (Puma theory 0.987)"),
    "tau": (0.0, 1.0, "an inflow time constant above 1 s is not physical for this rotor"),
    "tau0": (0.0, 0.3, "the mean inflow settles within a few rotor revolutions"),
    "tau_cs": (0.0, 1.0, "the cyclic inflow time constant should be below about 1 s"),
    "azimuth_bias": (-0.5, 0.5, "an azimuth offset over 30 deg points at a wiring or "
                                "sign error, not a bias"),
    "delay": (0.0, 0.1, "measurement-chain delays are tens of milliseconds"),
}
SECONDS = {"tau", "tau0", "tau_cs"}


@dataclass(frozen=True)
class Failure:
    """One finding: ``kind`` is ``spectrum``, ``whiteness``, ``input-correlation``,
    ``implausible``, ``undetermined`` or ``correlated``."""

    kind: str
    subject: str
    message: str
    detail: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {"kind": self.kind, "subject": self.subject, "message": self.message,
                **self.detail}


@dataclass(frozen=True)
class ResidualAnalysis:
    """Residual spectra over the band, noise floor and per-bin ratios per channel."""

    f_hz: np.ndarray
    measured: np.ndarray        # (3, nf) DFT of measured flap perturbation
    predicted: np.ndarray       # (3, nf)
    floor: np.ndarray           # (3,) noise power per bin
    ratio: np.ndarray           # (3, nf) |Z - Y|^2 / floor
    residual: np.ndarray        # (N, 3) time-domain residual
    floor_band_hz: tuple


def residual_analysis(record, model, band_hz=DEFAULT_BAND, trim=None) -> ResidualAnalysis:
    """Replay, residual and its spectrum against the measured noise floor."""
    record.check_band(band_hz)
    trim = trim or find_trim(record)
    u = model_inputs(record, model, trim)
    y = Simulator(model, record.dt).replay(u)[:, :3]
    z = perturbations(record, trim, FLAP_COLUMNS)
    e = z - y
    n = len(e)
    f = np.fft.rfftfreq(n, record.dt)
    Z, Y, E = (np.fft.rfft(a, axis=0).T for a in (z, y, e))
    k = np.flatnonzero((f >= band_hz[0] - 1e-9) & (f <= band_hz[1] + 1e-9))
    nyq = f[-1]
    lo = max(5.0 * band_hz[1], 5.0)
    hi = 0.8 * nyq
    hf = np.flatnonzero((f >= lo) & (f <= hi))
    if hf.size >= 20:
        floor = np.median(np.abs(E[:, hf]) ** 2, axis=1) / np.log(2)
        fb = (float(lo), float(hi))
    else:                       # no quiet high band: use the quietest in-band quartile
        p = np.abs(E[:, k]) ** 2
        floor = np.quantile(p, 0.25, axis=1) / np.log(4 / 3)
        fb = (float(band_hz[0]), float(band_hz[1]))
    floor = np.maximum(floor, np.finfo(float).tiny)
    ratio = np.abs(E[:, k]) ** 2 / floor[:, None]
    return ResidualAnalysis(f[k], Z[:, k], Y[:, k], floor, ratio, e, fb)


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


def spectrum_failures(ra: ResidualAnalysis, alpha=ALPHA) -> list[Failure]:
    """Per channel: is the in-band residual above the noise floor, where, and is
    the disagreement mostly magnitude or phase?"""
    out = []
    thr = -np.log(alpha)
    for c, ch in enumerate(FLAP_COLUMNS):
        r = ra.ratio[c]
        nb = r.size
        p = float(stats.chi2.sf(2 * r.sum(), 2 * nb))
        if p >= alpha:
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
            parts.append({"f1_hz": f1, "f2_hz": f2, "mostly": kind,
                          "magnitude_error_db": float(np.mean(mag_db[sl])),
                          "phase_error_deg": float(np.mean(ph_deg[sl]))})
        where = ", ".join(f"{s['f1_hz']:.3g}-{s['f2_hz']:.3g} Hz ({s['mostly']}: "
                          f"{s['magnitude_error_db']:+.1f} dB, {s['phase_error_deg']:+.0f} deg)"
                          for s in parts)
        excess = float(r.mean())
        out.append(Failure("spectrum", ch,
                           f"{ch}: model and measurement part at {where}; in-band residual "
                           f"power {excess:.3g}x the noise floor",
                           {"p_value": p, "excess_power": excess, "segments": parts}))
    return out


def residual_tests(ra: ResidualAnalysis, record, model, trim=None, max_lag=25,
                   alpha=ALPHA) -> list[Failure]:
    """Ljung-Box whiteness of each channel's residual and its cross-correlation
    with each excited input (lags -max_lag..max_lag; Bonferroni over lags).
    With a white residual each sample cross-correlation has variance ~1/N
    whatever the input's colour, so the bound holds for doublet inputs too."""
    trim = trim or find_trim(record)
    e = ra.residual
    n = len(e)
    out = []
    u = model_inputs(record, model, trim)
    zcrit = stats.norm.isf(alpha / (2 * (2 * max_lag + 1)))
    for c, ch in enumerate(FLAP_COLUMNS):
        x = e[:, c] - e[:, c].mean()
        den = float(x @ x)
        if den == 0:
            continue
        r = np.array([x[:-k] @ x[k:] / den for k in range(1, max_lag + 1)])
        q = n * (n + 2) * np.sum(r**2 / (n - np.arange(1, max_lag + 1)))
        p = float(stats.chi2.sf(q, max_lag))
        if p < alpha:
            out.append(Failure("whiteness", ch,
                               f"{ch}: residual is not white (Ljung-Box Q = {q:.1f} over "
                               f"{max_lag} lags, p = {p:.2g}): structure left in the error",
                               {"q": float(q), "p_value": p, "lag1": float(r[0])}))
        xs = x / np.sqrt(den)
        best = None
        for j, name in enumerate(model.inputs):
            v = u[:, j] - u[:, j].mean()
            dv = float(v @ v)
            if dv <= 1e-30:
                continue
            v = v / np.sqrt(dv)
            cc = np.correlate(xs, v, mode="full")[n - 1 - max_lag: n + max_lag]
            zmax = float(np.max(np.abs(cc)) * np.sqrt(n))
            if zmax > zcrit and (best is None or zmax > best[1]):
                best = (name, zmax, int(np.argmax(np.abs(cc))) - max_lag)
        if best is not None:       # inputs are correlated with each other: name the strongest
            name, zmax, lag = best
            out.append(Failure("input-correlation", f"{ch}~{name}",
                               f"{ch}: residual correlates most with input {name} "
                               f"(peak {zmax / np.sqrt(n):.2f} at lag {lag} samples, "
                               f"{zmax:.1f} sigma): the model misses part of the "
                               f"response to {name}",
                               {"input": name, "z": zmax, "lag": lag}))
    return out


def parameter_failures(parameters, sigma, correlation=None, names=None, omega=None,
                       rel_sigma=0.5, corr_limit=0.95) -> list[Failure]:
    """Estimates outside the physical range by more than 1 sigma, poorly determined
    (``sigma/|estimate| > rel_sigma``), or strongly correlated pairs."""
    out = []
    for name, est in parameters.items():
        s = sigma.get(name)
        if name in PLAUSIBLE:
            lo, hi, why = PLAUSIBLE[name]
            scale = 1.0 / omega if (name in SECONDS and omega) else 1.0
            v, sv = est * scale, (s or 0.0) * scale
            if v - sv > hi or v + sv < lo:
                unit = " s" if scale != 1.0 else ""
                out.append(Failure("implausible", name,
                                   f"{name} = {v:.4g}{unit} (1-sigma {sv:.2g}) is outside "
                                   f"[{lo:g}, {hi:g}]{unit}: {why}; the structure is "
                                   "probably missing an effect that this parameter absorbs",
                                   {"estimate": est, "sigma": s, "range": [lo, hi]}))
        if s is not None and est != 0 and s / abs(est) > rel_sigma:
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
