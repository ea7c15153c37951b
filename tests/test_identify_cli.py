"""``inflowsim identify`` and ``inflowsim bandstudy`` from the command line."""
import json

import numpy as np
import pytest

from inflowsim import build_model
from inflowsim.cli import main
from inflowsim.identify import band_study
from inflowsim.identify.tables import markdown_table
from inflowsim.report.fit import fit_report
from inflowsim.model.paramfile import read_parameters
from inflowsim.data.record import write_record
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record

TWO = (Manoeuvre("theta1s", "doublet", np.radians(1.0), 2.0, 0.4),
       Manoeuvre("theta1c", "doublet", np.radians(1.0), 8.0, 0.4))


@pytest.fixture(scope="module")
def rec_path(tmp_path_factory):
    p = tmp_path_factory.mktemp("rec") / "doublets.csv"
    write_record(virtual_record(VirtualTest(manoeuvres=TWO, seed=11)), p)
    return p


def test_json_shape_and_out_round_trip(rec_path, tmp_path, capsys):
    out = tmp_path / "fit.json"
    before = rec_path.read_bytes()
    assert main(["identify", str(rec_path), "--model", "glauert", "--json",
                 "--out", str(out), "--progress"]) == 0
    cap = capsys.readouterr()
    doc = json.loads(cap.out)
    assert {"structure", "effects", "band_hz", "cost", "parameters", "fit"} <= set(doc)
    assert doc["structure"] == "glauert"
    assert doc["band_hz"] == pytest.approx([6 / 26.6, 42 / 26.6])
    assert set(doc["parameters"]["tau_cs"]) >= {"estimate", "sigma"}
    assert "identify glauert" in cap.err          # progress (asked) on stderr only
    ps = read_parameters(out)
    m = build_model(ps.structure, ps.parameters, ps.constants)
    assert m.parameters["c3"] == pytest.approx(doc["parameters"]["c3"]["estimate"])
    assert rec_path.read_bytes() == before


def test_add_fix_tie_and_report(rec_path, tmp_path, capsys):
    rep = tmp_path / "rep"
    assert main(["identify", str(rec_path), "--model", "basic", "--add",
                 "separate-time-constants", "--fix", "n_beta=0.9", "--tie", "tau0=tau_cs",
                 "--report", str(rep), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    p = doc["parameters"]
    assert p["n_beta"]["estimate"] == 0.9 and p["n_beta"]["fixed"] is True
    assert p["tau0"]["estimate"] == p["tau_cs"]["estimate"]
    for name in ("index.html", "table.md", "fit.json", "fit_frequency.png", "fit_time.png"):
        assert (rep / name).stat().st_size > 0


@pytest.mark.parametrize("argv, needle", [
    (["--model", "glauert", "--add", "warp-drive"], "unknown effect"),
    (["--model", "glauert", "--band", "0.3", "80"], "Nyquist"),
    (["--model", "glauert", "--fix", "tau=3"], "not a parameter"),
    (["--model", "glauert", "--tie", "tau0"], "two or more"),
    (["--model", "glauert+hub-velocity-coupling"], "alternatives"),
])
def test_user_errors_exit_2_with_one_line(rec_path, argv, needle, capsys):
    assert main(["identify", str(rec_path), *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and len(err.splitlines()) == 1


def test_outputs_are_never_clobbered(rec_path, tmp_path, capsys):
    out = tmp_path / "exists.json"
    out.write_text("keep")
    assert main(["identify", str(rec_path), "--model", "basic", "--out", str(out)]) == 2
    assert out.read_text() == "keep"
    before = rec_path.read_bytes()
    assert main(["identify", str(rec_path), "--model", "basic", "--out", str(rec_path),
                 "--force"]) == 2
    assert rec_path.read_bytes() == before
    assert "refusing" in capsys.readouterr().err


def test_record_lacking_a_channel(tmp_path, capsys):
    rec = virtual_record(VirtualTest(manoeuvres=TWO))
    cols = {k: v for k, v in rec.channels.items() if k != "muy"}
    from inflowsim.data.record import Record
    p = tmp_path / "nomuy.csv"
    write_record(Record.from_arrays(rec.t, cols, rec.meta), p)
    assert main(["identify", str(p), "--model", "glauert"]) == 2
    assert "muy" in capsys.readouterr().err


def test_tables_name_every_parameter(rec_path, tmp_path):
    from inflowsim.identify import identify
    r = identify(rec_path, "empirical")
    md = markdown_table(r)
    page = fit_report(r).write(tmp_path / "rep").read_text()
    from inflowsim.report.units import parameter_label
    for n in r.parameters:          # the page names each with the unit it shows
        assert f"`{n}`" in md and f"<td>{parameter_label(n)}</td>" in page


def test_band_study_and_command(rec_path, tmp_path, capsys):
    basic = virtual_record(VirtualTest(structure="basic", manoeuvres=TWO, seed=12))
    st = band_study(basic, "basic", lowers_hz=[0.15, 0.2256, 0.4])
    assert st.lower_hz == pytest.approx([4 / 26.6, 6 / 26.6, 11 / 26.6])
    assert st.n_freq[0] > st.n_freq[-1] and all(st.converged)
    # right structure: more frequencies, tighter bounds
    assert st.sigma["tau"][0] < st.sigma["tau"][-1]
    out = tmp_path / "bs"
    assert main(["bandstudy", str(rec_path), "--model", "basic", "--lower", "0.2", "0.4",
                 "--out", str(out), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert len(doc["lower_hz"]) == 2 and set(doc["estimates"]) == {"lambda_beta2",
                                                                    "n_beta", "tau"}
    assert (out / "bandstudy.png").stat().st_size > 0
