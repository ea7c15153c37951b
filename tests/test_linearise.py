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



@pytest.mark.parametrize("mu", [0.10, 0.35])
def test_the_eq14_structure_is_the_eq14_truth_at_one_trim_inflow(mu, monkeypatch):
    """The Eq. (14) truth's averaged linearisation is
    ``...+advance-ratio-perturbation+momentum-speed`` at the truth's values and trim:
    every entry of A and B to 2e-6 of its row once the structure linearises about the
    truth's own trim inflow (its periodic solution's mean), so no term is missing.
    With its own, Eq. (14)'s by Newton, the flap rows hold to 3e-4 (measured 2.2e-4
    at mu 0.35) and the inflow rows to 1 % (6.4e-3, the lambda1c row's mux column at
    mu 0.35: Newton's cyclic trim inflow is not the periodic truth's mean).  Both effects
    take the same trim inflow: advance-ratio-perturbation took the basic model's,
    17 % high at mu 0.10, its mux, muy columns 6e-3 of the flap rows off
    (``bench/amplitude.md``, "High mu")."""
    import inflowsim.model.effects.momentum_speed as mse
    from inflowsim.flighttest.nonlinear import trim_inputs
    from inflowsim.physics import momentum_speed as ms
    # the truth on the effect's disc quadrature: its default 12 x 4 points move the
    # inflow rows by 5e-5 of a row at mu 0.10, a quadrature's, not a term's
    spec = RotorSpec(constants=PUMA.with_mu(mu), speed="eq14", n_disc_psi=ms.N_PSI,
                     n_disc_r=ms.N_R)
    lin = linearise(spec)
    u0 = trim_inputs(mu)
    trim = dict(zip(("theta0", "theta1c", "theta1s"), u0[:3]),
                **dict(zip(("beta0", "beta1c", "beta1s"), lin.trim_beta)),
                muz=0.0, mux=mu, muy=0.0)
    k = spec.constants.with_trim(trim)
    p = {**truth_parameters(spec), "k_V": 1.0, "k_mu": 1.0}
    structure = BASE + "+advance-ratio-perturbation+momentum-speed"

    def error():
        """Per row of (beta'', lambda'), the largest difference over its largest entry."""
        a, b = model_linearisation(build_model(structure, p, k))
        rows = np.maximum(np.max(np.abs(lin.A), axis=1), np.max(np.abs(lin.B), axis=1))
        return np.maximum(np.max(np.abs(lin.A - a), axis=1),
                          np.max(np.abs(lin.B - b), axis=1))[3:] / rows[3:]

    own = error()
    assert np.max(own[:3]) < 3e-4
    assert np.max(own[3:]) < 1e-2
    truth_lam = np.array(lin.trim_lambda).reshape(3, 1)
    mse._coupling.cache_clear()
    # the trims remembered were made with the effect's own trim inflow
    import inflowsim.model.effects.advance_ratio_perturbation as arp
    from inflowsim.model.recent import Recent
    monkeypatch.setattr(arp, "_TRIMS", Recent(arp._TRIMS.size))
    monkeypatch.setattr(mse, "_coupling", lambda mu_, a0s, v, theta, beta, muz: (
        *ms.speed_coupling(mu_, a0s, theta, beta, muz, truth_lam[:, 0], v=v), truth_lam))
    assert np.max(error()) < 2e-6


def test_a_key_that_cannot_be_hashed_is_made_and_not_remembered_also_when_empty():
    """Code generation asks with constants holding symbols: an unhashable key.  On an
    empty memo ``dict.pop`` returns its default without hashing the key, and storing
    it raised ``TypeError`` (the first advance-ratio code generation in a process)."""
    from inflowsim.model.recent import Recent
    memo, calls = Recent(2), []
    for _ in range(2):
        assert memo.get([1, 2], lambda: calls.append(1) or "made") == "made"
    assert len(calls) == 2 and memo._made == {}
    assert memo.get((1, 2), lambda: calls.append(1) or "kept") == "kept"
    assert memo.get((1, 2), lambda: "again") == "kept" and len(calls) == 3


def test_the_first_advance_ratio_code_generation_in_a_process_runs(tmp_path):
    """``inflowsim fmu build --model basic+advance-ratio-perturbation`` ended in that
    ``TypeError`` traceback when its trim memo was empty: a fresh process each time."""
    import os
    import subprocess
    import sys
    from pathlib import Path
    import inflowsim
    root = str(Path(inflowsim.__file__).resolve().parents[1])    # the tree under test
    code = ("import inflowsim\n"
            f"assert inflowsim.__file__.startswith({root!r})\n"
            "from inflowsim.fmu.codegen import traced\n"
            "from inflowsim.model.structure import Structure\n"
            "traced(Structure.parse('basic+advance-ratio-perturbation'))\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=tmp_path, env={**os.environ, "PYTHONPATH": root})
    assert res.returncode == 0, res.stderr[-2000:]
