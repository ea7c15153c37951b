"""A flight-test campaign: many records at several flight conditions, on Dask.

:mod:`.plan` (which records, conditions, manoeuvres), :mod:`.work` (the work on
one record and on one condition, and the agreement across conditions: pure
functions any worker runs), :mod:`.engine` (Dask, the resumable store, the
progress bar), :mod:`.tables` (the pandas table, the report).  Dask and pandas
are imported only when a campaign runs.
"""
from .plan import Plan, PlanEntry, read_plan
from .work import Settings, agreement, condition_task, record_task

__all__ = ["Plan", "PlanEntry", "read_plan", "Settings", "record_task", "condition_task",
           "agreement", "run_campaign"]


def run_campaign(*args, **kwargs):
    """:func:`inflowsim.campaign.engine.run_campaign` (imported on first use).

    Parameters
    ----------
    *args, **kwargs
        As :func:`inflowsim.campaign.engine.run_campaign` takes them (plan, out,
        settings, scheduler, workers [-], progress ...).
    """
    from .engine import run_campaign as run
    return run(*args, **kwargs)
