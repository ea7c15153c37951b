"""Which effect is missing: refit with each candidate and test what it explains.

For each effect of the catalogue that the structure lacks and may take, the
structure plus that effect is fitted to the same records and band, starting
from the base estimates and the effect's neutral values (so the start
reproduces the base fit wherever the effect nests).  With the error covariance
estimated, the cost (12) is the negative log-likelihood of complex Gaussian
residuals up to a constant, so ``2 (J_base - J_with)`` is chi-square with as
many degrees of freedom as the effect adds (``model.md`` section 7).  An effect
with no parameter of its own (``flap-inertia``) does not nest; it is judged on
the same statistic with one degree of freedom, which is conservative.

Candidates are ranked by the log p-value of that statistic (most significant
first), then by cost reduction.  The default level ``alpha = 1e-3`` per
candidate keeps the chance of a false alarm over the whole catalogue below 1 %.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from .effects import CATALOGUE
from .errors import InputError
from .presets import theory_parameters
from .structure import Structure

ALPHA = 1e-3


@dataclass(frozen=True)
class Candidate:
    """One candidate effect tried on top of a base fit."""

    effect: str
    structure: str
    cost_reduction: float
    statistic: float
    dof: int
    log10_p: float
    significant: bool
    physics: str
    added: dict                      # {name: (estimate, sigma)} of the effect's parameters
    fit: object = field(repr=False, compare=False, default=None)
    error: str | None = None

    def to_json(self) -> dict:
        return {"effect": self.effect, "cost_reduction": self.cost_reduction,
                "significant": self.significant, "statistic": self.statistic,
                "dof": self.dof, "log10_p_value": self.log10_p, "physics": self.physics,
                "structure": self.structure,
                "parameters": {n: {"estimate": e, "sigma": s} for n, (e, s) in self.added.items()},
                **({"error": self.error} if self.error else {})}


def applicable(structure: Structure, pool=None) -> list[str]:
    """Effects not in ``structure`` that may be added to it."""
    out = []
    for name in pool or CATALOGUE:
        if name not in CATALOGUE:
            raise InputError(f"unknown effect {name!r} (known: {', '.join(CATALOGUE)})")
        if name in structure.effects:
            continue
        if any(a in structure.effects for a in CATALOGUE[name].alternatives):
            continue
        out.append(name)
    return out


def nested_start(base_fit, structure: Structure, constants) -> dict:
    """Start values for ``structure`` reproducing ``base_fit`` where it nests:
    base estimates, the new effects' neutral values, and a superseded ``tau``
    copied into ``tau0`` and ``tau_cs``."""
    start = theory_parameters(structure, constants)
    for e in structure.effects:
        start.update({n: v for n, v in CATALOGUE[e].neutral_values(constants).items()
                      if n in start})
    for n, v in base_fit.parameters.items():
        if n in start:
            start[n] = v
    if "tau" in base_fit.parameters and "tau0" in start and "tau0" not in base_fit.parameters:
        start["tau0"] = start["tau_cs"] = base_fit.parameters["tau"]
    return start


def _statistic(j_base, j_new, dof):
    stat = max(0.0, 2.0 * (j_base - j_new))
    d = max(dof, 1)
    return stat, d, float(stats.chi2.logsf(stat, d) / np.log(10))


def try_effect(records, base_fit, effect: str, band_hz, fit_fn, alpha=ALPHA) -> Candidate:
    """Fit ``base + effect`` and test the cost reduction."""
    s = base_fit.structure.with_effect(effect)
    eff = CATALOGUE[effect]
    start = nested_start(base_fit, s, base_fit.constants[0])
    dof = len(s.parameters) - len(base_fit.structure.parameters)
    try:
        fit = fit_fn(records, s, band_hz=band_hz, start=start)
    except InputError as exc:
        return Candidate(effect, s.name, 0.0, 0.0, dof, 0.0, False, eff.physics, {},
                         None, str(exc))
    stat, d, lp = _statistic(base_fit.cost, fit.cost, dof)
    added = {n: (float(fit.parameters[n]), fit.sigma.get(n)) for n in eff.parameters}
    return Candidate(effect, s.name, float(base_fit.cost - fit.cost), stat, dof, lp,
                     bool(lp < np.log10(alpha)), eff.physics, added, fit)


def rank_candidates(records, base_fit, band_hz, fit_fn, pool=None, alpha=ALPHA,
                    progress=None) -> list[Candidate]:
    """Every applicable candidate tried and ranked, best first."""
    out = []
    for name in applicable(base_fit.structure, pool):
        if progress:
            progress(f"trying {base_fit.structure.name}+{name}")
        out.append(try_effect(records, base_fit, name, band_hz, fit_fn, alpha))
    return sorted(out, key=lambda c: (c.error is not None, c.log10_p, -c.cost_reduction))
