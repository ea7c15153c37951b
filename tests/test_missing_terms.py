"""Where the missing term lives (issue #24, item 1): the score map of single-entry
additions (:mod:`inflowsim.diagnose.terms`).

Truths with one matrix entry outside the catalogue, one per block of Eq. (1) (the
flap equation, the inflow equation, the measurement map), written as a test effect
through the public effect interface; the records are the basic model's plus that
entry, fitted with basic.  The map must rank the hidden entry first with the
right sign; on null records nothing is significant after Holm's correction; the
gradient matches central differences of the cost (12) and the statistic the
likelihood-ratio statistic of an actual refit with the entry free.  The study
over ten seeds per block is marked slow.
"""
from dataclasses import replace
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

import inflowsim as ifs
from conftest import TWO_AXES
from inflowsim.cli import main
from inflowsim.diagnose import diagnose
from inflowsim.diagnose.terms import MissingTerms, Term, missing_terms, physics_group
from inflowsim.flighttest.virtual import VirtualTest, virtual_record
from inflowsim.identify import identify
from inflowsim.identify.estimator import as_records, spectra_of, fit_state
from inflowsim.identify.problem import Problem
from inflowsim.model.effects import Effect, ParameterSpec
from inflowsim.model.effects.user import registered
from inflowsim.model.presets import theory_parameters
from inflowsim.report.terms import missing_terms_plot

NOISE = 1e-4
NAME = "hidden-entry"
#: block -> (equation, variable, how the truth adds it, value): each a term on the
#: right-hand side of the named equation
HIDDEN = {
    "flap": ("beta1s", "beta1c", ("d", 2, 1, -1.0), 0.05),
    "inflow": ("lambda0", "lambda1s", ("p_lambda", 0, 2, 1.0), 0.3),
    "measurement": ("beta1c", "beta0", ("flap_map", 1, 0, 1.0), 0.1),
    # the cyclic blade pitch follows the cyclic flap (theta1c += k beta1c, theta1s
    # += k beta1s): a term in every row the cyclic pitch enters (issue #36)
    "pitch": ("theta1", "beta1", ("pitch", None, None, None), -0.1),
}


def hidden_effect(block):
    """An effect adding ``k_hidden * variable`` to one equation of ``block``."""
    name, i, j, sign = HIDDEN[block][2]

    def equations(eq, p, k):
        if name == "flap_map":
            return eq
        if name == "pitch":
            # written out here, not with the map's own code: each cyclic's columns of
            # h_u (flap rows, right-hand side: d on the left) and p_u (inflow rows)
            d, pb = np.array(eq.d, dtype=float), np.array(eq.p_beta, dtype=float)
            hu, pu = np.asarray(eq.h_u, dtype=float), np.asarray(eq.p_u, dtype=float)
            for col in (1, 2):             # theta1c from beta1c, theta1s from beta1s
                d[:, col] -= p["k_hidden"] * hu[:, col]
                pb[:, col] += p["k_hidden"] * pu[:, col]
            return eq.with_(d=d, p_beta=pb)
        m = np.array(getattr(eq, name), dtype=float)
        m[i, j] += sign * p["k_hidden"]
        return eq.with_(**{name: m})

    def measurement(m, p, k):
        if name != "flap_map":
            return m
        fm = np.zeros((3, 6))
        fm[i, j] = p["k_hidden"]
        return m.with_(flap_map=fm)

    return Effect(name=NAME, physics="a test term outside the catalogue", paper="test",
                  parameters=("k_hidden",), theory=lambda k: {"k_hidden": 0.0},
                  equations=equations, measurement=measurement, offered=False,
                  specs=(ParameterSpec("k_hidden", "-", "coefficient of the hidden term",
                                       -10.0, 10.0, plausible=(-1.0, 1.0, "a test")),))


def truth_record(block, seed, value=None, hold="zoh"):
    """``(record, truth value)``: basic (tau = 5) plus the hidden term of ``block``
    (``block=None``: the null, basic alone); held inputs (fast to make) unless
    ``hold="continuous"``."""
    k = virtual_record(VirtualTest(duration=1.0)).constants
    if block is None:
        s = ifs.Structure.parse("basic")
        p = theory_parameters(s, k) | {"tau": 5.0}
        return virtual_record(VirtualTest(structure=s, parameters=p, seed=seed, dt=1 / 64,
                                          noise_flap=NOISE, manoeuvres=TWO_AXES,
                                          hold=hold)), 0.0
    v = HIDDEN[block][3] if value is None else value
    with registered(hidden_effect(block)):
        s = ifs.Structure.parse(f"basic+{NAME}")
        p = theory_parameters(s, k) | {"tau": 5.0, "k_hidden": v}
        rec = virtual_record(VirtualTest(structure=s, parameters=p, seed=seed, dt=1 / 64,
                                         noise_flap=NOISE, manoeuvres=TWO_AXES, hold=hold))
    return rec, v


@lru_cache(maxsize=None)
def mapped(block, seed, value=None, hold="zoh"):
    rec, v = truth_record(block, seed, value, hold)
    fit = identify(rec, "basic")
    return rec, fit, missing_terms(rec, fit)


def top_is_hidden(block, terms):
    eq, var = HIDDEN[block][:2]
    top = terms.terms[0]
    return (top.block, top.equation, top.variable) == (block, eq, var) and \
        top.sign == np.sign(HIDDEN[block][3])


@pytest.mark.parametrize("block", list(HIDDEN))
def test_the_map_ranks_the_hidden_entry_first(block):
    rec, fit, terms = mapped(block, 0)
    assert isinstance(terms, MissingTerms)
    assert top_is_hidden(block, terms), terms.rows[:3]
    assert terms.terms[0].significant()
    assert terms.rows[0]["equation"] == HIDDEN[block][0]
    assert set(terms.rows[0]) >= {"equation", "variable", "statistic", "p_value", "sign",
                                  "group"}
    # the map names it: significant and alone in its first group
    assert terms.determination == "determined" and terms.answer == terms.terms[0]
    assert terms.answer_json()["entry"]["variable"] == HIDDEN[block][1]
    # one entry takes up all there is: freeing the shared parameters per row group
    # adds nothing beside it, and the map is made at the base fit
    assert not terms.made_freed and terms.freed_gain < 7.82, terms.freed_gain


@pytest.mark.slow
@pytest.mark.parametrize("hold", ["zoh", "continuous"])
@pytest.mark.parametrize("block", list(HIDDEN))
def test_the_map_ranks_the_hidden_entry_first_over_ten_seeds(block, hold):
    hits = [top_is_hidden(block, mapped(block, seed, hold=hold)[2]) for seed in range(10)]
    assert sum(hits) >= 8, hits


def test_nothing_is_significant_on_a_null_record():
    rec, fit, terms = mapped(None, 0)
    assert terms.significant == (), terms.rows[:3]
    assert "no single added term is significant" in terms.describe()[0]
    # and it names none: not determined, in the text and the JSON
    assert terms.determination == "not-significant" and terms.answer is None
    assert "not determined" in terms.describe()[0]
    assert terms.answer_json()["entry"] is None
    # every excited entry is tested: theta0 is silent in these records, and the
    # coning stiffness is lambda_beta2 freed in the coning row (issue #36)
    untested = [t for t in terms.terms if not t.testable]
    assert {t.variable for t in untested if (t.block, t.equation, t.variable)
            != ("flap", "beta0", "beta0")} == {"theta0"}
    assert {n for n, *_ in terms.freed} == {"lambda_beta2", "n_beta", "tau"}
    assert terms.n_tested == len(terms.terms) - len(untested)


@pytest.mark.slow
def test_nothing_is_significant_on_null_records_over_ten_seeds():
    found = [len(mapped(None, seed)[2].significant) for seed in range(1, 11)]
    assert all(mapped(None, seed)[2].answer is None for seed in range(1, 11))
    # Holm holds the family-wise error at 1e-3: one false alarm in ten is already rare
    assert sum(found) == 0, found
    # and the statistics of the null are chi-square with one degree of freedom
    stats_all = np.concatenate([[t.statistic for t in mapped(None, s)[2].terms
                                 if t.testable] for s in range(1, 11)])
    assert 0.7 < stats_all.mean() < 1.3, stats_all.mean()


def _cost_at(rec, fit, block, k_value):
    """The cost (12) of basic + the hidden entry at ``k_value``, every parameter and
    ``S`` held at the base fit's (the end effects re-solved)."""
    with registered(hidden_effect(block)):
        s = ifs.Structure.parse(f"basic+{NAME}")
        spectra = spectra_of(as_records(rec), s, fit.band_hz, None, None)
        vals = dict(fit.parameters) | {"k_hidden": k_value}
        prob = Problem(s, spectra, vals, fixed=tuple(s.parameters))
        st = fit_state(prob, np.zeros(0), list(fit.S))
        return prob.cost(st.r, st.S)


@pytest.mark.parametrize("block", list(HIDDEN))
def test_the_gradient_is_the_cost_s_derivative(block):
    rec, fit, terms = mapped(block, 0)
    eq, var = HIDDEN[block][:2]
    # the gradient at the base fit itself (the map's default is made with the shared
    # parameters freed per row group)
    terms = missing_terms(rec, fit, free_shared=False, confirm=0)
    t = next(t for t in terms.terms if (t.block, t.equation, t.variable) == (block, eq, var))
    h = 1e-5
    fd = (_cost_at(rec, fit, block, h) - _cost_at(rec, fit, block, -h)) / (2 * h)
    assert t.gradient == pytest.approx(fd, rel=1e-4)
    # and the sign: the cost falls in the direction of the one-step estimate
    assert np.sign(fd) == -t.sign


def test_the_statistic_approaches_the_likelihood_ratio_of_a_refit():
    """A small hidden flap term: the refit with the entry free gives a
    likelihood-ratio statistic and an estimate close to the score statistic and the
    one-step estimate.  The score statistic is the smaller (its ``S`` is the base's,
    which holds the misfit; and it carries the bounds' degrees-of-freedom factor):
    the classical ``LM <= LR`` of a linear model."""
    rec, fit, _ = mapped("flap", 0, 0.002)
    terms = missing_terms(rec, fit, free_shared=False)
    eq, var = HIDDEN["flap"][:2]
    t = next(t for t in terms.terms if (t.block, t.equation, t.variable) ==
             ("flap", eq, var))
    with registered(hidden_effect("flap")):
        refit = identify(rec, f"basic+{NAME}", start=dict(fit.parameters) | {"k_hidden": 0})
        lr = 2.0 * (fit.cost - refit.cost)
        est = refit.parameters["k_hidden"]
    assert 3.0 < lr < 30.0, lr
    assert 0.75 * lr < t.statistic <= lr, (t.statistic, lr)
    assert t.coefficient == pytest.approx(est, rel=0.1)
    # the map's own confirming refit of that entry is that refit
    assert t.refit_statistic == pytest.approx(lr, rel=0.05, abs=0.5)
    assert t.refit_coefficient == pytest.approx(est, rel=0.02)


def test_groups_name_the_entry_not_a_cause():
    """Issue 36: servo dynamics were labelled "flap-rate coupling (lag or
    gyroscopic)"; a label says what the entry is."""
    assert physics_group("flap", "beta1s", "beta1c") == "cross-flap stiffness"
    assert physics_group("flap", "beta0", "beta0") == "flap stiffness"
    assert physics_group("flap", "beta0", "beta0_prime") == "flap damping"
    assert physics_group("flap", "beta1c", "beta1s_prime") == "cross flap-rate term"
    assert physics_group("inflow", "lambda1c", "q") == "hub-motion forcing of the inflow"
    assert physics_group("measurement", "beta1c", "beta1s") == "sensor cross-talk"
    assert physics_group("measurement", "beta0", "beta0") == "sensor gain"
    words = {physics_group(b, e, v) for b in ("flap", "inflow", "measurement")
             for e in ("beta0", "beta1c") for v in ("beta1s", "beta0_prime", "lambda1c",
                                                    "theta1c", "q", "mux")
             if not (b == "measurement" and v.endswith("_prime"))}
    assert not any(w in g for g in words for w in ("lag", "gyroscopic", "delta-3",
                                                   "Glauert", "wake skew", "azimuth"))


def test_the_map_is_a_frozen_picklable_table_and_draws(tmp_path):
    import pickle
    rec, fit, terms = mapped("flap", 0)
    again = pickle.loads(pickle.dumps(terms))
    assert again.rows == terms.rows
    with pytest.raises(AttributeError):
        terms.alpha = 0.5
    grid = terms.grid()
    # the variables, then the lagged entries' (a slow state each drives)
    assert terms.lagged and grid.shape == (9, len(terms.variables) + len(terms.lagged))
    i = terms.equations.index(("flap", "beta1s"))
    j = terms.columns.index(("beta1c", None))
    assert grid[i, j] == np.nanmax(grid)
    assert np.isfinite(grid[i, terms.columns.index(("beta1c", terms.lag))])
    fig = missing_terms_plot(terms, tmp_path / "map.png")
    assert (tmp_path / "map.png").stat().st_size > 1000
    assert fig.axes


def test_diagnose_carries_the_map_into_its_text_and_json(tmp_path, capsys, monkeypatch):
    import json
    import inflowsim.diagnose.search as search
    from inflowsim.data.record import write_record
    rec, _ = truth_record("flap", 0)
    path = write_record(rec, tmp_path / "r.csv")
    d = diagnose(rec, "basic", pool=["time-delay"])
    assert top_is_hidden("flap", d.missing_terms)
    # the command's rendering of that diagnosis (one diagnosis, two outputs)
    # the command imports diagnose when it runs (a fast start-up): patch its source
    monkeypatch.setattr(search, "diagnose", lambda *a, **k: d)
    assert main(["diagnose", str(path), "--model", "basic", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    top = doc["missing_terms"][0]
    assert (top["equation"], top["variable"], top["sign"]) == ("beta1s", "beta1c", 1)
    assert top["group"] == "cross-flap stiffness" and top["significant"]
    assert top["refit_statistic"] > top["statistic"] > 0
    assert 0 <= top["refit_p_adjusted"] < 1e-3
    answer = doc["missing_terms_answer"]
    assert answer["determination"] == "determined"
    assert (answer["entry"]["equation"], answer["entry"]["variable"]) == ("beta1s", "beta1c")
    assert main(["diagnose", str(path), "--model", "basic"]) == 0
    out = capsys.readouterr().out
    assert "the data want a term in the beta1s equation proportional to beta1c" in out
    assert "cross-flap stiffness" in out
    # and the report draws the map
    from inflowsim.report.ladder import diagnosis_report
    index = diagnosis_report(d).write(tmp_path / "rep")
    assert (tmp_path / "rep" / "diagnose-terms.png").stat().st_size > 1000
    assert 'src="diagnose-terms.png"' in Path(index).read_text()


def _term(variable, statistic, refit=None, first=False, p=1e-9):
    return Term("flap", "beta0", variable, statistic, p, p, 1, 0.1, "g",
                refit_statistic=refit, first_group=first,
                refit_p_adjusted=None if refit is None else p)


def test_the_map_names_an_entry_only_where_it_is_determined():
    """Issue 36: a tie (the record cannot tell the first entries apart) or no
    significant entry leaves the entry not determined; the text says so and names
    none; a refit's likelihood ratio counts as a test where the score falls short."""
    def table(*terms):
        return MissingTerms("basic", tuple(terms), 1e-3, 100, (), ())
    one = table(_term("p", 30, 60, True), _term("q", 25, 50))
    assert one.determination == "determined" and one.answer.variable == "p"
    tied = table(_term("p", 30, 60, True), _term("q", 29, 58, True))
    assert tied.determination == "tied" and tied.answer is None
    assert tied.answer_json()["first_group"][1]["variable"] == "q"
    # both in the beta0 equation: the equation is determined, the variable not
    assert tied.equation == ("flap", "beta0")
    assert tied.answer_json()["equation"] == {"block": "flap", "equation": "beta0"}
    assert "the equation is determined, the variable not" in " ".join(tied.describe())
    apart = table(_term("p", 30, 60, True),
                  replace(_term("q", 29, 58, True), block="measurement"))
    assert apart.equation is None and "which of them is not determined" in " ".join(
        apart.describe())
    none = table(_term("p", 3, 4, True, p=0.5), _term("q", 2, None, p=0.5))
    assert none.determination == "not-significant" and none.answer is None
    assert "not determined" in " ".join(none.describe())
    # significant by its refit alone (the score's local slope falls short)
    big = Term("flap", "beta0", "p", 5.0, 0.02, 1.0, 1, 0.1, "g", refit_statistic=80.0,
               refit_p_adjusted=1e-15, first_group=True)
    assert big.significant() and table(big).determination == "determined"


def test_the_map_refuses_another_band_than_the_fit_s():
    from inflowsim.errors import InputError
    rec, fit, _ = mapped(None, 0)
    with pytest.raises(InputError, match="band and hold the base fit was made with"):
        missing_terms(rec, fit, band_hz=(0.3, 1.2))


def test_the_map_by_groups_of_columns_equals_the_whole(monkeypatch):
    # a long record's sensitivities are made a few columns at a time (each pitch
    # entry with the columns it is made of): the same map as all columns at once,
    # to rounding (BLAS sums a column group's products in its own order)
    import inflowsim.diagnose.terms as terms
    rec, fit, _ = mapped("pitch", 0)
    # both without refits: which fit the map is made at (base or freed) rests on
    # the refits, and the chunks are compared, not that choice
    whole = missing_terms(rec, fit, confirm=0)
    rows = 6 * fit.data[0].f_hz.size
    monkeypatch.setattr(terms, "MAP_BYTES", 8 * rows * 5)
    inputs = whole.variables[len(terms.FLAP + terms.FLAP_RATE + terms.INFLOW):]
    entries = terms._entries(inputs, whole.lag)
    chunks = terms._column_chunks(entries, rows)
    assert len(chunks) > 10 and sorted(sum(chunks, [])) == list(range(len(whole.terms)))
    # a lagged entry with its constant one (its column is made from it)
    for c in chunks:
        assert all(entries.index(entries[e][:3] + (None,)) in c for e in c
                   if entries[e][3]), [entries[e] for e in c]
    parts = {t.key: t for t in missing_terms(rec, fit, confirm=0).terms}  # (refits: not chunked)
    for b in whole.terms:
        a = parts[b.key]
        assert a.testable == b.testable
        assert np.allclose([a.statistic, a.p_value, a.coefficient, a.gradient],
                           [b.statistic, b.p_value, b.coefficient, b.gradient],
                           rtol=1e-11, atol=0), b.key


@pytest.mark.parametrize("hold", ["zoh", "continuous"])
def test_a_lagged_entry_s_column_is_the_refit_model_s_derivative(hold):
    """A lagged entry (a slow state ``T w' + w = v`` with ``k w`` in the row): its
    column in the map is the derivative at ``k = 0`` of the very model its
    confirming refit fits (``_Augmented``: an appended state block at rest at the
    record's ends), weighted as the map weights; with continuous inputs and
    first-order flapping it is made as the constant entry's column times ``1 / (1 +
    j 2 pi f T)`` per bin, exactly (the held record's spectra taken as continuous:
    the same identity, another model of the same data)."""
    import inflowsim.diagnose.terms as terms
    from inflowsim.identify.problem import stack
    rec, fit, _ = mapped("flap", 0)
    s = fit.structure
    full = spectra_of(as_records(rec), s, fit.band_hz, None, None)
    if hold == "continuous":
        full = [replace(sp, hold="continuous") for sp in full]
    prob, theta, st, _, _ = terms._made_at(s, full, fit, (), s.n_inputs)
    if hold == "continuous":
        st = fit_state(prob, theta, list(fit.S))
    sp, W, nu = full[0], st.weights[0], st.nus[0]
    lag = terms.lag_time(fit.band_hz)
    assert lag == pytest.approx(1 / (2 * np.pi * fit.band_hz[0]))
    lagged = [("flap", 0, "lambda0", lag), ("inflow", 1, "beta1s", lag),
              ("measurement", 2, "beta0", lag), ("flap", 2, "beta1c_prime", lag)]
    entries = [e[:3] + (None,) for e in lagged] + lagged
    blk = np.empty((6 * sp.f_hz.size, len(entries)))
    terms._sensitivities(blk, entries, s, prob, theta, sp, W, nu, s.n_inputs)
    h = 1e-6
    for c, e in enumerate(lagged, start=len(lagged)):
        aug = terms._Augmented(s, [sp], prob.params(theta), prob.fixed, prob.ties_given,
                               (), e, s.n_inputs)
        (yp,), (ym,), (y0,) = aug._responses_many(
            [np.append(theta, x) for x in (h, -h, 0.0)])
        dy = ((yp[0] + yp[1] @ nu) - (ym[0] + ym[1] @ nu)) / (2 * h)
        ref = -stack(dy @ W.T)
        assert np.abs(blk[:, c] - ref).max() <= 1e-6 * np.abs(ref).max(), (hold, e)
        # at k = 0 the refit's model is the base's
        base = terms.model_from_equations(s, *prob.equations(theta, sp.constants),
                                          sp.constants, n_inputs=s.n_inputs)
        y_u, y_nu, _ = terms.flap_response(base, sp)
        np.testing.assert_allclose(y0[0], y_u, rtol=0, atol=1e-12 * np.abs(y_u).max())
        if hold == "continuous":
            # the constant entry's column over the lag, bin by bin
            const = blk[:, c - len(lagged)]
            n = const.size // 2
            z = (const[:n] + 1j * const[n:]).reshape(-1, 3)
            lz = z / (1 + 2j * np.pi * sp.f_hz * lag)[:, None]
            np.testing.assert_allclose(blk[:, c], np.concatenate([lz.real.ravel(),
                                                                  lz.imag.ravel()]))


def test_the_map_looks_for_slow_states_where_its_first_group_leaves_room():
    """Issue 36: a slow state driven by the inflow, absorbed by the base's inflow time
    constant, leaves stand-ins in the rows it acts in and its own lagged entry's score
    near zero.  Where a significant first group ties, or holds an entry in the inflow
    equation or on an inflow variable, the lagged inflow entries of every refitted
    entry's row are refitted (not the pitch's: it has none); not where one entry off
    the inflow stands alone, nor where nothing is significant."""
    from inflowsim.diagnose.terms import _looks_for_slow_states, _slow_rows
    inflow_row = replace(_term("theta1c", 30, 60, True), block="inflow", equation="lambda0")
    assert not _looks_for_slow_states([_term("p", 30, 60, True)], 1e-3)
    assert _looks_for_slow_states([_term("lambda1c", 30, 60, True)], 1e-3)
    assert _looks_for_slow_states([inflow_row], 1e-3)
    assert _looks_for_slow_states([_term("p", 30, 60, True), _term("q", 29, 58, True)],
                                  1e-3)
    assert not _looks_for_slow_states([_term("p", 3, 4, True, p=0.5),
                                       _term("q", 2, 3, True, p=0.5)], 1e-3)
    assert not _looks_for_slow_states([], 1e-3)
    pitch = Term("pitch", "theta1", "beta1", 30, 1e-9, 1e-9, 1, 0.1, "g")
    done = [_term("p", 30, 60, True), inflow_row, pitch, _term("lambda1c", 20, 40)]
    assert _slow_rows(done, 0.7) == tuple(
        (b, e, v, 0.7) for b, e in (("flap", "beta0"), ("inflow", "lambda0"))
        for v in ("lambda0", "lambda1c", "lambda1s"))
