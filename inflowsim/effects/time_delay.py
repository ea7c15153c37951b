"""``time-delay``: one pure delay shared by the recorded flap channels (section 2.2)."""
from ._effect import Effect


def _measurement(m, p, k):
    return m.with_(delays=(p["delay"],) * 3)


EFFECT = Effect(
    name="time-delay",
    physics="The measurement chain delays the recorded flap by a fixed time: a phase "
            "lag growing linearly with frequency on every flap channel.",
    paper="Section 2.2",
    parameters=("delay",),
    theory=lambda k: {"delay": 0.0},
    measurement=_measurement,
)
