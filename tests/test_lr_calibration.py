"""How a likelihood-ratio statistic against a fit with ``S`` estimated from the
record's own bins is read (``model.md`` section 7, "likelihood-ratio statistics"):
``2 (J_0 - J) / (kappa k)`` as ``F(k, d)``.

Default: against an independent route, a Monte Carlo of the concentrated
likelihood (``S`` re-estimated from the residuals to convergence) on a linear
complex three-channel regression of 24 bins, where chi-square says ``1e-2`` about
three times as often as it happens; and the tails themselves.  Slow: null records of
the virtual flight test (64 Hz, white noise), the atoms the diagnosis tries most
(``time-delay``, ``skewed-wake``), the calibrated p-values uniform in their tail.
"""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from inflowsim.diagnose.rule import lr_test
from inflowsim.diagnose.tails import chi2_sf, f_logsf, f_sf
from inflowsim.identify.estimator import lr_calibration_of, weight_dof


def _concentrated(Z, X, iters=10):
    """Per draw the concentrated cost ``n ln|S|`` (``S`` the residual's covariance at
    the weighted least-squares estimate, iterated to convergence)."""
    from test_bounds_finite_sample import relaxed_gls
    S = relaxed_gls(Z, X, iters)[2]
    return Z.shape[1] * np.log(np.real(np.linalg.det(S)))


def test_the_calibrated_statistic_is_uniform_where_chi_square_is_not():
    """24 bins, three correlated channels, one parameter tested beside another: the
    statistic's mean is ``kappa`` (1.14), chi-square passes ``alpha`` 1.3-1.7 times
    too often at 0.1-0.01, the calibrated reading never more often than ``alpha``
    beyond the binomial scatter (20 000 draws), and no less than 0.6 of it."""
    rng = np.random.default_rng(11)
    m, n, reps = 3, 24, 20000
    X = rng.normal(size=(n, m, 2)) + 1j * rng.normal(size=(n, m, 2))
    L = np.array([[1.0, 0, 0], [0.5, 1, 0], [0.2, -0.3, 0.6]])
    v = (rng.normal(size=(reps, n, m)) + 1j * rng.normal(size=(reps, n, m))) / np.sqrt(2)
    Z = (X[..., :1] @ np.array([0.7]))[None] + v @ L.T        # the second is null
    stat = 2 * (_concentrated(Z, X[..., :1]) - _concentrated(Z, X))
    kappa, d = lr_calibration_of([2 * m * n], [L @ L.T], 2)
    (nu, _), = weight_dof([2 * m * n], [L @ L.T], 2)
    assert kappa == pytest.approx(2 * m * n / (2 * m * n - 2) * (1 + m / nu))
    assert d == pytest.approx(2 * (nu - m + 1))
    assert stat.mean() == pytest.approx(kappa, rel=0.04)
    p_chi2 = chi2_sf(stat, 1)
    p_cal = f_sf(stat / kappa, 1, d)
    for a in (0.1, 0.05, 0.01):
        sd = math.sqrt(a * (1 - a) / reps)
        assert (p_chi2 < a).mean() > a + 4 * sd                 # chi-square: too often
        # F's tail is the heavier: here (a linear model) a little conservative,
        # never more often than said
        assert 0.6 * a < (p_cal < a).mean() < a + 4 * sd, (a, (p_cal < a).mean())


def test_lr_test_reads_chi_square_without_a_calibration_and_f_with_one():
    for stat, k, b in ((12.0, 1, 0), (12.0, 1, 1), (30.0, 3, 0), (30.0, 3, 2)):
        s, d, lp = lr_test(stat / 2, 0.0, k, b)
        if not b:
            assert lp == pytest.approx(math.log10(chi2_sf(stat, k)), rel=1e-12)
        s2, _, lp2 = lr_test(stat / 2, 0.0, k, b, (1.3, 60.0))
        assert s2 == s == stat and lp2 > lp          # never more significant
        if not b:
            assert lp2 == pytest.approx(math.log10(f_sf(stat / 1.3 / k, k, 60.0)),
                                        rel=1e-12)
    # d infinite: chi-square of the scaled statistic
    assert lr_test(6.0, 0.0, 1, 0, (1.2, math.inf))[2] == pytest.approx(
        math.log10(chi2_sf(10.0, 1)), rel=1e-12)


def test_f_log_tail_joins_its_asymptote_where_the_tail_underflows():
    """Below 1e-290 the incomplete beta's leading term: continuous across the switch
    and within 1e-4 of the exact tail where both are computed (1e-250 .. 1e-290)."""
    from scipy import special
    for k, d in ((1, 63.0), (3, 40.0), (2, 200.0)):
        for target in (-250, -280, -289):
            x = 1.0
            while math.log10(f_sf(x, k, d)) > target:
                x *= 1.05
            a, b = 0.5 * d, 0.5 * k
            z = d / (d + k * x)
            asym = a * math.log(z) + b * math.log1p(-z) - math.log(a) - special.betaln(a, b)
            assert asym == pytest.approx(math.log(f_sf(x, k, d)), rel=1e-4)
        assert math.isfinite(f_logsf(1e20, k, d)) and f_logsf(1e20, k, d) < -290 * math.log(10)


@pytest.mark.slow
@pytest.mark.parametrize("rotor", ["puma", "hingeless"])
def test_null_records_statistics_read_so_are_calibrated(rotor, monkeypatch):
    """Null records of the virtual flight test (``glauert`` truth, 64 Hz, held
    inputs, white noise; the detection study's generator), seeds 400-459: the
    statistics of ``time-delay`` and ``skewed-wake`` fitted beside the truth's
    structure, over ``kappa``, average about 1 (chi-square's mean; over 120 tests it
    scatters by about 0.15), and the calibrated p-values pass 0.1 about a tenth of
    the time (the study of 300 records, ``bench/rotor-physics.md``: 0.09-0.12 per
    atom and rotor).  A sanity check of the route, not of the factor's size: the
    linear Monte Carlo above tells the calibration from chi-square."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
    monkeypatch.setenv("INFLOWSIM_STUDY_ROTOR", rotor)
    from detection import record_for
    from inflowsim.identify import identify
    scaled, small = [], 0
    for seed in range(400, 460):
        rec, _ = record_for("null", "glauert", "zoh", 64, "white", seed)
        base = identify([rec], "glauert")
        for effect in ("time-delay", "skewed-wake"):
            fit = identify([rec], "glauert+" + effect, start=dict(base.parameters))
            stat, _, lp = lr_test(base.cost, fit.cost, 1, 0, fit.lr)
            scaled.append(stat / fit.lr[0])
            small += lp < -1
    assert 0.6 < np.mean(scaled) < 1.45, np.mean(scaled)
    assert 3 <= small <= 24, small


def test_the_rule_reads_calibrated_unless_asked_for_chi_square():
    """``Rule.calibrated`` chooses the reading; the default reads the fit's
    calibration (line 2's screen reads chi-square either way: ``tests/test_rule.py``),
    ``calibrated=False`` chi-square; a fit without one (a study's own ``fit_fn``) is
    read as chi-square."""
    from types import SimpleNamespace
    from inflowsim.diagnose.rule import DEFAULT_RULE, Rule, _lr
    fit = SimpleNamespace(lr=(1.2, 60.0))
    assert DEFAULT_RULE.calibrated and _lr(fit, DEFAULT_RULE) == (1.2, 60.0)
    assert _lr(fit, Rule(calibrated=False)) is None
    assert _lr(object(), DEFAULT_RULE) is None
