"""Which of two candidates explaining the same residual to name: the more likely one.

The four tests of :mod:`inflowsim.diagnose.candidates` judge each candidate
against the base alone.  Two candidates may explain the same part of the residual,
and the material test (a share of a noisy excess) can pass the weaker and fail the
stronger: on a white-noise record whose hidden effect is the 2/rev flap, a
1.1 ms ``time-delay`` (likelihood-ratio statistic 20) passed and the 2/rev flap
(statistic 72, the truth within 1 sigma) explained 7.7 % of an excess smaller than
its own scatter (``bench/README.md``).

So before a candidate ``A`` is named, it is tested against every *rival* ``B``:
a candidate that is significant and plausible, has no more parameters than ``A``,
and a larger likelihood-ratio statistic (for the same number of parameters, the
more likely model).  Both are fitted together, and the two nested tests of
:func:`inflowsim.diagnose.candidates.lr_test` decide:

* ``A`` is **explained by** ``B`` when, with ``B`` in the model, ``A`` is no longer
  significant while ``B`` still is with ``A``: everything ``A`` explains, ``B``
  explains, and more.  ``A`` is then not named.
* ``B`` takes ``A``'s place if its refit moved the residual toward white noise
  (the *whiter* test); its share of the excess is then taken as at least ``A``'s,
  since it explains what ``A`` explained.

A rival with more parameters cannot displace (a flexible effect can mimic a
simple one: ``glauert``'s four terms cover the direct in-plane forcing of the
nonlinear blade truth).  The rule acts only where a candidate was accepted, so it
never names an effect on a record where the four tests name none.

**A flexible candidate against a pair of simple ones.**  A candidate ``A`` of
:attr:`Rule.pair_min_dof <inflowsim.diagnose.rule.Rule>` parameters or more can mimic two simple effects at once:
on the nonlinear blade truth with no Eq. (14) coupling (no Glauert term in the
truth), ``glauert``'s seven gains were named for what the direct in-plane forcing
and the separate time constants explain with two parameters (Schwarz gain 251
against 219; beside those two ``glauert`` has p = 0.4).  So ``A`` is also compared
with pairs of significant, plausible candidates that have fewer parameters
together (one at least accepted; the ``max_pairs`` most likely): fitted
together, a pair whose Schwarz gain over the base is larger than ``A``'s is the
better model of the residual by the criterion the candidates are ranked by (it
applies to non-nested models, as the likelihood-ratio test does not), and its
better-ranked accepted member is named in ``A``'s place (``displaced``).  ``A`` is
not lost: the ladder judges it again, beside the pair, on the following rungs.
It is also fitted beside the pair, and where it is not significant there it is
``explained_by`` the pair (``"a+b"``); where it is, its reason says so.  On the
Eq. (14) truth at 256 Hz, ``glauert`` beside the direct forcing and the time
constants has p = 1e-5 but a Schwarz gain of -2.5 there: the record does not pay
for its seven gains once the two simple effects are in (``bench/README.md``).

**A flexible candidate against a simple one and its own part.**  Where ``A`` is
an effect of several parts fitted whole (``Effect.parts``: Glauert's ``F`` and
``G``) and no pair of two candidates beats it, it is also compared with an
accepted candidate ``B`` fitted together with one part of ``A`` alone (fewer
parameters together than ``A``; at most ``max_part_pairs``), counted only
where ``A`` whole explains ``B`` (``B`` is not significant beside it): ``A``'s
other part then stands in for ``B``.  If such a pair has the larger Schwarz gain,
``B`` is named and ``A`` is judged again, beside it, on the next rung (never
``explained_by``: its part is in the pair).  On the Eq. (14) truth at 256 Hz,
seed 5, all seven Glauert gains (194.9) took what the direct in-plane forcing
explains (180.6 alone, not significant beside them), and the time constants were
not significant, so no pair of two beat them; the direct forcing with Glauert's
``F`` alone gains 206.7 with four parameters, and ``G`` adds nothing beside them
(p 0.35).  The ladder then names ``F`` on the next rung (``bench/README.md``).

Once the candidate to name is settled, every other accepted candidate is fitted
together with it the same way: one that the named candidate explains (with it no
longer significant, while the named one still is with it) is no longer accepted and
says so (``explained_by``).  This never changes what is named; it tells the user
which other effects the record cannot show beside it: on the nonlinear blade truth
at 256 Hz ``glauert``'s in-plane gains leave ``advance-ratio-perturbation`` nothing
(``k_mu = -0.93 +- 1.03`` with them), while ``glauert`` stays significant beside it
(``bench/README.md``).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import InputError
from ..model.effects import CATALOGUE
from .candidates import ALPHA, lr_test, nested_start, rank, schwarz_gain
from .rule import DEFAULT_RULE, Rule, rule_with

# The numbers (rounds of displacement, the size of a candidate tested against
# pairs, how many pairs) are the rule's settings: :class:`~.rule.Rule`.


def _joint_fit(records, base_fit, first, others, held, band_hz, fit_fn):
    """``first`` (a fit of ``base`` plus effects) with the ``others`` candidates'
    effects added, fitted from their estimates; ``None`` where they cannot go
    together or the joint fit ends in a worse minimum than any one alone."""
    try:
        s = first.structure
        for c in others:
            if any(x in s.effects for x in CATALOGUE[c.effect].alternatives):
                return None
            # one of its parts is in ``first`` already: the others are freed from there
            if c.effect not in s.effects:
                s = s.with_effect(c.effect)
        start = nested_start(first, s, base_fit.constants[0])
        for c in others:
            if c.effect not in first.structure.effects:
                start.update({n: float(c.fit.parameters[n])
                              for n in CATALOGUE[c.effect].parameters if n in start})
        fixed = {n: float(base_fit.parameters[n]) for n in (base_fit.fixed or ())
                 if n in s.parameters}
        fixed.update({n: start[n] for n in held})
        fit = fit_fn(records, s, band_hz=band_hz, start=start, fixed=fixed or None)
    except InputError:
        return None
    # a joint fit in a worse minimum than either alone says nothing
    if fit.cost > min([first.cost] + [c.fit.cost for c in others]) + \
            1e-9 * max(1.0, abs(fit.cost)):
        return None
    return fit


def _joint(records, base_fit, a, b, band_hz, fit_fn, cache=None):
    """``base + A + B`` fitted from both candidates' estimates, or ``None``; kept in
    ``cache`` (a dict, one resolution's) where given."""
    key = (a.effect, a.held, b.effect, b.held)
    if cache is not None and key in cache:
        return cache[key]
    fit = _joint_fit(records, base_fit, a.fit, [b], a.held + b.held, band_hz, fit_fn)
    if cache is not None:
        cache[key] = fit
    return fit


def _boundary(c):
    return sum(1 for n in CATALOGUE[c.effect].boundary if n not in c.held)


def explained_by(records, base_fit, a, b, band_hz, fit_fn, alpha=ALPHA, cache=None):
    """``(explained, p of A given B, p of B given A)``: does ``b`` explain ``a``?"""
    both = _joint(records, base_fit, a, b, band_hz, fit_fn, cache)
    if both is None:
        return False, None, None
    *_, lp_a = lr_test(b.fit.cost, both.cost, a.dof, _boundary(a))
    *_, lp_b = lr_test(a.fit.cost, both.cost, b.dof, _boundary(b))
    lim = np.log10(alpha)
    return bool(lp_a >= lim and lp_b < lim), 10 ** lp_a, 10 ** lp_b


def _rivals(a, cands, tried):
    return sorted((c for c in cands if c.effect != a.effect and c.significant and c.plausible
                   and c.fit is not None and c.dof <= a.dof and c.statistic > a.statistic
                   and (a.effect, c.effect) not in tried),
                  key=lambda c: -c.statistic)


def _part_of(a, variant, base_fit):
    """``a`` with one part alone (``variant``: ``(held, dof, fit)``), to pair with a
    simple candidate; never named itself."""
    held, dof, fit = variant
    stat = max(0.0, 2.0 * (base_fit.cost - fit.cost))
    return dataclasses.replace(
        a, fit=fit, held=tuple(held), dof=dof, statistic=stat, accepted=False,
        schwarz_gain=schwarz_gain(base_fit.cost, fit.cost, dof, fit.n_freq), variants=())


def part_label(c) -> str:
    """``"glauert (k0p, kc, ks)"`` for a part alone, the effect's name when whole."""
    if not c.held:
        return c.effect
    own = (n for n in CATALOGUE[c.effect].parameters if n not in c.held)
    return f"{c.effect} ({', '.join(own)})"


def _pairs(a, cands, base_fit=None, rule: Rule = DEFAULT_RULE):
    """``(simple, with_part)``: pairs of significant, plausible candidates with
    fewer parameters together than ``a``, most likely first, at most
    ``rule.max_pairs``; and, where ``a`` is an effect of several parts fitted whole,
    pairs of an accepted candidate with one part of ``a`` alone, at most
    ``rule.max_part_pairs``."""
    ok = [c for c in cands if c.effect != a.effect and c.significant and c.plausible
          and c.fit is not None and c.dof < a.dof]
    out = [(b, c) for i, b in enumerate(ok) for c in ok[i + 1:]
           if b.dof + c.dof < a.dof and (b.accepted or c.accepted)
           and c.effect not in CATALOGUE[b.effect].alternatives]
    out = sorted(out, key=_less_likely)[:rule.max_pairs]
    if a.held or not a.variants or base_fit is None:
        return out, []
    parts = [_part_of(a, v, base_fit) for v in a.variants]
    with_part = [(b, c) for b in ok for c in parts
                 if b.accepted and b.dof + c.dof < a.dof
                 and b.effect not in CATALOGUE[a.effect].alternatives]
    return out, sorted(with_part, key=_less_likely)[:rule.max_part_pairs]


def _less_likely(pair):
    """Sort key of a pair: the more likely together first."""
    return -(pair[0].statistic + pair[1].statistic)


def _best_pair(records, base_fit, a, pairs, band_hz, fit_fn, progress, alpha=ALPHA,
               cache=None):
    """The pair of ``pairs`` with the largest Schwarz gain above ``a``'s, as
    ``(b, c, their fit, gain)``, or ``None``.  A pair of ``b`` with a part of ``a``
    counts only where ``a`` whole explains ``b`` (``b`` is not significant beside
    it): the rest of ``a`` then stands in for ``b``, not for physics of its own.
    That is checked first (the fit, kept in ``cache``, is the one :func:`_covered`
    makes if ``a`` is named), so a ``b`` with physics of its own costs no pair fits."""
    best = None
    for b, c in pairs:
        if c.effect == a.effect:
            if progress:
                progress(f"testing {b.effect} beside {a.effect}")
            _, p_b, _ = explained_by(records, base_fit, b, a, band_hz, fit_fn, alpha, cache)
            if p_b is None or p_b < alpha:
                continue
        if progress:
            progress(f"testing {a.effect} against {b.effect}+{part_label(c)}")
        both = _joint_fit(records, base_fit, b.fit, [c], b.held + c.held, band_hz, fit_fn)
        if both is None:
            continue
        gain = schwarz_gain(base_fit.cost, both.cost, b.dof + c.dof, both.n_freq)
        if gain > a.schwarz_gain and (best is None or gain > best[3]):
            best = (b, c, both, gain)
    return best


def simpler_pair(records, base_fit, a, cands, band_hz, fit_fn, progress=None, cache=None,
                 rule: Rule | None = None):
    """``(b, c, p of A beside them or None, their Schwarz gain)``: the pair of
    smaller candidates that, fitted together, has a larger Schwarz gain than ``a``
    (the best such pair), or ``None``.  Pairs of two candidates are tried first;
    pairs of a candidate with a part of ``a`` only where none of those wins."""
    rule = rule or DEFAULT_RULE
    if a.dof < rule.pair_min_dof or a.fit is None:
        return None
    cache = {} if cache is None else cache
    simple, with_part = _pairs(a, cands, base_fit, rule)
    best = (_best_pair(records, base_fit, a, simple, band_hz, fit_fn, progress,
                       rule.alpha) or
            _best_pair(records, base_fit, a, with_part, band_hz, fit_fn, progress,
                       rule.alpha, cache=cache))
    if best is None:
        return None
    b, c, both, gain = best
    if progress:
        progress(f"testing {a.effect} beside {b.effect}+{part_label(c)}")
    part = c.effect == a.effect
    three = _joint_fit(records, base_fit, both, [a], a.held + b.held +
                       (() if part else c.held), band_hz, fit_fn)
    p_a = None
    if three is not None:
        # a part of ``a`` in the pair: what is tested beside it is the rest of ``a``
        dof = a.dof - (c.dof if part else 0)
        p_a = 10 ** lr_test(both.cost, three.cost, dof, _boundary(a))[2]
    return b, c, p_a, gain


def _displace_by_pair(a, found, cands, alpha=ALPHA):
    """Candidates with ``a`` outranked by the pair ``found`` and the better-ranked
    accepted member of the pair as the one to name, ranked again."""
    b, c, p_a, gain = found
    name = next(x for x in cands if (x is b or x is c) and x.accepted)
    other = c if name is b else b
    part = c.effect == a.effect
    pair = f"{b.effect}+{part_label(c)}" if part else f"{b.effect}+{c.effect}"
    better = (f"{pair} ({b.dof + c.dof} parameter(s) against {a.dof}) fit better by "
              f"the Schwarz criterion ({gain:.1f} against {a.schwarz_gain:.1f})")
    if part:
        rest = ", ".join(c.held)
        beside = "" if p_a is None else (
            f"; beside them its {rest} {'are not' if p_a >= alpha else 'are'} "
            f"significant (p = {p_a:.2g})")
        new_a = dataclasses.replace(
            a, accepted=False,
            reason=f"not named whole before {pair}: {better}{beside}; it is judged "
                   "again beside them")
    elif p_a is not None and p_a >= alpha:
        new_a = dataclasses.replace(
            a, accepted=False, explained_by=pair,
            reason=f"explained by {pair}: with them, {a.effect} is not significant "
                   f"(p = {p_a:.2g}), and {better}")
    else:
        beside = "" if p_a is None else f" (beside them p = {p_a:.2g})"
        new_a = dataclasses.replace(
            a, accepted=False,
            reason=f"not named before {pair}: {better}; it is judged again beside "
                   f"them{beside}")
    new_n = dataclasses.replace(
        name, displaced=a.effect,
        reason=(f"accepted: with {part_label(other)} it explains the residual better "
                f"than {a.effect}{' whole' if part else ''} with fewer parameters "
                f"(Schwarz gain {gain:.1f} against {a.schwarz_gain:.1f})"))
    return rank([new_a if x is a else new_n if x is name else x for x in cands])


def resolve_rivals(records, base_fit, cands, band_hz, fit_fn, alpha=None,
                   progress=None, rule: Rule | None = None):
    """Ranked candidates (:func:`~inflowsim.diagnose.candidates.rank_candidates`)
    with the named one tested against its rivals by ``rule`` (its level ``alpha``
    where given); returns them ranked again."""
    rule = rule_with(rule, alpha)
    alpha = rule.alpha
    cands = list(cands)
    tried, tried_pairs = set(), set()
    cache = {}        # joint fits, by (effect, held) of the two candidates
    for _ in range(rule.max_rounds * max(1, len(cands))):
        a = next((c for c in cands if c.accepted), None)
        if a is None:
            break
        for b in _rivals(a, cands, tried):
            tried.add((a.effect, b.effect))
            if progress:
                progress(f"testing {a.effect} against {b.effect}")
            yes, p_a, p_b = explained_by(records, base_fit, a, b, band_hz, fit_fn, alpha)
            if not yes:
                continue
            why = (f"explained by {b.effect}: with it, {a.effect} is not significant "
                   f"(p = {p_a:.2g}), while {b.effect} is with {a.effect} (p = {p_b:.2g})")
            new_a = dataclasses.replace(a, accepted=False, reason=why, explained_by=b.effect)
            new_b = b
            if b.whiter:
                new_b = dataclasses.replace(
                    b, accepted=True, share=max(b.share, a.share), displaced=a.effect,
                    reason=(f"accepted: explains what {a.effect} explained (with "
                            f"{b.effect}, {a.effect} is not significant: p = {p_a:.2g}), "
                            f"more likely (statistic {b.statistic:.1f} against "
                            f"{a.statistic:.1f}, {b.dof} parameter(s) against {a.dof})"))
            cands = rank([new_a if c is a else new_b if c is b else c for c in cands])
            break
        else:
            if a.effect in tried_pairs:
                break
            tried_pairs.add(a.effect)
            found = simpler_pair(records, base_fit, a, cands, band_hz, fit_fn, progress,
                                 cache, rule)
            if found is None:
                break
            cands = _displace_by_pair(a, found, cands, alpha)
    return _covered(records, base_fit, cands, band_hz, fit_fn, alpha, progress, cache)


def _covered(records, base_fit, cands, band_hz, fit_fn, alpha, progress, cache=None):
    """The other accepted candidates marked where the named one explains them."""
    a = next((c for c in cands if c.accepted), None)
    if a is None:
        return cands
    out = []
    for b in cands:
        if b is not a and b.accepted:
            if progress:
                progress(f"testing {b.effect} beside {a.effect}")
            yes, p_b, p_a = explained_by(records, base_fit, b, a, band_hz, fit_fn, alpha,
                                         cache)
            if yes:
                b = dataclasses.replace(
                    b, accepted=False, explained_by=a.effect,
                    reason=(f"explained by {a.effect}: with it, {b.effect} is not "
                            f"significant (p = {p_b:.2g}), while {a.effect} is with "
                            f"{b.effect} (p = {p_a:.2g})"))
        out.append(b)
    return rank(out)
