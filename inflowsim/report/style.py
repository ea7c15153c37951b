"""One look for every figure: a colour per model role, log-frequency axes labelled
at decades and between them, phases unwrapped onto the measurement's branch.

Every plot of the package takes its colours from :data:`ROLE_COLOURS` through
:func:`model_colours` (the measured data black, the first model of a comparison the
base model's blue, the last the final model's red, those between from the
intermediate list), so one model has one colour in every figure of a report; a
frequency axis is :func:`log_frequency_axis`.  Matplotlib is imported inside the
functions that draw.
"""
from __future__ import annotations

import math
from types import MappingProxyType

import numpy as np

__all__ = ["ROLE_COLOURS", "model_colours", "log_frequency_axis", "align_phase_deg",
           "frequency_label"]

#: Colour by role, the same in every figure.  ``intermediate``: the models between
#: the base and the final one (a ladder's middle rungs), in order.
ROLE_COLOURS = MappingProxyType({
    "measured": "black",
    "truth": "0.45",
    "base model": "tab:blue",
    "final model": "tab:red",
    "schedule": "tab:purple",
    "intermediate": ("tab:orange", "tab:green", "tab:brown", "tab:pink", "tab:olive",
                     "tab:cyan"),
})


def model_colours(n: int) -> list:
    """Colours of ``n`` models compared in one figure, in order: the first is the
    base model, the last the final model, those between intermediate ones (one
    model alone is the base model).

    Parameters
    ----------
    n : int
        Number of models [-].
    """
    if n <= 0:
        return []
    if n == 1:
        return [ROLE_COLOURS["base model"]]
    mid = ROLE_COLOURS["intermediate"]
    return ([ROLE_COLOURS["base model"]] + [mid[k % len(mid)] for k in range(n - 2)]
            + [ROLE_COLOURS["final model"]])


def _tick_text(v) -> str:
    return f"{v:.10g}" if 1e-3 <= v < 1e4 else f"{v:.0e}"


def _labelled(mantissa: int, decades: float) -> bool:
    """Whether a tick of ``mantissa`` (1 to 9) is labelled on an axis spanning
    ``decades``: every one on a short axis, fewer as it widens, the decades always."""
    if decades <= 0.5:
        return True
    if decades <= 1.5:
        return mantissa in (1, 2, 3, 5)
    if decades <= 3.0:
        return mantissa in (1, 2, 5)
    return mantissa in (1, 3)


def log_frequency_axis(ax, axis: str = "x") -> None:
    """A log axis with a tick at every integer multiple of each decade, labelled at
    the decades and between them (at 2, 3 and 5 over a decade or so; at every tick
    on an axis shorter than half a decade; at 3 on a wide one).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
    axis : {"x", "y"}
        Which axis.
    """
    from matplotlib.ticker import Formatter, LogLocator, NullLocator

    class _Between(Formatter):
        def __call__(self, v, pos=None):
            if v <= 0:
                return ""
            lo, hi = sorted(self.axis.get_view_interval())
            decades = math.log10(hi / lo) if lo > 0 else 99.0
            mantissa = int(round(v / 10 ** math.floor(math.log10(v) + 1e-9)))
            return _tick_text(v) if _labelled(mantissa, decades) else ""

    if getattr(ax, f"get_{axis}scale")() != "log":
        # (setting the scale resets the locators of every axis shared with this one:
        # only where it is not log already, so each shared axis keeps the ones set here)
        getattr(ax, f"set_{axis}scale")("log")
    a = getattr(ax, f"{axis}axis")
    a.set_major_locator(LogLocator(base=10.0, subs=tuple(float(k) for k in range(1, 10)),
                                   numticks=100))
    a.set_major_formatter(_Between())
    a.set_minor_locator(NullLocator())


def frequency_label() -> str:
    """The frequency axis's label, with its unit."""
    return "frequency [Hz]"


def align_phase_deg(model_deg, measured_deg, where=None):
    """``model_deg`` moved by whole turns onto the branch of ``measured_deg`` (both
    unwrapped, [deg]): the mean difference over ``where`` (default every finite
    point of both) then lies within +-180 deg, so an unwrapped model and
    measurement are drawn on one branch.

    Parameters
    ----------
    model_deg, measured_deg : array_like
        Unwrapped phases [deg] at the same frequencies.
    where : array_like of bool, optional
        The points that count (e.g. coherent ones).
    """
    m = np.asarray(model_deg, dtype=float)
    d = np.asarray(measured_deg, dtype=float) - m
    ok = np.isfinite(d) if where is None else (np.asarray(where, bool) & np.isfinite(d))
    if not ok.any():
        return m
    return m + 360.0 * np.round(np.mean(d[ok]) / 360.0)
