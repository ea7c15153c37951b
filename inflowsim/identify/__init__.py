"""Frequency-domain output-error identification with Cramer-Rao bounds (issue #4).

Public API (stable): :func:`identify`, :func:`evaluate`, :class:`FitResult`,
:class:`Evaluation`, :func:`record_spectra`, :func:`snap_band`; the band study
:func:`band_study`.  Method: ``shared/spec/model.md`` section 7.
"""
from .bandstudy import BandStudy, band_study
from .estimator import Evaluation, evaluate, identify
from .results import FitResult, RecordFit, channel_fit
from .transform import DEFAULT_BAND, Spectra, record_spectra, snap_band

__all__ = ["identify", "evaluate", "FitResult", "RecordFit", "Evaluation", "channel_fit",
           "record_spectra", "snap_band", "Spectra", "DEFAULT_BAND", "band_study",
           "BandStudy"]
