"""Virtual flight test with the nonlinear blade truth (inflowsim.flighttest)."""
import numpy as np
import pytest

from inflowsim.flighttest.bladesim import RotorSpec
from inflowsim.simulate.discrete import zoh
from inflowsim.model.equations import assemble, rotation
from inflowsim.errors import InputError
from inflowsim.flighttest import FlightTest, blade_response, flighttest
from inflowsim.model import equations
from inflowsim.model.params import PUMA
from inflowsim.data.record import find_trim, read_record, write_record
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, pilot_controls, virtual_record

HUB0 = ("muz", "p", "q", "pdot", "qdot", "mux", "muy")


def _fixed_hub(n):
    return {c: np.zeros(n) for c in HUB0}


def _linear_replay(ctrl, dt, second_order):
    spec = RotorSpec()
    p = {"lambda_beta2": spec.lambda_beta2, "n_beta": spec.n_beta, "tau0": spec.tau0,
         "tau_cs": spec.tau_cs}
    _, _, eq, _ = equations("basic+separate-time-constants", p, PUMA)
    if second_order:
        eq = eq.with_(m2=np.eye(3))
    e, a, b = assemble(eq, second_order)
    om = PUMA.omega
    phi, gam = zoh(om * np.linalg.solve(e, a), om * np.linalg.solve(e, b)[:, :3], dt)
    x, y = np.zeros(len(a)), []
    for u in ctrl:
        y.append(x[:3].copy())
        x = phi @ x + gam @ u
    return np.array(y)


def test_small_amplitude_truth_agrees_with_the_linear_model_it_linearises_to():
    # hub fixed, V = mu: the truth linearises to basic + separate time constants
    # with the multiblade beta'' kept.  What the constant-coefficient model omits
    # (4/rev periodic coefficients of four blades, the blades' 2/rev and higher
    # harmonics) is measured here at 1-6 % of the peak response.
    test = FlightTest(rotor=RotorSpec(speed="mu"), body=None, noise_flap=0.0,
                      duration=6.0, manoeuvres=(Manoeuvre(amplitude=np.radians(0.1),
                                                          t_start=1.0),))
    t = np.arange(600) * test.dt
    ctrl = pilot_controls(t, test.manoeuvres)
    moved = blade_response(test, ctrl, _fixed_hub(600))["beta_meas"]
    still = blade_response(test, 0 * ctrl, _fixed_hub(600))["beta_meas"]
    pert = moved - still                      # the trim's 4/rev ripple cancels
    lin2 = _linear_replay(ctrl, test.dt, True)
    lin1 = _linear_replay(ctrl, test.dt, False)
    peak = np.abs(lin2).max(axis=0)
    err2 = np.abs(pert - lin2).max(axis=0) / peak
    err1 = np.abs(pert - lin1).max(axis=0) / peak
    assert np.all(err2 < [0.03, 0.06, 0.09])
    assert np.all(err1 > 3 * err2)            # the first-order model is further away


def test_small_amplitude_response_is_linear_in_the_amplitude():
    def pert(amp):
        test = FlightTest(body=None, noise_flap=0.0, duration=3.0,
                          manoeuvres=(Manoeuvre(amplitude=amp, t_start=0.5),))
        ctrl = pilot_controls(np.arange(300) * test.dt, test.manoeuvres)
        return (blade_response(test, ctrl, _fixed_hub(300))["beta_meas"]
                - blade_response(test, 0 * ctrl, _fixed_hub(300))["beta_meas"])
    a, b = pert(np.radians(0.05)), pert(np.radians(0.1))
    assert np.abs(b - 2 * a).max() < 1e-3 * np.abs(b).max()     # measured 8e-5
    # with the hub fixed only the Eq. (14) speed is nonlinear: measured 0.6 % at 4 deg
    big = pert(np.radians(4.0))
    assert 0.002 < np.abs(big - 80 * a).max() / np.abs(big).max() < 0.05


def test_record_is_seeded_has_totals_and_reads_back(tmp_path):
    test = FlightTest(duration=3.0, seed=5)
    a, b = flighttest(test), flighttest(test)
    np.testing.assert_array_equal(a.record["beta1c"], b.record["beta1c"])
    c = flighttest(FlightTest(duration=3.0, seed=6))
    assert not np.array_equal(a.record["beta1c"], c.record["beta1c"])
    noise = a.record["beta1s"] - flighttest(FlightTest(duration=3.0, noise_flap=0)).record[
        "beta1s"]
    assert np.std(noise) == pytest.approx(1e-4, rel=0.15)
    path = tmp_path / "ft.csv"
    write_record(a.record, path)
    rec = read_record(path)
    assert rec.constants.mu == PUMA.mu and rec.meta["synthetic"] == "true"
    assert rec.meta["seed"] == "5" and len(rec) == 300
    np.testing.assert_allclose(rec["beta1c"], a.record["beta1c"], rtol=1e-11, atol=1e-14)
    # totals: trim plus perturbations; the lead-in sits at the periodic trim
    trim = find_trim(rec)
    tr = a.truth["trim"]
    assert trim.values["theta0"] == pytest.approx(0.17)
    assert trim.values["mux"] == pytest.approx(PUMA.mu)
    for ch in ("beta0", "beta1c", "beta1s"):
        assert trim.values[ch] == pytest.approx(tr[ch], abs=tr["beta_ripple"][ch] + 1e-4)
    assert np.abs(rec["lambda0"][:150]).max() < 1e-4       # true inflow perturbation


def test_azimuth_bias_and_delay_are_measurement_only(tmp_path):
    base = FlightTest(duration=2.0, body=None, noise_flap=0.0, hold="zoh",
                      manoeuvres=(Manoeuvre(t_start=0.3, width=0.2, rise=0.0),))
    n = 200
    ctrl = pilot_controls(np.arange(n) * base.dt, base.manoeuvres)
    ref = blade_response(base, ctrl, _fixed_hub(n))
    biased = blade_response(FlightTest(**{**base.__dict__, "azimuth_bias": 0.3}),
                            ctrl, _fixed_hub(n))
    np.testing.assert_allclose(biased["beta_meas"][:, 1:],
                               ref["beta_meas"][:, 1:] @ rotation(0.3).T, atol=1e-14)
    # whole-sample delay: an exact shift; before the start, the periodic trim
    late = blade_response(FlightTest(**{**base.__dict__, "delay": 0.03}), ctrl,
                          _fixed_hub(n))
    # (to the O(h^4) difference of the pre-roll trim integrated with other steps)
    np.testing.assert_allclose(late["beta_meas"][3:], ref["beta_meas"][:-3], atol=1e-7)
    # fractional delay: cubic Hermite between sub-steps, against a run at dt/2
    half = FlightTest(**{**base.__dict__, "dt": 0.005, "duration": 2.0})
    ctrl2 = pilot_controls(np.arange(400) * 0.005, base.manoeuvres)
    fine = blade_response(half, ctrl2, _fixed_hub(400))["beta_meas"]
    frac = blade_response(FlightTest(**{**base.__dict__, "delay": 0.015}), ctrl,
                          _fixed_hub(n))["beta_meas"]
    np.testing.assert_allclose(frac[2:], fine[1::2][:n - 2], atol=1e-7)   # t_k - 0.015 s


def test_biased_record_rotates_recorded_pitch_not_the_pilot_input():
    rec = flighttest(FlightTest(duration=3.0, azimuth_bias=0.4,
                                manoeuvres=(Manoeuvre(t_start=1.0),))).record
    trim = find_trim(rec)
    expect = rotation(0.4) @ [0.01, -0.05]
    assert [trim.values["theta1c"], trim.values["theta1s"]] == pytest.approx(expect)
    d = rec["theta1s"] - trim.values["theta1s"]
    assert d.max() == pytest.approx(np.radians(1.0)) and np.ptp(rec["theta1c"]) < 1e-12


def test_linear_truth_delegates_to_the_virtual_record():
    vt = VirtualTest(structure="basic+time-delay", parameters=None, duration=3.0, seed=2)
    a = flighttest(vt)
    assert a.truth["truth"] == "linear" and a.truth["structure"] == "basic+time-delay"
    np.testing.assert_array_equal(a.record["beta1s"], virtual_record(vt)["beta1s"])


def test_bad_flight_tests_are_refused_with_one_line():
    for kw in ({"dt": 0.0}, {"duration": 0.01}, {"delay": -1.0},
               {"azimuth_bias": 4.0}, {"manoeuvres": (Manoeuvre(channel="p"),)},
               {"rotor": RotorSpec(n_blades=1)}):
        with pytest.raises(InputError) as exc:
            flighttest(FlightTest(**kw))
        assert "\n" not in str(exc.value)
