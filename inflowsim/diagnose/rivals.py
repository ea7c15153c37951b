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
from .candidates import ALPHA, lr_test, nested_start, rank

#: Rounds of displacement at most (each names a strictly more likely candidate).
MAX_ROUNDS = 3


def _joint(records, base_fit, a, b, band_hz, fit_fn):
    """``base + A + B`` fitted from both candidates' estimates, or ``None``."""
    try:
        s = a.fit.structure.with_effect(b.effect)
        if any(x in s.effects for x in CATALOGUE[b.effect].alternatives):
            return None
        start = nested_start(a.fit, s, base_fit.constants[0])
        start.update({n: float(b.fit.parameters[n]) for n in CATALOGUE[b.effect].parameters
                      if n in start})
        fixed = {n: float(base_fit.parameters[n]) for n in (base_fit.fixed or ())
                 if n in s.parameters}
        fixed.update({n: start[n] for n in a.held + b.held})
        fit = fit_fn(records, s, band_hz=band_hz, start=start, fixed=fixed or None)
    except InputError:
        return None
    # a joint fit in a worse minimum than either alone says nothing
    if fit.cost > min(a.fit.cost, b.fit.cost) + 1e-9 * max(1.0, abs(fit.cost)):
        return None
    return fit


def _boundary(c):
    return sum(1 for n in CATALOGUE[c.effect].boundary if n not in c.held)


def explained_by(records, base_fit, a, b, band_hz, fit_fn, alpha=ALPHA):
    """``(explained, p of A given B, p of B given A)``: does ``b`` explain ``a``?"""
    both = _joint(records, base_fit, a, b, band_hz, fit_fn)
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


def resolve_rivals(records, base_fit, cands, band_hz, fit_fn, alpha=ALPHA,
                   progress=None):
    """Ranked candidates (:func:`~inflowsim.diagnose.candidates.rank_candidates`)
    with the named one tested against its rivals; returns them ranked again."""
    cands = list(cands)
    tried = set()
    for _ in range(MAX_ROUNDS * max(1, len(cands))):
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
            break
    return _covered(records, base_fit, cands, band_hz, fit_fn, alpha, progress)


def _covered(records, base_fit, cands, band_hz, fit_fn, alpha, progress):
    """The other accepted candidates marked where the named one explains them."""
    a = next((c for c in cands if c.accepted), None)
    if a is None:
        return cands
    out = []
    for b in cands:
        if b is not a and b.accepted:
            if progress:
                progress(f"testing {b.effect} beside {a.effect}")
            yes, p_b, p_a = explained_by(records, base_fit, b, a, band_hz, fit_fn, alpha)
            if yes:
                b = dataclasses.replace(
                    b, accepted=False, explained_by=a.effect,
                    reason=(f"explained by {a.effect}: with it, {b.effect} is not "
                            f"significant (p = {p_b:.2g}), while {a.effect} is with "
                            f"{b.effect} (p = {p_a:.2g})"))
        out.append(b)
    return rank(out)
