"""The model's trim inflow against NASA's laser-velocimeter inflow surveys.

Run:  python examples/nasa_inflow.py [DATA_DIR] [--out DIR]

Reads the surveys at mu 0.15, 0.23 and 0.35 (DATA_DIR, default the copy the package
ships, ``inflowsim/data/nasa_lv_inflow``: NASA public data, source and licence named
there) as they are,
prints every defect found and what was done about it, fits Eq. (6) to each survey,
computes the model's trim inflow at the surveys' run conditions (momentum with
``V ~ mu`` and with the mass-flow speed, the skewed-wake gradient, Table 3's
Glauert Eq. (19)), prints the tables of ``docs/measured-inflow.md`` and writes the
figures ``nasa-radial-cuts.png``, ``nasa-harmonics.png``, ``nasa-disc.png`` into
DIR (default ``inflowsim-nasa-inflow`` in the system's temporary folder: nothing is
written into the repository unless asked, e.g. ``--out docs/figures`` to renew the
committed figures).  A missing DATA_DIR: one line on stderr, exit 2.
"""
import argparse
import sys
import tempfile
from pathlib import Path

from inflowsim.data.nasa_lv import DATA_DIR, read_surveys
from inflowsim.errors import InputError

DEFAULT_DATA = DATA_DIR
DEFAULT_OUT = Path(tempfile.gettempdir()) / "inflowsim-nasa-inflow"
FIGURES = ("nasa-radial-cuts.png", "nasa-harmonics.png", "nasa-disc.png")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("data", nargs="?", default=str(DEFAULT_DATA),
                    help="folder of the surveys (default the package's copy, "
                         f"{DATA_DIR})")
    ap.add_argument("--out", default=str(DEFAULT_OUT),
                    help=f"folder for the PNG figures (default {DEFAULT_OUT}; "
                         "--out docs/figures renews the committed ones)")
    args = ap.parse_args(argv)
    try:
        surveys = read_surveys(args.data)
        out = Path(args.out)
        if out.exists() and not out.is_dir():
            raise InputError(f"{out}: exists and is not a folder")
        for name in FIGURES:
            if (out / name).exists() and not (out / name).is_file():
                raise InputError(f"{out / name}: exists and is not a regular file")
    except InputError as exc:
        print(f"nasa_inflow: {exc}", file=sys.stderr)
        return 2
    # the fit and the plots (matplotlib) only once the input is known good
    from inflowsim.identify.inflow_survey import measured_inflow_response
    from inflowsim.report.measured_inflow import (comparison_table, conditions_table,
                                                  disc_plot, fit_table, harmonics_plot,
                                                  radial_cuts_plot)
    print("## Defects found\n")
    for s in surveys:
        for d in s.defects:
            print(f"- {d}")
    cmp = measured_inflow_response(surveys)
    print("\n## Run conditions as used\n")
    print(conditions_table(cmp))
    print("## Eq. (6) fitted, and the model's trim inflow (discrepancy in sigmas)\n")
    print(comparison_table(cmp))
    print("## The fits\n")
    print(fit_table(cmp))
    try:
        out.mkdir(parents=True, exist_ok=True)
        radial_cuts_plot(cmp, out / FIGURES[0])
        harmonics_plot(cmp, out / FIGURES[1])
        disc_plot(cmp, out / FIGURES[2])
    except OSError as exc:
        print(f"nasa_inflow: {out}: cannot write the figures ({exc.strerror})",
              file=sys.stderr)
        return 2
    print("figures: " + ", ".join(str(out / f) for f in FIGURES))
    return 0


if __name__ == "__main__":
    sys.exit(main())
