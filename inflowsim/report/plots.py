"""Report-quality figures, like the paper's Figures 1-5 (matplotlib, Agg, no pyplot).

Every ``*_plot`` function takes result objects (computing stays in
``validation``, ``identification`` ...), returns a
:class:`matplotlib.figure.Figure` and, given ``path``, also saves it as PNG.
Figures are built on :func:`new_figure` (an Agg canvas, no global pyplot state),
so they are safe in scripts, tests and servers; reuse :func:`new_figure` and
:func:`save_png` for new plots.
"""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from ..data.record import FLAP_COLUMNS
from ..channels import CONTROLS
from ..fileio import atomic_path

#: Axis labels of the flap channels (units: degrees on plots, radians inside).
FLAP_LABELS = {"beta0": r"$\beta_0$", "beta1c": r"$\beta_{1c}$", "beta1s": r"$\beta_{1s}$"}
#: The pilot controls' colours (the same in every control panel).
CONTROL_COLOURS = {"theta0": "tab:gray", "theta1c": "tab:olive", "theta1s": "tab:cyan"}
DPI = 110


def new_figure(nrows=1, ncols=1, size=(8.0, 6.0), sharex=True):
    """A figure on an Agg canvas and its axes array (always 2-D).  Matplotlib is
    imported here, on the first figure: a command that draws nothing never loads it."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, sharex=sharex, squeeze=False)
    return fig, axes


def save_png(fig, path, dpi: int = DPI) -> Path:
    """Save ``fig`` as PNG at ``path``, replacing a regular file only and never
    leaving it half-written (:func:`inflowsim.fileio.atomic_path`)."""
    p = Path(path)
    with atomic_path(p) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi, metadata={"Software": "inflowsim"})
    return p


def _as_list(results):
    return list(results) if isinstance(results, (list, tuple)) else [results]


def manoeuvre_window(t, u, names, before: float = 1.0, after: float = 4.0):
    """``(t0, t1)`` [s]: from ``before`` seconds ahead of the first control movement
    to ``after`` seconds past the last (the record's ends at most); the whole record
    when no control moves.

    Parameters
    ----------
    t : array_like
        Times [s].
    u : array_like, shape (N, m)
        Input perturbations (radians for the controls).
    names : sequence of str
        The inputs' names; the pilot controls (``CONTROLS``) are looked at.
    before, after : float
        Margins [s].
    """
    t = np.asarray(t, dtype=float)
    u = np.asarray(u, dtype=float)
    cols = [j for j, n in enumerate(names) if n in CONTROLS]
    if not cols or len(t) < 2:
        return float(t[0]), float(t[-1])
    dev = np.abs(u[:, cols] - u[:1, cols]).max(axis=1)
    scale = np.abs(u[:, cols]).max()
    moving = np.flatnonzero(dev > 1e-3 * scale) if scale > 0 else np.array([], int)
    if moving.size == 0:
        return float(t[0]), float(t[-1])
    return (max(float(t[0]), float(t[moving[0]]) - before),
            min(float(t[-1]), float(t[moving[-1]]) + after))


def time_response_plot(results, path=None, show_inputs: bool = False, title=None,
                       window=None):
    """Measured against predicted multiblade flap against time.

    Parameters
    ----------
    results : ValidationResult or sequence of them
        One or several models on the same record; the measured flap is taken
        from the first.  Colours follow :func:`.style.model_colours` (the first
        model the base model's, the last the final model's).
    path : path-like, optional
        Save the figure there as PNG.
    show_inputs : bool
        Add a panel with the pilot control perturbations [deg].
    title : str, optional
        Default names the structure(s) and the record.
    window : (float, float) or "manoeuvre", optional
        Time axis limits [s]; ``"manoeuvre"``: zoomed on the control movements
        (:func:`manoeuvre_window`); default the whole record.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .style import ROLE_COLOURS, model_colours
    res = _as_list(results)
    r0 = res[0]
    n = 3 + bool(show_inputs)
    colours = model_colours(len(res))
    fig, ax = new_figure(n, 1, size=(8.0, 2.1 * n + 0.6))
    for i, c in enumerate(FLAP_COLUMNS):
        a = ax[i, 0]
        a.plot(r0.t, np.degrees(r0.measured[:, i]), color=ROLE_COLOURS["measured"],
               lw=1.0, label="measured")
        for r, colour in zip(res, colours):
            a.plot(r.t, np.degrees(r.predicted[:, i]), lw=1.2, color=colour,
                   label=f"{r.structure} (fit {r.channels[c].fit_percent:.1f} % over "
                         f"{r.band_hz[0]:.3g}-{r.band_hz[1]:.3g} Hz)")
        a.set_ylabel(f"{FLAP_LABELS[c]} [deg]")
        a.grid(True, alpha=0.3)
        a.legend(loc="upper right", fontsize="small")
    if show_inputs:
        a = ax[3, 0]
        for j, name in enumerate(r0.inputs):
            if name in CONTROLS and np.ptp(r0.u[:, j]) > 1e-9:
                a.plot(r0.t, np.degrees(r0.u[:, j]), lw=1.0,
                       color=CONTROL_COLOURS[name], label=name)
        a.set_ylabel("control [deg]")
        a.grid(True, alpha=0.3)
        a.legend(loc="upper right", fontsize="small")
    ax[-1, 0].set_xlabel("time [s]")
    if window is not None:
        t0, t1 = (manoeuvre_window(r0.t, r0.u, r0.inputs) if window == "manoeuvre"
                  else window)
        ax[-1, 0].set_xlim(t0, t1)
        sel = (r0.t >= t0) & (r0.t <= t1)
        ys = [np.degrees(r0.measured[sel])] + [np.degrees(r.predicted[sel]) for r in res]
        for k, a in enumerate(ax[:3, 0]):          # the flap's scale over the window
            lo = min(float(np.nanmin(y[:, k])) for y in ys)
            hi = max(float(np.nanmax(y[:, k])) for y in ys)
            pad = 0.08 * (hi - lo) or 0.01
            a.set_ylim(lo - pad, hi + pad)
    names = ", ".join(r.structure for r in res)
    fig.suptitle(title or f"Flap perturbations about trim: measured and {names} "
                 f"({Path(r0.source).name})")
    if path is not None:
        save_png(fig, path)
    return fig


def frequency_response_plot(results, path=None, title=None, unwrap: bool = True):
    """Bode plot of a validation: the measured responses of the flap to each input,
    conditioned on the others, with error bands and coherence, and each model's
    analytic responses on top (:class:`~inflowsim.diagnose.validation.FrequencyComparison`).

    Parameters
    ----------
    results : ValidationResult or sequence of them
        Models compared on one record; measured taken from the first.
    path : path-like, optional
        Save as PNG.
    title : str, optional
    unwrap : bool
        Unwrap the phases (the default; labelled); ``False``: wrapped to +-180 deg.

    Returns
    -------
    matplotlib.figure.Figure
        One column per response pair (inputs, then outputs); rows magnitude [dB],
        phase [deg], coherence (:func:`inflowsim.report.frf_plots.frequency_response_plot`).
    """
    from .frf_plots import frequency_response_plot as bode
    res = _as_list(results)
    fr = res[0].frequency.measured
    models = {f"{r.structure} (J {r.frequency.overall_cost:.3g})": r.frequency.model
              for r in res}
    names = ", ".join(r.structure for r in res)
    return bode(fr, pairs=[(o, i) for i in fr.inputs for o in fr.outputs], models=models,
                path=path, unwrap=unwrap,
                title=title or f"Flap responses, each conditioned on the other inputs: "
                               f"measured and {names}, {res[0].band_hz[0]:.4g}-"
                               f"{res[0].band_hz[1]:.4g} Hz")


def _log_frequency_axis(ax):
    from .style import log_frequency_axis
    log_frequency_axis(ax)


def error_spectrum_plot(results: Sequence, path=None, title=None):
    """Measured over model response against frequency: magnitude [dB] and phase
    [deg] per response pair, where the measurement is read (coherence >= 0.6, two
    windows); the shaded band is the measurement's +-2 stated errors about 0."""
    from .frf_plots import BAND_SIGMA
    res = _as_list(results)
    fig, ax = new_figure(2, 1, size=(8.0, 5.5))
    styles = ("-", "--", ":", "-.")
    fr0 = res[0].frequency.measured
    valid = fr0.valid()
    err = np.hypot(fr0.random_error, fr0.bias_error)
    f = fr0.frequency_hz
    # the measurement's own error: a model inside it is as good as the data can tell
    band = np.max(np.where(valid, err, -np.inf), axis=(0, 1))
    band = np.where(np.isfinite(band), band, np.nan)
    ax[0, 0].fill_between(f, -20 * np.log10(1 + BAND_SIGMA * band),
                          20 * np.log10(1 + BAND_SIGMA * band), color="0.85", lw=0,
                          label=f"±{BAND_SIGMA:g} measurement errors (largest pair)")
    ax[1, 0].fill_between(f, -np.degrees(BAND_SIGMA * band), np.degrees(BAND_SIGMA * band),
                          color="0.85", lw=0)
    pairs = [(o, i) for i in range(len(fr0.inputs)) for o in range(len(fr0.outputs))]
    for k, r in enumerate(res):              # colour per pair, line style per model
        fc = r.frequency
        mag, ph = fc.magnitude_error_db, fc.phase_error_deg
        ls = styles[k % len(styles)]
        for n, (o, i) in enumerate(pairs):
            name = f"{fr0.outputs[o]}/{fr0.inputs[i]}"
            lab = f"{name} ({r.structure})" if len(res) > 1 else name
            kw = dict(lw=1.2, ls=ls, color=f"C{n % 10}", label=lab)
            ax[0, 0].plot(f, np.where(valid[o, i], mag[o, i], np.nan), **kw)
            ax[1, 0].plot(f, np.where(valid[o, i], ph[o, i], np.nan), **kw)
    ax[0, 0].set_ylabel("magnitude error [dB]")
    ax[1, 0].set_ylabel("phase error [deg]")
    ax[1, 0].set_xlabel("frequency [Hz]")
    for a in ax[:, 0]:
        a.axhline(0.0, color="k", lw=0.6)
        _log_frequency_axis(a)
        a.grid(True, which="both", alpha=0.3)
    ax[0, 0].legend(fontsize="x-small", ncol=3)
    fig.suptitle(title or "Measured over model response where coherence >= 0.6 "
                          "(0 dB, 0° is a perfect match)")
    if path is not None:
        save_png(fig, path)
    return fig


#: Square degrees per square radian (powers of angles as the plots show them).
DEG2 = (180.0 / np.pi) ** 2


def residual_spectrum_plot(analyses, path=None, title=None):
    """The fit's residual power against the noise floor, per flap channel and record.

    Parameters
    ----------
    analyses : ResidualAnalysis or sequence of them
        :func:`inflowsim.diagnose.failures.residual_analysis` results (one per record),
        e.g. ``Diagnosis.analyses``.

    Returns
    -------
    matplotlib.figure.Figure
        ``|Z - Y|^2`` (residual power of the unscaled transforms
        ``sum c_n x_n`` of :mod:`inflowsim.identify.transform`) and the floor
        estimated above the band (:func:`~inflowsim.diagnose.failures.noise_floor`),
        shown in [deg^2] like every flap plot; a residual at the floor is noise, one
        well above it is model error.
    """
    ras = _as_list(analyses)
    fig, ax = new_figure(3, 1, size=(8.0, 7.5))
    for k, ra in enumerate(ras):
        for i, c in enumerate(FLAP_COLUMNS):
            a = ax[i, 0]
            res = np.abs(ra.measured[i] - ra.predicted[i]) ** 2 * DEG2
            lab = f"record {k + 1}: " if len(ras) > 1 else ""
            a.semilogy(ra.f_hz, res, "o-", ms=3, lw=1, color=f"C{k}",
                       label=f"{lab}residual (mean {np.mean(ra.ratio[i]):.2g} x floor)")
            a.semilogy(ra.f_hz, np.broadcast_to(ra.floor[i] * DEG2, ra.f_hz.shape), "--",
                       color=f"C{k}", lw=1,
                       label=f"{lab}noise floor (from {ra.floor_band_hz[0]:.3g}-"
                             f"{ra.floor_band_hz[1]:.3g} Hz)")
            a.set_ylabel(f"{FLAP_LABELS[c]} residual power [deg²]")
            a.grid(True, which="both", alpha=0.3)
            a.legend(fontsize="x-small")
    ax[-1, 0].set_xlabel("frequency [Hz]")
    fig.suptitle(title or "Residual power of the fit against the noise floor")
    if path is not None:
        save_png(fig, path)
    return fig


def coherence_plot(results, path=None, title=None):
    """Coherence of the measured flap with each input, conditioned on the others.

    Where the partial coherence is near 1 the flap is a linear response to that
    input; where it falls, noise, unmeasured inputs or nonlinearity dominate, and no
    model can match those frequencies.  One panel per input: the partial coherence
    of each flap channel (the ordinary one with a single input) and, with several
    inputs, the multiple coherence (all inputs together); the line at 0.6 is where a
    response is read.  From the validation's composite responses
    (:mod:`inflowsim.identify.frf`).
    """
    from ..identify.frf import COHERENCE_OK
    r0 = _as_list(results)[0]
    fr = r0.frequency.measured
    q = len(fr.inputs)
    fig, ax = new_figure(q, 1, size=(8.0, 2.6 * q + 1.0))
    f = fr.frequency_hz
    for i, inp in enumerate(fr.inputs):
        a = ax[i, 0]
        for o, c in enumerate(fr.outputs):
            a.plot(f, fr.coherence[o, i], lw=1.2, color=f"C{o}", label=c)
            if q > 1:
                a.plot(f, fr.multiple_coherence[o], lw=0.8, ls=":", color=f"C{o}",
                       label=f"{c}, multiple")
        a.axhline(COHERENCE_OK, color="0.5", lw=0.6)
        a.set_ylim(0, 1.02)
        _log_frequency_axis(a)
        a.set_ylabel(f"coherence with {inp}" + (" (partial)" if q > 1 else "") + " [-]")
        a.grid(True, which="both", alpha=0.3)
        a.legend(fontsize="small", ncol=2)
    ax[-1, 0].set_xlabel("frequency [Hz]")
    fig.suptitle(title or "Measured flap against the inputs: coherence (composite of "
                          + ", ".join(f"{w:.3g}" for w in fr.windows_s) + " s windows)")
    if path is not None:
        save_png(fig, path)
    return fig


__all__ = ["new_figure", "save_png", "time_response_plot", "frequency_response_plot",
           "error_spectrum_plot", "residual_spectrum_plot", "coherence_plot",
           "manoeuvre_window", "FLAP_LABELS", "CONTROL_COLOURS"]
