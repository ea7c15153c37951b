"""Models on top of measured frequency responses, Tischler's cost, CR% and
insensitivity% (issue #25 item 2)."""
import numpy as np
import pytest

from inflowsim.diagnose.responses import validation_responses
from inflowsim.diagnose.validation import validate
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
from inflowsim.identify import identify
from inflowsim.identify.accuracy import parameter_accuracy
from inflowsim.identify.frf import tischler_cost
from inflowsim.model.build import build_model
from inflowsim.model.presets import preset_parameters


@pytest.fixture(scope="module")
def rec():
    return virtual_record(VirtualTest(manoeuvres=(
        Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0)), seed=2))


@pytest.fixture(scope="module")
def fits(rec):
    return {s: identify(rec, s) for s in ("basic", "glauert")}


def test_the_truth_costs_little_and_the_basic_model_much(rec, fits):
    k = rec.constants
    truth = build_model("glauert", preset_parameters("glauert", k, "paper"), k)
    res = [validate(rec, truth), validate(rec, fits["basic"].model)]
    fr, models = validation_responses(res, ["truth", "basic"])
    assert fr.inputs == ("theta1c", "theta1s")
    assert models["truth"].shape == fr.h.shape
    j_truth = [tischler_cost(fr, models["truth"], o, i) for o in fr.outputs
               for i in fr.inputs]
    j_basic = [tischler_cost(fr, models["basic"], o, i) for o in fr.outputs
               for i in fr.inputs]
    assert max(j_truth) < 10
    assert np.mean(j_basic) > 5 * np.mean(j_truth) and max(j_basic) > 50


def test_cramer_rao_and_insensitivity_percent(fits):
    fit = fits["glauert"]
    acc = {a.name: a for a in parameter_accuracy(fit)}
    assert set(acc) == set(fit.free)
    for n, a in acc.items():
        if a.sigma is None:
            assert "not determined" in a.flags
            continue
        assert a.cr_percent == pytest.approx(100 * fit.sigma[n] / abs(fit.parameters[n]))
        # alone, a parameter is never less well determined than with the others
        assert a.insensitivity_percent <= a.cr_percent * (1 + 1e-9)
        assert ("CR > 20 %" in a.flags) == (a.cr_percent > 20)
    assert any(a.cr_percent and a.cr_percent < 5 for a in acc.values())


@pytest.mark.slow
def test_reports_show_the_models_on_the_responses(rec, fits, tmp_path):
    from inflowsim.diagnose.search import explicit_ladder
    from inflowsim.report.ladder import ladder_report
    from inflowsim.report.validation import validation_report
    res = [validate(rec, fits["basic"].model), validate(rec, fits["glauert"].model)]
    path = validation_report(res).write(tmp_path / "v")
    html = path.read_text()
    assert "frequency.png" in html and "Tischler" in html and "J glauert" in html
    assert (tmp_path / "v" / "frequency.png").stat().st_size > 1000
    lad = explicit_ladder([rec], ["basic", "glauert"])
    html = ladder_report(lad, record=rec).write(tmp_path / "l").read_text()
    assert "ladder-bode-theta1s.png" in html and "insensitivity" in html
    assert "J basic" in html and "J glauert" in html
