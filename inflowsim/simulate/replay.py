"""Replay a record's inputs through a model with the record's intersample behaviour.

The time-domain counterpart of :mod:`inflowsim.identify.freqmodel`: outputs at
every sample ``t_n`` for input samples ``u_n``, exact for held (``zoh``) and
linear (``foh``) inputs, and for ``continuous`` records exact for the local-cubic
interpolation of the samples (error ``O(dt^4)`` for smooth inputs;
:mod:`inflowsim.simulate.sampled`).  Time shifts of either sign on outputs and inputs
(``Model.delays``, ``Model.input_delays``) are exact too: each group of outputs
with one delay is the state sampled at shifted times, driven by the recorded
inputs through its own taps.  Samples before the record continue the first one
(the record starts in trim), after it the last one.

Unlike :class:`inflowsim.simulate.simulator.Simulator` (a step-by-step loop, causal, inputs
held), a replay sees the whole record, so leads are possible.
"""
from __future__ import annotations

import numpy as np

from .discrete import lifted_replay
from ..errors import InputError
from .sampled import check_hold, shift_taps, tapped_inputs


def output_groups(model):
    """``[(rows, tau), ...]``: outputs (rows of ``model.c``) sharing one delay [s]."""
    d = np.asarray(model.delays, dtype=float)
    return [(np.flatnonzero(d == v), float(v)) for v in np.unique(d)]


def replay(model, u, dt: float, hold: str = "zoh", x0=None, states: bool = False):
    """Outputs ``(N, 6)`` at every sample for input samples ``u`` ``(N, m)``.

    Parameters
    ----------
    model : Model
    u : array_like (N, m)
        Input perturbations in ``model.inputs`` order [SI].
    dt : float
        Sample step [s].
    hold : {"zoh", "foh", "continuous"}
    x0 : array_like, optional
        State at the first sample of every output group's shifted time (default
        zero: at rest in trim).
    states : bool
        Also return the undelayed states ``(N, n)``.
    """
    hold = check_hold(hold)
    u = np.asarray(u, dtype=float)
    n, m = model.b.shape
    if u.ndim != 2 or u.shape[1] != m:
        raise InputError(f"replay needs inputs of shape (N, {m}) "
                         f"({', '.join(model.inputs)})")
    if not np.all(np.isfinite(u)):
        raise InputError("replay: inputs contain NaN or infinite values")
    if not (np.isfinite(dt) and dt > 0):
        raise InputError(f"dt = {dt}: the step must be a finite number > 0 s")
    x0 = np.zeros(n) if x0 is None else np.asarray(x0, dtype=float)
    sigma = np.asarray(model.input_delays, dtype=float)
    y = np.empty((len(u), model.c.shape[0]))
    cache = {}

    def run(tau):
        if tau not in cache:
            phi, taps = shift_taps(model.a, model.b, dt, hold, tau - sigma)
            v, G = tapped_inputs(u, taps)
            cache[tau] = lifted_replay(phi, G, v, x0)
        return cache[tau]

    for rows, tau in output_groups(model):
        y[:, rows] = np.einsum("kn,on->ko", run(tau), model.c[rows])
    if states:
        return y, run(0.0)
    return y


__all__ = ["output_groups", "replay"]
