"""Frequency-domain output-error estimation, Eqs. (10)-(12) (``model.md`` section 7).

Cost (12): ``J = sum_w [eps^H S^-1 eps + ln|S|]`` over the band, ``eps`` the measured
minus predicted flap transforms (three channels; the inflow states are not
measured), summed over records.  ``S`` (3x3 Hermitian, one per record: records may
differ in length, transform scaling and noise) is estimated with the parameters
by relaxation: for fixed parameters ``S = mean eps eps^H``; for fixed ``S`` a
Levenberg-Marquardt step on the ``S^-1/2``-weighted residuals; ``S`` is re-estimated
after every accepted step (:func:`_lm`).  End effects are eliminated inside every evaluation
(:mod:`.freqmodel`, :mod:`.problem`).

Starting points: a user ``start`` where given, the theory values
(:func:`inflowsim.model.presets.theory_parameters`), the paper's table for the matching
preset, and theory with slow inflow (time constants 20 azimuth rad: from the
apparent-mass values the search can fall into a quasi-static local minimum).
Each start gets a short run (``SHORT_RUN`` = 6 iterations); the lowest cost
continues to convergence; every start's cost is reported (``FitResult.starts``).

Bounds: the Cramer-Rao bound of the complex Gaussian likelihood,
``cov = M^-1`` with ``M = 2 Re sum_w G^H S^-1 G`` (``G = d eps / d theta``; the 2
because a circular complex residual of covariance ``S`` carries the information
of two real ones of covariance ``S/2``), the nuisance end terms accounted for by
projection (the Schur complement of the joint information), and widened by the
finite-sample factor of ``S`` estimated from the record's own bins (per record
``(nu + m) / (nu - m)`` on the variance, ``nu`` the bins' degrees of freedom, ``m = 3``:
:func:`weight_factors`, ``model.md`` section 7).  A second bound
(``sigma_colored``) corrects for coloured residuals, after Morelli and Klein: the
sandwich ``M^-1 V M^-1`` with ``V`` from the residuals' local spectrum and their
correlation across neighbouring frequencies (:func:`_colored`).  A third
(``sigma_robust``) is the misspecification-robust (Huber-White) sandwich of the
per-frequency scores with a Newey-West band over neighbouring frequencies
(:func:`_robust`): it holds whatever the residuals' distribution, level across
the band or correlation between neighbouring bins, but, like every bound read
from the residual, it bounds the scatter of the estimate about the value the
structure converges to, not the bias an incomplete structure adds to it
(``model.md`` section 7).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..model.build import build_model
from ..model.effects import CATALOGUE
from ..model.presets import preset_parameters, theory_parameters
from ..model.structure import Structure
from ..progress import bar
from .problem import Problem, unstack
from .results import FitResult, RecordFit, channel_fit
from .transform import DEFAULT_BAND, as_record, record_spectra

#: Iterations given to every starting point before the best one continues.
SHORT_RUN = 6
#: Cost fall [-] (of (12), a log-likelihood) of an accepted step below which the search
#: is near its minimum and starts its secant estimate of the curvature the
#: Gauss-Newton term lacks (:func:`_lm`): the relaxation's steps until then, number
#: for number.
NEAR = 0.01
#: Half-width (frequencies) of the local residual spectrum in the coloured bound.
HALF_WINDOW = 3
#: A correlation this close to 1 is reported.
CORRELATION_LIMIT = 0.98
#: Relative eigenvalue of the scaled information matrix below which a direction
#: is "not determined".
RANK_TOL = 1e-9
#: A record's residual covariance ``S`` more ill-conditioned than this lies in
#: fewer than three flap directions (noisy records: 3-12; noise-free with model
#: error: 1e6, ``bench/identify.md``, "Joint single-axis records") ...
S_CONDITION_LIMIT = 1e4
#: ... unless it is rounding: its largest eigenvalue below this share of the
#: measured flap power per bin (an exact fit of noise-free data).
S_ROUNDING = 1e-12


@dataclass
class _State:
    theta: np.ndarray
    resp: list
    nus: list
    bases: list
    r: list
    S: list
    weights: list

    @property
    def rr(self) -> float:
        return float(sum(x @ x for x in self.r))


def fit_state(prob, theta, S, weights=None):
    """The fit's state at ``theta``: the model's responses, the end-effect nuisance
    solved for by variable projection, the residuals and their weights.

    Parameters
    ----------
    prob : Problem
        The identification problem (:class:`inflowsim.identify.problem.Problem`).
    theta : ndarray
        Free parameters, in ``prob.free`` order.
    S : list of ndarray
        Each record's residual spectral density ``S`` (3 x 3) [rad^2].
    weights : list of ndarray, optional
        ``Problem.weight`` of each ``S`` when already at hand (another state's of
        the same ``S``); computed from ``S`` otherwise.

    Returns
    -------
    _State
        ``theta``, ``resp``, ``nus``, ``bases``, ``r`` (residuals), ``S``, ``weights``.
    """
    if weights is None:
        weights = [Problem.weight(s) for s in S]
    resp = prob.responses(theta)
    sol = prob.solve_nuisance(resp, weights)
    return _State(theta, resp, [s[0] for s in sol], [s[1] for s in sol],
                  [s[2] for s in sol], list(S), weights)


def _relax_S(prob, theta, S=None, rounds=4):
    """Nuisance and ``S`` for fixed parameters (a few alternations)."""
    if S is None:
        S = [np.eye(3) for _ in prob.spectra]
    st = fit_state(prob, theta, S)
    for _ in range(rounds):
        S = prob.estimate_S(prob.eps(st.resp, st.nus))
        st = fit_state(prob, theta, S)
    return st


def _reweighted(prob, st, S=None):
    """The state with ``S`` re-estimated from its own residuals (relaxation step;
    ``S`` that estimate when already made, :func:`_concentrated`)."""
    if S is None:
        S = prob.estimate_S(prob.eps(st.resp, st.nus))
    return fit_state(prob, st.theta, S)


def _concentrated(prob, st, with_S=False):
    """Cost (12) with ``S`` at its optimum for these residuals: ``sum n_f ln|S|``
    (plus the constant ``3 n_f``); ``with_S``: ``(cost, S)``."""
    S = prob.estimate_S(prob.eps(st.resp, st.nus))
    c = 3 * prob.n_freq + sum(sp.f_hz.size * float(np.log(np.real(np.linalg.det(x))))
                              for sp, x in zip(prob.spectra, S))
    return (c, S) if with_S else c


def _lm(prob, st, max_iter, report=None):
    """Levenberg-Marquardt on the cost (12) with ``S`` relaxed at every step.

    For fixed ``S`` the step is Gauss-Newton on the ``S^-1/2``-weighted residuals;
    a step is accepted when the cost with ``S`` re-estimated (the concentrated
    cost ``n_f ln|S|``) falls, and ``S`` is then updated: relaxation at every
    iteration.  Positive parameters (:meth:`Problem.log_mask`) step in ``log``; the
    others are clipped to their ranges; a step that makes the model invalid is
    rejected like one that raises the cost.

    The gradient ``J^T r`` at the re-estimated ``S`` is the concentrated cost's,
    but ``J^T J`` is not its curvature: re-estimating ``S`` takes a share of the
    curvature where ``S`` and the parameters are coupled (model error), and
    residuals of a structure that lacks an effect add second derivatives.  Near
    the minimum the relaxation then converges only linearly, its rate that share
    (0.9 for the default record's candidates: 60-100 iterations creeping at a cost
    fall of 1e-5 a step, stopped short of the minimum by about ten times the last
    fall).  The rule: once an accepted step lowers the cost by less than
    :data:`NEAR`, every accepted step updates a secant estimate ``A`` of the
    curvature ``J^T J`` lacks, ``(J^T J + A) s = y`` for the step ``s`` and the
    gradient's change ``y`` (the symmetric, sized update of Dennis, Gay and Welsch
    1981, NL2SOL, :func:`_secant`), and the next step takes the curvature, ``J^T J``
    or ``J^T J + A``, whose quadratic model predicted the last step's cost change
    more closely (NL2SOL's choice; ``J^T J + A`` only where it is positive definite
    with the damping, else the damping grows).  Before that the steps are the
    relaxation's, number for number.  The stop: a step below ``1e-9`` of each
    parameter's typical size, or a fall below ``1e-7 n_f`` at small damping; once
    the secant term exists, two such falls in a row (its steps are uneven: one
    small fall between larger ones is not the minimum).
    Returns ``(state, cost, iterations, converged)``.
    """
    lo, hi = prob.bounds()
    logm = prob.log_mask()
    lam = 1e-3
    c = _concentrated(prob, st)
    tol = 1e-7 * max(1.0, prob.n_freq)
    # secant term, last step (in the search's coordinates) and gradient, which
    # curvature the next step takes, near the minimum yet
    A, last, aug, near = None, None, False, False
    small_now = False
    for it in range(1, max_iter + 1):
        # forward differences suffice for the search; bounds use central ones
        J = np.vstack(prob.jacobian(st.theta, st.weights, st.nus, st.bases, central=False))
        J = J * np.where(logm, st.theta, 1.0)          # d r / d log(theta)
        r = np.concatenate(st.r)
        g = J.T @ r
        H = J.T @ J
        if near:
            A = _secant(A, H, g, *last)
        B = H + A if aug else H
        d = np.diag(H).copy()
        dmax = max(d.max(), 1e-300)
        d = np.where(d > 1e-12 * dmax, d, dmax * 1e-12)
        accepted = False
        at_lo, at_hi = st.theta <= lo, st.theta >= hi
        while lam < 1e12:
            try:
                delta = _step(B, g, lam * d, at_lo, at_hi, definite=aug)
            except np.linalg.LinAlgError:
                lam *= 10
                continue
            step = np.where(logm, 0.0, delta)
            grow = np.exp(np.clip(np.where(logm, delta, 0.0), -5, 5))
            tn = np.clip(np.where(logm, st.theta * grow, st.theta + step), lo, hi)
            try:
                # the trial keeps the state's S, and so its weights
                sn = fit_state(prob, tn, st.S, st.weights)
            except InputError:            # outside a parameter's range / unstable build
                lam *= 10
                continue
            cn, s_new = _concentrated(prob, sn, with_S=True)
            if cn < c:
                accepted = True
                break
            lam *= 10
        if not accepted:
            return st, c, it, True       # no descent left: at a minimum to precision
        small_step = np.all(np.abs(tn - st.theta) <= 1e-9 * prob.typical(tn))
        small_drop = (c - cn) <= tol
        was_small, small_now = small_now, small_drop
        moved = tn - st.theta
        moved[logm] = np.log(tn[logm] / st.theta[logm])
        if A is not None:
            # the curvature whose model predicted this step's change of the cost
            # (twice the model's: g and B are of |r|^2 / 2) more closely
            q = 2 * float(g @ moved) + float(moved @ H @ moved)
            aug = abs(q + float(moved @ A @ moved) - (cn - c)) < abs(q - (cn - c))
        last = (moved, g)
        near = near or (c - cn) < NEAR
        st, c = _reweighted(prob, sn, s_new), cn
        lam = max(lam / 10, 1e-9)
        if report:
            report(it, c)
        if small_step or (small_drop and lam <= 1e-2 and (A is None or was_small)):
            return st, c, it, True
    return st, c, max_iter, False


def _secant(A, H, g, s, g_old):
    """The secant estimate of the curvature the Gauss-Newton term lacks, after a step.

    ``A`` (``None``: zero) updated so that ``(H + A) s = y``, ``y = g - g_old`` the
    change of the gradient (half the cost's, as ``g = J^T r``) along the step ``s``
    (the search's coordinates), ``H = J^T J`` at the step's end: first sized down to
    what the step measured (``A <- min(1, |s^T y#| / |s^T A s|) A``, ``y# = y - H
    s``), then the symmetric rank-two update of Dennis, Gay and Welsch (1981, *ACM
    TOMS* 7, 348-368, NL2SOL)

        ``A + (v y^T + y v^T) / (y^T s) - (v^T s) y y^T / (y^T s)^2``, ``v = y# - A s``.

    A step along which the gradient did not grow (``y^T s <= 0``) leaves ``A``.
    """
    y = g - g_old
    ys = float(y @ s)
    if not (np.isfinite(ys) and ys > 0):
        return A
    if A is None:
        A = np.zeros_like(H)
    ysh = y - H @ s
    sas = float(s @ A @ s)
    if sas != 0:
        A = A * min(1.0, abs(float(s @ ysh)) / abs(sas))
    v = ysh - A @ s
    return A + (np.outer(v, y) + np.outer(y, v)) / ys - (float(v @ s) / ys ** 2) * np.outer(y, y)


def _step(H, g, damp, at_lo, at_hi, definite=False):
    """The damped Gauss-Newton step ``(H + diag(damp)) delta = -g``, with every
    parameter that sits at a range limit and that the step would push past it held
    (its row and column dropped, its step zero; repeated while another one is
    pushed out).

    A step clipped at the limit moves the held parameter by nothing while the
    others move as if it had moved: a poor step, refused at small damping and
    taken at large, so the damping never falls and the search crawls to its
    iteration limit (a candidate effect whose best value is its neutral boundary,
    as ``servo_tau`` on a record without servos).  Where no parameter is pushed
    past a limit it is the plain solve, number for number.  ``definite``: ``H`` may
    be indefinite (with the secant term, :func:`_lm`), and a damped matrix that is
    not positive definite raises :class:`numpy.linalg.LinAlgError` (Cholesky)."""
    solve = _solve_definite if definite else np.linalg.solve
    delta = solve(H + np.diag(damp), -g)
    held = (at_lo & (delta < 0)) | (at_hi & (delta > 0))
    while held.any():
        free = ~held
        delta = np.zeros_like(g)
        if free.any():
            sub = np.ix_(free, free)
            delta[free] = solve(H[sub] + np.diag(damp[free]), -g[free])
        more = (at_lo & (delta < 0)) | (at_hi & (delta > 0))
        if not more.any():
            break
        held |= more
    return delta


def _solve_definite(M, b):
    """``M^-1 b`` of a positive-definite ``M`` (Cholesky; :class:`numpy.linalg.LinAlgError`
    otherwise)."""
    L = np.linalg.cholesky(M)
    return np.linalg.solve(L.T, np.linalg.solve(L, b))


def fit_from(prob, theta, max_iter=100, report=None):
    """Fit from ``theta``: ``S`` from the start's residuals, then Levenberg-Marquardt.

    Parameters
    ----------
    prob : Problem
        The identification problem (:class:`inflowsim.identify.problem.Problem`).
    theta : ndarray
        Start of the free parameters, in ``prob.free`` order.
    max_iter : int
        Iterations at most [-] (0: the start's state and cost only).
    report : callable, optional
        ``report(iteration, cost)`` after each step.

    Returns
    -------
    (state, cost, iterations, converged)
        The fit's state (:func:`fit_state`), its cost (12), the iterations made and
        whether they converged.
    """
    st = _relax_S(prob, theta, rounds=1)
    st, j, it, ok = _lm(prob, st, max_iter, report)
    return st, prob.cost(st.r, st.S), it, ok


# -- bounds and failure modes ---------------------------------------------------------
def _information(prob, st):
    blocks = prob.jacobian(st.theta, st.weights, st.nus, st.bases, central=True)
    J = np.vstack(blocks)
    return 2.0 * J.T @ J, blocks


def _colored(prob, st, blocks, cov, grow=None):
    """Residual-spectrum sandwich for coloured residuals (after Morelli and Klein).

    ``cov_c = M^-1 V M^-1`` with ``V = 2 Re sum_k sum_j w_j G_k^H R_k(j) G_{k-j}``:
    ``R_k(j)`` the weighted residuals' correlation at lag ``j`` of the frequency
    index, averaged over the ``2 HALF_WINDOW + 1`` frequencies around ``k`` (a local
    residual spectrum, so noise whose level changes across the band is followed),
    ``w_j`` a Bartlett taper truncated at ``|j| <= L = ceil(nf^(1/3))`` (summing every
    lag of the sample correlation would cancel the term being estimated: at the
    optimum the residuals are orthogonal to the sensitivities).  For white
    residuals ``V = M`` and the bound is the Cramer-Rao one.
    """
    V = np.zeros_like(cov)
    for sp, blk, r, gr in zip(prob.spectra, blocks, st.r, grow or [1.0] * len(blocks)):
        Vr = np.zeros_like(cov)
        nf = sp.f_hz.size
        lmax = int(np.ceil(nf ** (1 / 3)))
        h = blk.shape[0] // 2
        G = (blk[:h] + 1j * blk[h:]).reshape(nf, 3, -1)
        e = unstack(r, nf)
        # conjugates once, and the bins k (and k - j) as slices of them, not index
        # arrays: the same numbers in the same layout, without a copy of G per lag
        # (a 2-hour record's G is 2 MB a parameter, 45 lags)
        ec, Gc = e.conj(), G.conj()
        for j in range(-lmax, lmax + 1):
            k0, k1 = max(j, 0), nf + min(j, 0)           # k = k0 ... k1 - 1
            size = k1 - k0
            prod = e[k0:k1][:, :, None] * ec[k0 - j:k1 - j][:, None, :]   # e_k e_{k-j}^H
            # local mean over a window of frequencies (cumulative sums)
            cs = np.concatenate([np.zeros((1, 3, 3), complex), np.cumsum(prod, axis=0)])
            lo = np.clip(np.arange(size) - HALF_WINDOW, 0, size)
            hi = np.clip(np.arange(size) + HALF_WINDOW + 1, 0, size)
            R = (cs[hi] - cs[lo]) / (hi - lo)[:, None, None]
            w = 1 - abs(j) / (lmax + 1)
            # sum_k G_k^H R_k G_{k-j} as one product over (k, i) (BLAS, not einsum)
            RG = (R @ G[k0 - j:k1 - j]).reshape(-1, G.shape[2])
            Vr += 2.0 * w * np.real(Gc[k0:k1].reshape(-1, G.shape[2]).T @ RG)
        V += gr * Vr
    return cov @ V @ cov


def _robust(prob, st, blocks, cov, grow=None):
    """Huber-White sandwich of the per-frequency scores, Newey-West band.

    ``cov_r = M^-1 V M^-1`` (Huber 1967; White 1982, *Econometrica* 50, 1-25) with
    the per-bin score ``s_k = 2 Re(G_k^H e~_k)`` (``G_k = d e_k / d theta`` of the
    weighted, nuisance-projected residual ``e_k`` at frequency ``k``; the cost's
    gradient is ``-sum_k s_k``) and

        ``V = sum_k s_k s_k^T + sum_{j=1}^{L} w_j (Gamma_j + Gamma_j^T)``,
        ``Gamma_j = sum_k s_k s_{k-j}^T``, ``w_j = 1 - j / (L + 1)``,

    the Bartlett-weighted band of Newey and West (1987, *Econometrica* 55,
    703-708) over neighbouring bins of one record; records add.  ``L`` spans the
    main lobe of the record's window, ``L = ceil(1 / (N dt df))`` (``df`` the
    spacing of the frequencies used): 1 on the record's own grid, more for a
    finer ``grid_hz``, whose neighbouring bins share noise.  ``e~_k = e_k /
    sqrt(1 - h_k)`` is the residual corrected for its leverage ``h_k`` (the
    bin's mean diagonal of the hat matrix of the sensitivities and the end-effect
    columns; MacKinnon and White 1985, *J. Econometrics* 29, 305-325, "HC2"): a
    fit pulls the residual towards zero most where the data inform it most.
    For circular white residuals of covariance ``S``, ``E s_k s_k^T = M_k`` and
    the bins are independent, so ``V -> M`` and ``cov_r -> M^-1``, the
    Cramer-Rao bound.  Unlike :func:`_colored` it uses each bin's own residual,
    not a local average, so it needs no model of how the residual's level
    varies across the band.
    """
    V = np.zeros_like(cov)
    for sp, blk, r, Q, gr in zip(prob.spectra, blocks, st.r, st.bases,
                                 grow or [1.0] * len(blocks)):
        nf = sp.f_hz.size
        df = np.min(np.diff(sp.f_hz)) if nf > 1 else np.inf
        lmax = int(np.ceil(1.0 / (sp.n_samples * sp.dt * df) - 1e-9)) if nf > 1 else 0
        lmax = min(max(lmax, 1), max(nf - 1, 0))
        # leverage: diagonal of J (J^T J)^-1 J^T (J^T J = M / 2) plus the nuisance's Q Q^T
        hd = np.einsum("ip,pq,iq->i", blk, 2.0 * cov, blk) + np.einsum("iq,iq->i", Q, Q)
        h = blk.shape[0] // 2
        hk = (hd[:h] + hd[h:]).reshape(nf, 3).sum(axis=1) / 6.0
        G = (blk[:h] + 1j * blk[h:]).reshape(nf, 3, -1)
        e = unstack(r, nf) / np.sqrt(np.clip(1.0 - hk, 1e-3, 1.0))[:, None]
        s = 2.0 * np.real(np.einsum("kip,ki->kp", G.conj(), e))      # (nf, p)
        Vr = s.T @ s
        for j in range(1, lmax + 1):
            g = s[j:].T @ s[:-j]
            Vr += (1.0 - j / (lmax + 1)) * (g + g.T)
        V += gr * Vr
    return cov @ V @ cov


def null_directions(M):
    """``(undetermined indices, flat directions)`` of an information matrix: the
    flat directions ``(relative eigenvalue, unit vector)`` of the scaled ``M`` at
    ``RANK_TOL`` of the largest or below, and every parameter with no information or
    a weight above 0.3 in one of them."""
    p = M.shape[0]
    dg = np.diag(M).copy()
    scale = np.sqrt(np.where(dg > 0, dg, 1.0))
    w, v = np.linalg.eigh(M / np.outer(scale, scale))
    top = max(w.max(), 1e-300)
    dead = set(np.flatnonzero(dg <= 1e-14 * max(dg.max(), 1e-300)).tolist())
    flat = [(float(max(w[i], 0.0) / top), v[:, i]) for i in range(p) if w[i] < RANK_TOL * top]
    for _, vec in flat:
        dead.update(np.flatnonzero(np.abs(vec) > 0.3).tolist())
    return sorted(dead), flat


def weight_dof(rows, S, lost):
    """Each record's degrees of freedom ``nu`` for its residual covariance ``S`` and
    ``S``'s dimension ``m``: ``[(nu, m)]``; ``rows`` each record's real residual
    rows (``2 m n``), ``lost`` the real dimensions the fit took from them all.

    A record's ``S`` (``m x m`` Hermitian, ``m = 3`` flap channels) is estimated
    from its ``n`` bins' residuals, which lost ``lost`` real dimensions of all
    records' ``n_data`` to the fit (parameters and end-effect nuisance); with the
    loss shared in proportion, ``nu = (rows / 2 m) (n_data - lost) / n_data``
    (``rows = 2 m n``): the bins' count less the record's share of the loss in
    complex ``m``-vectors, so that ``nu S~ / n`` (``S~`` the bias-corrected ``S``)
    is complex Wishart with ``nu`` degrees of freedom (``model.md`` section 7).
    """
    n_data = sum(rows)
    keep = max(n_data - lost, 1) / max(n_data, 1)
    out = []
    for n, s in zip(rows, S):
        m = np.asarray(s).shape[0]
        out.append((n / (2.0 * m) * keep, m))
    return out


def weight_factors(dofs):
    """Per record ``(c, g)`` of the finite-sample bound (``model.md`` section 7).

    ``c = (nu - m) / nu``: the information read with the estimated ``S`` is
    ``nu / (nu - m)`` times the true one on average (the mean of a complex inverse
    Wishart matrix), ``c`` undoes it; ``g = 1 + m / nu``: weighting by the estimated
    ``S`` instead of the true one adds ``m / nu`` of the information's inverse to
    the estimates' covariance (first order in ``1 / nu``).  A record with ``nu <= m``
    does not determine its ``S`` (``c = 0``: its information is not counted)."""
    return [((nu - m) / nu if nu > m else 0.0, 1.0 + m / nu if nu > 0 else 1.0)
            for nu, m in dofs]


def finite_sample_covariance(Ms, factors):
    """``A^-1 B A^-1`` with ``A = sum_r c_r M_r``, ``B = sum_r c_r g_r M_r`` over the
    records' information matrices ``Ms`` (:func:`weight_factors`); for one record
    ``M^-1 (nu + m) / (nu - m)``.  Raises :class:`numpy.linalg.LinAlgError` where
    ``A`` is singular (no record determines its ``S``)."""
    A = sum(c * M for M, (c, g) in zip(Ms, factors))
    B = sum(c * g * M for M, (c, g) in zip(Ms, factors))
    Ai = np.linalg.inv(A)
    return Ai @ B @ Ai


def _record_rows(prob, st):
    """``(rows, lost)`` of a fit's state for :func:`weight_dof`: each record's real
    residual rows (``2 m n``) and the real dimensions the fit took (its free
    parameters and the end-effect nuisance)."""
    lost = len(prob.free) + sum(Q.shape[1] for Q in st.bases)
    rows = [2 * np.asarray(s).shape[0] * sp.f_hz.size for sp, s in zip(prob.spectra, st.S)]
    return rows, lost


def lr_calibration(prob, st) -> tuple:
    """``(kappa, d)``: how a likelihood-ratio statistic against this fit is read
    (``model.md`` section 7): ``2 (J_0 - J) / (kappa k)`` as ``F(k, d)``, ``k`` the
    parameters it tests.

    The cost (12) is the likelihood with each record's ``S`` estimated from its own
    bins (the concentrated likelihood), and its statistics are larger than
    chi-square's: ``S`` is estimated from residuals that lost the fitted dimensions
    (``n_data / (n_data - lost)``), and weighting by an estimated ``S`` adds ``m / nu``
    (:func:`weight_factors`'s ``g``; over records in proportion to their rows).
    Their tail is ``F``'s with ``d = 2 (nu - m + 1)``: the information along one
    direction read with a complex Wishart ``S`` of ``nu`` degrees of freedom is the
    true one times ``chi2(2 (nu - m + 1)) / (2 (nu - m + 1))`` (over records,
    Satterthwaite's combination in proportion to their rows).  On 300 null records
    of the virtual flight test (64 Hz, 37 bins: ``kappa`` 1.19, ``d`` 64) the tested
    atoms' statistics read as chi-square passed ``1e-2`` 2.4 times and ``1e-3`` 4.4
    times as often as said; read so 1.04 and 1.5 times
    (``bench/studies/lr-calibration.md``).
    A fit whose records do not determine their ``S`` gives ``(1, inf)``:
    chi-square."""
    rows, lost = _record_rows(prob, st)
    return lr_calibration_of(rows, st.S, lost)


def lr_calibration_of(rows, S, lost) -> tuple:
    """:func:`lr_calibration` from each record's real residual ``rows`` (``2 m n``),
    its ``S`` and the real dimensions ``lost`` to the fit (:func:`weight_dof`)."""
    n_data = sum(rows)
    dofs = weight_dof(rows, S, lost)
    # the records that determine their S (c > 0), each with its g
    used = [(r, nu, m, g) for r, (nu, m), (c, g) in zip(rows, dofs, weight_factors(dofs))
            if c > 0.0]
    if not used:
        return 1.0, math.inf
    a = sum(r for r, _, _, _ in used)
    g = sum(r * gr for r, _, _, gr in used) / a
    d = a * a / sum(r * r / (2.0 * (nu - m + 1)) for r, nu, m, _ in used)
    return float(n_data / max(n_data - lost, 1) * g), float(d)


def covariances(prob, st):
    """Cramer-Rao covariances of the free parameters at a fit's state, over the
    directions the records determine.

    Parameters
    ----------
    prob : Problem
        The identification problem.
    st : _State
        The state at the estimate (:func:`fit_state`).

    Returns
    -------
    cov, cov_coloured, cov_robust : ndarray
        White-residual, coloured-residual (sandwich) and robust covariances, in
        ``prob.free`` order (NaN where undetermined), scaled for the degrees of
        freedom the fit took and for ``S`` estimated from each record's bins
        (:func:`finite_sample_covariance`; the sandwiches ``g`` only).
    dead : list of int
        Indices of the parameters the records do not determine.
    n_null : int
        Dimension of the information matrix's null space.
    """
    M, blocks = _information(prob, st)
    p = M.shape[0]
    dead, null_dirs = null_directions(M)
    ok = np.array([i for i in range(p) if i not in dead], dtype=int)
    cov = np.full((p, p), np.nan)
    cov_c = np.full((p, p), np.nan)
    cov_r = np.full((p, p), np.nan)
    if ok.size:
        # S is estimated from residuals that lost the fitted degrees of freedom
        # (parameters and end-effect states): scale the bounds back up
        n_data = sum(b.shape[0] for b in blocks)
        lost = ok.size + sum(Q.shape[1] for Q in st.bases)
        dof = n_data / max(n_data - lost, 1)
        sub = np.linalg.inv(M[np.ix_(ok, ok)])
        blocks_ok = [b[:, ok] for b in blocks]
        # S is estimated from each record's few bins: the bound for that (c, g)
        factors = weight_factors(weight_dof([b.shape[0] for b in blocks], st.S, lost))
        try:
            cov[np.ix_(ok, ok)] = finite_sample_covariance(
                [2.0 * b.T @ b for b in blocks_ok], factors) * dof
        except np.linalg.LinAlgError:
            return cov, cov_c, cov_r, list(range(p)), p
        # the sandwiches read the weighting's scale from the residual: only g
        grow = [g for _, g in factors]
        cov_c[np.ix_(ok, ok)] = _colored(prob, st, blocks_ok, sub, grow) * dof
        cov_r[np.ix_(ok, ok)] = _robust(prob, st, blocks_ok, sub, grow) * dof
    return cov, cov_c, cov_r, sorted(dead), len(null_dirs)


def _excitation_hint(prob):
    quiet = []
    for name in prob.structure.inputs:
        idx = prob.structure.inputs.index(name)
        if all(np.max(np.abs(sp.U[:, idx])) == 0 for sp in prob.spectra):
            quiet.append(name)
    return (f"; the records do not excite {', '.join(quiet)} in the band" if quiet else "")


def _warnings(prob, theta, cov, dead, n_null, converged, iterations):
    names = prob.free_names
    out = []
    if not converged:
        out.append(f"not converged after {iterations} iterations: try a start closer to "
                   "the answer (start=...), fit a simpler structure first, or fix the "
                   "poorly determined parameters")
    if dead:
        dn = ", ".join(names[i] for i in dead)
        out.append(f"not determined by the data: {dn} (information matrix rank "
                   f"{len(names) - n_null} of {len(names)}): fix them (--fix NAME) or tie "
                   "them, widen the band, or add excitation" + _excitation_hint(prob))
    sig = np.sqrt(np.diag(cov))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sig, sig)
    p = len(names)
    for i in range(p):
        for j in range(i + 1, p):
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > CORRELATION_LIMIT:
                out.append(f"{names[i]} and {names[j]} are correlated ({corr[i, j]:+.3f}): "
                           "the data barely separate them; fix or tie one, or add "
                           "excitation that moves them differently")
    poor = [names[i] for i in range(p) if np.isfinite(sig[i]) and theta[i] != 0
            and sig[i] > abs(theta[i])]
    if poor:
        out.append(f"poorly determined (1-sigma bound larger than the estimate): "
                   f"{', '.join(poor)}")
    lo, hi = prob.bounds()
    for i in range(p):
        at_lo = np.isfinite(lo[i]) and theta[i] <= lo[i] + 1e-12 * max(1.0, abs(lo[i]))
        if at_lo or (np.isfinite(hi[i]) and theta[i] >= hi[i]):
            out.append(f"{names[i]} = {theta[i]:g} is at the limit of its range: the data "
                       "push it beyond; the structure may lack an effect")
    return out, corr


#: A record whose residual covariance rests on fewer degrees of freedom than this
#: many times its dimension is said to (its bounds widened by 1.5 or more).
FEW_DOF = 3.0


def _few_bins(prob, st) -> list:
    """Records whose bins leave few degrees of freedom for their ``S``: the bounds
    are widened for it (:func:`weight_factors`), or, at ``nu <= m``, the record's
    information is not counted."""
    rows, lost = _record_rows(prob, st)
    out = []
    for sp, (nu, m) in zip(prob.spectra, weight_dof(rows, st.S, lost)):
        if nu <= m:
            out.append(f"{sp.source}: its {sp.f_hz.size} frequencies leave {nu:.1f} "
                       f"degrees of freedom for the {m} x {m} residual covariance, no more "
                       "than its dimension: the record cannot estimate its noise, and its "
                       "information is not counted in the bounds; widen the band or "
                       "lengthen the record")
        elif nu < FEW_DOF * m:
            out.append(f"{sp.source}: its {sp.f_hz.size} frequencies leave {nu:.1f} "
                       f"degrees of freedom for the {m} x {m} residual covariance: the "
                       f"bounds are widened by {np.sqrt((nu + m) / (nu - m)):.2f} for "
                       "the noise estimated from so few, and are themselves uncertain; "
                       "widen the band or lengthen the record")
    return out


def _collapsed_s(spectra, S) -> list:
    """Records whose residual lies almost in one or two flap directions: the
    likelihood then fits the other directions exactly and the bounds shrink to
    nothing, whatever the structure lacks there (noise-free data with model error)."""
    out = []
    for sp, s in zip(spectra, S):
        ev = np.linalg.eigvalsh(np.asarray(s))
        power = float(np.mean(np.abs(sp.Z) ** 2))
        if ev[-1] > S_ROUNDING * power and ev[0] * S_CONDITION_LIMIT < ev[-1]:
            cond = ev[-1] / ev[0] if ev[0] > 0 else float("inf")
            out.append(f"{sp.source}: the residual lies almost in one direction of the "
                       f"three flap channels (its covariance has condition {cond:.1e}): "
                       "the bounds assume noise in every direction, so a response the "
                       "structure lacks is fitted around, not seen, and the bounds are "
                       "too small; typical of noise-free data: check the structure "
                       "(diagnose) or add the measurement's noise")
    return out


# -- public API -----------------------------------------------------------------------
def as_records(records):
    """A list of :class:`~inflowsim.data.record.Record` from one record, a path or a
    list of them (:class:`InputError` for none).

    Parameters
    ----------
    records : Record, path or list of them
        The flight-test records.
    """
    if isinstance(records, (str, bytes)) or not hasattr(records, "__iter__"):
        records = [records]
    records = [as_record(r) for r in records]
    if not records:
        raise InputError("identify: give at least one record")
    return records


def spectra_of(records, structure, band_hz, grid_hz, hold=None):
    """Each record's spectra over the band for ``structure``'s inputs.

    Parameters
    ----------
    records : list of Record
        The records (:func:`as_records`).
    structure : Structure
        The structure whose inputs are transformed.
    band_hz : (float, float) or None
        Analysis band [Hz] (``None``: the default band).
    grid_hz : array_like or None
        Frequencies of the transform [Hz] (``None``: the record's grid in the band).
    hold : {"continuous", "zoh", "foh"}, optional
        Intersample behaviour of the inputs (default each record's own).
    """
    if band_hz is None:
        band_hz = DEFAULT_BAND
    return [record_spectra(r, structure.inputs, band_hz, grid_hz, hold) for r in records]


def _band(spectra):
    return (min(sp.band_hz[0] for sp in spectra), max(sp.band_hz[1] for sp in spectra))


def _check_names(structure, names, what):
    for n in names:
        if n not in structure.parameters:
            raise InputError(f"{what}: {n} is not a parameter of {structure.name} "
                             f"(its parameters: {', '.join(structure.parameters)})")


def _starts(structure, constants, start):
    theory = theory_parameters(structure, constants)
    cands = []
    if start:
        cands.append(("start", {**theory, **start}))
        # an effect started at its neutral saddle (Effect.theory_start) is also
        # tried at its theory values, the rest as started
        for e in structure.effects:
            eff = CATALOGUE[e]
            if not eff.theory_start:
                continue
            neutral = eff.neutral_values(constants)
            if all(n in start and np.isclose(start[n], neutral[n]) for n in eff.parameters):
                cands.append((f"start, {e} at theory", {
                    **theory, **start, **{n: theory[n] for n in eff.parameters}}))
    cands.append(("theory", dict(theory)))
    try:
        paper = preset_parameters(structure, constants, "paper")
        cands.append(("paper", paper))
    except (ValueError, KeyError):
        pass
    # identified inflow is often much slower than the apparent-mass theory
    # (Tables 1-3: 16-32 azimuth rad): a slow-inflow start guards against the
    # quasi-static local minimum
    slow = {n: 20.0 for n in ("tau", "tau0", "tau_cs") if n in theory}
    cands.append(("theory, slow inflow", {**theory, **slow, **(start or {})}))
    uniq = []
    for label, vals in cands:
        if not any(all(np.isclose(vals[n], u[n], rtol=1e-12, atol=0) for n in vals)
                   for _, u in uniq):
            uniq.append((label, vals))
    return uniq


def identify(records, structure, band_hz=DEFAULT_BAND, start=None, fixed=None, ties=None,
             progress=None, grid_hz=None, multistart=True, hold=None) -> FitResult:
    """Estimate a structure's parameters from flight records (Eqs. 10-12).

    Parameters
    ----------
    records : Record, path, or a sequence of them
        Fitted together (joint cost; each record keeps its own constants, step and
        residual covariance ``S``).
    structure : str or Structure
        E.g. ``"glauert"``, ``"empirical+time-delay"``.
    band_hz : (float, float)
        Band [Hz]; snaps to each record's grid ``k / (N dt)``.  Default: the
        paper's 0.2256-1.58 Hz.
    start : dict, optional
        Starting values (any subset; the rest from theory).
    fixed : dict, optional
        ``{name: value}`` held fixed; a value ``None`` fixes it at the user's
        ``start`` value, or else at its theory value.
    ties : sequence of tuples, optional
        ``[("tau0", "tau_cs")]``: one estimated value for several parameters.
    progress : callable, optional
        Called with one-line progress messages.
    grid_hz : array_like, optional
        Chosen frequencies [Hz] instead of the record's grid (direct DFT, inside
        ``band_hz``).  The transform relation stays exact (:mod:`.freqmodel`); the
        bounds then assume independent residuals across frequency, which holds only
        approximately off the record's grid (neighbouring frequencies closer than
        ``1/duration`` are correlated: see ``sigma_colored``).
    multistart : bool
        Try the theory, paper and user starts and keep the lowest cost (default);
        otherwise only the first of them.
    hold : {"continuous", "zoh", "foh"}, optional
        Intersample behaviour of every record's inputs, overriding each record's
        own (``# hold:``; absent means ``continuous``, measured data).  The
        transform and the model use the exact relation for it (:mod:`.freqmodel`).

    Returns
    -------
    FitResult
    """
    s = Structure.parse(structure)
    recs = as_records(records)
    spectra = spectra_of(recs, s, band_hz, grid_hz, hold)
    start = dict(start or {})
    fixed = dict(fixed or {})
    ties = [tuple(t) for t in (ties or [])]
    _check_names(s, start, "start")
    _check_names(s, fixed, "fixed")
    say = progress or (lambda msg: None)
    theory = theory_parameters(s, spectra[0].constants)
    fixed = {n: float(start.get(n, theory[n]) if v is None else v) for n, v in fixed.items()}
    starts = _starts(s, spectra[0].constants, start)
    if not multistart:
        starts = starts[:1]
    # every start gets a short run (one relaxation round); the best continues.  Only
    # the best start's problem and state are kept (its responses and nuisance
    # bases are the record's length: 90 MB of a 2-hour record's three starts)
    trials, best = [], None
    # a start that the fixed values make equal to an earlier one (an effect's theory
    # start whose parameters are all held) has that one's short run: reported
    # again, not run again (the same numbers)
    runs = {}
    with bar(progress, len(starts), f"identify {s.name}: trying starts", "start") as b:
        for label, vals in starts:
            vals = dict(vals)
            vals.update(fixed)
            same = tuple((n, float(vals[n]).hex()) for n in sorted(vals))
            if same in runs:
                trials.append((runs[same][0], label, runs[same][1]))
                b.update()
                continue
            prob = Problem(s, spectra, vals, fixed=tuple(fixed), ties=ties)
            if not prob.free:
                raise InputError("identify: every parameter is fixed; nothing to estimate")
            try:
                build_model(s, prob.params(prob.theta0()), spectra[0].constants)
            except InputError as exc:
                raise InputError(f"start values ({label}): {exc}") from None
            b.set_postfix_str(f"{label}: {len(prob.free)} parameters, "
                              f"{prob.n_freq} frequencies")
            st, j, iters, _ = fit_from(prob, prob.theta0(), max_iter=SHORT_RUN)
            b.update()
            trials.append((j, label, iters))
            runs[same] = (j, iters)
            if best is None or j < best[0]:   # the first of equal costs, as min() takes
                best = (j, label, prob, st, iters)
            del prob, st
    j, label, prob, st, it0 = best
    del best

    def step(b, i, c):
        b.set_postfix_str(f"cost {c:.6f}", refresh=False)
        b.update()
    with bar(progress, None, f"identify {s.name}: fitting from start {label}",
             "iteration") as b:
        st, j, iters, conv = fit_from(prob, st.theta, report=lambda i, c: step(b, i, c))
    say(f"identify {s.name}: cost {j:.6f}, {'converged' if conv else 'NOT converged'}")
    return _result(prob, st, j, it0 + iters, conv, tuple((t[1], t[0]) for t in trials))


def _result(prob, st, j, iters, conv, starts):
    theta = st.theta
    cov, cov_c, cov_r, dead, n_null = covariances(prob, st)
    warns, corr = _warnings(prob, theta, cov, dead, n_null, conv, iters)
    params = prob.params(theta)
    sigma, sigma_c, sigma_r = {}, {}, {}
    for i, g in enumerate(prob.free):
        sd = float(np.sqrt(cov[i, i])) if np.isfinite(cov[i, i]) else None
        sc = float(np.sqrt(cov_c[i, i])) if np.isfinite(cov_c[i, i]) else None
        sr = float(np.sqrt(cov_r[i, i])) if np.isfinite(cov_r[i, i]) else None
        if sd is not None:
            # corrections, never below the Cramer-Rao bound
            sc = None if sc is None else max(sc, sd)
            sr = None if sr is None else max(sr, sd)
        for n in g:
            sigma[n], sigma_c[n], sigma_r[n] = sd, sc, sr
    data = []
    for sp, (y_u, y_nu), nu, S in zip(prob.spectra, st.resp, st.nus, st.S):
        m = build_model(prob.structure, params, sp.constants)
        k = m.end_basis.shape[1]
        x0 = m.end_state(nu[:k], sp.u_time[0])
        data.append(RecordFit(sp.source, sp.constants, sp.dt, sp.f_hz, sp.Z,
                              y_u + y_nu @ nu, x0, S, sp.trim, sp.trim_method,
                              sp.u_time, sp.z_time, sp.hold, nu))
    warns += _few_bins(prob, st) + _collapsed_s(prob.spectra, st.S)
    Zall = np.vstack([d.Z for d in data])
    Yall = np.vstack([d.Y for d in data])
    model = build_model(prob.structure, params, prob.spectra[0].constants)
    return FitResult(
        structure=prob.structure, constants=tuple(sp.constants for sp in prob.spectra),
        parameters=params, sigma=sigma, sigma_colored=sigma_c, sigma_robust=sigma_r,
        free=prob.free_names,
        correlation=corr, fixed=prob.fixed,
        ties=tuple(g for g in prob.free if len(g) > 1), cost=float(j), S=tuple(st.S),
        band_hz=_band(prob.spectra), n_freq=prob.n_freq,
        records=tuple(sp.source for sp in prob.spectra), fit=channel_fit(Zall, Yall),
        iterations=iters, converged=conv, warnings=tuple(warns), model=model,
        data=tuple(data), starts=starts, lr=lr_calibration(prob, st))


@dataclass(frozen=True, eq=False)
class Evaluation:
    """Cost and residual spectra of a structure with given parameters.

    ``residuals[r]`` is ``(nf, 3)`` complex (measured minus predicted flap transform,
    end effects eliminated) at ``f_hz[r]``; ``S[r]`` the estimated covariance.

    Attributes
    ----------
    cost : float
        Cost (12) [-].
    residuals : tuple of ndarray
        Per record, ``(nf, 3)`` complex residual spectra [rad s].
    f_hz : tuple of ndarray
        Per record, frequencies [Hz].
    S : tuple of ndarray
        Per record, residual covariance [rad^2 s^2].
    Z, Y : tuple of ndarray
        Per record, measured and predicted flap transforms [rad s].
    band_hz : tuple of float
        The band [Hz].
    n_freq : int
        Frequencies over all records [-].
    records : tuple of str
        The records.
    fit : dict
        Per channel fit figures (:func:`~inflowsim.identify.results.channel_fit`).
    nu : tuple
        Per record, the end-effect nuisance.
    """

    cost: float
    residuals: tuple
    f_hz: tuple
    S: tuple
    Z: tuple
    Y: tuple
    band_hz: tuple
    n_freq: int
    records: tuple
    fit: dict
    nu: tuple = ()


def evaluate(records, structure, params, band_hz=DEFAULT_BAND, grid_hz=None,
             hold=None) -> Evaluation:
    """Cost (12) and residual spectra for fixed parameters (no estimation).

    ``S`` and the end-effect nuisance are still estimated (they are not model
    parameters), so the cost is the one :func:`identify` minimises and costs of
    nested structures on the same records and band compare as log-likelihoods.

    Parameters
    ----------
    records : Record, path or list of them
        The flight-test records (each with its own flight condition and trim).
    structure : str or Structure
        The structure.
    params : mapping of str to float
        Its parameters (SI; angles [rad], time constants in azimuth units [-]).
    band_hz : (float, float)
        Analysis band [Hz].
    grid_hz : float, optional
        Frequency grid spacing [Hz] (default each record's ``1 / T``).
    hold : {"continuous", "zoh", "foh"}, optional
        Intersample behaviour of the records' inputs (default each record's own).
    """
    s = Structure.parse(structure)
    recs = as_records(records)
    spectra = spectra_of(recs, s, band_hz, grid_hz, hold)
    prob = Problem(s, spectra, dict(params), fixed=tuple(s.parameters))
    st = _relax_S(prob, np.zeros(0), rounds=4)
    eps = prob.eps(st.resp, st.nus)
    Y = tuple(sp.Z - e for sp, e in zip(spectra, eps))
    return Evaluation(cost=prob.cost(st.r, st.S), residuals=tuple(eps),
                      f_hz=tuple(sp.f_hz for sp in spectra), S=tuple(st.S),
                      Z=tuple(sp.Z for sp in spectra), Y=Y, band_hz=_band(spectra),
                      n_freq=prob.n_freq, records=tuple(sp.source for sp in spectra),
                      fit=channel_fit(np.vstack([sp.Z for sp in spectra]), np.vstack(Y)),
                      nu=tuple(st.nus))


__all__ = ["SHORT_RUN", "NEAR", "HALF_WINDOW", "CORRELATION_LIMIT", "RANK_TOL",
           "S_CONDITION_LIMIT", "S_ROUNDING", "FEW_DOF", "null_directions",
           "weight_dof", "weight_factors", "finite_sample_covariance", "lr_calibration",
           "lr_calibration_of", "identify", "Evaluation",
           "evaluate", "fit_state", "fit_from", "as_records", "spectra_of",
           "covariances"]
