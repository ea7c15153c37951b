"""``time-delay``: one time shift shared by the recorded flap channels (section 2.2).

The paper's software estimated "time shifts in the input and output vectors";
``delay`` [s] is fitted with either sign, the recorded flap the model's at
``t - delay``.  A measurement chain only delays: named with a lead (its
``physical`` range ``[0, 1]`` s), the effect mimics some other physics in the band
and the verdict calls it a stand-in (:mod:`inflowsim.diagnose.verdict`).  Per-channel shifts of any
output or input are the ``delay-<channel>`` effects (:mod:`.time_shifts`).
"""
from ._effect import Effect, ParameterSpec


def _measurement(m, p, k):
    return m.with_(delays=(p["delay"],) * 3)


EFFECT = Effect.of_one(
    name="time-delay",
    physics="The measurement chain shifts the recorded flap in time (a lag, or a "
            "lead): a phase error growing linearly with frequency on every flap "
            "channel.",
    paper="Section 2.2",
    theory=0.0,
    measurement=_measurement,
    spec=ParameterSpec("delay", "s", "time shift of the recorded flap channels (delay > "
                       "0, lead < 0)", -1.0, 1.0, plausible=(-0.1, 0.1, "measurement-"
                       "chain time shifts are tens of milliseconds"),
                       physical=(0.0, 1.0, "a measurement chain delays the recorded "
                                 "flap; it cannot lead the pitch that drives it")),
    alternatives=("delay-beta0", "delay-beta1c", "delay-beta1s"),
)


__all__ = ["EFFECT"]
