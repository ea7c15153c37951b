"""Are the Cramer-Rao bounds honest?  The spread of the normalised errors over many seeds.

Issue #35's done-when study (``bench/rotor_physics_done.py``) drew 5 seeds a case; on
some cases the errors ``(estimate - truth) / sigma`` spread 1.4-2.25 over them.  Here
the same records, by the study's own generators (:func:`rotor_physics_done.make_record`),
are drawn for many seeds and fitted by ``identify`` with the truth's structure (the
effect's held parameters held at the truth, as the ladder holds them), so that it is
about the bound, not the diagnosis.

Every generator draws its record as a noise-free response plus the flap noise
``csv_records.flap_noise(seed, ...)`` (the seed draws nothing else), so a case's record
of seed ``s`` is its noise-free record (``noise=0``) plus that draw: the record is
generated once and the seeds cost a fit each (:func:`noisy`; checked against the
generator's own record of one seed, :func:`check_generator`, to the CSV's 12 digits).

Per case and parameter: the errors' mean and spread (standard deviation) in units of
each reported bound (``sigma``, ``sigma_colored``, ``sigma_robust``), with the spread's
sampling uncertainty ``s / sqrt(2 (N - 1))`` (normal errors); and, to tell the bound's
two possible faults apart, the estimates' spread over the Cramer-Rao bound at the
truth with the noise's true covariance ``S = N sigma_n^2 I`` (the estimator's
efficiency) and the reported bound's rms over that (the bound's bias).

    python bench/studies/bounds_spread.py --seeds 200 [--cases servo-hingeless,...]
    python bench/studies/bounds_spread.py --summary bench/results/bounds-spread.jsonl.gz

Output: one JSON line per case (every seed's errors) appended to ``--out``.
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent / "tests"))
sys.path.insert(0, str(HERE.parent))

import rotor_physics_done as D  # noqa: E402
from csv_records import flap_noise  # noqa: E402

NOISE = 1e-4               # [rad], every generator's
#: ``name: (effect or None for the control, done-when case, structure, held, band)``.
CASES = {
    "servo-hingeless": ("servo-actuators", "hingeless", "basic+servo-actuators",
                        ("servo_zeta",), None),
    "servo-two-axis": ("servo-actuators", "two-axis", "basic+servo-actuators",
                       ("servo_zeta",), None),
    "servo-coloured": ("servo-actuators", "coloured", "basic+servo-actuators",
                       ("servo_zeta",), None),
    "lag-two-axis": ("lead-lag", "two-axis", "glauert+lead-lag",
                     ("nu_zeta", "zeta_lag"), None),
    "lag-coloured": ("lead-lag", "coloured", "glauert+lead-lag",
                     ("nu_zeta", "zeta_lag"), None),
    "lag-hingeless": ("lead-lag", "hingeless", "glauert+lead-lag",
                      ("nu_zeta", "zeta_lag"), None),
    # controls: the paper's glauert on the Puma (the lag's generator, its truth
    # without the lag), and the servo hingeless case on a narrow band (15 bins)
    "glauert-puma": (None, "two-axis", "glauert", (), None),
    "servo-hingeless-narrow": ("servo-actuators", "hingeless", "basic+servo-actuators",
                               ("servo_zeta",), (0.2256, 0.7)),
}


def clean_record(name, folder, noise=0.0, seed=0):
    """``(record, truth, colour_hz)`` of a case drawn with flap noise ``noise`` [rad]
    (0: the noise-free record)."""
    effect, case, *_ = CASES[name]
    rotor, kind, colour = D._case(case)
    if effect is not None:
        rec, truth = D.make_record(effect, case, seed, Path(folder) / "rec.csv",
                                   noise=noise)
        return rec, truth, colour
    import test_lead_lag_records as G
    with D._drawn(G, noise):
        rec, truth = G._record(Path(folder) / "rec.csv", "glauert", rotor, D._single(kind),
                               D.RATE, colour, seed)
    return rec, truth, colour


def noisy(clean, colour, seed):
    """The case's record of ``seed``: the noise-free record plus the generator's draw."""
    from inflowsim.data.record import Record
    e = flap_noise(seed, len(clean.t), D.RATE, colour, NOISE)
    ch = dict(clean.channels)
    for i, c in enumerate(("beta0", "beta1c", "beta1s")):
        ch[c] = np.asarray(ch[c]) + e[:, i]
    return Record.from_arrays(clean.t, ch, clean.meta, f"seed {seed}")


def check_generator(name, seed=1):
    """Largest difference [rad] between the generator's record of ``seed`` and
    :func:`noisy`'s (the CSV's 12 significant digits: about 1e-13)."""
    with tempfile.TemporaryDirectory() as d:
        clean, _, colour = clean_record(name, d)
        Path(d, "rec.csv").unlink()
        own, _, _ = clean_record(name, d, noise=NOISE, seed=seed)
        mine = noisy(clean, colour, seed)
        return max(float(np.max(np.abs(np.asarray(own[c]) - np.asarray(mine[c]))))
                   for c in ("beta0", "beta1c", "beta1s"))


def true_bound(clean, structure, truth, held, band):
    """The Cramer-Rao bound at the truth with the noise's true covariance
    ``S = N NOISE^2 I`` (white noise; the transform's scaling, as ``floor_ratio``),
    per free parameter the records determine: ``{name: sigma}``."""
    from inflowsim.identify.estimator import _information, fit_state, null_directions
    prob = _problem(clean, structure, truth, held, band)
    st = fit_state(prob, prob.theta0(), [len(clean.t) * NOISE ** 2 * np.eye(3)])
    M, _ = _information(prob, st)
    dead, _ = null_directions(M)
    ok = [i for i in range(M.shape[0]) if i not in dead]
    c = np.linalg.inv(M[np.ix_(ok, ok)])
    return {prob.free_names[i]: float(np.sqrt(c[k, k])) for k, i in enumerate(ok)}


def _problem(clean, structure, truth, held, band, record=None):
    from inflowsim.identify.estimator import spectra_of
    from inflowsim.identify.problem import Problem
    from inflowsim.model.structure import Structure
    s = Structure.parse(structure)
    sp = spectra_of([record or clean], s, band, None)
    return Problem(s, sp, {n: truth[n] for n in s.parameters}, fixed=tuple(held))


def neighbour_correlation(clean, colour, structure, truth, held, band, seeds):
    """The residual's correlation between neighbouring bins, as the estimator sees it
    (weighted by the true ``S``, end effects projected out, at the truth), over
    ``seeds``: ``|mean e_k e_{k+1}^H| / mean |e_k|^2`` (channels' diagonal) and the
    same of bins two apart; independent bins give about ``1 / sqrt(count)``."""
    from inflowsim.identify.estimator import fit_state
    from inflowsim.identify.problem import unstack
    num1, num2, den, count = 0j, 0j, 0.0, 0
    for seed in seeds:
        prob = _problem(clean, structure, truth, held, band, noisy(clean, colour, seed))
        st = fit_state(prob, prob.theta0(), [len(clean.t) * NOISE ** 2 * np.eye(3)])
        e = unstack(st.r[0], prob.n_freq)
        num1 += np.sum(e[1:] * e[:-1].conj())
        num2 += np.sum(e[2:] * e[:-2].conj())
        den += float(np.sum(np.abs(e) ** 2)) / e.shape[0]
        count += (e.shape[0] - 1) * 3
    n_per = count / len(seeds) / 3 + 1
    return {"lag1": abs(num1) / den / (n_per - 1), "lag2": abs(num2) / den / (n_per - 2),
            "independent": 1 / np.sqrt(count)}


def profile(name, seeds=range(5)):
    """Is the cost quadratic over one sigma?  Per seed and parameter: the cost (12)
    with the parameter held at ``estimate -+ sigma`` and the rest refitted, its rise
    over the minimum on either side (a quadratic cost: ``dof / 2`` on both, ``dof``
    the bound's degrees-of-freedom scaling, 1.07 here)."""
    from inflowsim.identify import identify
    effect, case, structure, held, band = CASES[name]
    with tempfile.TemporaryDirectory() as d:
        clean, truth, colour = clean_record(name, d)
    fixed = {n: truth[n] for n in held}
    kw = {"band_hz": band} if band else {}
    out = []
    for seed in seeds:
        rec = noisy(clean, colour, seed)
        f = identify(rec, structure, start=truth, fixed=fixed, **kw)
        for n in f.free:
            sg = f.sigma.get(n)
            if not sg:
                continue
            rise = []
            for sign in (-1, 1):
                g = identify(rec, structure, start=f.parameters,
                             fixed=fixed | {n: f.parameters[n] + sign * sg}, **kw)
                rise.append(g.cost - f.cost)
            out.append({"seed": seed, "parameter": n, "rise": rise})
    return {"case": name, "profile": out}


def run_case(name, seeds, diagnostics=True):
    """One case over ``seeds``: every seed's estimates and bounds (a JSON-ready dict);
    ``diagnostics``: also the true bound, the bins' correlation and the parameters'
    correlation (:func:`true_bound`, :func:`neighbour_correlation`)."""
    from inflowsim.identify import identify
    effect, case, structure, held, band = CASES[name]
    t0 = time.process_time()
    with tempfile.TemporaryDirectory() as d:
        clean, truth, colour = clean_record(name, d)
    t_gen = time.process_time() - t0
    fixed = {n: truth[n] for n in held}
    kw = {"band_hz": band} if band else {}
    twin = identify(clean, structure, start=truth, fixed=fixed, **kw)
    rows = []
    t1 = time.process_time()
    for seed in seeds:
        f = identify(noisy(clean, colour, seed), structure, start=truth, fixed=fixed, **kw)
        rows.append({"seed": seed, "converged": f.converged, "estimate": {
            n: [f.parameters[n], f.sigma[n], f.sigma_colored[n], f.sigma_robust[n]]
            for n in f.free if f.sigma.get(n)}})
    white = colour is None and diagnostics
    ref = true_bound(clean, structure, truth, held, band) if white else {}
    from inflowsim.identify.accuracy import parameter_accuracy
    acc = parameter_accuracy(f) if diagnostics else ()
    neigh = (neighbour_correlation(clean, colour, structure, truth, held, band, seeds[:50])
             if white else {})
    return {"case": name, "effect": effect, "done_case": case, "structure": structure,
            "held": list(held), "band_hz": list(twin.band_hz), "n_freq": twin.n_freq,
            "colour_hz": colour, "truth": truth, "true_bound": ref,
            "twin": {n: [twin.parameters[n], truth[n]] for n in twin.free},
            "twin_S_over_noise": [float(abs(twin.S[0][i, i])) / (len(clean.t) * NOISE ** 2)
                                  for i in range(3)],
            "cr_over_insensitivity": {a.name: a.cr_percent / a.insensitivity_percent
                                      for a in acc if a.cr_percent},
            "neighbour_correlation": neigh,
            "seeds": rows, "cpu_generate_s": t_gen,
            "cpu_fit_s": (time.process_time() - t1) / max(len(seeds), 1)}


def spread(z):
    """``(mean, std, its sampling uncertainty)`` of errors ``z`` (1-d)."""
    z = np.asarray(z, dtype=float)
    s = float(np.std(z, ddof=1))
    return float(np.mean(z)), s, s / np.sqrt(2 * (len(z) - 1))


def summary(paths):
    docs = [d for p in paths for d in D._read(p)]
    print("| case | bins | seeds | parameter | errors' mean [sigma] | spread / sigma | "
          "spread / sigma_colored | spread / sigma_robust | seeds 0-4: spread / sigma | "
          "estimates' spread / true CR | rms sigma / true CR |")
    print("| --- | ---: | ---: | --- | ---: | --- | --- | --- | ---: | ---: | ---: |")
    for d in docs:
        rows = d["seeds"]
        names = list(dict.fromkeys(n for r in rows for n in r["estimate"]))
        for n in names:
            e = np.array([r["estimate"][n] for r in rows if n in r["estimate"]],
                         dtype=float)
            t = d["truth"][n]
            cells = []
            for k in (1, 2, 3):
                m, s, u = spread((e[:, 0] - t) / e[:, k])
                cells.append(f"{s:.2f} +- {u:.2f}")
            m0 = spread((e[:, 0] - t) / e[:, 1])[0]
            first = [r for r in rows[:5] if n in r["estimate"]]
            z5 = [(r["estimate"][n][0] - t) / r["estimate"][n][1] for r in first]
            ref = d["true_bound"].get(n)
            eff = (f"{np.std(e[:, 0], ddof=1) / ref:.3f}" if ref else "-")
            bias = (f"{np.sqrt(np.mean(e[:, 1] ** 2)) / ref:.3f}" if ref else "-")
            print(f"| {d['case']} | {d['n_freq']} | {len(e)} | `{n}` | {m0:+.2f} | "
                  f"{' | '.join(cells)} | {np.std(z5, ddof=1):.2f} | {eff} | {bias} |")
    print()
    print("| case | seeds | every parameter's errors pooled: spread / sigma | "
          "noise-free twin's largest error / sigma | twin's residual / noise level | "
          "CPU a fit [s] |")
    print("| --- | ---: | --- | ---: | --- | ---: |")
    for d in docs:
        rows = d["seeds"]
        z = [(v[0] - d["truth"][n]) / v[1] for r in rows for n, v in r["estimate"].items()]
        m, s, u = spread(z)
        sig = {n: np.mean([r["estimate"][n][1] for r in rows if n in r["estimate"]])
               for n in rows[0]["estimate"]}
        tw = max(abs(v[0] - v[1]) / sig[n] for n, v in d["twin"].items() if n in sig)
        print(f"| {d['case']} | {len(rows)} | {s:.3f} | {tw:.1e} | "
              f"{', '.join(f'{x:.1e}' for x in d['twin_S_over_noise'])} | "
              f"{d['cpu_fit_s']:.2f} |")
    print()
    print("| case | residual's correlation with the next bin / two bins on (independent: "
          "about) | CR % over insensitivity % per parameter (correlation) |")
    print("| --- | --- | --- |")
    for d in docs:
        nc = d.get("neighbour_correlation") or {}
        nb = (f"{nc['lag1']:.3f} / {nc['lag2']:.3f} ({nc['independent']:.3f})" if nc
              else "-")
        ci = ", ".join(f"{n} {v:.1f}" for n, v in d.get("cr_over_insensitivity", {}).items())
        print(f"| {d['case']} | {nb} | {ci} |")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--seeds", type=int, default=200)
    ap.add_argument("--out", default=str(HERE.parent / "results" / "bounds-spread.jsonl"))
    ap.add_argument("--summary", nargs="+")
    ap.add_argument("--check-generator", metavar="CASE")
    ap.add_argument("--profile", metavar="CASE",
                    help="the cost's rise at estimate -+ sigma, seeds 0-4 (JSON line)")
    a = ap.parse_args(argv)
    if a.summary:
        summary(a.summary)
        return 0
    if a.check_generator:
        print(f"{a.check_generator}: largest difference "
              f"{check_generator(a.check_generator):.2e} rad")
        return 0
    if a.profile:
        print(json.dumps(profile(a.profile)))
        return 0
    for name in a.cases.split(","):
        if name not in CASES:
            print(f"unknown case {name!r} (known: {', '.join(CASES)})", file=sys.stderr)
            return 2
    with open(a.out, "a") as out:
        for name in a.cases.split(","):
            out.write(json.dumps(run_case(name, list(range(a.seeds)))) + "\n")
            out.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
