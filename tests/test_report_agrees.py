"""Reports that agree with themselves (issue #28 item 5), on small hand-made data:
the wording of where a model fails, units and angles in the ladder table, the band
study's layout.  The demo's own page is checked in test_cli's demo test."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from inflowsim.diagnose.failures import Failure
from inflowsim.report.fit_plots import band_study_plot, panel_grid
from inflowsim.report.ladder import failure_message, ladder_rows
from inflowsim.report.units import parameter_label, parameter_value


def _analysis(f_hz, z, y):
    """A residual analysis of beta1c only (the other channels match exactly)."""
    nf = len(f_hz)
    measured = np.ones((3, nf), complex)
    predicted = np.ones((3, nf), complex)
    measured[1], predicted[1] = z, y
    ratio = np.ones((3, nf))
    ratio[1] = np.abs(np.asarray(z) - np.asarray(y)) ** 2 / 1e-6
    return SimpleNamespace(f_hz=np.asarray(f_hz, float), measured=measured,
                           predicted=predicted, ratio=ratio)


def _spectrum_failure(ra, segments):
    return Failure("spectrum", "beta1c", "beta1c: the diagnosis's own message",
                   {"excess_power": float(ra.ratio[1].mean()), "segments": segments})


def test_phase_errors_of_both_signs_do_not_cancel():
    f = [0.3, 0.4, 0.5, 0.6]
    y = np.ones(4, complex)
    z = np.exp(1j * np.radians([10.0, -10.0, 10.0, -10.0]))    # signed mean: 0 deg
    ra = _analysis(f, z, y)
    seg = [{"f1_hz": 0.3, "f2_hz": 0.6, "mostly": "phase"}]
    text = failure_message(_spectrum_failure(ra, seg), [ra])
    assert "0.3-0.6 Hz (4 frequencies), mostly phase" in text
    assert "phase error 10.0 deg rms" in text and " 0.0 deg" not in text
    assert "magnitude error 0.00 dB rms" in text


def test_a_one_frequency_range_is_one_frequency():
    f = [0.2256, 0.3, 0.4]
    z = np.array([2.0, 1.0, 1.0], complex)
    ra = _analysis(f, z, np.ones(3, complex))
    seg = [{"f1_hz": 0.2256, "f2_hz": 0.2256, "mostly": "magnitude"}]
    text = failure_message(_spectrum_failure(ra, seg), [ra])
    assert "at 0.226 Hz, mostly magnitude" in text and "0.226-0.226" not in text
    assert f"magnitude error {20 * math.log10(2):.2f} dB rms" in text


def test_other_findings_and_unmatched_analyses_keep_their_message():
    ra = _analysis([0.3, 0.4, 0.5], np.ones(3) * 2.0, np.ones(3))
    fail = _spectrum_failure(ra, [{"f1_hz": 0.3, "f2_hz": 0.5, "mostly": "magnitude"}])
    assert failure_message(fail, []) == fail.message
    other = Failure("whiteness", "beta0", "beta0: structured")
    assert failure_message(other, [ra]) == "beta0: structured"


def _rung(params, sigma, cost, fits, added=None, ratios=None):
    fit = SimpleNamespace(parameters=params, sigma=sigma, fixed=(), cost=cost,
                          fit={c: {"fit_percent": v} for c, v in fits.items()},
                          S=(np.eye(3) * 1e-6,))
    ra = None if ratios is None else SimpleNamespace(ratio=np.array(ratios)[:, None]
                                                     * np.ones((3, 5)))
    return SimpleNamespace(structure=SimpleNamespace(name=added or "basic"), fit=fit,
                           added=added, analyses=() if ra is None else (ra,))


def test_ladder_table_in_degrees_with_units_and_the_plots_ratio():
    fits = {"beta0": 90.0, "beta1c": 95.0, "beta1s": 96.0}
    lad = SimpleNamespace(rungs=(
        _rung({"tau": 0.8}, {"tau": 0.1}, -100.0, fits, ratios=[9.0, 4.0, 2.0]),
        _rung({"tau": 0.8, "azimuth_bias": 0.4}, {"tau": 0.1, "azimuth_bias": 0.01},
              -150.0, fits, "azimuth-bias", ratios=[1.0, 1.1, 0.9])))
    header, rows = ladder_rows(lad)
    by = {r[0]: r[1:] for r in rows}
    assert by["azimuth_bias [deg]"][1] == f"{math.degrees(0.4):.4g} " \
                                          f"({math.degrees(0.01):.2g})"
    assert "tau [azimuth rad]" in by and "cost J (Eq. 12) [-]" in by
    assert by["beta0 residual power / noise floor [-]"] == ["9", "1"]
    assert all(r[0] == "added" or r[0].endswith("]") for r in rows)


def test_parameter_units():
    assert parameter_label("azimuth_bias") == "azimuth_bias [deg]"
    assert parameter_value("azimuth_bias", math.pi) == pytest.approx(180.0)
    assert parameter_label("c1") == "c1 [-]" and parameter_value("c1", 0.5) == 0.5
    assert parameter_label("delay") == "delay [s]"
    assert parameter_value("tau", None) is None


@pytest.mark.parametrize("n", range(1, 21))
def test_panel_grid_leaves_no_row_mostly_empty(n):
    rows, cols = panel_grid(n)
    assert rows * cols >= n and cols <= 5
    assert rows * cols - n < max(cols / 2, 1)      # the last row at least half full


def test_band_study_plot_of_three_parameters_has_no_empty_panel():
    study = SimpleNamespace(structure="basic", upper_hz=1.58,
                            lower_hz=np.array([0.1, 0.2, 0.3]),
                            estimates={"lambda_beta2": [1.0, 1.01, 1.02],
                                       "n_beta": [1.1, 1.1, 1.2],
                                       "azimuth_bias": [0.1, 0.2, 0.3]},
                            sigma={"lambda_beta2": [0.01] * 3, "n_beta": [0.01] * 3,
                                   "azimuth_bias": [0.01, None, 0.01]})
    fig = band_study_plot(study)
    axes = [a for a in fig.get_axes() if a.get_visible() and a.axison]
    assert len(fig.get_axes()) == len(axes) == 3
    for a in axes:
        assert a.get_xlabel() == "lower band limit [Hz]"
        assert a.get_ylabel().startswith("[") and a.get_ylabel().endswith("]")
    ab = next(a for a in axes if a.get_title().startswith("azimuth_bias"))
    assert ab.get_title() == "azimuth_bias [deg]" and ab.get_ylabel() == "[deg]"
    y = ab.get_lines()[0].get_ydata()
    np.testing.assert_allclose(y, np.degrees([0.1, 0.2, 0.3]))
