"""How much of a residual the inputs explain, measured without a noise floor.

Under coloured sensor noise the floor measured above the band is far below the
noise in it (:mod:`inflowsim.diagnose.lpm`), so a residual's excess over that
floor is mostly noise and the share of it a candidate removes says little.  A
model error, though, is the inputs seen through a wrong frequency response:
``dH(f) U(f)`` with ``dH`` smooth, plus a smooth transient.  Regressing each
channel's residual on those terms (each input's transform times Legendre
polynomials of degree < ``Rule.degrees`` in frequency over the band, and the
polynomials alone) splits it into the part the inputs explain and the rest; the
rest, per degree of freedom, is the channel's noise level in the band, whatever
its colour.  The *input-correlated excess* is the explained part's power over
that level, summed over the channels: for noise alone its mean is
``r (nf - r) / (nf - r - 1)`` per channel (``r`` the regression's rank, an F
law) less what the fit took from it (:func:`expected_for_noise`: half a
dimension for every real parameter fitted, model and end effects, whose
directions lie in the span), and a model error raises it.  The candidate tests
(:mod:`inflowsim.diagnose.rule`, line 4) use it in place of the deviance when a
record's noise is coloured.

:func:`judge` is line 4's measure of a fit's residual: the level deviance from
white noise at the base's floor (:func:`~.failures.level_deviance`) with, where
``Rule.input_view``, the input-correlated excess beside it as a second view; or,
where a record's in-band noise is ``Rule.coloured`` times the floor or more, the
input-correlated excess alone.

Why two views on white noise.  The level deviance tests each channel's mean power
over the band against the floor: over the default band's 37-41 bins a channel's
level scatters by about 16 % for noise alone, the fit's own parameters and end
effects take some 10 % of it (24 real parameters of 246 real numbers on the
hingeless lag records), and a deviance counts a level below the floor as much as
one above.  A model error confined to a narrow band (the hingeless rotor's lag
mode) is plain to the likelihood ratio (statistic 20-54) yet moves a channel's
level by no more than that scatter; where the draw left the base's level at or
below the floor, fitting it raised the level deviance (seed 2: 2.7 -> 5.7).  In
the input-correlated excess the same error is concentrated in the ``r`` (14)
dimensions of the smooth input span, not spread over ``nf`` bins: 44.6 -> 30.8
against 31.2 for noise on that record.
The rule (:meth:`~.rule.Scored.takes_input`) lets this view pass a structure only
where each of its atoms is significant (at ``alpha``, or over the atoms tried where
``Rule.input_familywise``).
"""
from __future__ import annotations

import numpy as np

from .failures import (WHITE_DEVIANCE, analyses_of, floor_deviance, level_deviance,
                       structure_statistic, white_level_deviance)
from .rule import DEFAULT_RULE, Rule


def project(e: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """Rows of ``e`` projected on the span of ``Q``'s orthonormal columns."""
    return (e @ Q.conj()) @ Q.T


def smooth_input_basis(ra, rule: Rule = DEFAULT_RULE) -> np.ndarray:
    """Orthonormal basis ``(nf, r)`` of the smooth input-correlated residuals of a
    :class:`~inflowsim.diagnose.failures.ResidualAnalysis`: each input's transform
    times Legendre polynomials of degree < ``rule.degrees``, and those alone."""
    f = ra.f_hz
    x = 2 * (f - f.min()) / max(f.max() - f.min(), np.finfo(float).tiny) - 1
    L = np.polynomial.legendre.legvander(x, rule.degrees - 1)
    U = np.zeros((f.size, 0)) if ra.U is None else ra.U
    scale = np.abs(U).max(axis=0) if U.size else np.zeros(0)
    U = U[:, scale > 0] / scale[scale > 0]
    X = np.hstack([L] + [U[:, [i]] * L for i in range(U.shape[1])])
    Q, s, _ = np.linalg.svd(X, full_matrices=False)
    return Q[:, :int(np.sum(s > 1e-8 * s[0]))]


def noise_levels(ra, Q) -> np.ndarray:
    """Per channel, the residual power per bin the basis ``Q`` leaves ``(3,)``."""
    e = ra.error
    rest = e - project(e, Q)
    return np.sum(np.abs(rest) ** 2, axis=1) / (e.shape[1] - Q.shape[1])


def input_excess(ra, Q, levels) -> float:
    """The power of the residual in ``Q``'s span over ``levels``, summed over the
    channels."""
    return float(np.sum(np.sum(np.abs(project(ra.error, Q)) ** 2, axis=1) / levels))


def expected_for_noise(nf: int, r: int, fitted: int = 0) -> float:
    """Mean of :func:`input_excess` for noise alone, all three channels.

    ``fitted``: real parameters the residual was fitted with (model and end-effect
    nuisance).  Their directions (responses to the inputs, smooth transients) lie
    in the basis's span and each takes half a complex dimension's power from the
    noise there: the bound where all of them lie in it."""
    return (3.0 * r - 0.5 * fitted) * (nf - r) / (nf - r - 1)


#: The floor-based measures: (deviance of an analysis against floors, its mean for
#: noise at the floor, the name candidates report), by ``Rule.white_measure``.
FLOOR_MEASURES = {
    "level": (level_deviance, lambda ra: white_level_deviance(ra.f_hz.size),
              "level deviance"),
    "deviance": (floor_deviance, lambda ra: WHITE_DEVIANCE * ra.ratio.size, "deviance"),
}


def judge(records, band_hz, base_fit, base_analyses, rule: Rule = DEFAULT_RULE):
    """``judge(fit) -> dict``, line 4's measure of a fit's residual
    (:func:`inflowsim.diagnose.rule.lattice`).

    The residual's level deviance from white noise at the floor
    (``rule.white_measure``) and its structure across frequency, against the base
    fit's floors (the sensor noise does not change with the model); ``judge(None)``
    describes the base, with the deviance expected of noise at the floor.  Where
    ``rule.input_view``, also the residual's input-correlated excess (``"input"``;
    the base's ``"input_noise"``: its mean for noise), line 4's second view.  Where
    a record's noise is coloured (the in-band noise ``rule.coloured`` times the
    floor or more) the floor says little, and the measure is the residual's
    input-correlated excess alone.

    Parameters
    ----------
    records : list of Record
        The records.
    band_hz : (float, float)
        Analysis band [Hz].
    base_fit : FitResult
        The base structure's fit.
    base_analyses : list of ResidualAnalysis
        Its residual analyses, per record.
    rule : Rule
        The settings (:class:`~inflowsim.diagnose.rule.Rule`).
    """
    coloured = any(k >= rule.coloured for ra in base_analyses
                   for k in ra.in_band_over_floor)
    if coloured or rule.input_view:
        bases = [smooth_input_basis(ra, rule) for ra in base_analyses]
        levels = [noise_levels(ra, Q) for ra, Q in zip(base_analyses, bases)]
        # what the fit took from the noise: its parameters (shared by the records)
        # and each record's end-effect nuisance
        fitted = [len(base_fit.free) / len(base_fit.data) + np.size(d.nu)
                  for d in base_fit.data]

        def excess(analyses):
            return sum(input_excess(ra, Q, lv) for ra, Q, lv
                       in zip(analyses, bases, levels))
        input_noise = sum(expected_for_noise(ra.f_hz.size, Q.shape[1], n)
                          for ra, Q, n in zip(base_analyses, bases, fitted))
    if coloured:
        # the floor is far below the noise: measure without it
        def measure(analyses):
            return {"deviance": excess(analyses), "structure": 0.0}
        base = measure(base_analyses)
        base["white_deviance"] = input_noise
        base["measure"] = "input-correlated excess"
    else:
        deviance, white, label = FLOOR_MEASURES[rule.white_measure]
        floors = [ra.floor for ra in base_analyses]

        def measure(analyses):
            out = {"deviance": sum(deviance(ra, fl) for ra, fl in zip(analyses, floors)),
                   "structure": sum(structure_statistic(ra, fl, rule.max_lag)
                                    for ra, fl in zip(analyses, floors))}
            if rule.input_view:
                # the second view: the same residual's input-correlated excess
                out["input"] = excess(analyses)
            return out
        base = measure(base_analyses)
        base["white_deviance"] = sum(white(ra) for ra in base_analyses)
        base["measure"] = label
        if rule.input_view:
            base["input_noise"] = input_noise
    cache = {id(base_fit): base}

    def judged(fit):
        if fit is None:
            return base
        if id(fit) not in cache:
            # against the base's floors: the candidate's own are not measured
            cache[id(fit)] = measure(analyses_of(records, fit, band_hz, check_colour=False,
                                                 rule=rule, floors_of=base_analyses))
        return cache[id(fit)]
    return judged


__all__ = ["FLOOR_MEASURES", "judge", "project", "smooth_input_basis", "noise_levels", "input_excess",
           "expected_for_noise"]
