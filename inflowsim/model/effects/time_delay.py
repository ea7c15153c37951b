"""``time-delay``: one time shift shared by the recorded flap channels (section 2.2).

The paper's software estimated "time shifts in the input and output vectors"; a
data system's skew can be a lag or a lead, so ``delay`` [s] takes either sign:
the recorded flap is the model's at ``t - delay``.  Per-channel shifts of any
output or input are the ``delay-<channel>`` effects (:mod:`.time_shifts`).
"""
from ._effect import Effect, ParameterSpec


def _measurement(m, p, k):
    return m.with_(delays=(p["delay"],) * 3)


EFFECT = Effect(
    name="time-delay",
    physics="The measurement chain shifts the recorded flap in time (a lag, or a "
            "lead): a phase error growing linearly with frequency on every flap "
            "channel.",
    paper="Section 2.2",
    parameters=("delay",),
    theory=lambda k: {"delay": 0.0},
    measurement=_measurement,
    specs=(ParameterSpec("delay", "s", "time shift of the recorded flap channels (delay > "
                         "0, lead < 0)", -1.0, 1.0, plausible=(-0.1, 0.1, "measurement-"
                         "chain time shifts are tens of milliseconds")),),
    alternatives=("delay-beta0", "delay-beta1c", "delay-beta1s"),
)


__all__ = ["EFFECT"]
