"""Parameter schedules: each parameter a low-order polynomial in the advance ratio
or in its inverse.

A campaign identifies the model at several flight conditions: estimates with
their bounds (1-sigma) at each ``mu``.  :func:`fit_schedule` fits each parameter
against ``mu`` by weighted least squares (weights ``1/sigma^2``): polynomials of
order 0 to ``max_order`` in the scaled variable ``x = (v - center)/scale``, with
``v`` either ``mu`` or ``1/mu`` (:data:`VARIABLES`; ``center``, ``scale`` the
middle and half-width of the fitted range of ``v``), the variable and order chosen
by one stated criterion (:data:`CRITERIA`), and beside it the test of whether a
constant would do (the weighted chi-square of the constant fit).  ``1/mu`` is
there because momentum theory makes the inflow's time constants and gains go like
``1/V ~ 1/mu`` (Pitt-Peters: ``tau0 = 4/(3 pi mu)``): a low-order polynomial in
``mu`` follows that curve between low speeds only with more coefficients than a
campaign's few conditions can pay for.

Evaluation (:meth:`Schedule.__call__`, ``schedule(mu) -> {name: value}``) holds
the end values outside the fitted range (``mu`` clamped to it: a polynomial
extrapolated beyond its data is not a model of anything) and evaluates each
polynomial by Horner's rule; the FMU's generated C
(:func:`inflowsim.fmu.generate.schedule_c`) does the same operations in the same
order, so both give the same doubles.  The range's ends inside the
:class:`~inflowsim.simulate.mutable.MuTable`'s range are knots of the table
(:meth:`Schedule.knots`), so the scheduled matrices stay tabulated to 1e-12.

A schedule may also carry the trim the rotor flies at each ``mu``
(:attr:`Schedule.trim`, :func:`fit_trim`): the measured trim totals
(:data:`inflowsim.physics.bladeelement.TRIM_KEYS`) of the conditions, each a
least-squares polynomial in the same ``x = (mu - center)/scale``, held at its end
values beyond the range like the parameters.  :meth:`Schedule.constants_at` puts it
in ``Constants.trim`` at ``mu``, so that the effects linearised about the trim
(``advance-ratio-perturbation``) are linearised about the trim of the ``mu`` they
fly at; the FMU computes the same polynomials in its C.

Time shifts (``delay``, ``delay_<channel>``) describe the recording, not the rotor,
and a step-by-step loop holds them: they are never scheduled, only held at their
weighted mean (:attr:`Schedule.held`), as are parameters without a finite bound.

Schedule files are JSON (``docs/campaign.md``, "Schedules"):
:func:`write_schedule`, :func:`read_schedule`.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from .params import Constants

#: Order-selection criteria of :func:`fit_schedule` (``chi2``: the weighted
#: chi-square of the residuals; ``k`` coefficients, ``n`` conditions):
#: ``"aic"`` ``chi2 + 2 k`` (Akaike), ``"aicc"`` the same plus ``2 k (k + 1) /
#: (n - k - 1)`` (small samples), ``"bic"`` ``chi2 + k ln n`` (Schwarz), ``"chi2"``
#: the lowest order whose residuals pass the chi-square test at ``alpha``.
CRITERIA = ("aic", "aicc", "bic", "chi2")
#: File format version of a schedule file (a file with a ``"trim"`` object is
#: still version 1: readers that do not know it ignore it, and a file without it
#: reads as a schedule without trim).
FORMAT = 1
#: Highest order of a trim total's polynomial in ``mu`` (:func:`fit_trim`).
TRIM_MAX_ORDER = 3
#: The variables a parameter's polynomial may be written in: the advance ratio
#: ``mu`` or its inverse ``1/mu``.
VARIABLES = ("mu", "1/mu")


def variable_value(variable: str, mu):
    """``mu`` or ``1.0 / mu`` (the C's operation) [-]."""
    return mu if variable == "mu" else 1.0 / mu


def is_time_shift(name: str) -> bool:
    """A parameter that shifts a channel in time (held, never scheduled)."""
    return name == "delay" or name.startswith("delay_")


def _chi2_sf(x: float, dof: int) -> float:
    if dof <= 0:
        return float("nan")
    from scipy.stats import chi2
    return float(chi2.sf(x, dof))


def horner(coefficients, x: float) -> float:
    """``sum_k c_k x^k`` by Horner's rule, highest degree first (the C's order)."""
    acc = coefficients[-1]
    for c in coefficients[-2::-1]:
        acc = acc * x + c
    return acc


@dataclass(frozen=True)
class ParameterSchedule:
    """One parameter against ``mu``: the chosen polynomial and the constant test.

    Attributes
    ----------
    name : str
    coefficients : tuple of float
        Power coefficients in ``x = (mu - center)/scale``, degree 0 first.
    covariance : tuple of tuple
        Their covariance: ``(X' W X)^-1`` times ``max(1, chi2/dof)`` (the bounds
        widened when the conditions scatter more than their bounds say).
    center, scale : float
        ``x = (mu - center)/scale`` [-].
    chi2, dof : float, int
        Weighted chi-square of the chosen polynomial's residuals, its degrees of
        freedom (conditions less coefficients).
    scores : tuple of float
        The criterion's value for each order tried (0, 1, ...).
    constant_value, constant_sigma : float
        The weighted mean and its 1-sigma bound (widened likewise).
    constant_chi2, constant_p : float
        Chi-square of the constant fit (``n - 1`` degrees of freedom) and its
        probability (None with a single condition: nothing to test).
    constant : bool
        A constant would do: ``constant_p >= alpha`` (or a single condition).
    mu, estimate, sigma : tuple of float
        The data fitted (conditions with a finite positive bound).
    variable : {"mu", "1/mu"}
        What the polynomial is in: ``x = (v - center)/scale`` with ``v = mu`` or
        ``v = 1/mu``.
    """

    name: str
    coefficients: tuple
    covariance: tuple
    center: float
    scale: float
    chi2: float
    dof: int
    scores: tuple
    constant_value: float
    constant_sigma: float
    constant_chi2: float
    constant_p: float
    constant: bool
    mu: tuple
    estimate: tuple
    sigma: tuple
    variable: str = "mu"

    @property
    def order(self) -> int:
        return len(self.coefficients) - 1

    @property
    def p_value(self) -> float:
        """Chi-square probability of the chosen polynomial's residuals."""
        return _chi2_sf(self.chi2, self.dof)

    def x(self, mu: float) -> float:
        """The polynomial's argument at ``mu`` (the C's operations, in its order)."""
        return (variable_value(self.variable, mu) - self.center) / self.scale

    def value(self, mu: float) -> float:
        """The polynomial at ``mu`` (no clamping: :class:`Schedule` clamps)."""
        return horner(self.coefficients, self.x(mu))

    def bound(self, mu: float) -> float:
        """1-sigma bound of the polynomial at ``mu`` (from :attr:`covariance`)."""
        x = self.x(mu)
        v = np.array([x ** k for k in range(len(self.coefficients))])
        return float(math.sqrt(max(v @ np.array(self.covariance) @ v, 0.0)))

    def to_json(self) -> dict:
        return {"order": self.order, "variable": self.variable,
                "center": self.center, "scale": self.scale,
                "coefficients": list(self.coefficients),
                "covariance": [list(r) for r in self.covariance],
                "chi2": self.chi2, "dof": self.dof, "p": _nan_none(self.p_value),
                "scores": list(self.scores),
                "constant": {"value": self.constant_value, "sigma": self.constant_sigma,
                             "chi2": self.constant_chi2,
                             "p": self.constant_p, "adequate": self.constant},
                "data": {"mu": list(self.mu), "estimate": list(self.estimate),
                         "sigma": list(self.sigma)}}

    @classmethod
    def from_json(cls, name: str, d: dict) -> "ParameterSchedule":
        c = d["constant"]
        coef = tuple(_real(v, f"schedule of {name}: coefficient") for v in d["coefficients"])
        cov = tuple(tuple(_real(v, f"schedule of {name}: covariance") for v in r)
                    for r in d["covariance"])
        if not coef or len(cov) != len(coef) or any(len(r) != len(coef) for r in cov):
            raise InputError(f"schedule of {name}: coefficients and covariance disagree "
                             "in size")
        scale = _real(d["scale"], f"schedule of {name}: scale")
        _real(d["center"], f"schedule of {name}: center")
        if not (math.isfinite(scale) and scale > 0) or not all(map(math.isfinite, coef)):
            raise InputError(f"schedule of {name}: scale and coefficients must be finite "
                             "(scale > 0)")
        variable = d.get("variable", "mu")
        if variable not in VARIABLES:
            raise InputError(f"schedule of {name}: variable {variable!r}: choose "
                             f"{' or '.join(VARIABLES)}")
        data = d.get("data") or {"mu": [], "estimate": [], "sigma": []}
        return cls(name, coef, cov, float(d["center"]), scale, float(d["chi2"]),
                   int(d["dof"]), tuple(_none_nan(v) for v in d.get("scores", ())),
                   float(c["value"]), float(c["sigma"]), float(c["chi2"]),
                   None if c.get("p") is None else float(c["p"]), bool(c["adequate"]),
                   tuple(map(float, data["mu"])), tuple(map(float, data["estimate"])),
                   tuple(map(float, data["sigma"])), variable)


@dataclass(frozen=True)
class TrimSchedule:
    """One trim total against ``mu``: a least-squares polynomial (:func:`fit_trim`).

    Attributes
    ----------
    column : str
        The record column (one of :data:`~inflowsim.physics.bladeelement.TRIM_KEYS`).
    coefficients : tuple of float
        Power coefficients in ``x = (mu - center)/scale``, degree 0 first [rad or -].
    center, scale : float
        ``x = (mu - center)/scale`` [-] (the parameters' convention in ``mu``).
    residual : float
        Largest absolute residual of the fit at the conditions [rad or -] (rounding
        only where the polynomial passes through every condition).
    mu, trim : tuple of float
        The data fitted: each condition's ``mu`` and trim total.
    """

    column: str
    coefficients: tuple
    center: float
    scale: float
    residual: float
    mu: tuple = ()
    trim: tuple = ()

    @property
    def order(self) -> int:
        return len(self.coefficients) - 1

    def x(self, mu: float) -> float:
        """The polynomial's argument at ``mu`` (the C's operations, in its order)."""
        return (mu - self.center) / self.scale

    def value(self, mu: float) -> float:
        """The polynomial at ``mu`` (no clamping: :class:`Schedule` clamps)."""
        return horner(self.coefficients, self.x(mu))

    def to_json(self) -> dict:
        return {"order": self.order, "center": self.center, "scale": self.scale,
                "coefficients": list(self.coefficients), "residual": self.residual,
                "data": {"mu": list(self.mu), "trim": list(self.trim)}}

    @classmethod
    def from_json(cls, column: str, d: dict) -> "TrimSchedule":
        coef = tuple(_real(v, f"trim schedule of {column}: coefficient")
                     for v in d["coefficients"])
        scale = _real(d["scale"], f"trim schedule of {column}: scale")
        _real(d["center"], f"trim schedule of {column}: center")
        if not coef or not all(map(math.isfinite, coef)) or not (
                math.isfinite(scale) and scale > 0):
            raise InputError(f"trim schedule of {column}: coefficients must be finite "
                             "(at least one) and scale finite > 0")
        data = d.get("data") or {"mu": [], "trim": []}
        return cls(str(column), coef, float(d["center"]), scale,
                   float(d.get("residual", 0.0)), tuple(map(float, data["mu"])),
                   tuple(map(float, data["trim"])))


def fit_trim(mu, trims, max_order: int = TRIM_MAX_ORDER, center: float | None = None,
             scale: float | None = None) -> tuple:
    """Each trim total against ``mu``: unweighted least-squares polynomials.

    The trim totals are measured (means over each record's quiet trim window,
    averaged over a condition's records), not estimated: they carry no bound to
    weight by, and their noise is far below their trend with speed, so no order
    is chosen by a criterion either.  The order is ``min(max_order, m - 1)`` with
    ``m`` the distinct ``mu`` that have the total: a cubic (the default 3) holds a
    collective's power bucket and the ``mu^3`` rise of the profile and parasite
    power, and a cyclic's near-linear trend with its curvature; with four
    conditions or fewer the polynomial passes through every one (residual at
    rounding), with more it smooths them, and :attr:`TrimSchedule.residual` says
    by how much.

    Parameters
    ----------
    mu : sequence of float
        Each condition's advance ratio [-].
    trims : mapping of column to sequence of float
        Each trim total at each condition [rad or -] (``nan`` or ``None``: not
        measured there; that condition is left out of that column's fit).
    max_order : int
        Highest order (>= 0).
    center, scale : float, optional
        ``x = (mu - center)/scale``; default the middle and half-width of ``mu``
        (the range of the whole schedule, so the parameters' and the trim's ``x``
        are the same number).

    Returns
    -------
    tuple of TrimSchedule
        In the order of ``trims``; a column with no finite value is left out.
    """
    if int(max_order) != max_order or max_order < 0:
        raise InputError(f"trim max_order {max_order!r}: an integer >= 0")
    mu = np.asarray(mu, dtype=float)
    if center is None:
        lo, hi = float(np.min(mu)), float(np.max(mu))
        center, scale = 0.5 * (lo + hi), (0.5 * (hi - lo) or 1.0)
    out = []
    for col, values in trims.items():
        y = np.array([np.nan if v is None else float(v) for v in values])
        if len(y) != len(mu):
            raise InputError(f"trim schedule of {col}: {len(y)} values for {len(mu)} "
                             "conditions")
        ok = np.isfinite(mu) & np.isfinite(y)
        if not ok.any():
            continue
        m, y = mu[ok], y[ok]
        order = max(0, min(int(max_order), len(np.unique(m)) - 1))
        x = (m - center) / scale
        coef, _, _ = _weighted_fit(x, y, np.ones(len(m)), order + 1)
        coef = tuple(float(c) for c in coef)
        # the residual of the evaluation every user makes (Horner, as the C)
        res = max(abs(horner(coef, xi) - b) for xi, b in zip(x, y))
        out.append(TrimSchedule(str(col), coef, float(center), float(scale), float(res),
                                tuple(map(float, m)), tuple(map(float, y))))
    return tuple(out)


def _nan_none(v):
    return None if v is None or v != v else float(v)


def _real(v, what: str) -> float:
    """A JSON number that is finite (a string, boolean or null is refused: a file
    this program writes has none there)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise InputError(f"{what} {v!r} is not a number")
    x = float(v)
    if not math.isfinite(x):
        raise InputError(f"{what} {v!r} is not finite")
    return x


#: Points of ``mu_range`` at which :meth:`Schedule.checked` evaluates every
#: scheduled value (its ends included).
CHECK_POINTS = 101


def _none_nan(v):
    return float("nan") if v is None else float(v)


@dataclass(frozen=True)
class Schedule:
    """Parameters of one structure as functions of ``mu``.

    ``schedule(mu)`` gives every parameter (scheduled and held) at ``mu``,
    ``mu`` clamped to :attr:`mu_range`.  Frozen and picklable.

    Attributes
    ----------
    structure : str
        The structure whose parameters these are.
    parameters : tuple of ParameterSchedule
        The scheduled parameters.
    held : tuple of (name, value, sigma)
        Parameters held constant: time shifts (their weighted mean) and parameters
        without a bound (their mean; ``sigma`` None).
    mu_range : (float, float)
        The ``mu`` of the conditions fitted; evaluation clamps to it.
    criterion, alpha, max_order :
        How the orders were chosen and the constant tested.
    constants : Constants or None
        The rotor (``mu`` is the range's middle), when known: the FMU's start values.
    source : str
    trim : tuple of TrimSchedule
        The trim totals against ``mu`` (:func:`fit_trim`), held at their end values
        beyond :attr:`mu_range`; empty: no trim (the constants' trim stays as given).
    """

    structure: str
    parameters: tuple
    held: tuple
    mu_range: tuple
    criterion: str = "aic"
    alpha: float = 0.05
    max_order: int = 3
    constants: Constants | None = None
    source: str = field(default="schedule", compare=False)
    trim: tuple = ()

    @property
    def names(self) -> tuple:
        """Scheduled parameter names."""
        return tuple(p.name for p in self.parameters)

    def __getitem__(self, name: str) -> ParameterSchedule:
        for p in self.parameters:
            if p.name == name:
                return p
        raise KeyError(name)

    def clamp(self, mu: float) -> float:
        lo, hi = self.mu_range
        return lo if mu < lo else hi if mu > hi else mu

    def __call__(self, mu: float) -> dict:
        """Every parameter at ``mu`` [-] (clamped to :attr:`mu_range`)."""
        m = self.clamp(float(mu))
        out = {n: v for n, v, _ in self.held}
        for p in self.parameters:
            out[p.name] = horner(p.coefficients, p.x(m))
        return out

    def bounds(self, mu: float) -> dict:
        """1-sigma bound of every scheduled and held parameter at ``mu``."""
        m = self.clamp(float(mu))
        out = {n: s for n, _, s in self.held}
        out.update({p.name: p.bound(m) for p in self.parameters})
        return out

    @property
    def trim_columns(self) -> tuple:
        """The trim totals scheduled (record columns)."""
        return tuple(t.column for t in self.trim)

    def trim_values(self, mu: float) -> dict:
        """Every scheduled trim total at ``mu`` [rad or -] (clamped to
        :attr:`mu_range`; empty without trim)."""
        m = self.clamp(float(mu))
        return {t.column: t.value(m) for t in self.trim}

    def constants_at(self, constants: Constants, mu: float | None = None) -> Constants:
        """``constants`` at ``mu`` (default ``constants.mu``) with the scheduled trim
        totals there in ``Constants.trim`` (its other columns kept); without trim,
        ``constants.trim`` as given."""
        k = constants if mu is None else constants.with_mu(mu)
        if not self.trim:
            return k
        return k.with_trim({**dict(k.trim or {}), **self.trim_values(k.mu)})

    def knots(self, lo: float, hi: float) -> tuple:
        """Where the clamped schedule has a kink within ``(lo, hi)``: the ends of
        :attr:`mu_range` of a schedule that is not constant (its trim included)."""
        if all(p.order == 0 for p in self.parameters + self.trim):
            return ()
        return tuple(k for k in self.mu_range if lo < k < hi)

    def model(self, constants: Constants, mu: float | None = None):
        """The :class:`~inflowsim.model.Model` at ``mu`` (default
        ``constants.mu``) with the scheduled parameters, and the scheduled trim
        (:meth:`constants_at`), there."""
        from .build import build_model
        k = self.constants_at(constants, mu)
        return build_model(self.structure, self(k.mu), k)

    def to_json(self) -> dict:
        doc = {"schedule": FORMAT, "structure": self.structure, "variable": "mu",
               "mu_range": list(self.mu_range), "criterion": self.criterion,
               "alpha": self.alpha, "max_order": self.max_order}
        if self.constants is not None:
            doc["constants"] = self.constants.as_dict()
        doc["parameters"] = {p.name: p.to_json() for p in self.parameters}
        doc["held"] = {n: {"estimate": v, "sigma": s} for n, v, s in self.held}
        if self.trim:
            doc["trim"] = {t.column: t.to_json() for t in self.trim}
        return doc

    @classmethod
    def from_json(cls, doc, where: str = "schedule file") -> "Schedule":
        from .structure import Structure
        if not isinstance(doc, dict) or doc.get("schedule") != FORMAT:
            raise InputError(f"{where}: not a schedule file (needs \"schedule\": {FORMAT})")
        try:
            s = Structure.parse(doc["structure"])
            params = tuple(ParameterSchedule.from_json(n, d)
                           for n, d in doc["parameters"].items())
            held = tuple((n, float(d["estimate"]),
                          None if d.get("sigma") is None else float(d["sigma"]))
                         for n, d in (doc.get("held") or {}).items())
            lo, hi = (float(v) for v in doc["mu_range"])
            k = doc.get("constants")
            constants = Constants.from_mapping(k) if k else None
            trim = tuple(TrimSchedule.from_json(c, d)
                         for c, d in (doc.get("trim") or {}).items())
            out = cls(s.name, params, held, (lo, hi), str(doc.get("criterion", "aic")),
                      float(doc.get("alpha", 0.05)), int(doc.get("max_order", 3)),
                      constants, where, trim)
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputError(f"{where}: malformed schedule ({type(exc).__name__}: {exc})"
                             ) from None
        return out.checked(where)

    def checked(self, where: str = "schedule") -> "Schedule":
        """Itself, or :class:`InputError`: the names must be the structure's
        parameters, the range finite and ordered, no time shift scheduled, the
        trim totals among those effects linearised about trim read, each once."""
        from ..physics.bladeelement import TRIM_KEYS
        from .structure import Structure
        s = Structure.parse(self.structure)
        lo, hi = self.mu_range
        if not (math.isfinite(lo) and math.isfinite(hi) and 0 <= lo <= hi):
            raise InputError(f"{where}: mu_range {lo:g}, {hi:g} must be finite, "
                             "0 <= lo <= hi")
        given = self.names + tuple(n for n, _, _ in self.held)
        twice = sorted({n for n in given if given.count(n) > 1})
        if twice:
            raise InputError(f"{where}: {twice[0]} is given twice (scheduled or held: "
                             "one of them)")
        for n in given:
            if n not in s.parameters:
                raise InputError(f"{where}: {n} is not a parameter of {s.name} "
                                 f"({', '.join(s.parameters)})")
        if lo <= 0 and any(p.variable != "mu" for p in self.parameters):
            raise InputError(f"{where}: a schedule in 1/mu needs mu_range above 0, "
                             f"not from {lo:g}")
        for n in self.names:
            if is_time_shift(n):
                raise InputError(f"{where}: {n} is a time shift; a step-by-step loop "
                                 "holds it (put it under \"held\")")
        cols = self.trim_columns
        for c in cols:
            if c not in TRIM_KEYS:
                raise InputError(f"{where}: trim {c!r} is not a trim total "
                                 f"({', '.join(TRIM_KEYS)})")
        if len(set(cols)) != len(cols):
            raise InputError(f"{where}: a trim total is scheduled twice")
        self._check_values(where)
        return self

    def _check_values(self, where: str) -> None:
        """Every scheduled and held value, at :data:`CHECK_POINTS` speeds across
        :attr:`mu_range`, finite and within its parameter's range (a time constant
        a polynomial takes below zero, a coefficient of 1e308, refused here rather
        than in the FMU's compiler or at run time)."""
        from .params import MU_MAX, SPECS
        lo, hi = self.mu_range
        if hi > MU_MAX:
            raise InputError(f"{where}: mu_range {lo:g}, {hi:g} reaches beyond the "
                             f"model's mu <= {MU_MAX:g}")
        for p in self.parameters + self.trim:
            if not (math.isfinite(p.center) and math.isfinite(p.scale) and p.scale > 0):
                raise InputError(f"{where}: {getattr(p, 'name', None) or p.column}: "
                                 "center and scale must be finite (scale > 0)")
        for mu in np.linspace(lo, hi, CHECK_POINTS):
            try:
                values = self(mu)
                trims = self.trim_values(mu)
            except (OverflowError, ZeroDivisionError):
                raise InputError(f"{where}: its polynomials overflow at mu {mu:.4g}") \
                    from None
            for n, v in values.items():
                try:
                    SPECS[n].check(v)
                except InputError as exc:
                    raise InputError(f"{where}: at mu {mu:.4g}: {exc}") from None
            for c, v in trims.items():
                if not math.isfinite(v):
                    raise InputError(f"{where}: trim {c} at mu {mu:.4g} is {v:g}")


def _weighted_fit(x, y, w, k):
    """Weighted least squares of ``y`` on ``1, x, ..., x^(k-1)``: coefficients,
    ``(X' W X)^-1`` and the chi-square of the residuals."""
    X = np.vander(x, k, increasing=True)
    sw = np.sqrt(w)
    q, r = np.linalg.qr(X * sw[:, None])
    coef = np.linalg.solve(r, q.T @ (y * sw))
    rinv = np.linalg.inv(r)
    cov = rinv @ rinv.T
    chi2 = float(np.sum(w * (y - X @ coef) ** 2))
    return coef, cov, chi2


def _score(criterion, chi2, k, n):
    if criterion == "aic":
        return chi2 + 2 * k
    if criterion == "aicc":
        return chi2 + 2 * k + 2 * k * (k + 1) / (n - k - 1) if n - k - 1 > 0 else math.inf
    if criterion == "bic":
        return chi2 + k * math.log(n)
    return chi2                              # "chi2": chosen by the test, see below


def fit_parameter(name: str, mu, estimate, sigma, criterion: str = "aic",
                  max_order: int = 3, alpha: float = 0.05,
                  center: float | None = None, scale: float | None = None,
                  variables=("mu",)) -> ParameterSchedule:
    """Fit one parameter's estimates against ``mu`` (see :func:`fit_schedule`).

    Conditions whose ``sigma`` is not finite and positive, or whose estimate is
    not finite, are left out.  Orders 0 to ``min(max_order, n - 2)`` are tried (at
    least one degree of freedom left to judge the scatter; order 0 with one
    condition) in each of ``variables``; order 0 is one candidate, the same in
    every variable.  ``center`` and ``scale`` (of ``mu``; default its range's middle
    and half-width) apply to ``mu``; ``1/mu`` takes its own range's."""
    mu, y, s = (np.asarray(a, dtype=float) for a in (mu, estimate, sigma))
    ok = np.isfinite(mu) & np.isfinite(y) & np.isfinite(s) & (s > 0)
    mu, y, s = mu[ok], y[ok], s[ok]
    n = len(mu)
    if n == 0:
        raise InputError(f"schedule of {name}: no condition with an estimate and a "
                         "finite bound")
    variables = tuple(variables)
    if not variables or any(v not in VARIABLES for v in variables):
        raise InputError(f"schedule variables {list(variables)}: choose from "
                         f"{', '.join(VARIABLES)}")
    if "1/mu" in variables and not np.all(mu > 0):
        variables = tuple(v for v in variables if v == "mu") or ("mu",)
    w = 1.0 / s ** 2
    top = max(0, min(int(max_order), n - 2, len(np.unique(mu)) - 1))
    # candidates (variable, center, scale, order, fit): order 0 once
    cands = []
    for var in variables:
        v = variable_value(var, mu)
        if var == "mu" and center is not None:
            c, h = float(center), float(scale)
        else:
            lo, hi = float(v.min()), float(v.max())
            c, h = 0.5 * (lo + hi), (0.5 * (hi - lo) or 1.0)
        x = (v - c) / h
        for k in range(0 if not cands else 1, top + 1):
            cands.append((var, c, h, k, _weighted_fit(x, y, w, k + 1)))
    scores = [_score(criterion, f[2], k + 1, n) for _, _, _, k, f in cands]
    if criterion == "chi2":
        passing = [i for i, (_, _, _, k, f) in enumerate(cands)
                   if not _chi2_sf(f[2], n - k - 1) < alpha]
        if passing:             # the lowest passing order; its best variable
            k_min = min(cands[i][3] for i in passing)
            best = min((i for i in passing if cands[i][3] == k_min),
                       key=lambda i: cands[i][4][2])
        else:
            best = max(range(len(cands)), key=lambda i: (cands[i][3], -cands[i][4][2]))
    else:
        best = int(np.argmin(scores))
    var, c, h, order, (coef, cov, chi2) = cands[best]
    dof = n - order - 1
    widen = max(1.0, chi2 / dof) if dof > 0 else 1.0
    c0, cov0, chi0 = cands[0][4]
    widen0 = max(1.0, chi0 / (n - 1)) if n > 1 else 1.0
    p0 = _chi2_sf(chi0, n - 1) if n > 1 else None
    # the criterion's value for each order in the chosen variable (order 0 shared)
    chosen_scores = tuple(float(scores[i]) for i, cd in enumerate(cands)
                          if cd[3] == 0 or cd[0] == var)
    return ParameterSchedule(
        name, tuple(float(v) for v in coef),
        tuple(tuple(float(v) for v in r) for r in cov * widen), float(c), float(h),
        float(chi2), int(dof), chosen_scores, float(c0[0]),
        float(math.sqrt(cov0[0, 0] * widen0)), float(chi0), p0,
        bool(p0 is None or not p0 < alpha), tuple(map(float, mu)), tuple(map(float, y)),
        tuple(map(float, s)), var)


def fit_schedule(structure, mu, estimates, sigmas, criterion: str = "aic",
                 max_order: int = 3, alpha: float = 0.05, constants=None,
                 source: str = "schedule", variables=("mu",), trim=None,
                 trim_order: int = TRIM_MAX_ORDER) -> Schedule:
    """Fit every parameter of ``structure`` against ``mu``, weighted by its bounds.

    Parameters
    ----------
    structure : str or Structure
        The structure identified at every condition.
    mu : sequence of float
        The advance ratio of each condition [-].
    estimates, sigmas : mapping of name to sequence of float
        Each parameter's estimate and 1-sigma bound at each condition (``nan`` or
        ``None``: not identified there).  A parameter with no finite bound at any
        condition, and every time shift, is held at its (weighted) mean.
    criterion : {"aic", "aicc", "bic", "chi2"}
        How each parameter's variable and order are chosen (:data:`CRITERIA`;
        ``chi2``: the lowest passing order, in the variable with the smaller
        chi-square).
    max_order : int
        Highest polynomial order tried (>= 0).
    alpha : float
        Level of the constant test (and of the ``"chi2"`` criterion).
    constants : Constants, optional
        The rotor, kept in the schedule (the FMU's start values).
    variables : sequence of {"mu", "1/mu"}
        What the polynomials may be written in (:data:`VARIABLES`; default ``mu``
        alone; ``1/mu`` only where every condition has ``mu > 0``).  Offering both
        tightens the bounds of a ``1/mu`` trend about threefold but, the criterion
        choosing among more candidates, covers less often: in
        ``tests/test_schedule.py`` (Pitt-Peters' ``tau0``, five speeds, 1 % bounds,
        20 seeds) 84 % of the points of a fine grid lie within 2 bounds, against
        93 % in ``mu`` alone.
    trim : mapping of column to sequence of float, optional
        The measured trim totals (:data:`~inflowsim.physics.bladeelement.TRIM_KEYS`)
        at each condition [rad or -]: fitted by :func:`fit_trim` (order up to
        ``trim_order``) in the parameters' ``x`` and kept as :attr:`Schedule.trim`.
    trim_order : int
        Highest order of the trim's polynomials (:data:`TRIM_MAX_ORDER`).

    Returns
    -------
    Schedule
    """
    from .structure import Structure
    if criterion not in CRITERIA:
        raise InputError(f"criterion {criterion!r}: choose {', '.join(CRITERIA)}")
    if int(max_order) != max_order or max_order < 0:
        raise InputError(f"max_order {max_order!r}: an integer >= 0")
    if not 0 < alpha < 1:
        raise InputError(f"alpha {alpha!r}: a level in (0, 1)")
    s = Structure.parse(structure)
    mu = np.asarray(mu, dtype=float)
    if mu.ndim != 1 or len(mu) == 0 or not np.all(np.isfinite(mu)):
        raise InputError("schedule: mu must be a non-empty sequence of finite numbers")
    center, scale = 0.5 * (mu.min() + mu.max()), 0.5 * (mu.max() - mu.min()) or 1.0

    def arr(d, n):
        v = d.get(n)
        return np.full(len(mu), np.nan) if v is None else np.array(
            [np.nan if e is None else float(e) for e in v])

    params, held = [], []
    for n in s.parameters:
        if n not in estimates:
            continue
        y, sg = arr(estimates, n), arr(sigmas, n)
        if len(y) != len(mu) or len(sg) != len(mu):
            raise InputError(f"schedule of {n}: {len(y)} estimates and {len(sg)} bounds "
                             f"for {len(mu)} conditions")
        has = np.isfinite(y) & np.isfinite(sg) & (sg > 0)
        if is_time_shift(n) or not has.any():
            fin = np.isfinite(y)
            if not fin.any():
                continue
            if has.any():
                w = 1.0 / sg[has] ** 2
                held.append((n, float(np.sum(w * y[has]) / np.sum(w)),
                             float(1.0 / math.sqrt(np.sum(w)))))
            else:
                v = y[fin]                  # one value repeated: that value
                held.append((n, float(v[0] if np.ptp(v) == 0 else np.mean(v)), None))
            continue
        params.append(fit_parameter(n, mu, y, sg, criterion, max_order, alpha,
                                    center, scale, variables))
    if not params and not held:
        raise InputError(f"schedule: no estimates of any parameter of {s.name}")
    trims = fit_trim(mu, trim, trim_order, center, scale) if trim else ()
    return Schedule(s.name, tuple(params), tuple(held),
                    (float(mu.min()), float(mu.max())), criterion, float(alpha),
                    int(max_order), constants, source, trims).checked()


def write_schedule(schedule: Schedule, path, overwrite: bool = True) -> Path:
    """Write ``schedule`` as JSON to ``path`` (atomically)."""
    from ..fileio import atomic_path, json_text
    p = Path(path)
    if p.exists() and not p.is_file():
        raise InputError(f"{p}: exists and is not a regular file")
    if p.exists() and not overwrite:
        raise InputError(f"{p} exists (overwrite to replace it)")
    with atomic_path(p) as tmp:
        Path(tmp).write_text(json_text(schedule.to_json()))
    return p


def read_schedule(path) -> Schedule:
    """A schedule file (:func:`write_schedule`), or one line saying what is wrong."""
    from ..fileio import read_json
    p = Path(path)
    doc = read_json(p, "schedule file")
    return Schedule.from_json(doc, str(p))


__all__ = ["Schedule", "ParameterSchedule", "TrimSchedule", "fit_schedule",
           "fit_parameter", "fit_trim", "TRIM_MAX_ORDER",
           "read_schedule", "write_schedule", "horner", "is_time_shift", "CRITERIA",
           "VARIABLES", "variable_value"]
