"""Fixed-step simulator: exactness, convergence order, agreement with peers."""
import control
import numpy as np
import pytest
from scipy import signal
from scipy.integrate import solve_ivp

from inflowsim import PUMA, build_model, preset_parameters
from inflowsim.errors import InputError
from inflowsim.data.inputs import doublet
from inflowsim.simulate.simulator import Simulator


def model(preset="glauert", **changes):
    p = preset_parameters(preset, PUMA, "paper") | changes
    return build_model(preset.split("+")[0] if False else preset, p, PUMA)


def doublet_inputs(m, t, amp=np.radians(1.0)):
    u = np.zeros((len(t), m.b.shape[1]))
    u[:, 2] = doublet(t, 0.1, 0.2, amp)                 # theta1s
    u[:, 4] = 0.3 * doublet(t, 0.15, 0.25, 0.05)        # q
    if u.shape[1] > 8:
        u[:, 8] = doublet(t, 0.05, 0.3, 1e-3)           # mux
    return u


@pytest.mark.parametrize("preset", ["basic", "empirical", "glauert"])
def test_zoh_equals_adaptive_ode_on_doublet(preset):
    """Exact ZOH against solve_ivp (DOP853, rtol 1e-12) with the same held input."""
    m = model(preset)
    dt = 0.005
    t = np.arange(0, 1.0, dt)
    u = doublet_inputs(m, t)
    y = Simulator(m, dt).replay(u)

    def f(tt, x):
        k = min(int(np.floor(tt / dt + 1e-9)), len(t) - 1)
        return m.a @ x + m.b @ u[k]

    x = np.zeros(m.a.shape[0])
    xs = [x]
    for k in range(len(t) - 1):        # integrate sample to sample: input constant inside
        sol = solve_ivp(lambda tt, xx: m.a @ xx + m.b @ u[k], (t[k], t[k + 1]), xs[-1],
                        method="DOP853", rtol=1e-12, atol=1e-15)
        xs.append(sol.y[:, -1])
    y_ref = np.array(xs) @ m.c.T
    scale = np.max(np.abs(y_ref))
    assert scale > 1e-3
    np.testing.assert_allclose(y, y_ref, atol=1e-9 * scale)


def test_rk4_converges_at_fourth_order():
    m = model("glauert")
    T = 1.0
    errs = []
    dts = [0.02, 0.01, 0.005, 0.0025]
    for dt in dts:
        t = np.arange(0, T, dt)
        u = np.zeros((len(t), m.b.shape[1]))
        u[:, 2] = np.radians(1.0)       # a step: held input, same for every dt
        y_rk = Simulator(m, dt, method="rk4").replay(u)
        y_ex = Simulator(m, dt).replay(u)
        errs.append(np.max(np.abs(y_rk[-1] - y_ex[-1])))
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(orders > 3.8) and np.all(orders < 4.3), orders


@pytest.mark.parametrize("preset", ["basic", "empirical", "glauert"])
def test_replay_equals_dlsim_and_forced_response(preset):
    m = model(preset)
    dt = 0.001
    t = np.arange(0, 2.0, dt)
    rng = np.random.default_rng(1)
    u = doublet_inputs(m, t) + 1e-3 * rng.standard_normal((len(t), m.b.shape[1]))
    x0 = 1e-3 * rng.standard_normal(6)
    sim = Simulator(m, dt)
    y = sim.replay(u, x0)
    d = np.zeros((6, u.shape[1]))
    _, y_dl, _ = signal.dlsim((sim.phi, sim.gam, m.c, d, dt), u, x0=x0)
    sys = control.ss(sim.phi, sim.gam, m.c, d, dt)
    y_fr = control.forced_response(sys, T=t, U=u.T, X0=x0).outputs.T
    np.testing.assert_allclose(y, y_dl, atol=1e-12, rtol=0)
    np.testing.assert_allclose(y, y_fr, atol=1e-12, rtol=0)


def test_step_equals_replay_and_time_from_counter():
    m = model("glauert")
    dt = 0.01
    t = np.arange(0, 3.0, dt)
    u = doublet_inputs(m, t)
    sim = Simulator(m, dt, t0=5.0)
    y = sim.replay(u)
    ys = np.array([sim.step(uk) for uk in u[:-1]])
    np.testing.assert_allclose(ys, y[1:], atol=1e-15)
    assert sim.step_count == len(t) - 1
    assert sim.time == 5.0 + (len(t) - 1) * dt        # t0 + k h, not a running sum


def test_state_get_set_and_reset():
    m = model("empirical")
    sim = Simulator(m, 0.01)
    u = np.zeros(m.b.shape[1]); u[2] = 0.01
    for _ in range(20):
        sim.step(u)
    saved = sim.state
    a = [sim.step(u) for _ in range(10)]
    sim.state = saved
    b = [sim.step(u) for _ in range(10)]
    np.testing.assert_array_equal(a, b)
    sim.reset()
    assert sim.step_count == 0 and np.all(sim.state == 0)
    with pytest.raises(InputError, match="state must be 6 finite"):
        sim.state = [np.nan] * 6
    with pytest.raises(InputError, match="dt"):
        Simulator(m, 0.0)


def test_mu_change_between_steps_follows_discrete_matrices():
    m = model("glauert")
    dt = 0.01
    sim = Simulator(m, dt)
    u = np.zeros(m.b.shape[1]); u[2] = 0.01
    for _ in range(10):
        sim.step(u)
    x = sim.state
    sim.set_mu(0.3)
    y = sim.step(u)
    m2 = m.with_mu(0.3)
    ref = Simulator(m2, dt)
    ref.state = x
    np.testing.assert_allclose(y, ref.step(u), atol=1e-15)
    assert not np.allclose(m2.a, m.a)
    with pytest.raises(InputError, match="mu"):
        sim.set_mu(0.0)


@pytest.mark.parametrize("delay", [0.03, 0.034, 0.0375])
def test_delay_exact_for_held_inputs(delay):
    """A delayed channel equals the undelayed one read at t - delay on a finer grid
    where the delay is a whole number of fine steps and the input is the same."""
    base = model("glauert+time-delay", delay=0.0)
    dm = base.with_parameters(delay=delay)
    dt, fine = 0.01, 0.0005
    t = np.arange(0, 1.0, dt)
    u = doublet_inputs(base, t)
    y = Simulator(dm, dt).replay(u)
    rep = int(round(dt / fine))
    yf = Simulator(base, fine).replay(np.repeat(u, rep, axis=0))
    shift = int(round(delay / fine))
    idx = np.arange(len(t)) * rep - shift
    ref = np.where(idx[:, None] >= 0, yf[np.clip(idx, 0, None)], 0.0)
    np.testing.assert_allclose(y[:, :3], ref[:, :3], atol=1e-12)
    np.testing.assert_allclose(y[:, 3:], yf[::rep][:, 3:], atol=1e-12)   # inflow undelayed
    # the stepping path gives the same delayed outputs
    sim = Simulator(dm, dt)
    ys = np.array([sim.step(uk) for uk in u[:-1]])
    np.testing.assert_allclose(ys, y[1:], atol=1e-14)


def test_replay_refuses_bad_inputs():
    m = model("basic")
    sim = Simulator(m, 0.01)
    with pytest.raises(InputError, match="shape"):
        sim.replay(np.zeros((10, 3)))
    u = np.zeros((10, 8)); u[3, 1] = np.inf
    with pytest.raises(InputError, match="NaN or infinite"):
        sim.replay(u)
