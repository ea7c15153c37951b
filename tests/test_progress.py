"""Progress on long work (issue #39): on standard error only, what and how far,
shown on a terminal or when asked (``--progress``), never with ``--quiet`` or into a
file or pipe; warnings whatever the setting; no raw optimiser iterations."""
import pytest
from conftest import run, virtual

from inflowsim import progress


@pytest.fixture(scope="module")
def rec_path(tmp_path_factory):
    from inflowsim.data.record import write_record
    p = tmp_path_factory.mktemp("rec") / "doublet.csv"
    write_record(virtual(structure="glauert", duration=12.0), p)
    return p


def _lines(err):
    """Every state of the stderr text: a bar's redraws are separate lines."""
    return [ln.strip() for ln in err.replace("\r", "\n").splitlines() if ln.strip()]


def test_identify_progress_only_when_asked(capsys, rec_path):
    code, out, err = run(capsys, "identify", rec_path, "-m", "basic")
    assert code == 0 and "lambda_beta2" in out
    # stderr is not a terminal: no progress, only warnings (basic on a glauert record:
    # every estimate is conditional on an incomplete structure)
    warnings = _lines(err)
    assert all(ln.startswith("warning:") for ln in warnings), err
    code, out_q, err = run(capsys, "identify", rec_path, "-m", "basic", "--quiet")
    assert code == 0 and _lines(err) == warnings and out_q == out
    code, out_p, err = run(capsys, "identify", rec_path, "-m", "basic", "--progress")
    assert code == 0 and out_p == out          # stdout is the same, progress apart
    lines = _lines(err)
    # what it is doing and how far: a bar over the starts (k/n) and the iterations
    assert any("identify basic: trying starts" in ln and "/3" in ln for ln in lines), err
    assert any("identify basic: fitting from start" in ln and "iteration" in ln
               for ln in lines), err
    # not a line per Levenberg-Marquardt iteration
    assert not any(ln.startswith("iteration ") for ln in lines), err


def test_warnings_are_shown_with_quiet(capsys, rec_path, tmp_path):
    from inflowsim.data.record import read_record, write_record
    rec = read_record(rec_path)
    ms = tmp_path / "ms.csv"
    write_record(rec.__class__.from_arrays(rec.t * 1000.0, dict(rec.channels), rec.meta), ms)
    code, out, err = run(capsys, "simulate", ms, "-m", "basic", "--out", tmp_path / "o.csv",
                         "--quiet")
    assert code == 0 and "warning:" in err and "is t in milliseconds?" in err


def test_quiet_and_progress_exclude_each_other(capsys):
    code, out, err = run(capsys, "model", "-m", "basic", "--quiet", "--progress")
    assert code == 2 and out == "" and "not allowed" in err


def test_a_callers_function_gets_one_line_per_step():
    seen = []
    with progress.bar(seen.append, 3, "work", "item") as b:
        for name in "abc":
            b.set_postfix_str(name)
            b.update()
    assert seen == ["work: 1/3 a", "work: 2/3 b", "work: 3/3 c"]
    with progress.bar(None, 3, "work") as b:    # None: nothing, silently
        b.update()


def test_shown_follows_the_setting(monkeypatch):
    try:
        progress.configure(True)
        assert progress.shown()
        progress.configure(False)
        assert not progress.shown()
        progress.configure(None)
        monkeypatch.setattr("sys.stderr", open("/dev/null", "w"))
        assert not progress.shown()                 # a file: not a terminal
    finally:
        progress.configure(None)


def test_fmu_build_says_what_it_is_doing(capsys, tmp_path, monkeypatch):
    """The steps are named as they run (the compiler itself is not under test
    here: a stand-in writes the library, so the test takes a second, not ten)."""
    import inflowsim.fmu.build as build
    monkeypatch.setattr(build, "compile_library",
                        lambda src, out_so, **kw: out_so.write_bytes(b"\x7fELF"))
    out = tmp_path / "m.fmu"
    code, stdout, err = run(capsys, "fmu", "build", "-m", "basic", "--out", out,
                            "--progress")
    assert code == 0 and "wrote" in stdout
    lines = _lines(err)
    assert any("generating the C equations" in ln for ln in lines), err
    assert any("compiling" in ln for ln in lines), err


def test_the_campaign_says_its_dashboard_address():
    """The dashboard's address, or why there is none (no bokeh, no dashboard)."""
    from types import SimpleNamespace

    from inflowsim.campaign.engine import dashboard
    assert dashboard(SimpleNamespace(dashboard_link="http://127.0.0.1:8787/status")) \
        == "http://127.0.0.1:8787/status"

    class NoBoard:
        @property
        def dashboard_link(self):
            raise KeyError("dashboard")
    assert "no dashboard" in dashboard(NoBoard()) and "bokeh" in dashboard(NoBoard())

    class Unserved:                   # a scheduler without one: no made-up address
        dashboard_link = "http://127.0.0.1:8787/status"

        def scheduler_info(self):
            return {"services": {}}
    assert "no dashboard" in dashboard(Unserved())


def test_a_single_flight_test_chooses_its_speed(capsys, tmp_path):
    """``flighttest --mu`` (issue #39): the record flies at that advance ratio; one
    outside (0, 0.5] is refused in one line."""
    from conftest import assert_user_error

    from inflowsim.data.record import read_record
    out = tmp_path / "r.csv"
    code, _, err = run(capsys, "flighttest", "--truth", "linear", "--mu", "0.15",
                       "--duration", "6", "--out", out)
    assert code == 0, err
    assert read_record(out).constants.mu == pytest.approx(0.15)
    code, out_, err = run(capsys, "flighttest", "--mu", "0.9", "--out", tmp_path / "x.csv")
    assert_user_error(code, out_, err, "--mu 0.9")
