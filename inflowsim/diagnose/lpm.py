"""The sensor noise *in* the band, whatever its colour, without a parametric model.

The floor of :func:`inflowsim.diagnose.failures.noise_floor` is measured above the band,
where the rotor barely answers, and carried into the band as white noise.  A
sensor whose noise is louder in the band than above it (a low-pass in the data
system, turbulence seen by the flap) then puts the whole band above that floor,
and every test against it (level, the share of the excess a candidate explains)
measures the noise as much as the model.

The local polynomial method (Pintelon, Schoukens, Vandersteen and Barbe,
"Estimation of nonparametric noise and FRF models for multivariable systems",
MSSP 24, 2010) estimates the noise power at each transform bin from the record
alone: over ``2 n + 1`` neighbouring bins the output transform is regressed on
the input transforms times a polynomial of degree ``R`` in the bin offset (a
smooth frequency response) plus a polynomial alone (the transient: the finite
transform's end effects, smooth in frequency); what the regression leaves,
divided by its degrees of freedom, is the noise power at that bin.  It needs no
model of the rotor, so model error does not raise it.

Its estimates scatter (a few degrees of freedom per bin), so the level carried
into the band is their smooth trend: ``ln`` of the estimates fitted by a line in
``f`` from the band's lower edge to ``Rule.lpm_span`` times its upper edge, scaled so
that its mean matches theirs.  Measured on 16 null records per kind (8 seeds at
64 and 256 Hz, 3 channels each): over the band it is 0.76-1.46 times the noise's
expected level for white noise and 0.74-1.41 for a 2 Hz low-pass (a quadratic
in ``ln f``, which the few low-frequency bins leave loose, reached 3.3).

The diagnosis uses it to *check* the white-noise floor
(``Rule.coloured``, :mod:`inflowsim.diagnose.rule`): a record with coloured noise is
reported, and its candidates are judged on the input-correlated excess
(:mod:`inflowsim.diagnose.excess`).  It is not used as the floor: its scatter
(about 20 % per channel) is larger than what the weakest effects add, and as
the floor it lost the paper's third effect under strong coloured noise
(``bench/README.md``).
"""
from __future__ import annotations

import numpy as np

from .rule import DEFAULT_RULE, Rule

#: Half-width [bins] and degree of the local polynomial.
LPM_HALF, LPM_DEGREE = 8, 1
#: Bins whose local regressions are solved together.
_BLOCK = 2048


def local_polynomial_noise(Z, U, half=LPM_HALF, degree=LPM_DEGREE) -> np.ndarray:
    """Noise power at each bin ``(nf, p)`` of outputs ``Z`` ``(nf, p)`` regressed
    locally on inputs ``U`` ``(nf, m)`` (consecutive bins of one grid); ``nan``
    within ``half`` bins of either end and where no degree of freedom is left."""
    Z, U = np.asarray(Z), np.asarray(U)
    nf, p = Z.shape
    out = np.full((nf, p), np.nan)
    j = np.arange(-half, half + 1) / half
    P = np.vander(j, degree + 1, increasing=True)
    scale = np.abs(U).max(axis=0)
    U = U[:, scale > 0] / scale[scale > 0]
    width = 2 * half + 1
    # the windows' regressors all at once, a block of bins at a time (a 2-hour
    # record holds tens of thousands of bins): batched SVDs instead of a loop, one
    # per window (its singular values give the rank, its left vectors the span)
    for start in range(half, nf - half, _BLOCK):
        ks = np.arange(start, min(start + _BLOCK, nf - half))
        idx = ks[:, None] + np.arange(-half, half + 1)[None, :]          # (b, width)
        Uw = U[idx]                                                       # (b, width, m)
        X = np.concatenate([np.broadcast_to(P, (ks.size,) + P.shape).astype(complex),
                            (Uw[:, :, :, None] * P[None, :, None, :]).reshape(
                                ks.size, width, -1)], axis=2)
        # a block's arrays (tens of MB) are freed as soon as they are used, before
        # the next block's are made
        del Uw
        Q, sv = np.linalg.svd(X, full_matrices=False)[:2]    # (the right vectors freed)
        del X
        r = np.sum(sv > 1e-9 * sv[:, :1], axis=1)
        for rank in np.unique(r):
            if rank >= width:         # no degree of freedom left: no estimate
                continue
            sel = np.flatnonzero(r == rank)
            Qr = (Q if sel.size == ks.size else Q[sel])[:, :, :rank]
            Zw = Z[idx[sel]]                                              # (s, width, p)
            e = Zw - Qr @ (np.conj(np.swapaxes(Qr, 1, 2)) @ Zw)
            out[ks[sel]] = np.sum(np.abs(e) ** 2, axis=1) / (width - rank)
            del Qr, Zw, e
        del Q
    return out


def in_band_noise(record, inputs, band_hz, hold, f_band,
                  rule: Rule = DEFAULT_RULE) -> np.ndarray | None:
    """The trend of the local-polynomial noise estimates at ``f_band``, ``(3, nf)``
    in the units of the band fit's transforms; ``None`` where the record holds too
    few bins for it.

    Parameters
    ----------
    record : Record
        The record.
    inputs : sequence of str
        The inputs the outputs are regressed on.
    band_hz : (float, float)
        Analysis band [Hz]; the trend is fitted from its lower edge to
        ``rule.lpm_span`` times its upper edge (``rule.nyquist_share`` of Nyquist
        at most).
    hold : {"continuous", "zoh", "foh"} or None
        Intersample behaviour of the inputs.
    f_band : array_like
        Frequencies [Hz] where the trend is evaluated.
    rule : Rule
        The settings (:class:`~inflowsim.diagnose.rule.Rule`).
    """
    from ..identify.transform import record_spectra
    hi = min(rule.lpm_span * band_hz[1], rule.nyquist_share * 0.5 / record.dt)
    if (hi - band_hz[0]) * record.duration < 2 * LPM_HALF + 21:
        return None
    sp = record_spectra(record, inputs, (band_hz[0], hi), hold=hold, require_motion=False,
                        keep=False)
    est = local_polynomial_noise(sp.Z, sp.U)
    ok = np.all(np.isfinite(est) & (est > 0), axis=1)
    if ok.sum() < 20:
        return None
    A = np.vander(sp.f_hz[ok], 2)
    xb = np.vander(np.asarray(f_band, dtype=float), 2)
    out = []
    for c in range(est.shape[1]):
        coef, *_ = np.linalg.lstsq(A, np.log(est[ok, c]), rcond=None)
        trend = np.exp(A @ coef)
        out.append(np.exp(xb @ coef) * np.mean(est[ok, c] / trend))
    return np.array(out)


__all__ = ["local_polynomial_noise", "in_band_noise"]
