"""``diagnose`` and the ladder: where a model fails, which effect is missing, add it
and watch the error fall (``workflow.md``).

:func:`diagnose` fits the structure (or evaluates given parameters), reports the
failures of :mod:`inflowsim.failures`, and ranks every candidate effect with
:mod:`inflowsim.candidates`.  :func:`ladder` adds the best significant effect and
ranks again until nothing significant is left: one-shot ranking is not enough
when two effects explain similar residuals.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from .candidates import ALPHA, Candidate, rank_candidates
from .failures import (Failure, parameter_failures, residual_analysis, residual_tests,
                       spectrum_failures)
from .identify import identify
from .identify.transform import DEFAULT_BAND
from .model import build_model
from .structure import Structure


@dataclass(frozen=True)
class Diagnosis:
    """What :func:`diagnose` found.

    ``failures`` where the fitted structure and the measurements part;
    ``candidates`` ranked best first; ``missing_effect`` the best significant
    candidate or ``None``.
    """

    structure: Structure
    fit: object = field(repr=False)
    failures: tuple
    candidates: tuple
    missing_effect: str | None
    band_hz: tuple

    def to_json(self) -> dict:
        return {"structure": self.structure.name, "effects": list(self.structure.effects),
                "cost": float(self.fit.cost), "band_hz": list(self.band_hz),
                "failures": [f.to_json() for f in self.failures],
                "candidates": [c.to_json() for c in self.candidates],
                "missing_effect": self.missing_effect,
                "parameters": {n: {"estimate": float(v), "sigma": self.fit.sigma.get(n)}
                               for n, v in self.fit.parameters.items()},
                "fit": self.fit.fit}


def _as_list(records):
    return list(records) if isinstance(records, (list, tuple)) else [records]


def failures_of(records, fit, band_hz) -> list[Failure]:
    """Failures of a fitted structure on each record (spectra, residual tests,
    estimates)."""
    out: list[Failure] = []
    for rec in _as_list(records):
        # each record's own flight condition and trim
        m = build_model(fit.structure, fit.parameters, rec.constants)
        ra = residual_analysis(rec, m, band_hz)
        out += spectrum_failures(ra) + residual_tests(ra, rec, m)
    out += parameter_failures(fit.parameters, fit.sigma, fit.correlation, list(fit.free),
                              omega=fit.constants[0].omega)
    out += [Failure("estimation", "fit", w) for w in fit.warnings]
    return out


def diagnose(records, structure, band_hz=DEFAULT_BAND, start=None, pool=None,
             alpha=ALPHA, progress=None, base_fit=None) -> Diagnosis:
    """Fit ``structure``, report where it fails, rank the missing effects.

    Parameters
    ----------
    records : Record or list of Record
    structure : str or Structure
    band_hz : (float, float)
        Analysis band [Hz], snapped to the records' grids.
    start : dict, optional
        Start values (e.g. a parameter file); default theory and paper values.
    pool : list of str, optional
        Candidate effects to try (default: the whole catalogue).
    alpha : float
        Significance level per candidate.
    """
    recs = _as_list(records)
    s = Structure.parse(structure)
    fit = base_fit or identify(recs, s, band_hz=band_hz, start=start, progress=progress)
    band = fit.band_hz
    fails = failures_of(recs, fit, band_hz)
    cands = rank_candidates(recs, fit, band_hz, identify, pool, alpha, progress)
    best = next((c.effect for c in cands if c.significant), None)
    return Diagnosis(s, fit, tuple(fails), tuple(cands), best, tuple(band))


@dataclass(frozen=True)
class Rung:
    """One structure tried on the ladder, with the diagnosis made on it."""

    structure: Structure
    fit: object = field(repr=False)
    added: str | None
    diagnosis: Diagnosis | None = field(repr=False, default=None)


@dataclass(frozen=True)
class Ladder:
    rungs: tuple
    band_hz: tuple

    @property
    def final(self) -> Rung:
        return self.rungs[-1]

    def to_json(self) -> dict:
        return {"band_hz": list(self.band_hz), "rungs": [
            {"structure": r.structure.name, "effects": list(r.structure.effects),
             "added": r.added, "cost": float(r.fit.cost), "fit": r.fit.fit,
             "S_diag": [[float(v) for v in abs(S.diagonal())] for S in r.fit.S],
             "parameters": {n: {"estimate": float(v), "sigma": r.fit.sigma.get(n)}
                            for n, v in r.fit.parameters.items()},
             "candidates": [c.to_json() for c in r.diagnosis.candidates] if r.diagnosis else [],
             "missing_effect": r.diagnosis.missing_effect if r.diagnosis else None}
            for r in self.rungs]}


def ladder(records, structure, band_hz=DEFAULT_BAND, max_steps=6, pool=None, alpha=ALPHA,
           progress=None) -> Ladder:
    """Add the best significant effect and rank again, until none is significant.

    The next rung's fit is the winning candidate's own fit (already made while
    ranking), so each rung costs one ranking.
    """
    recs = _as_list(records)
    d = diagnose(recs, structure, band_hz, pool=pool, alpha=alpha, progress=progress)
    rungs = [Rung(d.structure, d.fit, None, d)]
    for _ in range(max_steps):
        if d.missing_effect is None:
            break
        win: Candidate = next(c for c in d.candidates if c.effect == d.missing_effect)
        if progress:
            progress(f"adding {win.effect}: cost {d.fit.cost:.6g} -> {win.fit.cost:.6g}")
        d = diagnose(recs, win.fit.structure, band_hz, pool=pool, alpha=alpha,
                     progress=progress, base_fit=win.fit)
        rungs.append(Rung(d.structure, d.fit, win.effect, d))
    return Ladder(tuple(rungs), d.band_hz)


def explicit_ladder(records, structures, band_hz=DEFAULT_BAND, progress=None) -> Ladder:
    """A ladder over given structures (e.g. the paper's basic -> empirical -> glauert)."""
    recs = _as_list(records)
    rungs, prev = [], None
    for s in structures:
        st = Structure.parse(s)
        fit = identify(recs, st, band_hz=band_hz, progress=progress)
        added = None if prev is None else "+".join(
            e for e in st.effects if e not in prev.effects) or None
        rungs.append(Rung(st, fit, added, None))
        prev = st
    return Ladder(tuple(rungs), tuple(rungs[-1].fit.band_hz))
