"""Simulator: flight-condition and step changes from the shared table and Taylor
rule (inflowsim.simulate.mutable) against scipy's expm; the step's and replay's
input checks; RK4's stability limit."""
import numpy as np
import pytest
from scipy.linalg import expm

from conftest import assert_user_error, run, virtual
from inflowsim.data.record import write_record
from inflowsim.errors import InputError
from inflowsim.model.build import build_model
from inflowsim.model.params import PUMA
from inflowsim.model.presets import preset_parameters
from inflowsim.simulate import mutable
from inflowsim.simulate.discrete import TaylorZoh, rk4, rk4_max_step
from inflowsim.simulate.simulator import Simulator

RTOL = 1e-12


def model(structure="glauert", **k):
    return build_model(structure, preset_parameters(structure, PUMA, "paper"),
                       PUMA.with_mu(k.get("mu", PUMA.mu)))


def exact_pg(m, dt):
    """[phi gam] of m's zero-order hold by scipy's expm of the augmented matrix."""
    n, nu = m.b.shape
    aug = np.zeros((n + nu, n + nu))
    aug[:n, :n], aug[:n, n:] = m.a, m.b
    return expm(aug * dt)[:n]


def rel(got, want):
    return np.max(np.abs(got - want)) / np.max(np.abs(want))


@pytest.mark.parametrize("structure, dt", [("glauert", 1e-3), ("glauert", 0.02),
                                           ("basic", 0.01),
                                           ("glauert+flap-inertia", 5e-3),
                                           ("glauert+skewed-wake", 0.01)])
def test_mu_changes_follow_expm_to_1e12(structure, dt):
    m0 = model(structure)
    sim = Simulator(m0, dt)
    sim.set_mu(0.3)
    assert sim._mu_table is None                 # one change: an exact rebuild
    sim.set_mu(0.31)
    assert sim._mu_table, "the second change builds the table"
    rng = np.random.default_rng(3)
    mus = np.concatenate([rng.uniform(0.1, 0.5, 25), mutable.edges(), [0.1, 0.5]])
    for mu in mus:
        sim.set_mu(mu)
        want = exact_pg(m0.with_mu(mu), dt)
        got = np.hstack([sim.phi, sim.gam])
        assert rel(got, want) <= RTOL, (mu, rel(got, want))
        # the outputs' rows follow: y = c [phi gam] [x; u]
        np.testing.assert_allclose(sim._M[sim.n:-1], m0.c @ got, rtol=0, atol=1e-15)


def test_mu_every_step_equals_the_exact_hold_and_the_model_follows():
    m0 = model()
    dt = 0.01
    sim = Simulator(m0, dt)
    rng = np.random.default_rng(0)
    u = 1e-2 * rng.standard_normal((200, sim.m))
    x = np.zeros(sim.n)
    for k in range(200):
        mu = 0.3 + 0.18 * np.sin(0.05 * k)
        sim.set_mu(mu)
        y = sim.step(u[k])
        pg = exact_pg(m0.with_mu(mu), dt)
        x = pg @ np.concatenate([x, u[k]])
        scale = np.max(np.abs(x))
        np.testing.assert_allclose(sim.state, x, rtol=0, atol=RTOL * scale)
        np.testing.assert_allclose(y, m0.c @ x, rtol=0, atol=RTOL * scale)
    assert sim._mu_table
    # the model, the loads and the outputs are those at the last mu
    assert sim.model.constants.mu == mu
    np.testing.assert_array_equal(sim.model.a, m0.with_mu(mu).a)
    from inflowsim.model.loads import load_matrices
    lm = load_matrices(m0.with_mu(mu))
    np.testing.assert_allclose(sim.loads(), lm.c @ sim.state + lm.d @ u[-1], rtol=1e-14)


def test_no_table_where_it_cannot_apply():
    # RK4 (stability is checked at each mu), output delays, mu outside the table
    for sim in (Simulator(model(), 0.01, method="rk4"),
                Simulator(model("glauert+time-delay").with_parameters(delay=0.03), 0.01)):
        sim.set_mu(0.3)
        sim.set_mu(0.31)
        assert sim._mu_table is False
        want = Simulator(sim.model.with_mu(0.31), 0.01, method=sim.method)
        np.testing.assert_array_equal(sim.phi, want.phi)
    sim = Simulator(model(), 0.01)
    sim.set_mu(0.3)
    sim.set_mu(0.31)
    with pytest.raises(InputError, match="mu"):
        sim.set_mu(0.05)


@pytest.mark.parametrize("structure", ["glauert", "glauert+flap-inertia"])
def test_set_dt_follows_expm_to_1e12(structure):
    m = model(structure)
    sim = Simulator(m, 0.01)
    for dt in (1e-4, 1e-3, 1 / 60, 0.0203, 0.05, 0.2, 1.0):
        sim.set_dt(dt)
        got = np.hstack([sim.phi, sim.gam])
        assert rel(got, exact_pg(m, dt)) <= RTOL, dt
    # few terms where the step is short, the exponential where it would need > 30
    tz = TaylorZoh(m.a, m.b)
    assert 0 < mutable.taylor_terms(tz.norm_a, tz.norm_ab, 1e-3) <= 12
    assert mutable.taylor_terms(tz.norm_a, tz.norm_ab, 1.0) == 0


def test_set_dt_keeps_state_count_and_time():
    sim = Simulator(model(), 0.01, t0=2.0)
    u = np.full(sim.m, 1e-3)
    for _ in range(10):
        sim.step(u)
    x = sim.state
    sim.set_dt(0.005)
    assert sim.step_count == 10 and sim.time == pytest.approx(2.1, abs=1e-15)
    np.testing.assert_array_equal(sim.state, x)
    y = sim.step(u)
    ref = Simulator(model(), 0.005)
    ref.state = x
    np.testing.assert_allclose(y, ref.step(u), rtol=0, atol=1e-14)
    assert sim.time == pytest.approx(2.105, abs=1e-15)
    with pytest.raises(InputError, match="dt"):
        sim.set_dt(-1.0)


# -- RK4's stability limit ---------------------------------------------------------
def test_rk4_max_step_on_the_real_and_imaginary_axes():
    assert rk4_max_step([-1.0]) == pytest.approx(2.785293563405282, rel=1e-12)
    assert rk4_max_step([-10.0, -1.0]) == pytest.approx(0.2785293563405282, rel=1e-12)
    assert rk4_max_step([2j, -2j]) == pytest.approx(np.sqrt(8) / 2, rel=1e-12)
    assert rk4_max_step([0.5, 0.0]) == np.inf      # nothing the step could stabilise


def test_rk4_refuses_an_unstable_step_naming_the_largest_stable_one():
    m = model()
    h = rk4_max_step(np.linalg.eigvals(m.a))
    # at the limit the discrete map is on the unit circle, beyond it outside
    for f, inside in ((0.999, True), (1.001, False)):
        phi, _ = rk4(m.a, m.b, f * h)
        assert (np.max(np.abs(np.linalg.eigvals(phi))) <= 1.0) == inside
    Simulator(m, 0.999 * h, method="rk4")
    with pytest.raises(InputError) as err:
        Simulator(m, 0.1, method="rk4")
    assert "RK4 is unstable" in str(err.value) and f"{h:.4g} s" in str(err.value)
    sim = Simulator(m, 0.05, method="rk4")
    with pytest.raises(InputError, match="largest stable"):
        sim.set_dt(0.1)
    assert sim.dt == 0.05
    Simulator(m, 0.1)                                # the exact hold is stable anywhere


def test_simulate_command_refuses_an_unstable_rk4_step(capsys, tmp_path):
    rec = tmp_path / "rec.csv"
    write_record(virtual(structure="glauert", duration=12.0), rec)   # cached: test_user_errors
    code, out, err = run(capsys, "simulate", rec, "-m", "glauert", "--method", "rk4",
                         "--dt", "0.1", "--out", tmp_path / "out.csv")
    assert_user_error(code, out, err, "RK4 is unstable", "largest stable step")
    assert not (tmp_path / "out.csv").exists()


# -- the step's and replay's input checks ---------------------------------------------
@pytest.fixture
def sim():
    return Simulator(model(), 0.01)


@pytest.mark.parametrize("bad, words", [
    ([1j] * 10, ["complex"]), (np.full(10, 1 + 0j), ["complex"]),
    (["0.1"] * 10, ["text"]), (np.array(["0.1"] * 10), ["text"]),
    ([0.0] * 9 + ["x"], ["text"]), ([None] * 10, ["NaN or infinite"]),
    ([0.0] * 9 + [1e7], ["1e+07", "beyond 1e+06"]),
    (np.array([0.0] * 9 + [-2e6]), ["2e+06", "beyond 1e+06"]),
    ([0.0] * 9 + [-np.inf], ["NaN or infinite"]),
], ids=lambda v: repr(v)[:24])
def test_step_refuses_with_one_clear_line(sim, bad, words):
    u = np.full(sim.m, 1e-3)
    sim.step(u)
    x, k = sim.state, sim.step_count
    with pytest.raises(InputError) as err:
        sim.step(bad)
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("step: inputs must be 10 numbers")
    for w in words:
        assert w in msg, msg
    np.testing.assert_array_equal(sim.state, x)
    assert sim.step_count == k
    with pytest.raises(InputError):
        sim.replay(np.tile(np.asarray(bad, dtype=object), (3, 1)))


def test_step_takes_every_value_within_1e6(sim):
    # the sum of squares passes 1e12 but no input is beyond 1e6: taken
    u = np.full(sim.m, 9e5)
    y = sim.step(u)
    want = Simulator(model(), 0.01).replay(np.tile(u, (2, 1)))[1]
    np.testing.assert_allclose(y, want, rtol=1e-14)
    sim.step([1e6] + [0] * 9)
    sim.step(np.array([1, 0, 0, 0, 0, 0, 0, 0, 0, 0]))     # integers are numbers
    sim.step([0.0] * 9 + [np.float32(1e-3)])


@pytest.mark.parametrize("ct", [0.004, 0.015])
def test_mass_flow_speed_is_tabulated_above_0_1_and_exact_below(ct):
    """The mass-flow speed's branch points (mu = +-i lambda_hover) are as far from the
    table's segments as mu = 0: tabulated on [0.1, 0.5]; on the way to hover, exact."""
    from dataclasses import replace
    k = replace(PUMA, ct=ct, inflow_speed="mass-flow")
    m0 = build_model("glauert", preset_parameters("glauert", k, "paper"), k)
    sim = Simulator(m0, 0.01)
    sim.set_mu(0.3)
    sim.set_mu(0.31)
    assert sim._mu_table
    for mu in (0.0, 0.05, 0.0999, 0.1, 0.137, 0.42):
        sim.set_mu(mu)
        got = np.hstack([sim.phi, sim.gam])
        assert rel(got, exact_pg(m0.with_mu(mu), 0.01)) <= RTOL, mu
