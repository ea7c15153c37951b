"""NASA laser-velocimeter inflow surveys (issue #25 item 4): the files as they are,
their defects found, Eq. (6) fitted, the model's trim inflow, the example.

The data ship with the package (``inflowsim/data/nasa_lv_inflow``, issue #39: a
clone has them; ``INFLOWSIM_NASA_DATA`` points elsewhere); tests that need them skip
with the reason when the folder is absent.  The reader's and the fit's logic are
also tested on tables the tests write.
"""
from __future__ import annotations

import csv
import hashlib
import math
import os
import pickle
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from inflowsim.data.nasa_lv import read_survey, read_surveys
from inflowsim.errors import InputError
from inflowsim.identify.inflow_survey import (area_mean_inflow, fit_first_harmonic,
                                              measured_inflow_response)
from inflowsim.model.steady_inflow import glauert_inflow, steady_inflow_predictions

ROOT = Path(__file__).resolve().parents[1]
from inflowsim.data.nasa_lv import DATA_DIR

DATA = Path(os.environ.get("INFLOWSIM_NASA_DATA") or DATA_DIR)
needs_data = pytest.mark.skipif(
    not DATA.is_dir(), reason=f"NASA LV inflow data not found at {DATA} (the package "
    "ships them in inflowsim/data/nasa_lv_inflow; INFLOWSIM_NASA_DATA overrides)")

#: The files as received (README table; measured with sha256sum).
SHA256 = {
    "mu_015.csv": "527ac816cc02f415a53f75b6259ee8e5a8b4b137e65c0fdf5c048caff6aad376",
    "mu_023.csv": "d065ac8ca294fa296fad7351e2c1462bedbb5e2269421cb77766f07e2887f9e4",
    "mu_35.csv": "8998778a9d2b8dd3248f3038d9ef297122588e443343103fd273ee65170b0912",
}
#: The README's known defects, written out here by hand (file line: value as read ->
#: value meant): the transcribed standard deviations and radial stations of mu_023.
STD_MEANT = {2: 0.0117, 5: 0.0099, 7: 0.0108, 11: 0.0091, 14: 0.0129}
STATION_MEANT = {33: 0.86, 34: 0.90}


@pytest.fixture(scope="module")
def surveys():
    return {s.file: s for s in read_surveys(DATA)}


# ---------------------------------------------------------------- the files -------

@needs_data
def test_files_are_the_ones_received():
    for name, digest in SHA256.items():
        assert hashlib.sha256((DATA / name).read_bytes()).hexdigest() == digest, name


@needs_data
def test_the_readme_defects_are_detected_and_repaired(surveys):
    s = surveys["mu_023.csv"]
    std = {d.lines[0]: d for d in s.defects_of("std-transcription")}
    assert set(std) == set(STD_MEANT)
    for line, meant in STD_MEANT.items():
        i = int(np.where(s.line == line)[0][0])
        assert s.sigma[i] == pytest.approx(meant) and "repaired" in std[line].action
    # four of the five have a psi = 360 twin, whose standard deviation is the repair
    assert sum("psi = 360 row of this station reads" in d.detail for d in std.values()) == 4
    st = {d.lines[0] for d in s.defects_of("radial-station")}
    assert st == set(STATION_MEANT)
    for line, meant in STATION_MEANT.items():
        i = int(np.where(s.line == line)[0][0])
        assert s.r[i] == pytest.approx(meant) and s.in_fit[i]
    dec = surveys["mu_35.csv"].defects_of("extra-decimals")
    assert [d.lines for d in dec] == [(121,)] and "-0.01011" in dec[0].detail
    # the repaired stds are not reported a second time as extra decimals
    assert not s.defects_of("extra-decimals")
    for sv in surveys.values():
        dup = sv.defects_of("duplicate-azimuth")
        assert len(dup) == 1 and "every station and mean equal" in dup[0].detail
        assert not sv.in_fit[np.isclose(sv.psi, 2 * np.pi)].any()
    assert surveys["mu_015.csv"].defects_of("extra-column")
    assert surveys["mu_015.csv"].n_samples is not None
    assert surveys["mu_023.csv"].n_samples is None


@needs_data
def test_other_defects_found_and_nothing_dropped_silently(surveys):
    s15 = surveys["mu_015.csv"]
    out = s15.defects_of("outside-disc")
    assert len(out) == 1 and len(out[0].lines) == int((s15.r > 1.0).sum()) == 33
    miss = s15.defects_of("missing-points")[0].detail
    assert "no radial cut at psi = 120, 270 deg" in miss
    assert "(30, 0.2)" in miss and "(330, 0.7)" in miss
    for sv in surveys.values():
        # every row left out of the fit is accounted for by a reported defect
        left_out = set(sv.line[~sv.in_fit].tolist())
        named = {x for d in sv.defects if d.kind in ("duplicate-azimuth", "outside-disc")
                 for x in d.lines}
        assert left_out <= named, sv.file
        assert not sv.defects_of("checksum")
    # the file rows are all there, in file order
    n_rows = sum(1 for _ in open(DATA / "mu_015.csv", newline="")) - 1
    assert len(s15.line) == n_rows and list(s15.line) == list(range(2, n_rows + 2))


@needs_data
def test_conditions_in_si_and_the_model_conventions(surveys):
    c = surveys["mu_015.csv"].conditions
    assert c.omega == pytest.approx(2113 * 2 * math.pi / 60)
    assert c.mu == pytest.approx(28.50 * math.cos(math.radians(3.0)) / (c.omega * 0.8606))
    assert c.muz < 0                       # shaft forward: the free stream passes down
    # the tables' A1, B1 become theta1c = -A1, theta1s = -B1 (less pitch advancing)
    assert c.theta1c == pytest.approx(math.radians(1.11))
    assert c.theta1s == pytest.approx(math.radians(-3.23))
    assert c.solidity == pytest.approx(4 * 0.06604 / (math.pi * 0.8606))
    k = c.constants(a0=5.73)
    assert (k.mu, k.ct, k.omega, k.trim["theta1s"]) == (c.mu, 0.0064, c.omega, c.theta1s)


# ------------------------------------------------------------ the fit -------------

def _independent_fit(path, weighted=True):
    """Eq. (6) by weighted least squares, written here from the CSV text: the
    README's repairs applied by hand, psi = 360 and r/R > 1 left out, lambda down
    positive, weights 1/std^2, normal equations solved directly."""
    rows = list(csv.reader(open(path, newline="")))[1:]
    x, y, w = [], [], []
    for line, row in enumerate(rows, start=2):
        psi, r, mean, std = (float(v) for v in row[:4])
        if path.name == "mu_023.csv":
            std = STD_MEANT.get(line, std)
            r = STATION_MEANT.get(line, r)
        if psi >= 360.0 or r > 1.0:
            continue
        p = math.radians(psi)
        x.append([1.0, r * math.cos(p), r * math.sin(p)])
        y.append(-mean)
        w.append(1.0 / std**2 if weighted else 1.0)
    x, y, w = np.array(x), np.array(y), np.array(w)
    a = x.T @ (w[:, None] * x)
    coef = np.linalg.solve(a, x.T @ (w * y))
    res = y - x @ coef
    s2 = np.sum(w * res**2) / (len(y) - 3)
    return coef, np.sqrt(np.diag(s2 * np.linalg.inv(a))), len(y)


@needs_data
@pytest.mark.parametrize("name", sorted(SHA256))
def test_fitted_harmonics_match_an_independent_least_squares(surveys, name):
    fit = fit_first_harmonic(surveys[name])
    coef, sig, n = _independent_fit(DATA / name)
    assert fit.n_points == n
    np.testing.assert_allclose(fit.estimate, coef, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fit.sigma_scatter, sig, rtol=1e-9)
    eq, _, _ = _independent_fit(DATA / name, weighted=False)
    np.testing.assert_allclose(fit.equal_weights, eq, rtol=1e-9, atol=1e-12)
    # residuals of these surveys are correlated between neighbouring stations: the
    # bounds are inflated, never below the plain ones
    assert not fit.white and fit.inflation > 1.5
    assert np.all(fit.sigma >= fit.sigma_scatter * fit.inflation * (1 - 1e-12))


@needs_data
def test_readme_first_look_is_reproduced(surveys):
    """The README's rough equal-weight numbers (two digits)."""
    l0 = [fit_first_harmonic(surveys[n]).equal_weights for n in sorted(SHA256)]
    np.testing.assert_allclose([v[0] for v in l0], [0.019, 0.0065, 0.0044], atol=6e-4)
    np.testing.assert_allclose([v[1] for v in l0], [0.031, 0.025, 0.017], atol=1e-3)


def _synthetic_survey(tmp_path, noise, seed=0, ar=0.0):
    """A table of Eq. (6) with known harmonics plus noise (AR(1) along r when
    ``ar``), in the files' format, beside a README with run conditions."""
    rng = np.random.default_rng(seed)
    truth = (0.02, 0.03, -0.004)
    stations = [0.2, 0.4, 0.5, 0.6, 0.7, 0.74, 0.78, 0.82, 0.86, 0.9, 0.94, 0.98]
    lines = ["psi,r/R,mean,std"]
    for psi in range(0, 361, 30):
        e = 0.0
        for r in stations:
            e = ar * e + math.sqrt(1 - ar**2) * rng.normal(0.0, noise)
            lam = (truth[0] + truth[1] * r * math.cos(math.radians(psi))
                   + truth[2] * r * math.sin(math.radians(psi)) + e)
            lines.append(f"{psi},{r},{-lam:.6f},{noise:.4f}")
    (tmp_path / "mu_023.csv").write_text("\r\n".join(lines) + "\r\n")
    (tmp_path / "README.md").write_text(_README)
    return truth


_README = """Four blades, radius 0.8606 m, chord 0.06604 m (rectangular), NACA 0012, linear twist of
-8 deg root to tip with zero twist at r/R = 0.75; 2113 rpm (tip speed about 190 m/s).

| case | mu | C_T | V (m/s) | alpha shaft (deg) | theta0 at 0.75R (deg) | theta1c (deg) | theta1s (deg) | mean lag (deg) |
| --- | --- | --- | --- | --- | --- | --- | --- | --- |
| 2 | 0.23 | 0.0064 | 43.86 | -3.04 | 8.16 | -1.52 | 4.13 | 0.90 |
"""


def test_fit_recovers_known_harmonics_with_white_noise(tmp_path):
    truth = _synthetic_survey(tmp_path, noise=0.002, seed=3)
    s = read_survey(tmp_path / "mu_023.csv")
    f = fit_first_harmonic(s)
    assert f.white and f.inflation < 1.5
    assert np.all(np.abs(f.estimate - truth) < 3 * f.sigma)
    assert f.chi2_reduced == pytest.approx(1.0, abs=0.35)


def test_correlated_residuals_are_found_and_inflate_the_bounds(tmp_path):
    truth = _synthetic_survey(tmp_path, noise=0.002, seed=4, ar=0.9)
    f = fit_first_harmonic(read_survey(tmp_path / "mu_023.csv"))
    assert not f.white and f.rho_radial > 0.5
    assert f.inflation > 2.0
    assert np.all(np.abs(f.estimate - truth) < 3 * f.sigma)


def test_reader_repairs_only_a_known_form_and_reports_the_rest(tmp_path):
    _synthetic_survey(tmp_path, noise=0.002)
    text = (tmp_path / "mu_023.csv").read_bytes().decode().split("\r\n")
    # line 3 (psi 0, r 0.4): a std of an unknown form; line 16 (psi 30, r 0.4): a
    # station off the grid with no known repair; line 4: a transcribed std
    text[2] = ",".join(text[2].split(",")[:3] + ["0.7500"])
    text[15] = ",".join(["30", "0.45"] + text[15].split(",")[2:])
    text[3] = ",".join(text[3].split(",")[:3] + ["0.20021"])
    (tmp_path / "mu_023.csv").write_text("\r\n".join(text))
    s = read_survey(tmp_path / "mu_023.csv")
    std = {d.lines[0]: d for d in s.defects_of("std-transcription")}
    assert set(std) == {3, 4}
    assert "left out of the fit" in std[3].action and not s.in_fit[s.line == 3].any()
    assert "repaired to 0.0021" in std[4].action
    st = s.defects_of("radial-station")
    assert [d.lines for d in st] == [(16,)] and "left out of the fit" in st[0].action
    assert not s.in_fit[s.line == 16].any()


def test_missing_or_malformed_input_is_one_line(tmp_path):
    with pytest.raises(InputError, match="no such data folder"):
        read_surveys(tmp_path / "absent")
    (tmp_path / "README.md").write_text("nothing here\n")
    with pytest.raises(InputError, match="no blade count"):
        read_surveys(tmp_path)


# ------------------------------------------------------- the model's inflow -------

def test_trim_inflow_theories_against_their_formulas():
    mu, muz, ct, t1c, t1s = 0.23, -0.0122, 0.0064, 0.0265, -0.0721
    p = {x.theory: x for x in steady_inflow_predictions(mu, muz, ct, t1c, t1s)}
    assert p["momentum"].harmonics == pytest.approx((ct / (2 * mu), 0.0, 0.0))
    lam = p["momentum-tilt"].lambda0
    assert lam == pytest.approx(ct / (2 * math.hypot(mu, lam - muz)), rel=1e-10)
    v = dict(p["momentum-mass-flow"].gains)["V"]
    assert p["momentum-mass-flow"].lambda0 == pytest.approx(ct / (2 * v))
    chi = math.atan2(mu, ct / (2 * mu) - muz)
    assert p["skewed-wake"].lambda1c / p["skewed-wake"].lambda0 == pytest.approx(
        15 * math.pi / 32 * math.tan(chi / 2))
    # Eq. (19) at steady state, written out: lambda = L c + F nu_lambda
    l0, l1c, l1s = p["glauert-table3"].harmonics
    kc, ks = 0.1629, -0.1901
    k0 = 0.0692 - 5.73 * 0.0917 / (8 * 0.249)
    assert l0 == pytest.approx(ct / (2 * mu) + ks * (t1s - l1s) + kc * (t1c - l1c))
    assert l1c == pytest.approx(k0 * (t1c - l1c))
    assert l1s == pytest.approx(k0 * (t1s - l1s))
    # the bound follows Table 3's: zero when its sigmas are
    _, sig = glauert_inflow(mu, ct, t1c, t1s, params={"kc": kc, "ks": ks, "k0p": 0.0692})
    assert not sig.any() and all(x > 0 for x in p["glauert-table3"].sigma)


@needs_data
def test_comparison_pickles_and_names_where_the_model_parts(surveys):
    cmp = measured_inflow_response(surveys.values())
    back = pickle.loads(pickle.dumps(cmp))
    np.testing.assert_array_equal(back.cases[0].fit.estimate, cmp.cases[0].fit.estimate)
    for c in cmp.cases:
        # momentum (diagonal L, no hub moments) has no fore-aft gradient: many sigmas
        assert c.discrepancy("momentum")[1] < -4
        # the skewed-wake gradient lies within 2 sigma of the measured one
        assert abs(c.discrepancy("skewed-wake")[1]) < 2
    assert area_mean_inflow(surveys["mu_35.csv"])[0] < 0.6 * cmp.cases[2].prediction(
        "momentum").lambda0


# ------------------------------------------------------------ the example ---------

def _example(*args):
    return subprocess.run([sys.executable, str(ROOT / "examples" / "nasa_inflow.py"),
                           *map(str, args)], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})


def test_example_missing_folder_is_one_line_exit_2(tmp_path):
    res = _example(tmp_path / "absent", "--out", tmp_path / "fig")
    assert res.returncode == 2
    assert len(res.stderr.strip().splitlines()) == 1 and "no such data folder" in res.stderr
    assert not (tmp_path / "fig").exists()


def test_the_data_ship_with_the_package_with_source_and_licence():
    """A clone has the surveys (issue #39): the package's copy, byte for byte the
    files as received, with where they come from and their licence."""
    for name, digest in SHA256.items():
        assert hashlib.sha256((DATA_DIR / name).read_bytes()).hexdigest() == digest
    readme = (DATA_DIR / "README.md").read_text(encoding="utf-8")
    assert "NASA Langley" in readme and "BladeAD" in readme
    assert "Permission is hereby granted" in (DATA_DIR / "LICENSE-BladeAD.txt").read_text()
    assert len(read_surveys()) == 3                    # the default folder


def test_example_writes_nowhere_in_the_repository_by_default():
    """examples/nasa_inflow.py's default output is a temporary folder, not docs/."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("nasa_inflow",
                                                  ROOT / "examples" / "nasa_inflow.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert ROOT.resolve() not in Path(mod.DEFAULT_OUT).resolve().parents
    assert Path(mod.DEFAULT_DATA) == DATA_DIR


@needs_data
def test_the_write_up_holds_the_codes_tables(surveys):
    """Every table of the comparison is in docs/measured-inflow.md as the code
    prints it: the write-up's numbers are the code's."""
    from inflowsim.report.measured_inflow import (comparison_table, conditions_table,
                                                  fit_table)
    cmp = measured_inflow_response(surveys.values())
    doc = (ROOT / "docs" / "measured-inflow.md").read_text(encoding="utf-8")
    for table in (conditions_table(cmp), comparison_table(cmp), fit_table(cmp)):
        assert table in doc, table.splitlines()[0]
    for f in ("nasa-radial-cuts.png", "nasa-harmonics.png", "nasa-disc.png"):
        assert f"figures/{f}" in doc
        assert 0 < (ROOT / "docs" / "figures" / f).stat().st_size < 150_000, f


@needs_data
@pytest.mark.slow
def test_example_writes_small_figures_and_prints_the_tables(tmp_path):
    res = _example(DATA, "--out", tmp_path)
    assert res.returncode == 0, res.stderr
    for f in ("nasa-radial-cuts.png", "nasa-harmonics.png", "nasa-disc.png"):
        assert 0 < (tmp_path / f).stat().st_size < 150_000, f
    doc = (ROOT / "docs" / "measured-inflow.md").read_text(encoding="utf-8")
    tables = re.findall(r"((?:^\|.*\|\n)+)", res.stdout, flags=re.M)
    assert len(tables) == 3
    for t in tables:
        assert t in doc, t.splitlines()[0]
    assert "std-transcription" in res.stdout and "radial-station" in res.stdout
