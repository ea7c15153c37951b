"""Commands demo, model, simulate, validate: exit codes, one-line errors, JSON shapes."""
import json
import shutil
import subprocess

import numpy as np
import pytest

from conftest import assert_user_error, run
from inflowsim.cli import main
from inflowsim.model import build_model, descriptor
from inflowsim.model.params import PUMA
from inflowsim.model.presets import preset_parameters
from inflowsim.data.record import FLAP_COLUMNS, find_trim, read_record, write_record
from inflowsim.simulate.simulator import Simulator
from inflowsim.flighttest.virtual import VirtualTest, virtual_record


@pytest.fixture(scope="module")
def rec_path(tmp_path_factory):
    """A noise-free record of held inputs (``# hold: zoh``): the fixed-step
    simulator reproduces it exactly."""
    p = tmp_path_factory.mktemp("rec") / "doublet.csv"
    write_record(virtual_record(VirtualTest(noise_flap=0.0, hold="zoh")), p)
    return p


# -- model ------------------------------------------------------------------------
@pytest.mark.parametrize("structure", ["basic", "empirical", "glauert",
                                       "basic+time-delay"])
def test_model_json_matrices_are_the_descriptor(capsys, structure):
    code, out, _ = run(capsys, "model", "-m", structure, "--json")
    assert code == 0
    doc = json.loads(out)
    assert {"structure", "states", "inputs", "constants", "parameters", "E", "A",
            "B"} <= set(doc)
    e, a, b = descriptor(structure, preset_parameters(structure, PUMA, "paper"), PUMA)
    np.testing.assert_array_equal(np.array(doc["E"]), e)
    np.testing.assert_array_equal(np.array(doc["A"]), a)
    np.testing.assert_array_equal(np.array(doc["B"]), b)
    assert len(doc["inputs"]) == b.shape[1] and len(doc["states"]) == e.shape[0]
    assert doc["constants"]["mu"] == PUMA.mu


def test_model_mu_and_text(capsys):
    code, out, _ = run(capsys, "model", "-m", "glauert", "--mu", "0.3", "--json")
    doc = json.loads(out)
    k = PUMA.with_mu(0.3)
    _, a, _ = descriptor("glauert", preset_parameters("glauert", k, "paper"), k)
    np.testing.assert_array_equal(np.array(doc["A"]), a)
    assert doc["parameters"]["tau_cs"]["sigma"] == 0.89          # paper Table 3
    code, out, _ = run(capsys, "model", "-m", "glauert")
    assert code == 0
    assert "eigenvalues" in out and "tau_cs" in out and "lambda1s" in out


def test_model_json_is_a_parameter_file(capsys, tmp_path, rec_path):
    code, out, _ = run(capsys, "model", "-m", "empirical", "--json")
    p = tmp_path / "p.json"
    p.write_text(out)
    code, out2, _ = run(capsys, "model", "-m", "empirical", "--params", p, "--json")
    assert code == 0 and json.loads(out2)["A"] == json.loads(out)["A"]
    code, _, _ = run(capsys, "validate", rec_path, "-m", "empirical", "--params", p)
    assert code == 0


@pytest.mark.parametrize("argv, words", [
    (["model", "-m", "basic", "--mu", "0"], ["mu = 0"]),
    (["model", "-m", "basic", "--mu", "nan"], ["mu"]),
    (["model", "-m", "basic", "--mu", "abc"], ["--mu"]),
    (["model", "-m", "wobbly"], ["unknown model 'wobbly'"]),
    (["model", "-m", "basic+wobble"], ["unknown effect 'wobble'"]),
    (["model", "-m", "glauert+hub-velocity-coupling"], ["alternatives"]),
    (["model", "-m", "basic", "--params", "/nonexistent/p.json"], ["no such"]),
])
def test_model_user_errors(capsys, argv, words):
    try:
        code = main(argv)
    except SystemExit as exc:          # argparse errors (bad option values)
        code = exc.code
    out, err = capsys.readouterr()
    assert_user_error(code, out, err, *words)


def test_bad_params_files(capsys, tmp_path, rec_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    assert_user_error(*run(capsys, "validate", rec_path, "-m", "basic", "--params", bad),
                      "not valid JSON")
    wrong = tmp_path / "wrong.json"
    wrong.write_text(json.dumps({"structure": "basic", "parameters": {
        "lambda_beta2": 1.1, "n_beta": -1.0, "tau": 3.0}}))
    assert_user_error(*run(capsys, "simulate", rec_path, "-m", "basic", "--params", wrong,
                           "--out", tmp_path / "o.csv"), "n_beta")
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"structure": "basic", "parameters": {
        "lambda_beta2": 1.1, "n_beta": 1.0, "tau": 3.0}}))
    assert_user_error(*run(capsys, "validate", rec_path, "-m", "glauert", "--params",
                           other), "not glauert")


# -- simulate ---------------------------------------------------------------------
def test_simulate_writes_a_readable_record(capsys, tmp_path, rec_path):
    out = tmp_path / "sim.csv"
    code, text, _ = run(capsys, "simulate", rec_path, "-m", "glauert", "--out", out,
                        "--json")
    assert code == 0
    doc = json.loads(text)
    assert doc["samples"] == 2660 and doc["out"] == str(out)
    sim, rec = read_record(out), read_record(rec_path)
    assert "glauert" in sim.meta["description"] and sim.meta["omega"] == "27.5"
    assert sim.hold == "zoh"
    np.testing.assert_allclose(sim.t, rec.t)
    for c in ("theta1s", "q", "mux", "muy"):
        np.testing.assert_allclose(sim[c], rec[c], atol=1e-11)
    # noise-free record from the same model: the replay reproduces the flap
    for c in FLAP_COLUMNS:
        np.testing.assert_allclose(sim[c], rec[c], atol=1e-11)
    np.testing.assert_allclose(sim["lambda1c"], rec["lambda1c"], atol=1e-11)


def test_simulate_other_step_holds_inputs(capsys, tmp_path, rec_path):
    out = tmp_path / "fine.csv"
    assert run(capsys, "simulate", rec_path, "-m", "basic", "--dt", "0.0025",
               "--method", "rk4", "--out", out)[0] == 0
    sim, rec = read_record(out), read_record(rec_path)
    assert sim.dt == pytest.approx(0.0025)
    assert sim.t[-1] == pytest.approx(rec.t[-1])
    # held inputs: at every record sample time the value is the record's
    np.testing.assert_allclose(sim["theta1s"][::4], rec["theta1s"], atol=1e-11)
    # ZOH at the record's step and RK4 at a quarter of it agree at the shared times
    model = build_model("basic", preset_parameters("basic", rec.constants), rec.constants)
    trim = find_trim(rec)
    u = np.column_stack([rec[c] - trim.values[c] for c in model.inputs])
    y = Simulator(model, rec.dt).replay(u)
    np.testing.assert_allclose(sim["beta1s"][::4] - trim.values["beta1s"], y[:, 2],
                               atol=1e-4 * np.max(np.abs(y[:, 2])))


def test_simulate_never_overwrites(capsys, tmp_path, rec_path):
    before = rec_path.read_bytes()
    for extra in ([], ["--force"]):
        assert_user_error(*run(capsys, "simulate", rec_path, "-m", "basic", "--out",
                               rec_path, *extra), "input file")
    assert rec_path.read_bytes() == before
    out = tmp_path / "exists.csv"
    out.write_text("mine")
    assert_user_error(*run(capsys, "simulate", rec_path, "-m", "basic", "--out", out),
                      "--force")
    assert out.read_text() == "mine"
    assert run(capsys, "simulate", rec_path, "-m", "basic", "--out", out, "--force")[0] == 0
    assert read_record(out).meta["synthetic"] == "true"


@pytest.mark.parametrize("dt", ["0", "-0.01", "inf", "100"])
def test_simulate_bad_dt(capsys, tmp_path, rec_path, dt):
    assert_user_error(*run(capsys, "simulate", rec_path, "-m", "basic", "--dt", dt,
                           "--out", tmp_path / "x.csv"), "--dt")
    assert not (tmp_path / "x.csv").exists()


# -- validate ---------------------------------------------------------------------
def test_validate_json_and_report(capsys, tmp_path, rec_path):
    d = tmp_path / "report"
    code, out, err = run(capsys, "validate", rec_path, "-m", "glauert", "--json",
                         "--report", d)
    assert code == 0
    doc = json.loads(out)
    assert set(doc["channels"]) == set(FLAP_COLUMNS)
    for c in FLAP_COLUMNS:
        ch = doc["channels"][c]
        assert set(ch) >= {"rms", "tic", "fit_percent"}
        assert ch["fit_percent"] == pytest.approx(100.0, abs=1e-6)
    assert doc["band_hz"] == pytest.approx([6 / 26.6, 42 / 26.6])
    html = (d / "index.html").read_text()
    assert "glauert" in html and "time.png" in html and "frequency.png" in html
    for png in ("time.png", "frequency.png", "errors.png"):
        assert (d / png).read_bytes().startswith(b"\x89PNG")
    # text output and a band of one's own
    code, out, _ = run(capsys, "validate", rec_path, "-m", "basic", "--band", "0.3", "1.2")
    # the band never grows: 1.2 Hz snaps in to 31/26.6 = 1.165 Hz, not out to 1.203 Hz
    assert code == 0 and "beta1s" in out and "0.3008-1.165 Hz" in out


def test_validate_user_errors(capsys, tmp_path, rec_path):
    assert_user_error(*run(capsys, "validate", tmp_path / "none.csv", "-m", "basic"),
                      "no such file")
    rec = read_record(rec_path)
    lines = rec_path.read_text().splitlines()
    head = next(i for i, ln in enumerate(lines) if ln.startswith("t,"))
    cols = lines[head].split(",")
    j = cols.index("muy")
    nomuy = tmp_path / "nomuy.csv"
    nomuy.write_text("\n".join(lines[:head] + [",".join(
        v for k, v in enumerate(ln.split(",")) if k != j) for ln in lines[head:]]) + "\n")
    assert_user_error(*run(capsys, "validate", nomuy, "-m", "glauert"), "'muy'")
    nan = tmp_path / "nan.csv"
    body = lines[head + 5].split(",")
    body[cols.index("beta0")] = "nan"
    nan.write_text("\n".join(lines[:head + 5] + [",".join(body)] + lines[head + 6:]))
    assert_user_error(*run(capsys, "validate", nan, "-m", "basic"), "NaN")
    assert_user_error(*run(capsys, "validate", rec_path, "-m", "basic", "--band", "0.3",
                           "90"), "Nyquist")
    afile = tmp_path / "afile"
    afile.write_text("x")
    assert_user_error(*run(capsys, "validate", rec_path, "-m", "basic", "--report", afile),
                      "not a directory")
    assert afile.read_text() == "x" and len(rec) == 2660


# -- demo -------------------------------------------------------------------------
def test_demo_writes_report(capsys, tmp_path):
    """The demo finds the hidden glauert truth from basic and fits to the noise floor."""
    d = tmp_path / "demo"
    code, out, _ = run(capsys, "demo", "--out", d, "--json")
    assert code == 0
    doc = json.loads(out)
    assert doc["start"] == "basic" and doc["final"] == "glauert"
    assert set(doc["missing_effects_found"]) == {"glauert", "azimuth-bias",
                                                 "separate-time-constants"}
    costs = [r["cost"] for r in doc["ladder"]]
    assert costs == sorted(costs, reverse=True)           # the error falls rung by rung
    for c in FLAP_COLUMNS:
        assert doc["validation"]["final"][c]["rms"] < 1.3e-4     # noise is 1e-4 rad
        assert doc["validation"]["start"][c]["rms"] > doc["validation"]["final"][c]["rms"]
    assert (d / "index.html").exists() and (d / "ladder.png").exists()
    assert read_record(d / "record.csv").dt == 0.01
    _check_the_demo_report_agrees_with_itself((d / "index.html").read_text(), doc)


def _tables(page):
    """Each HTML table of the page as rows of cell texts (header row first)."""
    import html
    import re
    out = []
    for t in re.findall(r"<table>(.*?)</table>", page, flags=re.S):
        rows = [[html.unescape(re.sub(r"<[^>]+>", "", c)).strip()
                 for c in re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", tr, flags=re.S)]
                for tr in re.findall(r"<tr>(.*?)</tr>", t, flags=re.S)]
        out.append(rows)
    return out


def _check_the_demo_report_agrees_with_itself(page, doc):
    """Issue #28 item 5: one figure per quantity, findings in words that do not
    cancel or print empty ranges, angles in degrees, units everywhere, every
    section numbered."""
    import re
    # every section numbered
    heads = re.findall(r"<h2>(.*?)</h2>", page)
    assert heads and all(re.match(r"\d+(\.\d+)*\.? ", h) for h in heads), heads
    # the fit of the first and last structure: the same in the compare tables, the
    # ladder table and the JSON (validate and identify gave 31.47 and 31.62)
    tables = _tables(page)
    fits = [t for t in tables if t[0][:4] == ["channel", "rms error [deg]", "TIC [-]",
                                              "fit [%]"]]
    ladder = next(t for t in tables if t[0][0] == "quantity")
    assert len(fits) == 2
    for col, table, key in ((1, fits[0], "start"), (-1, fits[1], "final")):
        for row in table[1:]:
            lad = next(r for r in ladder if r[0] == f"{row[0]} fit [%]")
            assert row[3] == lad[col], (row, lad)
            rung = doc["ladder"][0 if col == 1 else -1]
            assert float(row[3]) == pytest.approx(rung["fit_percent"][row[0]], abs=0.006)
            assert doc["validation"][key][row[0]]["fit_percent"] == pytest.approx(
                rung["fit_percent"][row[0]], abs=1e-4)
    # where it fails: no signed mean rounded to -0 deg, no empty range
    assert "-0 deg" not in page and "+0 deg" not in page
    for a, b in re.findall(r"(\d[\d.]*)-(\d[\d.]*) Hz", page):
        assert a != b, f"{a}-{b} Hz"
    assert "deg rms" in page
    # angles in degrees, units on every quantity of the ladder table
    assert "[rad]" not in page
    for row in ladder[1:]:
        assert row[0] == "added" or re.search(r"\[[^\]]+\]", row[0]), row[0]
    assert "(1)" not in page


# -- the installed script -----------------------------------------------------------
@pytest.mark.skipif(shutil.which("inflowsim") is None, reason="script not installed")
def test_installed_script(tmp_path, rec_path):
    p = subprocess.run(["inflowsim", "validate", str(tmp_path / "missing.csv"), "-m",
                        "basic"], capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and p.stdout == ""
    assert len(p.stderr.strip().splitlines()) == 1 and "Traceback" not in p.stderr
    p = subprocess.run(["inflowsim", "validate", str(rec_path), "-m", "glauert",
                        "--json"], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0
    assert json.loads(p.stdout)["channels"]["beta1s"]["tic"] < 1e-9
