"""Bode plots of non-parametric frequency responses (:mod:`inflowsim.identify.frf`):
magnitude [dB], phase [deg] and coherence, with the error bands, and models on top.

Computing stays in :func:`inflowsim.identify.frf.frequency_response`; this module
only draws its :class:`~inflowsim.identify.frf.FrequencyResponse`
(:func:`inflowsim.report.plots.frequency_response_plot` draws a validation through
it).
"""
from __future__ import annotations

import numpy as np

from .plots import new_figure, save_png
from .style import ROLE_COLOURS, align_phase_deg, log_frequency_axis, model_colours

#: Half-width of the error bands, in stated errors (about 95 % for a Gaussian).
BAND_SIGMA = 2.0


def wrap_deg(phase_deg):
    """Phase wrapped to (-180, 180] deg."""
    p = np.mod(np.asarray(phase_deg, dtype=float) + 180.0, 360.0) - 180.0
    return np.where(p == -180.0, 180.0, p)


def phase_deg(h, unwrap: bool = False):
    """Phase of ``h`` [deg]: wrapped to +-180 unless ``unwrap`` (along the last axis,
    NaNs skipped)."""
    ph = np.angle(h)
    if not unwrap:
        return wrap_deg(np.degrees(ph))
    out = np.full(ph.shape, np.nan)
    ok = np.isfinite(ph)
    out[ok] = np.unwrap(ph[ok])
    return np.degrees(out)


def _break_wraps(ph):
    """NaN at each point that follows a +-180 deg wrap, so no line crosses the plot."""
    jump = np.abs(np.diff(ph, prepend=ph[:1])) > 180
    return np.where(jump, np.nan, ph)


def frequency_response_plot(fr, pairs=None, models=None, path=None, unwrap: bool = True,
                            threshold=None, title=None):
    """Bode plot of measured responses with error bands and models overlaid.

    Parameters
    ----------
    fr : FrequencyResponse
    pairs : sequence of (output, input), optional
        Responses to draw, one column each (default every pair).
    models : mapping of label to complex array, optional
        Model responses on ``fr.frequency_hz``, shaped like ``fr.h``
        ``(outputs, inputs, nf)``; drawn as lines.
    path : path-like, optional
        Save as PNG there.
    unwrap : bool
        Unwrap the phases (the default; each model on the measurement's branch);
        ``False``: wrapped to +-180 deg (the axis says which).
    threshold : float, optional
        Coherence below which points are drawn faint (default
        :data:`~inflowsim.identify.frf.COHERENCE_OK`).

    Returns
    -------
    matplotlib.figure.Figure
        Rows: magnitude [dB], phase [deg], coherence [-]; bands
        ``+-BAND_SIGMA`` times the stated error ``sqrt(eps^2 + bias^2)``.
    """
    from matplotlib.ticker import FormatStrFormatter, NullFormatter

    from ..identify.frf import COHERENCE_OK
    thr = COHERENCE_OK if threshold is None else threshold
    if pairs is None:
        pairs = [(o, i) for i in fr.inputs for o in fr.outputs]
    pairs = list(pairs)
    fig, axes = new_figure(3, len(pairs), size=(3.2 * len(pairs) + 1.0, 7.0))
    f = fr.frequency_hz
    meas = ROLE_COLOURS["measured"]
    colours = model_colours(len(models or {}))
    for col, (out, inp) in enumerate(pairs):
        o, i = fr.index(out, inp)
        h = fr.h[o, i]
        err = np.hypot(fr.random_error[o, i], fr.bias_error[o, i])
        good = fr.coherence[o, i] >= thr
        mag = 20 * np.log10(np.abs(h))
        ph = phase_deg(h, unwrap)
        ax_m, ax_p, ax_c = axes[0, col], axes[1, col], axes[2, col]
        lo = 20 * np.log10(np.maximum(1 - BAND_SIGMA * err, 1e-3))
        hi = 20 * np.log10(1 + BAND_SIGMA * err)
        band = good & np.isfinite(err)
        ax_m.fill_between(f, np.where(band, mag + lo, np.nan), np.where(band, mag + hi, np.nan),
                          color=meas, alpha=0.15, lw=0, label=f"±{BAND_SIGMA:g} error")
        ax_m.plot(f, np.where(good, mag, np.nan), ".-", color=meas, ms=3, lw=0.8,
                  label="measured")
        ax_m.plot(f, np.where(good, np.nan, mag), ".", color="0.7", ms=3,
                  label=f"coherence < {thr:g}")
        dph = np.degrees(BAND_SIGMA * err)
        ax_p.fill_between(f, np.where(band, ph - dph, np.nan), np.where(band, ph + dph, np.nan),
                          color=meas, alpha=0.15, lw=0)
        ax_p.plot(f, np.where(good, ph if unwrap else _break_wraps(ph), np.nan), ".-",
                  color=meas, ms=3, lw=0.8)
        ax_p.plot(f, np.where(good, np.nan, ph), ".", color="0.7", ms=3)
        for k, (label, hm) in enumerate((models or {}).items()):
            hm = np.asarray(hm)[o, i]
            ax_m.plot(f, 20 * np.log10(np.abs(hm)), "-", color=colours[k], lw=1.3,
                      label=label)
            php = phase_deg(hm, unwrap)
            php = align_phase_deg(php, ph, good) if unwrap else _break_wraps(php)
            ax_p.plot(f, php, "-", color=colours[k], lw=1.3)
        ax_c.plot(f, fr.coherence[o, i], "-", color=meas, lw=1,
                  label="partial" if len(fr.inputs) > 1 else "coherence")
        if len(fr.inputs) > 1:
            ax_c.plot(f, fr.multiple_coherence[o], "k:", lw=1, label="multiple")
            ax_c.plot(f, fr.ordinary_coherence[o, i], "--", color="0.5", lw=0.8,
                      label="ordinary")
        ax_c.axhline(thr, color="0.5", lw=0.6)
        ax_c.set_ylim(0, 1.05)
        ax_c.set_ylabel(r"coherence $\gamma^2$ [-]" if col == 0 else "")
        ax_m.set_title(f"{out} / {inp}", fontsize=9)
        for ax in (ax_m, ax_p, ax_c):
            log_frequency_axis(ax)
            ax.grid(True, which="both", lw=0.3)
        if not unwrap:
            ax_p.set_ylim(-180, 180)
            ax_p.set_yticks([-180, -90, 0, 90, 180])
        ax_c.set_xlabel("frequency [Hz]")
        if col == 0:
            ax_m.set_ylabel("magnitude [dB]")
            ax_p.set_ylabel("phase, unwrapped [deg]" if unwrap else "phase [deg]")
            ax_m.legend(fontsize=7, loc="best")
            ax_c.legend(fontsize=7, loc="lower left")
    fig.suptitle(title or "Frequency responses (" + ", ".join(fr.sources) + ")",
                 fontsize=10)
    if path is not None:
        save_png(fig, path)
    return fig


__all__ = ["BAND_SIGMA", "wrap_deg", "phase_deg", "frequency_response_plot"]
