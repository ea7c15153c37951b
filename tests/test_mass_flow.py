"""The whole envelope (issue #10 part 4): the momentum mass-flow speed keeps the inflow
model finite from hover to mu = 0.5, equals the paper's V ~ mu in fast flight, and leaves
the paper's presets bit for bit where V ~ mu is asked for."""
import math

import numpy as np
import pytest

from inflowsim.errors import InputError
from inflowsim.model.build import build_model
from inflowsim.model.loads import load_matrices
from inflowsim.model.params import PUMA, Constants
from inflowsim.model.presets import preset_parameters, theory_parameters
from inflowsim.physics.loads import mass_flow_parameter, momentum_inflow, momentum_l
from inflowsim.physics.theory import pitt_peters_time_constants
from inflowsim.simulate.simulator import Simulator

CT = 0.0064          # Puma at about 6 t: W / (rho pi R^2 (Omega R)^2), R 7.5 m, 27.5 rad/s


def flow(mu, ct=CT):
    return Constants(mu=mu, a0=5.73, solidity=0.0917, omega=27.5, radius=7.5, ct=ct,
                     inflow_speed="mass-flow").check()


@pytest.mark.parametrize("mu", [0.0, 0.02, 0.1, 0.249, 0.5])
def test_momentum_inflow_solves_glauerts_formula(mu):
    lam = momentum_inflow(mu, CT)
    assert 2 * lam * math.hypot(mu, lam) == pytest.approx(CT, rel=1e-14)


def test_momentum_inflow_limits():
    assert momentum_inflow(0.0, CT) == pytest.approx(math.sqrt(CT / 2), rel=1e-15)
    assert momentum_inflow(0.5, CT) == pytest.approx(CT / (2 * 0.5), rel=2e-4)


def test_hover_mass_flow_is_twice_the_induced_velocity():
    # hover momentum theory: lambda = sqrt(CT/2), d lambda / d CT = 1/(4 lambda) = 1/(2V)
    assert mass_flow_parameter(0.0, CT) == pytest.approx(2 * math.sqrt(CT / 2), rel=1e-15)


@pytest.mark.parametrize("mu", [0.0, 0.05, 0.1, 0.2, 0.3, 0.5])
def test_mass_flow_is_the_linearised_momentum_theory(mu):
    """An independent route: the finite-difference derivative of the nonlinear momentum
    solution in thrust is 1/(2V)."""
    h = 1e-7
    d = (momentum_inflow(mu, CT + h) - momentum_inflow(mu, CT - h)) / (2 * h)
    assert d == pytest.approx(1 / (2 * mass_flow_parameter(mu, CT)), rel=1e-7)


@pytest.mark.parametrize("mu", [0.0, 0.1, 0.3])
def test_steady_inflow_of_the_model_follows_momentum_theory(mu):
    """Collective step on the basic model (theory values): the steady lambda0 is
    delta CT / (2 V), the linearised Glauert formula, with delta CT from Eq. (4)."""
    k = flow(mu)
    m = build_model("basic", theory_parameters("basic", k), k)
    u = np.zeros(m.b.shape[1])
    u[0] = math.radians(0.5)
    x = -np.linalg.solve(m.a, m.b @ u)
    d_ct = load_matrices(m)(x, u)[0]
    h = 1e-7
    slope = (momentum_inflow(mu, CT + h) - momentum_inflow(mu, CT - h)) / (2 * h)
    assert x[m.states.index("lambda0")] == pytest.approx(slope * d_ct, rel=1e-6)


def test_fast_flight_equals_the_papers_gain():
    """``V = mu (1 + 3/2 (lambda/mu)^2 + ...)``: the paper's gain to second order in
    ``lambda / mu`` (0.1 % at mu = 0.35, 0.03 % at 0.5)."""
    for mu in (0.249, 0.35, 0.5):
        ratio = (np.diag(momentum_l(mu, 0.5, mass_flow_parameter(mu, CT)))
                 / np.diag(momentum_l(mu, 0.5)))
        small = (momentum_inflow(mu, CT) / mu) ** 2
        assert np.all(ratio < 1) and np.all(1 - ratio < 2 * small), (mu, ratio)
    assert 1 - mass_flow_parameter(0.5, CT) / 0.5 > -3e-4


def test_pitt_peters_apparent_mass_values():
    """Theory time constants are the Pitt-Peters apparent mass diag(8/(3 pi),
    16/(45 pi), 16/(45 pi)) over the momentum gains, with the flow speed V: finite at
    hover."""
    for mu in (0.0, 0.1, 0.3):
        v = mass_flow_parameter(mu, CT)
        tau0, tau_cs = pitt_peters_time_constants(v)
        assert tau0 * 2 * v == pytest.approx(8 / (3 * math.pi), rel=1e-14)
        assert tau_cs * v / 2 == pytest.approx(16 / (45 * math.pi), rel=1e-14)
        p = theory_parameters("empirical", flow(mu))
        assert (p["tau0"], p["tau_cs"]) == pytest.approx((tau0, tau_cs), rel=1e-14)
    assert 8 / (3 * math.pi) == pytest.approx(0.8488, abs=1e-4)
    assert 16 / (45 * math.pi) == pytest.approx(0.1132, abs=1e-4)


@pytest.mark.parametrize("structure", ["basic", "empirical", "glauert"])
def test_papers_presets_bit_for_bit_with_v_mu(structure):
    p = preset_parameters(structure, PUMA, "paper")
    a = build_model(structure, p, PUMA)
    b = build_model(structure, p, Constants(mu=0.249, a0=5.73, solidity=0.0917,
                                            omega=27.5, radius=7.5, ct=CT))
    for name in ("E", "A", "B", "a", "b", "c"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


@pytest.mark.parametrize("structure", ["basic", "empirical", "glauert"])
def test_whole_envelope_is_finite_and_stable(structure):
    for mu in np.linspace(0.0, 0.5, 11):
        k = flow(float(mu))
        m = build_model(structure, theory_parameters(structure, k), k)
        assert np.all(np.isfinite(m.a)) and m.is_stable(), mu


def test_simulator_flies_from_hover_to_forward_flight():
    k = flow(0.0)
    m = build_model("glauert", theory_parameters("glauert", k), k)
    sim = Simulator(m, 1 / 60)
    u = np.zeros(sim.m)
    u[0] = math.radians(0.5)
    for i in range(600):                     # 10 s, accelerating to mu 0.3
        sim.set_mu(0.3 * min(i / 300, 1.0))
        y = sim.step(u)
    assert np.all(np.isfinite(y)) and np.all(np.isfinite(sim.loads()))
    assert sim.model.constants.mu == 0.3


def test_refusals_name_the_remedy():
    with pytest.raises(InputError, match="mass-flow"):
        Constants(mu=0.0, a0=5.73, solidity=0.0917, omega=27.5).check()
    with pytest.raises(InputError, match="needs the trim thrust coefficient"):
        Constants(mu=0.0, a0=5.73, solidity=0.0917, omega=27.5,
                  inflow_speed="mass-flow").check()
    with pytest.raises(InputError, match="inflow_speed"):
        Constants(mu=0.2, a0=5.73, solidity=0.0917, omega=27.5, ct=CT,
                  inflow_speed="fast").check()
    with pytest.raises(InputError, match="ct"):
        flow(0.1, ct=0.5)


def test_constants_round_trip_through_a_parameter_file():
    k = flow(0.05)
    d = k.as_dict()
    assert d["inflow_speed"] == "mass-flow" and d["ct"] == CT
    assert Constants.from_mapping(d) == k
    assert "inflow_speed" not in PUMA.as_dict() and "ct" not in PUMA.as_dict()
