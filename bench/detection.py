"""Detection and false-alarm study of the diagnosis (issue #9): ``bench/README.md``.

Records from the independent route (:func:`inflowsim.flighttest.virtual.virtual_record`:
the truth integrated by an adaptive ODE solver with smooth inputs, then
sampled; or inputs held, ``zoh``) at two sample rates, with white or coloured
(first-order low-pass, 2 Hz) flap noise of 1e-4 rad, or the coloured noise scaled
to the white noise's power in the band (``coloured-level``: :func:`noise_of`):

* ``null``: the truth is the structure diagnosed (glauert, Table 3; basic with
  slow inflow): any accepted candidate is a false alarm;
* ``hidden``: basic plus one offered effect, diagnosed from basic: the effect must
  be the missing one;
* ``multi``: the paper's story, truth glauert, ladder from basic: the three
  effects and nothing else;
* ``nonlinear``: the individual-blade truth (:mod:`inflowsim.flighttest`), ladder
  from basic;
* ``nonlinear-mu``: the same truth with the trim ``mu`` as the speed through the
  disc of its momentum loads (``RotorSpec(speed="mu")``): no Eq. (14) coupling, so
  no Glauert term in the truth; flap inertia, the direct in-plane forcing, the
  Pitt-Peters time constants and the 2/rev flap stay.

Every candidate's statistics are written, one JSON document a line, so the
acceptance rule can be studied offline; a summary table is printed.

``--offer NAME,...`` adds effects the catalogue does not offer by default (e.g.
``momentum-speed``) to every diagnosis's pool and to the hidden effects: the study
to run before offering one.

    python bench/detection.py --kind null --seeds 8 --out /tmp/null.jsonl
    python bench/detection.py --kind hidden --seeds 8 --out /tmp/hidden.jsonl
    python bench/detection.py --summary bench/results/current/*.jsonl.gz

``bench/results/`` keeps, gzipped, only the results the tables of ``bench/README.md``
are made from.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

TWO_AXES = None
EFFECT_VALUES = {
    "separate-time-constants": {"tau0": 2.0, "tau_cs": 20.0},
    "azimuth-bias": {"azimuth_bias": 0.3},
    "time-delay": {"delay": 0.03},
    "wake-distortion": {"K_R": 1.0},
}
#: Rotors of the study (``--rotor``): the Puma of the paper, and a hingeless rotor of
#: the Bo 105's size (flap frequency squared 1.25, Lock number 5.2) at 100 kt.
ROTORS = {
    "puma": ({}, {}),
    "hingeless": ({"mu": 0.236, "a0": 5.7, "solidity": 0.07, "omega": 44.4,
                   "radius": 4.91, "hub": "hingeless"},
                  {"lambda_beta2": 1.25, "n_beta": 0.65}),
}


def rotor_of():
    """(constants, base parameters) of the study's rotor (``INFLOWSIM_STUDY_ROTOR``)."""
    import os
    from dataclasses import replace
    from inflowsim.model.params import PUMA
    c, p = ROTORS[os.environ.get("INFLOWSIM_STUDY_ROTOR", "puma")]
    return replace(PUMA, **c), p
NOISE = 1e-4
COLOUR_HZ = 2.0
#: noise kinds: ``coloured`` has the white noise's variance (so 6-10 times its power
#: in the band at 64 Hz, 25-40 times at 256 Hz); ``coloured-level`` is scaled to the
#: white noise's mean power over the band: the same signal-to-noise ratio, only the
#: colour differs (the floor measured above the band is 46 times below the noise in
#: the band at 64 Hz, 540 times at 256 Hz)
NOISE_KINDS = ("white", "coloured", "coloured-level")


def noise_of(noise, rate):
    """(flap noise standard deviation [rad], colour [Hz] or None) of a noise kind."""
    if noise == "white":
        return NOISE, None
    if noise == "coloured":
        return NOISE, COLOUR_HZ
    if noise == "coloured-level":
        from inflowsim.identify.transform import DEFAULT_BAND
        from inflowsim.flighttest.virtual import noise_psd
        f = np.linspace(*DEFAULT_BAND, 200)
        return NOISE / np.sqrt(np.mean(noise_psd(1.0, 1 / rate, f, COLOUR_HZ))), COLOUR_HZ
    raise ValueError(f"unknown noise kind {noise!r} (known: {', '.join(NOISE_KINDS)})")


CONFIGS = [(hold, rate, noise) for hold in ("continuous", "zoh") for rate in (64, 256)
           for noise in NOISE_KINDS]


def _manoeuvres():
    from inflowsim.flighttest.virtual import Manoeuvre
    return (Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0))


def truth_of(kind, effect):
    """(truth structure, parameters, base structure)."""
    import inflowsim as ifs
    from inflowsim.model.presets import paper_table, theory_parameters, truth_parameters
    from inflowsim.flighttest.virtual import VirtualTest, virtual_record
    constants, rotor = rotor_of()
    k = virtual_record(VirtualTest(duration=1.0, constants=constants)).constants
    if kind == "null":
        if effect == "basic":
            s = ifs.Structure.parse("basic")
            return s, theory_parameters(s, k) | {"tau": 5.0} | rotor, s
        s = ifs.Structure.parse("glauert")
        return s, truth_parameters(s, k) | rotor, s
    if kind == "multi":
        s = ifs.Structure.parse("glauert")
        return s, truth_parameters(s, k) | rotor, ifs.Structure.parse("basic")
    s = ifs.Structure.parse("basic").with_effect(effect)
    p = truth_parameters(s, k) | {"tau": 5.0} | rotor | EFFECT_VALUES.get(effect, {})
    if effect == "hub-velocity-coupling":
        p |= {n: v for n, v in paper_table(2)[1].items() if n[0] == "k"}
    return s, {n: v for n, v in p.items() if n in s.parameters}, ifs.Structure.parse("basic")


def record_for(kind, effect, hold, rate, noise, seed):
    from inflowsim.flighttest.virtual import VirtualTest, virtual_record
    sigma, col = noise_of(noise, rate)
    if kind.startswith("nonlinear"):
        return nonlinear_flighttest_of(kind, hold, rate, sigma, col, seed).record, None
    s, p, base = truth_of(kind, effect)
    rec = virtual_record(VirtualTest(structure=s, parameters=p, dt=1 / rate, seed=seed,
                                     constants=rotor_of()[0],
                                     noise_flap=sigma, manoeuvres=_manoeuvres(),
                                     hold=hold, noise_color_hz=col))
    return rec, (s, p, base)


def nonlinear_flighttest_of(kind, hold, rate, sigma, col, seed):
    from inflowsim.flighttest import FlightTest, nonlinear_flighttest
    from inflowsim.flighttest.bladesim import RotorSpec
    rotor = RotorSpec(speed="mu" if kind == "nonlinear-mu" else "eq14")
    return nonlinear_flighttest(FlightTest(rotor=rotor, dt=1 / rate,
                                           manoeuvres=_manoeuvres(), seed=seed, hold=hold,
                                           noise_flap=sigma, noise_color_hz=col))


def _floor_ratio(fit, rec, noise, rate):
    """Residual power per flap channel over the true noise level in the band."""
    from inflowsim.flighttest.virtual import noise_psd
    sigma, col = noise_of(noise, rate)
    d = fit.data[0]
    level = len(rec) * np.mean(noise_psd(sigma, 1 / rate, d.f_hz, col))
    return [float(abs(fit.S[0][i, i]) / level) for i in range(3)]


def _noise_ratio(kind, hold, rate, noise, seed, rec, fit):
    """The record's own noise (record minus its noise-free twin) in the fit's band,
    per flap channel, over the same expected level as :func:`_floor_ratio`: what a
    perfect model would leave (37 bins scatter by about 16 %)."""
    from inflowsim.flighttest.virtual import noise_psd
    sigma, col = noise_of(noise, rate)
    clean = nonlinear_flighttest_of(kind, hold, rate, 0.0, col, seed).record
    f = fit.data[0].f_hz
    n = np.column_stack([rec[c] - clean[c] for c in ("beta0", "beta1c", "beta1s")])
    spec = np.fft.rfft(n, axis=0)
    ff = np.fft.rfftfreq(len(n), rec.dt)
    band = (ff >= f.min() - 1e-9) & (ff <= f.max() + 1e-9)
    level = len(rec) * np.mean(noise_psd(sigma, 1 / rate, f, col))
    return [float(v) for v in np.mean(abs(spec[band]) ** 2, axis=0) / level]


def run_one(job):
    import os
    from inflowsim.diagnose import diagnose, ladder
    from inflowsim.diagnose.rule import Rule
    settings = {}
    if os.environ.get("INFLOWSIM_STUDY_WIDTH"):
        settings["width"] = int(os.environ["INFLOWSIM_STUDY_WIDTH"])
    if os.environ.get("INFLOWSIM_STUDY_MEASURE") == "excess":
        settings["coloured"] = 0.0          # every record judged as coloured
    if os.environ.get("INFLOWSIM_STUDY_MEASURE") in ("level", "deviance"):
        settings["white_measure"] = os.environ["INFLOWSIM_STUDY_MEASURE"]
    rule = Rule(**settings)
    offer = [e for e in os.environ.get("INFLOWSIM_STUDY_OFFER", "").split(",") if e]
    pool = None
    if offer:
        from inflowsim.model.effects import CATALOGUE
        pool = [n for n, e in CATALOGUE.items() if e.offered] + offer
    kind, effect, hold, rate, noise, seed = job
    t0 = time.perf_counter()
    rec, truth = record_for(kind, effect, hold, rate, noise, seed)
    base = "basic" if truth is None else truth[2]
    out = {"kind": kind, "effect": effect, "hold": hold, "rate": rate, "noise": noise,
           "seed": seed, "rotor": os.environ.get("INFLOWSIM_STUDY_ROTOR", "puma")}
    if kind in ("null", "hidden"):
        d = diagnose(rec, base, rule=rule, pool=pool)
        out["missing_effect"] = d.missing_effect
        out["missing_effects"] = list(d.missing_effects)
        out["candidates"] = [c.to_json() for c in d.candidates]
        out["decision"] = d.decision.to_json()
        out["unexplained"] = [f.message for f in d.failures if f.kind == "unexplained"]
        out["base_floor_ratio"] = _floor_ratio(d.fit, rec, noise, rate)
        out["in_band_over_floor"] = list(d.analyses[0].in_band_over_floor)
        out["base_level_over_floor"] = [float(v) for v in d.analyses[0].ratio.mean(axis=1)]
        win = d.accepted if effect in d.missing_effects else None
        if win is not None:
            out["with_floor_ratio"] = _floor_ratio(win.fit, rec, noise, rate)
            s, p, _ = truth
            out["z"] = {n: (win.fit.parameters[n] - p[n]) / win.fit.sigma[n]
                        for n in p if win.fit.sigma.get(n)}
    else:
        lad = ladder(rec, base, rule=rule, pool=pool)
        if kind.startswith("nonlinear"):
            out["noise_floor_ratio"] = _noise_ratio(kind, hold, rate, noise, seed, rec,
                                                    lad.final.fit)
        out["added"] = [r.added for r in lad.rungs[1:]]
        out["in_band_over_floor"] = list(lad.rungs[0].analyses[0].in_band_over_floor)
        out["final"] = lad.final.structure.name
        out["final_floor_ratio"] = _floor_ratio(lad.final.fit, rec, noise, rate)
        out["final_parameters"] = {n: [v, lad.final.fit.sigma.get(n)]
                                   for n, v in lad.final.fit.parameters.items()}
        out["unexplained"] = [f.message for f in lad.final.diagnosis.failures
                              if f.kind == "unexplained"]
        out["rungs"] = [{"structure": r.structure.name, "added": r.added,
                         "cost": r.fit.cost,
                         "floor_ratio": _floor_ratio(r.fit, rec, noise, rate),
                         "candidates": [c.to_json() for c in r.diagnosis.candidates],
                         "decision": r.diagnosis.decision.to_json()}
                        for r in lad.rungs]
        if truth is not None:
            s, p, _ = truth
            if lad.final.structure == s:
                out["z"] = {n: (lad.final.fit.parameters[n] - p[n]) / lad.final.fit.sigma[n]
                            for n in p if lad.final.fit.sigma.get(n)}
    out["seconds"] = time.perf_counter() - t0
    return out


def jobs(kind, seeds, configs, offer=()):
    from inflowsim.model.effects import CATALOGUE
    if kind == "null":
        effects = ["glauert", "basic"]
    elif kind == "hidden":
        effects = [n for n, e in CATALOGUE.items() if e.offered] + list(offer)
    else:
        effects = [kind]
    return [(kind, e, h, r, nz, s) for e in effects for (h, r, nz) in configs
            for s in range(seeds)]


def _read(path):
    """A results file's text (``.jsonl`` or ``.jsonl.gz``)."""
    import gzip
    p = Path(path)
    return gzip.decompress(p.read_bytes()).decode() if p.suffix == ".gz" else p.read_text()


def summary(paths):
    rows = [json.loads(line) for p in paths for line in _read(p).splitlines()
            if line.strip()]
    by = {}
    for r in rows:
        key = (r["kind"], r["effect"], r["hold"], r["rate"], r["noise"],
               r.get("rotor", "puma"))
        by.setdefault(key, []).append(r)
    print("| kind | effect | hold | rate | noise | rotor | records | result |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for key in sorted(by):
        rs = by[key]
        kind, effect = key[0], key[1]
        if kind == "null":
            fa = sum(r["missing_effect"] is not None for r in rs)
            un = sum(bool(r["unexplained"]) for r in rs)
            res = f"false alarms {fa}/{len(rs)}, unexplained-residual claims {un}/{len(rs)}"
        elif kind == "hidden":
            ok = sum(r["missing_effect"] == effect for r in rs)
            extra = sum(bool(set(r.get("missing_effects") or []) - {effect}) for r in rs)
            res = f"named first {ok}/{len(rs)}, another effect beside it {extra}/{len(rs)}"
        else:
            finals = sorted({r["final"] for r in rs})
            res = f"final {', '.join(finals)}; max floor ratio " + ", ".join(
                f"{max(r['final_floor_ratio']):.2f}" for r in rs)
        print(f"| {kind} | {effect} | {key[2]} | {key[3]} | {key[4]} | {key[5]} | {len(rs)} "
              f"| {res} |")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kind", choices=("null", "hidden", "multi", "nonlinear", "nonlinear-mu"))
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--configs", default="all",
                    help="all, or hold:rate:noise[,...] e.g. continuous:64:white")
    ap.add_argument("--effects", help="comma-separated effects (hidden, null: a subset)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out")
    ap.add_argument("--width", type=int,
                    help="atoms paired on the lattice (study only; default the rule's, 3)")
    ap.add_argument("--measure", choices=("auto", "excess", "level", "deviance"),
                    default="auto",
                    help="what the material and whiter tests measure (study only): the "
                         "library's choice, the input-correlated excess on every record, "
                         "or on white-noise records the level deviance or the per-bin "
                         "deviance from the floor")
    ap.add_argument("--offer", help="comma-separated effects not offered by default, "
                    "added to every pool and to the hidden effects")
    ap.add_argument("--rotor", choices=tuple(ROTORS), default="puma",
                    help="the truth's rotor (virtual records; the nonlinear truth is the "
                         "Puma)")
    ap.add_argument("--summary", nargs="+")
    a = ap.parse_args(argv)
    if a.summary:
        summary(a.summary)
        return 0
    configs = CONFIGS if a.configs == "all" else [
        (h, int(r), n) for h, r, n in (c.split(":") for c in a.configs.split(","))]
    offer = [e for e in (a.offer or "").split(",") if e]
    todo = [j[:-1] + (j[-1] + a.first_seed,) for j in jobs(a.kind, a.seeds, configs, offer)
            if not a.effects or j[1] in a.effects.split(",")]
    if offer:
        import os
        os.environ["INFLOWSIM_STUDY_OFFER"] = ",".join(offer)
    import os
    os.environ["INFLOWSIM_STUDY_ROTOR"] = a.rotor
    if a.width is not None:
        os.environ["INFLOWSIM_STUDY_WIDTH"] = str(a.width)
    if a.measure != "auto":
        import os
        os.environ["INFLOWSIM_STUDY_MEASURE"] = a.measure
    out = open(a.out, "a") if a.out else sys.stdout
    with ProcessPoolExecutor(a.workers) as ex:
        for res in ex.map(run_one, todo):
            out.write(json.dumps(res) + "\n")
            out.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
