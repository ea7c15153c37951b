"""``inflowsim flighttest`` on the command line."""
import json

import numpy as np
import pytest

from inflowsim.cli import main
from inflowsim.data.record import find_trim, read_record


def test_writes_a_record_and_the_truth(tmp_path, capsys):
    out, tj = tmp_path / "ft.csv", tmp_path / "truth.json"
    rc = main(["flighttest", "--duration", "2", "--start", "1", "--seed", "3",
               "--azimuth-bias", "0.2",
               "--delay", "0.02", "--out", str(out), "--truth-json", str(tj)])
    assert rc == 0
    rec = read_record(out)
    assert len(rec) == 200 and rec.meta["seed"] == "3"
    truth = json.loads(tj.read_text())
    assert truth["truth"] == "nonlinear" and truth["rotor"]["n_blades"] == 4
    assert truth["measurement"] == {"azimuth_bias": 0.2, "delay": 0.02,
                                    "noise_flap": 1e-4, "noise_color_hz": None,
                                    "noise_inputs": 0.0, "seed": 3}
    assert truth["hold"] == "continuous"
    assert "azimuth" not in "".join(rec.meta.values())   # hidden from the record
    assert capsys.readouterr().out == ""                  # progress goes to stderr
    before = out.read_bytes()
    assert main(["flighttest", "--duration", "2", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "exists" in err and err.count("\n") == 1 and out.read_bytes() == before
    assert main(["flighttest", "--duration", "2", "--start", "1", "--seed", "4", "--out",
                 str(out), "--force"]) == 0
    assert out.read_bytes() != before


@pytest.mark.parametrize("argv, text", [
    (["--add", "glauert"], "--truth linear"),
    (["--model", "basic"], "--truth linear"),
    (["--set", "tau_cs"], "NAME=VALUE"),
    (["--set", "k01=1"], "takes lambda_beta2"),
    (["--truth", "linear", "--set", "k01=1"], "k01"),
    (["--truth", "linear", "--add", "nonsense"], "unknown effect"),
    (["--dt", "-1"], "dt"),
    (["--blades", "2"], "n_blades"),
    (["--truth", "linear", "--blades", "3"], "nonlinear only"),
])
def test_user_errors_exit_2_with_one_line(tmp_path, capsys, argv, text):
    out = tmp_path / "x.csv"
    assert main(["flighttest", "--duration", "1", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert text in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()


def test_linear_truth_with_added_effect(tmp_path, capsys):
    out = tmp_path / "lin.csv"
    rc = main(["flighttest", "--truth", "linear", "--model", "basic", "--add",
               "time-delay", "--set", "delay=0.05", "--input", "3211", "--duration", "4",
               "--out", str(out), "--json"])
    assert rc == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["structure"] == "basic+time-delay" and doc["parameters"]["delay"] == 0.05
    rec = read_record(out)
    d = rec["theta1s"] - find_trim(rec).values["theta1s"]
    assert np.isclose(d.max(), np.radians(1.0)) and rec.t[-1] == pytest.approx(3.99)


def test_linear_truth_added_effect_acts(tmp_path, capsys):
    """Issue 11: '--truth linear --add glauert' wrote a record whose Glauert terms
    were all zero (theory values are 'no effect'); the truth now takes the paper's
    estimates, and the record differs from the one without the effect."""
    outs = {}
    for add in ([], ["--add", "glauert"]):
        out = tmp_path / f"lin{len(add)}.csv"
        assert main(["flighttest", "--truth", "linear", "--model", "basic", *add,
                     "--duration", "8", "--noise", "0", "--out", str(out), "--json"]) == 0
        outs[len(add)] = (json.loads(capsys.readouterr().out), read_record(out))
    doc, rec = outs[2]
    from inflowsim.model.presets import paper_table
    assert doc["parameters"]["c3"] == paper_table(3)[1]["c3"] != 0
    assert doc["parameters"]["k0p"] == paper_table(3)[1]["k0p"]
    assert np.max(np.abs(rec["beta1s"] - outs[0][1]["beta1s"])) > 1e-4


def test_3211_body_motion_stays_bounded():
    """Issue 11: with a 3-2-1-1 the speed used to run away (mux 0.25 -> 0.8 in
    200 s): the body model now holds attitude, every mode is stable."""
    from inflowsim.flighttest.body import BodyModel
    from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
    a, _ = BodyModel().matrices()
    assert np.all(np.linalg.eigvals(a).real < 0)
    rec = virtual_record(VirtualTest(duration=200.0, dt=0.05, noise_flap=0.0,
                                     manoeuvres=(Manoeuvre(shape="3211"),), hold="zoh"))
    mux = rec["mux"] - 0.249
    assert np.max(np.abs(mux)) < 0.02 and np.max(np.abs(mux[rec.t > 150])) < 1e-3


@pytest.mark.parametrize("add", ["advance-ratio-perturbation", "lead-lag"])
def test_a_linear_truth_linearised_about_the_trim_flies(tmp_path, add):
    """Effects linearised about the trim take the virtual record's trim (they were
    refused for want of one when the truth's constants came from --mu)."""
    from inflowsim.cli import main
    from inflowsim.data.record import read_record
    out = tmp_path / "r.csv"
    assert main(["flighttest", "--truth", "linear", "--model", "basic", "--add", add,
                 "--duration", "6", "--out", str(out)]) == 0
    assert len(read_record(out)) == 600
