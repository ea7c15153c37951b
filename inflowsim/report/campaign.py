"""The campaign's figure: every estimate against ``mu`` with its bounds.

Drawn from the campaign table (:func:`inflowsim.campaign.tables.campaign_table`),
not from the fits: the computing is done and stored before anything is drawn.
"""
from __future__ import annotations

import math

import numpy as np

from .plots import new_figure, save_png


def estimates_vs_mu_plot(df, path=None, schedule=None):
    """One panel per parameter: each record's estimate (dots) and each flight
    condition's joint estimate (squares) against ``mu``, with 1-sigma bars, and
    the parameter's schedule (:class:`inflowsim.model.schedule.Schedule`, if
    given: its polynomial and 1-sigma band over its range, dashed where held).
    Values in the unit :mod:`.units` shows (degrees for angles), named on each
    axis.  The estimates set the vertical scale; a bar that reaches beyond it (a
    record that does not determine the parameter) is not drawn but marked by an
    open triangle at the axis's edge.  ``None`` where the table holds no estimate."""
    from .style import ROLE_COLOURS
    from .units import parameter_label, parameter_value
    names = [c[4:] for c in df.columns if c.startswith("est_")]
    ok = df[df["status"] == "ok"]
    names = [n for n in names if ok[f"est_{n}"].notna().any()]
    if not names or ok.empty:
        return None
    ncol = min(3, len(names))
    nrow = math.ceil(len(names) / ncol)
    fig, axes = new_figure(nrow, ncol, size=(4.0 * ncol, 2.8 * nrow), sharex=False)
    sched = ROLE_COLOURS["schedule"]
    clipped_any = False
    for ax, n in zip(axes.ravel(), names):
        def shown(v):
            return np.array([np.nan if x is None or not np.isfinite(x)
                             else parameter_value(n, x) for x in v], dtype=float)
        # the estimates set the scale: a record that does not determine a
        # parameter (a bound of thousands) must not flatten everyone else's
        # (the joint estimates, and the middle 80 % of the records')
        v = shown(ok[f"est_{n}"].dropna())
        joint = shown(ok[ok["kind"] == "condition"][f"est_{n}"].dropna())
        lo, hi = np.percentile(v, [10, 90])
        if joint.size:
            lo, hi = min(lo, joint.min()), max(hi, joint.max())
        pad = 0.3 * (hi - lo) or 0.1 * max(abs(hi), 1e-12)
        y0, y1 = lo - pad, hi + pad
        for kind, style, label, colour in (
                ("record", "o", "record", "0.35"),
                ("condition", "s", "condition (joint)", ROLE_COLOURS["measured"])):
            sub = ok[(ok["kind"] == kind) & ok[f"est_{n}"].notna()]
            if sub.empty:
                continue
            mu = sub["mu"].to_numpy(dtype=float)
            est = shown(sub[f"est_{n}"])
            sig = (shown(sub[f"sigma_{n}"]) if f"sigma_{n}" in sub
                   else np.full(est.shape, np.nan))
            wide = np.isfinite(sig) & ((est - sig < y0) | (est + sig > y1))
            bars = np.where(np.isfinite(sig) & ~wide, sig, np.nan)
            ax.errorbar(mu, est, yerr=np.nan_to_num(bars), fmt=style,
                        ms=4 if kind == "record" else 6, capsize=2, label=label,
                        color=colour, alpha=0.7 if kind == "record" else 1.0)
            if wide.any():
                clipped_any = True
                ax.plot(mu[wide], np.clip(est[wide], y0, y1), "^", mfc="none",
                        color=colour, ms=7, label=f"{kind}: bound beyond the axis")
        if schedule is not None and n in schedule.names:
            p = schedule[n]
            lo, hi = schedule.mu_range
            m = np.linspace(lo, hi, 60)
            sv = shown([p.value(x) for x in m])
            b = shown([p.bound(x) for x in m])
            ax.plot(m, sv, "-", color=sched, lw=1.2,
                    label=f"schedule (order {p.order}"
                          f"{', constant would do' if p.constant else ''})")
            ax.fill_between(m, sv - b, sv + b, color=sched, alpha=0.15, lw=0)
            xs = ok["mu"].dropna()
            if len(xs) and xs.min() < lo:           # held beyond the range
                ax.plot([xs.min(), lo], [sv[0], sv[0]], "--", color=sched, lw=1.0)
            if len(xs) and xs.max() > hi:
                ax.plot([hi, xs.max()], [sv[-1], sv[-1]], "--", color=sched, lw=1.0)
            ax.legend(fontsize=6)
        ax.set_ylim(y0, y1)
        ax.set_title(n)
        ax.set_ylabel(parameter_label(n), fontsize=8)
        ax.set_xlabel(r"advance ratio $\mu$ [-]")
        ax.grid(alpha=0.3)
    for ax in axes.ravel()[len(names):]:
        ax.set_visible(False)
    axes.ravel()[0].legend(fontsize=7)
    fig.suptitle("Estimates against advance ratio, 1-sigma bars"
                 + ("; open triangles: bound wider than the axis" if clipped_any else ""),
                 fontsize=10)
    if path is not None:
        save_png(fig, path)
    return fig


__all__ = ["estimates_vs_mu_plot"]
