"""Clean edges (issue #28 items 1-4) and a start that imports only what it needs
(issue #27 item 2)."""
import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import assert_user_error, run, virtual
from inflowsim.cli import COMMANDS

ROOT = Path(__file__).resolve().parents[1]


# -- start-up: what --version and --help import ---------------------------------------
#: Modules the help and the version must not import (seconds of start-up between them).
HEAVY = ("numpy", "scipy", "scipy.stats", "matplotlib", "inflowsim.diagnose",
         "inflowsim.report", "inflowsim.identify", "inflowsim.model")

_PROBE = """
import json, sys
from inflowsim.cli import main
heavy = {heavy!r}
seen = {{}}
for argv in {argvs!r}:
    try:
        main(argv)
    except SystemExit:
        pass
    seen[" ".join(argv)] = [m for m in heavy if m in sys.modules]
sys.stderr.write(json.dumps(seen))
"""


def test_help_and_version_import_no_computing_module():
    """``inflowsim --version``, ``--help`` and each command's ``--help``, in one fresh
    interpreter (one after the other: a module one of them imports stays in
    ``sys.modules`` and is charged to it)."""
    argvs = [["--version"], ["--help"]] + [[c, "--help"] for c in COMMANDS]
    argvs.append(["fmu", "build", "--help"])
    code = _PROBE.format(heavy=HEAVY, argvs=argvs)
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, env={**os.environ,
                                        "PYTHONPATH": str(ROOT)}, timeout=60)
    assert res.returncode == 0, res.stderr
    seen = json.loads(res.stderr.strip().splitlines()[-1])
    assert set(seen) == {" ".join(a) for a in argvs}
    assert {a: m for a, m in seen.items() if m} == {}


def test_top_level_names_resolve_on_use():
    import inflowsim as ifs
    assert ifs.Structure.parse("glauert").name == "glauert"
    assert ifs.build_model("basic", ifs.preset_parameters("basic", ifs.PUMA, "paper"),
                           ifs.PUMA).structure.name == "basic"
    assert set(ifs.__all__) <= set(dir(ifs))
    with pytest.raises(AttributeError):
        ifs.no_such_name


# -- outputs replace a regular file only (issue #28 item 1) ---------------------------
@pytest.fixture(scope="module")
def rec_path(tmp_path_factory):
    from inflowsim.data.record import write_record
    p = tmp_path_factory.mktemp("rec") / "doublet.csv"
    write_record(virtual(structure="glauert", duration=12.0), p)
    return p


def _special(kind, tmp_path, name):
    """A path ``name`` in ``tmp_path`` that is not a regular file; never a real device
    written to: a link to ``/dev/null`` is only ever refused or replaced."""
    p = tmp_path / name
    if kind == "fifo":
        os.mkfifo(p)
    elif kind == "link-to-devnull":
        p.symlink_to("/dev/null")
    elif kind == "link-to-fifo":
        os.mkfifo(tmp_path / "pipe")
        p.symlink_to(tmp_path / "pipe")
    elif kind == "dangling-link":
        p.symlink_to(tmp_path / "nowhere" / "x")
    elif kind == "folder":
        (p / "inside").mkdir(parents=True)
    return p


def _unchanged(kind, p):
    if kind == "fifo":
        return stat.S_ISFIFO(os.lstat(p).st_mode)
    if kind == "folder":
        return (p / "inside").is_dir()
    return p.is_symlink()


FILE_OUTPUTS = {
    "simulate": ("simulate", "{rec}", "-m", "glauert", "--force", "--out", "{out}"),
    "identify": ("identify", "{rec}", "-m", "glauert", "--force", "--out", "{out}"),
    "flighttest": ("flighttest", "--force", "--out", "{out}"),
    "flighttest-truth": ("flighttest", "--force", "--out", "{tmp}/ok.csv",
                         "--truth-json", "{out}"),
    "fmu": ("fmu", "build", "--force", "--out", "{out}"),
}
KINDS = ("fifo", "link-to-devnull", "link-to-fifo", "dangling-link", "folder")


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("command", sorted(FILE_OUTPUTS))
def test_force_replaces_a_regular_file_only(capsys, rec_path, tmp_path, command, kind):
    out = _special(kind, tmp_path, "x.fmu" if command == "fmu" else "x.out")
    argv = [a.format(rec=rec_path, out=out, tmp=tmp_path) for a in FILE_OUTPUTS[command]]
    code, stdout, err = run(capsys, *argv)
    words = {"folder": "is a folder", "dangling-link": "symbolic link to nothing"}
    assert_user_error(code, stdout, err, str(out), words.get(kind, "regular file only"))
    assert _unchanged(kind, out)
    assert not (tmp_path / "ok.csv").exists()


FOLDER_OUTPUTS = {
    "demo": ("demo", "--out", "{dir}"),
    "validate": ("validate", "{rec}", "-m", "glauert", "--report", "{dir}"),
    "identify": ("identify", "{rec}", "-m", "glauert", "--report", "{dir}"),
    "diagnose": ("diagnose", "{rec}", "-m", "basic", "--report", "{dir}"),
    "ladder": ("ladder", "{rec}", "--report", "{dir}"),
    "bandstudy": ("bandstudy", "{rec}", "-m", "glauert", "--force", "--out", "{dir}"),
}


@pytest.mark.parametrize("command", sorted(FOLDER_OUTPUTS))
def test_report_folders_and_their_files_are_regular(capsys, rec_path, tmp_path, command):
    """A FIFO given as the folder, and a FIFO where an earlier report's
    ``index.html`` was (named in its manifest, so the report would replace it)."""
    from inflowsim.report.document import MANIFEST
    fifo = _special("fifo", tmp_path, "rep")
    argv = [a.format(rec=rec_path, dir=fifo) for a in FOLDER_OUTPUTS[command]]
    assert_user_error(*run(capsys, *argv), str(fifo))
    d = tmp_path / "old"
    d.mkdir()
    (d / MANIFEST).write_text("index.html\n")
    os.mkfifo(d / "index.html")
    argv = [a.format(rec=rec_path, dir=d) for a in FOLDER_OUTPUTS[command]]
    assert_user_error(*run(capsys, *argv), str(d / "index.html"), "regular file only")
    assert stat.S_ISFIFO(os.lstat(d / "index.html").st_mode)


def test_writers_refuse_what_is_not_a_regular_file(tmp_path):
    """The library's writers, not only the commands' early checks."""
    from inflowsim.errors import InputError
    from inflowsim.fileio import atomic_path, safe_write_text
    from inflowsim.report.plots import new_figure, save_png
    fifo = _special("fifo", tmp_path, "f")
    null = _special("link-to-devnull", tmp_path, "n")
    for p in (fifo, null):
        with pytest.raises(InputError, match="regular file only"):
            safe_write_text(p, "x", overwrite=True)
        with pytest.raises(InputError, match="regular file only"):
            with atomic_path(p):
                pass
        with pytest.raises(InputError, match="regular file only"):
            save_png(new_figure()[0], p)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode) and null.is_symlink()
    assert sorted(q.name for q in tmp_path.iterdir()) == ["f", "n"]


def test_a_link_to_a_regular_file_is_written_through(tmp_path):
    from inflowsim.fileio import safe_write_text
    target = tmp_path / "real.txt"
    target.write_text("old\n")
    link = tmp_path / "link.txt"
    link.symlink_to(target)
    safe_write_text(link, "new\n", overwrite=True)
    assert link.is_symlink() and target.read_text() == "new\n"


def test_a_full_disk_names_the_file(capsys, rec_path, tmp_path, monkeypatch):
    """ENOSPC while writing (the temporary file's write fails, as on a full disk):
    one line naming the output, nothing left behind."""
    import builtins
    import errno

    import inflowsim.fileio as fileio

    class Full:
        def __init__(self, *a, **k):
            self.f = builtins.open(*a, **k)

        def write(self, text):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.f.close()

    monkeypatch.setattr(fileio, "open", Full, raising=False)
    out = tmp_path / "x.csv"
    code, stdout, err = run(capsys, "simulate", rec_path, "-m", "glauert", "--out", out)
    assert_user_error(code, stdout, err, str(out), "No space left on device")
    assert list(tmp_path.iterdir()) == []


# -- records that cannot be analysed, steps that cannot be run (issue #28 item 2) ------
@pytest.fixture(scope="module")
def still_path(tmp_path_factory):
    """The record with its three controls held at their first value: nothing moves
    the rotor (hub-motion columns left as they were)."""
    import numpy as np

    from inflowsim.data.record import write_record
    rec = virtual(structure="glauert", duration=12.0)
    still = rec.with_channels(**{c: np.full(len(rec), rec[c][0])
                                 for c in ("theta0", "theta1c", "theta1s")})
    p = tmp_path_factory.mktemp("still") / "still.csv"
    write_record(still, p)
    return p


@pytest.mark.parametrize("argv", [
    ("identify", "-m", "basic"), ("diagnose", "-m", "basic"), ("bandstudy", "-m", "basic"),
    ("ladder",), ("ladder", "--structures", "basic", "glauert"),
    ("validate", "-m", "basic"), ("validate", "-m", "glauert", "--trim-window", "0", "1"),
], ids=" ".join)
def test_a_record_where_no_control_moves_is_refused(capsys, still_path, argv):
    code, out, err = run(capsys, argv[0], still_path, *argv[1:])
    assert_user_error(code, out, err, str(still_path), "no control moves")


def test_the_trim_of_a_still_record_describes_itself(still_path):
    from inflowsim.data.record import find_trim, read_record
    trim = find_trim(read_record(still_path))
    assert trim.t_movement is None and "no control moves" in trim.describe()
    assert trim.as_dict()["description"] == trim.describe()


def test_a_still_record_too_short_for_a_trim_is_refused_by_name(still_path):
    # four samples: a record (at least 4) but not a trim (at least 5), nothing moving
    from inflowsim.data.record import Record, RecordError, find_trim, read_record
    rec = read_record(still_path)
    short = Record.from_arrays(rec.t[:4], {c: v[:4] for c, v in rec.channels.items()},
                               dict(rec.meta))
    with pytest.raises(RecordError, match="fewer than the 5 a trim needs"):
        find_trim(short)


def test_simulate_refuses_a_step_that_makes_too_many_samples(capsys, rec_path, tmp_path):
    from inflowsim.data.record import MAX_SAMPLES
    out = tmp_path / "x.csv"
    code, stdout, err = run(capsys, "simulate", rec_path, "-m", "basic", "--dt", "1e-9",
                            "--out", out)
    assert_user_error(code, stdout, err, "--dt 1e-09", f"at most {MAX_SAMPLES:,}")
    assert not out.exists()


def test_simulate_keeps_the_flight_condition_not_the_inputs_origin(capsys, rec_path,
                                                                    tmp_path):
    from inflowsim.data.record import read_record, write_record
    src = tmp_path / "in.csv"
    write_record(read_record(rec_path).with_meta(
        aircraft="Puma (virtual, nonlinear blade-element truth)", seed="7",
        description="theta1s doublet, nonlinear blade-element truth", trim_window="0 1.5"),
        src)
    out = tmp_path / "sim.csv"
    assert run(capsys, "simulate", src, "-m", "basic", "--out", out)[0] == 0
    text = out.read_text()
    assert "truth" not in text and "seed" not in text and "aircraft" not in text
    meta = read_record(out).meta
    assert {k: meta[k] for k in ("omega", "mu", "a0", "solidity", "trim_window")} == {
        "omega": "27.5", "mu": "0.249", "a0": "5.73", "solidity": "0.0917",
        "trim_window": "0 1.5"}
    assert meta["hold"] == "zoh" and "model basic" in meta["description"]


# -- what used to be accepted silently (issue #28 item 3) ------------------------------
def test_a_record_too_short_for_the_band_names_the_length_needed(capsys, tmp_path):
    """3 s of the paper's band kept 4 bins from 0.33 Hz (and the ladder added two
    effects to them); the band needs one period of 0.2256 Hz, 4.43 s."""
    from inflowsim.data.record import band_needs, write_record
    from inflowsim.defaults import DEFAULT_BAND
    p = tmp_path / "short.csv"
    write_record(virtual(structure="glauert", duration=3.0), p)
    need = f"{band_needs(DEFAULT_BAND):.4g} s"
    assert need == "4.433 s"
    for argv in (("ladder", p), ("identify", p, "-m", "basic"), ("validate", p, "-m", "basic"),
                 ("diagnose", p, "-m", "basic")):
        assert_user_error(*run(capsys, *argv), "too short", need)


def test_a_record_just_long_enough_for_the_band_passes():
    from inflowsim.data.record import band_needs
    rec = virtual(structure="glauert", duration=4.5)
    assert rec.duration >= band_needs((0.2256, 1.58))
    rec.check_band((0.2256, 1.58))


def _param_file(tmp_path, name, edit):
    from inflowsim.model.params import PUMA
    from inflowsim.model.presets import preset_parameters
    doc = {"structure": "glauert", "effects": ["separate-time-constants", "glauert",
                                               "azimuth-bias"],
           "constants": PUMA.as_dict(),
           "parameters": preset_parameters("glauert", PUMA, "paper")}
    edit(doc)
    p = tmp_path / name
    p.write_text(json.dumps(doc))
    return p


@pytest.mark.parametrize("name, edit, words", [
    ("effects.json", lambda d: d.update(effects=[]), ('"effects" lists []', "glauert")),
    ("twice.json", lambda d: d.update(effects=["glauert", "glauert"]), ("twice",)),
    ("omega.json", lambda d: d["constants"].update(omega="27.5"),
     ("constants omega", '"27.5" is not a number')),
    ("tau.json", lambda d: d["parameters"].update(tau0=True), ("tau0", "true is not a number")),
    ("est.json", lambda d: d["parameters"].update(tau0={"estimate": "1.0"}),
     ("tau0 estimate", "not a number")),
    ("trim.json", lambda d: d["constants"].update(trim={"theta0": "0.1"}),
     ("trim theta0", "not a number")),
], ids=lambda x: x if isinstance(x, str) else "")
def test_the_strict_parameter_reader(capsys, rec_path, tmp_path, name, edit, words):
    p = _param_file(tmp_path, name, edit)
    out = tmp_path / "x.csv"
    code, stdout, err = run(capsys, "simulate", rec_path, "-m", "glauert", "-p", p,
                            "--out", out)
    assert_user_error(code, stdout, err, str(p), *words)
    assert not out.exists()


def test_the_structure_and_effects_of_a_written_fit_agree(tmp_path):
    """What the reader refuses is never what the package writes."""
    from inflowsim.model.paramfile import read_parameters
    p = _param_file(tmp_path, "ok.json", lambda d: d.update(
        structure="glauert+time-delay", effects=["separate-time-constants", "glauert",
                                                 "azimuth-bias", "time-delay"],
        parameters={**d["parameters"], "delay": 0.0}))
    assert read_parameters(p).structure.name == "glauert+time-delay"


def test_an_rpm_omega_in_a_parameter_file_is_warned_as_in_a_record(capsys, rec_path,
                                                                  tmp_path):
    p = _param_file(tmp_path, "rpm.json", lambda d: d["constants"].update(omega=262.6))
    for argv in (("simulate", rec_path, "-m", "glauert", "-p", p, "--out", tmp_path / "o.csv"),
                 ("model", "-m", "glauert", "-p", p)):
        code, _, err = run(capsys, *argv)
        assert code == 0
        warned = [ln for ln in err.splitlines() if "262.6" in ln]
        assert len(warned) == 1 and str(p) in warned[0] and "rpm" in warned[0], err


def test_time_in_milliseconds_is_warned(capsys, rec_path, tmp_path):
    from inflowsim.data.record import read_record, write_record
    rec = read_record(rec_path)
    ms = tmp_path / "ms.csv"
    write_record(rec.__class__.from_arrays(rec.t * 1000.0, dict(rec.channels), rec.meta), ms)
    assert any("milliseconds" in w for w in read_record(ms).warnings())
    assert not any("sample step" in w for w in rec.warnings())
    code, _, err = run(capsys, "simulate", ms, "-m", "basic", "--out", tmp_path / "o.csv")
    assert code == 0 and "is t in milliseconds?" in err


@pytest.mark.parametrize("window", [("0", "1000"), ("-1", "0.5"), ("11", "12.5")])
def test_a_trim_window_outside_the_record_is_refused(capsys, rec_path, window):
    code, out, err = run(capsys, "validate", rec_path, "-m", "glauert", "--trim-window",
                         *window)
    assert_user_error(code, out, err, "trim window", "outside the record")


def test_a_trim_window_at_the_records_ends_is_taken(rec_path):
    from inflowsim.data.record import find_trim, read_record
    rec = read_record(rec_path)
    assert find_trim(rec, (0.0, 1.5)).n_samples == 151
    assert find_trim(rec, (rec.t[-1] - 0.5, rec.t[-1])).method == "window"


@pytest.mark.parametrize("text", ["glauert+time-delay+time-delay",
                                  "basic+flap-inertia+skewed-wake+flap-inertia"])
def test_an_effect_given_twice_is_refused(capsys, rec_path, text):
    from inflowsim.errors import InputError
    from inflowsim.model.structure import Structure
    with pytest.raises(InputError, match="given twice"):
        Structure.parse(text)
    assert_user_error(*run(capsys, "identify", rec_path, "-m", text), "given twice")
    assert Structure.parse("glauert+azimuth-bias").name == "glauert"   # in the preset: same


def test_api_misuse_raises_the_packages_error_naming_the_choices():
    import inflowsim as ifs
    with pytest.raises(ifs.InputError, match="params: a mapping.*lambda_beta2, n_beta, tau"):
        ifs.build_model("basic", None, ifs.PUMA)
    with pytest.raises(ifs.InputError, match="constants: a Constants"):
        ifs.build_model("basic", ifs.preset_parameters("basic"), None)
    with pytest.raises(ifs.InputError, match="'papr': choose 'paper' or 'theory'"):
        ifs.preset_parameters("basic", source="papr")
    with pytest.raises(ifs.InputError, match="constants: a Constants"):
        ifs.preset_parameters("basic", constants={"mu": 0.25})


# -- the record format's promises (issue #28 item 4) -----------------------------------
def _rows(path):
    lines = path.read_text().splitlines()
    h = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))
    return lines[:h], [ln.split(",") for ln in lines[h:]]


def test_columns_may_come_in_any_order(capsys, rec_path, tmp_path):
    """``t`` found by name: the columns reversed read as the same record."""
    import numpy as np

    from inflowsim.data.record import read_record
    meta, rows = _rows(rec_path)
    p = tmp_path / "reversed.csv"
    p.write_text("\n".join(meta + [",".join(r[::-1]) for r in rows]) + "\n")
    a, b = read_record(rec_path), read_record(p)
    assert b.order == a.order[::-1]
    np.testing.assert_array_equal(a.t, b.t)
    for c in a.order:
        np.testing.assert_array_equal(a[c], b[c])
    code, out, _ = run(capsys, "validate", p, "-m", "glauert", "--json")
    code0, out0, _ = run(capsys, "validate", rec_path, "-m", "glauert", "--json")
    assert code == code0 == 0
    assert json.loads(out)["channels"] == json.loads(out0)["channels"]


@pytest.mark.parametrize("sep, name", [(";", "semicolons"), ("\t", "tabs")])
def test_another_separator_is_named(capsys, rec_path, tmp_path, sep, name):
    meta, rows = _rows(rec_path)
    p = tmp_path / "sep.csv"
    p.write_text("\n".join(meta + [sep.join(r) for r in rows]) + "\n")
    assert_user_error(*run(capsys, "validate", p, "-m", "glauert"), str(p),
                      f"separated by {name}", "comma-separated")


def test_a_header_without_t_is_refused(capsys, rec_path, tmp_path):
    meta, rows = _rows(rec_path)
    p = tmp_path / "no_t.csv"
    rows[0][0] = "time"
    p.write_text("\n".join(meta + [",".join(r) for r in rows]) + "\n")
    assert_user_error(*run(capsys, "validate", p, "-m", "glauert"), "no column 't'")
