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
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..data.record import FLAP_COLUMNS
from ..channels import CONTROLS
from ..fileio import atomic_path

#: Axis labels of the flap channels (units: degrees on plots, radians inside).
FLAP_LABELS = {"beta0": r"$\beta_0$", "beta1c": r"$\beta_{1c}$", "beta1s": r"$\beta_{1s}$"}
DPI = 110


def new_figure(nrows=1, ncols=1, size=(8.0, 6.0), sharex=True):
    """A figure on an Agg canvas and its axes array (always 2-D)."""
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


def time_response_plot(results, path=None, show_inputs: bool = False, title=None):
    """Measured against predicted multiblade flap against time.

    Parameters
    ----------
    results : ValidationResult or sequence of them
        One or several models on the same record; the measured flap is taken
        from the first.
    path : path-like, optional
        Save the figure there as PNG.
    show_inputs : bool
        Add a panel with the pilot control perturbations [deg].
    title : str, optional
        Default names the structure(s) and the record.

    Returns
    -------
    matplotlib.figure.Figure
    """
    res = _as_list(results)
    r0 = res[0]
    n = 3 + bool(show_inputs)
    fig, ax = new_figure(n, 1, size=(8.0, 2.1 * n + 0.6))
    for i, c in enumerate(FLAP_COLUMNS):
        a = ax[i, 0]
        a.plot(r0.t, np.degrees(r0.measured[:, i]), color="k", lw=1.0, label="measured")
        for r in res:
            a.plot(r.t, np.degrees(r.predicted[:, i]), lw=1.2, label=f"{r.structure} "
                   f"(fit {r.channels[c].fit_percent:.1f} % over {r.band_hz[0]:.3g}-"
                   f"{r.band_hz[1]:.3g} Hz)")
        a.set_ylabel(f"{FLAP_LABELS[c]} [deg]")
        a.grid(True, alpha=0.3)
        a.legend(loc="upper right", fontsize="small")
    if show_inputs:
        a = ax[3, 0]
        for j, name in enumerate(r0.inputs):
            if name in CONTROLS and np.ptp(r0.u[:, j]) > 1e-9:
                a.plot(r0.t, np.degrees(r0.u[:, j]), lw=1.0, label=name)
        a.set_ylabel("pitch [deg]")
        a.grid(True, alpha=0.3)
        a.legend(loc="upper right", fontsize="small")
    ax[-1, 0].set_xlabel("time [s]")
    names = ", ".join(r.structure for r in res)
    fig.suptitle(title or f"Flap perturbations about trim: measured and {names} "
                 f"({Path(r0.source).name})")
    if path is not None:
        save_png(fig, path)
    return fig


def frequency_response_plot(results, path=None, title=None):
    """Magnitude [dB] and phase [deg] of the flap responses against frequency.

    Measured responses (markers) are ratios of the measured flap DFT to the
    reference input DFT; model responses (lines) are the predicted flap over the
    same input DFT (``validation`` module).  One column per flap channel.

    Parameters
    ----------
    results : ValidationResult or sequence of them
        Models compared on one record; measured taken from the first.
    path : path-like, optional
        Save as PNG.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    res = _as_list(results)
    f0 = res[0].frequency
    fig, ax = new_figure(2, 3, size=(11.0, 6.0))
    for i, c in enumerate(FLAP_COLUMNS):
        am, ap = ax[0, i], ax[1, i]
        am.plot(f0.f_hz, f0.magnitude_db(f0.measured[i]), "ko", ms=3.5, label="measured")
        ap.plot(f0.f_hz, f0.phase_deg(f0.measured[i]), "ko", ms=3.5, label="measured")
        for r in res:
            fr = r.frequency
            lab = (f"{r.structure} ({r.magnitude_rms_db[c]:.2f} dB, "
                   f"{r.phase_rms_deg[c]:.1f}°)")
            am.plot(fr.f_hz, fr.magnitude_db(fr.model[i]), lw=1.3, label=lab)
            ap.plot(fr.f_hz, fr.phase_deg(fr.model[i]), lw=1.3, label=r.structure)
        am.set_title(f"{FLAP_LABELS[c]} / {f0.reference_input}")
        am.set_ylabel("magnitude [dB]")
        ap.set_ylabel("phase [deg]")
        ap.set_xlabel("frequency [Hz]")
        for a in (am, ap):
            a.grid(True, alpha=0.3)
        am.legend(fontsize="x-small")
    names = ", ".join(r.structure for r in res)
    fig.suptitle(title or f"Flap frequency responses: measured and {names}, band "
                 f"{res[0].band_hz[0]:.4g}-{res[0].band_hz[1]:.4g} Hz")
    if path is not None:
        save_png(fig, path)
    return fig


def error_spectrum_plot(results: Sequence, path=None, title=None):
    """Magnitude error [dB] and phase error [deg] against frequency per channel."""
    res = _as_list(results)
    fig, ax = new_figure(2, 1, size=(8.0, 5.5))
    styles = ("-", "--", ":", "-.")
    for k, r in enumerate(res):              # colour per channel, line style per model
        fr = r.frequency
        ls = styles[k % len(styles)]
        for i, c in enumerate(FLAP_COLUMNS):
            lab = f"{c} ({r.structure})" if len(res) > 1 else c
            kw = dict(lw=1.2, ls=ls, color=f"C{i}", label=lab)
            ax[0, 0].plot(fr.f_hz, fr.magnitude_error_db[i], **kw)
            ax[1, 0].plot(fr.f_hz, fr.phase_error_deg[i], **kw)
    ax[0, 0].set_ylabel("magnitude error [dB]")
    ax[1, 0].set_ylabel("phase error [deg]")
    ax[1, 0].set_xlabel("frequency [Hz]")
    for a in ax[:, 0]:
        a.axhline(0.0, color="k", lw=0.6)
        a.grid(True, alpha=0.3)
        a.legend(fontsize="x-small", ncol=3)
    fig.suptitle(title or "Measured over model response (0 dB, 0° is a perfect match)")
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


def coherence_plot(results, path=None, title=None, segment_s=None):
    """Coherence of each measured flap channel with the reference input.

    Where it is near 1 the flap is a linear response to that input; where it falls,
    noise, other inputs or nonlinearity dominate, and no model can match those
    frequencies. Welch estimate (``scipy.signal.coherence``, Hann windows of
    ``segment_s`` seconds, default a quarter of the record, 50 % overlap); the
    analysis band is shaded.
    """
    from scipy.signal import coherence
    r0 = _as_list(results)[0]
    fs = 1.0 / float(r0.t[1] - r0.t[0])
    n = len(r0.t)
    nper = int(min(n, max(16, round((segment_s or n / fs / 4) * fs))))
    ref = r0.frequency.reference_input
    x = r0.u[:, r0.inputs.index(ref)]
    fig, ax = new_figure(1, 1, size=(8.0, 3.8))
    a = ax[0, 0]
    for i, c in enumerate(FLAP_COLUMNS):
        f, g = coherence(x, r0.measured[:, i], fs=fs, nperseg=nper)
        keep = f <= max(3 * r0.band_hz[1], 2.0)
        a.plot(f[keep], g[keep], lw=1.2, label=c)
    a.axvspan(*r0.band_hz, color="0.85", zorder=0, label="analysis band")
    a.set_ylim(0, 1.02)
    a.set_xlabel("frequency [Hz]")
    a.set_ylabel(f"coherence with {ref}")
    a.grid(True, alpha=0.3)
    a.legend(fontsize="small")
    fig.suptitle(title or f"Measured flap against {ref}: coherence "
                          f"({nper / fs:.3g} s segments)")
    if path is not None:
        save_png(fig, path)
    return fig


__all__ = ["new_figure", "save_png", "time_response_plot", "frequency_response_plot",
           "error_spectrum_plot", "residual_spectrum_plot", "coherence_plot",
           "FLAP_LABELS"]
