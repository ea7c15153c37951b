"""``diagnose`` and the ladder: where a model fails, which effect is missing, add it
and watch the error fall (``workflow.md``).

:func:`diagnose` fits the structure (or evaluates given parameters), reports the
failures of :mod:`inflowsim.diagnose.failures`, and selects what is missing by the
rule (:func:`inflowsim.diagnose.rule.select`, its settings one
:class:`~inflowsim.diagnose.rule.Rule`), shown per atom by
:mod:`inflowsim.diagnose.candidates`.  :func:`ladder` adds what the rule adds and
selects again until nothing is accepted (line 5): one-shot ranking is not enough
when two effects explain similar residuals.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from .candidates import candidates_of
from .excess import judge
from .rule import (DEFAULT_RULE, Decision, Rule, atom_of, least_significant,
                   offered_effects, ranked, row_order, rule_with, select)
from .terms import missing_terms
from .failures import (Failure, _as_list, analyses_of, parameter_failures, residual_tests,
                       spectrum_failures, unexplained)
from ..identify import identify
from ..identify.identifiability import Identifiability, identifiability
from .verdict import Verdict, verdict
from .conditional import marked
from ..identify.transform import DEFAULT_BAND
from ..model.structure import Structure


@dataclass(frozen=True)
class Diagnosis:
    """What :func:`diagnose` found.

    ``failures`` where the fitted structure and the measurements part (with an
    ``unexplained`` finding when the residual keeps structure no candidate
    explains); ``decision`` the rule's table of scored structures and what it
    accepted (:mod:`inflowsim.diagnose.rule`); ``candidates`` its atoms, the added
    one first; ``missing_effect`` the effect of the atom the rule adds first, or
    ``None``; ``missing_effects`` those of the whole accepted structure.

    Attributes
    ----------
    structure : Structure
        The structure diagnosed.
    fit : FitResult
        Its fit.
    failures : tuple of Failure
        Where it fails.
    candidates : tuple of Candidate
        The atoms tried, the added one first.
    missing_effect : str or None
        The effect the rule adds first.
    band_hz : tuple of float
        The analysis band [Hz].
    analyses : tuple of ResidualAnalysis
        The fit's residual analyses, per record.
    verdict : Verdict or None
        The verdict (``docs/interface.md``: one vocabulary).
    identifiability : Identifiability or None
        What the records determine of the structure.
    missing_terms : object
        The score map of single-entry additions, or ``None``.
    decision : Decision or None
        The rule's table and what it accepted.
    """

    structure: Structure
    fit: object = field(repr=False)
    failures: tuple
    candidates: tuple
    missing_effect: str | None
    band_hz: tuple
    #: the base fit's :class:`~inflowsim.diagnose.failures.ResidualAnalysis` per record
    analyses: tuple = field(repr=False, default=())
    #: how much is left unexplained (:mod:`inflowsim.diagnose.verdict`)
    verdict: Verdict | None = None
    #: what the records determine of the base structure
    #: (:mod:`inflowsim.identify.identifiability`)
    identifiability: Identifiability | None = field(repr=False, default=None)
    #: the score map of single-entry additions at the base fit
    #: (:class:`~inflowsim.diagnose.terms.MissingTerms`)
    missing_terms: object = field(repr=False, default=None)
    #: the rule's decision (:class:`~inflowsim.diagnose.rule.Decision`)
    decision: Decision | None = field(repr=False, default=None)

    @property
    def missing_effects(self) -> tuple:
        """The effects of the accepted structure, the one added first (``()``:
        none)."""
        return self.decision.effects if self.decision is not None else ()

    @property
    def accepted(self):
        """The accepted structure's row (:class:`~inflowsim.diagnose.rule.Scored`),
        or ``None``; the ladder's next rung is ``decision.added_row``, its atom
        added first."""
        d = self.decision
        return d.chosen if d is not None and d.accepted else None

    def to_json(self) -> dict:
        return {"structure": self.structure.name, "effects": list(self.structure.effects),
                "cost": float(self.fit.cost), "band_hz": list(self.band_hz),
                "verdict": self.verdict.to_json() if self.verdict else None,
                "failures": [f.to_json() for f in self.failures],
                "candidates": [c.to_json() for c in self.candidates],
                "missing_effect": self.missing_effect,
                "missing_effects": list(self.missing_effects),
                "decision": self.decision.to_json() if self.decision else None,
                "parameters": parameter_entries(self.fit, self.identifiability),
                "identifiability": (self.identifiability.to_json()
                                    if self.identifiability else None),
                "missing_terms": (self.missing_terms.to_json()
                                  if self.missing_terms is not None else None),
                "missing_terms_freed": (self.missing_terms.freed_json()
                                        if self.missing_terms is not None else None),
                "missing_terms_answer": (self.missing_terms.answer_json()
                                         if self.missing_terms is not None else None),
                "fit": self.fit.fit}


def parameter_entries(fit, ident=None) -> dict:
    """``{name: {"estimate", "sigma", "determined", "held", ...}}`` of a fit: with
    ``ident`` (:func:`~inflowsim.identify.identifiability.identifiability`) every
    entry also carries its insensitivity, CIFER percentages, the bound with the
    held values' uncertainty and what it is conditional on.  An estimated entry
    carries ``sigma_robust`` and whether it is conditional on an incomplete
    structure (``conditional``, ``conditional_why``:
    :mod:`inflowsim.diagnose.conditional`)."""
    fixed = set(fit.fixed or ())
    out = {}
    for n, v in fit.parameters.items():
        s = fit.sigma.get(n)
        e = {"estimate": float(v), "sigma": s, "determined": s is not None,
             "held": n in fixed or (n not in fit.sigma)}
        if e["held"]:
            e["held_at"] = float(v)
        else:
            e["sigma_robust"] = getattr(fit, "sigma_robust", {}).get(n)
            if hasattr(fit, "conditional_entry"):
                e.update(fit.conditional_entry())
        out[n] = e
    if ident is not None:
        for p in ident.parameters:
            for n in p.name.split("="):
                if n in out:
                    out[n].update(p.to_json())
    return out


def verdict_reason(verd) -> str | None:
    """The reason a verdict gives every estimate of the structure judged to be
    conditional on an incomplete structure: excess left (``partly-explained``,
    ``unexplained``), or an effect named that is a stand-in (it fits the band
    without being the physics, so the estimates beside it absorb what it is not);
    ``None`` otherwise."""
    if verd is None:
        return None
    if verd.status in ("partly-explained", "unexplained"):
        where = ", ".join(f"{c} peaks at {r:.3g} times the floor near {f:.3g} Hz"
                          for c, f, r in verd.where)
        return (f"conditional on an incomplete structure: the verdict is {verd.status} "
                f"({where}); the bounds do not include the bias of what the structure "
                "lacks")
    standing = [x.effect for x in getattr(verd, "stand_ins", ())]
    if standing:
        return (f"conditional on an incomplete structure: {', '.join(standing)} "
                f"{'is a stand-in' if len(standing) == 1 else 'are stand-ins'} (see the "
                "verdict); the bounds do not include the bias of what the structure "
                "lacks")
    return None


def failures_of(records, fit, band_hz, analyses=None,
                rule: Rule = DEFAULT_RULE) -> list[Failure]:
    """Failures of a fitted structure on each record (spectra, residual tests,
    estimates).

    Parameters
    ----------
    records, fit, band_hz
        The records, the fitted structure and the analysis band [Hz], as
        :func:`analyses_of`.
    analyses : list of ResidualAnalysis, optional
        The fit's residual analyses (default: computed, :func:`analyses_of`).
    rule : Rule
        The settings (:class:`~inflowsim.diagnose.rule.Rule`): the tests' level
        and lags, the floor band, what is coloured noise.
    """
    out: list[Failure] = []
    for ra in analyses or analyses_of(records, fit, band_hz, rule=rule):
        out += spectrum_failures(ra, rule=rule) + residual_tests(ra, rule=rule)
    out += parameter_failures(fit.parameters, fit.sigma, fit.correlation, list(fit.free),
                              omega=fit.constants[0].omega, hub=fit.constants[0].hub)
    out += [Failure("estimation", "fit", w) for w in fit.warnings]
    return out


def diagnose(records, structure, band_hz=DEFAULT_BAND, start=None, pool=None,
             alpha=None, progress=None, base_fit=None, hold=None,
             assess=True, manoeuvres=None, rule: Rule | None = None) -> Diagnosis:
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
    alpha : float, optional
        Significance level per test [-]: ``rule.alpha`` where given
        (:data:`~inflowsim.diagnose.rule.LEGACY`).
    hold : {"continuous", "zoh", "foh"}, optional
        Intersample behaviour of the records' inputs (default each record's own).
    rule : Rule, optional
        The settings of the selection and the tests
        (:class:`~inflowsim.diagnose.rule.Rule`; default
        :data:`~inflowsim.diagnose.rule.DEFAULT_RULE`).
    progress : callable, optional
        Progress (:mod:`inflowsim.progress`): the base fit's, a bar per lattice.
    base_fit : FitResult, optional
        The structure's fit when already made (the ladder's next rung).
    assess : bool
        Say what the records determine of the base structure
        (``Diagnosis.identifiability``, with the standard manoeuvres that would
        determine the rest); the ladder asks it of its last rung only.
    manoeuvres : callable, optional
        The manoeuvres whose added information the assessment reports
        (:func:`inflowsim.flighttest.advice.standard_manoeuvres`, as the commands
        pass); ``None``: none.
    """
    recs = _as_list(records)
    s = Structure.parse(structure)
    rule = rule_with(rule, alpha=alpha)
    fit = base_fit or identify(recs, s, band_hz=band_hz, start=start, progress=progress,
                               hold=hold)
    band = fit.band_hz
    analyses = analyses_of(recs, fit, band_hz, rule=rule)
    fails = failures_of(recs, fit, band_hz, analyses, rule)

    def fit_fn(r, st, band_hz, start, fixed=None):
        return identify(r, st, band_hz=band_hz, start=start, fixed=fixed, hold=hold)
    dec = select(recs, fit, band_hz, fit_fn, pool, judge(recs, band_hz, fit, analyses, rule),
                 rule, progress)
    cands = candidates_of(dec)
    if dec.accepted:
        verd = verdict(analyses, analyses_of(recs, dec.chosen.fit, band_hz,
                                             check_colour=False, rule=rule),
                       dec.effects, fit=dec.chosen.fit, rule=rule,
                       alone=_alone(recs, dec, analyses, band_hz, rule))
    else:
        fails += unexplained(analyses, rule=rule)
        verd = verdict(analyses, analyses, (), rule=rule)
    best = dec.effects[0] if dec.accepted else None
    ident = identifiability(recs, fit, band_hz, hold, manoeuvres) if assess else None
    # the base fit's estimates are conditional where its residual keeps excess
    fit = marked(fit, analyses, reason=verdict_reason(verd), rule=rule)
    return Diagnosis(s, fit, tuple(fails), tuple(cands), best, tuple(band),
                     tuple(analyses), verd, ident,
                     missing_terms(recs, fit, band_hz, hold) if assess else None, dec)


def _alone(recs, dec, analyses, band_hz, rule) -> dict | None:
    """``{effect: share of the excess it removes alone}`` where the decision names
    two or more effects: each effect's best single row of the lattice (largest
    statistic, equal within ``rule.tie`` by the rule's order), its residual analysed (:func:`~inflowsim.diagnose.verdict.excess_share`);
    ``None`` for one effect, or where an effect has no row of its own."""
    from .verdict import excess_share
    if len(dec.effects) < 2:
        return None
    out = {}
    for e in dec.effects:
        rows = [r for r in dec.rows if tuple(r.effects) == (e,) and r.fit is not None]
        if not rows:
            return None
        best = ranked(rows, lambda r: r.statistic, row_order, rule.tie)[0]
        out[e] = excess_share(analyses, analyses_of(recs, best.fit, band_hz,
                                                    check_colour=False, rule=rule))
    return out


@dataclass(frozen=True)
class Rung:
    """One structure tried on the ladder, with the diagnosis made on it.

    Attributes
    ----------
    structure : Structure
        The structure of the rung.
    fit : FitResult
        Its fit.
    added : str or None
        The effects added on this rung, ``"a+b"`` (``None`` on the first).
    diagnosis : Diagnosis or None
        The diagnosis made on it.
    analyses : tuple of ResidualAnalysis
        The fit's residual analyses per record.
    atoms : tuple of str
        The rule's atoms added (an effect, or one part of one: ``glauert (k0p, kc, ks)``).
    indistinguishable : tuple
        ``((atom, Vuong z), ...)``: the other admissible single atoms of the step
        that added this rung's atom which the record cannot tell from it (the
        deciding :attr:`~inflowsim.diagnose.rule.Decision.indistinguishable`).
    """

    structure: Structure
    fit: object = field(repr=False)
    #: the effects added on this rung, ``"a+b"`` (``None`` on the first)
    added: str | None
    diagnosis: Diagnosis | None = field(repr=False, default=None)
    #: the fit's residual analyses per record (its diagnosis's, when it has one)
    analyses: tuple = field(repr=False, default=())
    #: the rule's atoms added on this rung (an effect, or one part of one)
    atoms: tuple = ()
    #: ``((atom, Vuong z), ...)`` the record cannot tell from the atom added here
    indistinguishable: tuple = ()


@dataclass(frozen=True)
class Ladder:
    """What :func:`ladder` (or :func:`explicit_ladder`) climbed.

    Attributes
    ----------
    rungs : tuple of Rung
        The structures tried, in order.
    band_hz : tuple of float
        The analysis band [Hz].
    verdict : Verdict or None
        The verdict on the last rung.
    identifiability : Identifiability or None
        What the records determine of the last rung.
    removed : tuple of (str, float)
        Atoms removed as explained by later ones, with ``log10 p`` [-].
    """

    rungs: tuple
    band_hz: tuple
    #: how much of the first rung's excess the effects added leave unexplained
    verdict: Verdict | None = None
    #: what the records determine of the final structure
    identifiability: Identifiability | None = field(repr=False, default=None)
    #: atoms added on a rung and removed at the end, not significant beside the
    #: effects added after them: ``((atom, log10 p), ...)``
    removed: tuple = ()

    @property
    def final(self) -> Rung:
        return self.rungs[-1]

    def to_json(self) -> dict:
        last = len(self.rungs) - 1
        return {"band_hz": list(self.band_hz),
                "verdict": self.verdict.to_json() if self.verdict else None,
                "removed": [{"atom": a, "log10_p_beside_others": lp}
                            for a, lp in self.removed],
                "identifiability": (self.identifiability.to_json()
                                    if self.identifiability else None),
                "missing_terms": (self.final.diagnosis.missing_terms.to_json()
                                  if self.final.diagnosis is not None
                                  and self.final.diagnosis.missing_terms is not None
                                  else None),
                "missing_terms_freed": (self.final.diagnosis.missing_terms.freed_json()
                                        if self.final.diagnosis is not None
                                        and self.final.diagnosis.missing_terms is not None
                                        else None),
                "missing_terms_answer": (self.final.diagnosis.missing_terms.answer_json()
                                         if self.final.diagnosis is not None
                                         and self.final.diagnosis.missing_terms is not None
                                         else None),
                "rungs": [
            {"structure": r.structure.name, "effects": list(r.structure.effects),
             "added": r.added, "atoms": list(r.atoms),
             "indistinguishable_from": [{"atom": a, "vuong_z": z}
                                        for a, z in r.indistinguishable],
             "cost": float(r.fit.cost),
             "fit": r.fit.fit,
             "S_diag": [[float(v) for v in abs(S.diagonal())] for S in r.fit.S],
             "parameters": parameter_entries(r.fit, self.identifiability
                                             if i == last else None),
             "candidates": [c.to_json() for c in r.diagnosis.candidates] if r.diagnosis else [],
             "missing_effect": r.diagnosis.missing_effect if r.diagnosis else None,
             "decision": (r.diagnosis.decision.to_json()
                          if r.diagnosis and r.diagnosis.decision else None)}
            for i, r in enumerate(self.rungs)]}


def ladder(records, structure, band_hz=DEFAULT_BAND, max_steps=None, pool=None,
           alpha=None, progress=None, hold=None, manoeuvres=None,
           rule: Rule | None = None) -> Ladder:
    """Add what the rule accepts (:mod:`inflowsim.diagnose.rule`: one atom, or a pair)
    and diagnose again, until nothing is accepted.

    The next rung's fit is the accepted structure's own fit (already made on the
    lattice), so each rung costs one lattice.

    Parameters
    ----------
    records : Record, path or list of them
        The flight-test records (each with its own flight condition and trim).
    structure : str or Structure
        The starting structure (a preset, then ``+effect`` terms).
    band_hz : (float, float)
        Analysis band [Hz], snapped to the records' grids.
    max_steps : int, optional
        Rungs added at most (and atoms removed at most) [-]: ``rule.max_steps``
        where given (:data:`~inflowsim.diagnose.rule.LEGACY`).
    pool : list of str, optional
        Candidate effects (default the catalogue's offered ones).
    alpha : float, optional
        Significance level per test [-]: ``rule.alpha`` where given.
    progress : callable, optional
        Progress (:mod:`inflowsim.progress`): a bar per lattice, a line per rung.
    hold : {"continuous", "zoh", "foh"}, optional
        Intersample behaviour of the records' inputs (default each record's own).
    manoeuvres : callable, optional
        The manoeuvres whose information the last rung's assessment reports
        (:func:`inflowsim.flighttest.advice.standard_manoeuvres`).
    rule : Rule, optional
        The settings of the selection and the tests (default
        :data:`~inflowsim.diagnose.rule.DEFAULT_RULE`).
    """
    recs = _as_list(records)
    rule = rule_with(rule, alpha=alpha, max_steps=max_steps)
    d = diagnose(recs, structure, band_hz, pool=pool, rule=rule, progress=progress,
                 hold=hold, assess=False)
    rungs = [Rung(d.structure, d.fit, None, d, d.analyses)]
    removed, steps = [], 0
    while True:
        while steps < rule.max_steps:
            win = d.decision.added_row if d.decision is not None else None
            if win is None:
                break
            steps += 1
            if progress:
                progress(f"adding {' + '.join(win.atoms)}: cost {d.fit.cost:.6g} -> "
                         f"{win.fit.cost:.6g}")
            told = d.decision.indistinguishable
            d = diagnose(recs, win.fit.structure, band_hz, pool=pool, rule=rule,
                         progress=progress, base_fit=win.fit, hold=hold, assess=False)
            rungs.append(Rung(d.structure, d.fit, "+".join(win.effects), d, d.analyses,
                              win.atoms, told))
        # line 5's last clause: an atom added earlier that the later ones explain
        # (no longer significant beside them) is removed, the least significant first
        added_atoms = [a for r in rungs[1:] for a in r.atoms
                       if a not in {x for x, _ in removed}]
        worst = least_significant(recs, d.fit, added_atoms, band_hz, hold, rule)
        if worst is None or len(removed) >= rule.max_steps:
            break
        atom, fit, lp = worst
        removed.append((atom, lp))
        if progress:
            progress(f"removing {atom}: not significant beside the others (p = "
                     f"{10 ** lp:.2g})")
        gone = {atom_of(a).effect for a, _ in removed}
        pool = [e for e in (pool or offered_effects()) if e not in gone]
        d = diagnose(recs, fit.structure, band_hz, pool=pool, rule=rule,
                     progress=progress, base_fit=fit, hold=hold, assess=False)
        last = rungs[-1]
        rungs[-1] = dataclasses.replace(last, structure=d.structure, fit=d.fit,
                                        diagnosis=d, analyses=d.analyses)
    gone = {atom_of(a).effect for a, _ in removed if atom_of(a).whole}
    added = tuple(dict.fromkeys(e for r in rungs[1:] for e in r.added.split("+")
                                if e in d.structure.effects and e not in gone))
    verd = verdict(rungs[0].analyses, rungs[-1].analyses, added, fit=rungs[-1].fit,
                   rule=rule)
    # the last rung is the answer: it says what the records determine of it and,
    # where excess is left, where a term is missing
    ident = identifiability(recs, rungs[-1].fit, band_hz, hold, manoeuvres)
    last = dataclasses.replace(d, identifiability=ident,
                               missing_terms=missing_terms(recs, d.fit, band_hz, hold))
    fin = marked(rungs[-1].fit, rungs[-1].analyses, reason=verdict_reason(verd), rule=rule)
    rungs[-1] = dataclasses.replace(rungs[-1], diagnosis=dataclasses.replace(last, fit=fin),
                                    fit=fin)
    return Ladder(tuple(rungs), d.band_hz, verd, ident, tuple(removed))


def explicit_ladder(records, structures, band_hz=DEFAULT_BAND, progress=None,
                    hold=None, manoeuvres=None, rule: Rule = DEFAULT_RULE) -> Ladder:
    """A ladder over given structures (e.g. the paper's basic -> empirical -> glauert).

    Parameters
    ----------
    records : Record, path or list of them
        The flight-test records (each with its own flight condition and trim).
    structures : sequence of str
        The structures to fit, in order (``basic empirical glauert``).
    band_hz : (float, float)
        Analysis band [Hz].
    progress : callable, optional
        Progress (:mod:`inflowsim.progress`).
    hold : {"continuous", "zoh", "foh"}, optional
        Intersample behaviour of the records' inputs (default each record's own).
    manoeuvres : callable, optional
        The manoeuvres whose information the last rung's assessment reports.
    rule : Rule
        The settings of the tests (default
        :data:`~inflowsim.diagnose.rule.DEFAULT_RULE`).
    """
    recs = _as_list(records)
    rungs, prev = [], None
    for s in structures:
        st = Structure.parse(s)
        fit = identify(recs, st, band_hz=band_hz, progress=progress, hold=hold)
        added = None if prev is None else "+".join(
            e for e in st.effects if e not in prev.effects) or None
        analyses = tuple(analyses_of(recs, fit, band_hz, rule=rule))
        rungs.append(Rung(st, marked(fit, analyses, rule=rule), added, None, analyses))
        prev = st
    added = tuple(r.added for r in rungs[1:] if r.added)
    verd = verdict(rungs[0].analyses, rungs[-1].analyses, added, fit=rungs[-1].fit,
                   rule=rule)
    last = rungs[-1]
    rungs[-1] = dataclasses.replace(last, fit=marked(last.fit, last.analyses,
                                                     reason=verdict_reason(verd), rule=rule))
    return Ladder(tuple(rungs), tuple(rungs[-1].fit.band_hz), verd,
                  identifiability(recs, rungs[-1].fit, band_hz, hold, manoeuvres))


__all__ = ["Diagnosis", "parameter_entries", "analyses_of", "failures_of", "diagnose", "Rung", "Ladder", "ladder", "explicit_ladder"]
