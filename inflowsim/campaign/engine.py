"""Running a campaign on Dask, resumably.

:func:`run_campaign` keys every record and condition (:mod:`.work`), skips what
the store under ``out/results`` already holds, sends the rest to a Dask cluster
(a local cluster of processes by default, or the scheduler at ``scheduler``),
writes each result the moment it arrives (so a campaign killed halfway restarts
where it stopped), then the joint fits per condition, then the tables and the
report (:mod:`.tables`).

Workers on other machines: start a scheduler (``dask scheduler``) and workers
that point at it (``dask worker tcp://HOST:8786 --nworkers N --nthreads 1``),
with ``inflowsim`` installed and the records at the same paths (a shared file
system); then ``inflowsim campaign PLAN --out DIR --scheduler tcp://HOST:8786``.
Results are written by this process only.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError
from ..progress import SHOW, bar
from .plan import Plan
from .work import (OK, Settings, agreement, condition_key, condition_task,
                   current_verdict, file_hash, record_key, record_task, version)


class Store:
    """Results as JSON files ``out/results/{records,conditions}/KEY.json``,
    each written atomically (a temporary file renamed)."""

    def __init__(self, out):
        self.root = Path(out) / "results"

    def _path(self, kind, key):
        return self.root / kind / f"{key}.json"

    def get(self, kind, key):
        p = self._path(kind, key)
        try:
            doc = json.loads(p.read_text())
        except (OSError, ValueError):
            return None
        return current_verdict(doc) if isinstance(doc, dict) else None

    def put(self, kind, key, doc):
        from ..fileio import atomic_path, json_text
        p = self._path(kind, key)
        p.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(p) as tmp:
            Path(tmp).write_text(json_text(doc))


@dataclass
class CampaignResult:
    """What a run produced: per-record and per-condition results (plan order),
    the agreement across conditions, how much was computed and reused."""

    records: list
    conditions: list
    agreement: dict
    settings: dict
    computed: dict = field(default_factory=dict)
    reused: dict = field(default_factory=dict)
    files: dict = field(default_factory=dict)
    #: the parameter schedule across conditions (:mod:`.schedule`), or None, and
    #: why not / which conditions it leaves out
    schedule: object = None
    schedule_note: str = ""


def _client(scheduler, workers, progress=None):
    """A Dask client: the scheduler at ``scheduler``, or a local cluster of
    ``workers`` single-threaded processes (default: the machine's cores).  The
    cluster's dashboard address is said through ``progress`` (a local cluster has
    one when ``bokeh``, Dask's dashboard library, is installed)."""
    import importlib.util
    import logging

    from dask.distributed import Client, LocalCluster
    if scheduler:
        try:
            client, cluster = Client(scheduler, timeout="20s"), None
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError(f"--scheduler {scheduler}: cannot connect ({exc})") from None
    else:
        n = workers or os.cpu_count() or 1
        board = ":0" if importlib.util.find_spec("bokeh") else None
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=board, silence_logs=logging.ERROR)
        client = Client(cluster)
    if progress is not None:
        # a local scheduler without bokeh serves no dashboard page (404) at the
        # address it lists
        where = dashboard(client) if scheduler or board else NO_DASHBOARD
        progress(f"campaign: Dask dashboard at {where}")
    return client, cluster


#: What the campaign says when its scheduler serves no dashboard.
NO_DASHBOARD = "none (the scheduler runs no dashboard; pip install bokeh for one)"


def dashboard(client) -> str:
    """The Dask dashboard's address of ``client``'s scheduler, or why there is none.

    Parameters
    ----------
    client : dask.distributed.Client
    """
    none = NO_DASHBOARD
    try:
        # dashboard_link formats a default port even when the scheduler serves none
        info = client.scheduler_info() if hasattr(client, "scheduler_info") else None
        if info is not None and "dashboard" not in (info.get("services") or {}):
            return none
        return client.dashboard_link
    except (KeyError, AttributeError):
        return none


def run_campaign(plan: Plan, out, settings: Settings, scheduler=None, workers=None,
                 progress=True, stream=None, schedule_criterion: str = "aic",
                 schedule_max_order: int = 3, schedule_variables=("mu",)
                 ) -> CampaignResult:
    """Run (or resume) the campaign of ``plan`` into the folder ``out``.

    ``workers = 0``: no cluster, everything in this process (debugging, tests).
    ``schedule_criterion``, ``schedule_max_order``, ``schedule_variables``: how the
    parameter schedule across conditions chooses each polynomial's variable and order
    (:func:`inflowsim.model.schedule.fit_schedule`); the schedule is computed from
    the stored results at the end of every run, so they are not part of the keys.
    ``progress``: ``True`` a bar per stage and the Dask dashboard's address on
    standard error when progress is shown (:mod:`inflowsim.progress`), ``False`` or
    ``None`` nothing, a callable one line per result; ``stream`` is not used (kept
    for callers that pass it).

    Parameters
    ----------
    plan : Plan
        The records and their conditions (:func:`~inflowsim.campaign.plan.read_plan`).
    out : path-like
        The results folder (created; reused by a restarted campaign).
    settings : Settings
        Model, band [Hz], candidates, level and hold of every analysis.
    scheduler : str, optional
        A Dask scheduler's address (``tcp://host:8786``); default a local cluster.
    workers : int, optional
        Local worker processes (default the cores; 0: everything in this process).
    progress : bool, callable or None
        Progress (see above).
    stream : object, optional
        Not used (kept for callers that pass it).
    schedule_criterion : {"aic", "aicc", "bic", "chi2"}
        How each schedule polynomial's order is chosen.
    schedule_max_order : int
        Highest polynomial order of the schedule.
    schedule_variables : tuple of str
        What the polynomials are in (``"mu"``, ``"1/mu"``) [-].
    """
    progress = SHOW if progress is True else (progress or None)
    from ..model.schedule import CRITERIA
    if schedule_criterion not in CRITERIA:
        raise InputError(f"schedule criterion {schedule_criterion!r}: choose "
                         f"{', '.join(CRITERIA)}")
    if int(schedule_max_order) != schedule_max_order or schedule_max_order < 0:
        raise InputError(f"schedule order {schedule_max_order!r}: an integer >= 0")
    from ..model.schedule import VARIABLES
    schedule_variables = tuple(schedule_variables)
    if not schedule_variables or any(v not in VARIABLES for v in schedule_variables):
        raise InputError(f"schedule variables {list(schedule_variables)}: choose from "
                         f"{', '.join(VARIABLES)}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    store = Store(out)
    entries = list(plan.entries)
    infos = [{"condition": e.condition, "manoeuvre": e.manoeuvre, "group": e.group,
              "plan_mu": e.mu} for e in entries]
    hashes = [file_hash(e.path) for e in entries]
    keys = [record_key(h, settings) for h in hashes]
    records: list = [store.get("records", k) for k in keys]
    todo = [i for i, r in enumerate(records) if r is None]
    computed = {"records": 0, "conditions": 0}
    reused = {"records": len(entries) - len(todo), "conditions": 0}

    client = cluster = None
    try:
        if workers != 0 and todo:
            client, cluster = _client(scheduler, workers, progress)
        _stage(client, record_task, [(entries[i].path, settings, infos[i]) for i in todo],
               todo, "records", keys, records, store, computed,
               lambda i: Path(entries[i].path).name, _record_failed, stream, progress)

        groups = plan.conditions
        cond_keys, cond_args = [], []
        for cond, members in groups.items():
            idx = [entries.index(m) for m in members]
            usable = [i for i in idx if records[i].get("status") == OK]
            cond_keys.append(condition_key(cond, [hashes[i] for i in usable], settings))
            cond_args.append((cond, [entries[i].path for i in usable]))
        conditions: list = [store.get("conditions", k) for k in cond_keys]
        ctodo = [j for j, c in enumerate(conditions) if c is None]
        reused["conditions"] = len(conditions) - len(ctodo)
        for j in list(ctodo):
            if not cond_args[j][1]:             # no usable record: an error row, no fit
                cond, _ = cond_args[j]
                conditions[j] = {"kind": "condition", "condition": cond, "records": [],
                                 "status": "error", "verdict": "error",
                                 "missing_effect": None, "key": cond_keys[j],
                                 "error": "no record of this condition could be analysed"}
                ctodo.remove(j)
        if ctodo and client is None and workers != 0:
            client, cluster = _client(scheduler, workers, progress)
        _stage(client, condition_task,
               [(cond_args[j][0], cond_args[j][1], settings) for j in ctodo], ctodo,
               "conditions", cond_keys, conditions, store, computed,
               lambda j: cond_args[j][0], _condition_failed, stream, progress)
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()

    for r, info in zip(records, infos):        # the plan's labels, not the stored ones
        r.update({k: v for k, v in info.items() if k != "plan_mu"})
    res = CampaignResult(records, conditions, agreement(records, conditions),
                         {**settings.as_dict(), "version": version(), "plan": plan.source,
                          "schedule": {"criterion": schedule_criterion,
                                       "max_order": int(schedule_max_order),
                                       "variables": list(schedule_variables)}},
                         computed, reused)
    from .tables import write_outputs
    res.files = write_outputs(res, out)
    return res


def _stage(client, fn, args, tags, kind, keys, results, store, computed, note, failed,
           stream, progress):
    """One stage of the campaign (``kind`` ``"records"`` or ``"conditions"``): run
    ``fn(*a)`` for each ``a`` of ``args`` (result slot ``tags[n]``), and as each
    finishes: key it, store it (unless transient), put it in ``results``, count it,
    step the progress bar with ``note(tag)``.  ``failed(a, exc)``: the error row of
    a task whose worker was lost."""
    if not tags:
        return
    with bar(progress, len(tags), f"campaign: {kind}", kind[:-1]) as b:
        def done(tag, res):
            res["key"] = keys[tag]
            if not res.get("transient"):
                store.put(kind, keys[tag], res)
            results[tag] = res
            computed[kind] += 1
            b.set_postfix_str(str(note(tag)), refresh=False)
            b.update()

        _map(client, fn, list(zip(args, tags)), done, failed)


def _lost(exc) -> dict:
    return {"status": "error", "verdict": "error", "missing_effect": None,
            "error": f"the worker failed: {type(exc).__name__}: {exc}",
            "transient": True}                 # not stored: a restart tries again


def _record_failed(args, exc) -> dict:
    return {"kind": "record", "record": str(args[0]),
            **(args[2] if len(args) > 2 else {}), **_lost(exc)}


def _condition_failed(args, exc) -> dict:
    return {"kind": "condition", "condition": str(args[0]), **_lost(exc)}


def _map(client, fn, jobs, done, failed):
    """Run ``fn(*args)`` for every ``(args, tag)`` of ``jobs``; ``done(tag, result)``
    as each finishes (in completion order); a task whose worker failed gives
    ``failed(args, exc)``."""
    if not jobs:
        return
    if client is None:
        for args, tag in jobs:
            done(tag, fn(*args))
        return
    from dask.distributed import as_completed
    futures = {}
    for args, tag in jobs:
        fut = client.submit(fn, *args, pure=False)
        futures[fut] = (args, tag)
    for fut in as_completed(list(futures)):
        args, tag = futures[fut]
        try:
            res = fut.result()
        except Exception as exc:               # a worker lost: the task's own error row
            res = failed(args, exc)
        done(tag, res)


__all__ = ["Store", "CampaignResult", "NO_DASHBOARD", "dashboard", "run_campaign"]
