"""The exact relation between a record's transforms and the model, for its hold.

The record's transforms (:mod:`.transform`) are ``X = sum_n c_n x_n z^-n``,
``z = exp(j w dt)``, with ``c_n = 1`` for held inputs and Gregory's end-corrected
weights for continuous records.  Per intersample behaviour (:mod:`inflowsim.simulate.sampled`):

*Discrete (``zoh``, ``foh``).*  The state sampled at ``t_n - d`` obeys
``xi_{n+1} = phi xi_n + sum_o G_o u_{n+o}`` exactly (:func:`inflowsim.simulate.sampled.shift_taps`),
so at ANY frequency

    ``(z I - phi) XI = sum_o G_o U_o + z xi_0 - z^(1-N) xi_N``,

``U_o = sum_{n<N} u_{n+o} z^-n`` (samples outside the record continue the first
or last one).

*Continuous.*  For ``x' = a x + b u`` on ``[0, T]``, ``T = (N-1) dt``, the finite
Fourier integrals obey ``j w X = a X + b U + x(0) - x(T) e^{-j w T}``, and the
Gregory-weighted sums are those integrals over ``dt`` to aliasing accuracy, so

    ``XI = (j w I - a)^-1 [b U^(d) + (xi(0) - xi(T) e^{-j w T}) / dt]``

where ``U^(d)`` is the transform of the input shifted by ``d``: ``e^{-j w d}``
times ``U`` plus the integrals over the two end windows the shift moves in and
out (:func:`window_integral`; local-cubic interpolation inside the record, the
first or last sample outside).

*Time shifts.*  Flap channels with the same output delay ``tau`` form a group; the
group sees recorded input ``j`` shifted by ``tau - input_delay_j`` and gets its
own end states ``(xi_0, xi_end)``: the *end effects* (the record neither starts
nor ends at rest), nuisance parameters eliminated by linear least squares inside
every cost evaluation (:mod:`.problem`).  With one group (no shifts, or one shared
flap delay) that is ``2 n`` real numbers per record.  Flap outputs are
``Y = C XI`` (``C`` includes the azimuth-bias rotation).
"""
from __future__ import annotations

import weakref

import numpy as np

from ..simulate.sampled import BASES, shift_taps

__all__ = ["flap_response", "flap_derivatives", "leading",
           "leading_states", "truncated", "shift_groups", "window_integral", "shifted_transform",
           "continuous_input"]


def shift_groups(model):
    """``[(rows, tau), ...]``: flap channels (``rows`` of ``beta0 beta1c beta1s``)
    sharing one output delay parameter, of value ``tau`` [s].  The partition is
    the structure's (``Measurement.delay_groups``), not the values', so the
    number of end states never changes with the parameters."""
    d = np.asarray(model.delays, dtype=float)
    return [(np.array(g), float(d[g[0]])) for g in model.measurement.delay_groups]


def _powers(p, f_hz, dt):
    """``z^p`` from the phase directly (no accumulated rounding)."""
    return np.exp(2j * np.pi * np.asarray(f_hz) * dt * p)


def shifted_transform(U, u, f_hz, dt, o):
    """``sum_{n=0}^{N-1} u_{n+o} z^-n`` from ``U = sum u_n z^-n`` (plain DFT), the
    samples beyond the record continuing the first or last one."""
    if o == 0:
        return U
    N = len(u)
    if o > 0:
        corr = -sum(_powers(-j, f_hz, dt)[:, None] * u[j] for j in range(o))
        corr = corr + sum(_powers(-j, f_hz, dt) for j in range(N, N + o))[:, None] * u[-1]
    else:
        corr = sum(_powers(-j, f_hz, dt) for j in range(o, 0))[:, None] * u[0]
        corr = corr - sum(_powers(-j, f_hz, dt)[:, None] * u[j] for j in range(N + o, N))
    return _powers(o, f_hz, dt)[:, None] * (U + corr)


#: Gauss-Legendre nodes per sample interval for the end-window integrals.
_GL = np.polynomial.legendre.leggauss(8)


def _cubic(u, pos):
    """Local-cubic interpolation of samples ``u`` (``(N, m)``) at fractional sample
    positions ``pos`` inside ``[0, N-1]``; the first/last sample outside."""
    N = len(u)
    offs, coef = BASES["continuous"]
    out = np.empty((pos.size, u.shape[1]))
    inside = (pos >= 0) & (pos <= N - 1)
    out[pos < 0] = u[0]
    out[pos > N - 1] = u[-1]
    p = pos[inside]
    i = np.clip(np.floor(p).astype(int), 0, max(N - 2, 0))
    s = p - i
    acc = np.zeros((p.size, u.shape[1]))
    for k, o in enumerate(offs):
        ell = np.polyval(coef[k][::-1], s)
        acc += ell[:, None] * u[np.clip(i + o, 0, N - 1)]
    out[inside] = acc
    return out


def window_integral(u, dt, f_hz, alpha, beta):
    """``(1/dt) int_alpha^beta u(t) e^{-j w t} dt`` (oriented) for every column of the
    samples ``u`` (``u(n dt) = u_n``), ``(nf, m)``.

    Local-cubic interpolation inside the record, the first or last sample
    outside; Gauss-Legendre on every piece between sample times.
    """
    u = np.asarray(u, float)
    nf = np.size(f_hz)
    if alpha == beta:
        return np.zeros((nf, u.shape[1]), dtype=complex)
    sign = 1.0
    if beta < alpha:
        alpha, beta, sign = beta, alpha, -1.0
    N = len(u)
    edges = np.concatenate([[alpha], np.arange(np.ceil(alpha / dt), np.floor(beta / dt) + 1)
                            * dt, [beta]])
    edges = np.unique(np.clip(edges, alpha, beta))
    if N > 1:
        edges = np.unique(np.concatenate([edges, [x for x in (0.0, (N - 1) * dt)
                                                  if alpha < x < beta]]))
    x, w = _GL
    lo, hi = edges[:-1], edges[1:]
    t = (0.5 * (hi - lo)[:, None] * (x + 1) + lo[:, None]).ravel()
    wt = (0.5 * (hi - lo)[:, None] * w).ravel()
    vals = _cubic(u, t / dt)                                  # (nt, m)
    ph = np.exp(-2j * np.pi * np.outer(f_hz, t)) * wt         # (nf, nt)
    return sign * (ph @ vals) / dt


def continuous_input(sp, d):
    """``U^(d)``: transform of the recorded inputs shifted by ``d`` [s] (delayed
    for ``d > 0``), ``(nf, m)``, read-only.  A function of the record and ``d``
    only: the last few shifts of each record are remembered (a fit's Jacobian moves
    the delay in one column of twenty, and the end-window integrals cost more than
    the rest of a response)."""
    if d == 0:
        return sp.U
    memo = _record_memo(sp)["shifts"]
    key = float(d)
    out = memo.get(key)
    if out is None:
        T = (sp.n_samples - 1) * sp.dt
        u, f = sp.u_time, sp.f_hz
        ends = window_integral(u, sp.dt, f, -d, 0.0) - window_integral(u, sp.dt, f, T - d, T)
        out = np.exp(-2j * np.pi * f * d)[:, None] * (sp.U + ends)
        out.flags.writeable = False
        _evict(memo)
        memo[key] = out
    return out


#: Shifted input transforms (:func:`continuous_input`) and eigen-decompositions
#: (:func:`_eig`) remembered: the most recent few, each a pure function of its key.
MEMO = 8
_RECORDS = weakref.WeakKeyDictionary()
_EIGS: dict = {}


def _record_memo(sp) -> dict:
    """What :func:`flap_response` remembers of one record (its :class:`Spectra`,
    which is immutable): ``shifts`` (:func:`continuous_input`) and ``terms``."""
    memo = _RECORDS.get(sp)
    if memo is None:
        memo = {"shifts": {}, "terms": None}
        try:
            _RECORDS[sp] = memo
        except TypeError:             # not weakly referable: nothing remembered
            pass
    return memo


def _terms(sp):
    """``(s, zs, ze)`` of a record: the transform variable of its model (``j w``,
    or ``z`` of a held record) and the factors of its start and end states, read-only."""
    memo = _record_memo(sp)
    out = memo["terms"]
    if out is None:
        f = sp.f_hz
        if sp.hold == "continuous":
            w = 2 * np.pi * f
            T = (sp.n_samples - 1) * sp.dt
            out = 1j * w, np.ones(f.size), -np.exp(-1j * w * T)
        else:
            zs = _powers(1, f, sp.dt)
            out = zs, zs, -_powers(1 - sp.n_samples, f, sp.dt)
        for x in out:
            x.flags.writeable = False
        memo["terms"] = out
    return out


def _evict(memo):
    """Drop the oldest entry of a full memo (another thread may have done it)."""
    if len(memo) >= MEMO:
        try:
            del memo[next(iter(memo))]
        except (KeyError, RuntimeError, StopIteration):
            pass


#: Largest condition number of the eigenvector matrix for which the response is
#: taken from the eigen-decomposition (relative error about ``cond * 1e-16``);
#: beyond it (near-repeated poles) each frequency's system is solved directly.
EIG_COND = 1e6
#: Frequencies evaluated at once: bounds the temporary ``(nf, n, n)`` arrays of a
#: long record (a 2-hour record's floor band holds 150 000 bins; its band 9 750).
BLOCK = 16384


def flap_response(model, sp, method="auto"):
    """Predicted flap transforms, affine in the end-effect nuisance.

    Parameters
    ----------
    model : Model
        SI state space (``a, b, c, delays, input_delays``, end-state map).
    sp : Spectra
        The record's transforms, its hold and its time inputs.
    method : {"auto", "eig", "solve"}
        How ``(s I - A)^-1`` is applied at every frequency: through the
        eigen-decomposition of ``A`` (``O(n^2)`` a frequency; ``auto`` uses it
        when the eigenvectors are well conditioned, :data:`EIG_COND`) or by
        solving each frequency's system (``solve``).  The two agree to rounding.

    Returns
    -------
    y_u : ndarray, complex ``(nf, 3)``
        Response to the record's inputs.
    y_nu : ndarray, complex ``(nf, 3, 2 k G)``
        Response to the slow coordinates of the start and end states (``k`` each,
        :meth:`Model.end_state`) of the ``G`` shift groups: the flap transforms are
        ``y_u + y_nu @ nu``.
    groups : list
        :func:`shift_groups`.
    """
    model = leading(model)
    nf = sp.f_hz.size
    if nf <= BLOCK:
        return _flap_response(model, sp, method)
    from dataclasses import replace
    # each block written into the whole (the blocks and their concatenation held at
    # once were twice a 2-hour floor band's 86 MB of end-state responses)
    y_u = y_nu = groups = None
    for i in range(0, nf, BLOCK):
        blk = slice(i, min(i + BLOCK, nf))
        a, b, g = _flap_response(model, replace(sp, f_hz=sp.f_hz[blk], U=sp.U[blk],
                                                 Z=sp.Z[blk]), method)
        if y_u is None:
            y_u = np.empty((nf,) + a.shape[1:], dtype=a.dtype)
            y_nu = np.empty((nf,) + b.shape[1:], dtype=b.dtype)
            groups = g
        y_u[blk], y_nu[blk] = a, b
        del a, b
    return y_u, y_nu, groups


#: Fewest states a model keeps in :func:`leading`: flap and inflow.
LEADING = 6


def leading(model):
    """``model`` with the states that drive neither the first ones nor the flap
    outputs dropped: the smallest ``n0 >= 6`` with ``a[:n0, n0:] = 0`` and
    ``c[:3, n0:] = 0`` exactly (an appended state block whose coupling is zero,
    as ``lead-lag`` at ``k_flap_lag = 0``: its states are driven but drive
    nothing).  The flap response and the end-state responses are then those of the
    leading ``n0`` states alone, their end states ``end_basis[:n0] v +
    end_input[:n0] u`` (the system is block-triangular: ``(s I - A)^-1`` and, for a
    held record, ``exp(A dt)`` and its input taps keep the leading block as it is).
    The model itself where no such ``n0 < n`` exists.

    The same response as the whole model's, to rounding (the whole model's
    eigenvectors mix the dropped states into the rest at rounding level): and a
    parameter that acts only on the dropped states has, exactly, no influence,
    rather than a rounding-level one a search can wander on.
    """
    return truncated(model, leading_states(model))


def leading_states(model) -> int:
    """``n0`` of :func:`leading`: the number of states it keeps (``n`` where none
    can be dropped)."""
    a = model.a
    n = a.shape[0]
    if n <= LEADING:
        return n
    c = model.c
    for n0 in range(LEADING, n):
        if not a[:n0, n0:].any() and not c[:3, n0:].any():
            return n0
    return n


def truncated(model, n0):
    """``model`` with only its first ``n0`` states (the model itself for all of
    them); ``n0`` from :func:`leading_states` (or more)."""
    if n0 >= model.a.shape[0]:
        return model
    out = object.__new__(type(model))
    out.__dict__.update(model.__dict__)
    for name, x in (("a", model.a[:n0, :n0]), ("b", model.b[:n0]), ("c", model.c[:, :n0]),
                    ("end_basis", model.end_basis[:n0]),
                    ("end_input", model.end_input[:n0])):
        x = np.array(x)                 # contiguous, as a model's own arrays
        x.flags.writeable = False
        out.__dict__[name] = x
    return out


def _eig(a):
    """``(lam, V, V^-1)`` of ``a``, or ``None`` where ``V`` is ill conditioned
    (read-only; remembered for the last :data:`MEMO` matrices: a parameter that
    only moves the input or output maps leaves ``a`` as it was)."""
    key = (a.dtype.str, a.shape, a.tobytes())
    try:
        out = _EIGS.pop(key)
    except KeyError:
        out = _eig_new(a)
        _evict(_EIGS)
    _EIGS[key] = out                  # most recent last
    return out


def _eig_new(a):
    if not np.isfinite(a).all():
        return None
    lam, V = np.linalg.eig(a)
    # np.linalg.cond(V) (2-norm), without its wrapper: the same singular values
    sv = np.linalg.svd(V, compute_uv=False)
    with np.errstate(all="ignore"):
        cond = sv[0] / sv[-1]
    if np.isnan(cond) and not np.isnan(V).any():
        cond = np.inf
    if cond > EIG_COND:
        return None
    out = lam, V, np.linalg.inv(V)
    for x in out:
        x.flags.writeable = False
    return out


def _eig_products(dec, den, inp, C, P, zs, ze, groups):
    """:func:`_flap_response`'s eigen path: ``y_u`` and ``y_nu`` from the
    eigen-decomposition ``dec`` of the state matrix, the denominators ``den = s -
    lam`` ``(nf, n)`` (overwritten by the resolvent ``1 / den``) and each group's
    input term ``inp[g]`` ``(nf, n)``.

    The products are written into their results where whole (every flap channel in
    one group: the end-state responses' two halves, the resolvent, the weighted
    input): the same operations on the same operands as forming each and then
    assigning it, without a long record's temporaries (a 2-hour record's
    end-state responses are 5.6 MB a model, evaluated some 200 times a fit).
    """
    _, V, Vi = dec
    nf, n = den.shape
    k = P.shape[1]
    G = len(groups)
    r = np.divide(1.0, den, out=den)                         # (nf, n) resolvent
    vp = Vi @ P
    # every flap channel in one group (no per-channel delays): slices, not index
    # arrays (the same numbers, a third of the cost), every entry written
    whole = G == 1 and tuple(groups[0][0]) == (0, 1, 2)
    if whole:
        y_nu = np.empty((nf, 3, 2 * k), dtype=complex)
        cv = C @ V
        x = inp[0] @ Vi.T
        x *= r
        y_u = x @ cv.T
        del x
        e = (r @ (cv.T[:, :, None] * vp[:, None, :]).reshape(n, -1)).reshape(nf, 3, k)
        np.multiply(zs[:, None, None], e, out=y_nu[:, :, :k])
        np.multiply(ze[:, None, None], e, out=y_nu[:, :, k:])
        return y_u, y_nu, groups
    y_u = np.empty((nf, 3), dtype=complex)
    y_nu = np.zeros((nf, 3, 2 * k * G), dtype=complex)
    for g, (rows, _) in enumerate(groups):
        cv = C[rows] @ V
        y_u[:, rows] = ((inp[g] @ Vi.T) * r) @ cv.T
        # C V diag(r) V^-1 P at every frequency as one product (nf, n) x (n, rows k)
        e = (r @ (cv.T[:, :, None] * vp[:, None, :]).reshape(n, -1)).reshape(
            nf, len(rows), k)
        y_nu[:, rows, 2 * k * g:2 * k * g + k] = zs[:, None, None] * e
        y_nu[:, rows, 2 * k * g + k:2 * k * (g + 1)] = ze[:, None, None] * e
    return y_u, y_nu, groups


def _input_maps(model, sp, groups):
    """``(A, maps)``: the state matrix ``A`` of the record's hold (``a``, or ``exp(a
    dt)`` of a held record) and per shift group ``maps[g] = {key: M}``, the group's
    input term ``sum_key X_key M^T`` without the end states' part (``X_key =``
    :func:`_input_basis` ``(sp, key)``, a function of the record and the key only):
    for a continuous record one key, the input shifts, with ``M = b``; for a held
    one a key per tap offset ``o`` with ``M = G_o``
    (:func:`inflowsim.simulate.sampled.shift_taps`)."""
    a, b = model.a, model.b
    sigma = np.asarray(model.input_delays, float)
    if sp.hold == "continuous":
        return a, [{("shift",) + tuple((tau - sigma).tolist()): b} for _, tau in groups]
    phi, maps = None, []
    for _, tau in groups:
        phi, taps = shift_taps(a, b, sp.dt, sp.hold, tau - sigma)
        maps.append(dict(taps))
    return phi, maps


def _input_basis(sp, key):
    """``X_key`` ``(nf, m)`` of :func:`_input_maps`: the recorded inputs' transform
    shifted by each column's ``d`` (a continuous record's key ``("shift", d_1, ...)``,
    :func:`continuous_input`) or by the tap offset ``o`` (a held record's,
    :func:`shifted_transform`)."""
    if sp.hold != "continuous":
        return shifted_transform(sp.U, sp.u_time, sp.f_hz, sp.dt, key)
    d = np.array(key[1:])
    if d.size and (d == d[0]).all():
        # one shift for every input: its transform as it is
        return np.ascontiguousarray(continuous_input(sp, d[0]))
    ud = np.empty((sp.f_hz.size, d.size), dtype=complex)
    for v in np.unique(d):
        cols = np.flatnonzero(d == v)
        ud[:, cols] = continuous_input(sp, v)[:, cols]
    return ud


def _input_terms(model, sp, groups):
    """``(inp, A, s, zs, ze)``: each shift group's input term ``inp[g]`` ``(nf, n)``
    of ``(s I - A) x = input + zs x_0 + ze x_end`` (the end states' input part ``q
    u`` included), the state matrix ``A`` of the record's hold (``a``, or ``exp(a
    dt)`` of a held record) and :func:`_terms`."""
    n = model.a.shape[0]
    q = model.end_input
    nf = sp.f_hz.size
    u0, u1 = sp.u_time[0], sp.u_time[-1]
    A, maps = _input_maps(model, sp, groups)
    # per group the input term (nf, n) of  (s I - A) x = input + zs x_0 + ze x_end
    inp = np.empty((len(groups), nf, n), dtype=complex)
    s, zs, ze = _terms(sp)
    for g, terms in enumerate(maps):
        if sp.hold == "continuous":
            (key, b), = terms.items()
            inp[g] = _input_basis(sp, key) @ b.T
            continue
        acc = np.zeros((nf, n), dtype=complex)
        for o, Go in terms.items():
            acc += _input_basis(sp, o) @ Go.T
        inp[g] = acc
    # end states on the slow manifold: x = P v + q u (q = 0 for first-order flapping,
    # where adding its zeros would change no number)
    if np.count_nonzero(q):
        # outer(zs, q u0) + outer(ze, q u1) added to every group's term with one
        # temporary (the same numbers, the sum taken the other way round: ``zs`` of
        # a continuous record is real, ``ze`` complex)
        t = np.multiply(ze[:, None], (q @ u1)[None, :])
        t += np.multiply(zs[:, None], (q @ u0)[None, :])
        inp += t[None]
    return inp, A, s, zs, ze


#: Bytes of the per-parameter temporaries :func:`flap_derivatives` makes at once
#: (``(nf, p, n)`` complex, a few of them): its parameters are taken in runs of
#: this size (a 2-hour record's 9 752 bins: 1.9 MB a parameter of a 12-state model).
DERIVATIVE_BYTES = 16 * 2 ** 20


def flap_derivatives(model, pairs, sp, nu, weight=None):
    """Derivatives of the flap transforms at a fixed end-effect nuisance, ``d (y_u +
    y_nu nu) / d theta_i`` ``(nf, 3, p)`` complex, by the resolvent.

    At every frequency ``y = C (s I - A)^-1 x`` with ``x`` the input term and the
    end states (:func:`flap_response`), so, ``R = (s I - A)^-1``,

        ``dy = dC R x + C R (dA R x + dx)``,

    with ``dA, dC, dx`` the changes of the model's small matrices (``A`` of the
    record's hold, ``C``, the input maps, the end-state basis and input:
    :func:`_input_maps`) taken as differences ``(plus - minus) / step`` of the
    models ``pairs = [(plus, minus, step), ...]`` (one per parameter: a central or
    one-sided difference, ``minus`` or ``plus`` the model itself).  ``R`` is
    applied in the eigen basis of ``A`` (``V diag(1 / (s - lam)) V^-1``), or by
    solving each frequency's system where :func:`flap_response` would
    (ill-conditioned eigenvectors, a pole on a bin).  A parameter that moves a
    time shift of a continuous record moves the input basis, ``dx`` the difference
    of the shifted transforms times their maps.  The states kept for a parameter
    are those that drive the flap outputs in the model or either of its two
    (:func:`leading_states`).

    Parameters
    ----------
    model : Model
        The model at the parameters (``theta``).
    pairs : list of (Model, Model, float)
        Per parameter the models at ``theta_i + h`` and ``theta_i - h`` (or
        ``theta``) and the step between them [the parameter's unit].
    sp : Spectra
        The record's transforms.
    nu : ndarray
        The end-effect nuisance (:func:`flap_response`'s ``y_nu @ nu``).
    weight : ndarray (3, 3), optional
        A weighting ``W`` of the flap channels: ``W dy`` returned.

    Returns
    -------
    ndarray, complex ``(nf, 3, p)`` [rad s per unit of the parameter]
    """
    # each parameter with the states its two models need (a parameter that acts
    # only on states its models drop has, exactly, no influence: :func:`leading`)
    n_base = leading_states(model)
    by_states = {}
    for i, (mp, mm, _) in enumerate(pairs):
        n0 = max(n_base, leading_states(mp), leading_states(mm))
        by_states.setdefault(n0, []).append(i)
    if len(by_states) == 1:
        (n0, _), = by_states.items()
        return _derivatives(truncated(model, n0), [
            (truncated(mp, n0), truncated(mm, n0), step) for mp, mm, step in pairs],
            sp, nu, weight)
    y = np.empty((sp.f_hz.size, 3, len(pairs)), dtype=complex)
    for n0, idx in by_states.items():
        y[:, :, idx] = _derivatives(truncated(model, n0), [
            (truncated(pairs[i][0], n0), truncated(pairs[i][1], n0), pairs[i][2])
            for i in idx], sp, nu, weight)
    return y


def _derivatives(model, pairs, sp, nu, weight):
    """:func:`flap_derivatives` of models of the same states."""
    groups = shift_groups(model)
    inp, A, s, zs, ze = _input_terms(model, sp, groups)
    nf, n, p = s.size, A.shape[0], len(pairs)
    C, P, k = model.c[:3], model.end_basis, model.end_basis.shape[1]
    dec = _eig(A)
    if dec is not None:
        den = s[:, None] - dec[0]
        if not (den != 0).all():           # a pole exactly on a bin: as the solve does
            dec = None
    if dec is not None:
        _, T, Ti = dec
        r = np.divide(1.0, den, out=den)

        def resolvent(z):                  # z (nf, ..., n) in eigen coordinates
            z *= r.reshape((nf,) + (1,) * (z.ndim - 2) + (n,))
            return z
    else:
        T = Ti = np.eye(n)
        sA = s[:, None, None] * np.eye(n) - A

        def resolvent(z):
            shape = z.shape
            z = np.linalg.solve(sA, z.reshape(nf, -1, n).transpose(0, 2, 1))
            return np.ascontiguousarray(z.transpose(0, 2, 1)).reshape(shape)
    u0, u1 = sp.u_time[0], sp.u_time[-1]
    # the small matrices' differences, each parameter's
    dA = np.empty((p, n, n))
    dC = np.empty((p, 3, n))
    dq = np.empty((p,) + model.end_input.shape)
    dP = np.empty((p, n, k))
    dmaps = [{} for _ in groups]           # per group {key: {i: dM}}
    for i, (mp, mm, step) in enumerate(pairs):
        Ap, maps_p = _input_maps(mp, sp, shift_groups(mp))
        Am, maps_m = _input_maps(mm, sp, shift_groups(mm))
        dA[i] = (Ap - Am) / step
        dC[i] = (mp.c[:3] - mm.c[:3]) / step
        dq[i] = (mp.end_input - mm.end_input) / step
        dP[i] = (mp.end_basis - mm.end_basis) / step
        for g in range(len(groups)):
            tp, tm = maps_p[g], maps_m[g]
            for key in {**tp, **tm}:
                Mp, Mm = tp.get(key), tm.get(key)
                dM = (Mp if Mm is None else Mm * -1.0 if Mp is None else Mp - Mm) / step
                if dM.any():
                    dmaps[g].setdefault(key, {})[i] = dM
    # z = [xi | X_key ... | zs | ze] @ coef: for every parameter at once, in eigen
    # coordinates, dA R x (coef (V^-1 dA V)^T), the input maps' change and the end
    # states' (dq u + dP nu): one product, each part's columns only where some
    # parameter moves it
    wide = bool(dq.any() or dP.any())
    y = np.empty((nf, 3, p), dtype=complex)
    whole = len(groups) == 1 and tuple(groups[0][0]) == (0, 1, 2)
    per = max(1, DERIVATIVE_BYTES // (16 * nf * n))
    for g, (rows, _) in enumerate(groups):
        nu0, nu1 = nu[2 * k * g:2 * k * g + k], nu[2 * k * g + k:2 * k * (g + 1)]
        # the state's response R x in eigen coordinates (nf, n), x with the end states
        x = inp[g] + np.outer(zs, P @ nu0) + np.outer(ze, P @ nu1)
        xi = resolvent(x @ Ti.T)
        del x
        keys = list(dmaps[g])
        parts = [xi] + [_input_basis(sp, key) for key in keys] + \
            ([zs[:, None], ze[:, None]] if wide else [])
        basis = np.concatenate(parts, axis=1)
        del parts
        # the output maps, weighted where every channel is in this group
        Cw = C[rows] @ T
        dCw = dC[:, rows] @ T                                   # (p, rows, n)
        if whole and weight is not None:
            Cw, dCw = weight @ Cw, weight @ dCw
        moves_c = dCw.any(axis=(1, 2))
        for j0 in range(0, p, per):
            m = min(per, p - j0)
            coef = np.zeros((basis.shape[1], m, n), dtype=complex)
            coef[:n] = (Ti @ dA[j0:j0 + m] @ T).transpose(2, 0, 1)
            row = n
            for key in keys:
                M = dmaps[g][key]
                w = next(iter(M.values())).shape[1]
                for i, dM in M.items():
                    if j0 <= i < j0 + m:
                        coef[row:row + w, i - j0] = (Ti @ dM).T
                row += w
            if wide:
                coef[row, :] = (dq[j0:j0 + m] @ u0 + dP[j0:j0 + m] @ nu0) @ Ti.T
                coef[row + 1, :] = (dq[j0:j0 + m] @ u1 + dP[j0:j0 + m] @ nu1) @ Ti.T
            z = resolvent((basis @ coef.reshape(len(coef), m * n)).reshape(nf, m, n))
            out = (z.reshape(nf * m, n) @ Cw.T).reshape(nf, m, len(rows))
            del z
            # dC R x, for the parameters that move C (the azimuth bias)
            for t in np.flatnonzero(moves_c[j0:j0 + m]):
                out[:, t] += xi @ dCw[j0 + t].T
            y[:, rows, j0:j0 + m] = out.transpose(0, 2, 1)
    if not whole and weight is not None:
        y = weight @ y
    return y


def _flap_response(model, sp, method):
    C = model.c[:3]
    n = model.a.shape[0]
    P = model.end_basis
    k = P.shape[1]
    nf = sp.f_hz.size
    groups = shift_groups(model)
    G = len(groups)
    inp, A, s, zs, ze = _input_terms(model, sp, groups)
    dec = None if method == "solve" else _eig(A)
    if dec is None and method == "eig":
        raise ValueError("flap_response: the eigenvectors are ill conditioned")
    if dec is not None:
        den = s[:, None] - dec[0]
        if not (den != 0).all():           # a pole exactly on a bin: as the solve does
            dec = None
    if dec is not None:
        return _eig_products(dec, den, inp, C, P, zs, ze, groups)
    y_u = np.empty((nf, 3), dtype=complex)
    y_nu = np.zeros((nf, 3, 2 * k * G), dtype=complex)
    # one solve for every group's input term and the shared end-state basis
    rhs = np.empty((nf, n, G + 2 * k), dtype=complex)
    rhs[:, :, :G] = np.moveaxis(inp, 0, 2)
    rhs[:, :, G:G + k] = zs[:, None, None] * P
    rhs[:, :, G + k:] = ze[:, None, None] * P
    sol = np.linalg.solve(s[:, None, None] * np.eye(n) - A, rhs)
    for g, (rows, _) in enumerate(groups):
        cr = C[rows]
        y_u[:, rows] = sol[:, :, g] @ cr.T
        y_nu[:, rows, 2 * k * g:2 * k * (g + 1)] = cr @ sol[:, :, G:]
    return y_u, y_nu, groups
