"""Eq. (14)'s speed through the disc linearised about the trim
(``physics.momentum_speed``, effect ``momentum-speed``), against the individual-blade
truth's own momentum loads and its finite-difference linearisation."""
import numpy as np
import pytest

from inflowsim.errors import InputError
from inflowsim.flighttest.bladesim import BladeRotor, RotorSpec
from inflowsim.flighttest.linearise import eq14_coupling, linearise
from inflowsim.model.build import build_model
from inflowsim.model.params import PUMA
from inflowsim.physics import loads as ld
from inflowsim.physics.multiblade import blade_angles
from inflowsim.physics.momentum_speed import (eq14_trim_inflow, momentum_loads,
                                              speed_coupling)


def _state(rng):
    z = np.concatenate([0.1 * rng.standard_normal(6), 0.03 + 0.01 * rng.standard_normal(3)])
    u = np.concatenate([0.1 * rng.standard_normal(3), 0.01 * rng.standard_normal(5),
                        [0.2 + 0.05 * rng.random(), 0.02 * rng.standard_normal()]])
    return z, u


def test_the_disc_sums_are_the_blade_truths():
    """On the truth's quadrature (12 azimuths, 4 radii) the multiblade loads equal
    the individual-blade rotor's momentum loads (blades set from the multiblade
    state, at any azimuth) to rounding; with V = mux they are L^-1 lambda."""
    rng = np.random.default_rng(3)
    rotor = BladeRotor(RotorSpec(constants=PUMA.with_mu(0.2)))
    for _ in range(5):
        z, u = _state(rng)
        psi = rng.uniform(0, 2 * np.pi)
        b, db, lam = z[0:3], z[3:6], z[6:9]
        rates = np.array([db[0], db[1] + b[2], db[2] - b[1]])
        x = np.concatenate([blade_angles(b, psi, 4), blade_angles(rates, psi, 4), lam])
        ref = rotor.momentum_loads(psi, x, tuple(u))
        got = momentum_loads(z, u, PUMA.a0s, n_psi=12, n_r=4)
        assert np.max(np.abs(got - ref)) < 1e-13 * np.max(np.abs(ref))
        lm = ld.momentum_l(u[8], PUMA.a0s)
        assert np.allclose(lm @ momentum_loads(z, u, PUMA.a0s, speed="mu"), lam,
                           rtol=1e-13, atol=1e-16)


def test_the_coupling_is_the_blade_truths_linearisation():
    """Complex steps on the multiblade disc sums equal central differences of the
    blade truth averaged over a blade passage (``flighttest.linearise``) at the
    truth's trim: one route differentiates Eq. (14) in multiblade form, the other
    the individual blades."""
    spec = RotorSpec(constants=PUMA.with_mu(0.12))
    ref = eq14_coupling(spec)
    lin = linearise(spec)
    from inflowsim.flighttest.nonlinear import TRIM_CONTROLS
    theta = [TRIM_CONTROLS[c] for c in ("theta0", "theta1c", "theta1s")]
    a, b = speed_coupling(0.12, PUMA.a0s, theta, lin.trim_beta, 0.0, lin.trim_lambda,
                          n_psi=12, n_r=4)
    scale = np.max(np.abs(ref["A"]))
    assert np.max(np.abs(a - ref["A"])) < 1e-6 * scale
    # measured: 2e-11 of the largest term (the blade route's central differences)
    assert np.max(np.abs(b - ref["B"])) < 1e-6 * scale


def test_the_trim_inflow_with_eq14_balances_the_loads():
    """Newton's trim inflow makes blade-element and momentum loads equal, and lies
    below the basic model's (V > mu carries more mass: less inflow for the thrust)."""
    from inflowsim.physics.bladeelement import trim_inflow
    theta, beta = np.array([0.17, 0.01, -0.05]), np.array([0.1, 0.01, -0.005])
    for mu in (0.1, 0.3):
        lam = eq14_trim_inflow(mu, PUMA.a0s, theta, beta, 0.0)
        blade = (ld.g_theta(mu) @ theta + ld.g_beta(mu) @ beta + ld.g_lambda(mu) @ lam)
        z = np.concatenate([beta, np.zeros(3), lam])
        u = np.array([*theta, 0.0, 0, 0, 0, 0, mu, 0])
        assert np.allclose(blade, momentum_loads(z, u, PUMA.a0s), atol=1e-14)
        assert lam[0] < trim_inflow(mu, PUMA.a0s, theta, beta, 0.0)[0]


def _constants(mu):
    trim = {"theta0": 0.17, "theta1c": 0.01, "theta1s": -0.05, "muz": 0.0,
            "beta0": 0.1, "beta1c": 0.01, "beta1s": -0.005, "mux": mu, "muy": 0.0}
    return PUMA.with_mu(mu).with_trim(trim)


def test_the_effect_is_nested_and_adds_the_coupling():
    """At k_V = 0 the structure is the one without the effect; at k_V the inflow
    rows gain k_V times the coupling; with an azimuth bias the coupling acts on the
    true pitch.  It needs the record's trim, is not offered to the diagnosis by
    default, and is an alternative to glauert."""
    from inflowsim.model.effects import CATALOGUE
    from inflowsim.model.build import equations
    k = _constants(0.15)
    base = "basic+separate-time-constants+flap-inertia"
    p = {"lambda_beta2": 1.06, "n_beta": 0.987, "tau0": 2.8, "tau_cs": 1.5,
         "flap_inertia": 1.0}
    m0 = build_model(base + "+advance-ratio-perturbation", dict(p, k_mu=0.0), k)
    m1 = build_model(base + "+advance-ratio-perturbation+momentum-speed",
                     dict(p, k_mu=0.0, k_V=0.0), k)
    assert np.allclose(m0.a, m1.a) and np.allclose(m0.b, m1.b)
    # nested beside the direct in-plane forcing too, whose trim inflow moves with k_V
    # to Eq. (14)'s: at k_V = 0 it is the basic model's, the parent structure's
    m0 = build_model(base + "+advance-ratio-perturbation", dict(p, k_mu=1.0), k)
    m1 = build_model(base + "+advance-ratio-perturbation+momentum-speed",
                     dict(p, k_mu=1.0, k_V=0.0), k)
    np.testing.assert_array_equal(m0.a, m1.a)
    np.testing.assert_array_equal(m0.b, m1.b)
    m1 = build_model(base + "+advance-ratio-perturbation+momentum-speed",
                     dict(p, k_mu=1.0, k_V=1e-9), k)
    assert 0 < np.abs(m1.b - m0.b).max() < 1e-8
    _, _, eq0, _ = equations(base + "+advance-ratio-perturbation", dict(p, k_mu=0.0), k)
    _, _, eq1, _ = equations(base + "+advance-ratio-perturbation+momentum-speed",
                             dict(p, k_mu=0.0, k_V=0.7), k)
    from inflowsim.model.effects.momentum_speed import coupling
    a, b = coupling(k)
    assert np.allclose(eq1.p_lambda - eq0.p_lambda, 0.7 * a[:, 6:9])
    assert np.allclose(eq1.p_u - eq0.p_u, 0.7 * b)
    # azimuth bias: the recorded pitch columns are the true ones turned
    pb = dict(p, k_V=1.0, azimuth_bias=0.2)
    _, _, eqb, _ = equations(base + "+azimuth-bias+momentum-speed", pb, k)
    _, _, eqn, _ = equations(base + "+azimuth-bias", dict(p, azimuth_bias=0.2), k)
    from inflowsim.model.equations import rotation
    ab, bb = coupling(k, 0.2)
    assert np.allclose((eqb.p_u - eqn.p_u)[:, 1:3], bb[:, 1:3] @ rotation(-0.2))
    assert CATALOGUE["momentum-speed"].offered is False
    with pytest.raises(InputError, match="alternatives"):
        build_model("glauert+momentum-speed", {}, k)
    with pytest.raises(InputError, match="trim"):
        build_model(base + "+momentum-speed", dict(p, k_V=1.0), PUMA.with_mu(0.15))
    from inflowsim.model.structure import needs_trim
    assert needs_trim([base + "+momentum-speed"])       # the FMU takes the trim


def test_alternatives_exclude_each_other_either_way_round():
    """glauert does not name momentum-speed an alternative, momentum-speed names
    glauert: the diagnosis's atoms keep them apart from either side (the lattice
    of a ladder that added one never offers the other)."""
    from types import SimpleNamespace
    from inflowsim.diagnose.rule import atoms, excluded
    from inflowsim.model.structure import Structure
    pool = ["glauert", "momentum-speed", "skewed-wake"]
    for have, other in (("glauert", "momentum-speed"), ("momentum-speed", "glauert")):
        fit = SimpleNamespace(structure=Structure.parse(f"basic+{have}"), fixed=())
        names = {a.effect for a in atoms(fit, pool)}
        assert other not in names and "skewed-wake" in names
        assert excluded(other, (have,))


def test_also_adds_effects_not_offered_to_the_pool(tmp_path, capsys):
    """``--also`` (diagnose, ladder, campaign): the default pool or ``--candidates``,
    plus effects not offered by default; an unknown one is one line, exit 2."""
    from conftest import assert_user_error, run
    from inflowsim.commands._common import pool_with
    from inflowsim.data.record import write_record
    from inflowsim.flighttest.virtual import VirtualTest, virtual_record
    from inflowsim.model.effects import CATALOGUE
    offered = [n for n, e in CATALOGUE.items() if e.offered]
    assert pool_with(None, []) is None
    assert pool_with(None, ["momentum-speed"]) == offered + ["momentum-speed"]
    assert pool_with(["glauert"], ["momentum-speed", "glauert"]) == ["glauert",
                                                                     "momentum-speed"]
    p = tmp_path / "r.csv"
    write_record(virtual_record(VirtualTest(duration=4.0)), p)
    for cmd in ("diagnose", "ladder"):
        code, out, err = run(capsys, cmd, p, "--model", "basic", "--also", "bogus")
        assert_user_error(code, out, err, "--also bogus", "not an effect")


@pytest.mark.parametrize("mu", [0.0, 0.15])
def test_with_any_base_speed_the_steady_state_is_eq14s(mu):
    """The coupling replaces the base model's momentum loads by Eq. (14)'s, whatever
    the base model's speed through the disc (the gain ``L`` it is taken out with):
    the model's steady-state response to every input is the same with the paper's
    ``V = mu`` and with the mass-flow speed (only the apparent mass, a time scale,
    follows ``L``), and down to hover; without the effect the two differ."""
    from dataclasses import replace
    base = "basic+separate-time-constants"
    p = {"lambda_beta2": 1.06, "n_beta": 0.987, "tau0": 2.8, "tau_cs": 1.5, "k_V": 1.0}
    k_flow = replace(_constants(max(mu, 0.15)).with_mu(mu), inflow_speed="mass-flow",
                     ct=0.006)
    k_mu = replace(k_flow, inflow_speed="mu")

    def dc_gain(structure, k):
        m = build_model(structure, {n: p[n] for n in p if n != "k_V" or "speed" in
                                    structure}, k)
        return -np.linalg.solve(m.a, m.b)

    g_flow = dc_gain(base + "+momentum-speed", k_flow)
    assert np.all(np.isfinite(g_flow)) and np.abs(g_flow).max() > 0.1
    if mu == 0.0:            # V = mu has no hover; the mass-flow model is finite there
        return
    g_mu = dc_gain(base + "+momentum-speed", k_mu)
    np.testing.assert_allclose(g_flow, g_mu, rtol=0, atol=1e-9 * np.abs(g_mu).max())
    without = dc_gain(base, k_flow) - dc_gain(base, k_mu)
    assert np.abs(without).max() > 1e-3 * np.abs(g_mu).max()
