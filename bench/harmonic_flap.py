"""Is the residual the catalogue leaves on the blade truth the blades' periodic
coefficients?  (issue #9; ``bench/README.md``)

The individual-blade truth (:mod:`inflowsim.flighttest.bladesim`) with ``V = mu``
and the hub held fixed is exactly linear in the flap, the inflow and the pitch, but
each blade's equation has periodic coefficients (``U_T = r + mu sin psi``,
``beta mu cos psi`` in ``U_P``).  This study derives, from the truth's own
right-hand side, the constant-coefficient (averaged) multiblade system with the
blade flap truncated at harmonic ``K`` (``beta_i = beta0 + sum_n beta_nc cos n psi_i
+ beta_ns sin n psi_i``, projected back with the rotating-frame terms removed,
averaged over the azimuth with many blades).  ``K = 1`` is the model every structure
of the catalogue shares (with flap inertia); ``K = 2, 3`` keep the blades' higher
harmonic flapping, through which the periodic coefficients act at order ``mu^2``.
Each is simulated with the record's inputs (scipy ``lsim``, linear between samples)
and compared with the truth's record.

    python bench/harmonic_flap.py [--mu 0.249] [--rate 256] [--blades 4]
"""
from __future__ import annotations

import argparse
import dataclasses

import numpy as np
from scipy import signal

#: the identification band of the studies [Hz] (inflowsim's default)
BAND = (0.2256, 1.58)


def averaged_system(rotor, K, n_psi=12):
    """``(A, B)`` in azimuth time of the flap harmonics ``0..K`` (``2K+1``
    coordinates, their rates) and the three inflow states, inputs ``theta0,
    theta1c, theta1s``; by finite differences of the truth's right-hand side
    (exact: it is linear in these), averaged over ``n_psi`` azimuths."""
    nb = rotor.nb
    nh = 2 * K + 1
    n = 2 * nh + 3

    def deriv(psi, z, u):
        b, db, lam = z[:nh], z[nh:2 * nh], z[2 * nh:]
        ang = psi + rotor.offsets
        basis = [np.ones(nb)]
        dbasis = [np.zeros(nb)]
        for k in range(1, K + 1):
            basis += [np.cos(k * ang), np.sin(k * ang)]
            dbasis += [-k * np.sin(k * ang), k * np.cos(k * ang)]
        basis, dbasis = np.array(basis), np.array(dbasis)       # (nh, nb)
        beta = b @ basis
        rate = db @ basis + b @ dbasis
        x = np.concatenate([beta, rate, lam])
        uu = np.zeros(10)
        uu[:3] = u
        uu[8] = rotor.spec.constants.mu
        f = rotor.rhs(psi, x, uu)
        acc = f[nb:2 * nb]
        proj = (basis @ acc) * np.array([1.0] + [2.0] * (nh - 1)) / nb
        dd = proj.copy()
        for k in range(1, K + 1):
            c, s = 2 * k - 1, 2 * k
            dd[c] = proj[c] - 2 * k * db[s] + k * k * b[c]
            dd[s] = proj[s] + 2 * k * db[c] + k * k * b[s]
        return np.concatenate([db, dd, f[2 * nb:]])

    A = np.zeros((n, n))
    B = np.zeros((n, 3))
    for psi in np.linspace(0, 2 * np.pi, n_psi, endpoint=False):
        f0 = deriv(psi, np.zeros(n), np.zeros(3))
        for j in range(n):
            e = np.zeros(n)
            e[j] = 1e-6
            A[:, j] += (deriv(psi, e, np.zeros(3)) - f0) / 1e-6
        for j in range(3):
            e = np.zeros(3)
            e[j] = 1e-6
            B[:, j] += (deriv(psi, np.zeros(n), e) - f0) / 1e-6
    return A / n_psi, B / n_psi


def main(argv=None):
    from inflowsim.flighttest import FlightTest, nonlinear_flighttest
    from inflowsim.flighttest.bladesim import BladeRotor, RotorSpec
    from inflowsim.model.params import PUMA
    from inflowsim.virtual import Manoeuvre
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mu", type=float, default=0.249)
    ap.add_argument("--rate", type=float, default=256.0)
    ap.add_argument("--blades", type=int, default=4, help="the truth's blade count")
    a = ap.parse_args(argv)
    k = dataclasses.replace(PUMA, mu=a.mu)
    amp = np.radians(0.5)
    man = (Manoeuvre(amplitude=amp), Manoeuvre(channel="theta1c", t_start=12.0,
                                                amplitude=amp))
    spec = RotorSpec(constants=k, speed="mu", n_blades=a.blades)
    test = FlightTest(rotor=spec, dt=1 / a.rate, manoeuvres=man, seed=0, hold="continuous",
                      noise_flap=0.0, body=None)
    rec = nonlinear_flighttest(test).record
    # the periodic trim's N/rev ripple is in both records: the difference is the
    # response to the doublets alone (the truth is linear in the pitch here)
    still = nonlinear_flighttest(dataclasses.replace(test, manoeuvres=())).record
    t = rec.t
    u = np.column_stack([rec[c] - still[c] for c in ("theta0", "theta1c", "theta1s")])
    z = np.column_stack([rec[c] - still[c] for c in ("beta0", "beta1c", "beta1s")])
    rotor16 = BladeRotor(dataclasses.replace(spec, n_blades=16))
    om = k.omega
    print(f"mu = {a.mu}, {a.rate:g} Hz, {a.blades} blades, doublets 0.5 deg, hub fixed, "
          "V = mu")
    print("| flap harmonics kept (K) | states | residual power / flap power "
          "(beta0, beta1c, beta1s) | same, 0.2256-1.58 Hz only |")
    print("| --- | --- | --- | --- |")
    for K in (1, 2, 3):
        A, B = averaged_system(rotor16, K)
        C = np.zeros((3, A.shape[0]))
        C[0, 0] = C[1, 1] = C[2, 2] = 1.0
        sys = signal.StateSpace(A * om, B * om, C, np.zeros((3, 3)))
        _, y, _ = signal.lsim(sys, u, t)
        r = [float(np.sum((z[:, i] - y[:, i]) ** 2) / np.sum(z[:, i] ** 2)) for i in range(3)]
        # the same over the identification band only (the transforms' bins in it)
        f = np.fft.rfftfreq(len(t), t[1] - t[0])
        band = (f >= BAND[0]) & (f <= BAND[1])
        Z, E = np.fft.rfft(z, axis=0)[band], np.fft.rfft(z - y, axis=0)[band]
        rb = [float(np.sum(abs(E[:, i]) ** 2) / np.sum(abs(Z[:, i]) ** 2)) for i in range(3)]
        print(f"| {K} | {A.shape[0]} | " + ", ".join(f"{v:.2e}" for v in r) + " | "
              + ", ".join(f"{v:.2e}" for v in rb) + " |")


if __name__ == "__main__":
    main()
