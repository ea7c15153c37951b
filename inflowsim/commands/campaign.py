"""``inflowsim campaign``: a flight-test campaign on Dask, resumable.

``PLAN`` is a folder of records or a manifest (CSV or TOML: record, flight
condition, manoeuvre, group; :mod:`inflowsim.campaign.plan`).  Per record:
validate, diagnose and ladder; per flight condition: the records fitted
together (a joint diagnosis and ladder); across conditions: agreement on the
missing effect.  Runs on a local Dask cluster of the machine's cores, or on the
cluster at ``--scheduler``.  Results are stored under ``--out`` keyed by each
record's hash, the settings and the package version: a restarted campaign skips
what is done.  Writes ``campaign.parquet``, ``campaign.csv``, ``report.html``,
``report.md``, ``estimates_vs_mu.png``, ``schedule.json`` (each parameter against ``mu``:
``inflowsim fmu build --schedule``) and ``campaign.json`` there; ``--json``
prints the document on stdout (the progress bar is on stderr).
"""
from __future__ import annotations

from ..defaults import MAX_STEPS
from ..errors import InputError
from ._checks import finite_float
from ._common import add_also_option, pool_with, print_json, progress, unknown_effect, warn

HELP = "a campaign of records at several flight conditions, on Dask (resumable)"


def add_arguments(p):
    from ..defaults import DEFAULT_BAND
    p.add_argument("plan", metavar="PLAN",
                   help="folder of records (*.csv) or manifest (.csv or .toml)")
    p.add_argument("--out", "-o", required=True, metavar="DIR",
                   help="results folder (created; reused by a restarted campaign)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="Dask scheduler address (tcp://host:8786); default a local "
                        "cluster of this machine's cores")
    p.add_argument("--workers", type=int, metavar="N",
                   help="local cluster worker processes (default: the cores; 0: no "
                        "cluster, run in this process)")
    p.add_argument("--model", "-m", default=None,
                   help="starting structure of every diagnosis and ladder "
                        "(default: the plan's, else glauert)")
    p.add_argument("--band", nargs=2, type=finite_float, metavar=("F1", "F2"), default=None,
                   help=f"band [Hz] (default {DEFAULT_BAND[0]:g} {DEFAULT_BAND[1]:g})")
    p.add_argument("--candidates", nargs="+", metavar="EFFECT",
                   help="effects to try (default: every applicable one)")
    add_also_option(p)
    p.add_argument("--alpha", type=finite_float, default=None,
                   help="significance level per candidate")
    p.add_argument("--max-steps", type=int, default=None, help="ladder steps at most "
                                                                f"(default {MAX_STEPS})")
    p.add_argument("--hold", choices=("continuous", "zoh", "foh"),
                   help="intersample behaviour of every record (default each record's)")
    p.add_argument("--schedule-criterion", choices=("aic", "aicc", "bic", "chi2"),
                   default="aic", help="how each parameter's polynomial order in mu is "
                   "chosen for schedule.json (default aic: chi-square + 2 per "
                   "coefficient; chi2: the lowest order whose residuals pass the "
                   "chi-square test)")
    p.add_argument("--schedule-order", type=int, default=3, metavar="N",
                   help="highest polynomial order of the schedule (default 3)")
    p.add_argument("--schedule-variable", choices=("mu", "1/mu", "both"), default="mu",
                   help="what each schedule polynomial is in (default mu; 1/mu suits "
                        "inflow time constants, which go like 1/V; both: the "
                        "criterion chooses per parameter)")
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")


def _setting(s, key, kinds, what, default):
    """``s[key]`` (the manifest's ``[settings]``) if of ``kinds``, else one line."""
    if key not in s:
        return default
    v = s[key]
    if isinstance(v, bool) or not isinstance(v, kinds):
        raise InputError(f"plan setting {key} = {v!r}: must be {what}")
    return v


def _settings(args, plan):
    from ..campaign.work import Settings
    from ..defaults import ALPHA, DEFAULT_BAND, HOLDS
    from ..model.structure import Structure
    from ._checks import check_band
    s = plan.settings
    model = args.model or _setting(s, "model", str, "a structure name", "glauert")
    Structure.parse(model)                            # refuses an unknown structure
    if args.band:
        band = tuple(args.band)
    else:
        band = _setting(s, "band", list, "two frequencies [F1, F2] in Hz", DEFAULT_BAND)
        if len(band) != 2 or not all(isinstance(b, (int, float)) and
                                     not isinstance(b, bool) for b in band):
            raise InputError(f"plan setting band = {band!r}: must be two frequencies "
                             "[F1, F2] in Hz")
        band = tuple(float(b) for b in band)
    check_band(band, "band")
    alpha = args.alpha if args.alpha is not None else \
        _setting(s, "alpha", (int, float), "a number in (0, 0.5)", ALPHA)
    if not 0 < float(alpha) < 0.5:
        raise InputError(f"--alpha {alpha:g}: choose a level in (0, 0.5)")
    steps = args.max_steps if args.max_steps is not None else \
        _setting(s, "max_steps", int, "a whole number >= 0", MAX_STEPS)
    if steps < 0:
        raise InputError(f"--max-steps {steps}: must be >= 0")
    cands = args.candidates or _setting(s, "candidates", list, "a list of effect names",
                                        None)
    if cands is not None and not all(isinstance(c, str) for c in cands):
        raise InputError(f"plan setting candidates = {cands!r}: must be effect names")
    hold = args.hold or _setting(s, "hold", str, f"one of {', '.join(HOLDS)}", None)
    if hold is not None and hold not in HOLDS:
        raise InputError(f"plan setting hold = {hold!r}: choose {', '.join(HOLDS)}")
    pool = pool_with(cands, args.also)
    if pool is not None:
        from ..model.effects import CATALOGUE
        for e in pool:
            if e not in CATALOGUE:
                raise InputError(f"candidate {e!r}: {unknown_effect(e, CATALOGUE)}")
    return Settings(model=model, band=band, pool=None if pool is None else tuple(pool),
                    alpha=float(alpha), max_steps=steps, hold=hold)


def run(args) -> int:
    from pathlib import Path

    from ..campaign.plan import read_plan
    from ..errors import InputError
    from ..fileio import check_folder
    if args.workers is not None and args.workers < 0:
        raise InputError(f"--workers {args.workers}: must be >= 0")
    if args.scheduler and args.workers is not None:
        raise InputError("--scheduler and --workers: the scheduler's cluster has its own "
                         "workers; give one of them")
    out = check_folder(args.out)
    plan = read_plan(args.plan, exclude=[out])
    for e in plan.entries:
        if Path(e.path).resolve() == out.resolve() or out.resolve() in Path(e.path).parents:
            raise InputError(f"--out {out}: holds the plan's record {e.path}")
    settings = _settings(args, plan)
    from ..campaign.engine import run_campaign
    from ..campaign.tables import json_document
    if args.schedule_order < 0:
        raise InputError(f"--schedule-order {args.schedule_order}: must be >= 0")
    res = run_campaign(plan, out, settings, scheduler=args.scheduler, workers=args.workers,
                       progress=progress, schedule_criterion=args.schedule_criterion,
                       schedule_max_order=args.schedule_order,
                       schedule_variables=(("mu", "1/mu") if args.schedule_variable == "both"
                                           else (args.schedule_variable,)))
    doc = json_document(res, res.files)
    failed = [r for r in res.records if r.get("status") != "ok"]
    if args.json:
        print_json(doc)
    else:
        ag = res.agreement
        print(f"{len(res.records)} records, {len(res.conditions)} conditions "
              f"({res.computed['records']} records and {res.computed['conditions']} "
              f"conditions computed, the rest found in {out})")
        for c in res.conditions:
            print(f"  {c['condition']}: {c.get('missing_effect') or 'none'}"
                  + (f" (error: {c.get('error')})" if c.get("status") != "ok" else ""))
        print(f"consensus: {ag['consensus'] or 'none'}; "
              f"{len(ag['disagreements'])} record(s) disagree with their condition")
        bad = [r for r in res.records if r.get("status") != "ok"]
        for r in bad:
            warn(f"{r.get('record')} could not be analysed: {r.get('error')}")
        if res.schedule is not None:
            sch = res.schedule
            trend = [p.name for p in sch.parameters if not p.constant]
            print(f"schedule: {res.files['schedule']} ({len(sch.parameters)} parameters "
                  f"against mu {sch.mu_range[0]:.3g}-{sch.mu_range[1]:.3g}; not constant: "
                  f"{', '.join(trend) or 'none'}"
                  + ("; with the trim the conditions flew at" if sch.trim else "") + ")")
        else:
            print(f"schedule: none ({res.schedule_note})")
        print(f"report: {res.files['html']} (and {res.files['report']})")
    if res.records and len(failed) == len(res.records):
        raise InputError(f"every one of the {len(failed)} records failed (the first: "
                         f"{failed[0].get('error')}); see {res.files['report']}")
    return 0
