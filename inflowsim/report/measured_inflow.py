"""Figures and tables of the comparison with measured inflow (NASA LV surveys).

Computing stays in :mod:`inflowsim.identify.inflow_survey`; every ``*_plot`` takes
its :class:`~inflowsim.identify.inflow_survey.MeasuredInflowComparison`, returns a
Figure and, given ``path``, saves it as PNG.
"""
from __future__ import annotations

import numpy as np

from ..identify.inflow_survey import eq6
from ..model.steady_inflow import LABELS, THEORIES
from .plots import new_figure, save_png

#: Theories drawn, with their line styles.
STYLES = {
    "momentum": dict(color="tab:blue", ls="--"),
    "momentum-mass-flow": dict(color="tab:cyan", ls=":"),
    "skewed-wake": dict(color="tab:red", ls="-"),
    "glauert-table3": dict(color="tab:purple", ls="-."),
}
#: Azimuths of the radial cuts [deg]: aft, advancing, front, retreating.
CUTS = (0, 90, 180, 300)
DPI = 80


def radial_cuts_plot(comparison, path=None, cuts=CUTS):
    """Measured inflow against ``r/R`` at several azimuths, one row per ``mu``, with
    the Eq. (6) fit and the model's trim inflow of each theory."""
    cases = comparison.cases
    fig, axes = new_figure(len(cases), len(cuts), size=(10.0, 2.3 * len(cases) + 0.6),
                           sharex=True)
    rr = np.linspace(0.0, 1.0, 21)
    for i, case in enumerate(cases):
        s = case.survey
        for j, az in enumerate(cuts):
            ax = axes[i, j]
            near = np.isclose(np.degrees(s.psi), az) & (s.r <= 1.0)
            ax.errorbar(s.r[near], s.lambda_i[near], yerr=s.sigma[near], fmt="o", ms=3,
                        color="k", elinewidth=0.6, capsize=0, label="measured (LV, +-std)")
            psi = np.radians(az)
            ax.plot(rr, eq6(case.fit.estimate, psi, rr), color="0.45", lw=2.5, alpha=0.6,
                    label="Eq. (6) fit")
            for th, st in STYLES.items():
                ax.plot(rr, eq6(case.prediction(th).harmonics, psi, rr), lw=1.3,
                        label=LABELS[th], **st)
            ax.axhline(0.0, color="0.8", lw=0.6)
            if not near.any():
                ax.text(0.5, 0.5, "no cut", transform=ax.transAxes, ha="center",
                        color="0.5")
            ax.set_ylim(-0.03, 0.08)
            if i == 0:
                ax.set_title(rf"$\psi$ = {az} deg")
            if j == 0:
                ax.set_ylabel(rf"$\mu$ = {case.mu:.2f}" + "\n" + r"$\lambda_i$ (down +)")
            if i == len(cases) - 1:
                ax.set_xlabel("r/R")
    axes[0, -1].legend(fontsize=6, loc="upper left")
    if path is not None:
        save_png(fig, path, dpi=DPI)
    return fig


def harmonics_plot(comparison, path=None):
    """``lambda0, lambda1c, lambda1s`` against ``mu``: fitted (1-sigma bars, the
    equal-weight fit beside) and each theory."""
    cases = comparison.cases
    mu = comparison.mu
    fig, axes = new_figure(1, 3, size=(10.0, 3.3), sharex=True)
    names = (r"$\lambda_0$", r"$\lambda_{1c}$", r"$\lambda_{1s}$")
    for k, ax in enumerate(axes[0]):
        est = np.array([c.fit.estimate[k] for c in cases])
        sig = np.array([c.fit.sigma[k] for c in cases])
        eqw = np.array([c.fit.equal_weights[k] for c in cases])
        ax.errorbar(mu, est, yerr=sig, fmt="o", color="k", capsize=3,
                    label="measured, WLS fit +-1 sigma")
        ax.plot(mu + 0.006, eqw, "s", mfc="none", color="0.4", ms=5,
                label="measured, equal weights")
        for th, st in STYLES.items():
            pr = np.array([c.prediction(th).harmonics[k] for c in cases])
            ps = np.array([c.prediction(th).sigma[k] for c in cases])
            ax.plot(mu, pr, marker=".", label=LABELS[th], **st)
            if ps.any():
                ax.fill_between(mu, pr - ps, pr + ps, color=st["color"], alpha=0.12)
        ax.axhline(0.0, color="0.8", lw=0.6)
        ax.set_title(names[k])
        ax.set_xlabel(r"$\mu$")
    axes[0, 0].legend(fontsize=6)
    if path is not None:
        save_png(fig, path, dpi=DPI)
    return fig


def disc_plot(comparison, path=None, theory="skewed-wake"):
    """Over the disc: measured inflow (filled contours of the stations), the Eq. (6)
    fit, ``theory``'s trim inflow and the fit's residual, one row per ``mu``.
    ``psi = 0`` aft points down the page (the free stream comes from the top)."""
    from matplotlib.tri import Triangulation

    cases = comparison.cases
    fig, axes = new_figure(len(cases), 4, size=(10.0, 2.5 * len(cases) + 0.5),
                           sharex=True)
    levels = np.linspace(-0.03, 0.07, 11)
    rlev = np.linspace(-0.025, 0.025, 11)
    rg, pg = np.meshgrid(np.linspace(0.2, 1.0, 17), np.radians(np.arange(0, 361, 10)))
    # x forward (psi = 180 deg) up the page, y to starboard (psi = 90 deg) right
    xg, yg = -rg * np.cos(pg), rg * np.sin(pg)
    for i, case in enumerate(cases):
        s = case.survey
        rows = case.fit.rows
        x, y = -s.r[rows] * np.cos(s.psi[rows]), s.r[rows] * np.sin(s.psi[rows])
        tri = Triangulation(y, x)
        # the hub is not surveyed: no contour across it
        cx, cy = x[tri.triangles].mean(axis=1), y[tri.triangles].mean(axis=1)
        tri.set_mask(np.hypot(cx, cy) < 0.18)
        panels = (
            ("measured", lambda ax: ax.tricontourf(tri, s.lambda_i[rows], levels=levels,
                                                   cmap="viridis", extend="both")),
            ("Eq. (6) fit", lambda ax: ax.contourf(yg, xg, eq6(case.fit.estimate, pg, rg),
                                                   levels=levels, cmap="viridis",
                                                   extend="both")),
            (LABELS[theory], lambda ax: ax.contourf(
                yg, xg, eq6(case.prediction(theory).harmonics, pg, rg), levels=levels,
                cmap="viridis", extend="both")),
            ("measured - fit", lambda ax: ax.tricontourf(tri, case.fit.residuals,
                                                         levels=rlev, cmap="RdBu_r",
                                                         extend="both")),
        )
        for j, (title, draw) in enumerate(panels):
            ax = axes[i, j]
            cs = draw(ax)
            ax.plot(y, x, ".", color="k", ms=1.2)
            t = np.linspace(0, 2 * np.pi, 100)
            ax.plot(np.cos(t), np.sin(t), color="0.3", lw=0.6)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            if i == 0:
                ax.set_title(title, fontsize=8)
            if j == 0:
                ax.set_ylabel(rf"$\mu$ = {case.mu:.2f}" + "\n(front up, advancing right)",
                              fontsize=7)
            if j in (2, 3):
                fig.colorbar(cs, ax=ax, shrink=0.8)
    if path is not None:
        save_png(fig, path, dpi=DPI)
    return fig


def comparison_table(comparison) -> str:
    """Markdown: per ``mu`` and harmonic, the fitted value +- inflated 1-sigma, the
    equal-weight fit and each theory with its discrepancy in sigmas."""
    theories = THEORIES
    head = ("| mu | harmonic | measured (WLS +- 1 sigma) | equal weights | "
            + " | ".join(LABELS[t] for t in theories) + " |")
    lines = [head, "|" + " --- |" * (4 + len(theories))]
    for c in comparison.cases:
        for k, name in enumerate(("lambda0", "lambda1c", "lambda1s")):
            cells = [f"{c.mu:.3f}", f"`{name}`",
                     f"{c.fit.estimate[k]:.4f} +- {c.fit.sigma[k]:.4f}",
                     f"{c.fit.equal_weights[k]:.4f}"]
            for t in theories:
                pr = c.prediction(t)
                z = c.discrepancy(t)[k]
                sig = f" +- {pr.sigma[k]:.4f}" if pr.sigma[k] else ""
                cells.append(f"{pr.harmonics[k]:.4f}{sig} ({z:+.1f})")
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def fit_table(comparison) -> str:
    """Markdown: the fit's diagnostics per survey."""
    lines = ["| mu | points | chi2/dof | residual rms | variance explained | area mean "
             "(from r/R) | rho radial | rho azimuthal | white | inflation | sigma scatter "
             "(l0, l1c, l1s) | sigma cluster | outliers (file lines) |", "|" + " --- |" * 13]
    for c in comparison.cases:
        f = c.fit
        lines.append(
            f"| {c.mu:.3f} | {f.n_points} | {f.chi2_reduced:.2f} | {f.residual_rms:.4f} | "
            f"{f.explained:.2f} | {c.area_mean[0]:.4f} ({c.area_mean[1]:g}) | "
            f"{f.rho_radial:.2f} | {f.rho_azimuthal:.2f} | {'yes' if f.white else 'no'} | "
            f"{f.inflation:.2f} | {', '.join(f'{x:.4f}' for x in f.sigma_scatter)} | "
            f"{', '.join(f'{x:.4f}' for x in f.sigma_cluster)} | "
            f"{', '.join(map(str, f.outliers)) or '-'} |")
    return "\n".join(lines) + "\n"


def conditions_table(comparison) -> str:
    """Markdown: the run conditions as used (SI / model conventions)."""
    lines = ["| file | mu (V cos a / Omega R) | muz | C_T | shaft (deg) | theta1c (deg) | "
             "theta1s (deg) | chi (deg) | k_skew | mass-flow V |", "|" + " --- |" * 10]
    for c in comparison.cases:
        k = c.survey.conditions
        sw = dict(c.prediction("skewed-wake").gains)
        mf = dict(c.prediction("momentum-mass-flow").gains)
        lines.append(f"| `{c.survey.file}` | {k.mu:.4f} | {k.muz:.4f} | {k.ct:g} | "
                     f"{np.degrees(k.shaft_angle):.2f} | {np.degrees(k.theta1c):.2f} | "
                     f"{np.degrees(k.theta1s):.2f} | {np.degrees(sw['chi']):.1f} | "
                     f"{sw['k_skew']:.3f} | {mf['V']:.4f} |")
    return "\n".join(lines) + "\n"


__all__ = ["radial_cuts_plot", "harmonics_plot", "disc_plot", "comparison_table",
           "fit_table", "conditions_table"]
