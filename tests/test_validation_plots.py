"""Plots of validation results: labelled axes with units, titles naming the structures."""
from inflowsim.model import build_model
from inflowsim.report.plots import error_spectrum_plot, frequency_response_plot, time_response_plot
from inflowsim.model.presets import preset_parameters
from inflowsim.diagnose.validation import validate
from inflowsim.flighttest.virtual import VirtualTest, virtual_record


def _results():
    rec = virtual_record(VirtualTest(duration=13.3))
    return [validate(rec, build_model(s, preset_parameters(s, rec.constants), rec.constants))
            for s in ("basic", "glauert")]


def test_plots_are_labelled(tmp_path):
    res = _results()
    fig = time_response_plot(res, path=tmp_path / "t.png", show_inputs=True)
    axes = fig.get_axes()
    assert len(axes) == 4
    assert all("[deg]" in a.get_ylabel() for a in axes)
    assert axes[-1].get_xlabel() == "time [s]"
    title = fig._suptitle.get_text()
    assert "basic" in title and "glauert" in title
    assert [t.get_text() for t in axes[0].get_legend().get_texts()][0] == "measured"
    assert (tmp_path / "t.png").read_bytes().startswith(b"\x89PNG")

    fig = frequency_response_plot(res, path=tmp_path / "f.png")
    axes = fig.get_axes()
    assert len(axes) == 3 * 3               # magnitude, phase, coherence per flap channel
    assert {a.get_ylabel() for a in axes} == {"magnitude [dB]", "phase, unwrapped [deg]",
                                              r"coherence $\gamma^2$ [-]", ""}
    assert "frequency [Hz]" in {a.get_xlabel() for a in axes}
    assert "glauert" in fig._suptitle.get_text() and "conditioned" in fig._suptitle.get_text()
    # one point per grid frequency, and each model's analytic response on top
    n = res[1].frequency.f_hz.size
    labels = [ln.get_label() for ln in axes[0].get_lines()]
    assert labels[0] == "measured" and len(axes[0].get_lines()[0].get_xdata()) == n
    assert any(s.startswith("basic (J ") for s in labels)
    assert any(s.startswith("glauert (J ") for s in labels)
    assert (tmp_path / "f.png").read_bytes().startswith(b"\x89PNG")

    fig = error_spectrum_plot(res)
    assert len(fig.get_axes()[0].get_lines()) == 3 * 2 + 1     # + the 0 dB line
