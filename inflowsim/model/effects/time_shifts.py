"""``delay-<channel>``: a time shift of one recorded channel, output or input.

The paper's "time shifts in the input and output vectors" (section 2.2): each
recorded channel may lag (``delay_<channel> > 0``) or lead (``< 0``) the truth
by its own time [s], for example a control position sampled by another data
system than the blade sensors.  Outputs: ``delay-beta0``, ``delay-beta1c``,
``delay-beta1s`` (alternatives to the shared ``time-delay``); inputs:
``delay-theta0`` ... ``delay-muy``.  The sampled-data relations of every hold are
exact for any shift (:mod:`inflowsim.simulate.sampled`).

Not offered to the diagnosis by default (13 more candidates, each one degree of
freedom, would raise the chance of a false alarm over the catalogue and the
run time); ask for them by name (``--add delay-theta1s``, ``--candidates``).
"""
from ._effect import Effect, ParameterSpec
from ..equations import FLAP, INPUTS


def _output(channel):
    i = FLAP.index(channel)

    def measurement(m, p, k):
        d = list(m.delays)
        d[i] = p[f"delay_{channel}"]
        groups = tuple(g for g in (tuple(r for r in grp if r != i)
                                   for grp in m.delay_groups) if g) + ((i,),)
        return m.with_(delays=tuple(d), delay_groups=tuple(sorted(groups)))
    return measurement


def _input(channel):
    def measurement(m, p, k):
        return m.with_(input_delays=tuple(m.input_delays)
                       + ((channel, p[f"delay_{channel}"]),))
    return measurement


def _effect(channel, output):
    kind = "flap channel" if output else "input"
    return Effect.of_one(
        name=f"delay-{channel}",
        physics=f"The recorded {kind} {channel} is shifted in time against the other "
                "channels (a data-system skew, lag or lead).",
        paper="Section 2.2 (time shifts in the input and output vectors)",
        theory=0.0,
        measurement=_output(channel) if output else _input(channel),
        uses_inplane=channel in ("mux", "muy"),
        alternatives=("time-delay",) if output else (),
        offered=False,
        spec=ParameterSpec(f"delay_{channel}", "s", f"time shift of the recorded "
                           f"{channel} (delay > 0, lead < 0)", -1.0, 1.0,
                           plausible=(-0.1, 0.1, "data-system skews are tens of "
                                                 "milliseconds")),
    )


EFFECTS = tuple(_effect(c, True) for c in FLAP) + tuple(_effect(c, False) for c in INPUTS)


__all__ = ["EFFECTS"]
