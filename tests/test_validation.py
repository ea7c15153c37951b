"""Validation harness: fit figures, frequency comparison, errors."""
import numpy as np
import pytest

from inflowsim.errors import InputError, RecordError
from inflowsim.model import build_model
from inflowsim.model.params import PUMA
from inflowsim.model.presets import preset_parameters
from inflowsim.data.record import FLAP_COLUMNS, Record
from inflowsim.diagnose.validation import PAPER_BAND_HZ, dft_bins, fit_metrics, validate
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record


def _model(structure, rec=None, **changes):
    k = rec.constants if rec is not None else PUMA
    p = preset_parameters(structure, k, "paper")
    p.update(changes)
    return build_model(structure, p, k)


@pytest.fixture(scope="module")
def clean(noise_free_glauert):
    return noise_free_glauert


@pytest.mark.parametrize("structure, extra", [
    ("basic", {}), ("glauert", {}), ("empirical+time-delay", {"delay": 0.034})])
def test_perfect_model_on_noise_free_record(structure, extra):
    k = PUMA
    params = preset_parameters(structure, k, "paper")
    params.update(extra)
    man = (Manoeuvre("theta1s", "3211", np.radians(1.0), 2.0, 0.3),
           Manoeuvre("theta1c", "doublet", np.radians(0.5), 6.0, 0.4))
    rec = virtual_record(VirtualTest(structure=structure, parameters=params,
                                     manoeuvres=man, noise_flap=0.0, hold="zoh"))
    res = validate(rec, build_model(structure, params, rec.constants))
    assert res.hold == "zoh"
    for c in FLAP_COLUMNS:
        f = res.channels[c]
        assert f.rms < 1e-13
        assert f.tic < 1e-10
        assert f.fit_percent == pytest.approx(100.0, abs=1e-8)
    np.testing.assert_allclose(res.measured_dft, res.predicted_dft, rtol=0, atol=1e-12)
    # the responses are estimates from windows of transients (noise-free, so their
    # stated random error is near zero and says nothing): the model's analytic
    # responses, hold and hub path included, lie within a few percent of them (the
    # estimator itself is that far from the truth on these 26.6 s doublet records)
    fc = res.frequency
    fr, v = fc.measured, fc.valid
    assert fr.inputs == ("theta1c", "theta1s") and v.mean() > 0.4
    rel = np.abs(fr.h[v] / fc.model[v] - 1)
    assert np.median(rel) < 0.08 and np.quantile(rel, 0.9) < 0.25
    assert max(res.magnitude_rms_db.values()) < 1.5
    assert max(res.phase_rms_deg.values()) < 10.0


@pytest.mark.parametrize("structure, extra", [
    ("glauert", {}), ("empirical+time-delay", {"delay": -0.021}),
    ("basic+delay-theta1s", {"delay_theta1s": 0.017})])
def test_replay_of_a_continuous_record_converges(structure, extra):
    """A record of the truth integrated with smooth inputs (adaptive ODE solver):
    the local-cubic replay error falls like dt^4, and replaying it as a held
    record (the old convention) is wrong by far more."""
    params = preset_parameters(structure, PUMA, "paper") | extra
    err = {}
    for rate in (64, 256):
        rec = virtual_record(VirtualTest(structure=structure, parameters=params,
                                         noise_flap=0.0, dt=1 / rate, duration=8.0))
        m = build_model(structure, params, rec.constants)
        res = validate(rec, m)
        assert res.hold == "continuous"
        scale = np.max(np.abs(res.measured))
        # leads read past the record's end, where the inputs are continued flat
        sel = res.t < res.t[-1] - 0.1
        err[rate] = np.max(np.sqrt(np.mean((res.measured - res.predicted)[sel] ** 2,
                                           axis=0))) / scale
        held = validate(rec, m, hold="zoh")
        assert max(held.channels[c].rms for c in FLAP_COLUMNS) / scale > 30 * err[rate]
    assert err[256] < 1e-6 and err[256] < err[64] / 50


def test_fit_metrics_of_scaled_prediction():
    rng = np.random.default_rng(3)
    z = rng.standard_normal(500) + 0.3
    for a in (0.5, 0.9, 1.0, 1.7):
        f = fit_metrics(z, a * z)
        rms_z = np.sqrt(np.mean(z**2))
        assert f.rms == pytest.approx(abs(1 - a) * rms_z, rel=1e-12, abs=1e-15)
        assert f.tic == pytest.approx(abs(1 - a) / (1 + abs(a)), rel=1e-12, abs=1e-15)
        assert f.fit_percent == pytest.approx(
            100 * (1 - abs(1 - a) * np.linalg.norm(z) / np.linalg.norm(z - z.mean())),
            rel=1e-12)


def test_fit_metrics_hand_values():
    f = fit_metrics([1.0, -1.0, 1.0, -1.0], [0.0, 0.0, 0.0, 0.0])
    assert (f.rms, f.tic, f.fit_percent) == (1.0, 1.0, 0.0)
    f = fit_metrics([2.0, 0.0], [1.0, 1.0])        # e = (1, -1), ||z - mean|| = sqrt 2
    assert f.rms == 1.0
    assert f.tic == pytest.approx(1.0 / (1.0 + np.sqrt(2.0)))
    assert f.fit_percent == pytest.approx(100 * (1 - 1.0))
    g = fit_metrics([0.0, 0.0], [0.0, 0.0])
    assert np.isnan(g.tic) and np.isnan(g.fit_percent) and g.rms == 0.0


def test_noise_floor_and_wrong_model():
    rec = virtual_record(VirtualTest(noise_flap=1e-4, seed=4))
    good = validate(rec, _model("glauert", rec))
    bad = validate(rec, _model("basic", rec))
    for c in FLAP_COLUMNS:
        # the truth leaves only the sensor noise (and the noise in the trim estimate)
        assert good.channels[c].rms == pytest.approx(1e-4, rel=0.1)
        assert bad.channels[c].rms > 1.5 * good.channels[c].rms
        assert bad.channels[c].fit_percent < good.channels[c].fit_percent
    assert bad.phase_rms_deg["beta1s"] > 10 * good.phase_rms_deg["beta1s"]


def test_default_band_is_the_paper_grid(clean):
    bins = dft_bins(clean)
    assert (bins[0], bins[-1]) == (6, 42)
    res = validate(clean, _model("glauert", clean))
    assert res.band_hz == pytest.approx((6 / 26.6, 42 / 26.6))
    assert res.frequency.inputs == ("theta1s",)
    f = res.frequency.f_hz
    assert (f[0], f[-1]) == pytest.approx(res.band_hz)
    assert PAPER_BAND_HZ[0] <= res.band_hz[0] + 1e-3


def test_trim_is_reported(clean):
    res = validate(clean, _model("glauert", clean))
    doc = res.to_json()
    assert "before the first control movement" in doc["trim"]["description"]
    assert doc["hold"] == "continuous"
    assert doc["trim"]["values"]["theta1s"] == pytest.approx(-0.05)
    assert set(doc["channels"]["beta0"]) >= {"rms", "tic", "fit_percent"}
    # the input perturbations are about trim: zero before the doublet
    assert np.max(np.abs(res.u[res.t < 1.6])) < 1e-12


def test_explicit_inputs(clean):
    m = _model("glauert", clean)
    res = validate(clean, m, inputs=["theta1s", "muz"])
    assert res.frequency.inputs == ("theta1s", "muz")
    assert "muz" not in res.frequency.paths and "qdot" in res.frequency.paths
    assert res.frequency.model.shape == res.frequency.measured.h.shape == (
        3, 2, res.frequency.f_hz.size)
    with pytest.raises(InputError, match="input 'beta0'"):
        validate(clean, m, inputs=["beta0"])
    with pytest.raises(InputError, match="theta0 does not move"):
        validate(clean, m, inputs=["theta0"])


def test_missing_channel_named(clean):
    cols = {c: clean[c] for c in clean.order if c != "muy"}
    rec = Record.from_arrays(clean.t, cols, clean.meta, source="nomuy.csv")
    with pytest.raises(RecordError, match="'muy'"):
        validate(rec, _model("glauert", rec))
    validate(rec, _model("basic", rec))          # basic does not use muy


def test_band_beyond_record(clean):
    m = _model("glauert", clean)
    with pytest.raises(RecordError, match="Nyquist"):
        validate(clean, m, band_hz=(0.3, 60.0))
    with pytest.raises(RecordError, match="too short"):
        validate(clean, m, band_hz=(0.005, 0.05))
    with pytest.raises(InputError):
        validate(clean, m, band_hz=(1.0, 0.5))


from hypothesis import given, settings, strategies as st  # noqa: E402
from hypothesis.extra.numpy import arrays  # noqa: E402

_sig = arrays(np.float64, 16, elements=st.floats(-1e3, 1e3, allow_subnormal=False))


@settings(max_examples=60, deadline=None)
@given(_sig, _sig)
def test_fit_metric_bounds(z, y):
    f = fit_metrics(z, y)
    assert f.rms >= 0
    assert f.rms == pytest.approx(np.sqrt(np.mean((z - y) ** 2)))
    if np.any(z) or np.any(y):
        assert -1e-12 <= f.tic <= 1 + 1e-12          # triangle inequality
        assert f.tic == pytest.approx(fit_metrics(y, z).tic)
    if np.ptp(z) > 0:
        assert f.fit_percent <= 100.0 + 1e-9
        # predicting the mean of z scores exactly 0 %
        assert fit_metrics(z, np.full_like(z, z.mean())).fit_percent == pytest.approx(
            0.0, abs=1e-9)
