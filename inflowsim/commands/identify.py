"""``inflowsim identify``: frequency-domain output-error fit with 1-sigma bounds.

Prints the parameter table (or with ``--json`` the ``interface.md`` document);
``--out FIT.json`` writes that document, a parameter file that ``simulate``,
``validate`` and the FMU read as it is; ``--report DIR`` writes the tables
(Markdown, HTML), the frequency-domain fit and the time-domain reconstruction
plots.  Progress goes to stderr.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import InputError
from ..fileio import check_output, safe_write_text
from ..model.paramfile import write_json
from ..model.structure import Structure
from ._common import add_record_arguments, print_json, progress, read_records

HELP = "estimate a structure's parameters with 1-sigma bounds (frequency-domain output error)"


def add_arguments(p):
    p.add_argument("records", nargs="+", metavar="RECORD",
                   help="flight-test record(s) (CSV); several are fitted together")
    p.add_argument("--model", "-m", required=True,
                   help="structure: basic, empirical, glauert, then +effect terms")
    p.add_argument("--add", action="append", default=[], metavar="EFFECT",
                   help="add an effect to the structure (repeatable)")
    p.add_argument("--band", nargs=2, type=float, metavar=("F1", "F2"),
                   help="frequency band [Hz] (default 0.2256 1.58, snapped to the "
                        "record's grid 1/T)")
    p.add_argument("--fix", action="append", default=[], metavar="NAME[=VALUE]",
                   help="hold a parameter fixed (at VALUE, or its theory value)")
    p.add_argument("--tie", action="append", default=[], metavar="A=B[=C]",
                   help="estimate one value for several parameters")
    p.add_argument("--start", metavar="FILE",
                   help="parameter file with starting values")
    add_record_arguments(p)
    p.add_argument("--out", metavar="FIT.json", help="write the fit (a parameter file)")
    p.add_argument("--report", metavar="DIR", help="write tables and plots into DIR")
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")
    p.add_argument("--force", action="store_true", help="overwrite existing outputs")


def parse_fix(items) -> dict:
    out = {}
    for it in items:
        name, _, val = it.partition("=")
        name = name.strip()
        if not name:
            raise InputError(f"--fix {it!r}: give NAME or NAME=VALUE")
        if val:
            try:
                out[name] = float(val)
            except ValueError:
                raise InputError(f"--fix {it!r}: {val!r} is not a number") from None
        else:
            out[name] = None
    return out


def parse_ties(items) -> list:
    ties = []
    for it in items:
        names = [n.strip() for n in it.split("=")]
        if len(names) < 2 or not all(names):
            raise InputError(f"--tie {it!r}: give two or more names as A=B")
        ties.append(tuple(names))
    return ties


def structure_of(args) -> Structure:
    s = Structure.parse(args.model)
    for e in args.add:
        s = s.with_effect(e)
    return s


def check_outputs(out, inputs, force):
    """Refuse before any work: an existing ``out`` without ``force``, or an input."""
    if out is not None:
        check_output(out, force, inputs)


def write_report(result, folder, force=False, protect=()):
    """Tables (``table.md``, ``table.html``), plots (``fit_frequency.png``,
    ``fit_time.png``) and ``fit.json`` into ``folder`` (created)."""
    import json

    from ..report.fit_plots import fit_plot, reconstruction_plot
    from ..identify.tables import html_table, markdown_table
    d = Path(folder)
    if d.exists() and not d.is_dir():
        raise InputError(f"{d}: exists and is not a folder")
    d.mkdir(parents=True, exist_ok=True)
    names = ["table.md", "table.html", "fit.json"]
    names += [f"fit_frequency{i or ''}.png" for i in range(len(result.data))]
    names += [f"fit_time{i or ''}.png" for i in range(len(result.data))]
    if not force:
        for n in names:
            if (d / n).exists():
                raise InputError(f"{d / n}: exists; choose another folder or pass --force")
    safe_write_text(d / "table.md", markdown_table(result), True, protect)
    safe_write_text(d / "table.html", "<!doctype html><meta charset='utf-8'>"
                    "<title>identify</title>\n" + html_table(result)
                    + "".join(f"<img src='fit_frequency{i or ''}.png'><img src='fit_time"
                              f"{i or ''}.png'>\n" for i in range(len(result.data))),
                    True, protect)
    safe_write_text(d / "fit.json", json.dumps(result.to_json(), indent=2) + "\n", True,
                    protect)
    for i in range(len(result.data)):
        fit_plot(result, d / f"fit_frequency{i or ''}.png", i)
        reconstruction_plot(result, d / f"fit_time{i or ''}.png", i)
    return d


def run(args) -> int:
    from ..identify import DEFAULT_BAND, identify
    from ..identify.tables import markdown_table
    from ..model.paramfile import read_parameters
    s = structure_of(args)
    check_outputs(args.out, args.records, args.force)
    recs = read_records(args.records, args)
    start = None
    if args.start:
        ps = read_parameters(args.start)
        start = {n: v for n, v in ps.parameters.items() if n in s.parameters}
    band = tuple(args.band) if args.band else DEFAULT_BAND
    result = identify(recs, s, band_hz=band, start=start, fixed=parse_fix(args.fix),
                      ties=parse_ties(args.tie), progress=progress, hold=args.hold)
    for w in result.warnings:
        progress(f"warning: {w}")
    doc = result.to_json()
    if args.out:
        write_json(doc, args.out, overwrite=args.force, protect=args.records)
        progress(f"wrote {args.out}")
    if args.report:
        write_report(result, args.report, args.force, protect=args.records)
        progress(f"wrote {args.report}/table.md, table.html and plots")
    if args.json:
        print_json(doc)
    else:
        print(markdown_table(result), end="")
    return 0
