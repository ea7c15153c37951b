"""Every user error is exit 2 and one line, checked before long work; nothing
silently wrong (issue #11, items 2-5)."""
import json
import math
import os
import stat
import tempfile

import numpy as np
import pytest

from conftest import assert_user_error, run, virtual
from inflowsim.cli import main
from inflowsim.data.record import write_record
from inflowsim.errors import InputError
from inflowsim.fileio import json_text, safe_write_text
from inflowsim.model.build import build_model
from inflowsim.model.params import PUMA
from inflowsim.model.presets import preset_parameters
from inflowsim.simulate.simulator import Simulator


@pytest.fixture(scope="module")
def rec_path(tmp_path_factory):
    p = tmp_path_factory.mktemp("rec") / "doublet.csv"
    write_record(virtual(structure="glauert", duration=12.0), p)
    return p


def edit_record(src, dst, meta=None, cell=None, scale=None):
    """Copy record ``src`` to ``dst`` changing a metadata line, one cell
    ``(column, row, value)`` or a whole column ``(column, factor)``."""
    lines = open(src).read().splitlines()
    h = next(i for i, ln in enumerate(lines) if ln.startswith("t,"))
    header = lines[h].split(",")
    if meta:
        key, value = meta
        lines = [f"# {key}: {value}" if ln.startswith(f"# {key}:") else ln for ln in lines]
    if cell:
        col, row, value = cell
        r = lines[h + 1 + row].split(",")
        r[header.index(col)] = value
        lines[h + 1 + row] = ",".join(r)
    if scale:
        col, factor = scale
        j = header.index(col)
        for i in range(h + 1, len(lines)):
            r = lines[i].split(",")
            r[j] = repr(float(r[j]) * factor)
            lines[i] = ",".join(r)
    dst.write_text("\n".join(lines) + "\n")
    return dst


# -- output folders checked before the work ------------------------------------------
@pytest.fixture
def unwritable(tmp_path, monkeypatch):
    """A folder no file can be created in.  Permission bits do not bind root (CI runs
    as root), so there the folder refuses through a failing ``mkstemp``, which is what
    the check and every writer use."""
    d = tmp_path / "ro"
    d.mkdir()
    if os.geteuid() != 0:
        d.chmod(0o555)
    else:
        real = tempfile.mkstemp

        def mkstemp(*args, **kwargs):
            where = kwargs.get("dir", args[2] if len(args) > 2 else None)
            if where is not None and os.path.realpath(where).startswith(str(d)):
                raise PermissionError(13, "Permission denied", str(where))
            return real(*args, **kwargs)
        monkeypatch.setattr(tempfile, "mkstemp", mkstemp)
    yield d
    d.chmod(0o755)


@pytest.mark.parametrize("argv", [
    ("simulate", "{rec}", "-m", "glauert", "--out", "{ro}/x.csv"),
    ("identify", "{rec}", "-m", "glauert", "--out", "{ro}/p.json"),
    ("identify", "{rec}", "-m", "glauert", "--report", "{ro}/rep"),
    ("validate", "{rec}", "-m", "glauert", "--report", "{ro}/v"),
    ("bandstudy", "{rec}", "-m", "glauert", "--out", "{ro}/bs"),
    ("diagnose", "{rec}", "-m", "basic", "--report", "{ro}/d"),
    ("ladder", "{rec}", "-m", "basic", "--report", "{ro}/l"),
    ("flighttest", "--truth", "linear", "--duration", "5", "--out", "{ro}/r.csv"),
    ("fmu", "build", "--out", "{ro}/x.fmu"),
    ("demo", "--out", "{ro}/demo"),
], ids=lambda a: " ".join(a[:2]))
def test_unwritable_output_folder_is_refused_before_work(capsys, rec_path, unwritable,
                                                         argv):
    argv = [a.format(rec=rec_path, ro=unwritable) for a in argv]
    code, out, err = run(capsys, *argv)
    # one line and nothing before it: refused before any fit or simulation printed
    assert_user_error(code, out, err, "cannot write", str(unwritable))


@pytest.mark.parametrize("argv", [
    ("simulate", "{rec}", "-m", "glauert", "--out", "{f}/x.csv"),
    ("identify", "{rec}", "-m", "glauert", "--report", "{f}/rep"),
    ("bandstudy", "{rec}", "-m", "glauert", "--out", "{f}/bs"),
    ("fmu", "build", "--out", "{f}/x.fmu"),
], ids=lambda a: a[0])
def test_output_below_a_regular_file_is_refused(capsys, rec_path, tmp_path, argv):
    f = tmp_path / "afile"
    f.write_text("keep\n")
    code, out, err = run(capsys, *[a.format(rec=rec_path, f=f) for a in argv])
    assert_user_error(code, out, err, "does not exist")
    assert f.read_text() == "keep\n"


@pytest.mark.parametrize("argv", [("fmu", "build", "--force", "--out"),
                                  ("simulate", "{rec}", "-m", "glauert", "--force",
                                   "--out")], ids=lambda a: a[0])
def test_force_onto_a_folder_is_refused(capsys, rec_path, tmp_path, argv):
    d = tmp_path / "x.fmu"
    (d / "inside").mkdir(parents=True)
    code, out, err = run(capsys, *[a.format(rec=rec_path) for a in argv], d)
    assert_user_error(code, out, err, "is a folder")
    assert (d / "inside").is_dir()


def test_an_unforeseen_os_error_is_one_line(capsys, rec_path, tmp_path, monkeypatch):
    import inflowsim.data.record as mod      # simulate imports it when it runs

    def full(*a, **k):
        raise OSError(28, "No space left on device", str(tmp_path / "x.csv"))
    monkeypatch.setattr(mod, "write_record", full)
    code, out, err = run(capsys, "simulate", rec_path, "-m", "glauert", "--out",
                         tmp_path / "x.csv")
    assert_user_error(code, out, err, "No space left on device")


# -- parameter files with wrongly typed fields -----------------------------------------
@pytest.fixture(scope="module")
def param_doc(rec_path, tmp_path_factory):
    p = tmp_path_factory.mktemp("p") / "p.json"
    assert main(["identify", str(rec_path), "-m", "glauert", "--fix", "c2",
                 "--out", str(p)]) == 0
    return json.loads(p.read_text())


@pytest.mark.parametrize("path, value, words", [
    (("effects",), 5, ['"effects" must be a list']),
    (("effects",), [1], ['"effects" must be a list']),
    (("constants",), [1, 2], ["constants: must be an object"]),
    (("constants", "trim"), 5, ['"trim" must be an object']),
    (("constants", "omega"), "x", ["constants omega", "not a number"]),
    (("structure",), 7, ['"structure" must be a string']),
    (("parameters", "n_beta", "sigma"), "abc", ["n_beta sigma", "not a number"]),
    (("parameters", "n_beta", "sigma"), -1.0, ["n_beta sigma", ">= 0"]),
    (("parameters", "n_beta", "sigma"), [1], ["n_beta sigma", "not a number"]),
    (("parameters", "n_beta", "estimate"), "abc", ["n_beta", "not a number"]),
    (("parameters", "n_beta", "estimate"), None, ["n_beta", "not a number"]),
], ids=lambda v: str(v))
def test_wrongly_typed_parameter_file_fields(capsys, rec_path, tmp_path, param_doc,
                                             path, value, words):
    doc = json.loads(json.dumps(param_doc))
    node = doc
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(doc))
    for argv in (("validate", rec_path, "-m", "glauert", "-p", p),
                 ("simulate", rec_path, "-m", "glauert", "-p", p, "--out",
                  tmp_path / "s.csv")):
        code, out, err = run(capsys, *argv)
        assert_user_error(code, out, err, str(p), *words)
    assert not (tmp_path / "s.csv").exists()


# -- records: absurd values refused, implausible ones warned about ----------------------
@pytest.mark.parametrize("omega", ["1e-320", "1e308", "1e150", "0.1"])
@pytest.mark.parametrize("command", ["validate", "identify", "diagnose"])
def test_absurd_rotor_speed_is_refused(capsys, rec_path, tmp_path, omega, command):
    p = edit_record(rec_path, tmp_path / "om.csv", meta=("omega", omega))
    code, out, err = run(capsys, command, p, "-m", "glauert")
    assert_user_error(code, out, err, "omega", "allowed range")


def test_rotor_speed_in_rpm_draws_a_warning(capsys, rec_path, tmp_path):
    p = edit_record(rec_path, tmp_path / "rpm.csv", meta=("omega", "265"))
    code, out, err = run(capsys, "validate", p, "-m", "glauert")
    assert code == 0
    assert "warning" in err and "omega = 265 rad/s" in err and "rpm" in err
    assert "27.75 rad/s" in err


@pytest.mark.parametrize("column", ["beta1c", "theta1s", "q"])
@pytest.mark.parametrize("value", ["1e160", "-1e300", "2e6"])
@pytest.mark.parametrize("command", ["identify", "diagnose", "ladder", "bandstudy",
                                     "validate", "simulate"])
def test_one_absurd_cell_is_refused(capsys, rec_path, tmp_path, column, value, command):
    p = edit_record(rec_path, tmp_path / "big.csv", cell=(column, 200, value))
    extra = {"bandstudy": ["--out", tmp_path / "bs"],
             "simulate": ["--out", tmp_path / "s.csv"]}.get(command, [])
    code, out, err = run(capsys, command, p, "-m", "glauert", *extra)
    assert_user_error(code, out, err, f"column {column}", "data row 201",
                      "beyond any physical value")


def test_implausible_flap_draws_a_warning(capsys, rec_path, tmp_path):
    p = edit_record(rec_path, tmp_path / "deg.csv", scale=("beta0", 1e6))
    code, out, err = run(capsys, "validate", p, "-m", "glauert")
    assert code == 0
    assert "warning" in err and "beta0 reaches" in err


def test_degrees_instead_of_radians_draws_a_hint(capsys, rec_path, tmp_path):
    p = edit_record(rec_path, tmp_path / "deg.csv", scale=("theta1s", 180 / math.pi))
    run(capsys, "validate", p, "-m", "glauert")
    p = edit_record(rec_path, tmp_path / "deg.csv", scale=("theta0", 180 / math.pi))
    code, out, err = run(capsys, "validate", p, "-m", "glauert")
    assert "theta0 reaches" in err and "degrees instead of radians" in err


def test_repeated_metadata_key_is_refused(capsys, rec_path, tmp_path):
    lines = open(rec_path).read().splitlines()
    p = tmp_path / "dup.csv"
    p.write_text("\n".join(["# omega: 28"] + lines) + "\n")
    code, out, err = run(capsys, "validate", p, "-m", "glauert")
    assert_user_error(code, out, err, "'omega' given twice", "line")


@pytest.mark.parametrize("command", ["validate", "identify", "diagnose"])
def test_dead_flap_sensor_is_refused_even_with_json(capsys, rec_path, tmp_path, command):
    p = edit_record(rec_path, tmp_path / "dead.csv", scale=("beta1s", 0.0))
    code, out, err = run(capsys, command, p, "-m", "glauert", "--json")
    assert_user_error(code, out, err, "column beta1s is constant", "dead")


@pytest.mark.parametrize("argv", [
    ("flighttest", "--truth", "linear", "--duration", "5", "--seed", "-1", "--out"),
    ("flighttest", "--truth", "linear", "--duration", "5", "--seed", str(2 ** 40),
     "--out"),
    ("demo", "--seed", "-1", "--out")], ids=lambda a: " ".join(a[-3:-1]))
def test_seed_out_of_range(capsys, tmp_path, argv):
    out_path = tmp_path / ("r.csv" if argv[0] == "flighttest" else "demo")
    code, out, err = run(capsys, *argv, out_path)
    assert_user_error(code, out, err, "--seed")
    assert not out_path.exists()


# -- output -------------------------------------------------------------------------
def test_json_never_holds_bare_nan():
    doc = {"a": math.nan, "b": [1.0, math.inf, np.float64(-np.inf)],
           "c": np.array([np.nan, 2.0]), "d": {"e": np.int64(3)}, "f": np.bool_(True)}
    text = json_text(doc)
    assert "NaN" not in text and "Infinity" not in text
    back = json.loads(text)
    assert back == {"a": None, "b": [1.0, None, None], "c": [None, 2.0],
                    "d": {"e": 3}, "f": True}


def strict_json(text):
    def refuse(c):
        raise AssertionError(f"bare {c} in JSON output")
    return json.loads(text, parse_constant=refuse)


def test_undetermined_bound_is_null_in_json(capsys, rec_path, tmp_path):
    # the doublet in theta1s alone cannot determine c2: its bound is undefined
    code, out, _ = run(capsys, "identify", rec_path, "-m", "glauert", "--json",
                       "--out", tmp_path / "p.json")
    assert code == 0
    doc = strict_json(out)
    strict_json((tmp_path / "p.json").read_text())
    assert doc["parameters"]["c2"]["sigma"] is None


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_written_files_follow_the_umask(tmp_path, mask):
    old = os.umask(mask)
    try:
        p = safe_write_text(tmp_path / "x.txt", "x\n")
    finally:
        os.umask(old)
    assert stat.S_IMODE(p.stat().st_mode) == 0o666 & ~mask


def test_command_outputs_follow_the_umask(capsys, rec_path, tmp_path):
    old = os.umask(0o022)
    try:
        assert run(capsys, "simulate", rec_path, "-m", "glauert", "--out",
                   tmp_path / "s.csv")[0] == 0
        assert run(capsys, "validate", rec_path, "-m", "glauert", "--report",
                   tmp_path / "rep")[0] == 0
    finally:
        os.umask(old)
    files = [tmp_path / "s.csv", *(tmp_path / "rep").iterdir()]
    assert len(files) > 2
    for f in files:
        assert stat.S_IMODE(f.stat().st_mode) == 0o644, f


def test_the_demo_folder_is_ignored_by_the_checkout():
    from pathlib import Path
    from inflowsim.commands.demo import DEFAULT_DIR
    ignore = Path(__file__).resolve().parents[1] / ".gitignore"
    assert f"/{DEFAULT_DIR}/" in ignore.read_text().splitlines()


# -- the API: Simulator.step ---------------------------------------------------------
@pytest.fixture
def sim():
    k = PUMA
    return Simulator(build_model("glauert", preset_parameters("glauert", k, "paper"), k),
                     0.01)


@pytest.mark.parametrize("bad, words", [
    (None, ["got None"]), (0.1, ["shape ()"]), ([1.0, 2.0], ["shape (2,)"]),
    ("abc", ["got str"]), (np.zeros((1, 10)), ["shape (1, 10)"]),
    (np.array(["a"] * 10), ["10 numbers"]),
    ("nan", ["finite"]), ("inf", ["finite"]), ("list-nan", ["finite"]),
], ids=lambda v: repr(v)[:20])
def test_step_refuses_bad_inputs_and_keeps_its_state(sim, bad, words):
    u = np.zeros(sim.m)
    u[2] = 0.01
    sim.step(u)
    x, k = sim.state, sim.step_count
    if isinstance(bad, str) and bad in ("nan", "inf"):
        value = float(bad)
        bad = u.copy()
        bad[4] = value
    elif isinstance(bad, str) and bad == "list-nan":
        bad = [0.0] * sim.m
        bad[0] = math.nan
    with pytest.raises(InputError) as err:
        sim.step(bad)
    for w in words:
        assert w in str(err.value)
    np.testing.assert_array_equal(sim.state, x)
    assert sim.step_count == k
    y = sim.step(u)                       # and it goes on as if nothing happened
    assert np.all(np.isfinite(y))


def test_step_result_unchanged_by_the_checks(sim):
    u = np.zeros(sim.m)
    u[2] = 0.01
    ys = np.array([sim.step(u) for _ in range(50)])
    ref = np.array(sim.replay(np.tile(u, (51, 1)))[1:])
    np.testing.assert_allclose(ys, ref, rtol=0, atol=1e-15)
    sim.reset()
    np.testing.assert_array_equal(np.array([sim.step(list(u)) for _ in range(50)]), ys)


def test_an_internal_os_error_keeps_its_traceback(capsys, rec_path, tmp_path, monkeypatch):
    """A missing file of the program's own (not the user's) is a bug, not bad input:
    it is not reported as exit 2."""
    import inflowsim.data.record as mod      # simulate imports it when it runs

    def missing(*a, **k):
        raise FileNotFoundError(2, "No such file or directory", "/usr/lib/some.font")
    monkeypatch.setattr(mod, "write_record", missing)
    with pytest.raises(FileNotFoundError):
        main(["simulate", str(rec_path), "-m", "glauert", "--out", str(tmp_path / "x.csv")])
