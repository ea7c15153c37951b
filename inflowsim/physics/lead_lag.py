"""The lag modes coupled to flap, in multiblade coordinates (``model.md`` 9.1).

Rigid blade, flap and lag about a central hinge with equivalent springs (the lag
frequency ``nu_zeta`` [per rev] holds a lag hinge offset's centrifugal stiffness),
lag angle ``zeta`` positive *against* the rotation (aft, Johnson's convention),
azimuth time (``' = d/dpsi``), moments over ``I_b Omega^2``::

    beta'' + lambda_beta2 beta - 2 beta zeta' + beta zeta'^2 = 4 n_beta int r (theta U_T^2 + U_P U_T) dr
    zeta'' + C zeta' + nu^2 zeta + 2 beta beta' (1 - zeta') = 4 n_beta int r (-(theta U_T + U_P) U_P + delta U_T^2) dr

with ``U_T = r (1 - zeta') + mu sin(psi - zeta)``, ``U_P = muz - lambda0 - r
((lambda1c - qbar) cos(psi - zeta) + (lambda1s - pbar) sin(psi - zeta)) - r beta' - mu
beta cos(psi - zeta)`` (the base model's, section 1, met by the blade where it is, at
``psi - zeta``), ``delta = c_d0 / a0`` the profile drag over the lift slope, ``C =
2 zeta_lag nu_zeta`` the lag damper.  The ``2 beta`` terms are the Coriolis coupling
(a blade flapping up comes nearer the shaft and, keeping its angular momentum, leads).

Linearised about a forward-flight trim (pitch, flap and inflow with their cyclics,
the steady lag the trim's drag holds), projected on ``(1, 2 cos psi, 2 sin psi)``
and averaged over the azimuth (the base model's constant-coefficient
approximation), with ``zeta = zeta0 + zeta1c cos psi + zeta1s sin psi``: the
coefficients are :mod:`inflowsim.physics.lead_lag_terms`, derived with sympy by
``bench/lead_lag_derivation.py``.  The trim's flap has its 2/rev part (the rigid
blades', ``beta`` of :func:`coefficients`), and the steady lag is the steady state of
the same averaged lag rows under the trim's lag moment (:func:`steady_lag`), its 2/rev
part included (held by the flap's Coriolis moment ``-2 beta beta'``): each a few
tenths of a per cent of the blades' airspeed, which the Coriolis moments carry into
the 1/rev couplings (``model.md`` 9.1).  Checked against the individual-blade equations integrated blade by blade (``tests/test_lead_lag.py``)
and against the blade truth's own equations differenced about its periodic trim
(``tests/test_bladesim_lag.py``).  Pure functions of numbers or of sympy symbols
(the FMU's C is generated from them).
"""
from __future__ import annotations

import numpy as np


#: The effect's name (its run-time solves in the FMU: the effect's ``runtime``).
NAME = "lead-lag"

#: Blade section profile drag coefficient ``c_d0`` [-] (NACA 0012 at the small
#: angles of a trimmed rotor; Johnson, *Helicopter Theory*, uses 0.01).
CD0 = 0.01
#: Columns of the multiblade coefficients (:data:`lead_lag_terms.COLS`): the base
#: states ``z = (beta, lambda, beta')`` of a :class:`StateBlock`, the six
#: azimuth-unit inputs ``(theta0, theta1c, theta1s, muz, qbar, pbar)``, the lag
#: ``x = (zeta0, zeta1c, zeta1s, zeta0', zeta1c', zeta1s')``; and the base
#: equations' blocks (flap, flap rate, inflow).
Z_COLS = [0, 1, 2, 6, 7, 8, 3, 4, 5]
U_COLS = list(range(9, 15))
X_COLS = list(range(15, 21))
BETA, DBETA, LAMBDA = slice(0, 3), slice(3, 6), slice(6, 9)


def _arr(rows):
    try:
        return np.array(rows, dtype=float)
    except TypeError:                # symbols: the FMU's generator
        return np.array(rows, dtype=object)


def lag_structure(nu_zeta, zeta_lag):
    """The projected lag equation's spring, damper and rotating-frame terms moved to
    the right-hand side, rows ``(zeta0, zeta1c, zeta1s)`` per ``x`` (3 x 6) [-]:
    ``zeta0'' = -nu^2 zeta0 - C zeta0'``, ``zeta1c'' = -(nu^2 - 1) zeta1c - C zeta1s
    - C zeta1c' - 2 zeta1s'`` and ``zeta1s'' = -(nu^2 - 1) zeta1s + C zeta1c - C
    zeta1s' + 2 zeta1c'``, ``C = 2 zeta_lag nu`` (the Coriolis terms are the trim's:
    :func:`coefficients`)."""
    c = 2 * zeta_lag * nu_zeta
    k0 = nu_zeta**2
    k = k0 - 1
    o = 0 * c
    return _arr([[-k0, o, o, -c, o, o],
                 [o, -k, -c, o, -c, -2 + o],
                 [o, c, -k, o, 2 + o, -c]])


def _solve3(a, b, numeric=None):
    """``a^-1 b`` for a 3 x 3 ``a``: LAPACK for numbers; traced on symbols for the
    FMU (``numeric``, the constants' ``k.numeric``) a run-time call, the generated C
    solving the system (the effect's ``runtime``: a symbolic solve's nested quotients grow
    past what the code generator expands); Cramer's rule for symbols otherwise."""
    if a.dtype != object and np.asarray(b).dtype != object:
        return np.linalg.solve(a, b)
    if numeric is not None:
        args = tuple(a.ravel()) + tuple(np.asarray(b).ravel())
        return numeric(NAME, args, ((3, 1),))[0][:, 0]
    m = [[a[i, j] for j in range(3)] for i in range(3)]

    def d3(x):
        return (x[0][0] * (x[1][1] * x[2][2] - x[1][2] * x[2][1])
                - x[0][1] * (x[1][0] * x[2][2] - x[1][2] * x[2][0])
                + x[0][2] * (x[1][0] * x[2][1] - x[1][1] * x[2][0]))
    dm = d3(m)
    out = []
    for j in range(3):
        mj = [[b[i] if c == j else m[i][c] for c in range(3)] for i in range(3)]
        out.append(d3(mj) / dm)
    return np.array(out, dtype=object)


def _solve2(a, b, numeric=None):
    """``a^-1 b`` for a 2 x 2 ``a`` and ``b`` (2 x m): LAPACK for numbers; traced,
    each column a run-time 3 x 3 solve (``a`` bordered by a unit row, as
    :func:`second_harmonic`'s); Cramer's rule for symbols otherwise."""
    if a.dtype != object and np.asarray(b).dtype != object:
        return np.linalg.solve(a, b)
    b = np.asarray(b, dtype=object)
    o = 0 * a[0, 0]
    if numeric is not None:
        kk = np.array([[a[0, 0], a[0, 1], o], [a[1, 0], a[1, 1], o], [o, o, 1 + o]],
                      dtype=object)
        return np.column_stack([_solve3(kk, np.array([b[0, j], b[1, j], o], dtype=object),
                                        numeric)[:2] for j in range(b.shape[1])])
    det = a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]
    inv = np.array([[a[1, 1], -a[0, 1]], [-a[1, 0], a[0, 0]]], dtype=object) / det
    return inv @ b


def steady_lag(structure, structure2, stiffness, moment, numeric=None):
    """The steady lag ``(zeta0, zeta1c, zeta1s, zeta2c, zeta2s)`` [rad] of the trim:
    the averaged lag rows at rest, first harmonics and second,

    ``(S + A11) zeta_t + A12 zeta2_t + Z1 = 0``, ``A21 zeta_t + (A22 - S2) zeta2_t
    + Z2 = 0``,

    with ``S`` the spring, damper and rotating-frame displacement terms
    (:func:`lag_structure`), ``S2`` the second harmonic's
    (:func:`second_harmonic_structure`, ``structure2``), ``A`` the lag rows'
    displacement columns about the trim without lag (``stiffness``, 5 x 5,
    :func:`lead_lag_terms.lag_stiffness`) and ``Z`` the lag's trim moment
    (:func:`lead_lag_terms.lag_trim`: the drag and the Coriolis moment of the cyclic
    flap, whose 2/rev part ``-2 beta beta'`` holds the trim's 2/rev lag).  Solved
    by eliminating the second harmonic (two 2 x 2 systems, one 3 x 3)."""
    a, z = stiffness, moment
    p = _solve2(structure2 - a[3:, 3:],
                np.column_stack([a[3:, :3], z[3:]]), numeric)       # zeta2 = p (zeta, 1)
    z1 = _solve3(structure[:, :3] + a[:3, :3] + a[:3, 3:] @ p[:, :3],
                 -(z[:3] + a[:3, 3:] @ p[:, 3]), numeric)
    return np.concatenate([z1, p[:, :3] @ z1 + p[:, 3]])


def coefficients(mu, nb, dl, theta, beta, muz, lam, nu_zeta, zeta_lag, lm=None,
                 g_lambda=None, numeric=None):
    """The lag's multiblade coefficients about a forward-flight trim.

    Parameters
    ----------
    mu, nb, dl : float
        Advance ratio, ``n_beta`` and ``c_d0 / a0`` [-].
    theta : sequence of 3
        Trim pitch ``(0, 1c, 1s)`` (true, not recorded) [rad].
    beta : sequence of 5
        Trim flap ``(0, 1c, 1s, 2c, 2s)``: its 2/rev part the rigid blades'
        (:func:`inflowsim.model.effects.lead_lag.trim_flap2`) [rad].
    muz : float
        Trim hub velocity normal to the disc [-].
    lam : sequence of 3
        Trim inflow of the rigid blades (the basic model's steady state) [-].
    nu_zeta, zeta_lag : float
        Lag frequency [per rev] and damper [-] (the steady lag's).
    lm, g_lambda : ndarray (3, 3), optional
        The inflow model's gain ``L`` and the loads per inflow ``G_lambda``: the
        trim inflow then moves by the steady lag's share of the trim's loads,
        ``(I - L G_lambda)^-1 L dc`` (two fixed-point steps: the share is a few
        per cent of the cyclic loads; the steady lag and the inflow are found
        together to the square of that).  Without them the inflow is ``lam``.
    numeric : callable, optional
        Traced for the FMU: the constants' ``k.numeric`` (the 3 x 3 solves and the
        trim polynomials of :mod:`lead_lag_terms`, calls ``lead-lag/<table>``, run
        in the generated C, the effect's ``runtime``).

    Returns
    -------
    zeta_t : ndarray (5,)
        The steady lag ``(zeta0, zeta1c, zeta1s, zeta2c, zeta2s)``
        (:func:`steady_lag`) [rad].
    flap, lag, loads : ndarray (3, 21)
        The flap rows' right-hand side, the lag rows' (without
        :func:`lag_structure`) and ``(C_T, C_mc, C_ms) / (a0 s)``, columns
        :data:`lead_lag_terms.COLS`; in the flap and load rows the base columns
        hold only the steady lag's share (the rest is the base model's) [-].
    lam_t : ndarray (3,)
        The trim inflow they are linearised about [-].
    """
    # the generated tables (200 kB of source) are read only when a lag model is built,
    # not by every command that imports the catalogue
    from . import lead_lag_terms as lt
    s_x = lag_structure(nu_zeta, zeta_lag)
    s_2 = second_harmonic_structure(nu_zeta, zeta_lag)
    if numeric is not None:
        # traced: the trim inflow once at run time (its closed form is a quotient
        # that every coefficient would otherwise carry into the generator's expansion)
        lam = _solve3(np.eye(3).astype(object), np.asarray(lam, dtype=object), numeric)
    lam_t = np.asarray(lam)

    # traced, the trim polynomials too are run-time calls (their tables printed
    # into C): expanded into the descriptor they were most of its code
    tables = None if numeric is None else (
        lambda name, arg, shapes: numeric(f"{NAME}/{name}", arg, shapes))

    def at(lam_t):
        args = (mu, nb, dl, theta, beta, muz - lam_t[0], lam_t[1], lam_t[2])
        return args, steady_lag(s_x, s_2, lt.lag_stiffness(*args, numeric=tables),
                                lt.lag_trim(*args, numeric=tables), numeric)

    args, zt = at(lam_t)
    if lm is not None:
        a = np.eye(3) - lm @ g_lambda
        for _ in range(2):
            lam_t = np.asarray(lam) + _solve3(a, lm @ lt.load_trim(*args, tuple(zt),
                                                                   numeric=tables),
                                              numeric)
            args, zt = at(lam_t)
    flap, lag, loads = lt.terms(*args, tuple(zt), numeric=tables)
    # the second-harmonic lag, quasi-static, condensed into the first harmonics
    rows2, flap2, lag2, loads2 = (lambda r: (r[:2], *r[2:]))(
        lt.second_harmonic(*args, tuple(zt), numeric=tables))
    # traced, its rows and columns are run-time numbers (the table's call): the
    # products below are of numbers, not of polynomials
    t2 = second_harmonic(nu_zeta, zeta_lag, rows2, numeric)
    return (zt, flap + flap2 @ t2, lag + lag2 @ t2, loads + loads2 @ t2, lam_t)


def second_harmonic_structure(nu_zeta, zeta_lag):
    """The second-harmonic lag's spring, damper and rotating-frame displacement terms,
    rows ``(zeta2c, zeta2s)`` per ``(zeta2c, zeta2s)`` (2 x 2) [-]: with ``zeta =
    zeta2c cos 2psi + zeta2s sin 2psi`` at rest in the fixed frame, ``zeta'' + C zeta'
    + nu^2 zeta`` projected on ``(2 cos 2psi, 2 sin 2psi)`` is ``((nu^2 - 4) zeta2c + 2 C
    zeta2s, (nu^2 - 4) zeta2s - 2 C zeta2c)``, ``C = 2 zeta_lag nu``."""
    c = 2 * zeta_lag * nu_zeta
    k = nu_zeta**2 - 4
    return _arr([[k, 2 * c], [-2 * c, k]])


def second_harmonic(nu_zeta, zeta_lag, rows, numeric=None):
    """The quasi-static second-harmonic lag ``(zeta2c, zeta2s)`` per the columns of
    :data:`lead_lag_terms.COLS` (2 x 21) [rad per unit]: its rows at rest,
    ``S2 zeta2 = lag2 w + lag2_z2 zeta2`` (``S2``: :func:`second_harmonic_structure`;
    ``rows = (lag2, lag2_z2)`` of :func:`lead_lag_terms.second_harmonic`), solved for
    ``zeta2``.  Its modes lie at ``2 -+ nu_zeta`` per rev in the fixed frame (1.35 and
    2.65 per rev at ``nu_zeta = 0.65``), far above the flap's band: its own rates are
    left out (``model.md`` 9.1)."""
    lag2, lag2_z2 = rows
    k = second_harmonic_structure(nu_zeta, zeta_lag) - lag2_z2
    if k.dtype != object and np.asarray(lag2).dtype != object:
        return np.linalg.solve(k, lag2)
    # traced: each column a run-time 3 x 3 solve (the 2 x 2 bordered by a unit row),
    # so that the generated C multiplies the rows' polynomials by numbers known at
    # run time instead of expanding products of polynomials
    lag2 = np.asarray(lag2, dtype=object)
    o = 0 * k[0, 0]
    kk = np.array([[k[0, 0], k[0, 1], o], [k[1, 0], k[1, 1], o], [o, o, 1 + o]],
                  dtype=object)
    out = np.zeros(lag2.shape, dtype=object)
    for j in range(lag2.shape[1]):
        if not (lag2[0, j] == 0 and lag2[1, j] == 0):
            out[:, j] = _solve3(kk, np.array([lag2[0, j], lag2[1, j], o], dtype=object),
                                numeric)[:2]
    return out


__all__ = ["NAME", "CD0", "Z_COLS", "U_COLS", "X_COLS", "lag_structure", "steady_lag",
           "coefficients", "second_harmonic_structure", "second_harmonic"]
