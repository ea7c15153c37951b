"""Lead-lag hidden and null records (``tests/test_lead_lag_records.py``'s generator):
the ladder (hidden) or the diagnosis (null) with lead-lag asked for beside the
offered effects; one JSON line per record on stdout.

    python bench/lead_lag_detection.py lag 5,6,7,8,9 > lag.jsonl
    python bench/lead_lag_detection.py null 5,6,7,8,9 > null.jsonl
    python bench/lead_lag_detection.py bounds 0-29 > bounds.jsonl

``bounds``: the hingeless sweep (``CASES[4]``) fitted with its truth's structure,
started at the truth: each estimate's error in its Cramer-Rao bounds, ``z``, over the
seeds (are the bounds calibrated, or is there a bias?).
"""
import json
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
import test_lead_lag_records as T  # noqa: E402
from inflowsim.diagnose import diagnose, ladder  # noqa: E402


def bounds(seeds):
    import inflowsim as ifs
    from inflowsim.identify import identify
    rotor, kind, rate, colour, band, truth = T.CASES[4]
    s = ifs.Structure.parse("glauert+lead-lag")
    tmp = Path(tempfile.mkdtemp())
    for seed in seeds:
        rec, p = T._record(tmp / f"bounds_{seed}.csv", str(s), rotor, kind, rate, colour,
                           seed, params=truth)
        fit = identify(rec, s, band_hz=band, start={n: p[n] for n in s.parameters})
        print(json.dumps(dict(case=[rotor, kind, rate, colour, seed], z={
            n: (fit.parameters[n] - p[n]) / fit.sigma[n] for n in fit.free
            if fit.sigma.get(n)})), flush=True)


def main(which, seeds):
    if which == "bounds":
        return bounds(seeds)
    cases = T.CASES if which == "lag" else [T.CASES[0], T.CASES[3], T.CASES[4]]
    tmp = Path(tempfile.mkdtemp())
    for seed in seeds:
        for rotor, kind, rate, colour, band, truth in cases:
            t0 = time.time()
            path = tmp / f"{which}_{rotor}_{kind}_{rate}_{seed}.csv"
            if which == "lag":
                rec, p = T._record(path, "glauert+lead-lag", rotor, kind, rate, colour, seed,
                                   params=truth)
                lad = ladder(rec, "glauert", band_hz=band, pool=T.POOL)
                first = lad.rungs[0].diagnosis
                row = first.decision.added_row if first.decision else None
                fit = lad.final.fit
                res = dict(case=[rotor, kind, rate, colour, seed],
                           added=[r.added for r in lad.rungs[1:]], status=lad.verdict.status,
                           floor_ratio=T.floor_ratio(fit, rec, rate, colour).tolist(),
                           first_stat=row.statistic if row else None,
                           first_gain=row.schwarz_gain if row else None,
                           est={n: [fit.parameters.get(n), fit.sigma.get(n), p[n]]
                                for n in T.LAG},
                           within=("nu_zeta" in fit.parameters and not T._within(fit, p)),
                           names=[(c.effect, c.reason) for c in first.candidates[:3]],
                           secs=time.time() - t0)
            else:
                rec, _ = T._record(path, "glauert", rotor, kind, rate, colour, seed)
                d = diagnose(rec, "glauert", band_hz=band, pool=T.POOL)
                lag = [c for c in d.candidates if c.effect == "lead-lag"]
                res = dict(case=[rotor, kind, rate, colour, seed], missing=d.missing_effect,
                           lag=lag[0].reason if lag else None, secs=time.time() - t0)
            print(json.dumps(res), flush=True)


if __name__ == "__main__":
    a, _, b = sys.argv[2].partition("-")
    main(sys.argv[1], list(range(int(a), int(b) + 1)) if b
         else [int(s) for s in sys.argv[2].split(",")])
