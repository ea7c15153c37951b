"""Which effect is missing: refit with each candidate, accept only what is worth it.

For each effect of the catalogue that the structure lacks and may take, the
structure plus that effect is fitted to the same records and band, starting
from the base estimates and the effect's neutral values (so the start
reproduces the base fit: every candidate *nests* the base).  A candidate is
**accepted** only when all four hold, and named only when the fifth does:

1. **Significant.**  With the error covariance estimated, the cost (12) is the
   negative log-likelihood of complex Gaussian residuals up to a constant, so
   ``2 (J_base - J_with)`` is chi-square with as many degrees of freedom as the
   effect adds (``model.md`` section 7); for a parameter whose neutral value is
   the edge of its range (``flap_inertia = 0``, the first-order limit) the law
   is the 50:50 mixture of chi-square with 0 and 1 degree of freedom (Self and
   Liang, 1987).  Level ``alpha = 1e-3`` per candidate.
   **Parsimonious:** the Schwarz criterion prefers it with at least positive
   evidence, ``2 (J_base - J_with) - dof ln(n_data) > schwarz_min`` (2: the
   approximate ``2 ln B`` of Kass and Raftery, JASA 90, 1995, whose "positive"
   starts at 2): for one added parameter this is weaker than the level above,
   for an effect of six or seven free gains it is stronger (the gains can fit a
   weak forcing of another shape plus the noise: ``bench/README.md``; and the
   best of an effect's part variants, below, is a choice among three).
2. **Plausible.**  Every added parameter is determined by the data and its
   estimate, within 3 sigma, reaches its physical range (sign, theory range:
   ``Effect.plausible``); an estimate the data do not determine cannot be shown
   plausible.  An effect made of separate physical terms (``Effect.parts``:
   Glauert's ``F`` on the rates and ``G`` on the in-plane velocities) whose
   record leaves a part undetermined (``c1..c4`` multiply the in-plane
   velocities, which a record of control inputs never moves) is refitted with
   that whole part held at its neutral values (``held``) and tested with the
   degrees of freedom that remain: the term the record can show is judged on its
   own, and the held parameters are reported as such.  Where the record
   determines every part, the effect is also fitted with each part alone (the
   others held at neutral), and the variant with the largest Schwarz gain is the
   candidate: on the nonlinear blade truth at 256 Hz, seed 7, Glauert's ``F``
   alone gains 10.4 where all seven gains lose 2.1 (``bench/README.md``).  An
   effect of one part (``hub-velocity-coupling``'s gain matrix) is all or nothing.
3. **Material.**  The candidate explains at least ``material`` (10 %) of the
   base residual's excess over the noise floor: of ``D_base - D_white``, where
   ``D`` is the residual's level deviance from white noise at the floor
   (:func:`inflowsim.diagnose.failures.level_deviance`, ``sum nf (m - 1 - ln m)`` over
   the channels, ``m`` a channel's mean power over the floor in the band: the
   likelihood-ratio statistic of the level) and ``D_white`` its mean for noise
   alone; a base residual with no excess has nothing to explain.  (The per-bin
   deviance, ``sum r - 1 - ln r`` over the bins, adds how unevenly the power
   falls on the bins, whose scatter for noise hid a model error spread over the
   band: ``bench/README.md``.)  An effect
   that is significant only because the record is long is not what the
   residual is made of.  Where a record's sensor noise is coloured (its level
   in the band :data:`~inflowsim.diagnose.failures.COLOURED` times the floor or more,
   :mod:`inflowsim.diagnose.lpm`) the floor says little, and both the excess and
   the share are taken of the residual's *input-correlated excess*
   (:mod:`inflowsim.diagnose.excess`: its power in the span of smooth response
   errors over the in-band noise level, less what noise alone gives).
4. **Whiter.**  The refit's residual spectrum is closer to white noise at the
   floor (``D`` falls): an effect that pushes the residual *below* the floor
   fits the noise, not the physics.  Under coloured noise: the input-correlated
   excess falls.

5. **Unrivalled.**  The candidate to name is not explained by a more likely
   one with no more parameters (:mod:`inflowsim.diagnose.rivals`): with that
   rival in the model it is no longer significant.  The rival, if its refit is
   whiter, is named in its place.  A candidate of three or more parameters is
   not named before a pair of smaller candidates that, fitted together with
   fewer parameters, have the larger Schwarz gain; the pair's better accepted
   member is named, and the flexible one is judged again on the next rung.  Where
   no such pair wins, an effect of several parts fitted whole is also compared
   with an accepted candidate it explains plus one of its own parts alone.

Accepted candidates are ranked by the Schwarz criterion gain ``2 (J_base -
J_with) - dof ln(n_data)`` (``n_data`` the real numbers fitted), so an effect
with one parameter that explains nearly as much as one with seven comes first;
the rest follow by p-value.  When nothing is accepted and the residual is still
structured, the diagnosis says so (:func:`inflowsim.diagnose.failures.unexplained`)
instead of adding a small spurious effect.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import stats

from ..model.effects import CATALOGUE
from ..defaults import ALPHA
from ..errors import InputError
from ..model.presets import theory_parameters
from ..model.structure import Structure
from .rule import DEFAULT_RULE, Rule, rule_with



@dataclass(frozen=True)
class Candidate:
    """One candidate effect tried on top of a base fit.

    ``significant``, ``plausible``, ``share`` (of the excess over the floor
    explained), ``whiter`` (residual structure fell) are the four tests;
    ``accepted`` all of them; ``reason`` says which failed, in words.
    """

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
    schwarz_gain: float = 0.0
    plausible: bool = False
    share: float = 0.0
    structure_before: float = 0.0
    structure_after: float = 0.0
    whiteness_before: float = 0.0      # deviance from white noise at the floor
    whiteness_after: float = 0.0
    accepted: bool = False
    reason: str = ""
    #: parameters of the effect the data did not determine, held at their neutral values
    held: tuple = ()
    #: what ``whiteness_before``/``_after`` measure: ``"level deviance"`` (from white
    #: noise at the floor), ``"input-correlated excess"`` (a record with coloured
    #: noise) or, in a study, ``"deviance"`` (per bin)
    measure: str = "level deviance"
    #: a more likely candidate that explains this one (:mod:`inflowsim.diagnose.rivals`)
    explained_by: str | None = None
    #: the candidate this one displaced as the one to name
    displaced: str | None = None
    #: an effect of several parts (``Effect.parts``) fitted with one part alone:
    #: ``((held, dof, fit), ...)``, the others held at neutral; empty otherwise
    variants: tuple = field(repr=False, compare=False, default=())

    @property
    def whiter(self) -> bool:
        return self.whiteness_after < self.whiteness_before

    def to_json(self) -> dict:
        return {"effect": self.effect, "cost_reduction": self.cost_reduction,
                "significant": self.significant, "accepted": self.accepted,
                "reason": self.reason, "statistic": self.statistic, "dof": self.dof,
                "log10_p_value": self.log10_p, "schwarz_gain": self.schwarz_gain,
                "plausible": self.plausible, "share_of_excess": self.share,
                "held_at_neutral": list(self.held),
                "structure_before": self.structure_before,
                "structure_after": self.structure_after,
                "deviance_before": self.whiteness_before,
                "deviance_after": self.whiteness_after, "measure": self.measure,
                "explained_by": self.explained_by, "displaced": self.displaced,
                "physics": self.physics,
                "structure": self.structure,
                "parameters": {n: {"estimate": e, "sigma": s} for n, (e, s) in self.added.items()},
                **({"error": self.error} if self.error else {})}


def applicable(structure: Structure, pool=None) -> list[str]:
    """Effects not in ``structure`` that may be added to it (``pool``, default the
    catalogue's offered effects)."""
    out = []
    for name in pool or [n for n, e in CATALOGUE.items() if e.offered]:
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


def lr_test(j_base, j_new, dof, boundary=0):
    """``(statistic, dof, log10 p)`` of ``2 (J_base - J_new)``: chi-square with ``dof``
    degrees of freedom, or for ``boundary`` parameters at the edge of their range
    the mixture ``2^-b sum_i C(b, i) chi2(dof - b + i)`` (Self and Liang)."""
    stat = max(0.0, 2.0 * (j_base - j_new))
    d = max(dof, 1)
    if not boundary:
        return stat, d, float(stats.chi2.logsf(stat, d) / np.log(10))
    b = min(boundary, d)
    if stat == 0.0:
        return stat, d, 0.0
    p = sum(stats.binom.pmf(i, b, 0.5) * (stats.chi2.sf(stat, d - b + i) if d - b + i > 0
                                         else 0.0) for i in range(b + 1))
    return stat, d, float(np.log10(max(p, 1e-300)))


def floor_cost(fit, floors) -> float:
    """``J_floor - J_fit``: the cost (12) the fit would have if every record's
    residual sat at its noise floor (``floors``: per record, per-bin noise power of
    each flap channel, ``(3, nf)``), less its own (negative: how far above the
    floor it is)."""
    out = 0.0
    for S, fl, d in zip(fit.S, floors, fit.data):
        nf = d.f_hz.size
        out += float(np.sum(np.log(fl))) - nf * float(np.log(np.real(np.linalg.det(S))))
    return out


def _plausible(eff, fit, constants, held=(), sigmas=DEFAULT_RULE.plausible_sigmas):
    """Every estimated parameter of the effect (all but ``held``) is determined by
    the data and reaches its plausible range within ``sigmas``: an
    estimate the data do not determine cannot be shown plausible (fix or tie it,
    or add excitation, and try the effect again)."""
    ranges = eff.plausible_ranges(constants)
    estimated = [n for n in eff.parameters if n not in held]
    undetermined = [n for n in estimated if fit.sigma.get(n) is None]
    if undetermined:
        return False, (f"{', '.join(undetermined)} not determined by the data (fix or "
                       "tie, or add excitation)")
    for n in estimated:
        est, sig = fit.parameters[n], fit.sigma[n]
        if n not in ranges:
            continue
        lo, hi, why = ranges[n]
        if est + sigmas * sig < lo or est - sigmas * sig > hi:
            return False, (f"{n} = {est:.4g} +- {sig:.2g} is outside [{lo:g}, {hi:g}]: "
                           f"{why}")
    return True, ""


def schwarz_gain(j_base, j_new, dof, n_freq) -> float:
    """``2 (J_base - J_new) - dof ln(n_data)``, ``n_data = 6 n_freq`` the real numbers
    fitted (three complex channels a bin): the criterion candidates rank by."""
    return float(2.0 * (j_base - j_new) - dof * np.log(6 * n_freq))


def _best_parts(records, base_fit, eff, s, start, base_fixed, fit, dof, band_hz, fit_fn):
    """The effect whole or one of its parts alone (the others held at neutral),
    whichever has the largest Schwarz gain: ``(fit, held, dof, why held,
    variants)``, ``variants`` every part alone the data determine, as
    ``(held, dof, fit)``."""
    best = (schwarz_gain(base_fit.cost, fit.cost, dof, fit.n_freq), fit, (), dof)
    variants = []
    for part in eff.parts:
        others = tuple(n for q in eff.parts if q is not part for n in q)
        try:
            f = fit_fn(records, s, band_hz=band_hz, start=start,
                       fixed={**base_fixed, **{n: start[n] for n in others}})
        except InputError:
            continue
        if any(f.sigma.get(n) is None for n in part):
            continue
        d = dof - len(others)
        variants.append((others, d, f))
        gain = schwarz_gain(base_fit.cost, f.cost, d, f.n_freq)
        if gain > best[0]:
            best = (gain, f, others, d)
    _, fit, held, dof = best
    return (fit, held, dof, "not worth their parameters beside the effect's other part",
            tuple(variants))


def try_effect(records, base_fit, effect: str, band_hz, fit_fn, alpha=None,
               judge=None, rule: Rule | None = None) -> Candidate:
    """Fit ``base + effect`` and test it by ``rule`` (default
    :data:`~.rule.DEFAULT_RULE`, its level ``alpha`` where given; ``judge(fit)``
    gives the residual measures; without it only the significance is known)."""
    rule = rule_with(rule, alpha)
    alpha = rule.alpha
    s = base_fit.structure.with_effect(effect)
    eff = CATALOGUE[effect]
    k = base_fit.constants[0]
    start = nested_start(base_fit, s, k)
    # what the base held stays held (values it was fitted with)
    base_fixed = {n: float(base_fit.parameters[n]) for n in (base_fit.fixed or ())
                  if n in s.parameters}
    dof = len(s.parameters) - len(base_fit.structure.parameters)
    held, held_why, variants = (), "not determined by the data", ()
    try:
        fit = fit_fn(records, s, band_hz=band_hz, start=start, fixed=base_fixed or None)
        # an effect of separate physical terms holds only what the record leaves
        # undetermined (a null direction of the information): it has no
        # information, so holding it biases nothing else, while holding a determined
        # parameter would (a single-axis record moves mux a little: Glauert's c1,
        # c3, c4 show, c2 not).  An effect of one term is all or nothing: half a
        # gain matrix is not that effect's physics, and its free half mimics others
        # (the nonlinear truth's direct in-plane forcing, one doublet)
        held = tuple(n for n in eff.parameters if fit.sigma.get(n) is None
                     and n not in base_fixed) if len(eff.parts) > 1 else ()
        if held and len(held) < len(eff.parameters):
            fit = fit_fn(records, s, band_hz=band_hz, start=start,
                         fixed={**base_fixed, **{n: start[n] for n in held}})
            dof -= len(held)
        else:
            held = ()
        if not held and len(eff.parts) > 1:
            fit, held, dof, held_why, variants = _best_parts(
                records, base_fit, eff, s, start, base_fixed, fit, dof, band_hz, fit_fn)
    except InputError as exc:
        return Candidate(effect, s.name, 0.0, 0.0, dof, 0.0, False, eff.physics, {},
                         None, str(exc), reason=str(exc))
    bnd = sum(1 for n in eff.boundary if n in s.parameters and n not in held)
    stat, d, lp = lr_test(base_fit.cost, fit.cost, dof, bnd)
    added = {n: (float(fit.parameters[n]), fit.sigma.get(n)) for n in eff.parameters}
    dj = float(base_fit.cost - fit.cost)
    significant = bool(lp < np.log10(alpha))
    plausible, why = _plausible(eff, fit, k, held, rule.plausible_sigmas)
    share, q0, q1, d0, d1 = 0.0, 0.0, 0.0, 0.0, 0.0
    reasons = []
    if judge is not None:
        base, new = judge(None), judge(fit)
        q0, q1 = base["structure"], new["structure"]
        d0, d1 = base["deviance"], new["deviance"]
        excess = d0 - base["white_deviance"]
        share = (d0 - d1) / excess if excess > 0 else 0.0
    if not significant and rule.uses("significant"):
        reasons.append(f"not significant (p = {10 ** lp:.2g} >= {alpha:g})")
    gain = schwarz_gain(base_fit.cost, fit.cost, d, fit.n_freq)
    if significant and gain <= rule.schwarz_min and rule.uses("parsimonious"):
        reasons.append(f"not worth its {d} parameters: Schwarz gain {gain:.1f} <= "
                       f"{rule.schwarz_min:g} (2 dJ = {stat:.1f} against {d} ln n = "
                       f"{d * np.log(6 * fit.n_freq):.1f})")
    if not plausible and rule.uses("plausible"):
        reasons.append(f"implausible: {why}")
    label = base["measure"] if judge is not None else "level deviance"
    floor_based = label != "input-correlated excess"
    if judge is not None and rule.uses("material"):
        if excess <= 0 and floor_based:
            reasons.append(f"the base residual is at the noise floor ({label} {d0:.1f} "
                           f"<= {base['white_deviance']:.1f} for noise): nothing to explain")
        elif excess <= 0:
            reasons.append(f"the base residual's input-correlated excess ({d0:.1f}) is no "
                           f"more than noise gives ({base['white_deviance']:.1f}): nothing "
                           "to explain")
        elif share < rule.material:
            what = "excess over the noise floor" if floor_based else \
                "input-correlated excess (coloured noise)"
            reasons.append(f"explains {100 * share:.1f} % of the residual's {what} "
                           f"(< {100 * rule.material:g} %)")
    if judge is not None and d1 >= d0 and rule.uses("whiter"):
        reasons.append(f"does not move the residual toward white noise at the floor "
                       f"({label} {d0:.1f} -> {d1:.1f})" if floor_based else
                       f"does not reduce the input-correlated excess ({d0:.1f} -> {d1:.1f})")
    accepted = not reasons and judge is not None
    reason = "; ".join(reasons) or "accepted"
    if held:
        reason += f" ({', '.join(held)} {held_why}: held at neutral)"
    return Candidate(effect, s.name, dj, stat, d, lp, significant, eff.physics, added, fit,
                     schwarz_gain=gain, plausible=plausible,
                     share=float(share), structure_before=q0, structure_after=q1,
                     whiteness_before=d0, whiteness_after=d1,
                     accepted=accepted, reason=reason, held=held, measure=label,
                     variants=variants)


def rank_candidates(records, base_fit, band_hz, fit_fn, pool=None, alpha=None,
                    progress=None, judge=None, rule: Rule | None = None) -> list[Candidate]:
    """Every applicable candidate tried and ranked: accepted ones first by Schwarz
    gain, then the rest by p-value."""
    out = []
    for name in applicable(base_fit.structure, pool):
        if progress:
            progress(f"trying {base_fit.structure.name}+{name}")
        out.append(try_effect(records, base_fit, name, band_hz, fit_fn, alpha, judge, rule))
    return rank(out)


def rank(cands) -> list[Candidate]:
    """Accepted first by Schwarz gain, then the rest by p-value; failed fits last."""
    return sorted(cands, key=lambda c: (c.error is not None, not c.accepted,
                                        -c.schwarz_gain if c.accepted else c.log10_p,
                                        -c.cost_reduction))
