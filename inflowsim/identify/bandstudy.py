"""Band study (the paper's Figure 6): estimates and bounds against the lower
frequency limit, the upper limit fixed.  Each fit is warm-started from the
previous one (only the first tries every starting point)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.structure import Structure
from ..progress import bar
from .estimator import as_records, identify
from .transform import DEFAULT_BAND


@dataclass(frozen=True, eq=False)
class BandStudy:
    """``lower_hz`` (snapped lower limits), per parameter ``estimates`` and ``sigma``
    (lists aligned with ``lower_hz``), ``cost``, ``n_freq`` and ``converged`` per fit.

    Attributes
    ----------
    structure : str
        The structure fitted.
    upper_hz : float
        Upper band limit [Hz].
    lower_hz : ndarray
        Snapped lower limits [Hz].
    estimates, sigma : dict of str to list
        Per parameter, estimates and 1-sigma bounds aligned with ``lower_hz`` (SI).
    cost : list of float
        Cost (12) per fit [-].
    n_freq : list of int
        Frequencies per fit [-].
    converged : list of bool
        Whether each fit converged.
    """

    structure: str
    upper_hz: float
    lower_hz: np.ndarray
    estimates: dict
    sigma: dict
    cost: list
    n_freq: list
    converged: list

    def to_json(self) -> dict:
        return {"structure": self.structure, "upper_hz": self.upper_hz,
                "lower_hz": [float(f) for f in self.lower_hz],
                "estimates": {n: [float(v) for v in vs] for n, vs in self.estimates.items()},
                "sigma": {n: list(vs) for n, vs in self.sigma.items()},
                "cost": self.cost, "n_freq": self.n_freq, "converged": self.converged}


def default_lowers(record, upper_hz, n_points=10):
    """Lower limits: grid bins from the second bin up to a third of the band."""
    df = 1.0 / record.duration
    k_hi = max(3, int((upper_hz / df) / 3))
    ks = np.unique(np.linspace(2, k_hi, n_points).round().astype(int))
    return ks * df


def band_study(records, structure, upper_hz=DEFAULT_BAND[1], lowers_hz=None,
               progress=None, **kw) -> BandStudy:
    """Fit ``structure`` over ``[f1, upper_hz]`` for each lower limit ``f1`` [Hz].

    ``lowers_hz`` default: :func:`default_lowers` (ten limits from ``2/T``).
    Further keywords (``fixed``, ``ties``) go to :func:`identify`.  Fits run from
    the highest lower limit (fewest frequencies, the paper's band) downwards,
    each starting from the previous estimates.

    Parameters
    ----------
    records : Record, path or list of them
        The flight-test records (each with its own flight condition and trim).
    structure : str or Structure
        The structure fitted.
    upper_hz : float
        Upper band limit [Hz].
    lowers_hz : sequence of float, optional
        Lower band limits [Hz] (default :func:`default_lowers`).
    progress : callable, optional
        Progress (:func:`inflowsim.progress.bar`): a step per fit.
    **kw
        ``fixed``, ``ties``: as :func:`~inflowsim.identify.identify` takes them.
    """
    s = Structure.parse(structure)
    recs = as_records(records)
    lowers = np.sort(np.asarray(lowers_hz if lowers_hz is not None
                                else default_lowers(recs[0], upper_hz), dtype=float))
    fits = {}
    start = kw.pop("start", None)
    with bar(progress, len(lowers), f"bandstudy {s.name}", "fit") as b:
        for f1 in lowers[::-1]:
            b.set_postfix_str(f"lower limit {f1:.4g} Hz")
            r = identify(recs, s, band_hz=(f1, upper_hz), start=start,
                         multistart=start is None or not fits, **kw)
            b.set_postfix_str(f"lower {r.band_hz[0]:.4g} Hz: cost {r.cost:.4f}")
            b.update()
            fits[f1] = r
            start = {n: v for n, v in r.parameters.items() if n not in r.fixed}
    order = [fits[f] for f in lowers]
    names = list(order[0].parameters)
    return BandStudy(
        structure=s.name, upper_hz=float(order[0].band_hz[1]),
        lower_hz=np.array([r.band_hz[0] for r in order]),
        estimates={n: [r.parameters[n] for r in order] for n in names},
        sigma={n: [r.sigma.get(n) for r in order] for n in names},
        cost=[r.cost for r in order], n_freq=[r.n_freq for r in order],
        converged=[r.converged for r in order])


__all__ = ["BandStudy", "default_lowers", "band_study"]
