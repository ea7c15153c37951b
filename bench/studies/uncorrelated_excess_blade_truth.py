"""What the verdict can tell of the power the lag blade truth leaves above the floor
(issue #35; ``bench/rotor-physics.md``, "The lag on the blade truth").

The Puma blade truth with lead-lag (``nu_zeta`` 0.25, ``zeta_lag`` 0.2, ``--speed mu``,
hub fixed) flies a 3-2-1-1 on ``theta1s`` (noise 1e-4 rad white, seed 6); the ladder
from the rigid blades' structure ends ``explained`` with ``beta1s`` above the floor at
1 deg.  Four records, each laddered: the truth at 1 and 0.5 deg, the rigid truth at
1 deg (exactly linear here), and the 1 deg record's noise on the lag truth's linear
part (``100 x`` its response to 0.01 deg): the same noise without the nonlinear part.
Per channel of each ladder's last rung:

* ``over``: the mean in-band residual power over the floor (the verdict's), its
  level test's p-value;
* ``corr``/``rest``: the part of it in the span of the smooth input-correlated
  residuals (:func:`inflowsim.diagnose.excess.smooth_input_basis`) and the rest
  (noise alone: ``r / nf`` and ``1 - r / nf``);
* ``input p``/``smooth p``: :func:`inflowsim.diagnose.failures.channel_structure`;
* ``coh``: CIFER's coherence (Welch, ``--window`` s, 80 % overlap) of ``theta1s`` to
  the channel, mean over the band;
* ``loc``: the residual's power outside that span where the model's in-band response
  is (its envelope ``v``, mean 1) over its mean power, ``e^H M e / e^H e`` with
  ``M = E^H diag(v) E / n`` (``E`` the bins' synthesis over one record period),
  beside its value for stationary white noise through the same projection ``A``
  (``tr(A M A) / tr A``: the fit's own depletion of the residual where the response
  is) and the p-value of ``e^H A (M - loc A) A e > 0`` for it (Gil-Pelaez on the
  eigenvalues, complex Gaussian bins).  A response that is not linear puts its
  distortion where the response is; noise is stationary.

    python bench/studies/uncorrelated_excess_blade_truth.py [--seed 6]
"""
from __future__ import annotations

import argparse
import time

import numpy as np

BASE = "basic+separate-time-constants+flap-inertia"
COLS = ("beta0", "beta1c", "beta1s")


def records(seed):
    from inflowsim.data.record import Record
    from inflowsim.flighttest.bladesim import RotorSpec
    from inflowsim.flighttest.nonlinear import FlightTest, nonlinear_flighttest
    from inflowsim.flighttest.virtual import Manoeuvre

    def rec(amp, lag=True, noise=1e-4):
        man = (Manoeuvre(channel="theta1s", shape="3211", amplitude=np.radians(amp),
                         t_start=2.0, width=0.4),) if amp else ()
        spec = RotorSpec(speed="mu", **({"nu_zeta": 0.25, "zeta_lag": 0.2} if lag else {}))
        return nonlinear_flighttest(FlightTest(rotor=spec, manoeuvres=man, seed=seed,
                                               body=None, noise_flap=noise)).record
    full = rec(1.0)
    still, small, clean = rec(0.0, noise=0.0), rec(0.01, noise=0.0), rec(1.0, noise=0.0)
    ch = dict(full.channels)
    for c in COLS:     # the same noise on the linear part
        ch[c] = still[c] + 100 * (small[c] - still[c]) + (full[c] - clean[c])
    lin = Record.from_arrays(full.t, ch, full.meta, "linear part + the 1 deg noise")
    return {"lag 1 deg": full, "lag 0.5 deg": rec(0.5), "rigid 1 deg": rec(1.0, lag=False),
            "linear part 1 deg": lin}


def _gil_pelaez(lam) -> float:
    """P(sum lam_i X_i > 0), X_i independent Exp(1)."""
    from scipy import integrate
    lam = lam[np.abs(lam) > 1e-12 * np.abs(lam).max()]
    val, _ = integrate.quad(lambda u: np.imag(np.prod(1 / (1 - 1j * lam * u))) / u,
                            0, np.inf, limit=500)
    return float(0.5 + val / np.pi)


def localisation(ra, c, Q):
    f = ra.f_hz
    T = 1 / np.diff(f).mean()
    t = np.arange(8 * f.size) * T / (8 * f.size)
    E = np.exp(2j * np.pi * np.outer(t, f))
    A = np.eye(f.size) - Q @ Q.conj().T
    e = A @ (ra.error[c] / np.sqrt(ra.floor[c]))
    y = E @ (ra.predicted / np.sqrt(ra.floor)).T
    v = np.sum(np.abs(y) ** 2 / np.mean(np.abs(y) ** 2, axis=0), axis=1)
    v = v / v.mean()
    M = (E.conj().T * v) @ E / t.size
    loc = float(np.real(e.conj() @ M @ e) / np.real(e.conj() @ e))
    AMA = A @ M @ A
    null = float(np.real(np.trace(AMA)) / np.real(np.trace(A)))
    return loc, null, _gil_pelaez(np.linalg.eigvalsh(AMA - loc * A))


def coherence(rec, c, band, window):
    from scipy import signal
    n = int(round(window / rec.dt))
    f, g = signal.coherence(rec["theta1s"] - rec["theta1s"].mean(), rec[c] - rec[c].mean(),
                            fs=1 / rec.dt, nperseg=n, noverlap=int(0.8 * n))
    return float(np.mean(g[(f >= band[0]) & (f <= band[1])]))


def main(argv=None):
    from inflowsim.diagnose import ladder
    from inflowsim.diagnose.excess import project, smooth_input_basis
    from inflowsim.diagnose.failures import channel_structure, level_p_value
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=6)
    ap.add_argument("--window", type=float, default=10.24, help="coherence window [s]")
    a = ap.parse_args(argv)
    t0 = time.process_time()
    recs = records(a.seed)
    print(f"records: {time.process_time() - t0:.1f} s CPU")
    for name, rec in recs.items():
        t1 = time.process_time()
        lad = ladder(rec, BASE)
        ra, v = lad.final.analyses[0], lad.verdict
        Q = smooth_input_basis(ra)
        nf, r = ra.f_hz.size, Q.shape[1]
        print(f"\n{name}: {' + '.join(x.added for x in lad.rungs[1:])}, {v.status} "
              f"({time.process_time() - t1:.1f} s CPU); {nf} bins, smooth input span "
              f"{r} (noise: {r / nf:.2f} in it, {1 - r / nf:.2f} outside)")
        print("  " + v.describe())
        for c, ch in enumerate(COLS):
            w = ra.error[c] / np.sqrt(ra.floor[c])
            pw = project(w[None], Q)[0]
            st = channel_structure(ra, c)
            loc, null, p = localisation(ra, c, Q)
            print(f"  {ch}: over {ra.ratio[c].mean():.2f} (p {level_p_value(ra, c):.2g}), "
                  f"corr {np.sum(np.abs(pw) ** 2) / nf:.2f}, "
                  f"rest {np.sum(np.abs(w - pw) ** 2) / nf:.2f}, "
                  f"input p {st['input_p_value']:.2g}, smooth p {st['p_value']:.2g}, "
                  f"coh {coherence(rec, ch, lad.band_hz, a.window):.3f}, "
                  f"loc {loc:.2f} (noise {null:.2f}, p {p:.2g}), in-band noise "
                  f"{lad.rungs[0].analyses[0].in_band_over_floor[c]:.2f}")


if __name__ == "__main__":
    main()
