"""The verdict every diagnosis and ladder carries: how much is left unexplained.

A channel has **excess** when its in-band residual is above the noise floor
(power over the floor tested as ``2 sum r ~ chi2(2 nf)``, level ``alpha``) *and*
structured: smooth across frequency and correlated with the inputs
(:func:`inflowsim.diagnose.failures.channel_structure`; coloured sensor noise
raises the level but is not input-correlated).  Then:

- ``no-missing-effect``: no effect named and no channel with excess;
- ``unexplained``: no effect named, yet a channel has excess;
- ``explained``: effects named and no channel keeps excess;
- ``partly-explained``: effects named and a channel keeps excess (the effect is
  part of the answer, never reported alone as *the* missing effect).

``remaining_excess`` is each channel's mean residual power over the floor in the
band (1: noise alone); ``where`` the channels that keep excess, with the frequency
of their largest ratio.

**Uncorrelated excess.**  A channel whose residual is significantly above the floor
(the same level test at ``alpha``) but not structured -- not input-correlated, or
not smooth across frequency -- leaves no excess a linear model could take up, so
it changes no status; but power is left above the floor there, and the verdict
says so (``Verdict.uncorrelated_excess``, :class:`UncorrelatedExcess`) instead of
calling the residual "at the noise floor".  Two causes give it: a response that
is not linear at the record's amplitude (the nonlinear blade truth with lead-lag at
1 deg leaves 1.06 times the noise per in-band bin in ``beta1s`` that no linear
model takes; ``bench/rotor-physics.md``), which smaller inputs or a second
amplitude tell, and sensor noise above the floor the record gives.  One record
does not tell them apart reliably: the coherence is near 1 either way at these
signal-to-noise ratios, and the local polynomial estimate of the in-band noise
(:mod:`inflowsim.diagnose.lpm`) is raised by both; so the text names both.

**Stand-ins** (issue #36).  An effect named whose estimate is impossible for what
it claims to be, or that leaves most of the excess, mimics the missing physics in
the band rather than being it.  Each named effect is a stand-in
(:class:`StandIn`, ``Verdict.stand_ins``) where

- an estimate lies outside its parameter's *physical* range
  (:attr:`~inflowsim.model.params.ParameterSpec.physical`: a ``time-delay`` whose
  delay is a lead) or its *plausible* range (``ParameterSpec.plausible``, for the
  rotor's hub) by more than ``Rule.plausible_sigmas`` of its bound; or
- the effects named together remove less than ``Rule.stand_in_share`` of the
  starting structure's excess over the floor (``excess_explained``; also where
  the verdict finds no significant structured excess left: most of the
  starting excess power is still there); or
- two or more effects are named together and each alone (its own best fit from
  the starting structure) removes so little that their shares alone, summed, are
  under ``Rule.stand_in_share`` of what they remove together: they explain the
  excess only together, by compensating each other, not each its own part
  (``"partner"``; true effects named together remove about their own parts, which
  add up).

The text then reads "behaves like X in this band; the missing physics is
probably elsewhere: see the map".
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..data.record import FLAP_COLUMNS
from .failures import above_floor, excess_channels
from .rule import DEFAULT_RULE, Rule

STATUSES = ("no-missing-effect", "explained", "partly-explained", "unexplained")


@dataclass(frozen=True)
class StandIn:
    """A named effect that behaves like the missing physics without being it.

    ``reasons``: ``((kind, parameter, estimate, sigma, low, high, why), ...)``,
    ``kind`` ``"physical"`` (outside what the effect can be: ``why`` says what),
    ``"plausible"`` (outside what the rotor's physics expects), ``"excess"``
    (the effects named leave most of the excess: ``estimate`` the share they
    remove, ``low`` the share required, the other fields ``None``) or
    ``"partner"`` (it explains excess only together with the others named:
    ``estimate`` the share it removes alone, ``low`` the named effects' shares
    alone summed, ``high`` the share they remove together).
    """

    effect: str
    reasons: tuple

    def because(self) -> str:
        out = []
        for kind, n, e, sig, lo, hi, why in self.reasons:
            if kind == "excess":
                out.append(f"the effects named remove {100 * e:.0f} % of the excess "
                           f"over the floor, under {100 * lo:.0f} %")
            elif kind == "partner":
                out.append(f"alone it removes {100 * e:.0f} % of the excess over the "
                           f"floor, the effects named {100 * hi:.0f} % together but "
                           f"{100 * lo:.0f} % alone, summed: it explains excess only "
                           "together with them")
            else:
                pm = "" if sig is None else f" +- {sig:.2g}"
                rng = f"[{lo:g}, {hi:g}]"
                out.append(f"{n} = {e:.4g}{pm} is outside its {kind} range {rng}: {why}")
        return "; ".join(out)

    def describe(self) -> str:
        return (f"{self.effect} is a stand-in: it behaves like {self.effect} in this "
                f"band ({self.because()}); the missing physics is probably elsewhere: "
                "see the map of missing terms")

    def to_json(self) -> dict:
        return {"effect": self.effect,
                "reasons": [{"kind": k, "parameter": n, "estimate": e, "sigma": sig,
                             "low": lo, "high": hi, "why": why}
                            for k, n, e, sig, lo, hi, why in self.reasons],
                "text": self.describe()}


def stand_ins(effects, fit, excess_explained, sigmas: float | None = None,
              rule: Rule = DEFAULT_RULE, alone=None) -> tuple:
    """The :class:`StandIn` among ``effects`` (named, in the fitted structure of
    ``fit``) given the share of the excess they remove together (``None``: the
    starting structure had none): an estimate ``sigmas`` (default
    ``rule.plausible_sigmas``) of its bounds outside its range, a share under
    ``rule.stand_in_share``, or, ``alone`` given (``{effect: share it removes
    alone}``, two or more effects), shares alone summing to under
    ``rule.stand_in_share`` of the share together."""
    alone = {e: max(float(v), 0.0) for e, v in (alone or {}).items()
             if v is not None and e in effects}
    partner = (len(effects) >= 2 and len(alone) == len(effects)
               and excess_explained is not None and excess_explained > 0
               and sum(alone.values()) < rule.stand_in_share * excess_explained)
    sigmas = rule.plausible_sigmas if sigmas is None else sigmas
    from ..model.effects import CATALOGUE
    from ..model.params import SPECS
    k = fit.constants[0] if fit is not None else None
    out = []
    for e in effects:
        reasons = []
        if fit is not None and e in CATALOGUE:
            for n in CATALOGUE[e].parameters:
                if n not in fit.parameters or n not in SPECS or n in set(fit.fixed or ()):
                    continue
                spec = SPECS[n]
                est = float(fit.parameters[n])
                sig = fit.sigma.get(n)
                margin = sigmas * sig if sig is not None else 0.0
                ranges = (("physical", spec.physical),
                          ("plausible", spec.plausible_range(k.omega, k.hub)))
                for kind, rng in ranges:
                    if rng is None:
                        continue
                    lo, hi, why = rng
                    if est + margin < lo or est - margin > hi:
                        reasons.append((kind, n, est, None if sig is None else float(sig),
                                        float(lo), float(hi), why))
                        break
        if excess_explained is not None and excess_explained < rule.stand_in_share:
            reasons.append(("excess", None, float(excess_explained), None,
                            rule.stand_in_share, None, None))
        if partner:
            reasons.append(("partner", None, alone[e], None, float(sum(alone.values())),
                            float(excess_explained), None))
        if reasons:
            out.append(StandIn(e, tuple(reasons)))
    return tuple(out)


@dataclass(frozen=True)
class UncorrelatedExcess:
    """A channel of one record whose residual is significantly above the noise
    floor but not structured as model error: what no linear model takes up.

    ``over_floor`` the mean in-band residual power over the floor [-];
    ``p_value`` the level test's (``2 sum r ~ chi2(2 nf)``); ``input_p_value`` and
    ``structure_p_value`` those of its dependence on the inputs and its smoothness
    across frequency (:func:`inflowsim.diagnose.failures.channel_structure`; not
    both under the level); ``input_correlated`` whether the first is (then the
    residual is only not smooth); ``record`` the record's index in the order
    given, from 0 (``None`` for a single record); ``in_band_noise`` the record's
    sensor noise in the band over the floor estimated without a model
    (:mod:`inflowsim.diagnose.lpm`; ``None`` where not estimated): data, not
    rendered, for a short record's estimate is raised by a nonlinear or lightly
    damped response too (the blade truth's ``beta1s``: 4.2-4.4 with or without its
    nonlinear part, whose noise is at the floor).
    """

    channel: str
    over_floor: float
    p_value: float
    input_p_value: float
    structure_p_value: float
    input_correlated: bool = False
    record: int | None = None
    in_band_noise: float | None = None

    def describe(self) -> str:
        where = "" if self.record is None else f" in record {self.record + 1}"
        v = self.over_floor
        times = f"{v:.2g}" if v < 100 else f"{v:.0f}"
        head = f"{self.channel} keeps {times} times the floor{where}"
        if self.input_correlated:
            return (f"{head}, correlated with the inputs but not smooth across frequency "
                    "(sensor noise above the floor, or an error no smooth response takes)")
        return (f"{head}, not correlated with the inputs (a response that is not linear "
                "at this amplitude: try smaller inputs or compare two amplitudes; or "
                "sensor noise above the floor)")

    def to_json(self) -> dict:
        return {"channel": self.channel, "record": self.record,
                "over_floor": self.over_floor, "p_value": self.p_value,
                "input_p_value": self.input_p_value,
                "structure_p_value": self.structure_p_value,
                "input_correlated": self.input_correlated,
                "in_band_noise": self.in_band_noise, "text": self.describe()}


def uncorrelated_excess(analyses, alpha=None, rule: Rule = DEFAULT_RULE,
                        noise_of=None, above=None) -> tuple:
    """The :class:`UncorrelatedExcess` of ``analyses`` (per record): channels whose
    in-band residual is above the floor at ``alpha`` (default ``rule.alpha``; the
    level test of :func:`~inflowsim.diagnose.failures.excess_channels`) and not
    structured (:func:`~inflowsim.diagnose.failures.channel_structure`), the
    complement of ``excess_channels`` among the channels above the floor.
    ``noise_of``: analyses of the same records whose in-band noise estimates
    (``in_band_over_floor``) are taken where ``analyses`` lack them (a candidate's
    are made without); ``above``: :func:`~inflowsim.diagnose.failures.above_floor`
    of the same, where already measured."""
    alpha = rule.alpha if alpha is None else alpha
    if above is None:
        above = above_floor(analyses, alpha, rule)
    out = []
    for i, c, p, st in above:
        if st["structured"]:
            continue
        ra = analyses[i]
        noise = tuple(ra.in_band_over_floor)
        if not noise and noise_of is not None:
            noise = tuple(noise_of[i].in_band_over_floor)
        out.append(UncorrelatedExcess(
            FLAP_COLUMNS[c], float(ra.ratio[c].mean()), p, float(st["input_p_value"]),
            float(st["p_value"]), bool(st["input_p_value"] < alpha),
            None if len(analyses) == 1 else i,
            float(noise[c]) if len(noise) > c else None))
    return tuple(out)


@dataclass(frozen=True)
class Verdict:
    """See the module docstring; ``effects`` the effects named (diagnose: the one
    missing effect; ladder: every effect added)."""

    status: str
    remaining_excess: tuple          # ((channel, power over floor), ...)
    initial_excess: tuple            # the same for the starting structure
    where: tuple                     # ((channel, peak_hz, peak ratio), ...)
    effects: tuple = ()
    #: the effects named that are stand-ins (:class:`StandIn`)
    stand_ins: tuple = ()
    #: channels above the floor whose residual is not structured
    #: (:class:`UncorrelatedExcess`): power left that changes no status
    uncorrelated_excess: tuple = ()

    def is_stand_in(self, effect: str) -> bool:
        return any(x.effect == effect for x in self.stand_ins)

    @property
    def excess_explained(self) -> float | None:
        """Share of the starting structure's excess over the floor (summed over the
        channels, ``max(power over floor - 1, 0)``) that the effects named remove;
        ``None`` where there was no excess."""
        before = sum(max(v - 1.0, 0.0) for _, v in self.initial_excess)
        after = sum(max(v - 1.0, 0.0) for _, v in self.remaining_excess)
        return None if before <= 0 else float(1.0 - after / before)

    def to_json(self) -> dict:
        return {"status": self.status, "excess_explained": self.excess_explained,
                "remaining_excess": dict(self.remaining_excess),
                "initial_excess": dict(self.initial_excess),
                "where": [{"channel": c, "peak_hz": f, "peak_over_floor": r}
                          for c, f, r in self.where],
                "effects": list(self.effects),
                "stand_ins": [x.to_json() for x in self.stand_ins],
                "uncorrelated_excess": [x.to_json() for x in self.uncorrelated_excess]}

    def describe(self) -> str:
        """One line, rendered from the fields."""
        left = ", ".join(f"{c} {v:.2g}" for c, v in self.remaining_excess)
        where = "; ".join(f"{c} peaks at {r:.3g} times the floor near {f:.3g} Hz"
                          for c, f, r in self.where)
        named = " + ".join(self.effects)
        # "at the noise floor" only where no channel is above it at all
        floor = ("no input-correlated excess left" if self.uncorrelated_excess else
                 "the residual is at the noise floor")
        text = {
            "no-missing-effect": f"no missing effect: {floor}",
            "explained": f"explained by {named}: {floor}",
            "partly-explained": f"partly explained by {named}: excess left ({where})",
            "unexplained": f"unexplained: excess outside the catalogue ({where})",
        }[self.status]
        for x in self.uncorrelated_excess:
            text += f"; {x.describe()}"
        out = f"verdict: {text}; residual power over the floor: {left}"
        for x in self.stand_ins:
            out += f"; {x.describe()}"
        return out


def power_over_floor(analyses) -> tuple:
    """Per channel the mean in-band residual power over the floor, over records."""
    return tuple((ch, float(np.mean([ra.ratio[c].mean() for ra in analyses])))
                 for c, ch in enumerate(FLAP_COLUMNS))


def excess_share(initial_analyses, analyses) -> float | None:
    """The share of the starting structure's excess over the floor that a fit with
    residual ``analyses`` removes (:attr:`Verdict.excess_explained`); ``None``
    where there was none."""
    before = sum(max(v - 1.0, 0.0) for _, v in power_over_floor(initial_analyses))
    after = sum(max(v - 1.0, 0.0) for _, v in power_over_floor(analyses))
    return None if before <= 0 else float(1.0 - after / before)


def verdict(initial_analyses, final_analyses, effects=(), alpha=None,
            fit=None, rule: Rule = DEFAULT_RULE, alone=None) -> Verdict:
    """The verdict from the starting structure's and the final structure's residual
    analyses (the same when nothing was named), tested at ``alpha`` (default
    ``rule.alpha``); ``fit`` the final structure's fit, whose estimates say which
    named effects are stand-ins (:func:`stand_ins`; ``alone`` the share each
    removes alone, where several are named in one decision)."""
    final = final_analyses if effects else initial_analyses
    above = above_floor(final, alpha, rule)
    where = tuple(w[:3] for w in excess_channels(final, alpha, rule, above))
    if effects:
        status = "partly-explained" if where else "explained"
    else:
        status = "unexplained" if where else "no-missing-effect"
    v = Verdict(status, power_over_floor(final), power_over_floor(initial_analyses),
                where, tuple(effects),
                uncorrelated_excess=uncorrelated_excess(final, alpha, rule,
                                                        noise_of=initial_analyses,
                                                        above=above))
    if not effects:
        return v
    from dataclasses import replace
    return replace(v, stand_ins=stand_ins(effects, fit, v.excess_explained, rule=rule,
                                          alone=alone))


__all__ = ["STATUSES", "UncorrelatedExcess", "Verdict", "excess_share",
           "power_over_floor", "stand_ins", "uncorrelated_excess", "verdict"]
