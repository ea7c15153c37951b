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
    ``None`` where the table holds no estimate."""
    names = [c[4:] for c in df.columns if c.startswith("est_")]
    ok = df[df["status"] == "ok"]
    names = [n for n in names if ok[f"est_{n}"].notna().any()]
    if not names or ok.empty:
        return None
    ncol = min(3, len(names))
    nrow = math.ceil(len(names) / ncol)
    fig, axes = new_figure(nrow, ncol, size=(4.0 * ncol, 2.6 * nrow), sharex=False)
    for ax, n in zip(axes.ravel(), names):
        for kind, style, label in (("record", "o", "record"),
                                   ("condition", "s", "condition (joint)")):
            sub = ok[(ok["kind"] == kind) & ok[f"est_{n}"].notna()]
            if sub.empty:
                continue
            sig = sub.get(f"sigma_{n}")
            ax.errorbar(sub["mu"], sub[f"est_{n}"],
                        yerr=None if sig is None else sig.fillna(0.0), fmt=style,
                        ms=4 if kind == "record" else 6, capsize=2, label=label,
                        alpha=0.6 if kind == "record" else 1.0)
        if schedule is not None and n in schedule.names:
            p = schedule[n]
            lo, hi = schedule.mu_range
            m = np.linspace(lo, hi, 60)
            v = np.array([p.value(x) for x in m])
            b = np.array([p.bound(x) for x in m])
            ax.plot(m, v, "-", color="C3", lw=1.2,
                    label=f"schedule (order {p.order}"
                          f"{', constant would do' if p.constant else ''})")
            ax.fill_between(m, v - b, v + b, color="C3", alpha=0.15, lw=0)
            xs = ok["mu"].dropna()
            if len(xs) and xs.min() < lo:           # held beyond the range
                ax.plot([xs.min(), lo], [v[0], v[0]], "--", color="C3", lw=1.0)
            if len(xs) and xs.max() > hi:
                ax.plot([hi, xs.max()], [v[-1], v[-1]], "--", color="C3", lw=1.0)
            ax.legend(fontsize=6)
        # the estimates set the scale: a record that does not determine a
        # parameter (a bound of thousands) must not flatten everyone else's
        # (the joint estimates, and the middle 80 % of the records')
        v = ok[f"est_{n}"].dropna().to_numpy(dtype=float)
        joint = ok[ok["kind"] == "condition"][f"est_{n}"].dropna().to_numpy(dtype=float)
        lo, hi = np.percentile(v, [10, 90])
        if joint.size:
            lo, hi = min(lo, joint.min()), max(hi, joint.max())
        pad = 0.3 * (hi - lo) or 0.1 * max(abs(hi), 1e-12)
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_title(n)
        ax.set_xlabel(r"$\mu$")
        ax.grid(alpha=0.3)
    for ax in axes.ravel()[len(names):]:
        ax.set_visible(False)
    axes.ravel()[0].legend(fontsize=7)
    if path is not None:
        save_png(fig, path)
    return fig
