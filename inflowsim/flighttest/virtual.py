"""Virtual Puma records from a linear structure: data on a fresh machine.

The truth here is the linear model itself (a chosen structure plus effects and
parameters), driven by a pilot doublet or 3-2-1-1 and hub motion from
:class:`~inflowsim.flighttest.body.BodyModel`, with seeded sensor noise (white, or coloured:
first-order low-pass).  The record holds totals: trim plus perturbations.

Two kinds of record (``VirtualTest.hold``):

``continuous`` (default)
    As measured flight data are: smooth pilot inputs, and body and rotor
    integrated together in continuous time by an adaptive ODE solver (DOP853,
    relative tolerance 1e-12) with the inputs evaluated where the solver asks,
    then *sampled*.  Output time shifts sample the solution at ``t_n - delay``,
    input shifts record the input at ``t_n - delay``.  No code of the sampled-data
    model (:mod:`inflowsim.simulate.sampled`, the simulator) is on this route.
``zoh``
    Inputs held over each sample (the smooth signals sampled, then held) and the
    exact zero-order-hold replay (:func:`inflowsim.simulate.replay.replay`), as a
    digital controller's record; the record says ``# hold: zoh``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..channels import CONTROLS, INFLOW
from .body import HUB, BodyModel
from ..errors import InputError
from ..data.inputs import SHAPES, log_sweep, multisine, multisine_plan, fade_scalar
from ..model.build import build_model
from ..model.params import PUMA, Constants
from ..model.presets import preset_parameters
from ..data.record import FLAP_COLUMNS, INPUT_COLUMNS, Record

#: Trim totals of the virtual Puma at 100 kt [rad, -].
PUMA_TRIM = {"theta0": 0.17, "theta1c": 0.01, "theta1s": -0.05, "muz": 0.0, "p": 0.0,
             "q": 0.0, "pdot": 0.0, "qdot": 0.0, "muy": 0.0,
             "beta0": 0.06, "beta1c": 0.01, "beta1s": -0.002}
CONTROL_INDEX = {"theta0": 0, "theta1c": 1, "theta1s": 2}
#: A pilot's switch: 10-90 % rise time [s] of the smooth steps of a pulse train.
RISE = 0.1
KINDS = ("continuous", "zoh")


@dataclass(frozen=True)
class Manoeuvre:
    """Pilot input: ``shape`` on ``channel`` [rad] starting at ``t_start`` [s].

    ``doublet``, ``3211``: pulses of ``width`` [s] (doublet half-width, 3211 unit),
    each switch a smooth step of 10-90 % rise time ``rise`` [s] (0: sharp).
    ``sweep``: a log sweep over ``f_range`` [Hz] lasting ``length`` [s]
    (:func:`~inflowsim.data.inputs.log_sweep`).  ``multisine``: the ``harmonics``
    (integers) of ``1 / length`` [Hz] with relative amplitudes ``weights`` (empty:
    equal) and Schroeder phases (:func:`~inflowsim.data.inputs.multisine`).  Both
    have peak ``amplitude`` and are faded in and out over ``fade`` [s].
    """

    channel: str = "theta1s"
    shape: str = "doublet"
    amplitude: float = np.radians(1.0)
    t_start: float = 2.0
    width: float = 0.4          # doublet half-width or 3211 unit [s]
    rise: float = RISE
    f_range: tuple = (0.15, 3.0)
    length: float = 20.0
    harmonics: tuple = ()
    weights: tuple = ()
    fade: float = 1.0

    def signal(self, t) -> np.ndarray:
        """The perturbation [rad] at times ``t`` [s]."""
        if np.ndim(t) == 0 and self.shape in ("sweep", "multisine"):
            # the ODE solver asks one time at a time, tens of thousands of times
            return scalar_signal(self, float(t))
        if self.shape == "sweep":
            return log_sweep(t, self.t_start, self.length, *self.f_range,
                             self.amplitude, self.fade)
        if self.shape == "multisine":
            return multisine(t, self.t_start, self.length, 1.0 / self.length,
                             self.harmonics, self.amplitude, self.weights or None,
                             fade_s=self.fade)
        return SHAPES[self.shape](t, self.t_start, self.width, self.amplitude, self.rise)

    @property
    def max_step(self) -> float:
        """Largest ODE step [s] that follows the input: a quarter of a switch's rise,
        or a twentieth of the shortest period of a sweep or multisine."""
        if self.shape == "sweep":
            return 0.05 / max(self.f_range)
        if self.shape == "multisine":
            return 0.05 * self.length / max(self.harmonics)
        return self.rise / 4 if self.rise > 0 else np.inf


@dataclass(frozen=True)
class VirtualTest:
    """Everything that defines a virtual record; see :func:`virtual_record`.

    ``noise_color_hz``: ``None`` for white sensor noise, else the corner [Hz] of a
    first-order low-pass that colours it (AR(1) at the sample rate; same total
    variance ``noise_flap**2``).
    """

    structure: str = "glauert"
    parameters: dict | None = None
    constants: Constants = PUMA
    manoeuvres: tuple = (Manoeuvre(),)
    duration: float = 26.6
    dt: float = 0.01
    noise_flap: float = 1e-4
    noise_inputs: float = 0.0
    seed: int = 0
    body: BodyModel = field(default_factory=BodyModel)
    description: str = "longitudinal cyclic doublet, 100 kt"
    hold: str = "continuous"
    noise_color_hz: float | None = None


def pilot_controls(t, manoeuvres) -> np.ndarray:
    """Control perturbations ``(len(t), 3)`` (theta0, theta1c, theta1s) [rad]."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if t.size == 1:
        u = np.zeros((1, 3))
        for m in manoeuvres:
            u[0, CONTROL_INDEX[m.channel]] += m.signal(t[0])
        return u
    u = np.zeros((t.size, 3))
    for m in manoeuvres:
        u[:, CONTROL_INDEX[m.channel]] += m.signal(t)
    return u


def scalar_signal(m: Manoeuvre, t: float) -> float:
    """:meth:`Manoeuvre.signal` of a sweep or multisine at one time ``t`` [s]."""
    env = fade_scalar(t - m.t_start, m.length, m.fade)
    if env == 0.0:
        return 0.0
    tau = t - m.t_start
    if m.shape == "sweep":
        f1, f2 = m.f_range
        r = math.log(f2 / f1)
        return m.amplitude * env * math.sin(2 * math.pi * f1 * m.length / r
                                            * math.expm1(tau * r / m.length))
    w, ph, peak = multisine_plan(1.0 / m.length, tuple(m.harmonics), tuple(m.weights), ())
    arg = (2 * math.pi / m.length * tau) * np.asarray(m.harmonics, float) + ph
    return m.amplitude / peak * env * float(np.dot(w, np.cos(arg)))


def ode_max_step(test) -> float:
    """Largest ODE step [s] that follows every manoeuvre of ``test``."""
    return min([m.max_step for m in test.manoeuvres] + [np.inf]) if any(
        np.isfinite(m.max_step) for m in test.manoeuvres) else test.dt / 4


def sensor_noise(rng, n: int, sigma: float, dt: float, color_hz=None) -> np.ndarray:
    """Gaussian noise of standard deviation ``sigma``: white, or first-order
    low-pass (AR(1), ``rho = exp(-2 pi f_c dt)``) with corner ``color_hz``."""
    w = rng.standard_normal(n)
    if color_hz is None or sigma == 0:
        return sigma * w
    rho = float(np.exp(-2 * np.pi * color_hz * dt))
    # scipy.signal.lfilter([s], [1, -rho], w[1:], zi=[rho w[0]]) gives the same
    # doubles (tests/test_library_equivalence.py), but importing scipy.signal, which
    # nothing else on this path loads, costs 1.7-2.3 s (measured under the shared
    # machine's load, 16 on 2 cores) against about 2 ms for this loop over a 26.6 s
    # record: the loop stays (issue #39)
    e = np.empty(n)
    e[0] = w[0]
    s = np.sqrt(1 - rho * rho)
    for k in range(1, n):
        e[k] = rho * e[k - 1] + s * w[k]
    return sigma * e


def noise_psd(sigma: float, dt: float, f_hz, color_hz=None) -> np.ndarray:
    """Expected ``|DFT|^2 / N`` of :func:`sensor_noise` at ``f_hz`` [rad^2]: the noise
    floor against which residual power is judged."""
    f = np.asarray(f_hz, dtype=float)
    if color_hz is None:
        return np.full(f.shape, sigma ** 2)
    rho = np.exp(-2 * np.pi * color_hz * dt)
    return sigma ** 2 * (1 - rho ** 2) / np.abs(1 - rho * np.exp(-2j * np.pi * f * dt)) ** 2


def _truth(test: VirtualTest):
    k = test.constants
    trim = dict(PUMA_TRIM, mux=k.mu)
    if k.trim is None:                 # effects linearised about trim see the record's trim
        k = k.with_trim(trim)
    params = test.parameters or preset_parameters(test.structure, k, "paper")
    return k, trim, build_model(test.structure, params, k)


def _continuous(test: VirtualTest, model, omega_r: float, t: np.ndarray):
    """Rotor outputs ``(N, 6)`` at ``t_n - delay`` and recorded inputs ``(N, 10)`` at
    ``t_n - input delay``, integrating body and rotor together (DOP853)."""
    k = test.constants
    ab, bb = test.body.matrices()
    ch, dh = test.body.hub_matrices(omega_r, k.mu)
    nb, n = ab.shape[0], model.a.shape[0]
    # rotor inputs (SI, the channel order: controls, then the hub) from the body
    # state and the controls
    assert CONTROLS + HUB == INPUT_COLUMNS
    cu = np.vstack([np.zeros((3, nb)), ch])
    du = np.vstack([np.eye(3), dh])
    cols = [INPUT_COLUMNS.index(c) for c in model.inputs]
    bm = model.b
    A = np.block([[ab, np.zeros((nb, n))], [bm @ cu[cols], model.a]])
    B = np.vstack([bb, bm @ du[cols]])

    def rhs(tt, z):
        return A @ z + B @ pilot_controls(tt, test.manoeuvres)[0]

    shifts = np.concatenate([model.delays[:3], model.input_delays])
    t0 = min(0.0, float(t[0] - max(shifts.max(), 0.0))) - 1.0
    t1 = float(t[-1] - min(shifts.min(), 0.0)) + test.dt
    from scipy.integrate import solve_ivp
    sol = solve_ivp(rhs, (t0, t1), np.zeros(nb + n), method="DOP853", rtol=1e-12,
                    atol=1e-16, dense_output=True, max_step=ode_max_step(test))
    if not sol.success:
        raise InputError(f"virtual record: the ODE solver failed ({sol.message})")
    y = np.empty((t.size, 6))
    for i in range(6):
        z = sol.sol(t - model.delays[i])
        y[:, i] = model.c[i] @ z[nb:]
    u = np.empty((t.size, len(INPUT_COLUMNS)))
    in_delay = dict(zip(model.inputs, model.input_delays))
    for j, c in enumerate(INPUT_COLUMNS):
        tj = t - in_delay.get(c, 0.0)
        u[:, j] = sol.sol(tj)[:nb].T @ cu[j] + pilot_controls(tj, test.manoeuvres) @ du[j]
    return y, u


def control_response(test: VirtualTest, f_hz) -> np.ndarray:
    """The truth's frequency response from the recorded pilot controls (theta0,
    theta1c, theta1s) to the recorded flap, body path included, shape ``(3, 3, nf)``
    [rad/rad]: rotor and body integrated together as :func:`virtual_record` does
    (``hold = "continuous"``), ``H(s) = C (sI - A)^-1 B`` at ``s = j 2 pi f``, with
    the output and input time shifts.  What a non-parametric estimate from such a
    record should find."""
    k, trim, model = _truth(test)
    omega_r = k.omega * (k.radius or 7.5)
    ab, bb = test.body.matrices()
    ch, dh = test.body.hub_matrices(omega_r, k.mu)
    nb, n = ab.shape[0], model.a.shape[0]
    cu = np.vstack([np.zeros((3, nb)), ch])
    du = np.vstack([np.eye(3), dh])
    cols = [INPUT_COLUMNS.index(c) for c in model.inputs]
    A = np.block([[ab, np.zeros((nb, n))], [model.b @ cu[cols], model.a]])
    B = np.vstack([bb, model.b @ du[cols]])
    C = np.hstack([np.zeros((3, nb)), model.c[:3]])
    w = 2 * np.pi * np.atleast_1d(np.asarray(f_hz, dtype=float))
    eye = np.eye(A.shape[0])
    h = np.stack([C @ np.linalg.solve(1j * wi * eye - A, B) for wi in w], axis=-1)
    h = h * np.exp(-1j * np.outer(model.delays[:3], w))[:, None, :]
    in_delay = dict(zip(model.inputs, model.input_delays))
    d_in = np.array([in_delay.get(c, 0.0) for c in CONTROLS])
    return h * np.exp(1j * np.outer(d_in, w))[None, :, :]


def virtual_record(test: VirtualTest = VirtualTest(), include_truth: bool = True) -> Record:
    """A record (totals, ``record-format.md``) from a linear truth.

    Columns: the ten inputs, the measured flap (with noise), and where
    ``include_truth`` the true inflow ``lambda0, lambda1c, lambda1s`` (fitting never
    reads them).  Metadata ``# hold:`` says which kind of record it is.
    """
    if test.hold not in KINDS:
        raise InputError(f"virtual record: hold {test.hold!r}: choose {', '.join(KINDS)}")
    k, trim, model = _truth(test)
    n = int(round(test.duration / test.dt))
    t = np.arange(n) * test.dt
    omega_r = k.omega * (k.radius or 7.5)
    if test.hold == "continuous":
        y, pert_u = _continuous(test, model, omega_r, t)
        pert = {c: pert_u[:, j] for j, c in enumerate(INPUT_COLUMNS)}
    else:
        from ..simulate.replay import replay
        controls = pilot_controls(t, test.manoeuvres)
        hub = test.body.response(controls, test.dt, omega_r, k.mu)
        pert = {"theta0": controls[:, 0], "theta1c": controls[:, 1],
                "theta1s": controls[:, 2], **hub}
        u = np.column_stack([pert[c] for c in model.inputs])
        y = replay(model, u, test.dt, "zoh")
    rng = np.random.default_rng(test.seed)
    cols = {}
    for c in INPUT_COLUMNS:
        v = trim[c] + pert[c]
        if test.noise_inputs:
            v = v + test.noise_inputs * rng.standard_normal(n)
        cols[c] = v
    for i, c in enumerate(FLAP_COLUMNS):
        cols[c] = trim[c] + y[:, i] + sensor_noise(rng, n, test.noise_flap, test.dt,
                                                   test.noise_color_hz)
    if include_truth:
        for i, c in enumerate(INFLOW):
            cols[c] = y[:, 3 + i]
    meta = {"omega": k.omega, "mu": k.mu, "a0": k.a0, "solidity": k.solidity,
            "radius": k.radius or 7.5, "aircraft": "Puma (virtual)",
            "description": test.description, "synthetic": "true", "seed": test.seed,
            "hold": test.hold}
    if k.hub is not None:
        meta["hub"] = k.hub
    if test.noise_color_hz is not None:
        meta["noise"] = f"first-order low-pass, corner {test.noise_color_hz:g} Hz"
    return Record.from_arrays(t, cols, meta, source="<virtual>")


__all__ = ["PUMA_TRIM", "CONTROL_INDEX", "RISE", "KINDS", "Manoeuvre", "VirtualTest",
           "pilot_controls", "scalar_signal", "ode_max_step", "sensor_noise", "noise_psd",
           "control_response", "virtual_record"]
