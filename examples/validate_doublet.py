"""Validate two models on a virtual Puma doublet record (the Python API of ``validate``).

Run:  python examples/validate_doublet.py [OUT_DIR]

Makes a virtual record (glauert truth with the paper's Table 3 values, flap noise
1e-4 rad), writes it as CSV, reads it back as any flight record would be read,
replays its measured inputs through the ``basic`` (Table 1) and ``glauert``
(Table 3) presets, prints the fit figures and writes a report with the paper-like
plots into OUT_DIR (default ``inflowsim-validate-doublet`` in the system's temporary
folder).
"""
import sys
import tempfile
from pathlib import Path

from inflowsim import build_model, preset_parameters
from inflowsim.report.validation import format_table, validation_report
from inflowsim.data.record import read_record, write_record
from inflowsim.diagnose.validation import validate
from inflowsim.flighttest.virtual import VirtualTest, virtual_record


def main(out_dir=None):
    # default: a temporary folder, never the repository (issue #39)
    out = Path(out_dir or Path(tempfile.gettempdir()) / "inflowsim-validate-doublet")
    out.mkdir(parents=True, exist_ok=True)
    csv = out / "doublet.csv"
    if not csv.exists():
        write_record(virtual_record(VirtualTest(structure="glauert", seed=1)), csv)
    rec = read_record(csv)
    results = []
    for structure in ("basic", "glauert"):
        model = build_model(structure, preset_parameters(structure, rec.constants, "paper"),
                            rec.constants)
        res = validate(rec, model)              # default band 0.2256-1.58 Hz
        print(format_table(res), end="\n\n")
        results.append(res)
    path = validation_report(results).write(out, protect=[csv])
    print(f"report: {path}")


if __name__ == "__main__":
    main(*sys.argv[1:2])
