"""What the ``lead-lag`` effect leaves on the lag blade truth, channel by channel
(issue #35; ``docs/model.md`` 9.1, ``bench/rotor-physics.md``).

The blade truth with lead-lag (``RotorSpec(nu_zeta=...)``, ``--speed mu``, hub fixed)
flies a 3-2-1-1 on ``theta1s``, noise-free.  Its response splits into

* its linear part, ``(a / 0.01 deg)`` times the response to a 0.01 deg 3211 (the rigid
  truth is exactly linear here: its remainder is 0), and
* its nonlinear part, the response to the ``a`` deg 3211 less the linear part: what no
  linear model can take (the lag's products: Coriolis ``2 beta zeta'``, ``U_T^2`` with
  ``zeta'``, the lag's azimuth in ``U_P``).

Each linear model, simulated with the same inputs (scipy ``lsim``), is compared with the
linear part: the effect's (``build_model`` at the truth's values, the trim from the
controls and the truth's mean flap) and the truth's own averaged multiblade Jacobian in
harmonics ``0..K`` of flap and lag (16 blades, central differences about the truth's
periodic trim written in the harmonics of blade 0's flap and lag), the 2/rev parts held
quasi-static or dynamic.  Each row: the error's in-band power per DFT bin (0.2256-1.58
Hz) over the white noise's, ``N sigma^2`` with ``sigma = 1e-4`` rad: what it adds to a
fit's floor ratio before the fit moves any parameter.

    python bench/studies/lead_lag_blade_truth.py [--rotor puma|hingeless] [--amplitude 1]
"""
from __future__ import annotations

import argparse
import dataclasses

import numpy as np
from scipy import signal

BAND = (0.2256, 1.58)
BASE = "basic+separate-time-constants+flap-inertia"
SIGMA = 1e-4


def rotor(name):
    import inflowsim as ifs
    from inflowsim.flighttest.bladesim import RotorSpec
    if name == "hingeless":
        k = dataclasses.replace(ifs.PUMA, mu=0.236, a0=5.7, solidity=0.07, omega=44.4,
                                radius=4.91, hub="hingeless")
        return RotorSpec(constants=k, lambda_beta2=1.25, n_beta=0.65, speed="mu",
                         nu_zeta=0.65, zeta_lag=0.2)
    return RotorSpec(speed="mu", nu_zeta=0.25, zeta_lag=0.2)


def harmonic_trim(spec, u0, K=6, n=720):
    """Blade 0's flap and lag over one revolution of the four-blade periodic trim, in
    harmonics ``0..K``; the mean inflow; the trim."""
    from inflowsim.flighttest.bladesim import BladeRotor
    rot = BladeRotor(spec)
    tr = rot.periodic_trim(u0)
    nb, h, x = rot.nb, 2 * np.pi / n, tr.x.copy()
    rows = []
    for m in range(n):
        rows.append((x[0], x[2 * nb + 3], *x[2 * nb:2 * nb + 3]))
        x = rot.step(m * h, x, tuple(u0), h)
    rows, psi = np.array(rows), np.arange(n) * h

    def four(y):
        return np.array([y.mean()] + [2 * np.mean(y * f(k * psi)) for k in range(1, K + 1)
                                      for f in (np.cos, np.sin)])
    return four(rows[:, 0]), four(rows[:, 1]), rows[:, 2:].mean(axis=0), tr


def averaged(spec16, Kf, Kl, bt, zt, lam_t, u0, n_psi=4, eps=1e-6):
    """``(A, B)`` in azimuth time: flap harmonics (``2 Kf + 1``), their rates, the
    inflow (3), lag harmonics (``2 Kl + 1``), their rates; inputs the first eight of
    ``INPUTS_AZ``.  About the trim ``bt, zt`` (harmonic coefficients), ``lam_t``."""
    from inflowsim.flighttest.bladesim import BladeRotor
    rot = BladeRotor(spec16)
    nb, nf, nl = rot.nb, 2 * Kf + 1, 2 * Kl + 1
    n = 2 * nf + 3 + 2 * nl
    Kt = (len(bt) - 1) // 2

    def basis(ang, K):
        b, db = [np.ones_like(ang)], [np.zeros_like(ang)]
        for k in range(1, K + 1):
            b += [np.cos(k * ang), np.sin(k * ang)]
            db += [-k * np.sin(k * ang), k * np.cos(k * ang)]
        return np.array(b), np.array(db)

    def proj(acc, B, c, dc, K):          # back on the harmonics, rotating frame removed
        p = (B @ acc) * np.array([1.0] + [2.0] * (2 * K)) / nb
        out = p.copy()
        for k in range(1, K + 1):
            out[2 * k - 1] = p[2 * k - 1] - 2 * k * dc[2 * k] + k * k * c[2 * k - 1]
            out[2 * k] = p[2 * k] + 2 * k * dc[2 * k - 1] + k * k * c[2 * k]
        return out

    def deriv(psi, z, u):
        ang = psi + rot.offsets
        (Bf, dBf), (Bl, dBl), (Bt, dBt) = basis(ang, Kf), basis(ang, Kl), basis(ang, Kt)
        b, db, lam = z[:nf], z[nf:2 * nf], z[2 * nf:2 * nf + 3]
        q, dq = z[2 * nf + 3:2 * nf + 3 + nl], z[2 * nf + 3 + nl:]
        x = np.concatenate([bt @ Bt + b @ Bf, bt @ dBt + db @ Bf + b @ dBf, lam_t + lam,
                            zt @ Bt + q @ Bl, zt @ dBt + dq @ Bl + q @ dBl])
        uu = np.zeros(10)
        uu[:8], uu[8] = u0[:8] + u, u0[8]
        f = rot.rhs(psi, x, uu)
        return np.concatenate([db, proj(f[nb:2 * nb], Bf, b, db, Kf), f[2 * nb:2 * nb + 3],
                               dq, proj(f[3 * nb + 3:], Bl, q, dq, Kl)])

    A, B = np.zeros((n, n)), np.zeros((n, 8))
    for psi in np.linspace(0, 2 * np.pi / nb, n_psi, endpoint=False):
        for j in range(n):
            d = np.zeros(n)
            d[j] = eps
            A[:, j] += (deriv(psi, d, np.zeros(8)) - deriv(psi, -d, np.zeros(8))) / (2 * eps)
        for j in range(8):
            d = np.zeros(8)
            d[j] = eps
            B[:, j] += (deriv(psi, np.zeros(n), d) - deriv(psi, np.zeros(n), -d)) / (2 * eps)
    return A / n_psi, B / n_psi


def quasi_static(A, B, Kf, Kl, flap=(), lag=()):
    """The harmonics ``flap``, ``lag`` (indices among each's ``2K + 1``) held at rest:
    their accelerations' rows solved for them, their rates dropped."""
    nf, nl = 2 * Kf + 1, 2 * Kl + 1
    rows = [nf + i for i in flap] + [2 * nf + 3 + nl + i for i in lag]
    cols = list(flap) + [2 * nf + 3 + i for i in lag]
    keep = [i for i in range(A.shape[0]) if i not in rows + cols]
    s = np.linalg.solve(A[np.ix_(rows, cols)], np.hstack([A[np.ix_(rows, keep)], B[rows]]))
    a = A[np.ix_(keep, keep)] - A[np.ix_(keep, cols)] @ s[:, :len(keep)]
    return a, B[keep] - A[np.ix_(keep, cols)] @ s[:, len(keep):]


def main(argv=None):
    import inflowsim as ifs
    from inflowsim.flighttest.nonlinear import FlightTest, nonlinear_flighttest, trim_inputs
    from inflowsim.flighttest.virtual import Manoeuvre
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rotor", choices=("puma", "hingeless"), default="puma")
    ap.add_argument("--amplitude", type=float, default=1.0, help="3211 amplitude [deg]")
    a = ap.parse_args(argv)
    spec = rotor(a.rotor)
    k = spec.constants

    def record(amp):
        man = (Manoeuvre(channel="theta1s", shape="3211", amplitude=np.radians(amp),
                         t_start=2.0, width=0.4),) if amp else ()
        return nonlinear_flighttest(FlightTest(rotor=spec, manoeuvres=man, seed=0, body=None,
                                               noise_flap=0.0)).record
    still, small, full = record(0.0), record(0.01), record(a.amplitude)
    cols = ("beta0", "beta1c", "beta1s")
    t = still.t
    u = np.column_stack([full[c] - still[c] for c in ("theta0", "theta1c", "theta1s")])
    lin = np.column_stack([small[c] - still[c] for c in cols]) * (a.amplitude / 0.01)
    nonlin = np.column_stack([full[c] - still[c] for c in cols]) - lin
    f = np.fft.rfftfreq(len(t), t[1] - t[0])
    band = (f >= BAND[0]) & (f <= BAND[1])

    def level(e):
        return np.mean(np.abs(np.fft.rfft(e, axis=0)[band]) ** 2, axis=0) / (len(t) * SIGMA**2)

    print(f"{a.rotor}, mu = {k.mu}, nu_zeta = {spec.nu_zeta}, zeta_lag = {spec.zeta_lag}, "
          f"3211 on theta1s {a.amplitude:g} deg, noise-free; in-band power per bin over "
          "the noise's (beta0, beta1c, beta1s)")
    print("| model | against the truth's linear part |")
    print("| --- | --- |")
    print("| the truth's nonlinear part (no linear model takes it) | "
          + ", ".join(f"{v:.2f}" for v in level(nonlin)) + " |")
    om = k.omega

    def row(label, A, B, C=None):
        if C is None:
            C = np.zeros((3, A.shape[0]))
            C[0, 0] = C[1, 1] = C[2, 2] = 1.0
        y = signal.lsim(signal.StateSpace(A * om, B[:, :3] * om, C, np.zeros((3, 3))),
                        u, t)[1]
        print(f"| {label} | " + ", ".join(f"{v:.2f}" for v in level(lin - y)) + " |",
              flush=True)

    u0 = trim_inputs(k.mu)
    bt, zt, lam_t, tr = harmonic_trim(spec, u0)
    kk = k.with_trim({"theta0": u0[0], "theta1c": u0[1], "theta1s": u0[2],
                      "beta0": tr.beta[0], "beta1c": tr.beta[1], "beta1s": tr.beta[2],
                      "muz": 0.0})
    p = {"lambda_beta2": spec.lambda_beta2, "n_beta": spec.n_beta, "tau0": spec.tau0,
         "tau_cs": spec.tau_cs, "flap_inertia": 1.0, "nu_zeta": spec.nu_zeta,
         "zeta_lag": spec.zeta_lag, "k_flap_lag": 1.0}
    for extra in ("", "+second-harmonic-flap"):
        m = ifs.build_model(BASE + "+lead-lag" + extra,
                            p | ({"k_beta2": 1.0} if extra else {}), kk)
        ei = np.linalg.inv(m.E)
        names, inputs = list(m.states), list(m.inputs_az)
        C = np.zeros((3, len(names)))
        for i, c in enumerate(cols):
            C[i, names.index(c)] = 1.0
        b = (ei @ m.B)[:, [inputs.index(c) for c in ("theta0", "theta1c", "theta1s")]]
        row(f"`{BASE}+lead-lag{extra}`, truth's values", ei @ m.A, b, C)
    spec16 = dataclasses.replace(spec, n_blades=16)
    sys33 = averaged(spec16, 3, 3, bt, zt, lam_t, u0)
    sys22 = averaged(spec16, 2, 2, bt, zt, lam_t, u0)
    row("truth's Jacobian, harmonics 0-1 (flap and lag)", *averaged(spec16, 1, 1, bt, zt,
                                                                    lam_t, u0))
    row("truth's Jacobian, 0-2, 2/rev flap and lag quasi-static",
        *quasi_static(*sys22, 2, 2, flap=(3, 4), lag=(3, 4)))
    A, B = sys22
    nf, nl = 5, 5
    f2 = [3, 4, nf + 3, nf + 4]
    l12 = [2 * nf + 3 + i for i in range(2 * nl)]
    A = A.copy()
    A[np.ix_(f2, l12)] = 0
    A[np.ix_(l12, f2)] = 0
    row("same, the 2/rev flap uncoupled from the lag",
        *quasi_static(A, B, 2, 2, flap=(3, 4), lag=(3, 4)))
    row("truth's Jacobian, 0-3, dynamic", *sys33)


if __name__ == "__main__":
    main()
