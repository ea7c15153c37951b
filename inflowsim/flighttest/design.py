"""Optimal multisine inputs for identification (issue #25, item 3).

Given a structure, its current estimates and the parameters of interest (those of
the effects the diagnosis hesitates between, or a list), choose the relative
amplitudes of each control's multisine harmonics, within a peak (or rms) limit,
that maximise the information on those parameters; report the Cramer-Rao bounds
expected before (a standard 1 deg doublet) and after (the designed input).

Method
------
*Criterion.*  D_s-optimal: maximise ``log det (M^-1)_ss^-1``, the information on
the parameters of interest ``s`` with every other free parameter estimated too
(Fedorov; Morelli and Klein, *Aircraft System Identification*, ch. 9).  In the
frequency-domain output-error model (Eqs. 10-12) with noise covariance ``S`` per
transform bin, a harmonic ``k`` of amplitude ``a_k`` on control ``c`` adds
``M_k = a_k^2 Re(G_k^H S^-1 G_k)`` with ``G_k = dH(f_k)/dtheta d_c(f_k)``: the
sensitivity of the model's response (:meth:`Model.frequency_response`, central
differences) to the model inputs that pilot control ``c`` moves, hub motion
included (``d_c`` from the body model of the virtual flight test).  Harmonics of
different controls are distinct frequencies (interleaved), so their
informations add.

*Optimisation.*  The constraint is each control's amplitude: the peak of its
signal never exceeds the limit (``limit="peak"``, the default), or its rms equals
the limit (``limit="rms"``, a power budget).  First the split of a control's
power among its harmonics is found for a fixed power by the multiplicative
algorithm ``p_k <- p_k g_k / sum_j p_j g_j`` per control, ``g_k = tr(A M_k)``, ``A =
M^-1_{:,s} ((M^-1)_ss)^-1 M^-1_{s,:}`` the gradient of the criterion (Silvey,
Titterington and Torsney 1978), which increases the criterion at each step: under
an rms limit that is the design.  Under a peak limit the power a control can carry
depends on the split (a spectrum piled on a few harmonics has a higher peak
factor), so the criterion is evaluated for the peak-limited signals of the family
``p_k^gamma`` (``gamma`` from 0, equal powers, to 1.5; 1 is the power-optimal
split) with each control's signal scaled to the limit by a guaranteed bound on its
peak (:func:`peak_bound`), and the best is taken.  Schroeder phases for the chosen
powers keep the peak factor low.

*Expected bounds.*  The identification's own information and bound formulas
(:mod:`inflowsim.identify.estimator`: the variable-projection sensitivities of
the transformed record, ``M = 2 J^T J``, the degrees-of-freedom correction) at
the current estimates, on the noise-free virtual record of each input, with the
noise ``S`` of white flap noise ``sigma`` (``sigma^2 N`` per bin of the record's
transform): the bounds a record flown with that input should give.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..channels import CONTROLS, INPUTS
from ..errors import InputError
from ..progress import bar
from ..identify.transform import DEFAULT_BAND

#: Iterations of the multiplicative algorithm.
ITERATIONS = 300


@dataclass(frozen=True)
class InputDesign:
    """A designed multisine and the bounds it promises.

    ``harmonics[c]`` the harmonic numbers of ``1 / length`` [Hz] on control
    ``channels[c]``, ``amplitudes[c]`` their amplitudes [rad] (zero where the design
    puts no power), ``peak`` per control [rad]; ``sigma_before`` / ``sigma_after``
    the expected 1-sigma Cramer-Rao bounds per free parameter with the standard
    doublet and with the design; ``interest`` the parameters the criterion
    serves.
    """

    structure: str
    parameters: dict
    interest: tuple
    channels: tuple
    limit: float
    limit_kind: str
    length: float
    t_start: float
    duration: float
    dt: float
    fade: float
    harmonics: tuple
    amplitudes: tuple
    peak: tuple
    sigma_before: dict
    sigma_after: dict
    noise_flap: float
    band_hz: tuple
    criterion_gain: float = field(default=float("nan"))

    def manoeuvres(self) -> tuple:
        """The design as :class:`~inflowsim.flighttest.virtual.Manoeuvre` s (one
        multisine per control), for :func:`~inflowsim.flighttest.virtual.virtual_record`
        or :func:`~inflowsim.flighttest.nonlinear.flighttest`."""
        from .virtual import Manoeuvre
        out = []
        for c, h, a, pk in zip(self.channels, self.harmonics, self.amplitudes, self.peak):
            keep = [i for i, x in enumerate(a) if x > 0]
            out.append(Manoeuvre(channel=c, shape="multisine", amplitude=pk,
                                 t_start=self.t_start, length=self.length,
                                 harmonics=tuple(h[i] for i in keep),
                                 weights=tuple(a[i] / max(a) for i in keep),
                                 fade=self.fade))
        return tuple(out)

    def ratio(self) -> dict:
        """``sigma_after / sigma_before`` per parameter of interest."""
        return {n: self.sigma_after[n] / self.sigma_before[n] for n in self.interest
                if self.sigma_before.get(n) and self.sigma_after.get(n) is not None}

    def to_json(self) -> dict:
        return {"structure": self.structure, "parameters": dict(self.parameters),
                "interest": list(self.interest), "band_hz": list(self.band_hz),
                "limit": {"kind": self.limit_kind, "value_rad": self.limit,
                          "value_deg": float(np.degrees(self.limit))},
                "noise_flap": self.noise_flap,
                "record": {"duration_s": self.duration, "dt_s": self.dt,
                           "t_start_s": self.t_start, "length_s": self.length,
                           "fade_s": self.fade, "base_hz": 1.0 / self.length},
                "channels": [{"channel": c, "harmonics": list(h),
                              "frequency_hz": [k / self.length for k in h],
                              "amplitude_rad": list(a), "peak_rad": pk}
                             for c, h, a, pk in zip(self.channels, self.harmonics,
                                                    self.amplitudes, self.peak)],
                "sigma_before": dict(self.sigma_before),
                "sigma_after": dict(self.sigma_after),
                "before": "a 1 deg theta1s doublet (half-width 0.4 s) at t_start",
                "criterion_gain": self.criterion_gain}


# -- pieces -----------------------------------------------------------------------------
def manoeuvres_from_json(doc) -> tuple:
    """The manoeuvres of a design document (:meth:`InputDesign.to_json`)."""
    from .virtual import Manoeuvre
    try:
        rec = doc["record"]
        out = []
        for ch in doc["channels"]:
            a = [float(x) for x in ch["amplitude_rad"]]
            keep = [i for i, x in enumerate(a) if x > 0]
            if ch["channel"] not in CONTROLS or not keep:
                raise ValueError(f"channel {ch['channel']!r}")
            out.append(Manoeuvre(channel=ch["channel"], shape="multisine",
                                 amplitude=float(ch["peak_rad"]),
                                 t_start=float(rec["t_start_s"]),
                                 length=float(rec["length_s"]),
                                 harmonics=tuple(int(ch["harmonics"][i]) for i in keep),
                                 weights=tuple(a[i] / max(a) for i in keep),
                                 fade=float(rec["fade_s"])))
        return tuple(out), float(rec["duration_s"]), float(rec["dt_s"])
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise InputError(f"not an input design (inflowsim design --out): {exc}") from None


def pilot_directions(model, body, f_hz) -> np.ndarray:
    """Model inputs moved by a unit pilot control, ``(n_inputs, 3, nf)``: the control
    itself plus the hub motion the body model answers with [SI per rad]."""
    k = model.constants
    omega_r = k.omega * (k.radius or 7.5)
    ab, bb = body.matrices()
    ch, dh = body.hub_matrices(omega_r, k.mu)
    cu = np.vstack([np.zeros((3, ab.shape[0])), ch])
    du = np.vstack([np.eye(3), dh])
    cols = [INPUTS.index(c) for c in model.inputs]
    w = 2 * np.pi * np.atleast_1d(f_hz)
    eye = np.eye(ab.shape[0])
    out = np.empty((len(cols), 3, w.size), dtype=complex)
    for i, wi in enumerate(w):
        out[:, :, i] = (cu @ np.linalg.solve(1j * wi * eye - ab, bb) + du)[cols]
    return out


def harmonic_information(structure, params, constants, free, body, f_hz, S) -> np.ndarray:
    """Per-unit-amplitude information ``(3 controls, nf, p, p)`` of a harmonic at each
    frequency on each control: ``Re(G^H S^-1 G)`` with ``G = dH/dtheta d_c``."""
    from ..model.build import build_model
    from ..identify.problem import TYPICAL
    base = build_model(structure, params, constants)
    d = pilot_directions(base, body, f_hz)                           # (m, 3, nf)
    sens = []
    for n in free:
        h = 1e-6 * max(abs(params[n]), TYPICAL.get(n, 0.1))
        hp = build_model(structure, {**params, n: params[n] + h}, constants)
        hm = build_model(structure, {**params, n: params[n] - h}, constants)
        dH = (hp.frequency_response(f_hz)[:3] - hm.frequency_response(f_hz)[:3]) / (2 * h)
        sens.append(np.einsum("omf,mcf->ocf", dH, d))                 # (3 out, 3 ctrl, nf)
    G = np.stack(sens, axis=-1)                                       # (3, 3, nf, p)
    Si = np.linalg.inv(S)
    return np.real(np.einsum("ocfp,oq,qcfr->cfpr", G.conj(), Si, G))


def _ds_gradient(M, s):
    Mi = np.linalg.pinv(M)
    Css = Mi[np.ix_(s, s)]
    A = Mi[:, s] @ np.linalg.pinv(Css) @ Mi[s, :]
    return A, float(-np.linalg.slogdet(Css)[1])


def optimise_powers(info, blocks, iterations=ITERATIONS, interest_idx=None):
    """Powers per harmonic (each control's block summing to 1) maximising the D_s
    criterion; ``info (n, p, p)`` per harmonic, ``blocks`` the harmonic indices of
    each control.  Returns the powers and the criterion's gain over equal powers."""
    n, p = info.shape[0], info.shape[1]
    s = list(range(p)) if interest_idx is None else list(interest_idx)
    w = np.zeros(n)
    for b in blocks:
        w[b] = 1.0 / len(b)
    _, crit0 = _ds_gradient(np.einsum("k,kpq->pq", w, info), s)
    for _ in range(iterations):
        A, _ = _ds_gradient(np.einsum("k,kpq->pq", w, info), s)
        g = np.maximum(np.einsum("pq,kqp->k", A, info), 0.0)
        for b in blocks:
            tot = float(np.dot(w[b], g[b]))
            if tot > 0:
                w[b] = w[b] * g[b] / tot
    _, crit = _ds_gradient(np.einsum("k,kpq->pq", w, info), s)
    return w, crit - crit0


def peak_bound(base_hz: float, harmonics, weights, phases, n_grid: int = 4096,
               refine: int = 32) -> float:
    """An upper bound on the peak of ``sum_k w_k cos(2 pi k base_hz tau + phi_k)``
    over one period, tight to a few parts in a million.

    The dense grid of :func:`~inflowsim.data.inputs.multisine_peak` can miss the
    peak by up to ``L dtau / 2`` (``L = sum |w_k| 2 pi k base_hz``, the largest
    slope); every grid cell that could hold a higher value is refined ``refine``
    times, and inside a refined cell the true maximum exceeds the nearest sample by
    at most ``S dtau'^2 / 8`` (``S = sum |w_k| (2 pi k base_hz)^2``, the largest
    curvature; the derivative vanishes at an interior maximum).
    """
    from ..data.inputs import multisine_unit
    h = np.asarray(harmonics, dtype=float)
    w = np.abs(np.asarray(weights, dtype=float))
    n = max(n_grid, 16 * int(h.max()))
    dtau = 1.0 / (n * base_hz)
    tau = np.arange(n) * dtau
    x = np.abs(multisine_unit(tau, base_hz, harmonics, weights, phases))
    om = 2 * np.pi * h * base_hz
    slope, curv = float(np.sum(w * om)), float(np.sum(w * om ** 2))
    top = float(x.max())
    cand = np.flatnonzero(x + slope * dtau / 2 >= top)
    sub = (np.arange(-refine, refine + 1) / (2 * refine)) * dtau      # the cell, both sides
    t2 = (tau[cand][:, None] + sub[None, :]).ravel()
    best = float(np.max(np.abs(multisine_unit(t2, base_hz, harmonics, weights, phases))))
    return max(best, top) + curv * (dtau / (2 * refine)) ** 2 / 8


def _keep(wb):
    """Harmonics the design keeps: over 0.1 % of the largest power."""
    wb = wb / max(wb.max(), 1e-300)
    return np.where(wb > 1e-3, wb, 0.0)


def peak_limited(w, blocks, hs, length, lim):
    """Per control: the amplitudes ``a`` [rad] (dropped harmonics 0) of the split
    ``w`` scaled so the signal's peak bound (:func:`peak_bound`) is ``lim``, and the
    commanded amplitude (the multisine's nominal peak, which
    :func:`~inflowsim.data.inputs.multisine` scales its grid peak to)."""
    from ..data.inputs import multisine_plan
    amps, commanded = [], []
    for b, h in zip(blocks, hs):
        a = np.sqrt(_keep(w[b]))
        keep = a > 0
        hk = tuple(int(x) for x, kp in zip(h, keep) if kp)
        wts = tuple(float(x) for x in a[keep] / a[keep].max())
        wu, ph, grid_peak = multisine_plan(1.0 / length, hk, wts, ())
        bound = peak_bound(1.0 / length, hk, wu, ph)
        scale = lim / bound                 # amplitude of the unit weights
        amps.append(a / a[keep].max() * scale)
        commanded.append(float(grid_peak * scale))
    return amps, commanded


def _criterion(amps, blocks, info, s_idx):
    M = sum(np.einsum("k,kpq->pq", a ** 2, info[b]) for a, b in zip(amps, blocks))
    return _ds_gradient(M, s_idx)[1]


#: Exponents of the peak-limited search (0: equal powers; 1: the power-optimal split).
GAMMAS = tuple(np.round(np.arange(0.0, 1.51, 0.125), 3))


def expected_bounds(test, structure, params, band_hz=DEFAULT_BAND) -> dict:
    """1-sigma Cramer-Rao bounds the identification would report for a record of
    ``test`` (a :class:`~inflowsim.flighttest.virtual.VirtualTest`) at ``params``:
    its own sensitivities and bound formulas on the noise-free record, with the
    white flap noise ``test.noise_flap`` as ``S``."""
    from dataclasses import replace
    from .virtual import virtual_record
    from ..identify.estimator import _bounds, _state
    from ..identify.problem import Problem
    from ..identify.transform import record_spectra
    rec = virtual_record(replace(test, noise_flap=0.0), include_truth=False)
    from ..model.structure import Structure
    s = Structure.parse(structure)
    sp = record_spectra(rec, s.inputs, band_hz)
    prob = Problem(s, [sp], params)
    S = test.noise_flap ** 2 * len(rec) * np.eye(3)
    st = _state(prob, prob.theta0(), [S])
    cov, _, _, dead, _ = _bounds(prob, st)
    out = {}
    for i, g in enumerate(prob.free):
        v = cov[i, i]
        for n in g:
            out[n] = float(np.sqrt(v)) if np.isfinite(v) else None
    return out


# -- the design -------------------------------------------------------------------------
def design_input(structure, parameters=None, interest=None, effects=(), channels=CONTROLS,
                 limit_deg: float = 1.0, limit: str = "peak", duration: float = 26.6,
                 t_start: float = 2.0, dt: float = 0.01, fade: float = 1.0,
                 band_hz=DEFAULT_BAND, noise_flap: float = 1e-4,
                 iterations: int = ITERATIONS, progress=None) -> InputDesign:
    """Design a multisine that maximises the information on ``interest``.

    Parameters
    ----------
    structure : str or Structure
        The structure identified (``effects`` are added to it).
    parameters : mapping, optional
        Current estimates (any subset; the rest: the paper's values, theory values
        for added effects, :func:`~inflowsim.model.presets.truth_parameters`).
    interest : sequence of str, optional
        Parameters to learn (default: those of ``effects``, else every parameter).
    effects : sequence of str
        Candidate effects the diagnosis hesitates between: added to the structure,
        their parameters the default ``interest``.
    channels : sequence of str
        Controls moved at once (interleaved harmonics).
    limit_deg : float
        Amplitude limit per control [deg]: the peak (``limit="peak"``) or the rms
        (``limit="rms"``) of its signal.
    duration, t_start, dt, fade : float
        The record [s]: the multisine runs from ``t_start`` to 1 s before the end,
        faded in and out over ``fade``; its base frequency is ``1 / length``.
    band_hz : (float, float)
        Identification band [Hz]: the harmonics lie in it.
    noise_flap : float
        Flap sensor noise [rad] (white) the bounds are expected for.
    iterations : int
        Iterations of the power optimisation [-].
    progress : callable, optional
        Progress (:func:`inflowsim.progress.bar`): the five steps (information,
        powers, peak-limited split, the bounds before and after) as they run.

    Returns
    -------
    InputDesign
    """
    from .virtual import PUMA_TRIM, Manoeuvre, VirtualTest
    from ..model.params import PUMA
    from ..model.presets import truth_parameters
    from ..model.structure import Structure
    from ..data.inputs import interleaved_harmonics, multisine_plan
    s = Structure.parse(structure)
    for e in effects:
        s = s.with_effect(e)
    params = truth_parameters(s, PUMA)
    unknown = sorted(set(parameters or {}) - set(s.parameters))
    if unknown:
        raise InputError(f"parameter {unknown[0]!r} is not one of {s.name}'s "
                         f"({', '.join(s.parameters)})")
    params.update({k: float(v) for k, v in (parameters or {}).items()})
    from ..model.effects import CATALOGUE
    if interest is None:
        interest = [n for e in effects for n in CATALOGUE[e].parameters] or list(s.parameters)
    interest = tuple(interest)
    bad = [n for n in interest if n not in s.parameters]
    if bad:
        raise InputError(f"interest {bad[0]!r}: not a parameter of {s.name} "
                         f"({', '.join(s.parameters)})")
    channels = tuple(channels)
    if not channels or any(c not in CONTROLS for c in channels) or \
            len(set(channels)) < len(channels):
        raise InputError(f"channels {' '.join(channels)}: choose distinct controls of "
                         f"{', '.join(CONTROLS)}")
    if limit not in ("peak", "rms"):
        raise InputError(f"limit {limit!r}: choose peak or rms")
    if not (np.isfinite(limit_deg) and 0 < limit_deg <= 20):
        raise InputError(f"amplitude limit {limit_deg:g} deg: choose a value in (0, 20]")
    if not (np.isfinite(noise_flap) and noise_flap > 0):
        raise InputError(f"noise {noise_flap:g}: a standard deviation > 0")
    length = duration - t_start - 1.0
    if length <= 2 * fade or length <= 0:
        raise InputError(f"duration {duration:g} s: too short for a multisine after "
                         f"{t_start:g} s")
    k1 = max(1, int(np.ceil(band_hz[0] * length - 1e-9)))
    k2 = int(np.floor(band_hz[1] * length + 1e-9))
    if k2 - k1 + 1 < 2 * len(channels):
        raise InputError(f"band {band_hz[0]:g}-{band_hz[1]:g} Hz over {length:g} s holds "
                         f"too few harmonics for {len(channels)} control(s)")
    hs = interleaved_harmonics(len(channels), k1, k2)
    body = VirtualTest().body
    # the virtual truth's constants: effects linearised about trim see its trim
    k = PUMA.with_trim(dict(PUMA_TRIM, mux=PUMA.mu)) if PUMA.trim is None else PUMA
    free = list(s.parameters)
    f_all = np.array([kk / length for h in hs for kk in h])
    ctrl = np.array([CONTROLS.index(c) for c, h in zip(channels, hs) for _ in h])
    steps = bar(progress, 5, f"design {s.name}", "step")
    steps.set_postfix_str("information per harmonic")
    info_all = harmonic_information(s, params, k, free, body, f_all,
                                    noise_flap ** 2 * np.eye(3))
    steps.update()
    info = info_all[ctrl, np.arange(f_all.size)]                      # (n, p, p)
    blocks, i0 = [], 0
    for h in hs:
        blocks.append(np.arange(i0, i0 + len(h)))
        i0 += len(h)
    s_idx = [free.index(n) for n in interest]
    steps.set_postfix_str("optimising the harmonics' powers")
    w, gain = optimise_powers(info, blocks, iterations, s_idx)
    steps.update()
    steps.set_postfix_str(f"the {limit}-limited amplitudes")
    lim = np.radians(limit_deg)
    if limit == "peak":
        # the power-optimal split is not the peak-limited optimum: search the family
        # w^gamma, each control's signal scaled to the limit by a bound on its peak
        def split(g):
            out = np.zeros_like(w)
            for b in blocks:
                wb = np.where(w[b] > 0, w[b], 0.0) ** g
                out[b] = wb / wb.sum()
            return out
        tried = {g: peak_limited(split(g), blocks, hs, length, lim) for g in GAMMAS}
        crit = {g: _criterion(t[0], blocks, info, s_idx) for g, t in tried.items()}
        g_best = max(crit, key=crit.get)
        amps_arr, peaks = tried[g_best]
        gain = crit[g_best] - crit[0.0]
        amps = [tuple(float(x) for x in a) for a in amps_arr]
    else:
        amps, peaks = [], []
        for b in blocks:
            a = np.sqrt(_keep(w[b]))
            scale = lim / np.sqrt(0.5 * np.sum(a ** 2))
            amps.append(tuple(float(x) for x in a * scale))
        from ..data.inputs import multisine_plan
        for a, h in zip(amps, hs):
            keep = [i for i, x in enumerate(a) if x > 0]
            wts = tuple(a[i] / max(a) for i in keep)
            _, _, grid_peak = multisine_plan(1.0 / length, tuple(h[i] for i in keep),
                                             wts, ())
            peaks.append(float(grid_peak * max(a)))
    design = InputDesign(
        structure=s.name, parameters=dict(params), interest=interest, channels=channels,
        limit=float(lim), limit_kind=limit, length=float(length), t_start=float(t_start),
        duration=float(duration), dt=float(dt), fade=float(fade),
        harmonics=tuple(tuple(int(x) for x in h) for h in hs), amplitudes=tuple(amps),
        peak=tuple(peaks), sigma_before={}, sigma_after={}, noise_flap=float(noise_flap),
        band_hz=tuple(float(x) for x in band_hz), criterion_gain=float(gain))
    steps.update()
    before = VirtualTest(structure=s.name, parameters=params, manoeuvres=(Manoeuvre(
        t_start=t_start),), duration=duration, dt=dt, noise_flap=noise_flap)
    after = VirtualTest(structure=s.name, parameters=params,
                        manoeuvres=design.manoeuvres(), duration=duration, dt=dt,
                        noise_flap=noise_flap)
    from dataclasses import replace
    with steps:
        steps.set_postfix_str("expected bounds: a doublet")
        sigma_before = expected_bounds(before, s, params, band_hz)
        steps.update()
        steps.set_postfix_str("expected bounds: the design")
        sigma_after = expected_bounds(after, s, params, band_hz)
        steps.update()
    return replace(design, sigma_before=sigma_before, sigma_after=sigma_after)


def format_design(d) -> str:
    """The design and its bounds as the ``design`` command prints them."""
    lines = [f"structure {d.structure}; interest: {', '.join(d.interest)}",
             f"multisine on {', '.join(d.channels)}: {d.length:.4g} s from {d.t_start:g} s, "
             f"base {1 / d.length:.4g} Hz, {d.limit_kind} limit "
             f"{math.degrees(d.limit):.3g} deg per control"]
    for c, h, a, pk in zip(d.channels, d.harmonics, d.amplitudes, d.peak):
        used = [(k / d.length, x) for k, x in zip(h, a) if x > 0]
        lines.append(f"  {c}: peak {math.degrees(pk):.3g} deg; " + ", ".join(
            f"{f:.3g} Hz {math.degrees(x):.2g} deg" for f, x in used))
    lines.append(f"expected 1-sigma bounds (noise {d.noise_flap:g} rad): before = 1 deg "
                 "theta1s doublet, after = the design")
    lines.append(f"{'parameter':<14}{'value':>11}{'before':>11}{'after':>11}{'ratio':>8}")
    for n, v in d.parameters.items():
        b, a = d.sigma_before.get(n), d.sigma_after.get(n)
        r = f"{a / b:8.3f}" if a is not None and b else f"{'-':>8}"
        mark = " *" if n in d.interest else ""
        fb = f"{b:11.4g}" if b is not None else f"{'none':>11}"
        fa = f"{a:11.4g}" if a is not None else f"{'none':>11}"
        lines.append(f"{n:<14}{v:>11.4g}{fb}{fa}{r}{mark}")
    lines.append("(* parameters of interest; none: not determined by that input)")
    return "\n".join(lines)


__all__ = ["format_design", "InputDesign", "design_input", "manoeuvres_from_json",
           "expected_bounds", "harmonic_information", "optimise_powers", "pilot_directions",
           "peak_bound", "peak_limited"]
