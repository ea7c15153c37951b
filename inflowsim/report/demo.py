"""The whole story on a virtual Puma record with a hidden effect (``inflowsim demo``).

1. A virtual Puma record is made (a longitudinal then a lateral cyclic doublet;
   truth: the paper's Glauert-augmented model with its Table 3 values, i.e.
   ``basic`` plus three effects the user is not told about; flap noise 1e-4 rad,
   seed 0; continuous-time) and written to ``DIR/record.csv``.
2. Compare: the ``basic`` model (the paper's Table 1 structure), fitted to the
   record, is replayed against the measured flap.
3. See where it fails and which effect is missing: ``diagnose``.
4. Add it, refit, and repeat until nothing is accepted: the ladder.
5. The final structure is validated, and the hidden truth is revealed beside the
   estimates with their bounds.
"""
from __future__ import annotations

from pathlib import Path

from ..data.record import format_record, parse_record
from ..diagnose.search import ladder
from ..diagnose.validation import validate
from ..flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
from ..model.presets import preset_parameters
from .document import Report, check_report_folder
from .ladder import (CANDIDATE_HEADER, FAILURE_HEADER, candidate_rows, failure_rows,
                     ladder_report)
from .units import parameter_label, parameter_value
from .validation import FIT_HEADER, NO_RESPONSE, NO_RESPONSE_TEXT, fit_table_rows


TRUTH = "glauert"


START = "basic"


def demo_record(seed=0):
    """The embedded default: a virtual Puma record, a longitudinal then a lateral
    cyclic doublet (both axes excited, so every Glauert term is determined),
    hidden glauert truth, continuous-time as flight data are."""
    return virtual_record(VirtualTest(structure=TRUTH, seed=seed, manoeuvres=(
        Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0)),
        description="longitudinal then lateral cyclic doublet, 100 kt"))


FIT_NOTE = ("RMS error and TIC: the replay of the measured inputs from rest in trim, "
            "over the whole record; fit [%]: 100 (1 - |Z - Y| / |Z|) over the band's "
            "transforms, the figure identify, the ladder and the plots report; |H| and "
            "phase error: RMS over the points of the conditioned responses (1.1) with "
            "coherence >= 0.6.")


def run_demo(out_dir, seed=0, say=None):
    """Write the demo into ``out_dir``; return ``(index.html path, summary dict)``."""
    from .model_frf import model_frf_section
    from .plots import time_response_plot
    progress, say = say, say or (lambda m: None)
    out = Path(out_dir)
    check_report_folder(out, ("record.csv",))     # refuse before any work
    text = format_record(demo_record(seed))
    rec = parse_record(text, str(out / "record.csv"))     # as a user would read it
    say("demo: fitting basic, diagnosing, adding effects ...")
    lad = ladder([rec], START, progress=progress)
    first, last = lad.rungs[0], lad.rungs[-1]
    v_first = validate(rec, first.fit.model)
    v_last = validate(rec, last.fit.model)
    truth = preset_parameters(TRUTH, rec.constants, "paper")

    rep = Report("inflowsim demo: find the missing physics",
                 "virtual Puma doublets at 100 kt with a hidden effect; flap noise "
                 "0.0057 deg (1e-4 rad)")
    rep.paragraph("A record of a longitudinal then a lateral cyclic doublet was made from a "
                  "truth the user is not told. We start, as the paper did, from the basic momentum-inflow "
                  "model (its Table 1 structure), fit it, see where it fails, let the tool "
                  "name the missing effect, add it, refit, and repeat until nothing "
                  "is accepted.")
    rep.heading("1. Compare: the basic model, fitted, against the measurements")
    rows = fit_table_rows(v_first)
    rep.table(rows, FIT_HEADER)
    rep.paragraph(FIT_NOTE + (f" {NO_RESPONSE}: {NO_RESPONSE_TEXT}."
                              if any(NO_RESPONSE in r for r in rows) else ""))
    rep.figure(time_response_plot([v_first, v_last], show_inputs=True, window="manoeuvre"),
               "time",
               "Time-domain reconstruction over the manoeuvres: measured flap, the basic "
               "model and the final structure (the paper's Figures 1, 3, 5), and the "
               "pilot's controls below.")
    model_frf_section(rep, [v_first, v_last], [f"{first.structure.name} (first)",
                                               f"{last.structure.name} (last)"],
                      fits={first.structure.name: first.fit, last.structure.name: last.fit},
                      heading="1.1 Frequency responses: where the first structure fails")
    d0 = first.diagnosis
    rep.heading("2. Where it fails")
    rep.table(failure_rows(d0), FAILURE_HEADER)
    rep.paragraph("Where model and measurement part: each range of band frequencies "
                  "whose residual stands above the noise floor, whether magnitude or "
                  "phase carries most of the error there, and the RMS over the range "
                  "of the magnitude error [dB] and of the phase error [deg].")
    rep.heading("3. Which effect is missing")
    rep.table(candidate_rows(d0), CANDIDATE_HEADER)
    ladder_report(lad, rep, heading="4. Add it, refit, repeat: the ladder of structures")
    rep.heading("5. The final structure against the measurements")
    rows = fit_table_rows(v_last)
    rep.table(rows, FIT_HEADER)
    if any(NO_RESPONSE in r for r in rows):
        rep.paragraph(f"{NO_RESPONSE}: {NO_RESPONSE_TEXT}.")
    rep.heading("6. The hidden truth revealed")
    rows = []
    for n, tv in truth.items():
        est = last.fit.parameters.get(n)
        sg = last.fit.sigma.get(n)
        z = (est - tv) / sg if (est is not None and sg) else None
        rows.append([parameter_label(n), parameter_value(n, tv), parameter_value(n, est),
                     parameter_value(n, sg), z])
    rep.table(rows, ["parameter [unit]", "truth", "estimate", "1-sigma",
                     "(estimate - truth)/sigma [-]"])
    rep.paragraph(f"The truth was the paper's Glauert-augmented structure ({TRUTH}: basic + "
                  "separate-time-constants + glauert + azimuth-bias) with its Table 3 "
                  f"values. The ladder ended at {last.structure.name}.")
    rep.attach("record.csv", text, "the virtual record (record-format CSV)")
    path = rep.write(out)
    summary = {"report": str(path), "truth": TRUTH, "start": START,
               "ladder": [{"structure": r.structure.name, "added": r.added,
                           "atoms": list(r.atoms),
                           "cost": r.fit.cost,
                           "fit_percent": {c: v["fit_percent"] for c, v in r.fit.fit.items()}}
                          for r in lad.rungs],
               "final": last.structure.name,
               "validation": {"start": v_first.to_json()["channels"],
                              "final": v_last.to_json()["channels"]},
               "missing_effects_found": [r.added for r in lad.rungs if r.added]}
    return path, summary, lad


__all__ = ["TRUTH", "START", "demo_record", "FIT_NOTE", "run_demo"]
