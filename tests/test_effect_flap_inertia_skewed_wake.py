"""``flap-inertia`` and ``skewed-wake``: descriptor entries, neutral values,
stability with Puma theory values, parsing.  Expected blocks are built from
model.md's matrices (``inflowsim.physics.flapping`` / ``inflowsim.physics.loads``, themselves
checked against quadrature in ``test_quadrature.py``)."""
import math

import numpy as np
import pytest
from scipy.optimize import fsolve

from inflowsim import PUMA, Structure, build_model, descriptor, preset_parameters
from inflowsim.physics import flapping as fl
from inflowsim.physics import loads as ld
from inflowsim.model.effects.skewed_wake import theory_skew
from inflowsim.model.equations import rotation
from inflowsim.simulate.simulator import Simulator
from inflowsim.flighttest.virtual import PUMA_TRIM

from test_quadrature import loads_quad, zero_state

K = PUMA.with_trim(PUMA_TRIM)
MU = PUMA.mu


def _theory(structure, k=PUMA, **over):
    p = preset_parameters(structure, k, "theory")
    p.update(over)
    return p


def _without(p, name):
    return {k: v for k, v in p.items() if k != name}


# -- flap-inertia -------------------------------------------------------------------

@pytest.mark.parametrize("scale", [1.0, 0.37])
def test_flap_inertia_nine_state_descriptor_entry_by_entry(scale):
    s = "basic+flap-inertia"
    nb, lb2, tau = 0.95, 1.08, 5.0
    e, a, b = descriptor(s, {"lambda_beta2": lb2, "n_beta": nb, "tau": tau,
                             "flap_inertia": scale}, PUMA)
    lm = ld.momentum_l(MU, PUMA.a0s)
    z, i3 = np.zeros((3, 3)), np.eye(3)
    want_e = np.block([[i3, z, z], [z, tau * i3, z], [z, z, scale * i3]])
    want_a = np.block([
        [z, z, i3],
        [lm @ ld.g_beta(MU), lm @ ld.g_lambda(MU) - i3, lm @ ld.g_dbeta(MU)],
        [-fl.flap_d(MU, nb, lb2), fl.flap_h_lambda(MU, nb), -fl.flap_c(MU, nb)]])
    want_b = np.vstack([
        np.zeros((3, 8)),
        np.hstack([lm @ ld.g_theta(MU), lm @ ld.g_nu(MU), np.zeros((3, 2))]),
        np.hstack([fl.flap_h_theta(MU, nb), fl.flap_h_nu(MU, nb), fl.flap_h_eta()])])
    np.testing.assert_allclose(e, want_e, rtol=1e-15, atol=0)
    np.testing.assert_allclose(a, want_a, rtol=1e-15, atol=0)
    np.testing.assert_allclose(b, want_b, rtol=1e-15, atol=0)


def test_flap_inertia_moves_glauert_rate_terms_from_e21_to_a():
    p = preset_parameters("glauert", PUMA, "paper")
    e6, a6, b6 = descriptor("glauert", p, PUMA)
    e9, a9, b9 = descriptor("glauert+flap-inertia", p | {"flap_inertia": 1.0}, PUMA)
    assert np.abs(e6[3:6, 0:3]).max() > 0.1       # Glauert beta' terms live in E21 ...
    np.testing.assert_array_equal(e9[3:6, 0:3], 0.0)   # ... and leave it
    np.testing.assert_array_equal(e9[3:6, 6:9], 0.0)
    np.testing.assert_array_equal(e9[3:6, 3:6], e6[3:6, 3:6])
    np.testing.assert_array_equal(a9[3:6, 6:9], -e6[3:6, 0:3])
    np.testing.assert_array_equal(a9[3:6, 0:6], a6[3:6, :])
    np.testing.assert_array_equal(a9[6:9, 6:9], -e6[0:3, 0:3])
    np.testing.assert_array_equal(a9[6:9, 0:6], a6[0:3, :])
    np.testing.assert_array_equal(b9[3:6], b6[3:6])
    np.testing.assert_array_equal(b9[6:9], b6[0:3])


@pytest.mark.parametrize("structure", ["basic", "glauert"])
def test_flap_inertia_response_approaches_first_order_at_low_frequency(structure):
    p = preset_parameters(structure, PUMA, "paper")
    m6 = build_model(structure, p, PUMA)
    m9 = build_model(structure + "+flap-inertia", p | {"flap_inertia": 1.0}, PUMA)
    f = np.array([0.0, 0.01, 0.1, 1.0, 3.0])
    h6, h9 = m6.frequency_response(f), m9.frequency_response(f)
    err = np.abs(h9[:3] - h6[:3]).max(axis=(0, 1)) / np.abs(h6[:3]).max(axis=(0, 1))
    assert err[0] < 1e-12                    # identical static gains
    assert err[1] < 1e-3
    assert np.all(np.diff(err) > 0)          # the gap opens with frequency
    assert err[-1] > 1e-2                    # and is not nothing in the flap range


@pytest.mark.parametrize("base", ["basic", "empirical", "glauert"])
def test_flap_inertia_stable_and_parsed(base):
    s = Structure.parse(base + "+flap-inertia")
    assert s.parameters == Structure.parse(base).parameters + ("flap_inertia",)
    assert s.second_order and len(s.states) == 9 and s.states[6:] == (
        "beta0_prime", "beta1c_prime", "beta1s_prime")
    for source in ("theory", "paper"):
        m = build_model(s, preset_parameters(s, PUMA, source), PUMA)
        assert m.is_stable(), source
        # the added modes are the fast flap-inertia ones, about Omega in size
        assert np.abs(m.eigenvalues()).max() > 0.5 * PUMA.omega


@pytest.mark.parametrize("structure", ["basic", "glauert"])
def test_flap_inertia_nests_the_first_order_model(structure):
    """flap_inertia -> 0 is the first-order model: frequency responses (every
    input, every band frequency) and the slow-manifold end states converge to
    it linearly in the scale, the fast modes leave to -C/flap_inertia."""
    p = preset_parameters(structure, PUMA, "paper")
    m6 = build_model(structure, p, PUMA)
    f = np.linspace(0.2, 1.6, 8)
    h6 = m6.frequency_response(f)[:3]
    errs = []
    for scale in (1e-2, 1e-3, 1e-4):
        m9 = build_model(structure + "+flap-inertia", p | {"flap_inertia": scale}, PUMA)
        errs.append(np.abs(m9.frequency_response(f)[:3] - h6).max() / np.abs(h6).max())
        assert np.abs(m9.eigenvalues()).max() > 0.5 * PUMA.omega / scale
        # end states on the slow manifold: beta' is the first-order model's rate
        x6 = np.linspace(0.01, 0.06, 6)
        u = np.linspace(-0.02, 0.02, len(m6.inputs))
        xdot6 = m6.a @ x6 + m6.b @ u
        x9 = m9.end_state(x6, u)
        np.testing.assert_allclose(x9[6:] * PUMA.omega, xdot6[:3], rtol=1e-10, atol=1e-14)
    assert errs[0] < 0.05 and errs[1] < errs[0] / 5 and errs[2] < errs[1] / 5
    assert errs[2] < 1e-3


def test_flap_inertia_floor_is_the_neutral_start():
    from inflowsim.model.effects import CATALOGUE
    from inflowsim.model.effects.flap_inertia import FLOOR
    eff = CATALOGUE["flap-inertia"]
    assert eff.neutral_values(PUMA) == {"flap_inertia": FLOOR}
    assert eff.theory(PUMA) == {"flap_inertia": 1.0}
    assert eff.boundary == ("flap_inertia",)
    with pytest.raises(Exception, match="flap_inertia"):
        build_model("basic+flap-inertia", _theory("basic+flap-inertia", flap_inertia=0.0),
                    PUMA)


def test_flap_inertia_simulates():
    m = build_model("glauert+flap-inertia", preset_parameters("glauert", PUMA, "paper")
                    | {"flap_inertia": 1.0}, PUMA)
    u = np.zeros((200, len(m.inputs)))
    u[10:30, 2] = np.radians(1.0)
    y = Simulator(m, 0.01).replay(u)
    assert y.shape == (200, 6) and np.all(np.isfinite(y)) and np.abs(y[:, 2]).max() > 1e-4


# -- skewed-wake --------------------------------------------------------------------

def test_skewed_wake_descriptor_entry_by_entry():
    p = _theory("basic+skewed-wake", k_skew=0.5)
    e, a, b = descriptor("basic+skewed-wake", p, PUMA)
    e0, a0, b0 = descriptor("basic", _without(p, "k_skew"), PUMA)
    g = 0.5 * PUMA.a0s / MU
    # lambda0 row gains g x (C_mc row of the loads), lambda1c row g x (C_T row)
    for row, load_row in ((3, 1), (4, 0)):
        np.testing.assert_allclose(e[row, :3] - e0[row, :3], -g * ld.g_dbeta(MU)[load_row],
                                   rtol=0, atol=1e-15)
        np.testing.assert_allclose(a[row, :3] - a0[row, :3], g * ld.g_beta(MU)[load_row],
                                   rtol=0, atol=1e-15)
        np.testing.assert_allclose(a[row, 3:] - a0[row, 3:], g * ld.g_lambda(MU)[load_row],
                                   rtol=0, atol=1e-15)
        np.testing.assert_allclose(b[row, :3] - b0[row, :3], g * ld.g_theta(MU)[load_row],
                                   rtol=0, atol=1e-15)
        np.testing.assert_allclose(b[row, 3:6] - b0[row, 3:6], g * ld.g_nu(MU)[load_row],
                                   rtol=0, atol=1e-15)
    # everything else untouched: flap rows, lambda1s row, E22, accelerations
    np.testing.assert_array_equal(e[:3], e0[:3])
    np.testing.assert_array_equal(a[:3], a0[:3])
    np.testing.assert_array_equal(b[:3], b0[:3])
    np.testing.assert_array_equal(e[5], e0[5])
    np.testing.assert_array_equal(a[5], a0[5])
    np.testing.assert_array_equal(b[5], b0[5])
    np.testing.assert_array_equal(e[3:, 3:], e0[3:, 3:])
    np.testing.assert_array_equal(b[:, 6:], b0[:, 6:])


@pytest.mark.parametrize("base", ["basic", "glauert"])
def test_skewed_wake_neutral_value_is_the_structure_without_it(base):
    p = preset_parameters(base + "+skewed-wake", PUMA, "paper")
    p["k_skew"] = 0.0
    m = build_model(base + "+skewed-wake", p, PUMA)
    m0 = build_model(base, _without(p, "k_skew"), PUMA)
    for name in ("E", "A", "B", "a", "b", "c"):
        np.testing.assert_array_equal(getattr(m, name), getattr(m0, name), err_msg=name)


def test_skewed_wake_theta_columns_follow_the_azimuth_bias():
    dpsi = 0.39
    p = preset_parameters("glauert+skewed-wake", PUMA, "paper")
    p.update(azimuth_bias=dpsi, k_skew=0.6)
    b = build_model("glauert+skewed-wake", p, PUMA).B
    b0 = build_model("glauert", _without(p, "k_skew"), PUMA).B
    dl = 0.6 * PUMA.a0s / MU * np.array([[0, 1, 0], [1, 0, 0], [0, 0, 0]])
    want = (dl @ ld.g_theta(MU))[:, 1:3] @ rotation(-dpsi)
    np.testing.assert_allclose(b[3:6, 1:3] - b0[3:6, 1:3], want, rtol=0, atol=1e-14)


def test_skewed_wake_thrust_raises_inflow_at_the_rear():
    # steady state: a collective step gives more lambda1c (psi = 0 aft) with the skew
    p = _theory("basic+skewed-wake")
    m = build_model("basic+skewed-wake", p, PUMA)
    m0 = build_model("basic", _without(p, "k_skew"), PUMA)
    g, g0 = m.frequency_response(0.0)[:, 0, 0].real, m0.frequency_response(0.0)[:, 0, 0].real
    assert g[4] - g0[4] > 0.05 * g[3]


def test_skewed_wake_theory_values():
    assert math.isclose(theory_skew(PUMA), 15 * math.pi / 64, rel_tol=1e-15)
    # independent route: trim inflow as the fixed point lambda = L c of the
    # quadrature loads, then chi = atan(mu / (lambda0 - muz))
    s = zero_state()
    s["theta"] = np.array([PUMA_TRIM[n] for n in ("theta0", "theta1c", "theta1s")])
    s["beta"] = np.array([PUMA_TRIM[n] for n in ("beta0", "beta1c", "beta1s")])
    s["nu"][0] = PUMA_TRIM["muz"]
    lm = ld.momentum_l(MU, PUMA.a0s)

    def gap(lam):
        return lam - lm @ loads_quad(MU, {**s, "lam": lam})
    lam = fsolve(gap, np.array([0.02, 0.0, 0.0]), xtol=1e-14)
    chi = math.atan2(MU, lam[0] - PUMA_TRIM["muz"])
    assert 80 < math.degrees(chi) < 90
    assert math.isclose(theory_skew(K), 15 * math.pi / 64 * math.tan(chi / 2), rel_tol=1e-9)


@pytest.mark.parametrize("base", ["basic", "empirical", "glauert"])
@pytest.mark.parametrize("k", [PUMA, K], ids=["no-trim", "trim"])
def test_skewed_wake_stable_and_parsed(base, k):
    s = Structure.parse(base + "+skewed-wake")
    assert s.parameters == Structure.parse(base).parameters + ("k_skew",)
    for source in ("theory", "paper"):
        p = preset_parameters(s, k, source)
        assert p["k_skew"] == theory_skew(k)
        assert build_model(s, p, k).is_stable(), source


def test_all_three_new_effects_together():
    s = Structure.parse("glauert+flap-inertia+skewed-wake+advance-ratio-perturbation")
    assert s.parameters[-2:] == ("k_skew", "k_mu") and len(s.states) == 9
    assert build_model(s, preset_parameters(s, K, "paper"), K).is_stable()
