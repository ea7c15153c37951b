"""Truths outside the catalogue (issue #36, done-when): is the diagnosis honest?

Over the records of ``tests/outside_truths.py`` (five kinds of truth no catalogue
effect offers; per kind seeds 1-5 with both cyclics moved and seeds 1-5 with one,
``theta1s`` on odd seeds and ``theta1c`` on even ones; 64, 100 and 128 Hz; white
noise, or Butterworth-coloured at 3 Hz on seeds 3 and 5), ``diagnose(record,
"basic")`` with the default rule, and per record:

- the map's top entry (:mod:`inflowsim.diagnose.terms`: shared parameters freed
  per row group, the top entries confirmed by refits) and whether it lies in the
  equations and variables where the truth's term acts (``Truth.acts_at``);
- whether freeing the shared parameters per row group was significant, and the
  values;
- the verdict, the effects named, the share of the excess they remove and which
  are stand-ins; a ``time-delay`` named with a lead, or effects named that leave
  most of the excess, without the stand-in flag, are counted as failures.

Run::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python bench/outside.py   # bench/outside.md

``python bench/outside.py KIND ...`` runs only those kinds (not written);
``python bench/outside.py --from-json [MINUTES]`` writes the table again from the
stored rows; ``--ablation`` runs the map alone three ways on the same records
(``bench/results/outside_ablation.json``, a section of the table).
"""
from __future__ import annotations

import json
import platform
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

from outside_truths import KINDS, TRUTHS, outside_record  # noqa: E402

from inflowsim.diagnose import diagnose  # noqa: E402

SEEDS = (1, 2, 3, 4, 5)
RATES = {1: 64.0, 2: 100.0, 3: 64.0, 4: 128.0, 5: 64.0}
COLOUR = {3: 3.0, 5: 3.0}
#: Kinds whose term the data cannot place by a single entry: a stiffness in the
#: cyclic rows alone is, in the data, the shared lambda_beta2 moved plus a coning
#: term (the two fit alike); the freed parameters report it instead.
AMBIGUOUS = ("cyclic-stiffness",)


def cases(kinds=KINDS):
    """``[(kind, seed, axes, rate, colour_hz), ...]``: the study's records."""
    out = []
    for kind in kinds:
        for seed in SEEDS:
            one = "theta1s" if seed % 2 else "theta1c"
            for axes in ("both", one):
                out.append((kind, seed, axes, RATES[seed], COLOUR.get(seed)))
    return out


def study_row(kind, seed, axes, rate, colour, folder) -> dict:
    """Diagnose one record and summarise what the done-when asks of it."""
    rec, info = outside_record(Path(folder) / f"{kind}-{seed}-{axes}.csv", kind, seed,
                               rate=rate, axes=axes, colour_hz=colour)
    truth = info["truth"]
    t0 = time.process_time()
    d = diagnose(rec, "basic")
    cpu = time.process_time() - t0
    mt = d.missing_terms
    top = mt.terms[0]
    v = d.verdict
    fit = d.accepted.fit if d.accepted is not None else d.fit
    lead = ("time-delay" in v.effects and fit.parameters.get("delay", 0.0) < 0.0
            and not v.is_stand_in("time-delay"))
    unflagged = [e for e in v.effects if v.excess_explained is not None
                 and v.excess_explained < 0.5 and not v.is_stand_in(e)]
    freed = mt.freed
    return {"kind": kind, "seed": seed, "axes": axes, "rate": rate, "colour_hz": colour,
            "top": [top.block, top.equation, top.variable],
            "top_group": top.group,
            "top_significant": bool(top.significant(mt.alpha)),
            "top_refit_statistic": top.refit_statistic,
            "hit": bool(truth.acts_at(top.block, top.equation, top.variable)),
            "freed_p": freed[0][5] if freed else None,
            "freed": [[n, w, a, b] for n, w, a, b, _, _ in freed],
            "status": v.status, "effects": list(v.effects),
            "excess_explained": v.excess_explained,
            "stand_ins": [x.effect for x in v.stand_ins],
            "stand_in_reasons": [[r[0] for r in x.reasons] for x in v.stand_ins],
            "delay": fit.parameters.get("delay"),
            "lead_unflagged": bool(lead), "unflagged_excess": unflagged,
            "cpu_s": cpu}


def table(rows) -> list[str]:
    out = ["| truth | seed | axes | Hz | noise | map's top entry | in place | "
           "freed (p) | verdict | named (share) | stand-ins | CPU s |",
           "|" + " --- |" * 12]
    for r in rows:
        e = r["top"]
        where = f"{e[0]} {e[1]} x {e[2]}" + ("" if r["top_significant"] else " (n.s.)")
        fp = "-" if r["freed_p"] is None else f"{r['freed_p']:.1g}"
        share = "" if r["excess_explained"] is None else f" ({r['excess_explained']:.2f})"
        named = (" + ".join(r["effects"]) or "-") + (share if r["effects"] else "")
        out.append(f"| {r['kind']} | {r['seed']} | {r['axes']} | {r['rate']:g} | "
                   f"{'coloured' if r['colour_hz'] else 'white'} | {where} | "
                   f"{'yes' if r['hit'] else 'no'} | {fp} | {r['status']} | {named} | "
                   f"{', '.join(r['stand_ins']) or '-'} | {r['cpu_s']:.1f} |")
    return out


def row_hit(r) -> bool:
    """The top entry's row (``beta0`` ...) and variable where the truth acts, in any
    block: a term in the coning equation and one in the recorded coning differ
    little in the band (the coning settles within a few hundredths of a second)."""
    t = TRUTHS[r["kind"]]
    _, eq, var = r["top"]
    return any(e == eq for _, e in t.equations) and var in t.variables


def summary(rows) -> list[str]:
    placed = [r for r in rows if r["kind"] not in AMBIGUOUS]
    hits = sum(r["hit"] for r in placed)
    loose = sum(row_hit(r) for r in placed)
    out = [f"- map's top entry where the truth's term acts (block, equation and "
           f"variable): {hits} of {len(placed)} ({100 * hits / max(len(placed), 1):.0f} %) "
           f"over the kinds {', '.join(sorted({r['kind'] for r in placed}))}",
           f"- the same, its row and variable in any block (the coning equation or the "
           f"recorded coning): {loose} of {len(placed)} "
           f"({100 * loose / max(len(placed), 1):.0f} %)"]
    for kind in sorted({r["kind"] for r in rows}):
        rk = [r for r in rows if r["kind"] == kind]
        out.append(f"  - {kind}: {sum(r['hit'] for r in rk)} of {len(rk)} "
                   f"(two-axis {sum(r['hit'] for r in rk if r['axes'] == 'both')} of "
                   f"{sum(r['axes'] == 'both' for r in rk)}; row and variable in any "
                   f"block {sum(row_hit(r) for r in rk)})")
    amb = [r for r in rows if r["kind"] in AMBIGUOUS]
    if amb:
        sig = sum(r["freed_p"] is not None and r["freed_p"] < 1e-3 for r in amb)
        out.append(f"- {', '.join(AMBIGUOUS)}: freeing the shared parameters per row "
                   f"group significant on {sig} of {len(amb)} records")
    named = [r for r in rows if r["effects"]]
    out.append(f"- an effect named on {len(named)} of {len(rows)} records; stand-in "
               f"flagged on {sum(bool(r['stand_ins']) for r in named)} of them")
    out.append(f"- delay leads named without the flag: "
               f"{sum(r['lead_unflagged'] for r in rows)}; effects leaving most of the "
               f"excess named without the flag: "
               f"{sum(bool(r['unflagged_excess']) for r in rows)}")
    out.append(f"- verdicts: " + ", ".join(
        f"{s} {sum(r['status'] == s for r in rows)}"
        for s in ("no-missing-effect", "explained", "partly-explained", "unexplained")))
    cpu = sorted(r["cpu_s"] for r in rows)
    out.append(f"- CPU of one diagnosis (process time): median {cpu[len(cpu) // 2]:.1f} s, "
               f"max {cpu[-1]:.1f} s")
    return out


def run(kinds=KINDS, say=print, each=None):
    """The study's rows; ``each(rows)`` after every record (partial results)."""
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for case in cases(kinds):
            rows.append(study_row(*case, folder))
            r = rows[-1]
            say(f"{r['kind']} {r['seed']} {r['axes']}: top {r['top']} hit {r['hit']} "
                f"{r['status']} {r['effects']} stand-ins {r['stand_ins']} "
                f"{r['cpu_s']:.1f} s")
            if each is not None:
                each(rows)
    return rows


def _ablation_section() -> list[str]:
    path = HERE / "results" / "outside_ablation.json"
    if not path.exists():
        return []
    rows = json.loads(path.read_text())
    return ["## The map alone, before and after", "",
            "`python bench/outside.py --ablation` (the same records; the base fit and "
            "the map only): the top entry in place (block, equation and variable), "
            "with the score test at the base fit as before issue #36, with its top "
            "entries confirmed by refits only, with the shared parameters freed per "
            "row group only, and with both (the default).", "",
            *ablation_lines(rows), ""]


def write(rows, wall, complete=True):
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / "outside.json").write_text(json.dumps(rows, indent=1))
    state = "" if complete else (f" (partial: {len(rows)} of {len(cases())} records "
                                 "so far)")
    lines = ["# Truths outside the catalogue (issue #36)", "",
             "Written by `bench/outside.py` (its docstring says what it runs); the rows "
             "are in `bench/results/outside.json`.", "",
             f"Measured on {platform.machine()}, Python {platform.python_version()}, "
             f"{len(rows)} records in {wall / 60:.0f} min wall time on a shared "
             f"2-core machine under heavy load (CPU per diagnosis is process time)"
             f"{state}.", "",
             "## Summary", "", *summary(rows), "",
             "`cyclic-stiffness` is not counted in the share of tops in place: a "
             "stiffness in the cyclic flap rows alone fits, in the data, exactly as "
             "the shared `lambda_beta2` moved plus a term in the coning row, so no "
             "single entry can place it; freeing the shared parameters per row group "
             "absorbs it, and the map reports those values (`missing_terms_freed`).",
             "",
             "Against issue #36's done-when: no delay lead and no effect leaving most "
             "of the excess is named without the stand-in flag (met); the map's top "
             "entry lies where the truth's term acts on 72 % of the placeable records, "
             "not the 90 % asked (not met). The misses: `pitch-lag` acts in every row "
             "through the blade pitch, and its coning-row term is often placed in the "
             "recorded coning instead (the coning settles within hundredths of a "
             "second, so the two differ little in the band) or in an inflow-coupled "
             "cyclic entry; `rotor-speed`'s term is proportional to a slow extra state "
             "(0.8 s behind the inflow) that no single entry is, and on the records "
             "where the top misses it is in the right (coning) row on another "
             "variable.", "", *_ablation_section(), "## Per record", "", *table(rows), ""]
    (HERE / "outside.md").write_text("\n".join(lines))


#: The map's variants the ablation compares (``missing_terms`` keywords).
VARIANTS = (("base", {"free_shared": False, "confirm": 0}),
            ("refits", {"free_shared": False}),
            ("freed", {"confirm": 0}), ("freed+refits", {}))
LABELS = {"base": "base fit (before)", "refits": "refits only",
          "freed": "shared freed", "freed+refits": "freed + refits (default)"}


def ablation(kinds=KINDS, say=print) -> list:
    """The map alone on the study's records, three ways: the score test at the base
    fit (before issue #36), with the shared parameters freed per row group, and
    freed with the top entries confirmed by refits (the default): is the top entry
    where the truth's term acts?"""
    from inflowsim.diagnose.terms import missing_terms
    from inflowsim.identify import identify
    out = []
    with tempfile.TemporaryDirectory() as folder:
        for kind, seed, axes, rate, colour in cases(kinds):
            rec, info = outside_record(Path(folder) / "r.csv", kind, seed, rate=rate,
                                       axes=axes, colour_hz=colour)
            fit = identify(rec, "basic")
            row = {"kind": kind, "seed": seed, "axes": axes}
            for name, kw in VARIANTS:
                t = missing_terms(rec, fit, **kw).terms[0]
                row[name] = [t.block, t.equation, t.variable]
                row[name + "_hit"] = bool(info["truth"].acts_at(t.block, t.equation,
                                                                t.variable))
            say(f"{kind} {seed} {axes}: " + " ".join(
                f"{n} {row[n + '_hit']}" for n, _ in VARIANTS))
            out.append(row)
    return out


def ablation_lines(rows) -> list[str]:
    names = [n for n, _ in VARIANTS if n + "_hit" in rows[0]]
    out = ["| truth | " + " | ".join(LABELS[n] for n in names) + " |",
           "|" + " --- |" * (len(names) + 1)]
    for kind in sorted({r["kind"] for r in rows}):
        rk = [r for r in rows if r["kind"] == kind]
        out.append(f"| {kind} | " + " | ".join(
            f"{sum(r[n + '_hit'] for r in rk)} of {len(rk)}" for n in names) + " |")
    placed = [r for r in rows if r["kind"] not in AMBIGUOUS]
    out.append("| all but " + ", ".join(AMBIGUOUS) + " | " + " | ".join(
        f"{sum(r[n + '_hit'] for r in placed)} of {len(placed)}" for n in names) + " |")
    return out


def rejudged(rows):
    """The rows' flags computed again from their stored data with the library's
    rule (:func:`inflowsim.diagnose.verdict.stand_ins` on the stored share), for a
    table written from ``bench/results/outside.json``."""
    from inflowsim.diagnose.verdict import stand_ins
    for r in rows:
        if r["effects"]:
            extra = [x.effect for x in stand_ins(r["effects"], None, r["excess_explained"])]
            r["stand_ins"] = list(dict.fromkeys(r["stand_ins"] + extra))
        r["unflagged_excess"] = [e for e in r["effects"] if r["excess_explained"] is not None
                                 and r["excess_explained"] < 0.5
                                 and e not in r["stand_ins"]]
        r["lead_unflagged"] = bool("time-delay" in r["effects"] and (r["delay"] or 0) < 0
                                   and "time-delay" not in r["stand_ins"])
    return rows


def main(argv):
    if argv[:1] == ["--ablation"]:
        rows = ablation()
        (HERE / "results").mkdir(exist_ok=True)
        (HERE / "results" / "outside_ablation.json").write_text(json.dumps(rows, indent=1))
        print("\n".join(ablation_lines(rows)))
        return
    if argv[:1] == ["--from-json"]:
        rows = rejudged(json.loads((HERE / "results" / "outside.json").read_text()))
        write(rows, float(argv[1]) * 60 if len(argv) > 1 else 0.0,
              len(rows) == len(cases()))
        print("\n".join(summary(rows)))
        return
    kinds = tuple(argv) or KINDS
    t0 = time.time()
    if argv:
        rows = run(kinds)
    else:
        rows = run(kinds, each=lambda rows: write(rows, time.time() - t0, False))
        write(rows, time.time() - t0)
    print("\n".join(summary(rows)))


if __name__ == "__main__":
    main(sys.argv[1:])
