"""Issue #35's done-when, measured for the four new effects in one study.

"On your own independent records with each new effect hidden (two-axis and
single-axis doublets, sweeps, another rotor, coloured noise; seeds >= 5 per case):
named first, the ladder ends ``explained`` with every channel within 1.5 times the
floor, estimates within 3 sigma."

Each effect's records come from its own generator, which shares no code with the
effect (the tests' generators, imported, not copied):

``servo-actuators``
    ``tests/servo_records.py``: the servos integrated as their own ODE between the
    command and the blade pitch of the servo-free ``basic`` matrices; base ``basic``.
``lead-lag``
    ``tests/test_lead_lag_records.py``: the ``glauert+lead-lag`` truth's continuous
    matrices integrated by DOP853 (the integration route is independent; the lag's
    equations are the effect's own: the nonlinear blade truth's lag is
    ``bench/rotor-physics.md``'s "Not in this study"); base ``glauert``.
``wake-distortion``
    ``tests/test_wake_distortion.py``: Keller's term written by hand on the
    ``basic`` matrices (``K_R = 1``); base ``basic``.
``peters-he-6``
    ``tests/test_peters_he_records.py``: the whole six-state Peters-He rotor built
    directly (``tests/peters_he_direct.py``); base ``basic+separate-time-constants``.

All integrate the truth with scipy's DOP853 from smooth pilot inputs (raised-cosine
switches), body rates through a first-order filter of the cyclics, 30 s at
:data:`RATE`, flap noise of 1e-4 rad (white, or a second-order Butterworth low-pass
at :data:`COLOUR_HZ` rescaled to the same standard deviation), the default band.

The cases (:data:`CASES`): ``two-axis`` (a 3-2-1-1 on ``theta1s``, a doublet on
``theta1c``), ``theta1s`` and ``theta1c`` (one cyclic alone: the generator's
single-axis input, on the lateral cyclic with its two cyclics exchanged), ``sweep``
(the generator's log sweep), ``hingeless`` (two-axis doublets on the generator's
hingeless rotor), ``coloured`` (two-axis doublets under coloured noise).

Per record: the ladder from the base with the offered pool
(``offered_effects()``, which holds all four); the first rung's decision, what the
ladder adds, its verdict, each flap channel's residual over the noise's own level
in the band (``floor_ratio``), each estimate's error in its Cramer-Rao sigma
(``z``: every parameter of the final fit with a truth value); and the effect's size
on the record (:func:`effect_size`): the likelihood-ratio statistic of the rule's
test of the effect's first part, expected (its noncentrality, Wald's form) and as
drawn, and the power of that one-degree-of-freedom test at the rule's alpha.

    python bench/rotor_physics_done.py --effects lead-lag --seeds 0-4 --workers 2
    python bench/rotor_physics_done.py --cpu-estimate
    python bench/rotor_physics_done.py --summary bench/results/current/done-*.jsonl.gz

Output: ``bench/results/current/done-<effect>.jsonl`` (gzip it to keep), one
JSON document a line, appended; records already there are not run again.
"""
from __future__ import annotations

import argparse
import contextlib
import gzip
import json
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE))

RATE = 128                 # [Hz]
COLOUR_HZ = 3.0            # [Hz], the coloured noise's corner
CASES = ("two-axis", "theta1s", "theta1c", "sweep", "hingeless", "coloured")
EFFECTS = ("lead-lag", "servo-actuators", "wake-distortion", "peters-he-6")
BASES = {"servo-actuators": "basic", "lead-lag": "glauert", "wake-distortion": "basic",
         "peters-he-6": "basic+separate-time-constants"}
SERVO = {"servo_tau": 0.02, "servo_zeta": 0.7}     # [s], [-]
K_R = 1.0
ALPHA = 1e-3               # the rule's (``Rule().alpha``)
RESULTS = HERE / "results" / "current"


@contextlib.contextmanager
def _patched(module, name, value):
    """``module.name`` replaced by ``value`` inside the block (a generator's input
    or noise level; restored after)."""
    old = getattr(module, name)
    setattr(module, name, value)
    try:
        yield
    finally:
        setattr(module, name, old)


def _lateral(module):
    """The generator's own pilot with its two cyclics exchanged: its single-axis
    input on ``theta1c`` (the body's roll rate then follows through the filter)."""
    orig = module._pilot

    def pilot(*args, **kw):
        out = orig(*args, **kw)
        return (out[1], out[0]) + tuple(out[2:])
    return _patched(module, "_pilot", pilot)


@contextlib.contextmanager
def _drawn(module, noise=None, lateral=False):
    """The generator ``module`` inside the block with its noise level ``noise`` (None:
    its own) and, where ``lateral``, its single-axis input on ``theta1c``."""
    with contextlib.ExitStack() as st:
        if noise is not None:
            st.enter_context(_patched(module, "NOISE", noise))
        if lateral:
            st.enter_context(_lateral(module))
        yield


def _single(kind):
    """The generators' manoeuvre for a case's: both single-axis cases are theirs."""
    return {"theta1s": "single-axis", "theta1c": "single-axis"}.get(kind, kind)


def _case(case):
    """``(rotor, manoeuvre, colour)`` of a case: manoeuvre ``two-axis``,
    ``theta1s``, ``theta1c`` or ``sweep``."""
    if case == "hingeless":
        return "hingeless", "two-axis", None
    if case == "coloured":
        return "puma", "two-axis", COLOUR_HZ
    return "puma", case, None


def _hingeless_constants():
    from dataclasses import replace
    from inflowsim.model.params import PUMA
    from inflowsim.flighttest.virtual import VirtualTest, virtual_record
    from detection import ROTORS
    return virtual_record(VirtualTest(duration=1.0, constants=replace(
        PUMA, **ROTORS["hingeless"][0]))).constants


def make_record(effect, case, seed, path, noise=None):
    """``(record, truth parameters)`` of ``effect`` hidden, ``case``, ``seed``;
    ``noise`` [rad] overrides the generator's (a tiny one: the noise-free twin)."""
    rotor, kind, colour = _case(case)
    if effect == "servo-actuators":
        import servo_records as G
        k = _hingeless_constants() if rotor == "hingeless" else None
        with _drawn(G, noise):
            return G.record(path, "basic", SERVO["servo_tau"], SERVO["servo_zeta"],
                            kind=kind, rate=RATE, colour_hz=colour, seed=seed,
                            constants=k)
    if effect == "lead-lag":
        import test_lead_lag_records as G
        with _drawn(G, noise, kind == "theta1c"):
            return G._record(path, "glauert+lead-lag", rotor, _single(kind), RATE,
                             colour, seed)
    if effect == "wake-distortion":
        import test_wake_distortion as G
        import inflowsim as ifs
        from inflowsim.model.presets import theory_parameters
        k, base = G.ROTORS[rotor]
        p = theory_parameters(ifs.Structure.parse("basic"), k) | base | {"tau": 5.0}
        with _drawn(G, noise, kind == "theta1c"):
            rec = G.write_record(path, rotor, _single(kind), RATE, colour, seed, K_R)
        return rec, p | {"K_R": K_R}
    if effect == "peters-he-6":
        import test_peters_he_records as G
        import peters_he_detection as P
        k, lb2, nb = P.hingeless() if rotor == "hingeless" else (None, G.LB2, G.NB)
        with _drawn(G, noise, kind == "theta1c"):
            rec = G.make_record(path, 2, RATE, colour, seed, None,
                                kind in ("theta1s", "theta1c"), 1.0, constants=k,
                                lb2=lb2, nb=nb, sweep=kind == "sweep")
        return rec, P.truth(rec, lb2, nb)
    raise ValueError(f"unknown effect {effect!r} (known: {', '.join(EFFECTS)})")


def floor_ratio(fit, rec, colour):
    """Each flap channel's residual over the drawn noise's own level in the band
    (``tests/test_lead_lag_records.floor_ratio``: every generator draws its noise
    as ``csv_records.flap_noise`` does)."""
    from test_lead_lag_records import floor_ratio as fr
    return [float(v) for v in fr(fit, rec, RATE, colour)]


def effect_size(effect, rec, base, truth):
    """The hidden effect's size on the record, as the rule's test sees it.

    The rule tests an effect's first part (``Effect.parts[0]``: ``servo_tau``,
    ``k_flap_lag``, ``K_R``, ``k_ph``) with its other parameters held (the lag's
    frequency and damper at theory, the truth's values here), one degree of
    freedom.  ``lambda``: that test's noncentrality, ``((truth - neutral) /
    sigma)^2``, ``sigma`` the Cramer-Rao bound of the first part in the truth
    structure fitted to the record with the rest held at the truth (the Wald form
    of the expected statistic less its degree of freedom).  ``power``: the chance
    that a chi-square statistic of one degree of freedom and that noncentrality
    passes the critical value at the rule's alpha (10.83); a few per cent: no test
    at that alpha finds the effect on such records.  ``drawn``: the statistic on the
    record, ``2 (cost_base - cost_truth)``, both fitted to it from the truth."""
    import inflowsim as ifs
    from scipy.stats import chi2, ncx2
    from inflowsim.identify import identify
    from inflowsim.model.effects import CATALOGUE
    base = ifs.Structure.parse(base) if isinstance(base, str) else base
    full = base.with_effect(effect)
    e = CATALOGUE[effect]
    (name,) = e.parts[0] if e.parts else e.parameters
    neutral = e.neutral_values(rec.constants)[name]
    start = {n: v for n, v in truth.items() if n in full.parameters}
    fixed = {n: start[n] for n in e.parameters if n != name}
    fb = identify(rec, base, start={n: v for n, v in start.items() if n in base.parameters})
    ft = identify(rec, full, start=start, fixed=fixed or None)
    sig = ft.sigma.get(name)
    lam = ((truth[name] - neutral) / sig) ** 2 if sig else float("nan")
    crit = float(chi2.isf(ALPHA, 1))
    return {"parameter": name, "truth": truth[name], "neutral": neutral, "sigma": sig,
            "estimate": ft.parameters[name], "lambda": lam, "critical": crit,
            "power": float(ncx2.sf(crit, 1, lam)) if sig else float("nan"),
            "drawn": max(0.0, 2.0 * float(fb.cost - ft.cost))}


def servo_or_delay(case, seed):
    """Can the record tell the servos from a pure delay?  ``drawn``: ``2 (cost_delay
    - cost_servo)``, ``basic+time-delay`` and the truth (``basic+servo-actuators``,
    ``servo_zeta`` held at its truth, one parameter each) fitted to the record;
    ``bound``: an upper bound on its expectation, ``2 n_f ln(|S_n + R| / |S_n|)``
    with ``R`` the residual covariance of ``basic+time-delay`` fitted to the
    noise-free twin (1e-9 rad) and ``S_n`` the truth's on the record (the delay's
    best fit in the record's own weighting misfits no more than that one)."""
    import inflowsim as ifs
    from inflowsim.identify import identify
    tmp = Path(tempfile.mkdtemp(prefix="done35_"))
    rec, truth = make_record("servo-actuators", case, seed, tmp / "rec.csv")
    clean, _ = make_record("servo-actuators", case, seed, tmp / "clean.csv", noise=1e-9)
    sd = ifs.Structure.parse("basic+time-delay")
    ss = ifs.Structure.parse("basic+servo-actuators")
    sb = {n: v for n, v in truth.items() if n in ("lambda_beta2", "n_beta", "tau")}
    d0 = sb | {"delay": 2 * SERVO["servo_zeta"] * SERVO["servo_tau"]}
    fd = identify(rec, sd, start=d0)
    fs = identify(rec, ss, start=truth, fixed={"servo_zeta": truth["servo_zeta"]})
    fc = identify(clean, sd, start=d0)
    sn, r = np.asarray(fs.S[0]), np.asarray(fc.S[0])
    nf = int(fs.n_freq)
    return {"effect": "servo-actuators", "case": case, "seed": seed, "servo_or_delay": {
        "drawn": 2.0 * float(fd.cost - fs.cost),
        "bound": 2 * nf * float(np.linalg.slogdet(sn + r)[1] - np.linalg.slogdet(sn)[1]),
        "delay": [fd.parameters["delay"], fd.sigma.get("delay")],
        "servo_tau": [fs.parameters["servo_tau"], fs.sigma.get("servo_tau")]}}


def detection_lag_sizes(rotor="hingeless", seeds=(0,)):
    """The lag's size on ``bench/detection.py``'s hidden-lag records (``--kind
    hidden --effects lead-lag``, the 12 configurations, the rotor's truth ``basic +
    lead-lag`` at theory, base ``basic``): :func:`effect_size`'s measures.  One
    JSON line per configuration on stdout."""
    import os
    import detection as D
    os.environ["INFLOWSIM_STUDY_ROTOR"] = rotor
    for seed, (hold, rate, noise) in ((s, c) for s in seeds for c in D.CONFIGS):
        t0 = time.process_time()
        rec, (s, p, base) = D.record_for("hidden", "lead-lag", hold, rate, noise, seed)
        out = dict(rotor=rotor, hold=hold, rate=rate, noise=noise, seed=seed,
                   **effect_size("lead-lag", rec, base, p))
        out["cpu_s"] = time.process_time() - t0
        print(json.dumps(out), flush=True)


def run_one(job):
    """One record's ladder and measures (a JSON-ready dict)."""
    effect, case, seed, size = job
    from inflowsim.diagnose import ladder
    from inflowsim.diagnose.rule import offered_effects
    t0 = time.process_time()
    tmp = Path(tempfile.mkdtemp(prefix="done35_"))
    rec, truth = make_record(effect, case, seed, tmp / "rec.csv")
    t_gen = time.process_time() - t0
    rotor, kind, colour = _case(case)
    lad = ladder(rec, BASES[effect], pool=offered_effects())
    first = lad.rungs[0].diagnosis
    fit = lad.final.fit
    z = {n: (fit.parameters[n] - v) / fit.sigma[n] for n, v in truth.items()
         if n in fit.parameters and fit.sigma.get(n)}
    out = dict(effect=effect, case=case, seed=seed, rotor=rotor, manoeuvre=kind,
               colour_hz=colour, rate=RATE, base=BASES[effect],
               first=first.missing_effect,
               own_candidate=[{k: c.to_json()[k] for k in (
                   "atom", "accepted", "statistic", "log10_p_value", "schwarz_gain",
                   "plausible", "reason")} for c in first.candidates if c.effect == effect],
               first_candidates=[{k: c.to_json()[k] for k in (
                   "effect", "atom", "accepted", "statistic", "dof", "log10_p_value",
                   "schwarz_gain", "plausible", "reason")} for c in first.candidates[:4]],
               added=[r.added for r in lad.rungs[1:]], status=lad.verdict.status,
               final=lad.final.structure.name,
               base_floor_ratio=floor_ratio(lad.rungs[0].fit, rec, colour),
               floor_ratio=floor_ratio(fit, rec, colour), z=z,
               estimates={n: [fit.parameters[n], fit.sigma.get(n), truth.get(n)]
                          for n in fit.parameters},
               held=sorted(fit.fixed or ()))
    out["cpu_ladder_s"] = time.process_time() - t0 - t_gen
    if size:
        t1 = time.process_time()
        out["size"] = effect_size(effect, rec, BASES[effect], truth)
        out["cpu_size_s"] = time.process_time() - t1
    out["cpu_s"] = time.process_time() - t0
    return out


def _seeds(text):
    a, _, b = text.partition("-")
    return list(range(int(a), int(b) + 1)) if b else [int(s) for s in text.split(",")]


def _read(path):
    p = Path(path)
    data = p.read_bytes()
    text = gzip.decompress(data).decode() if p.suffix == ".gz" else data.decode()
    return [json.loads(line) for line in text.splitlines() if line.strip()]


def done(r):
    """Whether one record meets the done-when, and what failed (data)."""
    fails = []
    if not r["added"] or r["added"][0] != r["effect"]:
        fails.append("named first")
    if r["status"] != "explained":
        fails.append("explained")
    if max(r["floor_ratio"]) >= 1.5:
        fails.append("floor")
    if any(abs(v) > 3 for v in r["z"].values()):
        fails.append("3 sigma")
    return fails


def summary(paths):
    """Per effect x case: the done-when's parts, and the spread of the errors."""
    rows = [r for p in paths for r in _read(p)]
    _detection_table([r for r in rows if "hold" in r])
    sod = [r for r in rows if "servo_or_delay" in r]
    if sod:
        print("| case | seed | servo against delay, drawn | its bound | delay [ms] |")
        print("| --- | ---: | ---: | ---: | ---: |")
        for r in sod:
            x = r["servo_or_delay"]
            print(f"| {r['case']} | {r['seed']} | {x['drawn']:+.1f} | {x['bound']:.1f} | "
                  f"{1e3 * x['delay'][0]:.1f} +- {1e3 * x['delay'][1]:.1f} |")
        print()
    rows = [r for r in rows if "hold" not in r and "servo_or_delay" not in r]
    if not rows:
        return
    print("| effect | case | records | named first | ended explained | worst channel / "
          "floor (max) | estimates' abs(z) max | within 3 sigma | errors' mean, spread "
          "[sigma] | done-when met | its test's statistic (min) | power at alpha 1e-3 "
          "(min) |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- | ---: | ---: | ---: |")
    by = {}
    for r in rows:
        by.setdefault((r["effect"], r["case"]), []).append(r)
    order = {e: i for i, e in enumerate(EFFECTS)}
    corder = {c: i for i, c in enumerate(CASES)}
    for (e, c) in sorted(by, key=lambda k: (order.get(k[0], 9), corder.get(k[1], 9))):
        rs = by[(e, c)]
        n = len(rs)
        named = sum(bool(r["added"]) and r["added"][0] == e for r in rs)
        expl = sum(r["status"] == "explained" for r in rs)
        worst = max(max(r["floor_ratio"]) for r in rs)
        zs = [v for r in rs for v in r["z"].values()]
        zmax = max(abs(v) for v in zs) if zs else float("nan")
        within = sum(abs(v) <= 3 for v in zs)
        met = sum(not done(r) for r in rs)
        pw = [r["size"]["power"] for r in rs if "size" in r]
        st = [c["statistic"] for r in rs for c in r.get("own_candidate", [])[:1]]
        print(f"| `{e}` | {c} | {n} | {named}/{n} | {expl}/{n} | {worst:.2f} | {zmax:.2f} "
              f"| {within}/{len(zs)} | {np.mean(zs):+.2f}, {np.std(zs):.2f} | {met}/{n} | "
              f"{min(st) if st else float('nan'):.1f} | "
              f"{min(pw) if pw else float('nan'):.3g} |")
    print()
    print("Per parameter (errors over every case and seed of an effect, [sigma]):")
    print("| effect | parameter | estimates | mean | spread | max abs | beyond 3 sigma |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: |")
    for e in EFFECTS:
        rs = [r for r in rows if r["effect"] == e]
        for name in dict.fromkeys(n for r in rs for n in r["z"]):
            v = np.array([r["z"][name] for r in rs if name in r["z"]])
            print(f"| `{e}` | `{name}` | {len(v)} | {v.mean():+.2f} | "
                  f"{v.std(ddof=1) if len(v) > 1 else 0:.2f} | {abs(v).max():.2f} | "
                  f"{int(np.sum(abs(v) > 3))} |")
    print()
    print("Records that miss the done-when:")
    for r in rows:
        f = done(r)
        if f:
            big = {}
            for name, v in r["z"].items():
                if abs(v) > 3:       # the case's errors over its seeds: a draw or a bias?
                    w = np.array([q["z"][name] for q in by[(r["effect"], r["case"])]
                                  if name in q["z"]])
                    big[name] = (f"{v:+.2f} (the case's {len(w)} seeds: mean "
                                 f"{w.mean():+.2f}, spread {w.std(ddof=1) if len(w) > 1 else 0:.2f})")
            size = r.get("size", {})
            print(f"- {r['effect']}, {r['case']}, seed {r['seed']}: {', '.join(f)}; added "
                  f"{r['added']}, {r['status']}, worst channel {max(r['floor_ratio']):.2f} "
                  f"(base {max(r['base_floor_ratio']):.2f}); beyond 3 sigma "
                  f"{', '.join(f'{n} {t}' for n, t in big.items()) or '-'}; "
                  f"first rung: {r['first']}; lambda {size.get('lambda', float('nan')):.1f}, "
                  f"power {size.get('power', float('nan')):.3g}, drawn statistic "
                  f"{size.get('drawn', float('nan')):.1f}")


def _detection_table(rows):
    """:func:`detection_lag_sizes`' rows: per configuration, the test's noncentrality
    and power, and the statistics drawn (how many pass the critical value)."""
    if not rows:
        return
    print("| rotor | hold | rate | noise | records | noncentrality | power at alpha 1e-3 | "
          "statistics drawn | pass 10.83 | `k_flap_lag`'s errors [sigma] |")
    print("| --- | --- | ---: | --- | ---: | --- | ---: | --- | ---: | --- |")
    by = {}
    for r in rows:
        by.setdefault((r["rotor"], r["hold"], r["rate"], r["noise"]), []).append(r)
    for key, rs in by.items():
        lam = sorted(r["lambda"] for r in rs)
        drawn = [r["drawn"] for r in rs]
        z = [(r["estimate"] - r["truth"]) / r["sigma"] for r in rs]
        print(f"| {' | '.join(map(str, key))} | {len(rs)} | {lam[0]:.1f} to "
              f"{lam[len(lam) // 2]:.1f} (median) | {np.median([r['power'] for r in rs]):.2f} "
              f"| {', '.join(f'{d:.1f}' for d in drawn)} | {sum(d > r['critical'] for d, r in zip(drawn, rs))}/{len(rs)} "
              f"| {min(z):+.2f} to {max(z):+.2f} |")
    print()


def cpu_estimate(seed=0):
    """One record per effect (two-axis, Puma), in this process: its CPU [s]."""
    for e in EFFECTS:
        r = run_one((e, "two-axis", seed, True))
        print(f"{e}: ladder {r['cpu_ladder_s']:.1f} s, size {r['cpu_size_s']:.1f} s, "
              f"all {r['cpu_s']:.1f} s CPU; added {r['added']}, {r['status']}", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--effects", default=",".join(EFFECTS))
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--seeds", default="0-4", help="e.g. 0-4 or 0,2,5")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--no-size", action="store_true",
                    help="skip the effect's size (two fits)")
    ap.add_argument("--out-dir", default=str(RESULTS))
    ap.add_argument("--summary", nargs="+")
    ap.add_argument("--cpu-estimate", action="store_true")
    ap.add_argument("--servo-or-delay", metavar="CASE",
                    help="servo against a pure delay on CASE's servo records, --seeds: "
                         "JSON lines on stdout (servo_or_delay)")
    ap.add_argument("--detection-lag", metavar="ROTOR",
                    help="the lag's size on bench/detection.py's hidden-lag records "
                         "of ROTOR (puma, hingeless), --seeds: JSON lines on stdout")
    a = ap.parse_args(argv)
    if a.summary:
        summary(a.summary)
        return 0
    if a.cpu_estimate:
        cpu_estimate()
        return 0
    if a.servo_or_delay:
        for seed in _seeds(a.seeds):
            print(json.dumps(servo_or_delay(a.servo_or_delay, seed)), flush=True)
        return 0
    if a.detection_lag:
        detection_lag_sizes(a.detection_lag, _seeds(a.seeds))
        return 0
    effects = a.effects.split(",")
    cases = a.cases.split(",")
    for name in effects:
        if name not in EFFECTS:
            print(f"unknown effect {name!r} (known: {', '.join(EFFECTS)})", file=sys.stderr)
            return 2
    for name in cases:
        if name not in CASES:
            print(f"unknown case {name!r} (known: {', '.join(CASES)})", file=sys.stderr)
            return 2
    have = set()
    for e in effects:
        path = Path(a.out_dir) / f"done-{e}.jsonl"
        if path.exists():
            have |= {(r["effect"], r["case"], r["seed"]) for r in _read(path)}
    # seed by seed (every effect and case gets its first seeds first), records already
    # in the output files skipped: the study can be stopped and resumed
    todo = [(e, c, s, not a.no_size) for s in _seeds(a.seeds) for e in effects
            for c in cases if (e, c, s) not in have]
    Path(a.out_dir).mkdir(parents=True, exist_ok=True)
    outs = {e: open(Path(a.out_dir) / f"done-{e}.jsonl", "a") for e in effects}
    with ProcessPoolExecutor(a.workers) as ex:
        for res in ex.map(run_one, todo):
            outs[res["effect"]].write(json.dumps(res) + "\n")
            outs[res["effect"]].flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
