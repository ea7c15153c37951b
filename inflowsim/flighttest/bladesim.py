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
from ..physics.lead_lag import CD0
from ..physics.theory import PUMA_LAMBDA_BETA2, PUMA_N_BETA, pitt_peters_time_constants

SPEEDS = ("eq14", "mu")
#: Multiblade lag [rad] (blades with lead-lag).
LAG = ("zeta0", "zeta1c", "zeta1s")
#: The lag frequencies the truth flies [per rev] (the ``lead-lag`` effect's range).
LAG_RANGE = (0.05, 1.5)
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
    nu_zeta : float or None
        Each blade's lead-lag degree of freedom (``lead-lag``, ``model.md`` 9.1 and
        "The blade truth's lead-lag"): rotating lag frequency [per rev] of the
        lag hinge's equivalent spring.  ``None`` (default): rigid in-plane, the
        truth of the detection studies (its states and arithmetic unchanged).
    zeta_lag : float
        The lag damper's damping ratio [-] (``C_zeta = 2 zeta_lag nu_zeta``); with
        ``nu_zeta`` only.
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
    nu_zeta: float | None = None
    zeta_lag: float = 0.2

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
        if self.nu_zeta is not None:
            if not (np.isfinite(self.nu_zeta) and LAG_RANGE[0] <= self.nu_zeta
                    <= LAG_RANGE[1]):
                raise InputError(f"nu_zeta = {self.nu_zeta}: the lag frequency must be "
                                 f"in [{LAG_RANGE[0]:g}, {LAG_RANGE[1]:g}] per rev")
            if not (np.isfinite(self.zeta_lag) and 0 <= self.zeta_lag <= 3.0):
                raise InputError(f"zeta_lag = {self.zeta_lag}: the lag damper's "
                                 "damping ratio must be in [0, 3]")
        for name in ("n_span", "n_disc_psi", "n_disc_r"):
            if int(getattr(self, name)) < 3:
                raise InputError(f"{name} = {getattr(self, name)}: need at least 3 points")
        return self

    def with_(self, **kw) -> "RotorSpec":
        return replace(self, **kw)

    @property
    def lag(self) -> bool:
        """Whether the blades have their lead-lag degree of freedom."""
        return self.nu_zeta is not None

    @property
    def n_states(self) -> int:
        return (4 if self.lag else 2) * self.n_blades + 3

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
        #: profile drag over the lift slope, ``delta = c_d0 / a0`` (the lag's drag)
        self.delta = CD0 / k.a0
        self.lag = spec.lag

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
        beta, dbeta, lam = x[:nb], x[nb:2 * nb], x[2 * nb:2 * nb + 3]
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

    def lag_terms(self, psi, x, u, bb=None):
        """With the blades' lead-lag: flap and lag moments of each blade and the
        blade loads (``model.md``, "The blade truth's lead-lag").

        Blade ``i`` lags by ``zeta_i`` (aft, against the rotation): its azimuth in
        space is ``psi_i - zeta_i``, where the free stream, the radial flow, the
        inflow and the body rates meet it and where its lift acts on the hub; the
        swashplate sets its pitch at the hub azimuth ``psi_i`` (no kinematic
        pitch-lag coupling); its lag rate takes airspeed, ``U_T = r (1 - zeta_i')
        + mux sin(psi_i - zeta_i) + muy cos(psi_i - zeta_i)``.  In-plane force (aft
        positive) per span ``-(theta U_T + U_P) U_P + delta U_T^2`` over ``rho a0 c
        (Omega R)^2 / 2``: the lift tilted by the inflow angle and the profile drag.

        Returns ``(flap moment (Nb,), lag moment (Nb,), c_blade (3,))``: ``gamma/2
        int r g dr``, ``gamma/2 int r d dr`` and ``(C_T, C_mc, C_ms)/(a0 s)``.
        """
        nb = self.nb
        bb = self.blade_basis(psi) if bb is None else bb
        beta, dbeta, lam = x[:nb], x[nb:2 * nb], x[2 * nb:2 * nb + 3]
        zeta, dzeta = x[2 * nb + 3:3 * nb + 3], x[3 * nb + 3:]
        th0, th1c, th1s, muz, qb, pb, _, _, mux, muy = u
        theta = th0 + th1c * bb[:, 1] + th1s * bb[:, 2]
        ang = psi + self.offsets - zeta
        ca, sa = np.cos(ang), np.sin(ang)
        radial = mux * ca - muy * sa
        a = mux * sa + muy * ca
        e = (muz - lam[0]) - beta * radial                     # U_P = e - h r
        h = (lam[1] - qb) * ca + (lam[2] - pb) * sa + dbeta
        r = self.r
        ut = r * (1.0 - dzeta[:, None]) + a[:, None]           # U_T
        up = e[:, None] - h[:, None] * r
        tu = theta[:, None] * ut + up
        g = tu * ut                                            # lift
        d = -tu * up + self.delta * ut * ut                    # in-plane force, aft
        gi = g @ self.w_span
        di = d @ self.w_span[:, 1]
        c_blade = np.array([gi[:, 0].sum(), -(ca * gi[:, 1]).sum(),
                            -(sa * gi[:, 1]).sum()]) / (2.0 * nb)
        return 0.5 * self.gamma * gi[:, 1], 0.5 * self.gamma * di, c_blade

    def momentum_loads(self, psi, x, u, speed=None, bb=None) -> np.ndarray:
        """Local-momentum loads ``c_mom`` (Eqs. 5, 14-15) over the disc quadrature [-].

        ``speed`` ``"eq14"``: ``V = sqrt(mux^2 + muy^2 + (w_B - lambda_i)^2)``;
        ``"mu"``: ``V = mu`` (then ``c_mom = L^-1 lambda``).
        """
        speed = speed or self.spec.speed
        nb = self.nb
        lam0, lam1c, lam1s = x[2 * nb:2 * nb + 3]
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
        if self.lag:
            moment, lag_moment, c_blade = self.lag_terms(psi, x, u, bb)
        else:
            moment, c_blade = self.blade_terms(psi, x, u, bb)
        qb, pb, dqb, dpb = u[4], u[5], u[6], u[7]
        if self.spec.speed == "mu":
            c_mom = self.linv @ x[2 * nb:2 * nb + 3]
        else:
            c_mom = self.momentum_loads(psi, x, u, bb=bb)
        out = np.empty_like(x)
        out[:nb] = x[nb:2 * nb]
        # centre spring plus the gyroscopic and hub-acceleration moments
        out[nb:2 * nb] = (moment - self.spec.lambda_beta2 * x[:nb]
                          + bb @ (0.0, 2.0 * pb + dqb, dpb - 2.0 * qb))
        out[2 * nb:2 * nb + 3] = self.minv @ (c_blade - c_mom)
        if self.lag:
            self._lag_rows(out, x, bb, lag_moment, dqb, dpb)
        if self.spec.K_R:
            # wake curvature: the tip-path plane's rates qbar - beta1c', pbar - beta1s'
            # (the blades' rate harmonics are beta1c' + beta1s, beta1s' - beta1c)
            (b0, b1c, b1s), (d0, d1c, d1s) = (x[:2 * nb].reshape(2, nb) @ bb) * self._mbc
            kr = self.spec.K_R / self.spec.tau_cs
            out[2 * nb + 1] += kr * (qb - (d1c - b1s))
            out[2 * nb + 2] += kr * (pb - (d1s + b1c))
        return out

    def _lag_rows(self, out, x, bb, lag_moment, dqb, dpb):
        """The lag's inertia (Lagrange's equations of a blade turning at ``Omega``
        about a hinge at the shaft, flap up, lag aft: ``model.md``, "The blade
        truth's lead-lag") into ``out``: the flap rows gain the Coriolis
        ``-sin beta cos beta ((1 - zeta')^2 - 1)``, the lag rows are
        ``cos^2 beta zeta'' = Z - nu^2 zeta - C zeta' - sin 2beta beta' (1 - zeta')
        + sin beta cos beta (pbar' cos psi_i - qbar' sin psi_i)``."""
        nb = self.nb
        beta, dbeta = x[:nb], x[nb:2 * nb]
        zeta, dzeta = x[2 * nb + 3:3 * nb + 3], x[3 * nb + 3:]
        sc = np.sin(beta) * np.cos(beta)
        out[nb:2 * nb] -= sc * (dzeta * dzeta - 2.0 * dzeta)
        nu = self.spec.nu_zeta
        out[2 * nb + 3:3 * nb + 3] = dzeta
        out[3 * nb + 3:] = (lag_moment - nu * nu * zeta
                            - 2.0 * self.spec.zeta_lag * nu * dzeta
                            - 2.0 * sc * dbeta * (1.0 - dzeta)
                            + sc * (dpb * bb[:, 1] - dqb * bb[:, 2])) / np.cos(beta) ** 2

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
        if self.lag and x_guess is None:
            # the lag's quasi-static deflection under the trim's drag moment, and
            # time for the lightly damped lag to settle (decay ~ zeta_lag nu per rad)
            x[2 * nb + 3:3 * nb + 3] = np.mean(self.lag_terms(0.0, x, u)[1]) \
                / self.spec.nu_zeta ** 2
            max_revs = max(max_revs, int(math.ceil(
                6.0 / (self.spec.zeta_lag * self.spec.nu_zeta + 0.005))))
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
        if self.lag:
            for lo in (2 * nb + 3, 3 * nb + 3):
                out[lo:lo + nb] = np.roll(x[lo:lo + nb], 1)
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
            cb.append((self.lag_terms if self.lag else self.blade_terms)(p, xv, u)[-1])
        zeta = None
        if self.lag:
            zeta = multiblade(xs[:, 2 * nb + 3:3 * nb + 3], psi).mean(axis=0)
        return RotorTrim(x=x, beta=beta_mb.mean(axis=0),
                         lam=xs[:, 2 * nb:2 * nb + 3].mean(axis=0),
                         c=np.mean(cb, axis=0), beta_ripple=np.ptp(beta_mb, axis=0),
                         inputs=np.array(u), periods=periods, zeta=zeta)


@dataclass(frozen=True, eq=False)
class RotorTrim:
    """Periodic trim: state at ``psi = 0`` and period means.

    ``beta``: mean multiblade flap [rad]; ``lam``: mean inflow [-]; ``c``: mean
    blade loads ``(C_T, C_mc, C_ms)/(a0 s)``; ``beta_ripple``: peak-to-peak of the
    multiblade flap over a period (the ``Nb``/rev content) [rad]; ``periods``:
    blade-passage periods marched; ``zeta``: mean multiblade lag [rad] (blades with
    lead-lag; ``None`` without).
    """

    x: np.ndarray
    beta: np.ndarray
    lam: np.ndarray
    c: np.ndarray
    beta_ripple: np.ndarray
    inputs: np.ndarray
    periods: int = 0
    zeta: np.ndarray | None = None

    def as_dict(self) -> dict:
        names = FLAP
        d = {n: float(v) for n, v in zip(names, self.beta)}
        d.update({n: float(v) for n, v in zip(INFLOW,
                                              self.lam)})
        d.update({n: float(v) for n, v in zip(("cT", "cmc", "cms"), self.c)})
        d["beta_ripple"] = {n: float(v) for n, v in zip(names, self.beta_ripple)}
        if self.zeta is not None:
            d.update({n: float(v) for n, v in zip(LAG, self.zeta)})
        return d


def multiblade_derivatives(rotor: BladeRotor, psi: float, z, u) -> np.ndarray:
    """Multiblade form of the blade equations at azimuth ``psi``.

    ``z = (beta, beta', lambda)`` (9 multiblade values), with the blades' lead-lag
    ``z = (beta, beta', lambda, zeta, zeta')`` (15); returns ``(beta'', lambda')``
    (6), with lag ``(beta'', lambda', zeta'')`` (9).  The blades are set to ``beta0
    + beta1c cos psi_i + beta1s sin psi_i`` (no reactionless motion; the lag
    likewise), their accelerations projected back with the rotating-frame terms
    removed:
    ``beta1c'' = P_c(beta_i'') - 2 beta1s' + beta1c``,
    ``beta1s'' = P_s(beta_i'') + 2 beta1c' + beta1s``.
    With many blades (``Nb >= 8``) the projection is the azimuth average, so this
    is the constant-coefficient multiblade system the linear model approximates.
    """
    from ..physics.multiblade import blade_angles, multiblade
    z = np.asarray(z, dtype=float)
    nb = rotor.nb
    if len(z) != (15 if rotor.lag else 9):
        raise InputError(f"multiblade state of {len(z)} values: the rotor takes "
                         f"{15 if rotor.lag else 9}")

    def blades(q, dq):
        rate_mb = np.array([dq[0], dq[1] + q[2], dq[2] - q[1]])   # blade-rate harmonics
        return blade_angles(q, psi, nb), blade_angles(rate_mb, psi, nb)

    def accelerations(f, q, dq):
        p = multiblade(f, psi)
        return np.array([p[0], p[1] - 2 * dq[2] + q[1], p[2] + 2 * dq[1] + q[2]])

    b, db, lam = z[0:3], z[3:6], z[6:9]
    x = np.concatenate([*blades(b, db), lam]
                       + (list(blades(z[9:12], z[12:15])) if rotor.lag else []))
    f = rotor.rhs(psi, x, tuple(float(v) for v in u))
    out = [accelerations(f[nb:2 * nb], b, db), f[2 * nb:2 * nb + 3]]
    if rotor.lag:
        out.append(accelerations(f[3 * nb + 3:], z[9:12], z[12:15]))
    return np.concatenate(out)


__all__ = ["SPEEDS", "LAG", "LAG_RANGE", "MAX_STEP", "RotorSpec", "BladeRotor", "RotorTrim",
           "multiblade_derivatives"]
