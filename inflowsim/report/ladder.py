"""Tables, plots and HTML for a diagnosis and a ladder of structures.

The ladder table is the paper's Tables 1 -> 2 -> 3 side by side: one column per
structure tried, a row per parameter (estimate and 1-sigma bound), then cost and
per-channel fit.  :func:`ladder_plot` shows the error falling rung by rung.
"""
from __future__ import annotations

import numpy as np

from ..model.equations import FLAP
from .document import Report


def _noise_ratio(fit):
    """Per flap channel: residual power over the band relative to the last rung's
    (a proxy of the noise floor is the final fit; absolute values are shown too)."""
    return np.array([[abs(S[i, i]) for i in range(3)] for S in fit.S]).mean(axis=0)


def rung_label(rung) -> str:
    """A rung's short name: the structure on the first rung, else ``+`` and what it
    added, an effect's part named by its parameters (``+glauert (k0p, kc, ks)``, then
    ``+glauert (c1, c2, c3, c4)``: the two parts of one effect added on two rungs
    read apart).

    Parameters
    ----------
    rung : Rung
        A :class:`~inflowsim.diagnose.search.Rung`.
    """
    if rung.added is None:
        return rung.structure.name
    return "+" + " + ".join(getattr(rung, "atoms", ()) or rung.added.split("+"))


def held_parameters(fit, structure=None) -> tuple:
    """The parameters of the effects of ``structure`` (default ``fit``'s) that ``fit``
    holds fixed (not estimated), e.g. one part of an effect not added yet, at its
    neutral value.

    Parameters
    ----------
    fit : FitResult
    structure : Structure, optional
    """
    from ..model.effects import CATALOGUE
    fixed = set(getattr(fit, "fixed", ()) or ())
    effects = (structure or fit.structure).effects
    return tuple(n for e in effects if e in CATALOGUE for n in CATALOGUE[e].parameters
                 if n in fixed)


def column_label(rung) -> str:
    """A ladder column's heading: the structure and the parameters it holds fixed
    with their values (``glauert, c1-c4 held at 0``: an effect whose other part is
    not added yet shows as such).

    Parameters
    ----------
    rung : Rung
    """
    held = (held_parameters(rung.fit, rung.structure)
            if getattr(rung.fit, "fixed", ()) else ())
    if not held:
        return rung.structure.name
    vals = {rung.fit.parameters[n] for n in held}
    at = f" at {vals.pop():g}" if len(vals) == 1 else ""
    return f"{rung.structure.name} ({', '.join(held)} held{at})"


def ladder_rows(ladder) -> tuple[list, list]:
    """``(header, rows)``: parameters with bounds side by side (angles in degrees,
    every row naming its unit), cost, fit per channel, and the residual power per
    channel over the noise floor (the ladder plot's quantity; without residual
    analyses, the residual covariance's diagonal [rad^2])."""
    from .units import parameter_label, parameter_value
    rungs = ladder.rungs
    header = ["quantity"] + [column_label(r) for r in rungs]
    names: list[str] = []
    for r in rungs:
        names += [n for n in r.fit.parameters if n not in names]
    rows = []
    for n in names:
        row = [parameter_label(n)]
        for r in rungs:
            if n in r.fit.parameters:
                v = parameter_value(n, r.fit.parameters[n])
                s = parameter_value(n, r.fit.sigma.get(n))
                fixed = n in getattr(r.fit, "fixed", ())
                why = "fixed" if fixed else "not determined"
                cell = f"{v:.4g} ({s:.2g})" if s is not None else f"{v:.4g} ({why})"
                if not fixed and getattr(r.fit, "conditional", None):
                    cell += CONDITIONAL_MARK
                row.append(cell)
            else:
                row.append("")
        rows.append(row)
    rows.append([COST_LABEL] + [f"{r.fit.cost:.1f}" for r in rungs])
    rows.append(["added"] + ["" if r.added is None else rung_label(r)[1:] for r in rungs])
    for ch in FLAP:
        rows.append([f"{ch} fit [%]"] + [f"{r.fit.fit[ch]['fit_percent']:.2f}" for r in rungs])
    ratios = [floor_ratios(r) for r in rungs]
    if all(q is not None for q in ratios):
        for i, ch in enumerate(FLAP):
            rows.append([f"{ch} residual power / noise floor [-]"] +
                        [f"{q[i]:.3g}" for q in ratios])
    else:
        for i, ch in enumerate(FLAP):
            rows.append([f"{ch} residual power [rad^2]"] +
                        [f"{_noise_ratio(r.fit)[i]:.3g}" for r in rungs])
    return header, rows


#: Appended to an estimate conditional on an incomplete structure (the fit's residual
#: keeps structured excess over the floor, :mod:`inflowsim.diagnose.conditional`).
CONDITIONAL_MARK = " [conditional]"


def conditional_lines(ladder) -> list:
    """One line per rung whose estimates are conditional, with the reason."""
    return [f"{CONDITIONAL_MARK.strip()} {r.structure.name}: every estimate is "
            f"{r.fit.conditional}" for r in ladder.rungs
            if getattr(r.fit, "conditional", None)]


#: The cost's row and axis label: (12) is a log-likelihood, a pure number (its
#: log-determinant takes S in rad^2: differences between rungs are what count).
COST_LABEL = "cost J (Eq. 12) [-]"


def ladder_markdown(ladder) -> str:
    """The ladder's table (:func:`ladder_rows`) in Markdown, then what the records
    determine, the removed atoms and the verdict.

    Parameters
    ----------
    ladder : Ladder
    """
    # not pandas' to_markdown: ``inflowsim ladder`` prints this, and pandas' import
    # costs 1.6 s (measured after NumPy, under the shared machine's load)
    header, rows = ladder_rows(ladder)
    out = ["| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    out += conditional_lines(ladder)
    out += identifiability_lines(ladder.identifiability, ladder.final.structure.name)
    last = ladder.final.diagnosis
    if (ladder.verdict is not None and ladder.verdict.status in
            ("unexplained", "partly-explained") and last is not None
            and last.missing_terms is not None):
        out.append("where a term is missing (score test of every single-entry addition):")
        out += [f"  {line}" for line in last.missing_terms.describe()]
    for r in ladder.rungs[1:]:
        told = told_apart_line(" + ".join(r.atoms), getattr(r, "indistinguishable", ()))
        if told:
            out.append(told)
    for atom, lp in getattr(ladder, "removed", ()):
        out.append(f"removed {atom}: not significant beside the effects added after it "
                   f"(p = {10 ** lp:.2g})")
    if ladder.verdict is not None:
        out.append(ladder.verdict.describe())
    return "\n".join(out)


def identifiability_lines(ident, name) -> list:
    """What the records do not determine of ``name``, rendered from the data."""
    if ident is None:
        return []
    from ..identify.identifiability import describe
    lines = describe(ident)
    if not lines:
        return [f"every parameter of {name} is determined by the records"]
    return [f"what the records determine of {name}:"] + [f"  - {x}" for x in lines]


def floor_ratios(rung):
    """Per flap channel: the rung's mean residual power over the noise floor (1 is the
    floor: nothing left but noise), over its records; ``None`` without analyses."""
    if not rung.analyses:
        return None
    return np.mean([ra.ratio.mean(axis=1) for ra in rung.analyses], axis=0)


def ladder_plot(ladder, path=None):
    """Cost, and per-channel residual power over the noise floor, rung by rung."""
    from .plots import new_figure, save_png
    fig, ax2 = new_figure(2, 1, size=(8.0, 6.5), sharex=True)
    axes = ax2[:, 0]
    x = np.arange(len(ladder.rungs))
    labels = [rung_label(r) for r in ladder.rungs]
    axes[0].plot(x, [r.fit.cost for r in ladder.rungs], "o-", color="k")
    axes[0].set_ylabel(COST_LABEL)
    axes[0].set_title("Add the missing effect, watch the error fall")
    ratios = [floor_ratios(r) for r in ladder.rungs]
    if all(q is not None for q in ratios):
        pw = np.array(ratios)
        for i, ch in enumerate(FLAP):
            axes[1].semilogy(x, pw[:, i], "o-", label=ch)
        axes[1].axhline(1.0, color="k", ls="--", lw=1.2, label="noise floor")
        axes[1].set_ylabel("residual power / noise floor [-]")
    else:                                   # rungs fitted without residual analyses
        pw = np.array([_noise_ratio(r.fit) for r in ladder.rungs])
        for i, ch in enumerate(FLAP):
            axes[1].semilogy(x, pw[:, i] / pw[-1, i], "o-", label=ch)
        axes[1].axhline(1.0, color="grey", ls=":", lw=1)
        axes[1].set_ylabel("residual power / final rung's [-]")
    axes[1].set_xticks(x, labels, rotation=15)
    axes[1].legend()
    axes[1].grid(True, which="both", alpha=0.3)
    axes[0].grid(True, alpha=0.3)
    if path:
        save_png(fig, path)
    return fig


def worse_channels(ladder, tolerance=0.5):
    """Comments on steps that made a channel's fit worse by more than ``tolerance``
    percentage points while the cost fell: the effect traded one channel for others."""
    out = []
    rungs = ladder.rungs
    for prev, r in zip(rungs, rungs[1:]):
        for ch in FLAP:
            a, b = prev.fit.fit[ch]["fit_percent"], r.fit.fit[ch]["fit_percent"]
            if a is not None and b is not None and b < a - tolerance:
                out.append(f"Adding {rung_label(r)[1:]} made {ch} worse (fit {a:.1f} % -> "
                           f"{b:.1f} %) while the cost fell {prev.fit.cost - r.fit.cost:.1f}:"
                           f" the effect trades {ch} for the other channels; look at "
                           f"{ch}'s residual before trusting its new parameters.")
    return out


def candidate_plot(diagnosis, path=None):
    """Cost reduction of every candidate effect, accepted ones filled (the tests that
    decide are in the decision's table, :mod:`inflowsim.diagnose.rule`)."""
    from .plots import new_figure, save_png
    cands = list(diagnosis.candidates)
    fig, ax = new_figure(1, 1, size=(8.0, 0.45 * max(len(cands), 3) + 1.5))
    a = ax[0, 0]
    y = np.arange(len(cands))[::-1]
    red = [max(c.cost_reduction, 1e-3) if np.isfinite(c.cost_reduction) else 1e-3
           for c in cands]
    colors = ["C2" if c.accepted else "0.6" for c in cands]
    a.barh(y, red, color=colors)
    a.set_yticks(y, [c.atom for c in cands])
    a.set_xscale("log")
    a.set_xlabel("cost reduction when added [-] (green: accepted)")
    a.grid(True, axis="x", which="both", alpha=0.3)
    fig.suptitle(f"Candidate effects on {diagnosis.structure.name}")
    if path:
        save_png(fig, path)
    return fig


FAILURE_HEADER = ["kind", "subject", "finding"]


def failure_rows(diagnosis):
    """Rows ``kind, subject, finding`` of a diagnosis's failures, each finding as
    :func:`failure_message` words it."""
    return [[f.kind, f.subject, failure_message(f, diagnosis.analyses)]
            for f in diagnosis.failures]


def failure_message(failure, analyses=()) -> str:
    """A failure in words.  A ``spectrum`` failure is worded from its data: per
    frequency range where model and measurement part, whether magnitude or phase
    carries most of the error power, and the RMS of the magnitude error [dB] and of
    the phase error [deg] over the range's frequencies (an average of signed phase
    errors cancels to 0 deg where the model leads and lags in turn); a range of one
    transform frequency is one frequency.  Other kinds: their message."""
    if failure.kind != "spectrum" or "segments" not in failure.detail:
        return failure.message
    ch = failure.subject
    ra = _analysis_of(failure, analyses)
    if ch not in FLAP or ra is None:
        return failure.message
    c = FLAP.index(ch)
    z, y = ra.measured[c], ra.predicted[c]
    parts = []
    for seg in failure.detail["segments"]:
        f1, f2 = seg["f1_hz"], seg["f2_hz"]
        sel = (ra.f_hz >= f1) & (ra.f_hz <= f2) & (np.abs(z) > 0) & (np.abs(y) > 0)
        n = int(sel.sum())
        where = (f"{f1:.3g} Hz" if n <= 1 or f1 == f2 else
                 f"{f1:.3g}-{f2:.3g} Hz ({n} frequencies)")
        if n == 0:
            parts.append(f"{where} (mostly {seg['mostly']})")
            continue
        mag = 20.0 * np.log10(np.abs(z[sel]) / np.abs(y[sel]))
        ph = np.degrees(np.angle(z[sel] * np.conj(y[sel])))
        parts.append(f"{where}, mostly {seg['mostly']}: magnitude error "
                     f"{_rms(mag):.2f} dB rms, phase error {_rms(ph):.1f} deg rms")
    excess = failure.detail.get("excess_power")
    tail = "" if excess is None else \
        f"; in-band residual power {excess:.3g} times the noise floor"
    return f"{ch}: model and measurement part at " + "; ".join(parts) + tail


def _rms(v) -> float:
    return float(np.sqrt(np.mean(np.square(v))))


def _analysis_of(failure, analyses):
    """The residual analysis a spectrum failure was found in: the one whose channel
    carries the failure's mean excess power (one analysis per record)."""
    c = FLAP.index(failure.subject) if failure.subject in FLAP else None
    want = failure.detail.get("excess_power")
    if c is None or want is None:
        return None
    for ra in analyses or ():
        if np.isclose(float(ra.ratio[c].mean()), want, rtol=1e-12, atol=0.0):
            return ra
    return None


def candidate_rows(diagnosis):
    return [[c.atom, c.cost_reduction, c.dof, c.log10_p, 100 * c.share,
             "yes" if c.accepted else "no",
             c.physics if c.accepted else (c.error or c.reason)]
            for c in diagnosis.candidates]


CANDIDATE_HEADER = ["atom", "cost reduction [-]", "added parameters", "log10 p",
                    "share of excess [%]", "accepted", "physics, or why not"]

STRUCTURE_HEADER = ["atoms added", "parameters", "Schwarz gain [-]",
                    "log10 p beside the others", "share of excess [%]", "admissible",
                    "tests failed"]


def structure_rows(decision):
    """The rule's table (:class:`~inflowsim.diagnose.rule.Decision`), one row a
    structure, as the report prints it."""
    rule = decision.rule
    return [[" + ".join(r.atoms), r.dof, r.schwarz_gain,
             ", ".join(f"{lp:.1f}" for _, lp in r.beside),
             "" if r.share is None else 100 * r.share,
             "yes" if r.admissible(rule) else "no",
             ", ".join(r.failed(rule)) or "none"] for r in decision.rows]


def format_diagnosis(d) -> str:
    """Plain-text summary of a :class:`~inflowsim.diagnose.Diagnosis`."""
    lines = [f"structure {d.structure.name}: cost {d.fit.cost:.2f} over "
             f"{d.band_hz[0]:.4g}-{d.band_hz[1]:.4g} Hz"]
    lines.append("where it fails:" if d.failures else "where it fails: nothing found")
    lines += [f"  - {failure_message(f, d.analyses)}" for f in d.failures]
    lines.append("candidate effects, one atom each (* = added):")
    for c in d.candidates:
        mark = "*" if c.accepted else " "
        lines.append(f" {mark} {c.atom:<28} cost -{c.cost_reduction:9.2f}  "
                     f"dof {c.dof}  log10 p {c.log10_p:8.1f}  gain {c.schwarz_gain:8.1f}"
                     + ("" if c.accepted else f"  ({c.error or c.reason})"))
    lines += decision_lines(d.decision)
    if d.missing_effect:
        c = next(c for c in d.candidates if c.effect == d.missing_effect)
        named = " + ".join(d.missing_effects)
        physics = "; ".join(next(x.physics for x in d.candidates if x.effect == e)
                            for e in d.missing_effects)
        v = d.verdict
        standing = [x.effect for x in (v.stand_ins if v is not None else ())]
        stand = ("" if not standing else
                 f" [{', '.join(standing)}: a stand-in, see the verdict]")
        if v is not None and v.status == "partly-explained":
            share = v.excess_explained
            part = "" if share is None else f" {100 * share:.0f} % of the excess over the floor;"
            lines.append(f"part of the missing physics: {named}{stand} explains{part} "
                         f"excess is left (see the verdict): {physics}")
        else:
            lines.append(f"missing effect: {named}{stand}: {physics}")
        covered = [o.atom for o in d.candidates if o.explained_by in d.decision.added]
        if covered:
            lines.append(f"  it also explains what {', '.join(covered)} would: not "
                         f"significant beside it, so not shown apart by this record")
        lines.append(f"  add it: inflowsim identify RECORD --model {d.structure.name} "
                     + " ".join(f"--add {e}" for e in d.missing_effects))
    else:
        lines.append("missing effect: none accepted")
    if d.missing_terms is not None:
        lines.append("where a term is missing (score test of every single-entry addition):")
        lines += [f"  {line}" for line in d.missing_terms.describe()]
    lines += estimate_lines(d.fit)
    lines += identifiability_lines(d.identifiability, d.structure.name)
    if d.verdict is not None:
        lines.append(d.verdict.describe())
    return "\n".join(lines)


def estimate_lines(fit) -> list:
    """The fitted structure's estimates with their Cramer-Rao and robust bounds, and
    whether they are conditional on an incomplete structure, rendered from the fit."""
    from .units import parameter_value
    parts = []
    for n in fit.parameters:
        if n in fit.fixed or n not in fit.sigma:
            continue
        v, s = parameter_value(n, fit.parameters[n]), parameter_value(n, fit.sigma[n])
        sr = parameter_value(n, getattr(fit, "sigma_robust", {}).get(n))
        if s is None:
            parts.append(f"{n} {v:.4g} (not determined)")
        elif sr is None:
            parts.append(f"{n} {v:.4g} ({s:.2g})")
        else:
            parts.append(f"{n} {v:.4g} ({s:.2g}; robust {sr:.2g})")
    if not parts:
        return []
    head = (f"estimates of {fit.structure.name} (1-sigma Cramer-Rao; robust; angles in "
            "degrees, time constants in azimuth units):")
    out = [head, "  " + ", ".join(parts)]
    if getattr(fit, "conditional", None):
        out.append(f"  {CONDITIONAL_MARK.strip()} every estimate above is {fit.conditional}")
    return out


def diagnosis_report(d, rep: Report | None = None, prefix="diagnose") -> Report:
    rep = rep or Report(f"Diagnosis of {d.structure.name}")
    rep.heading(f"Diagnosis of {d.structure.name}")
    rep.paragraph(f"Fitted over {d.band_hz[0]:.4g}-{d.band_hz[1]:.4g} Hz: cost "
                  f"{d.fit.cost:.2f}. The diagnosis applies one rule "
                  "(inflowsim.diagnose.rule), in five lines:")
    from ..diagnose.rule import STATEMENT
    rep.paragraph(" ".join(STATEMENT))
    if d.failures:
        rep.heading("Where it fails", 3)
        rep.table(failure_rows(d), FAILURE_HEADER)
    rep.heading("Candidate effects, best first", 3)
    rep.table(candidate_rows(d), CANDIDATE_HEADER, digits=4)
    if d.decision is not None:
        rep.heading("Structures scored by the rule", 3)
        rep.table(structure_rows(d.decision), STRUCTURE_HEADER, digits=4)
    rep.paragraph(f"Missing effect: {' + '.join(d.missing_effects) or 'none accepted'}.")
    if getattr(d.fit, "conditional", None):
        rep.paragraph(f"The estimates of {d.structure.name} are {d.fit.conditional}.")
    if d.verdict is not None:
        rep.paragraph(d.verdict.describe()[0].upper() + d.verdict.describe()[1:] + ".")
    from .fit_plots import fit_plot
    from .plots import residual_spectrum_plot
    rep.figure(candidate_plot(d), f"{prefix}-candidates",
               "Cost reduction of each candidate effect (accepted in green).")
    if d.missing_terms is not None:
        from .terms import missing_terms_plot
        rep.heading("Where a term is missing", 3)
        rep.paragraph(" ".join(d.missing_terms.describe()))
        rep.figure(missing_terms_plot(d.missing_terms), f"{prefix}-terms",
                   "Score test of every single-entry addition to the flap and inflow "
                   "equations and the measurement map at the base fit (its shared "
                   "parameters freed per row group): colour -log10 p, "
                   "framed where significant after Holm's correction, with the sign "
                   "of the term the data want.")
    if d.analyses:
        rep.figure(residual_spectrum_plot(d.analyses), f"{prefix}-residual",
                   f"Residual power of {d.structure.name} against the noise floor: where "
                   "it stands above the floor, the model misses something.")
    for k in range(len(d.fit.data)):
        rep.figure(fit_plot(d.fit, index=k), f"{prefix}-fit-{k + 1}",
                   f"Frequency-domain fit of {d.structure.name}, record {k + 1}.")
    return rep


def ladder_report(ladder, rep: Report | None = None, record=None,
                  heading="The ladder: structures tried, side by side",
                  frf_heading="Where it fails, in frequency: first and last structure"
                  ) -> Report:
    """The ladder's table and plots; given the ``record`` it was climbed on, also the
    measured frequency responses with the first and last structures on top, their
    costs and the parameters' accuracy (:func:`.model_frf.model_frf_section`).
    ``heading`` and ``frf_heading`` title the two sections (a report numbers them)."""
    rep = rep or Report("Ladder of structures")
    header, rows = ladder_rows(ladder)
    rep.heading(heading)
    rep.paragraph("Estimates with 1-sigma Cramer-Rao bounds in brackets (angles in "
                  "degrees; time constants in azimuth units, radians of rotor "
                  "azimuth), the cost (12), a pure number whose differences between "
                  "rungs count (its log-determinant takes the residual covariance in "
                  "rad^2), the per-channel fit, and each flap channel's mean residual "
                  "power over the noise floor (1: nothing left but sensor noise) as "
                  "each effect is added.")
    rep.table(rows, header)
    for line in conditional_lines(ladder):
        rep.paragraph(line)
    if ladder.verdict is not None:
        rep.paragraph(ladder.verdict.describe()[0].upper() + ladder.verdict.describe()[1:]
                      + ".")
    for note in worse_channels(ladder):
        rep.paragraph(note)
    rep.figure(ladder_plot(ladder), "ladder",
               "The error falling as effects are added: the cost, and each channel's "
               "residual power over the sensor-noise floor (dashed line at 1: only "
               "noise left).")
    final = ladder.rungs[-1]
    if final.analyses:
        from .plots import residual_spectrum_plot
        rep.figure(residual_spectrum_plot(final.analyses), "ladder-final-residual",
                   f"Residual power of the final structure {final.structure.name} "
                   "against the noise floor.")
    if record is not None:
        from ..diagnose.validation import validate
        from .model_frf import model_frf_section
        first = ladder.rungs[0]
        ends = [first] if final is first else [first, final]
        model_frf_section(rep, [validate(record, r.fit.model) for r in ends],
                          [r.structure.name for r in ends],
                          fits={r.structure.name: r.fit for r in ends}, prefix="ladder",
                          heading=frf_heading)
    return rep


def told_apart_line(atom, indistinguishable) -> str:
    """``"time-delay added; the record cannot tell it from servo-actuators (Vuong z =
    0.4)"``, rendered from the decision's :attr:`~inflowsim.diagnose.rule.Decision.
    indistinguishable` (``""`` when the record tells every admissible rival apart)."""
    if not indistinguishable:
        return ""
    said = ", ".join(f"{a} (Vuong z = {z:+.1f})" for a, z in indistinguishable)
    return f"{atom} added; the record cannot tell it from {said}"


def decision_lines(decision) -> list:
    """The rule's decision in a few lines, rendered from its table (structures of
    more than one atom; the single atoms are the candidate lines above)."""
    if decision is None:
        return []
    rule = decision.rule
    out = []
    pairs = [r for r in decision.rows if len(r.atoms) > 1]
    if pairs:
        out.append("pairs fitted together (log10 p of each atom beside the other):")
        for r in pairs:
            if r.error is not None:
                continue
            beside = ", ".join(f"{a} {lp:.1f}" for a, lp in r.beside)
            ok = "admissible" if r.admissible(rule) else "not admissible"
            out.append(f"   {' + '.join(r.atoms):<44} gain {r.schwarz_gain:8.1f}  "
                       f"({beside}; {ok})")
    c = decision.chosen
    if c is None:
        out.append("rule: no structure is admissible (significant and plausible)")
    elif decision.accepted:
        out.append(f"rule: accepted {' + '.join(c.atoms)}, the admissible structure of "
                   f"largest Schwarz gain ({c.schwarz_gain:.1f}, {c.dof} parameter(s)); "
                   f"adds {decision.added[0]}"
                   + ("" if len(c.atoms) == 1 else ", the atom it needs most (the rest "
                      "is judged on the next rung)"))
        told = told_apart_line(decision.added[0], decision.indistinguishable)
        if told:
            out.append(f"  {told}")
    else:
        from ..diagnose.candidates import describe
        out.append(f"rule: the admissible structure of largest gain, "
                   f"{' + '.join(c.atoms)}, is not accepted: {describe(c, decision)}")
    return out


__all__ = ["rung_label", "held_parameters", "column_label", "ladder_rows", "COST_LABEL",
           "ladder_markdown", "identifiability_lines", "floor_ratios", "ladder_plot",
           "worse_channels", "candidate_plot", "FAILURE_HEADER", "failure_rows",
           "failure_message", "candidate_rows", "CANDIDATE_HEADER", "STRUCTURE_HEADER",
           "structure_rows", "format_diagnosis", "diagnosis_report", "ladder_report",
           "decision_lines", "told_apart_line"]
