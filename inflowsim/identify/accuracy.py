"""Accuracy figures of identified parameters as flight-test engineers read them:
Cramer-Rao percent and insensitivity percent (Tischler and Remple, *Aircraft and
Rotorcraft System Identification*, 2nd ed., section 11.4).

``CR% = 100 sigma / |theta|`` with ``sigma`` the Cramer-Rao bound (all free
parameters estimated together); ``insensitivity% = 100 / (|theta| sqrt(M_ii))``,
the bound the parameter would have if it alone were estimated (``M = cov^-1``, the
information).  Guidelines: ``CR% <= 20`` and ``insensitivity% <= 10``; a
parameter with a CR% far above its insensitivity% is correlated with others
(ratio beyond ``CORRELATED``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Guideline limits [%] (Tischler and Remple).
CR_LIMIT, INSENSITIVITY_LIMIT = 20.0, 10.0
#: CR% over insensitivity% beyond which a parameter is flagged as correlated.
CORRELATED = 3.0


@dataclass(frozen=True)
class ParameterAccuracy:
    """One estimated quantity (a tie group's names joined by ``=``)."""

    name: str
    estimate: float
    sigma: float | None
    cr_percent: float | None
    insensitivity_percent: float | None
    flags: tuple

    def as_row(self) -> list:
        return [self.name, self.estimate, self.sigma, self.cr_percent,
                self.insensitivity_percent, ", ".join(self.flags)]


HEADER = ["parameter", "estimate", "1-sigma", "CR [%]", "insensitivity [%]", "flags"]


def parameter_accuracy(fit) -> tuple:
    """:class:`ParameterAccuracy` per free quantity of a
    :class:`~inflowsim.identify.results.FitResult`, in ``fit.free`` order."""
    names = list(fit.free)
    sig = np.array([fit.sigma.get(n.split("=")[0]) or np.nan for n in names], dtype=float)
    ok = np.isfinite(sig) & (sig > 0)
    ins = np.full(len(names), np.nan)
    if ok.any():
        R = np.asarray(fit.correlation, dtype=float)[np.ix_(ok, ok)]
        C = R * np.outer(sig[ok], sig[ok])
        try:
            M = np.linalg.inv(C)
            ins[ok] = 1.0 / np.sqrt(np.maximum(np.diag(M), 1e-300))
        except np.linalg.LinAlgError:
            pass
    out = []
    for i, n in enumerate(names):
        est = float(fit.parameters[n.split("=")[0]])
        flags = []
        if not ok[i]:
            flags.append("not determined")
            out.append(ParameterAccuracy(n, est, None, None, None, tuple(flags)))
            continue
        cr = 100 * sig[i] / abs(est) if est else np.inf
        ip = 100 * ins[i] / abs(est) if est and np.isfinite(ins[i]) else np.inf
        if cr > CR_LIMIT:
            flags.append(f"CR > {CR_LIMIT:g} %")
        if ip > INSENSITIVITY_LIMIT:
            flags.append(f"insensitive (> {INSENSITIVITY_LIMIT:g} %)")
        if np.isfinite(ip) and ip > 0 and cr > CORRELATED * ip:
            flags.append("correlated")
        out.append(ParameterAccuracy(n, est, float(sig[i]), float(cr), float(ip),
                                     tuple(flags)))
    return tuple(out)


__all__ = ["CORRELATED", "ParameterAccuracy", "HEADER", "parameter_accuracy"]
