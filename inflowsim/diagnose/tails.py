"""Upper tails of the chi-square and F distributions and the binomial
probabilities, as ``scipy.stats`` gives them (``chi2.sf``, ``chi2.logsf``, ``f.sf``,
``binom.pmf``) through the same special functions (``chdtrc``, ``fdtrc``,
``_binom_pmf``), without importing ``scipy.stats``: that import was a third of a
diagnosis command's start (its docstring machinery and every distribution; 0.6 s
of the 4 s ``diagnose --model basic`` on the README's record, where a boundary
likelihood-ratio test asks for the binomial weights).
The same numbers, bit for bit (``tests/test_same_numbers.py``).
"""
from __future__ import annotations

import numpy as np
from scipy import special


def _out(a):
    a = np.asarray(a, dtype=float)
    return a[()] if a.ndim == 0 else a


def chi2_sf(x, df):
    """``P(X > x)``, ``X`` chi-square with ``df`` degrees of freedom; 1 for ``x <= 0``,
    NaN for ``df <= 0``."""
    x = np.asarray(x, dtype=float)
    df = np.asarray(df, dtype=float)
    with np.errstate(invalid="ignore"):
        out = np.where(x <= 0, 1.0, special.chdtrc(df, x))
    return _out(np.where(df > 0, out, np.nan))


def chi2_logsf(x, df):
    """``ln P(X > x)`` (:func:`chi2_sf`): 0 for ``x <= 0``; above the median the log
    of the tail, below it ``log1p`` of minus the distribution function (accurate
    near 0), as ``scipy.stats`` takes it."""
    x = np.asarray(x, dtype=float)
    df = np.asarray(df, dtype=float)
    median = 2 * special.gammaincinv(df / 2, 0.5)
    with np.errstate(divide="ignore", invalid="ignore"):
        inner = np.where(x > median, np.log(special.chdtrc(df, x)),
                         np.log1p(-special.chdtr(df, x)))
        out = np.where(x <= 0, 0.0, inner)
    return _out(np.where(df > 0, out, np.nan))


def f_sf(x, dfn, dfd):
    """``P(F > x)``, ``F`` with ``(dfn, dfd)`` degrees of freedom; 1 for ``x <= 0``."""
    x = np.asarray(x, dtype=float)
    dfn = np.asarray(dfn, dtype=float)
    dfd = np.asarray(dfd, dtype=float)
    with np.errstate(invalid="ignore"):
        out = np.where(x <= 0, 1.0, special.fdtrc(dfn, dfd, x))
    return _out(np.where((dfn > 0) & (dfd > 0), out, np.nan))


def f_logsf(x, dfn, dfd):
    """``ln P(F > x)`` (:func:`f_sf`, scalars): the log of the tail where it is
    above ``1e-290``; below, where ``fdtrc`` underflows, the leading term of the
    incomplete beta function ``I_z(a, b) ~ z^a (1 - z)^b / (a B(a, b))`` with ``z =
    dfd / (dfd + dfn x)``, ``a = dfd / 2``, ``b = dfn / 2`` (its relative error
    ``O(z)``, below 1e-4 there)."""
    p = float(f_sf(x, dfn, dfd))
    if p > 1e-290 or not np.isfinite(p):
        return float(np.log(p)) if p > 0 else -np.inf
    a, b = 0.5 * dfd, 0.5 * dfn
    z = dfd / (dfd + dfn * float(x))
    return float(a * np.log(z) + b * np.log1p(-z) - np.log(a) - special.betaln(a, b))


def binom_pmf(k, n, p):
    """``P(K = k)``, ``K`` binomial with ``n`` trials of probability ``p`` (integer
    ``0 <= k <= n``, ``0 <= p <= 1``: the mixture weights of a boundary test), as
    ``scipy.stats.binom.pmf`` takes it from SciPy's ``_binom_pmf`` (Boost's), or
    from ``scipy.stats`` itself where this SciPy has no such function."""
    try:
        from scipy.special._ufuncs import _binom_pmf
    except ImportError:                   # another SciPy: its own route
        from scipy import stats
        return stats.binom.pmf(k, n, p)
    return _out(_binom_pmf(np.asarray(k, dtype=float), np.asarray(n, dtype=float),
                           np.asarray(p, dtype=float)))


__all__ = ["chi2_sf", "chi2_logsf", "f_sf", "f_logsf", "binom_pmf"]
