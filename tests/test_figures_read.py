"""Figures that read at a glance (issue #39): every figure rendered and checked for
axes, units and labels; log-frequency axes labelled at decades and between them;
phases without wrapping jumps; one colour per model across figures; the ladder's
parts named; the campaign's estimates with units and bounds that do not flatten
the points."""
import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_rgba

from conftest import virtual
from inflowsim.diagnose.validation import validate
from inflowsim.model.build import build_model
from inflowsim.model.presets import preset_parameters
from inflowsim.report.campaign import estimates_vs_mu_plot
from inflowsim.report.ladder import column_label, rung_label
from inflowsim.report.plots import (coherence_plot, error_spectrum_plot,
                                    frequency_response_plot, manoeuvre_window,
                                    time_response_plot)
from inflowsim.report.style import ROLE_COLOURS, model_colours


@pytest.fixture(scope="module")
def two():
    """The basic and the glauert preset (paper values) validated on one record: a
    base and a final model."""
    rec = virtual(structure="glauert", duration=12.0, seed=3)
    k = rec.constants
    return [validate(rec, build_model(s, preset_parameters(s, k, "paper"), k))
            for s in ("basic", "glauert")]


def _drawn(fig):
    fig.canvas.draw()
    return fig


def _labelled_ticks(ax):
    """The values of the x tick labels shown inside the axis's limits."""
    lo, hi = ax.get_xlim()
    out = []
    for t in ax.xaxis.get_ticklabels(which="both"):
        x = t.get_position()[0]
        if t.get_visible() and t.get_text() and lo <= x <= hi:
            out.append(x)
    return out


def _check_log_axis(ax):
    """A log axis; where its tick labels are shown (a shared axis shows them on the
    bottom row only), labels at a decade and between decades."""
    assert ax.get_xscale() == "log"
    # every axis keeps the style's ticks (setting the scale on a shared axis once
    # reset the others' to matplotlib's, which label 0.5 and 1 only)
    assert type(ax.xaxis.get_major_formatter()).__name__ == "_Between"
    xs = _labelled_ticks(ax)
    if not any(t.get_visible() and t.get_text() for t in ax.xaxis.get_ticklabels()) \
            and not ax.xaxis.get_label().get_text():
        return False
    decades = [x for x in xs if abs(math.log10(x) - round(math.log10(x))) < 1e-9]
    between = [x for x in xs if x not in decades]
    assert decades and between, (ax.get_xlim(), xs)
    assert "[Hz]" in ax.get_xlabel() or ax.get_xlabel() == ""
    return True


def _has_unit(label):
    return "[" in label and "]" in label


def _line_colours(ax):
    return [to_rgba(ln.get_color()) for ln in ax.get_lines()]


def test_one_colour_per_model_across_figures(two):
    base, final = (to_rgba(c) for c in model_colours(2))
    assert base == to_rgba(ROLE_COLOURS["base model"])
    assert final == to_rgba(ROLE_COLOURS["final model"])
    t = time_response_plot(two, show_inputs=True)
    f = frequency_response_plot(two)
    for fig in (t, f):
        colours = {c for ax in fig.axes for c in _line_colours(ax)}
        assert base in colours and final in colours
    # the measured data are black in both, never a model's colour
    meas = to_rgba(ROLE_COLOURS["measured"])
    assert _line_colours(t.axes[0])[0] == meas
    assert meas in _line_colours(f.axes[0])
    # and each model's line carries its own colour in the time history's legend
    labels = {tx.get_text().split(" ")[0]: to_rgba(h.get_color()) for tx, h in
              zip(t.axes[0].get_legend().get_texts(), t.axes[0].get_legend().legend_handles)}
    assert labels["basic"] == base and labels["glauert"] == final


def test_time_history_has_units_controls_and_zooms_on_the_manoeuvre(two):
    fig = time_response_plot(two, show_inputs=True, window="manoeuvre")
    axes = fig.axes
    assert len(axes) == 4 and all(_has_unit(a.get_ylabel()) for a in axes)
    assert axes[-1].get_xlabel() == "time [s]"
    assert "control" in axes[-1].get_ylabel()
    t = two[0].t
    lo, hi = axes[-1].get_xlim()
    t0, t1 = manoeuvre_window(t, two[0].u, two[0].inputs)
    assert (lo, hi) == pytest.approx((t0, t1))
    assert hi - lo < 0.8 * (t[-1] - t[0])       # the manoeuvre, not the whole record


def test_log_frequency_axes_are_labelled_between_decades(two):
    for fig in (frequency_response_plot(two), error_spectrum_plot(two),
                coherence_plot(two)):
        _drawn(fig)
        checked = [_check_log_axis(ax) for ax in fig.axes]
        assert any(checked)
        for ax in fig.axes:
            assert _has_unit(ax.get_ylabel()) or ax.get_ylabel() == ""


def test_bode_phase_has_no_wrapping_jump(two):
    fig = frequency_response_plot(two)
    phase_axes = [a for a in fig.axes if "phase" in a.get_ylabel()] or fig.axes[3:6]
    assert phase_axes
    for ax in fig.axes[3:6]:
        for ln in ax.get_lines():
            y = np.asarray(ln.get_ydata(), float)
            y = y[np.isfinite(y)]
            assert np.all(np.abs(np.diff(y)) < 180)


def test_ladder_names_the_parts_and_the_held_parameters():
    s = SimpleNamespace(name="basic+glauert", effects=("glauert",))
    fit = SimpleNamespace(structure=s, fixed=("c1", "c2", "c3", "c4"),
                          parameters={"c1": 0.0, "c2": 0.0, "c3": 0.0, "c4": 0.0})
    first = SimpleNamespace(structure=s, fit=fit, added="glauert",
                            atoms=("glauert (k0p, kc, ks)",))
    second = SimpleNamespace(structure=s, fit=SimpleNamespace(structure=s, fixed=(),
                                                              parameters={}),
                             added="glauert", atoms=("glauert (c1, c2, c3, c4)",))
    assert rung_label(first) != rung_label(second)
    assert rung_label(first) == "+glauert (k0p, kc, ks)"
    assert column_label(first) == "basic+glauert (c1, c2, c3, c4 held at 0)"
    assert column_label(second) == "basic+glauert"


def test_estimates_vs_mu_has_units_and_wide_bounds_do_not_flatten():
    rows = []
    for k, mu in enumerate((0.1, 0.1, 0.2, 0.2, 0.3, 0.3)):
        rows.append({"kind": "record", "status": "ok", "mu": mu,
                     "est_tau0": 1.0 + mu + 0.01 * k, "sigma_tau0": 0.02,
                     "est_azimuth_bias": 0.05 + 0.01 * k, "sigma_azimuth_bias": 0.01})
    rows[1]["sigma_tau0"] = 4000.0                       # a record that does not determine it
    for mu in (0.1, 0.2, 0.3):
        rows.append({"kind": "condition", "status": "ok", "mu": mu,
                     "est_tau0": 1.0 + mu, "sigma_tau0": 0.01,
                     "est_azimuth_bias": 0.06, "sigma_azimuth_bias": 0.005})
    df = pd.DataFrame(rows)
    fig = _drawn(estimates_vs_mu_plot(df))
    by = {a.get_title(): a for a in fig.axes if a.get_visible()}
    tau, az = by["tau0"], by["azimuth_bias"]
    for ax in (tau, az):
        assert _has_unit(ax.get_ylabel()) and _has_unit(ax.get_xlabel())
    assert "[deg]" in az.get_ylabel()                      # an angle, in degrees
    lo, hi = tau.get_ylim()
    assert hi - lo < 2.0                                   # not stretched to +-4000
    marks = [ln for ln in tau.get_lines() if ln.get_marker() == "^"]
    assert marks and len(marks[0].get_xdata()) == 1        # the wide bound is marked
