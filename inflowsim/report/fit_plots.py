"""Plots of a fit: frequency-domain fit (the paper's Figures 1, 2, 4), time-domain
reconstruction (Figures 3, 5), band study (Figure 6).

Computing lives in :mod:`inflowsim.identify`; these functions only draw.  The
convention of every plot of the package (:mod:`.plots`): each returns its
``Figure``, drawn on its own Agg canvas (no pyplot, no global backend switch),
and saves a PNG when given a ``path``.
"""
from __future__ import annotations

import numpy as np

from ..model.equations import FLAP
from ..model.build import build_model
from ..simulate.replay import replay
from .plots import new_figure, save_png


def reconstruction_response(result, index: int = 0):
    """Time-domain reconstruction of record ``index``: ``(t, measured, predicted)``
    flap perturbations ``(N, 3)``; the model replayed with the record's inputs from
    the estimated initial state (the end-effect ``x_0``)."""
    d = result.data[index]
    m = build_model(result.structure, result.parameters, d.constants)
    y = replay(m, d.u_time, d.dt, d.hold, x0=d.x0)[:, :3]
    t = np.arange(len(d.u_time)) * d.dt
    return t, d.z_time, y


def _done(fig, path):
    if path is not None:
        save_png(fig, path, dpi=100)
    return fig


def _unwrapped_deg(h):
    ph = np.angle(h)
    out = np.full(ph.shape, np.nan)
    ok = np.isfinite(ph)
    out[ok] = np.unwrap(ph[ok])
    return np.degrees(out)


def fit_plot(result, path=None, index: int = 0, colour=None):
    """Measured against predicted flap transforms, magnitude [dB] and phase [deg]
    (unwrapped, the model on the measurement's branch).  ``colour``: the model's
    (default the base model's, :mod:`.style`)."""
    from .style import ROLE_COLOURS, align_phase_deg, frequency_label, model_colours
    colour = colour or model_colours(1)[0]
    meas = ROLE_COLOURS["measured"]
    d = result.data[index]
    fig, ax = new_figure(2, 3, size=(12, 6))
    for i, ch in enumerate(FLAP):
        pz = _unwrapped_deg(d.Z[:, i])
        py = align_phase_deg(_unwrapped_deg(d.Y[:, i]), pz)
        ax[0, i].plot(d.f_hz, 20 * np.log10(np.abs(d.Z[:, i])), ".", color=meas,
                      label="measured")
        ax[0, i].plot(d.f_hz, 20 * np.log10(np.abs(d.Y[:, i])), "-", color=colour,
                      label=f"model {result.structure.name}")
        ax[1, i].plot(d.f_hz, pz, ".", color=meas)
        ax[1, i].plot(d.f_hz, py, "-", color=colour)
        ax[0, i].set_title(ch)
        ax[1, i].set_xlabel(frequency_label())
        for a in ax[:, i]:
            a.grid(True, alpha=0.3)
    ax[0, 0].set_ylabel("magnitude [dB rad]")
    ax[1, 0].set_ylabel("phase, unwrapped [deg]")
    ax[0, 0].legend()
    fig.suptitle(f"{result.structure.name}: frequency-domain fit, {d.source}")
    return _done(fig, path)


def reconstruction_plot(result, path=None, index: int = 0, colour=None):
    """Measured and reconstructed flap perturbations against time.  ``colour``: the
    model's (default the base model's, :mod:`.style`)."""
    from .style import ROLE_COLOURS, model_colours
    colour = colour or model_colours(1)[0]
    t, z, y = reconstruction_response(result, index)
    fig, axes = new_figure(3, 1, size=(10, 7))
    ax = axes[:, 0]
    for i, ch in enumerate(FLAP):
        ax[i].plot(t, np.degrees(z[:, i]), "-", color=ROLE_COLOURS["measured"], lw=0.8,
                   label="measured")
        ax[i].plot(t, np.degrees(y[:, i]), "--", color=colour, lw=1.0,
                   label=f"model {result.structure.name}")
        ax[i].set_ylabel(f"{ch} [deg]")
        ax[i].grid(True, alpha=0.3)
    ax[0].legend()
    ax[-1].set_xlabel("time [s]")
    fig.suptitle(f"{result.structure.name}: time-domain reconstruction")
    return _done(fig, path)


def panel_grid(n: int, max_cols: int = 5) -> tuple[int, int]:
    """``(rows, columns)`` for ``n`` panels: at most ``max_cols`` columns, the fewest
    empty panels (then the most columns; two columns only up to six panels, so the
    figure does not grow a long thin column), so no row is left mostly empty (three
    parameters in four columns left a quarter of the figure blank)."""
    if n <= max_cols:
        return 1, max(n, 1)
    cols = [c for c in range(2, max_cols + 1) if c > 2 or n <= 6]
    best = min(cols, key=lambda c: ((-n) % c, -c))
    return -(-n // best), best


def band_study_plot(study, path=None):
    """Estimates with 1-sigma bars against the lower band limit (Figure 6), one panel
    per parameter (angles in degrees, each axis with its unit), laid out so that no
    row is left mostly empty (:func:`panel_grid`)."""
    from .units import parameter_label, parameter_unit, parameter_value
    names = list(study.estimates)
    nrow, ncol = panel_grid(len(names))
    fig, ax = new_figure(nrow, ncol, size=(3.2 * ncol, 2.5 * nrow), sharex=False)
    panels = [ax[k // ncol, k % ncol] for k in range(len(names))]
    for a, n in zip(panels, names):
        v = np.array([parameter_value(n, x) for x in study.estimates[n]], dtype=float)
        s = np.array([np.nan if x is None else parameter_value(n, x)
                      for x in study.sigma[n]], dtype=float)
        a.errorbar(study.lower_hz, v, yerr=s, fmt="o-", ms=3, capsize=2)
        a.set_title(parameter_label(n), fontsize=9)
        a.set_ylabel(f"[{parameter_unit(n) or '-'}]", fontsize=8)
    for a in panels:
        a.set_xlabel("lower band limit [Hz]", fontsize=8)
        a.tick_params(labelsize=7)
        a.grid(True, alpha=0.3)
    for k in range(len(panels), nrow * ncol):
        ax[k // ncol, k % ncol].axis("off")
    fig.suptitle(f"{study.structure}: estimates (1-sigma bars) against the lower "
                 f"frequency limit, upper limit {study.upper_hz:.4g} Hz")
    return _done(fig, path)


__all__ = ["reconstruction_response", "fit_plot", "reconstruction_plot", "panel_grid",
           "band_study_plot"]
