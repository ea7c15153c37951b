"""Results of an identification: a small frozen :class:`FitResult` and its JSON."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from ..model.equations import FLAP
from ..model.params import Constants
from ..model.structure import Structure


@dataclass(frozen=True, eq=False)
class RecordFit:
    """One record's frequency data for plotting and residual analysis.

    ``Z`` measured and ``Y`` predicted flap transforms ``(nf, 3)`` (``beta0 beta1c
    beta1s``) at ``f_hz``; ``x0`` the estimated initial state (end effects), used to
    replay the record in time with its ``hold``; ``nu`` all the end-effect nuisance
    (:func:`inflowsim.identify.freqmodel.flap_response`); ``S`` the record's
    residual covariance (3x3).

    Attributes
    ----------
    source : str
        The record.
    constants : Constants
        Its flight condition and rotor.
    dt : float
        Sample step [s].
    f_hz : ndarray
        Frequencies [Hz].
    Z, Y : ndarray, shape (nf, 3)
        Measured and predicted flap transforms [rad s].
    x0 : ndarray
        Estimated initial state (end effects).
    S : ndarray, shape (3, 3)
        Residual covariance [rad^2 s^2].
    trim : mapping of str to float
        The trim subtracted (SI).
    trim_method : str
        How it was found.
    u_time, z_time : ndarray
        Input and flap perturbations in time (SI).
    hold : str
        Intersample behaviour of the inputs.
    nu : ndarray or None
        Every end-effect nuisance.
    """

    source: str
    constants: Constants
    dt: float
    f_hz: np.ndarray
    Z: np.ndarray
    Y: np.ndarray
    x0: np.ndarray
    S: np.ndarray
    trim: Mapping
    trim_method: str
    u_time: np.ndarray = field(repr=False)
    z_time: np.ndarray = field(repr=False)
    hold: str = "zoh"
    nu: np.ndarray | None = field(default=None, repr=False)

    @property
    def residuals(self) -> np.ndarray:
        """``Z - Y`` ``(nf, 3)`` complex."""
        return self.Z - self.Y


def fit_percent(z, y):
    """The one fit figure of inflowsim [%]: ``100 (1 - ||z - y|| / ||z||)``.

    ``z`` measured and ``y`` predicted transforms over the analysis band (complex, one
    channel); 100 is a perfect fit, 0 no better than predicting nothing, negative
    worse than that.  ``identify``, ``validate``, the ladder and every report use it on
    the band's frequencies, so one model on one record reads the same everywhere.
    ``None`` when ``z`` is zero (nothing measured in the band).
    """
    z = np.asarray(z)
    y = np.asarray(y)
    scale = float(np.max(np.abs(z), initial=0.0))
    if scale == 0.0 or not np.isfinite(scale):
        return None
    return float(100.0 * (1.0 - np.linalg.norm((z - y) / scale)
                          / np.linalg.norm(z / scale)))


def channel_fit(Z: np.ndarray, Y: np.ndarray) -> dict:
    """Per flap channel: magnitude and phase errors over the band.

    ``mag_rms_db`` RMS of ``20 log10(|Y|/|Z|)`` [dB]; ``phase_rms_deg`` RMS of the
    wrapped phase of ``Y/Z`` [deg]; ``fit_percent`` :func:`fit_percent` over the
    band; ``residual_rms`` RMS ``|Z - Y|``.

    Parameters
    ----------
    Z : ndarray, shape (nf, 3)
        Measured flap transforms [rad s].
    Y : ndarray, shape (nf, 3)
        Predicted flap transforms [rad s].
    """
    out = {}
    for i, ch in enumerate(FLAP):
        z, y = Z[:, i], Y[:, i]
        ok = (np.abs(z) > 0) & (np.abs(y) > 0)
        ratio = y[ok] / z[ok]
        nz = float(np.linalg.norm(z))
        out[ch] = {
            "mag_rms_db": float(np.sqrt(np.mean((20 * np.log10(np.abs(ratio))) ** 2)))
            if ok.any() else None,
            "phase_rms_deg": float(np.sqrt(np.mean(np.degrees(np.angle(ratio)) ** 2)))
            if ok.any() else None,
            "fit_percent": fit_percent(z, y) if nz > 0 else None,
            "residual_rms": float(np.sqrt(np.mean(np.abs(z - y) ** 2))),
        }
    return out


@dataclass(frozen=True, eq=False)
class FitResult:
    """An identified structure with its bounds and fit figures.

    Attributes
    ----------
    structure : Structure
    constants : tuple of Constants
        Per record.
    parameters : dict
        Every parameter of the structure (estimated, fixed or tied) by name.
    sigma : dict
        1-sigma Cramer-Rao bound per estimated parameter (``None`` where the
        data do not determine it); tied parameters share their bound; fixed
        parameters are absent.
    sigma_colored : dict
        Bounds corrected for coloured residuals (residual-spectrum sandwich after
        Morelli & Klein), never below ``sigma``; same keys.
    sigma_robust : dict
        Misspecification-robust bounds (Huber-White sandwich of the per-frequency
        scores with a Newey-West band over neighbouring frequencies), never below
        ``sigma``; same keys.  They hold whatever the residuals' distribution or
        correlation, but not the bias of an incomplete structure (``conditional``).
    free : tuple of str
        Estimated quantities in ``correlation`` order (a tie group is ``a=b``).
    correlation : ndarray ``(p, p)``
    fixed : tuple of str
    ties : tuple of tuples
    cost : float
        Cost (12) at the estimate, summed over records.
    S : tuple of ndarray
        Residual covariance (3x3 Hermitian) per record.
    band_hz : (float, float)
        Band as used (snapped to the grid).
    n_freq : int
        Frequencies used, summed over records.
    records : tuple of str
        Sources.
    fit : dict
        Per flap channel, pooled over records (:func:`channel_fit`).
    iterations : int
    converged : bool
    warnings : tuple of str
        One-line reports of failure modes, each with what to do.
    model : Model
        Built at the first record's constants.
    data : tuple of RecordFit
        Frequency data per record (plots, residual analysis).
    starts : tuple
        ``(label, cost)`` of every starting point tried.
    conditional : str or None
        Set by the diagnosis's test (:func:`inflowsim.diagnose.conditional.marked`)
        when the residual keeps structured excess over the noise floor: every
        estimate is then conditional on an incomplete structure, and this is the
        reason, one line; ``None``: not judged, or the residual is at the floor.
    lr : (float, float)
        ``(kappa, d)``: a likelihood-ratio statistic ``2 (J_0 - J)`` of ``k``
        parameters against this fit is read as ``kappa k F(k, d)``
        (:func:`~inflowsim.identify.estimator.lr_calibration`; ``(1, inf)``,
        chi-square, where not computed).
    judged : bool
        Whether that test was made (:func:`~inflowsim.identify.identify` alone does
        not make it; the commands, :func:`~inflowsim.diagnose.diagnose` and the
        ladders do).
    """

    structure: Structure
    constants: tuple
    parameters: dict
    sigma: dict
    sigma_colored: dict
    free: tuple
    correlation: np.ndarray
    fixed: tuple
    ties: tuple
    cost: float
    S: tuple
    band_hz: tuple
    n_freq: int
    records: tuple
    fit: dict
    iterations: int
    converged: bool
    warnings: tuple
    model: object = field(repr=False)
    data: tuple = field(repr=False, default=())
    starts: tuple = ()
    sigma_robust: dict = field(default_factory=dict)
    conditional: str | None = None
    judged: bool = False
    lr: tuple = (1.0, float("inf"))

    @property
    def residuals(self) -> list:
        """Residual spectra ``Z - Y`` per record, ``(nf, 3)`` complex."""
        return [d.residuals for d in self.data]

    def to_json(self) -> dict:
        """The ``interface.md`` identify document; also a parameter file."""
        params = {}
        for n, v in self.parameters.items():
            entry = {"estimate": float(v), "sigma": self.sigma.get(n)}
            if n in self.fixed:
                entry["fixed"] = True
            if n in self.sigma_colored:
                entry["sigma_colored"] = self.sigma_colored[n]
            if n in self.sigma_robust:
                entry["sigma_robust"] = self.sigma_robust[n]
            if n not in self.fixed:
                entry.update(self.conditional_entry())
            params[n] = entry
        consts = self.constants[0].as_dict()
        return {
            "structure": self.structure.name,
            "effects": list(self.structure.effects),
            "band_hz": [float(self.band_hz[0]), float(self.band_hz[1])],
            "cost": float(self.cost),
            "parameters": params,
            "fit": self.fit,
            "constants": consts,
            "n_freq": int(self.n_freq),
            "lr_calibration": {"kappa": float(self.lr[0]),
                               "d": (None if not np.isfinite(self.lr[1])
                                     else float(self.lr[1]))},
            "records": list(self.records),
            "converged": bool(self.converged),
            "iterations": int(self.iterations),
            "warnings": list(self.warnings),
            "correlation": {"names": list(self.free),
                            "matrix": np.round(self.correlation, 6).tolist()},
            "ties": [list(t) for t in self.ties],
            "trim": [d.trim_method for d in self.data],
        }

    def conditional_entry(self) -> dict:
        """The fields an estimated parameter's JSON entry carries about the
        structure's completeness: ``conditional`` (bool; ``None`` where not
        :attr:`judged`) and ``conditional_why`` (the reason, or ``None``)."""
        return {"conditional": (self.conditional is not None) if self.judged else None,
                "conditional_why": self.conditional}


__all__ = ["RecordFit", "fit_percent", "channel_fit", "FitResult"]
