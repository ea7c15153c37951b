"""Speed work that must not move a number (issue #38): the distribution tails
without ``scipy.stats``, the airframe's long free response in blocks, the Jacobian
in runs of parameters, the streamed record reader."""
import numpy as np
import pytest
from scipy import stats

from conftest import TWO_AXES, virtual
from inflowsim.diagnose import tails


def test_the_tails_are_scipy_stats_bit_for_bit():
    x = np.concatenate([[0.0, -1.0, np.inf, np.nan, 1e-300], np.logspace(-8, 4, 400),
                        np.linspace(0.0, 300.0, 301)])
    for d in (1, 2, 3, 5, 12, 74, 0):
        assert np.array_equal(tails.chi2_sf(x, d), stats.chi2.sf(x, d), equal_nan=True)
        assert np.array_equal(tails.chi2_logsf(x, d), stats.chi2.logsf(x, d),
                              equal_nan=True)
        for d2 in (1, 10, 60, 0):
            assert np.array_equal(tails.f_sf(x, d, d2), stats.f.sf(x, d, d2), equal_nan=True)
    assert tails.chi2_logsf(3.0, 2) == stats.chi2.logsf(3.0, 2)
    assert np.ndim(tails.chi2_sf(3.0, 2)) == 0


def test_the_binomial_weights_are_scipy_stats_bit_for_bit():
    for n in range(1, 40):
        for k in range(n + 1):
            got, want = tails.binom_pmf(k, n, 0.5), stats.binom.pmf(k, n, 0.5)
            assert got == want and type(got) is type(want), (k, n)
    k = np.arange(7)
    assert np.array_equal(tails.binom_pmf(k, 6, 0.3), stats.binom.pmf(k, 6, 0.3))


def test_a_long_free_response_in_blocks(monkeypatch):
    from inflowsim.flighttest import body
    from inflowsim.flighttest.advice import standard_manoeuvres
    from inflowsim.model.params import PUMA
    fast = [c for _, c in standard_manoeuvres(20000, 1 / 64, PUMA)]
    monkeypatch.setattr(body, "FREE_BLOCK", 10 ** 9)          # step by step throughout
    slow = [c for _, c in standard_manoeuvres(20000, 1 / 64, PUMA)]
    for a, b in zip(fast, slow):
        for k in a:
            assert np.max(np.abs(a[k] - b[k])) <= 1e-13 * max(np.max(np.abs(b[k])), 1e-300)
    # a normal record's response is the step-by-step one exactly
    monkeypatch.undo()
    short = [c for _, c in standard_manoeuvres(2660, 0.01, PUMA)]
    monkeypatch.setattr(body, "FREE_BLOCK", 10 ** 9)
    same = [c for _, c in standard_manoeuvres(2660, 0.01, PUMA)]
    assert all(np.array_equal(a[k], b[k]) for a, b in zip(short, same) for k in a)


def test_the_jacobian_in_runs_of_parameters_is_the_same(monkeypatch):
    from inflowsim.identify import freqmodel, problem
    from inflowsim.identify.estimator import as_records, spectra_of, fit_state
    from inflowsim.model.presets import theory_parameters
    from inflowsim.model.structure import Structure
    rec = virtual(structure="glauert", seed=1, manoeuvres=TWO_AXES)
    s = Structure.parse("glauert+time-delay")
    sp = spectra_of(as_records(rec), s, (0.2256, 1.58), None)
    th = theory_parameters(s, sp[0].constants)
    out = []
    for limit in (freqmodel.DERIVATIVE_BYTES, 1):          # all at once; one at a time
        monkeypatch.setattr(freqmodel, "DERIVATIVE_BYTES", limit)
        prob = problem.Problem(s, sp, th)
        st = fit_state(prob, prob.theta0(), [np.eye(3)])
        out.append([prob.jacobian(prob.theta0(), st.weights, st.nus, st.bases, central=c)
                    for c in (True, False)])
    for a, b in zip(out[0], out[1]):
        for x, y in zip(a, b):
            # the same operations on smaller stacks (BLAS may block them otherwise)
            assert np.max(np.abs(x - y)) <= 1e-13 * np.max(np.abs(x))


def test_the_streamed_reader_reads_what_parse_record_reads(tmp_path):
    from inflowsim.data.record import parse_record, read_record, write_record
    p = tmp_path / "r.csv"
    write_record(virtual(structure="glauert", duration=6.0), p)
    a, b = read_record(p), parse_record(p.read_text(), str(p))
    assert a.order == b.order and dict(a.meta) == dict(b.meta) and a.source == b.source
    assert np.array_equal(a.t, b.t) and all(np.array_equal(a[c], b[c]) for c in a.order)
    # a bad row: the same one line as before, naming it
    text = p.read_text().splitlines()
    text[12] = text[12].replace(",", ",x", 1)
    p.write_text("\n".join(text) + "\n")
    from inflowsim.errors import RecordError
    with pytest.raises(RecordError, match="line 13: column"):
        read_record(p)
