"""The work of a campaign: pure functions a worker anywhere can run.

:func:`record_task` (one record: read and validate it, diagnose and climb the
ladder), :func:`condition_task` (the records of one flight condition fitted
together: a joint ladder) and :func:`agreement` (across conditions: which
missing effect, how many records and conditions name it, where they disagree
and why).  Each returns a plain JSON-ready ``dict``: what a worker sends back is
small, and what the store keeps is text.  A failure is a result too: ``status
"error"`` with the one-line error, never an exception out of the task.

Results are keyed by what determines them (:func:`record_key`): the record
file's SHA-256, the settings and the package version; a changed record, setting
or version is new work, anything else is found in the store.
"""
from __future__ import annotations

import hashlib
import json
import time
import traceback
from dataclasses import asdict, dataclass
from types import MappingProxyType

from ..defaults import MAX_STEPS
from ..errors import InputError

#: Status of a result.
OK, ERROR = "ok", "error"


@dataclass(frozen=True)
class Settings:
    """What every record and condition is analysed with (``diagnose``/``ladder``
    options): starting structure ``model``, ``band`` [Hz], candidate ``pool``
    (``None``: every applicable effect), significance ``alpha``, ladder
    ``max_steps``, ``hold`` override (``None``: each record's own).

    Attributes
    ----------
    model : str
        The starting structure of every diagnosis and ladder.
    band : (float, float)
        Analysis band [Hz].
    pool : tuple of str or None
        Candidate effects (``None``: every applicable one).
    alpha : float or None
        Significance level per test [-] (``None``: the rule's).
    max_steps : int
        Ladder steps at most [-].
    hold : str or None
        Intersample behaviour of every record (``None``: each record's own).
    """

    model: str = "glauert"
    band: tuple = (0.2256, 1.58)
    pool: tuple | None = None
    alpha: float | None = None
    max_steps: int = MAX_STEPS
    hold: str | None = None

    def as_dict(self) -> dict:
        d = asdict(self)
        d["band"] = [float(b) for b in self.band]
        d["pool"] = None if self.pool is None else list(self.pool)
        return d

    def search_kwargs(self) -> dict:
        from ..defaults import ALPHA
        return {"pool": None if self.pool is None else list(self.pool),
                "alpha": ALPHA if self.alpha is None else float(self.alpha),
                "hold": self.hold}


#: What a stored result holds: raised when its fields change, so that a restarted
#: campaign redoes work whose stored result lacks them (2: each record's and
#: condition's trim, which the schedule fits).
RESULTS_FORMAT = 2


def version() -> str:
    """The package version and the results' format: part of every result's key."""
    from .. import __version__
    return f"{__version__}/results-{RESULTS_FORMAT}"


def file_hash(path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _key(*parts) -> str:
    return hashlib.sha256(json.dumps(parts, sort_keys=True).encode()).hexdigest()[:32]


def record_key(record_hash: str, settings: Settings) -> str:
    """The store key of one record's result."""
    return _key("record", record_hash, settings.as_dict(), version())


def condition_key(condition: str, record_hashes, settings: Settings) -> str:
    """The store key of a condition's joint result (its records' hashes, sorted)."""
    return _key("condition", condition, sorted(record_hashes), settings.as_dict(),
                version())


def _one_line(exc) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


#: The campaign's verdicts before issue #39, as stored results and old tables hold
#: them, and what they read as now: ``adequate`` (no effect named) is
#: ``no-missing-effect``, ``missing-effect`` (one named) ``explained``; a stored result
#: reads the status of its own ladder's verdict instead where it holds one.
OLD_VERDICTS = MappingProxyType({"adequate": "no-missing-effect",
                                 "missing-effect": "explained"})


def current_verdict(doc: dict) -> dict:
    """``doc`` (a stored result) with its ``verdict`` in the one vocabulary
    (:data:`inflowsim.diagnose.verdict.STATUSES`, or ``error``): an old one is
    read through :data:`OLD_VERDICTS`.

    Parameters
    ----------
    doc : dict
        A record's or condition's result (:func:`record_task`, :func:`condition_task`).
    """
    old = doc.get("verdict")
    if old in OLD_VERDICTS:
        status = ((doc.get("ladder") or {}).get("verdict") or {}).get("status")
        doc = {**doc, "verdict": status or OLD_VERDICTS[old]}
    return doc


def _verdict(lad, diag) -> str:
    """The row's verdict: the ladder's (what is left after the effects it added), in
    diagnose's vocabulary."""
    v = lad.verdict or diag.verdict
    return v.status


def _fit_summary(fit) -> dict:
    return {"structure": fit.structure.name, "cost": float(fit.cost),
            "n_freq": int(fit.n_freq), "converged": bool(fit.converged),
            "fit_percent": {c: v.get("fit_percent") for c, v in fit.fit.items()},
            "parameters": {n: {"estimate": float(v), "sigma": fit.sigma.get(n)}
                           for n, v in fit.parameters.items()}}


def _ladder_summary(lad, diag) -> dict:
    return {"missing_effect": diag.missing_effect,
            "verdict": _verdict(lad, diag),
            "accepted": list(diag.missing_effects),
            "ladder_added": [r.added for r in lad.rungs if r.added],
            "final_structure": lad.final.structure.name,
            "base_fit": _fit_summary(diag.fit),
            "final_fit": _fit_summary(lad.final.fit),
            "candidates": {c.atom: {"accepted": bool(c.accepted), "reason": c.reason,
                                    "failed": list(c.failed)}
                           for c in diag.candidates},
            "diagnosis": diag.to_json(), "ladder": lad.to_json()}


def record_task(path: str, settings: Settings, info: dict | None = None) -> dict:
    """Read, validate, diagnose and climb the ladder on one record.

    The diagnosis is the ladder's first rung: the same call as
    ``inflowsim diagnose RECORD --model MODEL`` with these settings.  Returns
    ``{"kind": "record", "record", "status", "error", "warnings", "trim", "mu",
    "missing_effect", "verdict", ..., "seconds"}`` (:func:`_ladder_summary`;
    ``trim`` the record's trim totals, as a condition's).

    Parameters
    ----------
    path : str
        The record (CSV).
    settings : Settings
        The campaign's settings (model, band [Hz], candidates, level, hold ...).
    info : dict, optional
        The plan's labels of the record (condition, manoeuvre, group, plan ``mu`` [-]).
    """
    from ..data.record import find_trim, read_record
    from ..diagnose.search import ladder
    t0 = time.perf_counter()
    out = {"kind": "record", "record": str(path), **(info or {}), "status": OK,
           "error": None, "warnings": []}
    try:
        rec = read_record(path)
        out["warnings"] = list(rec.warnings())
        trim = find_trim(rec)
        if trim.warning:
            out["warnings"].append(trim.warning)
        out["trim"] = _trim_totals([trim.values])
        rec.check_band(settings.band)
        out["mu"] = float(rec.constants.mu)
        out["duration_s"] = float(rec.duration)
        lad = ladder(rec, settings.model, tuple(settings.band),
                     max_steps=settings.max_steps, **settings.search_kwargs())
        out.update(_ladder_summary(lad, lad.rungs[0].diagnosis))
    except InputError as exc:
        out.update(status=ERROR, error=_one_line(exc), verdict="error", missing_effect=None)
    except Exception as exc:            # a record must never end the campaign
        out.update(status=ERROR, verdict="error", missing_effect=None,
                   error=f"{type(exc).__name__}: {_one_line(exc)}",
                   traceback=traceback.format_exc(limit=8))
    out["seconds"] = time.perf_counter() - t0
    return out


def _trim_totals(values) -> dict:
    """``{column: mean}`` over ``values`` (each a record's :func:`~inflowsim.data.
    record.find_trim` values) of the trim totals effects linearised about trim read
    (:data:`~inflowsim.physics.bladeelement.TRIM_KEYS`; those every record has)."""
    from ..physics.bladeelement import TRIM_KEYS
    return {c: float(sum(v[c] for v in values) / len(values)) for c in TRIM_KEYS
            if all(c in v for v in values)}


def condition_task(condition: str, paths, settings: Settings) -> dict:
    """The records of one flight condition fitted together: a joint diagnosis
    and ladder (``identify``/``ladder`` on the list of records).

    Besides the ladder's summary: ``mu`` (the records' mean), ``rotor`` (the first
    record's ``a0, solidity, omega, radius``) and ``trim`` (each trim total of
    :data:`~inflowsim.physics.bladeelement.TRIM_KEYS`, the mean over the records of
    :func:`~inflowsim.data.record.find_trim`) [rad, -]: what the campaign's
    schedule needs to fly this condition.

    Parameters
    ----------
    condition : str
        The flight condition's label.
    paths : sequence of str
        Its records (CSV), fitted together.
    settings : Settings
        The campaign's settings.
    """
    from ..data.record import find_trim, read_record
    from ..diagnose.search import ladder
    t0 = time.perf_counter()
    out = {"kind": "condition", "condition": condition, "records": list(map(str, paths)),
           "status": OK, "error": None}
    try:
        recs = [read_record(p) for p in paths]
        out["mu"] = float(sum(r.constants.mu for r in recs) / len(recs))
        k = recs[0].constants            # the rotor, for the schedule's FMU
        out["rotor"] = {n: getattr(k, n) for n in ("a0", "solidity", "omega", "radius")
                        if getattr(k, n) is not None}
        # the trim the condition flies at: a model linearised about trim needs the
        # trim of its mu, and the trim changes strongly with speed
        out["trim"] = _trim_totals([find_trim(r).values for r in recs])
        lad = ladder(recs, settings.model, tuple(settings.band),
                     max_steps=settings.max_steps, **settings.search_kwargs())
        out.update(_ladder_summary(lad, lad.rungs[0].diagnosis))
    except InputError as exc:
        out.update(status=ERROR, error=_one_line(exc), verdict="error", missing_effect=None)
    except Exception as exc:
        out.update(status=ERROR, verdict="error", missing_effect=None,
                   error=f"{type(exc).__name__}: {_one_line(exc)}",
                   traceback=traceback.format_exc(limit=8))
    out["seconds"] = time.perf_counter() - t0
    return out


def agreement(records, conditions) -> dict:
    """Agreement on the missing effect across records and conditions.

    ``effects``: per named effect, how many records and conditions name it;
    ``by_condition``: each condition's joint answer and its records' answers;
    ``disagreements``: every record whose answer differs from its condition's
    joint answer, with why (what its own diagnosis said of the joint answer's
    candidate).  ``consensus``: the effect named by the most conditions (ties:
    ``None``), ``unanimous``: every successful condition names it.

    Parameters
    ----------
    records : sequence of dict
        The records' results (:func:`record_task`).
    conditions : sequence of dict
        The conditions' results (:func:`condition_task`).
    """
    ok_recs = [r for r in records if r.get("status") == OK]
    ok_conds = [c for c in conditions if c.get("status") == OK]
    effects: dict = {}
    for r in ok_recs:
        e = effects.setdefault(str(r["missing_effect"]), {"records": 0, "conditions": 0})
        e["records"] += 1
    for c in ok_conds:
        e = effects.setdefault(str(c["missing_effect"]), {"records": 0, "conditions": 0})
        e["conditions"] += 1
    by_cond, disagree = {}, []
    for c in conditions:
        mine = [r for r in records if r.get("condition") == c["condition"]]
        answers = {}
        for r in mine:
            k = "error" if r.get("status") != OK else str(r["missing_effect"])
            answers[k] = answers.get(k, 0) + 1
        by_cond[c["condition"]] = {"mu": c.get("mu"), "joint": c.get("missing_effect")
                                   if c.get("status") == OK else "error",
                                   "records": answers}
        if c.get("status") != OK:
            continue
        joint = c.get("missing_effect")
        for r in mine:
            if r.get("status") != OK or r.get("missing_effect") == joint:
                continue
            cand = (r.get("candidates") or {}).get(joint) if joint else None
            if joint is None:
                why = (f"the joint fit of the condition names no effect; this record "
                       f"alone names {r['missing_effect']}")
            elif cand is None:
                why = f"{joint} was not a candidate on this record"
            else:
                why = f"{joint} on this record alone: {cand['reason'] or 'not accepted'}"
            disagree.append({"record": r["record"], "condition": c["condition"],
                             "record_says": r.get("missing_effect"), "condition_says": joint,
                             "why": why})
    counts = sorted(((v["conditions"], k) for k, v in effects.items() if k != "None"),
                    reverse=True)
    consensus = None
    if counts and (len(counts) == 1 or counts[0][0] > counts[1][0]):
        consensus = counts[0][1]
    return {"effects": effects, "by_condition": by_cond, "disagreements": disagree,
            "consensus": consensus,
            "unanimous": bool(ok_conds) and all(c.get("missing_effect") == consensus
                                                for c in ok_conds)}


__all__ = ["Settings", "RESULTS_FORMAT", "version", "file_hash", "record_key",
           "condition_key", "OLD_VERDICTS", "current_verdict", "record_task",
           "condition_task", "agreement"]
