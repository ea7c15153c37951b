"""The HTML report writer: content, files beside it, never over a user's file."""
import pytest

from inflowsim.errors import InputError
from inflowsim.report.plots import new_figure
from inflowsim.report import MANIFEST, Report, format_cell


def _fig():
    fig, ax = new_figure(1, 1, size=(3, 2))
    ax[0, 0].plot([0, 1], [0, 1])
    return fig


def test_report_writes_index_and_pngs(tmp_path):
    d = tmp_path / "rep"
    rep = (Report("Title <x>", subtitle="sub").heading("Fit")
           .paragraph("a < b").table([["beta0", 1.234567e-4, 3, None]],
                                     header=["channel", "rms [rad]", "n", "x"],
                                     caption="cap")
           .figure(_fig(), "time", caption="Time").figure(_fig(), "inline", embed=True))
    path = rep.write(d)
    assert path == d / "index.html"
    text = path.read_text()
    assert "Title &lt;x&gt;" in text and "a &lt; b" in text
    assert "<td class=\"n\">0.0001235</td>" in text
    assert 'src="time.png"' in text and "data:image/png;base64," in text
    assert (d / "time.png").read_bytes().startswith(b"\x89PNG")
    assert not (d / "inline.png").exists()
    assert set(rep.files()) == {"index.html", "time.png"}
    # a second report into the same folder replaces its own files
    Report("again").figure(_fig(), "time").write(d)
    assert "again" in (d / "index.html").read_text()


def test_report_refuses_user_files(tmp_path):
    f = tmp_path / "afile"
    f.write_text("user data")
    with pytest.raises(InputError, match="not a directory"):
        Report("x").write(f)
    assert f.read_text() == "user data"
    d = tmp_path / "mine"
    d.mkdir()
    (d / "index.html").write_text("<p>my own page</p>")
    with pytest.raises(InputError, match="not part of an earlier inflowsim report"):
        Report("x").write(d)
    assert (d / "index.html").read_text() == "<p>my own page</p>"
    assert not (d / MANIFEST).exists()
    # a user PNG of the same name as a figure is refused too, before anything is written
    e = tmp_path / "pics"
    e.mkdir()
    (e / "time.png").write_bytes(b"user")
    with pytest.raises(InputError, match="time.png"):
        Report("x").figure(_fig(), "time").write(e)
    assert (e / "time.png").read_bytes() == b"user" and not (e / "index.html").exists()


def test_report_refuses_protected_input(tmp_path):
    d = tmp_path / "r"
    Report("first").write(d)
    with pytest.raises(InputError, match="input file"):
        Report("x").write(d, protect=[d / "index.html"])


def test_figure_names_checked():
    rep = Report("x").figure(_fig(), "a")
    with pytest.raises(InputError, match="twice"):
        rep.figure(_fig(), "a")
    with pytest.raises(InputError, match="letters"):
        rep.figure(_fig(), "../evil")


def test_format_cell():
    assert format_cell(None) == ""
    assert format_cell(True) == "yes"
    assert format_cell(float("nan")) == "nan"
    assert format_cell(2.0 / 3.0, digits=3) == "0.667"
    assert format_cell("text") == "text"
