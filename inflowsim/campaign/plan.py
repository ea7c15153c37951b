"""A campaign's plan: which records, at which flight condition, from which manoeuvre.

``PLAN`` is a folder of records (every ``*.csv`` in it, sorted; each record's
flight condition from its ``# mu:`` metadata, its manoeuvre from ``#
manoeuvre:`` or ``# description:``) or a manifest:

CSV
    a header row with ``record`` (a path, relative to the manifest's folder) and
    optionally ``condition``, ``manoeuvre``, ``group``.
TOML
    ``[[record]]`` tables with ``path`` and optionally ``condition``,
    ``manoeuvre``, ``group``; an optional ``[settings]`` table (``model``,
    ``band``, ``candidates``, ``alpha``, ``max_steps``, ``hold``) the command
    line overrides.

A record without a condition is at ``mu=<its mu to 3 decimals>``: records flown
at one speed form one condition.  Nothing here reads a record's data; only
metadata lines are read to name conditions (``validate`` in the per-record work
reads the rest).
"""
from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError

MANIFEST_SUFFIXES = (".csv", ".toml")
SETTINGS_KEYS = ("model", "band", "candidates", "alpha", "max_steps", "hold")


@dataclass(frozen=True)
class PlanEntry:
    """One record of the plan: ``path`` (absolute), ``condition`` label, ``mu``
    [-] (from the record's metadata; ``None`` where unreadable), ``manoeuvre``,
    ``group`` (free text, may be empty).

    Attributes
    ----------
    path : str
        The record (absolute path).
    condition : str
        Its flight condition's label.
    mu : float or None
        Its advance ratio [-] (``None`` where unreadable).
    manoeuvre : str
        What was flown (free text).
    group : str
        A grouping label (free text, may be empty).
    """

    path: str
    condition: str
    mu: float | None
    manoeuvre: str = ""
    group: str = ""


@dataclass(frozen=True)
class Plan:
    """A campaign's plan: its records with their flight conditions.

    Attributes
    ----------
    source : str
        The folder or manifest the plan was read from.
    entries : tuple of PlanEntry
        The records, in plan order.
    settings : dict
        Settings the manifest gives (model, band [Hz] ...), overridden by the options.
    """

    source: str
    entries: tuple
    settings: dict = field(default_factory=dict)

    @property
    def conditions(self) -> dict:
        """``{condition: [entries]}`` in first-seen order."""
        out: dict = {}
        for e in self.entries:
            out.setdefault(e.condition, []).append(e)
        return out


def _condition_of(meta: dict):
    try:
        mu = float(meta["mu"])
    except (KeyError, ValueError):
        return None, "unknown"
    return mu, f"mu={mu:.3f}"


def _entry(path: Path, condition="", manoeuvre="", group="") -> PlanEntry:
    from ..data.record import header_meta
    meta = header_meta(path)
    mu, cond = _condition_of(meta)
    return PlanEntry(str(path.resolve()), condition.strip() or cond, mu,
                     manoeuvre.strip() or meta.get("manoeuvre", meta.get("description", "")),
                     group.strip())


def read_plan(path, exclude=()) -> Plan:
    """The plan at ``path`` (folder, CSV or TOML manifest); folders under
    ``exclude`` (the campaign's own output) are never scanned.

    Parameters
    ----------
    path : path-like
        A folder of records (``*.csv``) or a manifest (``.csv`` or ``.toml``: record,
        flight condition, manoeuvre, group).
    exclude : iterable of path-like
        Folders never scanned (the campaign's own output).
    """
    p = Path(path)
    if not p.exists():
        raise InputError(f"{p}: no such folder or manifest")
    if p.is_dir():
        skip = [Path(x).resolve() for x in exclude]
        files = sorted(f for f in p.rglob("*.csv") if f.is_file() and not any(
            s == f.resolve() or s in f.resolve().parents for s in skip))
        if not files:
            raise InputError(f"{p}: no records (*.csv) in this folder")
        return Plan(str(p), tuple(_entry(f) for f in files))
    if p.suffix.lower() == ".toml":
        return _read_toml(p)
    if p.suffix.lower() == ".csv":
        return _read_csv(p)
    raise InputError(f"{p}: a plan is a folder of records or a manifest "
                     f"({' or '.join(MANIFEST_SUFFIXES)})")


def _resolve(base: Path, rel: str, where: str) -> Path:
    if not rel or not rel.strip():
        raise InputError(f"{where}: empty record path")
    f = Path(rel.strip())
    f = f if f.is_absolute() else base / f
    if not f.is_file():
        raise InputError(f"{where}: record {rel.strip()} not found ({f})")
    return f


def _read_csv(p: Path) -> Plan:
    from ..fileio import read_input_text
    text = read_input_text(p, "manifest", "manifest", "utf-8-sig")
    try:
        rows = list(csv.DictReader(io.StringIO(text)))
    except csv.Error as exc:
        raise InputError(f"{p}: not a CSV manifest ({exc})") from None
    if not rows or "record" not in (rows[0].keys() if rows else ()):
        raise InputError(f"{p}: a CSV manifest needs a header row with a 'record' "
                         "column (and optionally condition, manoeuvre, group)")
    out = []
    for i, r in enumerate(rows, start=2):
        f = _resolve(p.parent, r.get("record") or "", f"{p}: line {i}")
        out.append(_entry(f, r.get("condition") or "", r.get("manoeuvre") or "",
                          r.get("group") or ""))
    return Plan(str(p), tuple(out))


def _read_toml(p: Path) -> Plan:
    try:
        import tomllib
    except ModuleNotFoundError:                       # Python 3.10
        raise InputError(f"{p}: TOML plans need Python 3.11 or later; "
                         "use a CSV manifest") from None
    from ..fileio import check_nesting, read_input_text
    text = read_input_text(p, "manifest", "manifest", "utf-8-sig")
    try:
        doc = check_nesting(tomllib.loads(text), str(p))
    except RecursionError:
        raise InputError(f"{p}: nested too deeply") from None
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{p}: cannot read the manifest ({exc})") from None
    recs = doc.get("record")
    if not isinstance(recs, list) or not recs:
        raise InputError(f"{p}: a TOML manifest needs [[record]] tables with a path")
    out = []
    for i, r in enumerate(recs, start=1):
        if not isinstance(r, dict) or "path" not in r:
            raise InputError(f"{p}: [[record]] number {i} has no path")
        f = _resolve(p.parent, str(r["path"]), f"{p}: [[record]] number {i}")
        out.append(_entry(f, str(r.get("condition", "")), str(r.get("manoeuvre", "")),
                          str(r.get("group", ""))))
    settings = doc.get("settings", {})
    if not isinstance(settings, dict):
        raise InputError(f"{p}: [settings] must be a table")
    bad = sorted(set(settings) - set(SETTINGS_KEYS))
    if bad:
        raise InputError(f"{p}: unknown setting {bad[0]!r} (known: "
                         f"{', '.join(SETTINGS_KEYS)})")
    return Plan(str(p), tuple(out), dict(settings))


def write_plan_csv(entries, path, base=None) -> str:
    """A CSV manifest of ``entries`` (paths relative to ``base``) as text."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["record", "condition", "manoeuvre", "group"])
    for e in entries:
        rel = Path(e.path)
        if base is not None:
            try:
                rel = rel.resolve().relative_to(Path(base).resolve())
            except ValueError:
                pass
        w.writerow([str(rel), e.condition, e.manoeuvre, e.group])
    return buf.getvalue()


__all__ = ["MANIFEST_SUFFIXES", "SETTINGS_KEYS", "PlanEntry", "Plan", "read_plan",
           "write_plan_csv"]
