"""The map of missing terms: equation x variable, coloured by ``-log10 p``.

Draws a :class:`~inflowsim.diagnose.terms.MissingTerms` (computing stays in
:mod:`inflowsim.diagnose.terms`): one row per equation (flap, inflow, the recorded
flap of the measurement map), one column per variable, then one per variable of
the lagged entries (a slow state driven by it, ``T w' + w = v``: right of the
thick line, marked ``lag``); the colour is the score test's unadjusted
``-log10 p``, the significant entries (Holm-corrected) are
framed and carry the sign of the term the data want; the top entry of the
ranking (confirmed by a refit with it free, ``Term.refit_statistic``) is framed in
orange and named in the title.  Grey: not tested (a flap rate in the measurement
map) or not testable (confounded with the base's own parameters, or a silent
input).
"""
from __future__ import annotations

import numpy as np

from .plots import new_figure, save_png

__all__ = ["missing_terms_plot"]

_TEX = {"beta0": r"$\beta_0$", "beta1c": r"$\beta_{1c}$", "beta1s": r"$\beta_{1s}$",
        "beta0_prime": r"$\beta_0'$", "beta1c_prime": r"$\beta_{1c}'$",
        "beta1s_prime": r"$\beta_{1s}'$", "lambda0": r"$\lambda_0$",
        "lambda1c": r"$\lambda_{1c}$", "lambda1s": r"$\lambda_{1s}$",
        "theta0": r"$\theta_0$", "theta1c": r"$\theta_{1c}$", "theta1s": r"$\theta_{1s}$",
        "muz": r"$\mu_z$", "q": "$q$", "p": "$p$", "qdot": r"$\dot q$",
        "pdot": r"$\dot p$", "mux": r"$\mu_x$", "muy": r"$\mu_y$"}
_BLOCK = {"flap": "flap eq.", "inflow": "inflow eq.", "measurement": "recorded",
          "pitch": "fed into the pitch"}


def missing_terms_plot(terms, path=None, title=None):
    """Equation x variable map of a score map; returns the Figure (PNG at ``path``).

    Parameters
    ----------
    terms : MissingTerms
    path : path, optional
        Where to save the PNG.
    title : str, optional
    """
    grid = terms.grid()
    columns = terms.columns
    fig, axes = new_figure(1, 1, size=(10.0 + 0.3 * len(terms.lagged), 4.8), sharex=False)
    ax = axes[0, 0]
    cmap = _cmap()
    vmax = max(3.0, float(np.nanmax(grid)) if np.isfinite(grid).any() else 3.0)
    im = ax.imshow(np.ma.masked_invalid(grid), cmap=cmap, vmin=0.0, vmax=vmax,
                   aspect="auto", interpolation="nearest")
    ax.set_xticks(range(len(columns)))
    ax.set_xticklabels([_TEX.get(v, v) + ("\nlag" if lag else "") for v, lag in columns],
                       fontsize=8 if terms.lagged else None)
    ax.set_yticks(range(len(terms.equations)))
    ax.set_yticklabels([f"{_BLOCK[b]} {_TEX.get(e, e)}" for b, e in terms.equations])
    ri = {e: i for i, e in enumerate(terms.equations)}
    ci = {c: j for j, c in enumerate(columns)}
    from matplotlib.patches import Rectangle
    for t in terms.significant:
        if (t.block, t.equation) not in ri or (t.variable, t.lag or None) not in ci:
            continue        # a pitch entry (several rows): named in the title
        i, j = ri[(t.block, t.equation)], ci[(t.variable, t.lag or None)]
        ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, lw=2.0,
                               edgecolor="red"))
        ax.text(j, i, "+" if t.direction > 0 else "\u2212", ha="center", va="center",
                color="white", fontsize=11, fontweight="bold")
    top = next((t for t in terms.terms if t.testable), None)
    if top is not None and top.refit_statistic is not None and top.significant(terms.alpha):
        if (top.block, top.equation) in ri and (top.variable, top.lag or None) in ci:
            i, j = ri[(top.block, top.equation)], ci[(top.variable, top.lag or None)]
            ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, lw=3.0,
                                   edgecolor="orange"))
    else:
        top = None
    for y in (2.5, 5.5):
        ax.axhline(y, color="black", lw=1.0)
    for x in (2.5, 5.5, 8.5):
        ax.axvline(x, color="black", lw=0.6)
    if terms.lagged:
        n = len(terms.variables)
        ax.axvline(n - 0.5, color="black", lw=2.0)
        for x in (2.5, 5.5):
            ax.axvline(n + x, color="black", lw=0.6)
    ax.set_xlabel("variable the term is proportional to" + (
        "" if not terms.lagged else f"; lag: a slow state it drives (first-order lag of "
        f"{terms.lag:.3g} s)"))
    cb = fig.colorbar(im, ax=ax)
    cb.set_label(r"$-\log_{10} p$ (score test, 1 dof)")
    first = ("" if top is None else
             f"; first by refit: {top.equation} x {top.label} ({_BLOCK[top.block]})")
    ax.set_title(title or f"Where a term is missing in {terms.structure}: "
                 f"{len(terms.significant)} of {terms.n_tested} entries significant "
                 f"(Holm, {terms.alpha:g}){first}", fontsize=9)
    if path is not None:
        save_png(fig, path)
    return fig


def _cmap():
    from matplotlib import colormaps
    return colormaps["viridis"].with_extremes(bad="0.85")
