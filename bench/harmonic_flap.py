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

from inflowsim.flighttest.averaging import averaged_system, condense

#: the identification band of the studies [Hz] (inflowsim's default)
BAND = (0.2256, 1.58)


def main(argv=None):
    from inflowsim.flighttest import FlightTest, nonlinear_flighttest
    from inflowsim.flighttest.bladesim import BladeRotor, RotorSpec
    from inflowsim.model.params import PUMA
    from inflowsim.flighttest.virtual import Manoeuvre
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
    print("| model | states | residual power / flap power (beta0, beta1c, beta1s) | same, "
          "0.2256-1.58 Hz only |")
    print("| --- | --- | --- | --- |")
    f = np.fft.rfftfreq(len(t), t[1] - t[0])
    band = (f >= BAND[0]) & (f <= BAND[1])
    Z = np.fft.rfft(z, axis=0)[band]

    def row(label, A, B):
        C = np.zeros((3, A.shape[0]))
        C[0, 0] = C[1, 1] = C[2, 2] = 1.0
        sys = signal.StateSpace(A * om, B[:, :3] * om, C, np.zeros((3, 3)))
        _, y, _ = signal.lsim(sys, u, t)
        r = [float(np.sum((z[:, i] - y[:, i]) ** 2) / np.sum(z[:, i] ** 2)) for i in range(3)]
        E = np.fft.rfft(z - y, axis=0)[band]
        rb = [float(np.sum(abs(E[:, i]) ** 2) / np.sum(abs(Z[:, i]) ** 2)) for i in range(3)]
        print(f"| {label} | {A.shape[0]} | " + ", ".join(f"{v:.2e}" for v in r) + " | "
              + ", ".join(f"{v:.2e}" for v in rb) + " |")

    systems = {K: averaged_system(rotor16, K) for K in (1, 2, 3)}
    row("K = 1 (the multiblade model (1) with flap inertia)", *systems[1])
    row("K = 2, the 2/rev flap quasi-steady (`second-harmonic-flap`)",
        *condense(*systems[2], [3, 4, 8, 9]))
    row("K = 2, the 2/rev flap without its inertia (`beta2''` dropped)",
        *condense(*systems[2], [8, 9]))
    row("K = 2", *systems[2])
    row("K = 3", *systems[3])
    # the catalogue's structure itself, theory values (states beta, lambda, beta')
    from inflowsim.model.build import build_model
    st = "basic+flap-inertia+separate-time-constants+second-harmonic-flap"
    par = dict(lambda_beta2=spec.lambda_beta2, n_beta=spec.n_beta, tau0=spec.tau0,
               tau_cs=spec.tau_cs, flap_inertia=1.0, k_beta2=1.0)
    m = build_model(st, par, k)
    perm = [0, 1, 2, 6, 7, 8, 3, 4, 5]          # to the averaged order b, b', lambda
    from inflowsim.channels import input_scale
    row(f"`{st}`, theory values", m.a[np.ix_(perm, perm)] / om,
        m.b[perm, :3] / om / input_scale(om)[:3])


if __name__ == "__main__":
    main()
