"""The nonlinear truth linearised about its periodic trim (``flighttest.linearise``):
an independent route (the blade simulation's right-hand side, central differences,
the average over a blade passage) to the linear model's equations and to the
truth's parameters at every speed."""
import numpy as np
import pytest

from inflowsim.flighttest.bladesim import RotorSpec
from inflowsim.flighttest.linearise import (STATES, eq14_coupling, linearise,
                                            model_linearisation, truth_parameters)
from inflowsim.model.build import build_model
from inflowsim.model.params import PUMA
from inflowsim.channels import INPUTS_AZ

BASE = "basic+separate-time-constants+flap-inertia"


@pytest.mark.parametrize("mu", [0.10, 0.30])
def test_the_truth_with_speed_mu_is_the_model_at_its_own_values(mu):
    """With the trim mu as the speed through the disc the truth's linearisation
    is model (1) with separate time constants and flap inertia, at the truth's
    Pitt-Peters time constants, flap frequency and Lock number: every entry of
    A and of B's eight base columns (model.md sections 2-4)."""
    spec = RotorSpec(constants=PUMA.with_mu(mu), speed="mu")
    lin = linearise(spec)
    a, b = model_linearisation(build_model(BASE, truth_parameters(spec), spec.constants))
    scale = np.max(np.abs(lin.A))
    assert np.max(np.abs(lin.A - a)) < 1e-7 * scale
    assert np.max(np.abs(lin.B[:, :8] - b[:, :8])) < 1e-7 * np.max(np.abs(lin.B))
    # the in-plane velocity acts on the blades (U_T = r + mux sin psi) though the
    # base model has no such input: it is the advance-ratio-perturbation effect
    assert np.max(np.abs(lin.B[:, INPUTS_AZ.index("mux")])) > 1e-3
    assert lin.A.flags.writeable is False


def test_eq14_adds_the_papers_q_star_and_p_star_and_more():
    """Eq. (14)'s speed through the disc, linearised by the blade route, couples
    each cyclic inflow row to one combination of flap, flap rate, pitch and hub
    rate: q* = qbar - beta1s - beta1c' + theta1c (lambda1c) and p* = pbar + beta1c
    - beta1s' + theta1s (lambda1s), as the paper's Eq. (19) has it.  Its
    self-terms are not the paper's tie (F nu_lambda gives lambda1c the opposite of
    q*'s coefficient), and the mean row gains the mean normal velocity (muz,
    theta0, beta0.): the Eq. 14 truth lies outside the Glauert form.  (The
    combinations hold to 0.01 %: the trim flap adds products of its own.)"""
    d = eq14_coupling(RotorSpec(constants=PUMA.with_mu(0.10)))
    a, b = d["A"], d["B"]
    col, inp = STATES.index, INPUTS_AZ.index
    k_q = b[1, inp("qbar")]
    for v in (b[1, inp("theta1c")], -a[1, col("beta1s")], -a[1, col("beta1c_prime")]):
        assert v == pytest.approx(k_q, rel=1e-3)
    k_p = b[2, inp("pbar")]
    for v in (b[2, inp("theta1s")], a[2, col("beta1c")], -a[2, col("beta1s_prime")]):
        assert v == pytest.approx(k_p, rel=1e-3)
    assert abs(k_q) > 0.1 and abs(k_p) > 0.1
    # outside the Glauert form: the self-term is not -k_q, the mean row moves with
    # the mean normal velocity
    assert abs(a[1, col("lambda1c")] + k_q) > 0.5 * abs(k_q)
    assert abs(b[0, inp("muz")]) > 0.1 and abs(b[0, inp("theta0")]) > 0.1
    assert b[0, inp("theta0")] == pytest.approx(-a[0, col("beta0_prime")], rel=1e-3)


def test_the_eq14_structure_is_the_eq14_truth_at_the_truths_trim_inflow(monkeypatch):
    """At mu 0.35 the Eq. (14) truth's averaged linearisation is
    ``...+advance-ratio-perturbation+momentum-speed`` at the truth's values and
    trim, every entry of A and B to 2e-6 of its row, once the effects linearise
    about the truth's own trim inflow (its periodic solution's mean); with their
    own (the basic model's for advance-ratio-perturbation, Eq. 14's by Newton for
    momentum-speed) the rows differ by the trim inflow's share only, under 1 %
    (measured 0.64 %, the lambda1c row's mux column): the structure misses no
    term of the averaged truth (``bench/amplitude.md``, "High mu")."""
    import inflowsim.model.effects.advance_ratio_perturbation as arp
    import inflowsim.model.effects.momentum_speed as mse
    from inflowsim.flighttest.nonlinear import trim_inputs
    from inflowsim.physics import momentum_speed as ms
    mu = 0.35
    spec = RotorSpec(constants=PUMA.with_mu(mu), speed="eq14")
    lin = linearise(spec)
    u0 = trim_inputs(mu)
    trim = dict(zip(("theta0", "theta1c", "theta1s"), u0[:3]),
                **dict(zip(("beta0", "beta1c", "beta1s"), lin.trim_beta)),
                muz=0.0, mux=mu, muy=0.0)
    k = spec.constants.with_trim(trim)
    p = {**truth_parameters(spec), "k_V": 1.0, "k_mu": 1.0}
    structure = BASE + "+advance-ratio-perturbation+momentum-speed"

    def worst():
        a, b = model_linearisation(build_model(structure, p, k))
        rows = np.maximum(np.max(np.abs(lin.A), axis=1), np.max(np.abs(lin.B), axis=1))
        return np.max(np.maximum(np.max(np.abs(lin.A - a), axis=1),
                                 np.max(np.abs(lin.B - b), axis=1))[3:] / rows[3:])

    own = worst()
    assert 1e-4 < own < 1e-2
    monkeypatch.setattr(arp, "true_trim", lambda kk, dpsi=0.0: (
        *arp.true_trim_state(kk, dpsi), lin.trim_lambda))
    monkeypatch.setattr(mse, "_coupling", lambda mu_, a0s, v, theta, beta, muz: (
        ms.speed_coupling(mu_, a0s, theta, beta, muz, lin.trim_lambda, v=v)))
    assert worst() < 2e-6
