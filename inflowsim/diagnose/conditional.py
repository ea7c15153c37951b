"""Estimates conditional on an incomplete structure (issue #36).

Every bound the fit reports (``sigma``, ``sigma_colored``, ``sigma_robust``) is
read from the residual: it bounds the scatter of an estimate about the value the
*fitted structure* converges to, not the bias the structure's missing physics adds
to it (``model.md`` section 7).  So wherever the fit's own residual keeps
structured excess over the sensor-noise floor (the verdict's test,
:func:`inflowsim.diagnose.failures.excess_channels`: level above the floor at
``alpha``, smooth across frequency and input-correlated), every estimate of that fit
is marked **conditional on an incomplete structure**, with the reason in one line.
"""
from __future__ import annotations

import dataclasses

from .failures import excess_channels
from .rule import DEFAULT_RULE, Rule


def conditional_reason(analyses, alpha=None, rule: Rule = DEFAULT_RULE) -> str | None:
    """One line saying why a fit's estimates are conditional, from its residual
    analyses (one per record), or ``None`` where no channel keeps structured
    excess over the floor (tested at ``alpha``, default ``rule.alpha``)."""
    where = excess_channels(analyses, alpha, rule)
    if not where:
        return None
    worst = {}
    for ch, f, peak, mean in where:
        if ch not in worst or mean > worst[ch][2]:
            worst[ch] = (f, peak, mean)
    parts = ", ".join(f"{ch} {mean:.3g} times the floor (peak {peak:.3g} near {f:.3g} Hz)"
                      for ch, (f, peak, mean) in worst.items())
    return (f"conditional on an incomplete structure: the residual keeps structured "
            f"excess over the noise floor ({parts}); the bounds do not include the bias "
            "of what the structure lacks")


def marked(fit, analyses, alpha=None, reason=None, rule: Rule = DEFAULT_RULE):
    """``fit`` with :attr:`~inflowsim.identify.results.FitResult.conditional` set from
    its residual analyses (``reason`` where they show none but the caller knows
    one, e.g. a verdict on the same records)."""
    why = conditional_reason(analyses, alpha, rule) or reason
    if fit.judged and why == fit.conditional:
        return fit
    return dataclasses.replace(fit, conditional=why, judged=True)


__all__ = ["conditional_reason", "marked"]
