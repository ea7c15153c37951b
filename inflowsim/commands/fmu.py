"""``inflowsim fmu build [--out FILE.fmu] [--model FILE|STRUCTURE | --schedule FILE]
[--fmi-version {2,3}]``: the native FMI co-simulation FMU (FMI 2.0 by default, or
FMI 3.0).

A thin layer over :func:`inflowsim.fmu.build_fmu`; the FMU runs without Python.
``--model fit.json`` builds an FMU for the fit's structure with its values as start
values (so ``fmpy.simulate_fmu(fmu)`` needs none); without it, the presets' FMU, to
which :func:`inflowsim.fmu.start_values` of a fit applies.  ``--schedule
schedule.json`` (``inflowsim campaign`` writes one) builds an FMU whose parameters
follow the schedule at the ``mu`` of every step.
"""
from __future__ import annotations

import argparse

from ..errors import InputError
from ._common import (add_effect_arguments, add_progress_options, print_json, progress,
                      read_parameter_file)

HELP = "build the FMI 2.0 (or 3.0) co-simulation FMU (native C, no Python inside)"


def add_arguments(p):
    sub = p.add_subparsers(dest="action", metavar="ACTION")
    b = sub.add_parser("build", help="compile with the system C compiler and pack the FMU",
                       description="Compile the C model with the system C compiler "
                       "(cc/gcc or $CC) and pack modelDescription.xml, "
                       "binaries/linux64 (FMI 2.0) or binaries/x86_64-linux (FMI 3.0), "
                       "sources/ and documentation/.")
    b.add_argument("--out", "-o", default="inflowsim.fmu", metavar="FILE.fmu",
                   help="FMU file to write (default inflowsim.fmu)")
    b.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                   help="FMI 2.0 (default) or 3.0 co-simulation; the same model")
    b.add_argument("--platform", action="append", default=[], choices=("win64",),
                   help="also cross-compile this platform's binary (win64: needs "
                        "mingw-w64's x86_64-w64-mingw32-gcc); repeatable")
    b.add_argument("--model", "-m", metavar="FILE|STRUCTURE",
                   help="what the FMU runs: a parameter file (identify --out, the "
                        "ladder's; its parameters and constants become the start values) "
                        "or a structure such as glauert+flap-inertia (default: the three "
                        "presets, selected by the integer structure)")
    b.add_argument("--schedule", metavar="FILE",
                   help="a parameter schedule (inflowsim campaign's schedule.json): the "
                        "FMU runs its structure with the parameters at the mu of every "
                        "step")
    add_effect_arguments(b)
    add_progress_options(b, default=argparse.SUPPRESS)
    b.add_argument("--force", action="store_true", help="replace an existing file")
    b.add_argument("--json", action="store_true",
                   help="print {\"fmu\", \"guid\", \"model_identifier\"} on stdout")


def run(args) -> int:
    if getattr(args, "action", None) != "build":
        raise InputError("fmu: choose an action: build")
    from ..fmu import MODEL_IDENTIFIER, build_fmu, description_for
    from ..fmu.generate import guid
    if args.schedule and args.model:
        raise InputError("--model and --schedule: the schedule names its structure; "
                         "give one of them")
    if args.schedule:
        from ..model.schedule import read_schedule
        d = description_for(read_schedule(args.schedule))
    else:
        d = description_for(_model(args.model))
    path = build_fmu(args.out, overwrite=args.force, fmi_version=args.fmi_version,
                     platforms=tuple(args.platform), say=progress, model=d,
                     protect=tuple(f for f in (args.model, args.schedule) if f))
    if args.json:
        print_json({"fmu": str(path), "guid": guid(d), "model_identifier": MODEL_IDENTIFIER,
                    "fmi_version": f"{args.fmi_version}.0",
                    "structures": list(d.structures),
                    "scheduled": list(d.scheduled)})
    else:
        print(f"wrote {path} (FMI {args.fmi_version}.0 co-simulation of "
              f"{', '.join(d.structures)}, "
              + (f"parameters following mu: {', '.join(d.scheduled)}; " if d.scheduled
                 else "")
              + f"{'GUID' if args.fmi_version == 2 else 'instantiation token'} {guid(d)})")
    return 0


def _model(text):
    """A parameter file if ``text`` names one (or looks like a file name), else a
    structure."""
    from pathlib import Path
    if text is None:
        return None
    if Path(text).is_file() or text.endswith(".json"):
        return read_parameter_file(text)
    return text
