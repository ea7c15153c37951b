"""Replay a record through the fixed-step simulator and write the prediction as a
record (what ``inflowsim simulate`` does).

The record's input columns, as perturbations about its trim
(:func:`inflowsim.data.record.find_trim`), drive :class:`~inflowsim.simulate.simulator.Simulator`
from a zero state; with another step than the record's the inputs are held.
"""
from __future__ import annotations

import numpy as np

from ..channels import INFLOW
from .record import FLAP_COLUMNS, MAX_SAMPLES, REQUIRED_META, Record, find_trim, model_inputs
from ..errors import InputError
from ..simulate.simulator import Simulator


#: Metadata a simulated record keeps from its input: the constants of the flight
#: condition, and the trim window (the output is at trim there too).
KEPT_META = REQUIRED_META + ("radius", "hub", "trim_window")


def held_inputs(t_record, u_record, dt: float):
    """Sample times ``t0 + k dt`` up to the record's end and the held inputs there.

    Step ``k`` takes the last record sample at or before its time (a tolerance of
    1e-9 of a step absorbs rounding of ``k dt``).
    """
    t0, t1 = float(t_record[0]), float(t_record[-1])
    n = int(np.floor((t1 - t0) / dt + 1e-9)) + 1
    t = t0 + np.arange(n) * dt
    idx = np.searchsorted(t_record, t + 1e-9 * dt, side="right") - 1
    return t, u_record[np.clip(idx, 0, len(t_record) - 1)]


def simulate_record(rec: Record, model, dt: float | None = None, method: str = "zoh",
                    description: str | None = None) -> Record:
    """Predicted record (totals for flap and inputs) from ``rec``'s inputs.

    Parameters
    ----------
    rec : Record
    model : Model
    dt : float, optional
        Simulator step [s]; default the record's.
    method : {"zoh", "rk4"}
    description : str, optional
        The ``# description:`` of the result.
    """
    rec.require(model.inputs)
    trim = find_trim(rec)
    u = model_inputs(rec, model, trim)
    if dt is None:
        step, t, uh = rec.dt, rec.t, u
    else:
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"--dt {dt}: the step must be a finite number > 0 s")
        step = float(dt)
        span = float(rec.t[-1] - rec.t[0])
        if span / step + 1 > MAX_SAMPLES:
            raise InputError(f"--dt {dt:g} s makes {span / step + 1:.3g} samples of the "
                             f"{span:.4g} s record; at most {MAX_SAMPLES:,} (a step of at "
                             f"least {span / (MAX_SAMPLES - 1):.3g} s)")
        t, uh = held_inputs(rec.t, u, step)
        if len(t) < 4:
            raise InputError(f"--dt {dt:g} s leaves {len(t)} steps in the "
                             f"{rec.t[-1] - rec.t[0]:.4g} s record; need at least 4")
    y = Simulator(model, step, method=method).replay(uh)
    cols = {c: uh[:, j] + trim.values[c] for j, c in enumerate(model.inputs)}
    for i, c in enumerate(FLAP_COLUMNS):
        cols[c] = y[:, i] + trim.values.get(c, 0.0)
    for i, c in enumerate(INFLOW):
        cols[c] = y[:, 3 + i]
    # the flight condition only: what the input record says of its own origin (its
    # aircraft, a virtual test's truth and seed, noise) is not true of a simulation
    meta = {k: v for k, v in rec.meta.items() if k in KEPT_META}
    meta["description"] = description or f"simulated by inflowsim, model {model.structure.name}"
    meta["synthetic"] = "true"
    meta["hold"] = "zoh"          # the fixed-step simulator holds its inputs
    return Record.from_arrays(t, cols, meta)


__all__ = ["KEPT_META", "held_inputs", "simulate_record"]
