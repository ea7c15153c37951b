"""Peters-He hidden in forward flight, and null records with ``peters-he-6`` in the pool:
the study behind ``bench/rotor-physics.md``'s Peters-He section; one JSON line per
record on stdout.

    python bench/peters_he_detection.py hidden 21-25 > hidden.jsonl
    python bench/peters_he_detection.py null 31-35 > null.jsonl
    python bench/peters_he_detection.py higher 41-45 > higher.jsonl
    python bench/peters_he_detection.py hingeless 51-55 > hingeless.jsonl
    python bench/peters_he_detection.py wider 61-65 > wider.jsonl
    python bench/peters_he_detection.py wider-null 71-75 > wider-null.jsonl
    python bench/peters_he_detection.py summary bench/results/current/ph-{hidden,higher,null-direct}.jsonl.gz

Records from ``tests/test_peters_he_records.py``'s generator, which shares no code with
the effect: the direct construction of the whole Peters-He rotor
(``tests/peters_he_direct.py``: its own shape functions, gain by quadrature, the
skewed wake's couplings at ``X = tan(chi/2)`` of its own trim inflow) integrated by
scipy's DOP853 with smooth pilot inputs, body rates through a first-order filter of
the cyclic, white or coloured (second-order Butterworth) flap noise of 1e-4 rad.

``hidden``: six Peters-He states (``power`` 2) in the rotor, the ladder from
``basic+separate-time-constants`` (the truth's three-state part) with the offered
effects and ``peters-he-6`` (``--also peters-he-6``): the first rung's named effect,
the effects the ladder adds, its verdict, each flap channel's residual over the
noise's own level in the band (``floor_ratio``) and each estimate's distance from the
truth in its Cramer-Rao sigma (``z``: ``k_ph`` 1, the rotor's flap frequency and
inertia number, the Pitt-Peters time constants of the speed through the disc).

``higher``: ten and fifteen Peters-He states in the rotor (``power`` 3, 4; two-axis,
white noise, 200 Hz), the ladder's pool with all three orders: which order the
ladder names, and whether its residual reaches the floor.

``hingeless``: ``hidden``'s two-axis white, two-axis coloured and single-axis coloured
cases on ``bench/detection.py``'s hingeless rotor (flap frequency squared 1.25, Lock
number 5.2, ``mu`` 0.236, its hub in the record's header).

``wider``: the cases of :data:`WIDER`: log sweeps (0.15-3 Hz) on both cyclics in
turn or on ``theta1s`` alone, inputs held over each sample (``# hold: zoh``; the
truth's flow over one sample by DOP853, ``tests/test_peters_he_records._held``),
64 and 256 Hz, white or coloured noise (3 Hz, 2 deg cyclics), the Puma and the
hingeless rotor; ``hidden``'s measures.  ``wider-null``: :data:`WIDER_NULL`, the same
kinds on the three-state rotor, diagnosed as ``null``.  ``INFLOWSIM_PH_CASES``
(case names separated by ``;``) runs those cases only.

``null``: the three-state rotor (``power`` 1: the Gram gain, the present model's,
no skew couplings) by the same route, diagnosed from the same base with the same
pool: any named effect is a false alarm.  (``bench/detection.py --kind null --offer
peters-he-6`` gives the library-model route's null records, basic and glauert
truths.)
"""
import json
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import test_peters_he_records as T  # noqa: E402
from test_lead_lag_records import floor_ratio  # noqa: E402
from inflowsim.diagnose import diagnose, ladder  # noqa: E402
from inflowsim.model.effects import CATALOGUE  # noqa: E402

#: (name, rate [Hz], colour [Hz] or None, mu or None (the Puma's), single axis,
#: cyclic amplitude [deg]): the doublets of the first study
HIDDEN = (("two-axis white", 200, None, None, False, 1.0),
          ("two-axis coloured", 128, 3.0, None, False, 2.0),
          ("two-axis coloured 1 deg", 128, 3.0, None, False, 1.0),
          ("single-axis white", 200, None, None, True, 1.0),
          ("single-axis coloured", 128, 3.0, None, True, 2.0),
          ("two-axis white mu 0.33", 128, None, 0.33, False, 1.0),
          ("two-axis white mu 0.15", 128, None, 0.15, False, 1.0))
NULL = (("two-axis white", 200, None, None, False, 1.0),
        ("two-axis coloured", 128, 3.0, None, False, 1.0),
        ("single-axis white", 200, None, None, True, 1.0),
        ("single-axis coloured", 128, 3.0, None, True, 2.0))
#: the second study's cases, each ``HIDDEN``'s six fields then (sweep, hold, rotor):
#: log sweeps (two-axis, single-axis), held inputs (``zoh``), 64 and 256 Hz,
#: coloured noise, the hingeless rotor
WIDER = (("sweep two-axis white 256 Hz", 256, None, None, False, 1.0, True, "continuous", "puma"),
         ("sweep two-axis coloured 64 Hz", 64, 3.0, None, False, 2.0, True, "continuous", "puma"),
         ("sweep single-axis white 256 Hz", 256, None, None, True, 1.0, True, "continuous",
          "puma"),
         ("sweep single-axis coloured 64 Hz", 64, 3.0, None, True, 2.0, True, "continuous",
          "puma"),
         ("held two-axis white 64 Hz", 64, None, None, False, 1.0, False, "zoh", "puma"),
         ("held two-axis coloured 256 Hz", 256, 3.0, None, False, 2.0, False, "zoh", "puma"),
         ("held single-axis white 256 Hz", 256, None, None, True, 1.0, False, "zoh", "puma"),
         ("held sweep two-axis coloured 64 Hz", 64, 3.0, None, False, 2.0, True, "zoh", "puma"),
         ("hingeless, sweep two-axis white 256 Hz", 256, None, None, False, 1.0, True,
          "continuous", "hingeless"),
         ("hingeless, sweep single-axis coloured 64 Hz", 64, 3.0, None, True, 2.0, True,
          "continuous", "hingeless"),
         ("hingeless, held two-axis coloured 64 Hz", 64, 3.0, None, False, 2.0, False, "zoh",
          "hingeless"),
         ("hingeless, held sweep single-axis white 256 Hz", 256, None, None, True, 1.0, True,
          "zoh", "hingeless"),
         ("two-axis white 64 Hz", 64, None, None, False, 1.0, False, "continuous", "puma"),
         ("two-axis coloured 256 Hz", 256, 3.0, None, False, 2.0, False, "continuous", "puma"))
#: the null records of the second study: the same kinds on the three-state rotor
WIDER_NULL = tuple(c for c in WIDER if not c[0].startswith(("two-axis white 64",
                                                            "hingeless, sweep single")))


def hingeless():
    """``(constants, lambda_beta2, n_beta)`` of ``bench/detection.py``'s hingeless
    rotor (a Bo 105-size rotor at 100 kt)."""
    from dataclasses import replace
    from inflowsim.model.params import PUMA
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from detection import ROTORS
    c, p = ROTORS["hingeless"]
    return replace(PUMA, **c), p["lambda_beta2"], p["n_beta"]


def truth(rec, lb2=T.LB2, nb=T.NB):
    """The rotor's parameters in the structure's terms."""
    sep = CATALOGUE["separate-time-constants"].theory(rec.constants)
    return {"lambda_beta2": lb2, "n_beta": nb, "k_ph": 1.0} | sep


def _unpack(case):
    """``(name, rate, colour, mu, single, amp, sweep, hold, rotor)`` of a case of
    ``HIDDEN``/``NULL`` (doublets, continuous, the Puma) or ``WIDER``."""
    return tuple(case) + (False, "continuous", "puma")[len(case) - 6:]


def _rotor(name):
    return hingeless() if name == "hingeless" else (None, T.LB2, T.NB)


def hidden(case, seed, tmp, power=2, pool=T.POOL, rotor=None):
    name, rate, colour, mu, single, amp, sweep, hold, rname = _unpack(case)
    k, lb2, nb = rotor or _rotor(rname)
    rec = T.make_record(tmp / f"h_{seed}.csv", power, rate, colour, seed, mu, single, amp,
                        constants=k, lb2=lb2, nb=nb, sweep=sweep, hold=hold)
    lad = ladder(rec, T.BASE, pool=pool)
    first = lad.rungs[0].diagnosis
    fit = lad.final.fit
    p = truth(rec, lb2, nb)
    if rotor is not None:
        name = f"hingeless, {name}"
    return dict(case=name, seed=seed, first=first.missing_effect,
                named=[(c.effect, c.reason) for c in first.candidates[:3]],
                added=[r.added for r in lad.rungs[1:]], status=lad.verdict.status,
                final=lad.final.structure.name,
                floor_ratio=floor_ratio(fit, rec, rate, colour).tolist(),
                z={n: (fit.parameters[n] - v) / fit.sigma[n] for n, v in p.items()
                   if n in fit.parameters and fit.sigma.get(n)},
                k_ph=[fit.parameters.get("k_ph"), fit.sigma.get("k_ph")])


def null(case, seed, tmp):
    name, rate, colour, mu, single, amp, sweep, hold, rname = _unpack(case)
    k, lb2, nb = _rotor(rname)
    rec = T.make_record(tmp / f"n_{seed}.csv", 1, rate, colour, seed, mu, single, amp,
                        constants=k, lb2=lb2, nb=nb, sweep=sweep, hold=hold)
    d = diagnose(rec, T.BASE, pool=T.POOL)
    ph = [c for c in d.candidates if c.effect == "peters-he-6"]
    return dict(case=name, seed=seed, missing=d.missing_effect,
                accepted=[c.effect for c in d.candidates if c.accepted],
                peters_he=ph[0].reason if ph else None,
                floor_ratio=floor_ratio(d.fit, rec, rate, colour).tolist())


#: the pool with every Peters-He order (``higher``)
POOL_ALL = T.POOL + ["peters-he-10", "peters-he-15"]


def higher(case, seed, tmp):
    out = {}
    for power in (3, 4):
        out[f"power {power}"] = hidden(case, seed, tmp, power, POOL_ALL)
    return out


def on_hingeless(case, seed, tmp):
    return hidden(case, seed, tmp, rotor=hingeless())


#: the names of the cases to run, from ``INFLOWSIM_PH_CASES`` (separated by ``;``); all
#: when empty
CASES = [c for c in os.environ.get("INFLOWSIM_PH_CASES", "").split(";") if c]


def main(which, seeds):
    tmp = Path(tempfile.mkdtemp())
    run = {"hidden": hidden, "null": null, "higher": higher, "hingeless": on_hingeless,
           "wider": hidden, "wider-null": null}[which]
    for case in {"hidden": HIDDEN, "null": NULL, "higher": HIDDEN[:1],
                 "hingeless": (HIDDEN[0], HIDDEN[1], HIDDEN[4]), "wider": WIDER,
                 "wider-null": WIDER_NULL}[which]:
        if CASES and case[0] not in CASES:
            continue
        for seed in seeds:
            t0 = time.process_time()
            res = run(case, seed, tmp)
            res["cpu_s"] = time.process_time() - t0
            print(json.dumps(res), flush=True)


def _span(values, fmt):
    return f"{min(values):{fmt}} to {max(values):{fmt}}" if values else "-"


def summary(paths):
    """The tables of ``bench/rotor-physics.md`` from the JSON lines of ``paths``."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from detection import _read          # .jsonl or .jsonl.gz
    rows = [json.loads(line) for p in paths for line in _read(p).splitlines()
            if line.strip()]
    hidden_rows = [r for r in rows if "first" in r]
    for r in rows:
        hidden_rows += [dict(v, case=f"{k} states, {v['case']}") for k, v in r.items()
                        if k.startswith("power")]
    if hidden_rows:
        _hidden_table(hidden_rows)
    _null_table([r for r in rows if "missing" in r])


def _hidden_table(hidden_rows):
    print("| records | cases | named first | others named beside it | ladder | "
          "residual / floor | estimates' errors [sigma] | `k_ph` |")
    print("| --- | --- | ---: | --- | --- | --- | --- | --- |")
    by = {}
    for r in hidden_rows:
        by.setdefault(r["case"].replace("power 3", "10").replace("power 4", "15"),
                      []).append(r)
    for case, rs in by.items():
        truth = "peters-he-15" if case.startswith("15") else (
            "peters-he-10" if case.startswith("10") else "peters-he-6")
        first = sum(r["first"] == truth for r in rs)
        beside = sorted({e for r in rs for e in r["added"] if e != truth})
        status = sorted({r["status"] for r in rs})
        ratio = [max(r["floor_ratio"]) for r in rs]
        z = [v for r in rs for v in r["z"].values()]
        k = [r["k_ph"][0] for r in rs if r["k_ph"][0] is not None]
        print(f"| {len(rs)} | {case} | {first} | {', '.join(beside) or 'none'} | "
              f"{', '.join(status)} | {_span(ratio, '.2f')} | {_span(z, '+.2f')} | "
              f"{_span(k, '.3f')} |")


def _null_table(nulls):
    if not nulls:
        return
    print("\n| records | cases | named | accepted | `peters-he-6`'s p < 0.05 | < 0.01 | "
          "< 1e-3 | smallest p | base's residual / floor |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |")
    by = {}
    for r in nulls:
        by.setdefault(r["case"], []).append(r)
    for case, rs in list(by.items()) + [("all", nulls)]:
        ps = [_p(r) for r in rs if _p(r) is not None]
        ratio = [max(r["floor_ratio"]) for r in rs if "floor_ratio" in r]
        print(f"| {len(rs)} | {case} | {sum(r['missing'] is not None for r in rs)} | "
              f"{sum(bool(r['accepted']) for r in rs)} | {sum(p < 0.05 for p in ps)} | "
              f"{sum(p < 0.01 for p in ps)} | {sum(p < 1e-3 for p in ps)} | "
              f"{min(ps):.2g} | {_span(ratio, '.2f')} |")


def _p(row):
    """``peters-he-6``'s p-value in a null row's reason, or None."""
    text = row["peters_he"] or ""
    return float(text.split("p = ")[1].split()[0]) if "p = " in text else None


if __name__ == "__main__":
    if sys.argv[1] == "summary":
        summary(sys.argv[2:])
        raise SystemExit(0)
    a, _, b = sys.argv[2].partition("-")
    main(sys.argv[1], list(range(int(a), int(b) + 1)) if b
         else [int(s) for s in sys.argv[2].split(",")])
