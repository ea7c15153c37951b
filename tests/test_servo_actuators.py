"""Servo actuators (``servo-actuators``) and the appended-state core (``model.md`` 9).

Independent routes: the structure's frequency response equals the structure
without servos times the servo's own transfer function ``1/(T^2 s^2 + 2 zeta T s
+ 1)`` on the control columns (and nothing elsewhere); its steady state, loads
and end states are the servo-free model's; python-control's ``ss`` gives the same
poles as the descriptor."""
import numpy as np
import pytest

import inflowsim as ifs
from inflowsim.model.loads import load_matrices
from inflowsim.model.presets import truth_parameters

K = ifs.PUMA
F = np.array([0.05, 0.3, 1.0, 3.0, 8.0])


@pytest.mark.parametrize("base", ["basic", "glauert", "glauert+flap-inertia+azimuth-bias",
                                  "basic+advance-ratio-perturbation"])
@pytest.mark.parametrize("tau, zeta", [(0.02, 0.7), (0.045, 0.35), (0.01, 1.3)])
def test_the_servo_filters_each_control_and_nothing_else(base, tau, zeta):
    s0 = ifs.Structure.parse(base)
    s = s0.with_effect("servo-actuators")
    k = K.with_trim({"theta0": 0.17, "theta1c": 0.01, "theta1s": -0.05, "beta0": 0.06,
                     "beta1c": 0.01, "beta1s": -0.004, "muz": -0.02})
    p = truth_parameters(s, k) | {"servo_tau": tau, "servo_zeta": zeta}
    if "azimuth_bias" in p:
        p["azimuth_bias"] = 0.15
    m = ifs.build_model(s, p, k)
    m0 = ifs.build_model(s0, {n: p[n] for n in s0.parameters}, k)
    assert m.a.shape[0] == m0.a.shape[0] + 6
    sv = 2j * np.pi * F
    g = 1.0 / ((tau * sv) ** 2 + 2 * zeta * tau * sv + 1.0)
    h, h0 = m.frequency_response(F), m0.frequency_response(F)
    scale = np.abs(h0).max()
    np.testing.assert_allclose(h[:, :3], h0[:, :3] * g, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(h[:, 3:], h0[:, 3:], rtol=0, atol=1e-12 * scale)
    # steady state, loads and end states: the servo passes a constant command
    u = np.linspace(0.01, 0.02, m.b.shape[1])
    x = -np.linalg.solve(m.a, m.b @ u)
    x0 = -np.linalg.solve(m0.a, m0.b @ u)
    np.testing.assert_allclose(x[:6], x0[:6], rtol=0, atol=1e-12)
    np.testing.assert_allclose(x[-6:-3], u[:3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(load_matrices(m)(x, u), load_matrices(m0)(x0, u),
                               rtol=0, atol=1e-13)
    np.testing.assert_allclose(m.end_state(x0[:6], u), x, rtol=0, atol=1e-12)


def test_the_servo_states_and_poles():
    s = ifs.Structure.parse("glauert+servo-actuators")
    p = truth_parameters(s, K) | {"servo_tau": 0.025, "servo_zeta": 0.6}
    m = ifs.build_model(s, p, K)
    assert s.states[-6:] == ("theta0_a", "theta1c_a", "theta1s_a", "theta0_a_prime",
                             "theta1c_a_prime", "theta1s_a_prime")
    # the servo's own poles, three times: -zeta/T +- j sqrt(1 - zeta^2)/T
    want = (-0.6 + 1j * np.sqrt(1 - 0.36)) / 0.025
    ev = m.eigenvalues()
    assert np.sum(np.abs(ev - want) < 1e-6 * abs(want)) == 3
    sys = m.to_control()
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(sys.A)), np.sort_complex(ev),
                               rtol=1e-10)


def test_the_servo_tends_to_the_direct_structure_at_its_floor():
    from inflowsim.model.effects.servo_actuators import FLOOR
    s0 = ifs.Structure.parse("glauert")
    s = s0.with_effect("servo-actuators")
    p = truth_parameters(s, K) | {"servo_tau": FLOOR}
    h = ifs.build_model(s, p, K).frequency_response(F[:4])
    h0 = ifs.build_model(s0, {n: p[n] for n in s0.parameters}, K).frequency_response(F[:4])
    assert np.abs(h - h0).max() < 1e-4 * np.abs(h0).max()


# ---- identification and diagnosis on records written without the effect's code ----

from inflowsim.diagnose import diagnose, ladder  # noqa: E402
from servo_records import record as servo_record  # noqa: E402

ALSO = ("servo-actuators",)


def _pool():
    from inflowsim.diagnose.rule import offered_effects
    return offered_effects() + [e for e in ALSO if e not in offered_effects()]


def _check_named_and_explained(rec, truth, base, white=True):
    lad = ladder(rec, base, pool=_pool())
    first = lad.rungs[1].added if len(lad.rungs) > 1 else None
    assert first == "servo-actuators", [r.added for r in lad.rungs]
    assert lad.verdict.status == "explained", lad.verdict
    if white:
        # the floor is the white noise's level; under coloured noise the in-band noise
        # lies far above the floor measured above the band, and the verdict's own
        # measure (the input-correlated excess) is what says explained
        assert max(v for _, v in lad.verdict.remaining_excess) <= 1.5, lad.verdict
    fit = lad.rungs[-1].fit
    for name in ("servo_tau",):
        # the widest bound stated: where the record leaves servo_zeta to its neutral
        # value (a part not added), servo_tau's bound carries that held value's
        # uncertainty (sigma_total), for 2 zeta T is what the band sees
        info = lad.identifiability[name]
        sig = max(s for s in (fit.sigma[name], fit.sigma_robust.get(name),
                              info.sigma_total) if s is not None)
        est = fit.parameters[name]
        assert abs(est - truth[name]) < 3 * sig, (name, est, sig, truth[name])


def test_hidden_servos_are_named_with_the_truth_within_its_bound(tmp_path):
    rec, truth = servo_record(tmp_path / "r.csv", "basic", 0.025, 0.7, kind="two-axis",
                              seed=3)
    d = diagnose(rec, "basic", pool=_pool(), assess=False)   # the decision (no map)
    assert d.missing_effect == "servo-actuators", [(c.effect, c.reason) for c in d.candidates]
    est, sigma = d.candidates[0].added["servo_tau"]
    assert abs(est - truth["servo_tau"]) < 3 * sigma, (est, sigma)


@pytest.mark.slow
def test_hidden_servos_are_named_first_and_explain_the_record(tmp_path):
    rec, truth = servo_record(tmp_path / "r.csv", "basic", 0.025, 0.7, kind="two-axis",
                              seed=3)
    _check_named_and_explained(rec, truth, "basic")


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("kind, rate, colour_hz, base", [
    ("two-axis", 128, None, "basic"),
    ("theta1s", 64, None, "basic"),
    ("theta1c", 200, 3.0, "basic"),
    ("sweep", 128, None, "basic"),
    ("two-axis", 128, 3.0, "glauert"),
])
def test_hidden_servos_over_seeds_and_record_kinds(tmp_path, seed, kind, rate, colour_hz, base):
    tau, zeta = (0.02, 0.7) if seed % 2 else (0.03, 0.5)
    rec, truth = servo_record(tmp_path / "r.csv", base, tau, zeta, kind=kind, rate=rate,
                              colour_hz=colour_hz, seed=100 + seed)
    _check_named_and_explained(rec, truth, base, white=colour_hz is None)


@pytest.mark.slow
def test_no_alarm_with_servos_offered_on_a_record_without_them(tmp_path):
    from servo_records import record as rec_of
    rec, _ = rec_of(tmp_path / "r.csv", "basic", 1e-4, 0.7, kind="two-axis", seed=5)
    d = diagnose(rec, "basic", pool=_pool())
    assert d.missing_effect is None, [(c.effect, c.reason) for c in d.candidates]


def test_the_nonlinear_truths_servos_are_the_servo_transfer_function():
    """The blade truth's pitch behind servos (``FlightTest.servo``) against scipy's
    ``lsim`` of ``1/(T^2 s^2 + 2 zeta T s + 1)`` on a fine grid; the commanded
    (recorded) pitch is unchanged."""
    from scipy import signal
    from inflowsim.flighttest.nonlinear import FlightTest, true_controls
    from inflowsim.flighttest.virtual import Manoeuvre
    man = (Manoeuvre(channel="theta1s", shape="doublet", amplitude=np.radians(1.0),
                     t_start=1.0, width=0.4),
           Manoeuvre(channel="theta0", shape="doublet", amplitude=np.radians(0.5),
                     t_start=2.5, width=0.3))
    ft = FlightTest(duration=5.0, manoeuvres=man, servo=(0.03, 0.6))
    t = np.arange(0.0, 5.0, 2e-4)
    got = true_controls(ft)(t)
    cmd = true_controls(FlightTest(duration=5.0, manoeuvres=man))(t)
    sys = signal.lti([1.0], [0.03**2, 2 * 0.6 * 0.03, 1.0])
    for j in (0, 2):
        _, want, _ = signal.lsim(sys, cmd[:, j], t)
        assert np.abs(got[:, j] - want).max() < 2e-3 * np.abs(cmd[:, j]).max()
        assert np.abs(got[:, j] - cmd[:, j]).max() > 0.05 * np.abs(cmd[:, j]).max()
    with pytest.raises(ifs.InputError, match="hold continuous"):
        FlightTest(servo=(0.03, 0.6), hold="zoh").check()


@pytest.mark.slow
def test_the_worked_example_of_workflow_md(tmp_path, capsys):
    """``docs/workflow.md``, "A worked example": servos, then lag, then the floor."""
    from inflowsim.cli import main
    rec = str(tmp_path / "lagservo.csv")
    assert main(["flighttest", "--truth", "linear", "--model", "glauert", "--add",
                 "lead-lag", "--add", "servo-actuators", "--input", "3211", "--seed", "4",
                 "--out", rec]) == 0
    capsys.readouterr()
    assert main(["ladder", rec, "--model", "glauert", "--json"]) == 0
    import json
    doc = json.loads(capsys.readouterr().out)
    assert doc["verdict"]["status"] == "explained"
    assert doc["verdict"]["effects"] == ["servo-actuators", "lead-lag"]
    assert max(doc["verdict"]["remaining_excess"].values()) < 1.5
