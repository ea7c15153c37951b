r"""Nonlinear individual-blade rotor: the truth of the virtual flight test.

Not the code path that is fitted: ``Nb`` blades, each with its own flap
degree of freedom integrated in time, blade-element lift integrated along the
span, and three dynamic-inflow states driven by the difference between the
blades' loads and the local-momentum loads of the disc.  Azimuth time
``psi = Omega t``, ``' = d/dpsi``; conventions of ``model.md`` section 1.

Blade ``i`` at ``psi_i = psi + 2 pi i / Nb`` (velocities over ``Omega R``):

``U_T = r + mux sin psi_i + muy cos psi_i``,
``U_P = muz - lambda_i - r beta_i' - beta_i (mux cos psi_i - muy sin psi_i)
+ r (pbar sin psi_i + qbar cos psi_i)``,
``g_i(r) = theta_i U_T^2 + U_P U_T`` (lift per span over ``rho a0 c (Omega R)^2 / 2``),
with ``theta_i = theta0 + theta1c cos psi_i + theta1s sin psi_i`` the true pitch
and ``lambda_i = lambda0 + r (lambda1c cos psi_i + lambda1s sin psi_i)`` (6).
No twist, no tip loss, no reverse-flow correction; ``mux, muy`` are the *total*
in-plane velocities, so perturbations of the advance ratio act on the blades.

Flap of each blade (centre-spring equivalent of the hinge offset, Lock number
``gamma = 8 n_beta``):

``beta_i'' + lambda_beta2 beta_i = gamma/2 int_0^1 r g_i dr
+ (2 pbar + qbar') cos psi_i + (pbar' - 2 qbar) sin psi_i``

where the last two terms are the gyroscopic and hub-acceleration moments in the
rotating frame.  Projected on multiblade coordinates with the second derivatives
dropped and ``mux = mu``, ``muy = 0`` this is *exactly* Eq. (1) with the ``C, D,
H_theta, H_nu, H_eta, H_lambda`` of ``model.md`` section 2 (``tests/test_bladesim.py``
checks it by a finite-difference Jacobian).

Loads of the actual blades (Eq. 3; ``c`` normalised as in ``model.md`` section 3):
``c_blade = 1/(2 Nb) sum_i int_0^1 (1, -r cos psi_i, -r sin psi_i) g_i dr``.

Local-momentum loads of the disc (Eq. 5 with ``T = int 2 rho v_i V dA``):
``c_mom = 4/(a0 s) avg_psi int_0^1 (1, -r cos psi, -r sin psi) lambda_i V r dr``,
with the speed through the disc of Eq. (14)

``V = sqrt(mux^2 + muy^2 + (w_B - lambda_i)^2)``,

``w_B - lambda_i = U_P + theta U_T`` the blade normal velocity of Eq. (15) less the
inflow (``theta U_T`` carries the ``theta`` terms of ``p*, q*, T1, T2, theta0*``),
evaluated at quadrature points over the whole disc from the blades' multiblade
flap, flap rate and pitch (their 0 and 1/rev harmonics: the tip-path plane).

Inflow (apparent-mass form, ``M = L^-1 D_tau``):
``D_tau lambda' = L (c_blade - c_mom)``, ``L = diag(a0 s/(2 mu), -2 a0 s/mu,
-2 a0 s/mu)`` at the trim ``mu``.  With the Pitt-Peters time constants ``M`` is the
Pitt-Peters apparent mass and does not depend on ``mu``.

Replacing ``V`` by ``mu`` (``speed="mu"``) gives, because ``lambda_i`` is linear in
``r cos psi, r sin psi`` and the disc averages of the cross products vanish,
``c_mom = L^-1 lambda`` exactly (e.g. ``C_T = 4 avg int lambda0 mu r dr = 2 mu lambda0``),
so the inflow equation becomes ``D_tau lambda' + lambda = L c_blade``, the basic
model (2) with separate time constants.  With Eq. (14) the products of the trim
inflow with the perturbations of ``V`` (blade normal velocity, in-plane speed) are
the Glauert-type coupling ``F nu_lambda + G mu_xy`` of Eq. (19), from the physics.

State ``x = (beta_1..beta_Nb, beta_1'..beta_Nb', lambda0, lambda1c, lambda1s)``;
inputs ``u`` in azimuth units, the order of ``inflowsim.model.equations.INPUTS_AZ``
(``theta0 theta1c theta1s muz qbar pbar qbar' pbar' mux muy``), totals, true pitch.
Integration: classical RK4 in azimuth, fixed step, inputs held per step.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from ..errors import InputError
from ..channels import FLAP, INFLOW
from ..model.params import PUMA, Constants
from ..progress import bar
from ..physics.theory import PUMA_LAMBDA_BETA2, PUMA_N_BETA, pitt_peters_time_constants

SPEEDS = ("eq14", "mu")
#: Largest RK4 step in azimuth [rad] (5 deg).
MAX_STEP = math.radians(5.0)


@dataclass(frozen=True)
class RotorSpec:
    """Physical and numerical description of the individual-blade rotor.

    Parameters
    ----------
    constants : Constants
        ``mu`` (trim advance ratio, sets ``L``) [-], ``a0`` [1/rad], ``solidity`` [-],
        ``omega`` [rad/s], ``radius`` [m].
    n_blades : int
        Number of blades (Puma: 4) [-].
    lambda_beta2 : float
        Flap frequency squared (spring / hinge-offset equivalent) [-].
    n_beta : float
        Inertia number ``gamma/8`` [-].
    tau0, tau_cs : float, optional
        Inflow time constants [azimuth rad]; default Pitt-Peters at ``mu``.
    speed : {"eq14", "mu"}
        Speed through the disc in the momentum loads: Eq. (14) or the trim ``mu``.
    n_span : int
        Gauss-Legendre points along each blade (3 integrate the polynomial lift exactly).
    n_disc_psi, n_disc_r : int
        Disc quadrature for the momentum loads (uniform azimuth x Gauss-Legendre radius).
    K_R : float
        Keller's wake-curvature gain [-] (``wake-distortion``, ``model.md``): the
        cyclic inflow equations gain ``K_R (q_tpp, p_tpp)``, the tip-path plane's
        pitch and roll rates from the blades' flap.  0 (default): no wake bending,
        the truth of the detection studies.
    """

    constants: Constants = PUMA
    n_blades: int = 4
    lambda_beta2: float = PUMA_LAMBDA_BETA2
    n_beta: float = PUMA_N_BETA
    tau0: float | None = None
    tau_cs: float | None = None
    speed: str = "eq14"
    n_span: int = 4
    n_disc_psi: int = 12
    n_disc_r: int = 4
    K_R: float = 0.0

    def __post_init__(self):
        pp = pitt_peters_time_constants(self.constants.mu)
        if self.tau0 is None:
            object.__setattr__(self, "tau0", pp[0])
        if self.tau_cs is None:
            object.__setattr__(self, "tau_cs", pp[1])

    def check(self) -> "RotorSpec":
        """Raise :class:`InputError` naming the first bad value."""
        self.constants.check()
        if int(self.n_blades) != self.n_blades or self.n_blades < 3:
            raise InputError(f"n_blades = {self.n_blades}: need a whole number >= 3")
        for name in ("lambda_beta2", "n_beta", "tau0", "tau_cs"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name} = {v}: must be a finite number > 0")
        if self.speed not in SPEEDS:
            raise InputError(f"speed {self.speed!r}: choose {' or '.join(SPEEDS)}")
        if not np.isfinite(self.K_R):
            raise InputError(f"K_R = {self.K_R}: must be a finite number")
        for name in ("n_span", "n_disc_psi", "n_disc_r"):
            if int(getattr(self, name)) < 3:
                raise InputError(f"{name} = {getattr(self, name)}: need at least 3 points")
        return self

    def with_(self, **kw) -> "RotorSpec":
        return replace(self, **kw)

    @property
    def n_states(self) -> int:
        return 2 * self.n_blades + 3

    @property
    def l_matrix(self) -> np.ndarray:
        """Local-momentum gain ``L`` at the trim ``mu`` (Eq. 19) [-]."""
        k = self.constants
        return np.diag([k.a0s / (2 * k.mu), -2 * k.a0s / k.mu, -2 * k.a0s / k.mu])


@lru_cache(maxsize=16)
def _gauss(n: int):
    x, w = np.polynomial.legendre.leggauss(int(n))
    return 0.5 * (x + 1.0), 0.5 * w          # on [0, 1]


class BladeRotor:
    """Right-hand side and fixed-step RK4 integrator for a :class:`RotorSpec`.

    Parameters
    ----------
    spec : RotorSpec
    """

    def __init__(self, spec: RotorSpec):
        self.spec = spec.check()
        nb = spec.n_blades
        self.nb = nb
        self.offsets = 2.0 * np.pi * np.arange(nb) / nb
        r, w = _gauss(spec.n_span)
        self.r = r
        self.w_span = np.column_stack([w, w * r])        # int g dr, int r g dr
        rd, wd = _gauss(spec.n_disc_r)
        pd = 2.0 * np.pi * np.arange(spec.n_disc_psi) / spec.n_disc_psi
        cd, sd = np.cos(pd), np.sin(pd)
        self.disc_r = np.vstack([np.ones_like(rd), rd])
        self.disc_basis = np.column_stack([np.ones_like(pd), cd, sd, cd * cd, sd * sd,
                                           cd * sd])
        self._basis0 = np.column_stack([np.ones(nb), np.cos(self.offsets),
                                        np.sin(self.offsets)])
        self._mbc = np.array([1.0, 2.0, 2.0]) / nb
        # (1, -r cos, -r sin) lambda_i V r over the disc, 4/(a0 s) avg_psi int dr
        k = spec.constants
        scale = 4.0 / (k.a0s * spec.n_disc_psi)
        self.w_disc = scale * np.column_stack([wd * rd, wd * rd * rd])
        self.minv = np.diag(1.0 / np.array([spec.tau0, spec.tau_cs, spec.tau_cs])) \
            @ spec.l_matrix
        self.linv = np.linalg.inv(spec.l_matrix)
        self.gamma = 8.0 * spec.n_beta

    # -- loads ------------------------------------------------------------------
    def blade_basis(self, psi: float) -> np.ndarray:
        """``(1, cos psi_i, sin psi_i)`` per blade, shape ``(Nb, 3)``."""
        c, s = math.cos(psi), math.sin(psi)
        return self._basis0 @ np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])

    def blade_terms(self, psi, x, u, bb=None):
        """Flap moment ``gamma/2 int r g dr`` of each blade and the blade loads.

        Returns ``(moment (Nb,), c_blade (3,))`` with ``c_blade = (C_T, C_mc,
        C_ms)/(a0 s)`` of the actual blades (Gauss-Legendre along the span).
        """
        nb = self.nb
        bb = self.blade_basis(psi) if bb is None else bb
        beta, dbeta, lam = x[:nb], x[nb:2 * nb], x[2 * nb:]
        th0, th1c, th1s, muz, qb, pb, _, _, mux, muy = u
        # per blade: pitch, radial speed, in-plane speed, r-coefficient of -U_P less beta'
        k = np.array([[th0, 0.0, 0.0, 0.0],
                      [th1c, mux, muy, lam[1] - qb],
                      [th1s, -muy, mux, lam[2] - pb]])
        theta, radial, a, hp = (bb @ k).T
        e = (muz - lam[0]) - beta * radial            # U_P = e - h r
        h = hp + dbeta
        r = self.r
        ut = r + a[:, None]                           # U_T
        g = (theta[:, None] * ut + (e[:, None] - h[:, None] * r)) * ut
        gi = g @ self.w_span                          # (Nb, 2): int g dr, int r g dr
        m = bb.T @ gi
        c_blade = np.array([m[0, 0], -m[1, 1], -m[2, 1]]) / (2.0 * nb)
        return 0.5 * self.gamma * gi[:, 1], c_blade

    def momentum_loads(self, psi, x, u, speed=None, bb=None) -> np.ndarray:
        """Local-momentum loads ``c_mom`` (Eqs. 5, 14-15) over the disc quadrature [-].

        ``speed`` ``"eq14"``: ``V = sqrt(mux^2 + muy^2 + (w_B - lambda_i)^2)``;
        ``"mu"``: ``V = mu`` (then ``c_mom = L^-1 lambda``).
        """
        speed = speed or self.spec.speed
        nb = self.nb
        lam0, lam1c, lam1s = x[2 * nb:]
        th0, th1c, th1s, muz, qb, pb, _, _, mux, muy = u
        basis, rr = self.disc_basis, self.disc_r   # (1, c, s, c^2, s^2, cs); (1, r)
        lam_i = basis[:, :3] @ np.array([[lam0, 0.0], [0.0, lam1c], [0.0, lam1s]]) @ rr
        if speed == "mu":
            q = lam_i * self.spec.constants.mu
        else:
            bb = self.blade_basis(psi) if bb is None else bb
            # tip-path plane: 0 and 1/rev harmonics of the blades' flap and flap rate
            (b0, b1c, b1s), (d0, d1c, d1s) = (x[:2 * nb].reshape(2, nb) @ bb) * self._mbc
            # w_B - lambda_i = U_P + theta U_T = A0 + A1 r - lambda_i with
            #   A0 = muz - beta (mux cos - muy sin) + theta (mux sin + muy cos),
            #   A1 = theta - beta' + pbar sin + qbar cos,
            # the harmonic products written exactly on the basis (1, c, s, c^2, s^2, cs)
            a = np.array([[muz, th0 - d0],
                          [th0 * muy - b0 * mux, th1c - d1c + qb],
                          [th0 * mux + b0 * muy, th1s - d1s + pb],
                          [th1c * muy - b1c * mux, 0.0],
                          [th1s * mux + b1s * muy, 0.0],
                          [th1c * mux + b1c * muy + th1s * muy - b1s * mux, 0.0]])
            wl = basis @ a @ rr - lam_i
            q = lam_i * np.sqrt((mux * mux + muy * muy) + wl * wl)
        m = basis[:, :3].T @ (q @ self.w_disc)      # (3, 2)
        return np.array([m[0, 0], -m[1, 1], -m[2, 1]])

    # -- dynamics ---------------------------------------------------------------
    def rhs(self, psi, x, u) -> np.ndarray:
        """``x'`` [per azimuth rad] for state ``x`` and held inputs ``u`` (azimuth units)."""
        nb = self.nb
        bb = self.blade_basis(psi)
        moment, c_blade = self.blade_terms(psi, x, u, bb)
        qb, pb, dqb, dpb = u[4], u[5], u[6], u[7]
        if self.spec.speed == "mu":
            c_mom = self.linv @ x[2 * nb:]
        else:
            c_mom = self.momentum_loads(psi, x, u, bb=bb)
        out = np.empty_like(x)
        out[:nb] = x[nb:2 * nb]
        # centre spring plus the gyroscopic and hub-acceleration moments
        out[nb:2 * nb] = (moment - self.spec.lambda_beta2 * x[:nb]
                          + bb @ (0.0, 2.0 * pb + dqb, dpb - 2.0 * qb))
        out[2 * nb:] = self.minv @ (c_blade - c_mom)
        if self.spec.K_R:
            # wake curvature: the tip-path plane's rates qbar - beta1c', pbar - beta1s'
            # (the blades' rate harmonics are beta1c' + beta1s, beta1s' - beta1c)
            (b0, b1c, b1s), (d0, d1c, d1s) = (x[:2 * nb].reshape(2, nb) @ bb) * self._mbc
            kr = self.spec.K_R / self.spec.tau_cs
            out[2 * nb + 1] += kr * (qb - (d1c - b1s))
            out[2 * nb + 2] += kr * (pb - (d1s + b1c))
        return out

    def step(self, psi, x, u, h, u_mid=None, u_end=None) -> np.ndarray:
        """One classical RK4 step of ``h`` [azimuth rad]: ``u`` held, or ``u`` at the
        start, ``u_mid`` at the middle and ``u_end`` at the end of the step (inputs
        that vary continuously: fourth order for smooth inputs)."""
        f = self.rhs
        um = u if u_mid is None else u_mid
        ue = u if u_end is None else u_end
        k1 = f(psi, x, u)
        k2 = f(psi + 0.5 * h, x + 0.5 * h * k1, um)
        k3 = f(psi + 0.5 * h, x + 0.5 * h * k2, um)
        k4 = f(psi + h, x + h * k3, ue)
        return x + h / 6.0 * (k1 + 2.0 * (k2 + k3) + k4)

    def integrate(self, x0, psi0: float, u_samples, dpsi: float, max_step: float = MAX_STEP,
                  u_fine=None, progress=None):
        """States at every sample and every RK4 sub-step.

        Parameters
        ----------
        x0 : array_like
            State at ``psi0``.
        psi0 : float
            Azimuth of blade 0 at the first sample [rad].
        u_samples : array_like, shape (N, 10)
            Inputs (azimuth units, totals) held over each sample interval.
        dpsi : float
            Azimuth per sample, ``Omega dt`` [rad].
        max_step : float
            Largest RK4 step [rad]; each sample is split in equal sub-steps.
        u_fine : callable, optional
            Continuously varying inputs: ``u_fine(n_sub)`` returns the inputs at
            every half sub-step, shape ``(1 + 2 (N-1) n_sub, 10)`` (azimuth
            ``psi0 + j h / 2``); ``u_samples`` are then not held.
        progress : callable, optional
            Progress (:func:`inflowsim.progress.bar`), stepped per sample.

        Returns
        -------
        x : ndarray (N, n_states)
            States at the samples (``x[0] = x0``).
        sub : ndarray (1 + (N-1) n_sub, n_states)
            States at every sub-step (for interpolation between samples).
        n_sub : int
        """
        u_samples = np.asarray(u_samples, dtype=float)
        n = len(u_samples)
        n_sub = max(1, int(math.ceil(dpsi / max_step - 1e-12)))
        h = dpsi / n_sub
        sub = np.empty((1 + (n - 1) * n_sub, self.spec.n_states))
        x = np.array(x0, dtype=float)
        sub[0] = x
        j = 0
        fine = None if u_fine is None else np.asarray(u_fine(n_sub), dtype=float)
        with bar(progress, n - 1, "flighttest: flying the blades", "sample") as b:
            for k in range(n - 1):
                uk = tuple(float(v) for v in u_samples[k])
                base = psi0 + k * dpsi
                for m in range(n_sub):
                    if fine is None:
                        x = self.step(base + m * h, x, uk, h)
                    else:
                        i = 2 * j
                        x = self.step(base + m * h, x, fine[i], h, fine[i + 1],
                                      fine[i + 2])
                    j += 1
                    sub[j] = x
                if k % 100 == 99:
                    b.update(100)
        if not np.all(np.isfinite(sub[j])):
            raise InputError("the blade simulation diverged (non-finite state): "
                             "inputs too large or rotor unstable")
        return sub[::n_sub], sub, n_sub

    # -- trim -------------------------------------------------------------------
    def periodic_trim(self, u_trim, x_guess=None, max_revs: int = 200,
                      tol: float = 1e-12, max_step: float = MAX_STEP) -> "RotorTrim":
        """Periodic solution for constant inputs ``u_trim`` (the given controls).

        Marches blade-passage periods ``2 pi/Nb``, relabelling the blades after
        each (:meth:`relabel`), until the state changes by less than ``tol`` over a
        period; the returned state is at ``psi = 0`` (blade 0 aft).
        """
        nb = self.nb
        per = 2.0 * np.pi / nb
        n_sub = max(1, int(math.ceil(per / max_step - 1e-12)))
        h = per / n_sub
        u = tuple(float(v) for v in u_trim)
        x = np.zeros(self.spec.n_states) if x_guess is None else np.array(x_guess, float)
        for it in range(max_revs * nb):
            x_old = x
            for m in range(n_sub):
                x = self.step(m * h, x, u, h)
            x = self.relabel(x)
            if not np.all(np.isfinite(x)):
                break
            if np.max(np.abs(x - x_old)) < tol:
                return self._trim_summary(x, u, n_sub, h, it + 1)
        raise InputError(f"the blade simulation found no periodic trim in {max_revs} "
                         "revolutions at these controls (rotor unstable?)")

    def relabel(self, x) -> np.ndarray:
        """State after one blade passage expressed with blade 0 back at ``psi = 0``:
        the blade then at ``2 pi j/Nb`` was blade ``j - 1``."""
        nb = self.nb
        out = np.array(x, dtype=float)
        out[:nb] = np.roll(x[:nb], 1)
        out[nb:2 * nb] = np.roll(x[nb:2 * nb], 1)
        return out

    def _trim_summary(self, x, u, n_sub, h, periods):
        from ..physics.multiblade import multiblade
        nb = self.nb
        xs, cb = [x], []
        xi = x
        for m in range(n_sub):
            xi = self.step(m * h, xi, u, h)
            xs.append(xi)
        xs = np.array(xs[:-1])
        psi = np.arange(n_sub) * h
        beta_mb = multiblade(xs[:, :nb], psi)
        for p, xv in zip(psi, xs):
            cb.append(self.blade_terms(p, xv, u)[1])
        return RotorTrim(x=x, beta=beta_mb.mean(axis=0), lam=xs[:, 2 * nb:].mean(axis=0),
                         c=np.mean(cb, axis=0), beta_ripple=np.ptp(beta_mb, axis=0),
                         inputs=np.array(u), periods=periods)


@dataclass(frozen=True, eq=False)
class RotorTrim:
    """Periodic trim: state at ``psi = 0`` and period means.

    ``beta``: mean multiblade flap [rad]; ``lam``: mean inflow [-]; ``c``: mean
    blade loads ``(C_T, C_mc, C_ms)/(a0 s)``; ``beta_ripple``: peak-to-peak of the
    multiblade flap over a period (the ``Nb``/rev content) [rad]; ``periods``:
    blade-passage periods marched.
    """

    x: np.ndarray
    beta: np.ndarray
    lam: np.ndarray
    c: np.ndarray
    beta_ripple: np.ndarray
    inputs: np.ndarray
    periods: int = 0

    def as_dict(self) -> dict:
        names = FLAP
        d = {n: float(v) for n, v in zip(names, self.beta)}
        d.update({n: float(v) for n, v in zip(INFLOW,
                                              self.lam)})
        d.update({n: float(v) for n, v in zip(("cT", "cmc", "cms"), self.c)})
        d["beta_ripple"] = {n: float(v) for n, v in zip(names, self.beta_ripple)}
        return d


def multiblade_derivatives(rotor: BladeRotor, psi: float, z, u) -> np.ndarray:
    """Multiblade form of the blade equations at azimuth ``psi``.

    ``z = (beta, beta', lambda)`` (9 multiblade values); returns
    ``(beta'', lambda')`` (6).  The blades are set to ``beta0 + beta1c cos psi_i +
    beta1s sin psi_i`` (no reactionless motion), their accelerations projected
    back with the rotating-frame terms removed:
    ``beta1c'' = P_c(beta_i'') - 2 beta1s' + beta1c``,
    ``beta1s'' = P_s(beta_i'') + 2 beta1c' + beta1s``.
    With many blades (``Nb >= 8``) the projection is the azimuth average, so this
    is the constant-coefficient multiblade system the linear model approximates.
    """
    from ..physics.multiblade import blade_angles, multiblade
    z = np.asarray(z, dtype=float)
    nb = rotor.nb
    b, db, lam = z[0:3], z[3:6], z[6:9]
    rate_mb = np.array([db[0], db[1] + b[2], db[2] - b[1]])   # blade-rate harmonics
    x = np.concatenate([blade_angles(b, psi, nb), blade_angles(rate_mb, psi, nb), lam])
    f = rotor.rhs(psi, x, tuple(float(v) for v in u))
    p = multiblade(f[nb:2 * nb], psi)
    dd = np.array([p[0], p[1] - 2 * db[2] + b[1], p[2] + 2 * db[1] + b[2]])
    return np.concatenate([dd, f[2 * nb:]])


__all__ = ["SPEEDS", "MAX_STEP", "RotorSpec", "BladeRotor", "RotorTrim",
           "multiblade_derivatives"]
