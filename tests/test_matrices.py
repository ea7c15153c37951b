"""Every matrix entry against model.md (sections 2-5), written out independently.

Source of every expected value: shared/spec/model.md, the restated Eq. (1),
(4), (13), (19) of the paper; values at the Puma condition of section 8.
"""
import numpy as np
import pytest

from inflowsim import PUMA, build_model, descriptor, preset_parameters
from inflowsim.physics import flapping as fl
from inflowsim.physics import loads as ld
from inflowsim.errors import InputError
from inflowsim.model.params import Constants

MUS = [0.1, 0.249, 0.35]


def entries(mu, nb, lb2):
    """(matrix function, expected rows) straight from model.md."""
    return {
        "C": (fl.flap_c(mu, nb), [[nb, 0, 2 / 3 * mu * nb], [0, nb, 2], [4 / 3 * mu * nb, -2, nb]]),
        "D": (fl.flap_d(mu, nb, lb2), [[lb2, 0, 0], [4 / 3 * mu * nb, lb2 - 1, nb * (1 + mu**2 / 2)],
                                       [0, -nb * (1 - mu**2 / 2), lb2 - 1]]),
        "H_theta": (fl.flap_h_theta(mu, nb), [[nb * (1 + mu**2), 0, 4 / 3 * mu * nb],
                                              [0, nb * (1 + mu**2 / 2), 0],
                                              [8 / 3 * mu * nb, 0, nb * (1 + 3 * mu**2 / 2)]]),
        "H_nu": (fl.flap_h_nu(mu, nb), [[4 / 3 * nb, 0, 2 / 3 * mu * nb], [0, nb, 2],
                                        [2 * mu * nb, -2, nb]]),
        "H_eta": (fl.flap_h_eta(), [[0, 0], [1, 0], [0, 1]]),
        "H_lambda": (fl.flap_h_lambda(mu, nb), [[-4 / 3 * nb, 0, -2 / 3 * mu * nb], [0, -nb, 0],
                                                [-2 * mu * nb, 0, -nb]]),
        "G_dbeta": (ld.g_dbeta(mu), [[-1 / 6, 0, -mu / 8], [0, 1 / 16, 0], [mu / 12, 0, 1 / 16]]),
        "G_beta": (ld.g_beta(mu), [[0, 0, 0], [mu / 12, 0, 1 / 16 + mu**2 / 32],
                                   [0, -1 / 16 + mu**2 / 32, 0]]),
        "G_theta": (ld.g_theta(mu), [[1 / 6 + mu**2 / 4, 0, mu / 4], [0, -1 / 16 - mu**2 / 32, 0],
                                     [-mu / 6, 0, -1 / 16 - 3 * mu**2 / 32]]),
        "G_nu": (ld.g_nu(mu), [[1 / 4, 0, mu / 8], [0, -1 / 16, 0], [-mu / 8, 0, -1 / 16]]),
        "G_lambda": (ld.g_lambda(mu), [[-1 / 4, 0, -mu / 8], [0, 1 / 16, 0], [mu / 8, 0, 1 / 16]]),
    }


@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("name", list(entries(0.2, 1.0, 1.0)))
def test_matrix_entries(mu, name):
    got, want = entries(mu, 0.987, 1.06)[name]
    np.testing.assert_allclose(got, np.array(want, float), rtol=0, atol=1e-15)


def test_momentum_l_and_singular_refusal():
    a0s = PUMA.a0s
    np.testing.assert_allclose(ld.momentum_l(0.249, a0s),
                               np.diag([a0s / 0.498, -2 * a0s / 0.249, -2 * a0s / 0.249]))
    for mu in (0.0, 0.05, float("nan")):
        with pytest.raises(InputError, match="mu"):
            ld.momentum_l(mu, a0s)


def _blocks(mu=0.249, a0s=PUMA.a0s, nb=0.987, lb2=1.06):
    e = entries(mu, nb, lb2)
    g = {k: np.array(v[1], float) for k, v in e.items()}
    L = np.diag([a0s / (2 * mu), -2 * a0s / mu, -2 * a0s / mu])
    return g, L


def test_basic_descriptor_assembly_eq_9():
    k = PUMA
    p = {"lambda_beta2": 1.06, "n_beta": 0.987, "tau": 3.0}
    E, A, B = descriptor("basic", p, k)
    g, L = _blocks()
    E_ = np.block([[g["C"], np.zeros((3, 3))], [-L @ g["G_dbeta"], 3.0 * np.eye(3)]])
    A_ = np.block([[-g["D"], g["H_lambda"]], [L @ g["G_beta"], L @ g["G_lambda"] - np.eye(3)]])
    B_ = np.block([[g["H_theta"], g["H_nu"], g["H_eta"]],
                   [L @ g["G_theta"], L @ g["G_nu"], np.zeros((3, 2))]])
    for got, want in ((E, E_), (A, A_), (B, B_)):
        np.testing.assert_allclose(got, want, rtol=1e-14, atol=1e-15)


def test_empirical_descriptor_eq_13():
    p = preset_parameters("empirical", PUMA, "paper") | {"azimuth_bias": 0.0}
    E, A, B = descriptor("empirical", p, PUMA)
    np.testing.assert_allclose(E[3:, 3:], np.diag([p["tau0"], p["tau_cs"], p["tau_cs"]]))
    K = np.array([[p["k01"], p["k02"]], [p["k11"], p["k12"]], [p["k21"], p["k22"]]])
    np.testing.assert_allclose(B[3:, 8:10], K, atol=1e-15)
    np.testing.assert_allclose(B[:3, 8:10], 0.0)


def test_glauert_descriptor_eq_19_20():
    """F nu_lambda + G mu_xy moved into E21, A21, A22, B21, B22 and the G block."""
    k = PUMA
    p = preset_parameters("glauert", k, "paper") | {"azimuth_bias": 0.0}
    pb = {"lambda_beta2": p["lambda_beta2"], "n_beta": p["n_beta"], "tau": 1.0}
    Eb, Ab, Bb = descriptor("basic", pb, k)
    E, A, B = descriptor("glauert", p, k)
    k0 = p["k0p"] - k.a0s / (8 * k.mu)
    F = np.array([[p["ks"], p["kc"]], [0, k0], [k0, 0]])
    G = np.array([[p["c1"], p["c2"]], [-p["c3"], p["c4"]], [p["c4"], p["c3"]]])
    # p* = pbar + beta1c - beta1s' + theta1s ; q* = qbar - beta1s - beta1c' + theta1c
    dE21 = np.zeros((3, 3)); dE21[:, 2] = F[:, 0]; dE21[:, 1] = F[:, 1]
    dA21 = np.zeros((3, 3)); dA21[:, 1] = F[:, 0]; dA21[:, 2] = -F[:, 1]
    dA22 = np.zeros((3, 3)); dA22[:, 2] = -F[:, 0]; dA22[:, 1] = -F[:, 1]
    dB = np.zeros((3, 10)); dB[:, 2] += F[:, 0]; dB[:, 5] += F[:, 0]
    dB[:, 1] += F[:, 1]; dB[:, 4] += F[:, 1]; dB[:, 8:10] = G
    np.testing.assert_allclose(E[:3], Eb[:3], atol=1e-15)
    np.testing.assert_allclose(E[3:, :3] - Eb[3:, :3], dE21, atol=1e-14)
    np.testing.assert_allclose(E[3:, 3:], np.diag([p["tau0"], p["tau_cs"], p["tau_cs"]]))
    np.testing.assert_allclose(A[:3], Ab[:3], atol=1e-15)
    np.testing.assert_allclose(A[3:, :3] - Ab[3:, :3], dA21, atol=1e-14)
    np.testing.assert_allclose(A[3:, 3:] - Ab[3:, 3:], dA22, atol=1e-14)
    np.testing.assert_allclose(B[:3, :8], Bb[:3], atol=1e-15)
    np.testing.assert_allclose(B[3:, :8] - Bb[3:], dB[:, :8], atol=1e-14)
    np.testing.assert_allclose(B[3:, 8:], G, atol=1e-15)


def test_k0_enters_only_as_k0p():
    """model.md section 5: lambda1c/lambda1s self-terms of L c are -a0 s/(8 mu)."""
    k = PUMA
    p = preset_parameters("glauert", k, "paper")
    E, A, B = descriptor("glauert", p, k)
    assert A[4, 4] == pytest.approx(-1 - p["k0p"], abs=1e-14)
    assert E[4, 1] == pytest.approx(p["k0p"], abs=1e-14)
    assert B[4, 4] == pytest.approx(p["k0p"], abs=1e-14)     # qbar column
    assert B[5, 5] == pytest.approx(p["k0p"], abs=1e-14)     # pbar column


@pytest.mark.parametrize("mu", MUS)
def test_glauert_neutral_equals_basic_exactly(mu):
    """k0p = a0 s/(8 mu), the rest zero, equal time constants -> basic (model.md 5)."""
    k = PUMA.with_mu(mu)
    base = {"lambda_beta2": 1.06, "n_beta": 0.987, "tau": 4.2}
    neutral = dict(base, tau0=4.2, tau_cs=4.2, c1=0.0, c2=0.0, c3=0.0, c4=0.0,
                   k0p=k.a0s / (8 * mu), kc=0.0, ks=0.0)
    neutral.pop("tau")
    Eb, Ab, Bb = descriptor("basic", base, k)
    Eg, Ag, Bg = descriptor("basic+separate-time-constants+glauert", neutral, k)
    np.testing.assert_allclose(Eg, Eb, atol=1e-15, rtol=0)
    np.testing.assert_allclose(Ag, Ab, atol=1e-15, rtol=0)
    np.testing.assert_allclose(Bg[:, :8], Bb, atol=1e-15, rtol=0)
    np.testing.assert_array_equal(Bg[:, 8:], 0.0)


def test_azimuth_bias_rotates_pitch_inputs_and_flap_outputs():
    k = PUMA
    p = preset_parameters("empirical", k, "paper")
    d = p["azimuth_bias"]
    p0 = dict(p, azimuth_bias=0.0)
    m, m0 = build_model("empirical", p, k), build_model("empirical", p0, k)
    r = np.array([[np.cos(d), -np.sin(d)], [np.sin(d), np.cos(d)]])
    np.testing.assert_allclose(m.B[:, 1:3], m0.B[:, 1:3] @ r.T, atol=1e-14)
    np.testing.assert_allclose(m.c[1:3, 1:3], r, atol=1e-15)
    np.testing.assert_allclose(m.B[:, [0, *range(3, 10)]], m0.B[:, [0, *range(3, 10)]])


def test_si_state_space_from_descriptor():
    """x_dot = Omega E^-1 (A x + B S u), S = diag(1,1,1,1,1/Om,1/Om,1/Om^2,1/Om^2)."""
    k = PUMA
    m = build_model("basic", preset_parameters("basic", k, "paper"), k)
    om = k.omega
    np.testing.assert_allclose(m.E @ m.a, om * m.A, atol=1e-10)
    s = np.array([1, 1, 1, 1, 1 / om, 1 / om, 1 / om**2, 1 / om**2])
    np.testing.assert_allclose(m.E @ m.b, om * m.B * s, atol=1e-12)


@pytest.mark.parametrize("preset", ["basic", "empirical", "glauert"])
@pytest.mark.parametrize("source", ["paper", "theory"])
def test_puma_presets_are_stable(preset, source):
    m = build_model(preset, preset_parameters(preset, PUMA, source), PUMA)
    ev = m.eigenvalues()
    assert np.all(ev.real < 0), ev
    assert len(ev) == 6


@pytest.mark.parametrize("name,value,match", [
    ("n_beta", 0.0, "n_beta"), ("n_beta", -1.0, "n_beta"), ("tau", 0.0, "tau"),
    ("tau", float("inf"), "tau"), ("lambda_beta2", float("nan"), "lambda_beta2"),
])
def test_bad_parameters_refused_by_name(name, value, match):
    p = preset_parameters("basic", PUMA, "paper") | {name: value}
    with pytest.raises(InputError, match=match) as e:
        build_model("basic", p, PUMA)
    msg = str(e.value)
    assert "\n" not in msg and ("range" in msg or "finite" in msg)


def test_bad_constants_and_structures_refused():
    p = preset_parameters("basic", PUMA, "paper")
    with pytest.raises(InputError, match="mu = 0.01 is outside the allowed range"):
        build_model("basic", p, PUMA.with_mu(0.01))
    with pytest.raises(InputError, match="alternatives"):
        build_model("glauert+hub-velocity-coupling", p, PUMA)
    with pytest.raises(InputError, match="unknown effect"):
        build_model("basic+nonsense", p, PUMA)
    pg = preset_parameters("glauert", PUMA, "paper")
    pg.pop("c3")
    with pytest.raises(InputError, match="parameter c3 is missing"):
        build_model("glauert", pg, PUMA)
    with pytest.raises(InputError, match="tau is not a parameter"):
        build_model("glauert", p | pg, PUMA)
    with pytest.raises(InputError, match="omega"):
        build_model("basic", p, Constants(mu=0.249, a0=5.73, solidity=0.0917, omega=-1))
