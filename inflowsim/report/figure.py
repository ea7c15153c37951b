"""The canvas every figure is drawn on: :func:`new_figure` (an Agg canvas, no global
pyplot state) and :func:`save_png`.

A module of its own, below every plotting module, so that the plotting modules can
import each other one way only (issue #40: ``plots`` and ``frf_plots`` imported
each other).  :mod:`inflowsim.report.plots` re-exports both.
"""
from __future__ import annotations

from pathlib import Path

from ..fileio import atomic_path

#: Resolution of saved figures [dots per inch].
DPI = 110


def new_figure(nrows=1, ncols=1, size=(8.0, 6.0), sharex=True):
    """A figure on an Agg canvas and its axes array (always 2-D).  Matplotlib is
    imported here, on the first figure: a command that draws nothing never loads it.

    Parameters
    ----------
    nrows, ncols : int
        Rows and columns of axes.
    size : tuple of float
        Figure size (width, height) [in].
    sharex : bool
        The axes share their x axis.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, sharex=sharex, squeeze=False)
    return fig, axes


def save_png(fig, path, dpi: int = DPI) -> Path:
    """Save ``fig`` as PNG at ``path``, replacing a regular file only and never
    leaving it half-written (:func:`inflowsim.fileio.atomic_path`).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    path : path-like
        Where to write the PNG.
    dpi : int
        Resolution [dots per inch].
    """
    p = Path(path)
    with atomic_path(p) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi, metadata={"Software": "inflowsim"})
    return p


__all__ = ["DPI", "new_figure", "save_png"]
