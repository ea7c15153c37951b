"""First-harmonic inflow, Eq. (6), fitted to a measured inflow survey, and the
comparison with the model's trim inflow at the survey's conditions.

``lambda_i = lambda0 + lambda1c r cos psi + lambda1s r sin psi`` (down positive,
over ``Omega R``, ``psi = 0`` aft; ``model.md`` section 1) by weighted least squares
with the tabulated standard deviations as weights.  The 1-sigma bounds come from
the residual scatter (the covariance scaled by the reduced chi-square) and are
inflated where the residuals are not independent: neighbouring stations of one
radial cut share the inflow structure Eq. (6) leaves out, so their residuals are
correlated and the plain least-squares bound is too small.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..channels import INFLOW
from ..errors import InputError
from ..data.nasa_lv import Survey
from ..model.steady_inflow import SteadyInflow, steady_inflow_predictions

#: A lag-1 correlation of the residuals beyond this many standard errors
#: (``1/sqrt(n_pairs)``) says they are not white.
WHITENESS_Z = 2.0
#: A residual beyond this many residual standard deviations is named an outlier
#: (reported, kept).
OUTLIER_Z = 3.5


def eq6(harmonics, psi, r) -> np.ndarray:
    """Eq. (6): ``lambda0 + lambda1c r cos psi + lambda1s r sin psi`` [-]."""
    l0, l1c, l1s = harmonics
    psi, r = np.asarray(psi, float), np.asarray(r, float)
    return l0 + l1c * r * np.cos(psi) + l1s * r * np.sin(psi)


def design(psi, r) -> np.ndarray:
    """Regressors of Eq. (6), columns ``lambda0, lambda1c, lambda1s``."""
    psi, r = np.asarray(psi, float), np.asarray(r, float)
    return np.column_stack([np.ones_like(r), r * np.cos(psi), r * np.sin(psi)])


@dataclass(frozen=True, eq=False)
class HarmonicFit:
    """Eq. (6) fitted to one survey.

    ``estimate`` ``(lambda0, lambda1c, lambda1s)`` [-] (names :data:`NAMES`);
    ``sigma`` their 1-sigma bounds after inflation, ``sigma_scatter`` before (from
    the residual scatter alone), ``sigma_cluster`` the cluster-robust (sandwich,
    radial cuts as clusters) bounds, a cross-check; ``covariance`` the inflated one;
    ``inflation`` the factor applied; ``rho_radial``, ``rho_azimuthal`` the lag-1
    correlations of the weighted residuals between neighbouring stations along a
    radial cut and along a ring; ``white`` whether both lie within
    ``WHITENESS_Z/sqrt(n_pairs)`` of zero; ``chi2_reduced`` the weighted residual
    sum of squares per degree of freedom; ``residual_rms`` [-] unweighted;
    ``equal_weights`` the same fit with equal weights (estimate) and its inflated
    sigma, a sensitivity to the weighting; ``residuals`` measured minus Eq. (6) at
    the fitted rows ``rows`` (indices into the survey); ``outliers`` file lines of
    residuals beyond ``OUTLIER_Z`` residual standard deviations.
    """

    file: str
    mu: float
    estimate: np.ndarray
    sigma: np.ndarray
    sigma_scatter: np.ndarray
    sigma_cluster: np.ndarray
    covariance: np.ndarray
    inflation: float
    rho_radial: float
    rho_azimuthal: float
    white: bool
    n_points: int
    chi2_reduced: float
    residual_rms: float
    explained: float
    equal_weights: np.ndarray
    equal_weights_sigma: np.ndarray
    rows: np.ndarray = field(repr=False)
    residuals: np.ndarray = field(repr=False)
    outliers: tuple[int, ...] = ()

    def as_dict(self) -> dict:
        return {n: float(v) for n, v in zip(INFLOW, self.estimate)}


NAMES = INFLOW


def _wls(x, y, w):
    a = x * np.sqrt(w)[:, None]
    coef, *_ = np.linalg.lstsq(a, y * np.sqrt(w), rcond=None)
    return coef, np.linalg.inv(a.T @ a)


def _lag1(e, groups, order):
    """Lag-1 correlation of ``e`` between neighbours in ``order`` within each group,
    and the number of pairs."""
    a, b = [], []
    for g in np.unique(groups):
        idx = np.where(groups == g)[0]
        idx = idx[np.argsort(order[idx])]
        a += list(e[idx[:-1]])
        b += list(e[idx[1:]])
    if len(a) < 3:
        return 0.0, len(a)
    return float(np.corrcoef(a, b)[0, 1]), len(a)


def fit_first_harmonic(survey: Survey, weights: str = "std") -> HarmonicFit:
    """Weighted least-squares fit of Eq. (6) to ``survey`` (its ``in_fit`` rows).

    Parameters
    ----------
    survey : Survey
    weights : {"std", "equal"}
        ``"std"``: ``1/sigma^2`` with the tabulated standard deviations (relative
        weights; the scale comes from the residuals); ``"equal"``: ordinary least
        squares.

    Returns
    -------
    HarmonicFit
        Bounds: the covariance ``s^2 (X^T W X)^-1`` with ``s^2`` the reduced
        chi-square, times ``inflation^2``, ``inflation = sqrt((1 + rho)/(1 - rho))``
        with ``rho`` the larger positive lag-1 residual correlation (radial or
        azimuthal neighbours; the variance factor of a mean of AR(1) data), and
        never below the cluster-robust bound.
    """
    if weights not in ("std", "equal"):
        raise ValueError("weights must be 'std' or 'equal'")
    rows = np.where(survey.in_fit)[0]
    psi, r, y = survey.psi[rows], survey.r[rows], survey.lambda_i[rows]
    if weights == "std" and not np.all(survey.sigma[rows] > 0):
        bad = survey.line[rows][~(survey.sigma[rows] > 0)]
        raise InputError(f"{survey.file}: standard deviation not > 0 on line(s) "
                         f"{', '.join(map(str, bad))}: no weight (use weights='equal')")
    if len(rows) < 4:
        raise InputError(f"{survey.file}: {len(rows)} stations on the disc: too few to fit "
                         "Eq. (6) and judge its residuals")
    x = design(psi, r)
    w = 1.0 / survey.sigma[rows] ** 2 if weights == "std" else np.ones(len(rows))
    n, p = x.shape
    coef, xtwx_inv = _wls(x, y, w)
    res = y - x @ coef
    chi2r = float(np.sum(w * res**2) / (n - p))
    cov_scatter = chi2r * xtwx_inv
    e = res * np.sqrt(w)
    rho_r, n_r = _lag1(e, np.round(psi, 6), r)
    rho_p, n_p = _lag1(e, np.round(r, 4), psi)
    white = abs(rho_r) <= WHITENESS_Z / np.sqrt(max(n_r, 1)) and \
        abs(rho_p) <= WHITENESS_Z / np.sqrt(max(n_p, 1))
    rho = min(max(rho_r, rho_p, 0.0), 0.95)
    inflation = float(np.sqrt((1 + rho) / (1 - rho)))
    # sandwich with each radial cut a cluster: any correlation within a cut
    meat = np.zeros((p, p))
    cuts = np.unique(np.round(psi, 6))
    for g in cuts:
        idx = np.round(psi, 6) == g
        s = (x[idx] * (w[idx] * res[idx])[:, None]).sum(axis=0)
        meat += np.outer(s, s)
    g = len(cuts)
    cov_cluster = g / max(g - 1, 1) * (n - 1) / (n - p) * xtwx_inv @ meat @ xtwx_inv
    cov = cov_scatter * inflation**2
    sig = np.sqrt(np.diag(cov))
    sig_cl = np.sqrt(np.diag(cov_cluster))
    if np.any(sig_cl > sig):
        scale = np.maximum(sig_cl / sig, 1.0)
        cov = cov * np.outer(scale, scale)
        sig = np.sqrt(np.diag(cov))
    sd = np.sqrt(np.sum(w * res**2) / (n - p) / w)        # residual sd at each point
    out = tuple(int(survey.line[rows[i]]) for i in np.where(np.abs(res) > OUTLIER_Z * sd)[0])
    if weights == "std":
        eq = fit_first_harmonic(survey, "equal")
        eqw, eqs = eq.estimate, eq.sigma
    else:
        eqw, eqs = coef, sig
    return HarmonicFit(file=survey.file, mu=survey.mu, estimate=coef, sigma=sig,
                       sigma_scatter=np.sqrt(np.diag(cov_scatter)), sigma_cluster=sig_cl,
                       covariance=cov, inflation=inflation, rho_radial=rho_r,
                       rho_azimuthal=rho_p, white=bool(white), n_points=n,
                       chi2_reduced=chi2r, residual_rms=float(np.sqrt(np.mean(res**2))),
                       explained=float(1.0 - np.sum(res**2) / np.sum((y - y.mean())**2)),
                       equal_weights=eqw, equal_weights_sigma=eqs, rows=rows,
                       residuals=res, outliers=out)


def _trapezoid(y, x):
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


def area_mean_inflow(survey: Survey) -> tuple[float, float]:
    """Model-free mean inflow over the surveyed annulus: each radial cut integrated
    with the area weight ``r dr`` (trapezoids between its stations on the disc),
    the cuts averaged over azimuth (each cut standing for its share of the
    azimuths there are) [-].

    Returns ``(mean, r_min)``: each cut spans its own stations, ``r_min`` the
    largest of the cuts' innermost stations (the region inside them is not
    measured, or not in every cut).  The momentum
    ``lambda0`` is a disc-area mean, which this approaches where the inner disc
    carries little inflow.
    """
    rows = np.where(survey.in_fit)[0]
    psi, r, y = survey.psi[rows], survey.r[rows], survey.lambda_i[rows]
    means, inner = [], []
    for g in np.unique(np.round(psi, 6)):
        idx = np.where(np.round(psi, 6) == g)[0]
        idx = idx[np.argsort(r[idx])]
        rr, yy = r[idx], y[idx]
        if len(rr) < 2:
            continue
        means.append(_trapezoid(yy * rr, rr) / _trapezoid(rr, rr))
        inner.append(rr[0])
    return float(np.mean(means)), float(np.max(inner))


@dataclass(frozen=True, eq=False)
class SurveyComparison:
    """One survey, its Eq. (6) fit, its model-free area mean
    (:func:`area_mean_inflow`, ``(mean, r_min)``) and the model's trim inflow at its
    conditions."""

    survey: Survey
    fit: HarmonicFit
    predictions: tuple[SteadyInflow, ...]
    area_mean: tuple[float, float] = (float("nan"), float("nan"))

    @property
    def mu(self) -> float:
        return self.survey.mu

    def prediction(self, theory: str) -> SteadyInflow:
        return next(p for p in self.predictions if p.theory == theory)

    def discrepancy(self, theory: str) -> np.ndarray:
        """(predicted - measured) / sigma, per harmonic, with the fit's inflated sigma
        and the prediction's own (Table 3) sigma combined [-]."""
        pr = self.prediction(theory)
        s = np.hypot(self.fit.sigma, np.asarray(pr.sigma))
        return (np.asarray(pr.harmonics) - self.fit.estimate) / s


@dataclass(frozen=True, eq=False)
class MeasuredInflowComparison:
    """Every survey compared, by ascending ``mu``."""

    cases: tuple[SurveyComparison, ...]

    @property
    def mu(self) -> np.ndarray:
        return np.array([c.mu for c in self.cases])

    @property
    def defects(self):
        return tuple(d for c in self.cases for d in c.survey.defects)


def measured_inflow_response(surveys, beta1c=0.0, beta1s=0.0, c_mc=0.0,
                             c_ms=0.0) -> MeasuredInflowComparison:
    """Fit Eq. (6) to each survey and compute the model's trim inflow at its run
    conditions (:func:`inflowsim.model.steady_inflow.steady_inflow_predictions`).

    Parameters
    ----------
    surveys : sequence of Survey
        :func:`inflowsim.data.nasa_lv.read_surveys`.
    beta1c, beta1s : float
        Trim first-harmonic flap [rad]; 0: the rotor trimmed to zero flapping.
    c_mc, c_ms : float
        Hub moment coefficients [-]; 0 with zero flapping.
    """
    cases = []
    for s in sorted(surveys, key=lambda s: s.mu):
        c = s.conditions
        preds = steady_inflow_predictions(c.mu, c.muz, c.ct, c.theta1c, c.theta1s,
                                          beta1c, beta1s, c_mc, c_ms)
        cases.append(SurveyComparison(s, fit_first_harmonic(s), preds, area_mean_inflow(s)))
    return MeasuredInflowComparison(tuple(cases))


__all__ = ["NAMES", "eq6", "design", "HarmonicFit", "fit_first_harmonic", "area_mean_inflow",
           "SurveyComparison",
           "MeasuredInflowComparison", "measured_inflow_response"]
