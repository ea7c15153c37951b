"""``validate`` where the input has no power at some band frequencies (issue #28
item 5): a long record of repeated manoeuvres is periodic, so between its harmonics
the input's DFT is rounding (1e-18 of its peak) or exactly 0.  DFT ratios there were
noise over rounding: a 2-hour record printed a numpy RuntimeWarning and ``|H| [dB]
inf``; these repeated records printed 47 dB of error for the truth itself or were
refused.  The responses are now the conditioned ones of :mod:`inflowsim.identify.frf`
and the errors are taken where a response is read (coherence): still no warning, no
inf, no nan, small errors for the truth."""
import dataclasses
import warnings

import numpy as np
import pytest

from conftest import run, virtual
from inflowsim.data.record import FLAP_COLUMNS, Record, write_record
from inflowsim.diagnose.validation import validate
from inflowsim.identify.transform import dft
from inflowsim.model.build import build_model
from inflowsim.model.presets import preset_parameters
from inflowsim.report.frf_plots import phase_deg
from inflowsim.report.validation import NO_RESPONSE_TEXT, format_table


def _repeated(reps, seed=0):
    chunk = virtual(structure="glauert", duration=20.0, dt=1 / 64, noise_flap=0.0)
    n = len(chunk) * reps
    rng = np.random.default_rng(seed)
    cols = {k: np.tile(v, reps) + (1e-4 * rng.standard_normal(n) if k in FLAP_COLUMNS
                                   else 0.0)
            for k, v in chunk.channels.items()}
    meta = {k: v for k, v in chunk.meta.items() if not k.startswith("truth")}
    return Record.from_arrays(np.arange(n) / 64, cols, meta, source=f"<{reps} x 20 s>")


def _truth(rec):
    return build_model("glauert", preset_parameters("glauert", rec.constants, "paper"),
                       rec.constants)


@pytest.mark.parametrize("reps", [5, 6])      # 5: input DFT 1e-18 of peak; 6: exactly 0
def test_repeated_record_gives_finite_small_errors_without_warnings(reps):
    rec = _repeated(reps)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        v = validate(rec, _truth(rec))
        text = format_table(v)
    # the case of the issue: at some band transform frequencies the input has no
    # power (rounding or exactly 0), at others it has
    inp = v.frequency.inputs[0]
    u = rec.channels[inp] - rec.channels[inp][0]
    x = np.abs(dft(u[:, None], rec.dt, v.dft_f_hz, True)[:, 0])
    powered = x > 1e-9 * x.max()
    assert 0 < powered.sum() < powered.size
    # errors only where a response is read, and defined there
    valid = v.frequency.valid
    assert valid.any()
    assert np.all(np.isfinite(v.frequency.magnitude_error_db[valid]))
    assert np.all(np.isfinite(v.frequency.phase_error_deg[valid]))
    for c in FLAP_COLUMNS:
        # the truth with 1e-4 rad noise: small errors (before: 19-47 dB rms)
        assert v.magnitude_rms_db[c] < 1.0 and v.phase_rms_deg[c] < 5.0
    assert "inf" not in text and "nan" not in text


def test_no_defined_response_is_said_in_words():
    rec = _repeated(5)
    v = validate(rec, _truth(rec))
    nan = {c: float("nan") for c in FLAP_COLUMNS}
    text = format_table(dataclasses.replace(v, magnitude_rms_db=nan, phase_rms_deg=nan))
    assert "nan" not in text and NO_RESPONSE_TEXT in text


def test_ratio_helpers_never_warn_on_zeros():
    fc = validate(*(lambda r: (r, _truth(r)))(_repeated(5))).frequency
    bad = dataclasses.replace(fc, model=np.where(np.arange(fc.f_hz.size) == 3, 0.0,
                                                 fc.model))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mag, ph = bad.magnitude_error_db, bad.phase_error_deg
        unwrapped = phase_deg(np.array([1.0, np.nan, -1.0 + 1e-9j, -1.0 - 1e-9j]),
                              unwrap=True)
    assert np.all(np.isnan(mag[..., 3])) and np.all(np.isnan(ph[..., 3]))
    assert not np.isinf(mag).any()
    # unwrapping skips the undefined frequency instead of spreading NaN past it
    assert np.isnan(unwrapped[1]) and np.all(np.isfinite(unwrapped[[0, 2, 3]]))
    assert abs(unwrapped[3] - unwrapped[2]) < 1e-3


def test_validate_command_on_a_repeated_record_is_clean(tmp_path, capsys):
    path = tmp_path / "long.csv"
    write_record(_repeated(6), path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        code, out, err = run(capsys, "validate", path, "-m", "glauert")
    assert code == 0, err
    assert "Warning" not in err and "inf" not in out and "nan" not in out
