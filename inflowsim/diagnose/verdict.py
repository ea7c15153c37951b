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
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..data.record import FLAP_COLUMNS
from .failures import ALPHA, excess_channels

STATUSES = ("no-missing-effect", "explained", "partly-explained", "unexplained")


@dataclass(frozen=True)
class Verdict:
    """See the module docstring; ``effects`` the effects named (diagnose: the one
    missing effect; ladder: every effect added)."""

    status: str
    remaining_excess: tuple          # ((channel, power over floor), ...)
    initial_excess: tuple            # the same for the starting structure
    where: tuple                     # ((channel, peak_hz, peak ratio), ...)
    effects: tuple = ()

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
                "effects": list(self.effects)}

    def describe(self) -> str:
        """One line, rendered from the fields."""
        left = ", ".join(f"{c} {v:.2g}" for c, v in self.remaining_excess)
        where = "; ".join(f"{c} peaks at {r:.3g} times the floor near {f:.3g} Hz"
                          for c, f, r in self.where)
        named = " + ".join(self.effects)
        text = {
            "no-missing-effect": "no missing effect: the residual is at the noise floor",
            "explained": f"explained by {named}: the residual is at the noise floor",
            "partly-explained": f"partly explained by {named}: excess left ({where})",
            "unexplained": f"unexplained: excess outside the catalogue ({where})",
        }[self.status]
        return f"verdict: {text}; residual power over the floor: {left}"


def power_over_floor(analyses) -> tuple:
    """Per channel the mean in-band residual power over the floor, over records."""
    return tuple((ch, float(np.mean([ra.ratio[c].mean() for ra in analyses])))
                 for c, ch in enumerate(FLAP_COLUMNS))


def verdict(initial_analyses, final_analyses, effects=(), alpha=ALPHA) -> Verdict:
    """The verdict from the starting structure's and the final structure's residual
    analyses (the same when nothing was named)."""
    final = final_analyses if effects else initial_analyses
    where = tuple(w[:3] for w in excess_channels(final, alpha))
    if effects:
        status = "partly-explained" if where else "explained"
    else:
        status = "unexplained" if where else "no-missing-effect"
    return Verdict(status, power_over_floor(final), power_over_floor(initial_analyses),
                   where, tuple(effects))


__all__ = ["STATUSES", "Verdict", "power_over_floor", "verdict"]
