"""Why do the Eq. (14) truth's joint fits sit 2-3 bounds off at mu 0.30-0.35?
``bench/amplitude.md``, section "High mu".

At one speed and amplitude, the campaign's nine records (doublet, 3-2-1-1, sweep on
each control; ``bench/amplitude.py``'s ``clean_records``) are flown from several
truths with the same inputs, the scaled noise of ``bench/amplitude.py`` added with
the same seeds, and fitted jointly with its ``STRUCTURE``; each estimate against the
Eq. (14) truth's small-perturbation values (``truth``).  Truths (``--truths``):

* ``truth``: the individual-blade truth, as the campaign flies it;
* ``hubfixed``: the same with ``body=False`` (the hub fixed: only pitch inputs);
* ``deripple``: the truth's records less the periodic trim's ``Nb``/rev flap (the
  record flown without input subtracted, its mean added back): the response to the
  inputs alone, nonlinear and periodic as the truth's;
* ``linpart``: the truth's response's linear part, ``4 y(A/2) - y(A)`` (the ripple
  removed as in ``deripple``): the quadratic part of the amplitude response out;
* ``quad0.25``, ``quad0.5``, ``quad2``: ``linpart`` plus the quadratic part times 0.25,
  0.5, 2 (the truth at a quarter, half, twice the amplitude, at its noise): how the
  fits answer the size of the amplitude nonlinearity at a fixed noise;
* ``lti``: its twin from the truth's own azimuth-averaged linearisation
  (:func:`inflowsim.flighttest.linearise.linearise`, first-harmonic flap, no 2/rev),
  driven by the very inputs the truth was driven by (the pilot's and the body's, in
  continuous time) and integrated by DOP853 (rtol 1e-11): the truth without its
  periodic coefficients.  Its flap trim is the truth's mean periodic flap.
* ``model``: the same twin from the fitted structure's own linear model at the
  truth's values (``k_V = k_mu = k_beta2 = 1``, the trim of the record's lead-in):
  the estimator with no model error at all.
* ``lti+shf``: ``lti`` plus the structure's second-harmonic-flap terms (the model's
  matrices with ``k_beta2 = 1`` less those with ``k_beta2 = 0``): the averaged
  linearisation with the quasi-steady 2/rev flap added, the trim inflow the truth's.

    python bench/highmu.py --mu 0.35 --out /tmp/highmu.jsonl.gz
    python bench/highmu.py --summary bench/results/current/highmu.jsonl.gz
"""
from __future__ import annotations

import argparse
import gzip
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from amplitude import (NOISE, SEED_STEP, STRUCTURE, fit_row, read_rows,  # noqa: E402
                       with_noise)

TRUTHS = ("truth", "hubfixed", "deripple", "linpart", "quad0.25", "quad0.5", "quad2",
          "lti", "model", "lti+shf", "K2qs", "K2qs-mu2", "K2", "K3qs", "K3")
SHAPES = ("doublet", "3211", "sweep")
CONTROLS = ("theta0", "theta1c", "theta1s")
NAMES = ("tau0", "tau_cs", "lambda_beta2", "n_beta", "k_V", "k_mu", "k_beta2")


def flight_test(item, amplitude_deg, body=True, duration=20.0, dt=1.0 / 64):
    """The :class:`FlightTest` that ``campaign_record`` flies for ``item`` (noise 0)."""
    from inflowsim.flighttest.bladesim import RotorSpec
    from inflowsim.flighttest.campaign import SWEEP_HZ, WIDTH
    from inflowsim.flighttest.nonlinear import FlightTest
    from inflowsim.flighttest.virtual import Manoeuvre
    from inflowsim.model.params import PUMA
    if item.shape == "sweep":
        man = Manoeuvre(channel=item.control, shape="sweep",
                        amplitude=np.radians(amplitude_deg), t_start=2.0,
                        f_range=SWEEP_HZ, length=max(duration - 3.0, 2.0))
    else:
        man = Manoeuvre(channel=item.control, shape=item.shape,
                        amplitude=np.radians(amplitude_deg), t_start=2.0,
                        width=WIDTH[item.shape])
    return FlightTest(rotor=RotorSpec(constants=PUMA.with_mu(item.mu), speed="eq14"),
                      manoeuvres=(man,), duration=duration, dt=dt, noise_flap=0.0,
                      seed=item.seed, body=FlightTest().body if body else None)


def inputs_function(test):
    """``u(t) -> (len(t), 10)``: the truth's inputs (azimuth units, totals) at any
    times [s], exactly as :func:`nonlinear_flighttest` feeds the blades."""
    from inflowsim.flighttest.nonlinear import _trim_inputs, _true_controls, continuous_hub
    k = test.rotor.constants
    om = k.omega
    hub_at = continuous_hub(test, om * (k.radius or 7.5), k.mu)
    u0 = _trim_inputs(test)

    def u_at(t):
        h, c = hub_at(t), _true_controls(test, t)
        return u0 + np.column_stack([c, h["muz"], h["q"] / om, h["p"] / om,
                                     h["qdot"] / om**2, h["pdot"] / om**2,
                                     h["mux"], h["muy"]])
    return u_at, u0


def lti_flap(a, b, test, rtol=1e-11):
    """Flap perturbations ``(N, 3)`` of ``z' = A z + B (u - u0)`` (azimuth time)
    driven by the truth's inputs from rest at the trim."""
    from scipy.integrate import solve_ivp
    from inflowsim.flighttest.virtual import ode_max_step
    u_at, u0 = inputs_function(test)
    om = test.rotor.constants.omega
    n = int(round(test.duration / test.dt))
    t = np.arange(n) * test.dt
    sol = solve_ivp(lambda tt, z: om * (a @ z + b @ (u_at(tt)[0] - u0)), (0.0, t[-1]),
                    np.zeros(a.shape[0]), method="DOP853", rtol=rtol, atol=1e-14,
                    t_eval=t, max_step=ode_max_step(test))
    return sol.y[:3].T


def twin(rec, flap):
    """``rec`` with its flap channels replaced by ``flap`` (N, 3) totals."""
    from inflowsim.data.record import FLAP_COLUMNS
    return rec.with_channels(**{c: flap[:, i] for i, c in enumerate(FLAP_COLUMNS)})


def model_matrices(rec, mu, k_beta2=1.0):
    """The fitted structure's ``(A, B)`` at the truth's values and ``rec``'s trim."""
    from inflowsim.data.record import find_trim
    from inflowsim.flighttest.linearise import model_linearisation
    from inflowsim.model.build import build_model
    from inflowsim.model.params import PUMA
    from amplitude import truth
    tv = truth(mu)
    p = {n: tv[n] for n in ("lambda_beta2", "n_beta", "tau0", "tau_cs", "flap_inertia",
                            "k_V", "k_mu", "k_beta2")}
    p["k_beta2"] = k_beta2
    k = PUMA.with_mu(mu).with_trim(dict(find_trim(rec).values))
    return model_linearisation(build_model(STRUCTURE, p, k))


def harmonic_system(mu, K, n_psi=16, step=1e-6, n_blades=16):
    """The Eq. (14) truth's averaged linear system with each blade's flap kept to
    harmonic ``K``, about its periodic trim: ``(A, B)`` in azimuth time, states the
    ``2K+1`` flap harmonics, their rates, the three inflow states; inputs
    ``INPUTS_AZ`` (10).  As :func:`inflowsim.flighttest.averaging.averaged_system`
    (projection on the harmonics, rotating-frame terms removed, azimuth average,
    ``n_blades`` blades so that the average is exact), but by central differences
    about the trim (flap harmonics ``0..K`` of the truth's periodic trim, its mean
    inflow; harmonic rates zero) and with the in-plane inputs: Eq. (14) is not
    linear."""
    from inflowsim.flighttest.bladesim import BladeRotor, RotorSpec
    from inflowsim.flighttest.nonlinear import trim_inputs
    from inflowsim.model.params import PUMA
    rotor = BladeRotor(RotorSpec(constants=PUMA.with_mu(mu), speed="eq14",
                                 n_blades=n_blades))
    nb, nh = rotor.nb, 2 * K + 1
    n = 2 * nh + 3
    weights = np.array([1.0] + [2.0] * (nh - 1)) / nb

    def bases(psi):
        ang = psi + rotor.offsets
        basis, dbasis = [np.ones(nb)], [np.zeros(nb)]
        for k in range(1, K + 1):
            basis += [np.cos(k * ang), np.sin(k * ang)]
            dbasis += [-k * np.sin(k * ang), k * np.cos(k * ang)]
        return np.array(basis), np.array(dbasis)

    def deriv(psi, w):
        z, u = w[:n], w[n:]
        b, db, lam = z[:nh], z[nh:2 * nh], z[2 * nh:]
        basis, dbasis = bases(psi)
        f = rotor.rhs(psi, np.concatenate([b @ basis, db @ basis + b @ dbasis, lam]), u)
        proj = (basis @ f[nb:2 * nb]) * weights
        dd = proj.copy()
        for k in range(1, K + 1):
            c, s = 2 * k - 1, 2 * k
            dd[c] = proj[c] - 2 * k * db[s] + k * k * b[c]
            dd[s] = proj[s] + 2 * k * db[c] + k * k * b[s]
        return np.concatenate([db, dd, f[2 * nb:]])

    u0 = trim_inputs(mu)
    trim = rotor.periodic_trim(u0)
    basis0, _ = bases(0.0)
    b_trim = (basis0 @ trim.x[:nb]) * weights
    w0 = np.concatenate([b_trim, np.zeros(nh), trim.lam, u0])
    jac = np.zeros((n, n + 10))
    for psi in np.linspace(0.0, 2.0 * np.pi / nb, n_psi, endpoint=False):
        for j in range(n + 10):
            d = np.zeros(n + 10)
            d[j] = step
            jac[:, j] += (deriv(psi, w0 + d) - deriv(psi, w0 - d)) / (2 * step)
    jac /= n_psi
    return jac[:, :n], jac[:, n:]


def harmonic_twin_matrices(mu, K, quasi_steady=False, inplane2=True):
    """``(A, B)`` of :func:`harmonic_system` with the flap states reordered so
    that the first three are ``beta0, beta1c, beta1s`` (what the record measures);
    ``quasi_steady`` condenses harmonics 2..K and their rates; without ``inplane2``
    the in-plane velocity does not force the harmonics above 1."""
    from inflowsim.flighttest.averaging import condense
    a, b = harmonic_system(mu, K)
    nh = 2 * K + 1
    if not inplane2:
        b = b.copy()
        b[nh + 3:2 * nh, 8:10] = 0.0
    if quasi_steady:
        fast = list(range(3, nh)) + list(range(nh + 3, 2 * nh))
        return condense(a, b, fast)
    return a, b


def records(which, mu, amplitude_deg, progress):
    """The nine clean records of truth ``which``."""
    from inflowsim.flighttest.bladesim import RotorSpec
    from inflowsim.flighttest.campaign import campaign_items, campaign_record
    from inflowsim.flighttest.linearise import linearise
    from inflowsim.model.params import PUMA
    items = campaign_items((mu,), CONTROLS, SHAPES)
    t0 = time.process_time()
    body = which != "hubfixed"
    base = [campaign_record(it, noise=0.0, amplitude_deg=amplitude_deg, body=body)
            for it in items]
    if which in ("truth", "hubfixed"):
        progress(f"{which}: {time.process_time() - t0:.0f} s")
        return items, base
    if which in ("deripple", "linpart") or which.startswith("quad"):
        from inflowsim.data.record import FLAP_COLUMNS
        from inflowsim.flighttest.nonlinear import nonlinear_flighttest
        # no input, no body motion: the periodic trim alone, the same for every item
        still = nonlinear_flighttest(replace(flight_test(items[0], amplitude_deg),
                                             manoeuvres=())).record
        ripple = np.column_stack([still[c] - np.mean(still[c]) for c in FLAP_COLUMNS])
        out = []
        for it, rec in zip(items, base):
            y = np.column_stack([rec[c] for c in FLAP_COLUMNS]) - ripple
            if which != "deripple":
                # y = trim + L A + Q A^2: 4 y(A/2) - y(A) - 2 trim = trim + L A
                half = campaign_record(it, noise=0.0, amplitude_deg=amplitude_deg / 2)
                lin_part = (4 * (np.column_stack([half[c] for c in FLAP_COLUMNS]) - ripple)
                            - y - 2 * np.array([np.mean(still[c]) for c in FLAP_COLUMNS]))
                scale = 0.0 if which == "linpart" else float(which[4:])
                y = lin_part + scale * (y - lin_part)
            out.append(twin(rec, y))
        progress(f"{which}: {time.process_time() - t0:.0f} s")
        return items, out
    lin = linearise(RotorSpec(constants=PUMA.with_mu(mu), speed="eq14"))
    if which in ("K2qs", "K2qs-mu2", "K2", "K3qs", "K3"):
        hk = harmonic_twin_matrices(mu, int(which[1]), "qs" in which,
                                    inplane2=not which.endswith("-mu2"))
    out = []
    for it, rec in zip(items, base):
        test = flight_test(it, amplitude_deg)
        if which == "lti":
            a, b = lin.A, lin.B
        elif which in ("K2qs", "K2qs-mu2", "K2", "K3qs", "K3"):
            a, b = hk
        elif which == "model":
            a, b = model_matrices(rec, mu)
        else:                                        # lti+shf
            a1, b1 = model_matrices(rec, mu)
            a0, b0 = model_matrices(rec, mu, k_beta2=0.0)
            a, b = lin.A + a1 - a0, lin.B + b1 - b0
        out.append(twin(rec, lin.trim_beta + lti_flap(a, b, test)))
    progress(f"{which}: {time.process_time() - t0:.0f} s")
    return items, out


def run(mu, amplitude_deg, truths, seeds, out, mode="scaled", progress=None):
    """Fit every truth of ``truths``, noise-free once and with ``seeds`` noise draws
    (``mode``: ``scaled`` 1e-4 rad * A / 1 deg, or ``fixed`` 1e-4 rad), one JSON line
    per fit appended to ``out``."""
    progress = progress or (lambda m: print(m, file=sys.stderr, flush=True))
    opener = gzip.open if str(out).endswith(".gz") else open
    sig = NOISE * (amplitude_deg if mode == "scaled" else 1.0)
    with opener(out, "at", encoding="utf-8") as fh:
        for which in truths:
            items, clean = records(which, mu, amplitude_deg, progress)
            rows = [fit_row(clean, mu, amplitude_deg, "none", 0.0, None, SHAPES)]
            for k in range(seeds):
                recs = [with_noise(r, sig, (it.seed + k * SEED_STEP) % 2**32)
                        for it, r in zip(items, clean)]
                rows.append(fit_row(recs, mu, amplitude_deg, mode, sig, k, SHAPES))
            for row in rows:
                row["truth_kind"] = which
                fh.write(json.dumps(row) + "\n")
            fh.flush()
            progress(f"{which} mu {mu:g}: fitted, {time.process_time():.0f} s CPU")


def summary(rows, names=NAMES) -> str:
    """Per truth kind, speed and amplitude: mean z over the noisy seeds [their
    spread], and the noise-free fit's relative error [%]."""
    g = {}
    for r in rows:
        g.setdefault((r["truth_kind"], r["mu"], r["amplitude_deg"],
                      r["noise"] if r["mode"] == "fixed" else None), []).append(r)
    out = ["| truth | mu | A [deg] | noise | seeds | "
           + " | ".join(f"`{n}`" for n in names) + " |",
           "| --- | --- | --- | --- | --- | " + " | ".join("---" for _ in names) + " |"]
    for key in sorted(g, key=lambda k: (k[1], k[2], k[3] or 0, TRUTHS.index(k[0]))):
        noisy = [r for r in g[key] if r["mode"] != "none"]
        free = [r for r in g[key] if r["mode"] == "none"]
        cells = []
        for n in names:
            tv = noisy[0]["truth"].get(n, 0.0 if n == "k_beta2" else None)
            if (n not in noisy[0]["estimate"] or tv is None
                    or noisy[0]["sigma"][n] is None):      # k_mu with the hub fixed
                cells.append("-")
                continue
            z = np.array([(r["estimate"][n] - tv) / r["sigma"][n] for r in noisy])
            c = f"{z.mean():+.2f} [{z.std(ddof=1):.2f}]"
            if free:
                e = free[0]["estimate"][n]
                c += f"; {100 * (e / tv - 1):+.2f} %" if tv else f"; {e:+.3f}"
            cells.append(c)
        noise = "scaled" if key[3] is None else f"{key[3]:g} rad"
        out.append(f"| {key[0]} | {key[1]:.2f} | {key[2]:g} | {noise} | {len(noisy)} | "
                   + " | ".join(cells) + " |")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mu", type=float, default=0.35)
    ap.add_argument("--amplitude", type=float, default=0.25, help="input amplitude [deg]")
    ap.add_argument("--truths", nargs="+", choices=TRUTHS, default=list(TRUTHS))
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--noise", choices=("scaled", "fixed"), default="scaled",
                    help="flap noise 1e-4 rad * A/1 deg (scaled) or 1e-4 rad (fixed)")
    ap.add_argument("--out", help="results, appended, one JSON line per fit")
    ap.add_argument("--summary", nargs="+", metavar="FILE")
    a = ap.parse_args(argv)
    if a.summary:
        print(summary(read_rows(a.summary)))
        return 0
    if not a.out:
        ap.error("--out FILE is required (or --summary FILE)")
    t0 = time.process_time()
    run(a.mu, a.amplitude, a.truths, a.seeds, a.out, a.noise)
    print(f"{time.process_time() - t0:.0f} s CPU", file=sys.stderr)
    print(summary(read_rows([a.out])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
