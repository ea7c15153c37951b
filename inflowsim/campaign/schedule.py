"""A campaign's parameter schedule: the joint fit of every flight condition,
each parameter against ``mu`` (:func:`inflowsim.model.schedule.fit_schedule`).

The conditions' joint fits of the starting structure (the table's ``est_``,
``sigma_`` columns: the same structure at every condition) give each parameter's
estimate and bound at the condition's ``mu``; conditions that failed, or whose fit
is of another structure, are left out (and named).  The rotor is the conditions'
(``a0``, ``solidity``, ``omega``; the middle of the range as ``mu``), so
``inflowsim fmu build --schedule`` needs nothing else.

The trim goes with it: each condition's measured trim totals (``condition_task``'s
``trim``, the mean of its records' :func:`~inflowsim.data.record.find_trim`) are
fitted against ``mu`` (:func:`inflowsim.model.schedule.fit_trim`), so that a model
linearised about the trim (``advance-ratio-perturbation``) flies, in the Simulator
and the FMU, about the trim of the ``mu`` it is at, not about none.
"""
from __future__ import annotations

from collections import Counter

from ..errors import InputError


def campaign_schedule(conditions, criterion: str = "aic", max_order: int = 3,
                      alpha: float = 0.05, variables=("mu",),
                      trim_order: int | None = None):
    """``(schedule, note)``: the :class:`~inflowsim.model.schedule.Schedule` of the
    conditions' joint fits, or ``(None, why not)``; ``note`` names conditions left
    out.

    The schedule's trim (:attr:`~inflowsim.model.schedule.Schedule.trim`): each trim
    total every condition used has, an unweighted least-squares polynomial in
    ``mu`` of order ``min(trim_order, m - 1)`` (``m`` distinct ``mu``; default
    :data:`~inflowsim.model.schedule.TRIM_MAX_ORDER`, a cubic).  The totals are
    measured, not estimated: no bound to weight by and no order to choose against
    their scatter, which is far below their trend with speed; a cubic holds the
    collective's power bucket and the cyclics' curvature, and with four conditions
    or fewer it passes through each.  Each column's largest residual is
    :attr:`~inflowsim.model.schedule.TrimSchedule.residual` (in the report and the
    ``--json`` summary).  Conditions without a trim (results stored by an older
    version) leave the schedule without one."""
    from ..model.params import Constants
    from ..model.schedule import TRIM_MAX_ORDER, fit_schedule
    ok = [c for c in conditions if c.get("status") == "ok" and c.get("mu") is not None
          and (c.get("base_fit") or {}).get("structure")]
    if not ok:
        return None, "no condition was fitted"
    structures = Counter(c["base_fit"]["structure"] for c in ok)
    structure = structures.most_common(1)[0][0]
    used = [c for c in ok if c["base_fit"]["structure"] == structure]
    left = [c["condition"] for c in conditions if c not in used]
    names = list(used[0]["base_fit"]["parameters"])
    est = {n: [c["base_fit"]["parameters"].get(n, {}).get("estimate") for c in used]
           for n in names}
    sig = {n: [c["base_fit"]["parameters"].get(n, {}).get("sigma") for c in used]
           for n in names}
    mus = [float(c["mu"]) for c in used]
    rotor = next((c.get("rotor") for c in used if c.get("rotor")), None)
    constants = None
    if rotor:
        constants = Constants.from_mapping({**rotor, "mu": 0.5 * (min(mus) + max(mus))})
    trims = [c.get("trim") or {} for c in used]
    trim = {col: [t[col] for t in trims] for col in trims[0]
            if all(col in t for t in trims)}
    try:
        sch = fit_schedule(structure, mus, est, sig, criterion=criterion,
                           max_order=max_order, alpha=alpha, constants=constants,
                           source="campaign", variables=variables, trim=trim,
                           trim_order=TRIM_MAX_ORDER if trim_order is None
                           else trim_order)
    except InputError as exc:
        return None, str(exc)
    notes = [f"conditions left out (failed, or fitted with another structure than "
             f"{structure}): {', '.join(left)}"] if left else []
    from ..model.structure import needs_trim
    if needs_trim([structure]) and not sch.trim:
        notes.append(f"{structure} is linearised about the trim, but the conditions "
                     "hold no trim totals: the schedule's simulator and FMU keep the "
                     "trim they are given at every mu")
    return sch, "; ".join(notes)


def schedule_summary(sch, note: str = "") -> dict:
    """The schedule in the ``--json`` document: per parameter its order, the
    constant test, and its value and bound at the range's ends and middle; per
    trim total its order, largest residual and value there."""
    if sch is None:
        return {"schedule": None, "note": note}
    lo, hi = sch.mu_range
    at = (lo, 0.5 * (lo + hi), hi)
    return {"structure": sch.structure, "mu_range": list(sch.mu_range),
            "criterion": sch.criterion, "alpha": sch.alpha, "note": note,
            "parameters": {p.name: {
                "order": p.order, "constant_adequate": p.constant,
                "constant_p": p.constant_p,
                "at": [{"mu": m, "value": p.value(m), "sigma": p.bound(m)} for m in at]}
                for p in sch.parameters},
            "held": {n: {"value": v, "sigma": s} for n, v, s in sch.held},
            "trim": {t.column: {"order": t.order, "max_residual": t.residual,
                                "at": [{"mu": m, "value": t.value(m)} for m in at]}
                     for t in sch.trim}}


__all__ = ["campaign_schedule", "schedule_summary"]
