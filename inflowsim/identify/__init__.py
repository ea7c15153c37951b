"""Frequency-domain output-error identification with Cramer-Rao bounds (issue #4).

Public API (stable): :func:`identify`, :func:`evaluate`, :class:`FitResult`,
:class:`Evaluation`, :func:`record_spectra`, :func:`snap_band`; the band study
:func:`band_study`.  Method: ``shared/spec/model.md`` section 7.

The names resolve on first use, so importing one module of the package (the
non-parametric frequency responses of :mod:`.frf`) does not import the estimator.
"""
import importlib

_EXPORTS = {"identify": "estimator", "evaluate": "estimator", "Evaluation": "estimator",
            "FitResult": "results", "RecordFit": "results", "channel_fit": "results",
            "record_spectra": "transform", "snap_band": "transform", "Spectra": "transform",
            "DEFAULT_BAND": "transform", "band_study": "bandstudy",
            "BandStudy": "bandstudy"}

__all__ = ["identify", "evaluate", "FitResult", "RecordFit", "Evaluation", "channel_fit",
           "record_spectra", "snap_band", "Spectra", "DEFAULT_BAND", "band_study",
           "BandStudy"]


def __getattr__(name):
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
