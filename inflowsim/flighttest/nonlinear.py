"""Virtual flight test: records (``record-format.md``) from a truth that is not fitted.

Two truths:

- ``"nonlinear"`` (default): the individual-blade rotor of :mod:`inflowsim.flighttest.bladesim`
  (4 blades, blade-element lift, each blade's flap integrated by RK4 in azimuth,
  dynamic inflow driven by blade-element minus local-momentum loads with the
  Eq. (14) speed through the disc), flap measured as a flight-test system does:
  multiblade coordinates from the blades with the *recorded* azimuth
  (:mod:`inflowsim.physics.multiblade`), optional azimuth bias and time delay, noise.
- ``"linear"``: any structure plus effects, delegated to
  :func:`inflowsim.flighttest.virtual.virtual_record` (the truth is then the linear model).

Trim (nonlinear truth): the controls are *given* (``trim_controls``, true blade
pitch; default the virtual Puma's ``theta0 0.17, theta1c 0.01, theta1s -0.05`` rad)
with ``mux = mu``, ``muy = 0``, ``muz = trim_muz`` and no hub rates; the periodic
flap and inflow for them is solved by marching blade passages to a fixed point
(:meth:`BladeRotor.periodic_trim`).  The record then holds totals: trim plus
perturbations.  The pilot input (doublet or 3-2-1-1) is added in the *recorded*
control frame; the true pitch is the recorded one rotated back by the azimuth
bias (``model.md`` section 6).  Hub motion: :class:`inflowsim.flighttest.body.BodyModel`
driven by the true control perturbations (``body=None``: hub fixed).
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from .bladesim import MAX_STEP, BladeRotor, RotorSpec
from ..channels import CONTROLS, INFLOW
from .body import HUB, BodyModel
from ..model.equations import rotation
from ..errors import InputError
from ..physics.multiblade import multiblade
from ..data.record import FLAP_COLUMNS, INPUT_COLUMNS, Record
from .virtual import (KINDS, PUMA_TRIM, Manoeuvre, VirtualTest, ode_max_step,
                      pilot_controls, sensor_noise, virtual_record)

#: Given trim controls of the nonlinear truth (true pitch) [rad].
TRIM_CONTROLS = {c: PUMA_TRIM[c] for c in CONTROLS}
INFLOW_COLUMNS = INFLOW


@dataclass(frozen=True)
class FlightTest:
    """A virtual flight test with the nonlinear individual-blade truth.

    Parameters
    ----------
    rotor : RotorSpec
        The truth rotor (Puma defaults; constants give ``mu``, ``omega``, ``R``).
    trim_controls : dict
        ``theta0, theta1c, theta1s`` true trim pitch [rad].
    trim_muz : float
        Trim hub velocity normal to the disc over ``Omega R`` [-].
    manoeuvres : tuple of Manoeuvre
        Pilot inputs (recorded frame) [rad, s].
    duration, dt : float
        Record length and sample step [s].
    noise_flap, noise_inputs : float
        Standard deviation of Gaussian sensor noise on the flap [rad] and inputs.
    noise_color_hz : float or None
        White flap noise (``None``) or first-order low-pass with this corner [Hz]
        (:func:`inflowsim.flighttest.virtual.sensor_noise`).
    seed : int
        Noise seed.
    azimuth_bias : float
        Offset of the recorded azimuth [rad] (``model.md`` section 6).
    delay : float
        Time delay of the recorded flap [s].
    body : BodyModel or None
        Hub-motion model; ``None`` holds the hub fixed (no body motion).
    max_step : float
        Largest RK4 step in azimuth [rad].
    include_truth : bool
        Add the true inflow perturbation columns ``lambda0, lambda1c, lambda1s``.
    description : str
    servo : (float, float) or None
        Servo actuators between the pilot's command and the blade pitch: time
        constant ``1/omega_n`` [s] and damping [-] of second-order dynamics on each
        control (``model.md``, servo actuators); ``None``: the pitch is the command.
    hold : {"continuous", "zoh"}
        ``continuous`` (default): smooth pilot inputs, the body integrated in
        continuous time (DOP853) and the blades' RK4 fed the inputs at every stage
        time, as in flight; ``zoh``: inputs held over each sample (a digital
        controller's record, ``# hold: zoh``).
    """

    rotor: RotorSpec = field(default_factory=RotorSpec)
    trim_controls: dict = field(default_factory=lambda: dict(TRIM_CONTROLS))
    trim_muz: float = 0.0
    manoeuvres: tuple = (Manoeuvre(),)
    duration: float = 26.6
    dt: float = 0.01
    noise_flap: float = 1e-4
    noise_inputs: float = 0.0
    seed: int = 0
    azimuth_bias: float = 0.0
    delay: float = 0.0
    body: BodyModel | None = field(default_factory=BodyModel)
    max_step: float = MAX_STEP
    include_truth: bool = True
    description: str = "longitudinal cyclic doublet, 100 kt, nonlinear blade-element truth"
    hold: str = "continuous"
    noise_color_hz: float | None = None
    servo: tuple | None = None

    def check(self) -> "FlightTest":
        self.rotor.check()
        for name in ("duration", "dt", "max_step"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name} = {v}: must be a finite number > 0")
        if self.duration < 4 * self.dt:
            raise InputError(f"duration = {self.duration:g} s: need at least 4 samples "
                             f"of {self.dt:g} s")
        for name in ("noise_flap", "noise_inputs", "delay"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise InputError(f"{name} = {v}: must be a finite number >= 0")
        if not (np.isfinite(self.azimuth_bias) and abs(self.azimuth_bias) <= math.pi):
            raise InputError(f"azimuth_bias = {self.azimuth_bias}: must be in [-pi, pi] rad")
        missing = set(CONTROLS) - set(self.trim_controls)
        if missing:
            raise InputError(f"trim_controls: missing {sorted(missing)[0]}")
        for m in self.manoeuvres:
            if m.channel not in TRIM_CONTROLS:
                raise InputError(f"manoeuvre channel {m.channel!r}: choose theta0, "
                                 "theta1c or theta1s")
        if self.hold not in KINDS:
            raise InputError(f"hold {self.hold!r}: choose {', '.join(KINDS)}")
        if self.servo is not None:
            tau, zeta = self.servo
            if not (np.isfinite(tau) and 1e-3 <= tau <= 0.5):
                raise InputError(f"servo time constant {tau:g} s: need 0.001-0.5 s")
            if not (np.isfinite(zeta) and 0.05 <= zeta <= 5.0):
                raise InputError(f"servo damping {zeta:g}: need 0.05-5")
            if self.hold != "continuous":
                raise InputError("servo actuators need hold continuous (a servo's output "
                                 "is not held between samples)")
        return self


@dataclass(frozen=True, eq=False)
class FlightTestResult:
    """The record and a description of its truth (for ``--truth-json``).

    Attributes
    ----------
    record : Record
        The record (totals).
    truth : dict
        Its truth: parameters, trim, settings.
    """

    record: Record
    truth: dict


def trim_inputs(mu: float, trim_controls=None, trim_muz: float = 0.0) -> np.ndarray:
    """The truth's trim inputs (azimuth units, ``INPUTS_AZ``): the given true pitch
    (default :data:`TRIM_CONTROLS`), ``muz``, ``mux = mu``, no hub rates."""
    tc = TRIM_CONTROLS if trim_controls is None else trim_controls
    return np.array([tc["theta0"], tc["theta1c"], tc["theta1s"], trim_muz,
                     0.0, 0.0, 0.0, 0.0, mu, 0.0])


def _trim_inputs(test: FlightTest) -> np.ndarray:
    return trim_inputs(test.rotor.constants.mu, test.trim_controls, test.trim_muz)


def _advance(rotor: BladeRotor, x_trim, u_trim, n_back: int, dpsi: float, max_step):
    """Trim state at ``psi = -n_back dpsi`` (blade 0 there), from the state at 0."""
    if n_back == 0:
        return np.array(x_trim, float)
    per = 2 * np.pi / rotor.nb
    k = int(math.ceil(n_back * dpsi / per))
    span = k * per - n_back * dpsi
    x = np.array(x_trim, float)
    if span > 0:
        n = max(1, int(math.ceil(span / max_step)))
        for m in range(n):
            x = rotor.step(m * span / n, x, tuple(u_trim), span / n)
    for _ in range(k):          # blade 0 now sits where blade -k was
        x = rotor.relabel(x)
    return x


def _hermite(sub, n_sub, nb, dpsi, s):
    """Blade flap at fractional sub-step positions ``s`` (cubic Hermite with rates)."""
    h = dpsi / n_sub
    j = np.clip(np.floor(s).astype(int), 0, len(sub) - 2)
    f = (s - j)[:, None]
    b0, b1 = sub[j, :nb], sub[j + 1, :nb]
    d0, d1 = sub[j, nb:2 * nb] * h, sub[j + 1, nb:2 * nb] * h
    f2, f3 = f * f, f * f * f
    return ((2 * f3 - 3 * f2 + 1) * b0 + (f3 - 2 * f2 + f) * d0
            + (-2 * f3 + 3 * f2) * b1 + (f3 - f2) * d1)


def blade_response(test: FlightTest, controls_true, hub: dict, inputs_at=None,
                   progress=None):
    """Integrate the blades for true control perturbations and hub motion.

    Parameters
    ----------
    test : FlightTest
    controls_true : ndarray (N, 3)
        True pitch perturbations ``theta0, theta1c, theta1s`` [rad].
    hub : dict
        Perturbations ``muz, p, q, pdot, qdot, mux, muy`` (SI, arrays of N).
    inputs_at : callable, optional
        ``inputs_at(t) -> (len(t), 10)``: the inputs (azimuth units, totals) at any
        times [s], for continuously varying inputs; without it the sampled inputs
        are held over each sample.
    progress : callable, optional
        Progress (:func:`inflowsim.progress.bar`) of the integration.

    Returns
    -------
    dict
        ``beta_meas`` (N, 3) as recorded (recorded azimuth, delay, no noise);
        ``beta_true`` (N, 3) true multiblade flap; ``lam`` (N, 3) inflow; ``zeta``
        (N, 3) true multiblade lag (``None`` without the blades' lead-lag);
        ``beta_blades`` (N, Nb); ``trim`` (:class:`RotorTrim`); ``u`` (N, 10)
        true inputs in azimuth units; ``n_sub``.
    """
    test.check()
    rotor = BladeRotor(test.rotor)
    k = test.rotor.constants
    om = k.omega
    nb = rotor.nb
    dpsi = om * test.dt
    u0 = _trim_inputs(test)
    trim = rotor.periodic_trim(u0, max_step=test.max_step)
    n = len(controls_true)
    u = np.tile(u0, (n, 1))
    u[:, 0:3] += controls_true
    u[:, 3] += hub["muz"]
    u[:, 4] += hub["q"] / om
    u[:, 5] += hub["p"] / om
    u[:, 6] += hub["qdot"] / om**2
    u[:, 7] += hub["pdot"] / om**2
    u[:, 8] += hub["mux"]
    u[:, 9] += hub["muy"]
    n_pre = int(math.ceil(test.delay / test.dt - 1e-9)) + (1 if test.delay > 0 else 0)
    u_all = np.vstack([np.tile(u0, (n_pre, 1)), u])
    x0 = _advance(rotor, trim.x, u0, n_pre, dpsi, test.max_step)

    def fine(n_sub):            # the inputs at every half sub-step, from the pre-roll on
        j = np.arange(1 + 2 * (len(u_all) - 1) * n_sub)
        return inputs_at((j / (2 * n_sub) - n_pre) * test.dt)
    x, sub, n_sub = rotor.integrate(x0, -n_pre * dpsi, u_all, dpsi, test.max_step,
                                    None if inputs_at is None else fine, progress)
    x = x[n_pre:]
    t = np.arange(n) * test.dt
    psi = om * t
    beta_true = multiblade(x[:, :nb], psi)
    if test.delay > 0:
        s = (t - test.delay + n_pre * test.dt) / test.dt * n_sub
        blades_m = _hermite(sub, n_sub, nb, dpsi, s)
        psi_m = om * (t - test.delay)
    else:
        blades_m, psi_m = x[:, :nb], psi
    beta_meas = multiblade(blades_m, psi_m + test.azimuth_bias)
    zeta = (multiblade(x[:, 2 * nb + 3:3 * nb + 3], psi) if test.rotor.lag
            else None)
    return {"beta_meas": beta_meas, "beta_true": beta_true,
            "lam": x[:, 2 * nb:2 * nb + 3], "zeta": zeta,
            "beta_blades": x[:, :nb], "trim": trim, "u": u, "n_sub": n_sub}


def _hub(test: FlightTest, controls_true, omega_r, mu) -> dict:
    n = len(controls_true)
    if test.body is None:
        return {c: np.zeros(n) for c in HUB}
    return test.body.response(controls_true, test.dt, omega_r, mu)


def _commanded_controls(test: FlightTest, t):
    """Commanded pitch perturbations at times ``t`` (the recorded-frame pilot input
    rotated back by the azimuth bias)."""
    pilot = pilot_controls(t, test.manoeuvres)
    pilot[:, 1:3] = pilot[:, 1:3] @ rotation(-test.azimuth_bias).T
    return pilot


def true_controls(test: FlightTest):
    """``controls_at(t) -> (len(t), 3)``: the blades' pitch perturbations [rad] at any
    times [s]: the command, or its response through the servo actuators
    (``test.servo``), integrated here in continuous time (DOP853, rtol 1e-12).

    Parameters
    ----------
    test : FlightTest
        The flight test (manoeuvres, azimuth bias, servo actuators).
    """
    if test.servo is None:
        return lambda t: _commanded_controls(test, np.atleast_1d(t))
    tau, zeta = test.servo
    wn = 1.0 / tau
    t0 = -max(test.delay, 0.0) - 2 * test.dt
    t_end = test.duration + test.dt

    def rhs(tt, x):
        c = _commanded_controls(test, np.atleast_1d(tt))[0]
        return np.concatenate([x[3:], wn * wn * (c - x[:3]) - 2.0 * zeta * wn * x[3:]])
    from scipy.integrate import solve_ivp
    with np.errstate(divide="ignore", invalid="ignore"):   # the quiet lead-in: all zero
        sol = solve_ivp(rhs, (t0, t_end), np.zeros(6), method="DOP853", rtol=1e-12,
                        atol=1e-16, dense_output=True,
                        max_step=min(ode_max_step(test), tau / 4))

    def controls_at(t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return sol.sol(np.clip(t, t0, t_end))[:3].T
    return controls_at


def continuous_hub(test: FlightTest, omega_r, mu, controls_at=None):
    """``hub_at(t) -> {channel: array}``: the body driven by the smooth true controls
    (``controls_at``, default :func:`true_controls`), integrated in continuous time
    (DOP853, rtol 1e-12), at any times [s].

    Parameters
    ----------
    test : FlightTest
        The flight test (body model and manoeuvres).
    omega_r : float
        Tip speed ``Omega R`` [m/s].
    mu : float
        Trim advance ratio [-].
    controls_at : callable, optional
        The blades' pitch at any times (:func:`true_controls`).
    """
    if test.body is None:
        return lambda t: {c: np.zeros(np.size(t)) for c in HUB}
    controls_at = controls_at or true_controls(test)
    a, b = test.body.matrices()
    c, d = test.body.hub_matrices(omega_r, mu)
    t_end = test.duration + test.dt
    t0 = -max(test.delay, 0.0) - 2 * test.dt
    from scipy.integrate import solve_ivp
    sol = solve_ivp(lambda tt, x: a @ x + b @ controls_at(tt)[0], (t0, t_end),
                    np.zeros(a.shape[0]), method="DOP853", rtol=1e-12, atol=1e-16,
                    dense_output=True, max_step=ode_max_step(test))

    def hub_at(t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        h = sol.sol(np.clip(t, t0, t_end)).T @ c.T + controls_at(t) @ d.T
        return {name: h[:, i] for i, name in enumerate(HUB)}
    return hub_at


def nonlinear_flighttest(test: FlightTest = FlightTest(), progress=None) -> FlightTestResult:
    """A record (totals) from the nonlinear individual-blade truth; see module doc.

    Parameters
    ----------
    test : FlightTest
        What is flown (manoeuvres, speed, rotor, sensors).
    progress : callable, optional
        Progress of the blades' integration (:func:`inflowsim.progress.bar`).
    """
    t_start = time.perf_counter()
    test.check()
    k = test.rotor.constants
    radius = k.radius or 7.5
    n = int(round(test.duration / test.dt))
    t = np.arange(n) * test.dt
    pilot = pilot_controls(t, test.manoeuvres)            # recorded frame
    controls_at = true_controls(test)
    true = controls_at(t)
    omega_r = k.omega * radius
    if test.hold == "continuous":
        hub_at = continuous_hub(test, omega_r, k.mu, controls_at)
        hub = hub_at(t)
        u_trim = _trim_inputs(test)
        om = k.omega

        def inputs_at(tt):
            h, c = hub_at(tt), controls_at(tt)
            return u_trim + np.column_stack([
                c, h["muz"], h["q"] / om, h["p"] / om, h["qdot"] / om**2,
                h["pdot"] / om**2, h["mux"], h["muy"]])
        res = blade_response(test, true, hub, inputs_at, progress)
    else:
        hub = _hub(test, true, omega_r, k.mu)
        res = blade_response(test, true, hub, progress=progress)
    trim = res["trim"]
    rng = np.random.default_rng(test.seed)
    tc = test.trim_controls
    rec_trim = rotation(test.azimuth_bias) @ np.array([tc["theta1c"], tc["theta1s"]])
    totals = {"theta0": tc["theta0"] + pilot[:, 0],
              "theta1c": rec_trim[0] + pilot[:, 1], "theta1s": rec_trim[1] + pilot[:, 2],
              "muz": test.trim_muz + hub["muz"], "p": hub["p"], "q": hub["q"],
              "pdot": hub["pdot"], "qdot": hub["qdot"], "mux": k.mu + hub["mux"],
              "muy": hub["muy"]}
    cols = {}
    for c in INPUT_COLUMNS:
        v = np.asarray(totals[c], dtype=float)
        if test.noise_inputs:
            v = v + test.noise_inputs * rng.standard_normal(n)
        cols[c] = v
    for i, c in enumerate(FLAP_COLUMNS):
        cols[c] = res["beta_meas"][:, i] + sensor_noise(rng, n, test.noise_flap, test.dt,
                                                        test.noise_color_hz)
    if test.include_truth:
        for i, c in enumerate(INFLOW_COLUMNS):
            cols[c] = res["lam"][:, i] - trim.lam[i]
    meta = {"omega": k.omega, "mu": k.mu, "a0": k.a0, "solidity": k.solidity,
            "radius": radius, "aircraft": "Puma (virtual, nonlinear blade-element truth)",
            "description": test.description, "synthetic": "true", "seed": test.seed,
            "hold": test.hold}
    if k.hub is not None:
        # the rotor's hub: its effects' theory values and plausible ranges (a
        # hingeless rotor's lag frequency, 0.65 per rev, not an articulated one's)
        meta["hub"] = k.hub
    rec = Record.from_arrays(t, cols, meta, source="<flighttest>")
    elapsed = time.perf_counter() - t_start
    truth = {"truth": "nonlinear",
             "rotor": {"n_blades": test.rotor.n_blades,
                       "lambda_beta2": test.rotor.lambda_beta2,
                       "n_beta": test.rotor.n_beta, "gamma": 8 * test.rotor.n_beta,
                       "tau0": test.rotor.tau0, "tau_cs": test.rotor.tau_cs,
                       "speed": test.rotor.speed, "n_span": test.rotor.n_span,
                       "n_disc_psi": test.rotor.n_disc_psi,
                       "n_disc_r": test.rotor.n_disc_r}
             | ({"K_R": test.rotor.K_R} if test.rotor.K_R else {})
             | ({"nu_zeta": test.rotor.nu_zeta, "zeta_lag": test.rotor.zeta_lag}
                if test.rotor.lag else {}),
             "constants": k.as_dict(),
             "trim_controls": dict(tc), "trim_muz": test.trim_muz,
             "trim": trim.as_dict(),
             "measurement": {"azimuth_bias": test.azimuth_bias, "delay": test.delay,
                             "noise_flap": test.noise_flap,
                             "noise_color_hz": test.noise_color_hz,
                             "noise_inputs": test.noise_inputs, "seed": test.seed},
             "body": None if test.body is None else asdict(test.body),
             "manoeuvres": [asdict(m) for m in test.manoeuvres],
             "hold": test.hold,
             "servo": None if test.servo is None else {"servo_tau": test.servo[0],
                                                       "servo_zeta": test.servo[1]},
             "integration": {"method": "rk4", "step_deg": math.degrees(
                 k.omega * test.dt / res["n_sub"]), "substeps_per_sample": res["n_sub"]},
             "generation_seconds": elapsed}
    return FlightTestResult(rec, truth)


def linear_flighttest(test: VirtualTest) -> FlightTestResult:
    """A record from a linear structure plus effects (:func:`virtual_record`).

    Parameters
    ----------
    test : VirtualTest
        The linear truth (structure, parameters, manoeuvres, duration [s], step [s],
        noise [rad]).
    """
    from ..model.build import build_model
    from ..model.presets import preset_parameters
    k = test.constants
    if k.trim is None:       # effects linearised about trim see the record's (virtual_record)
        k = k.with_trim(dict(PUMA_TRIM, mux=k.mu))
    params = test.parameters or preset_parameters(test.structure, k, "paper")
    m = build_model(test.structure, params, k)   # validates
    rec = virtual_record(replace(test, parameters=dict(params)))
    truth = {"truth": "linear", "structure": m.structure.name,
             "effects": list(m.structure.effects), "parameters": dict(m.parameters),
             "constants": k.as_dict(),
             "manoeuvres": [asdict(x) for x in test.manoeuvres],
             "hold": test.hold,
             "measurement": {"noise_flap": test.noise_flap,
                             "noise_color_hz": test.noise_color_hz,
                             "noise_inputs": test.noise_inputs, "seed": test.seed}}
    return FlightTestResult(rec, truth)


def flighttest(test, progress=None) -> FlightTestResult:
    """Run a virtual flight test.

    Parameters
    ----------
    test : FlightTest or VirtualTest
        :class:`FlightTest` (nonlinear truth) or
        :class:`~inflowsim.flighttest.virtual.VirtualTest` (linear truth).
    progress : callable, optional
        Progress of the nonlinear truth's integration (:func:`inflowsim.progress.bar`;
        the linear truth takes well under a second).
    """
    if isinstance(test, VirtualTest):
        return linear_flighttest(test)
    return nonlinear_flighttest(test, progress)


__all__ = ["TRIM_CONTROLS", "INFLOW_COLUMNS", "FlightTest", "FlightTestResult",
           "trim_inputs", "blade_response", "continuous_hub", "nonlinear_flighttest",
           "linear_flighttest", "flighttest"]
