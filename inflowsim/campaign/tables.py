"""A campaign's results as tables and a report.

One table (pandas), one row per record and one per flight condition (``kind``),
written as ``campaign.parquet`` and ``campaign.csv``: where the row comes from
(record, condition, ``mu``, manoeuvre, group), its status and error, the
decision (``missing_effect``, ``verdict``, the effects the ladder added, its
final structure), the base fit's figures (cost, frequencies, fit per flap
channel), the trim totals it flew at (``trim_COLUMN``: the record's, or the mean
of the condition's records; what the schedule's trim is fitted to) and every
estimate with its bound (``est_NAME``, ``sigma_NAME``).
``report.md`` puts the estimates against ``mu`` with their bounds, the
parameter schedule (:mod:`.schedule`; written as ``schedule.json``, which
``inflowsim fmu build --schedule`` takes) and the missing effect by condition;
the figure (:mod:`inflowsim.report.campaign`) is drawn from the table and the
schedule, apart from the computing.  ``campaign.json`` is the ``--json``
document.
"""
from __future__ import annotations

from pathlib import Path

from ..fileio import atomic_path, json_text
from ..physics.bladeelement import TRIM_KEYS

TABLE_COLUMNS = ("kind", "record", "condition", "mu", "manoeuvre", "group", "status",
                 "error", "missing_effect", "verdict", "accepted", "ladder_added",
                 "final_structure", "structure", "cost", "n_freq", "converged",
                 "fit_beta0", "fit_beta1c", "fit_beta1s", "n_records", "seconds", "key")
#: The trim totals' columns (after :data:`TABLE_COLUMNS`, before the estimates).
TRIM_COLUMNS = tuple(f"trim_{c}" for c in TRIM_KEYS)


def _row(doc: dict) -> dict:
    base = doc.get("base_fit") or {}
    fitp = base.get("fit_percent") or {}
    row = {"kind": doc.get("kind"),
           "record": doc.get("record") if doc.get("kind") == "record" else None,
           "condition": doc.get("condition"), "mu": doc.get("mu", doc.get("plan_mu")),
           "manoeuvre": doc.get("manoeuvre"), "group": doc.get("group"),
           "status": doc.get("status"), "error": doc.get("error"),
           "missing_effect": doc.get("missing_effect"), "verdict": doc.get("verdict"),
           "accepted": ";".join(doc.get("accepted") or []),
           "ladder_added": ";".join(doc.get("ladder_added") or []),
           "final_structure": doc.get("final_structure"),
           "structure": base.get("structure"), "cost": base.get("cost"),
           "n_freq": base.get("n_freq"), "converged": base.get("converged"),
           "fit_beta0": fitp.get("beta0"), "fit_beta1c": fitp.get("beta1c"),
           "fit_beta1s": fitp.get("beta1s"),
           "n_records": len(doc.get("records") or []) if doc.get("kind") == "condition"
           else 1, "seconds": doc.get("seconds"), "key": doc.get("key")}
    for c, v in (doc.get("trim") or {}).items():
        row[f"trim_{c}"] = v
    for n, v in (base.get("parameters") or {}).items():
        row[f"est_{n}"] = v.get("estimate")
        row[f"sigma_{n}"] = v.get("sigma")
    return row


def campaign_table(result):
    """The campaign table (``pandas.DataFrame``): records first, then conditions."""
    import pandas as pd
    rows = [_row(r) for r in result.records] + [_row(c) for c in result.conditions]
    df = pd.DataFrame(rows)
    cols = [c for c in TABLE_COLUMNS if c in df.columns]
    trim = [c for c in TRIM_COLUMNS if c in df.columns]
    est = sorted(c for c in df.columns if c.startswith(("est_", "sigma_")))
    df = df[cols + trim + [c for c in est if c not in cols]]
    for c in ("record", "condition", "manoeuvre", "group", "error", "missing_effect",
              "verdict", "accepted", "ladder_added", "final_structure", "structure", "key"):
        if c in df.columns:
            df[c] = df[c].astype("string")
    for c in ("mu", "cost", "seconds", "fit_beta0", "fit_beta1c", "fit_beta1s", *trim,
              *[c for c in df.columns if c.startswith(("est_", "sigma_"))]):
        if c in df.columns:
            df[c] = pd.to_numeric(df[c], errors="coerce").astype("float64")
    return df


def json_document(result, files=None) -> dict:
    """The ``--json`` document: ``records``, ``conditions``, ``agreement``,
    ``schedule`` (:func:`.schedule.schedule_summary`), ``tables`` (file paths),
    ``work`` (computed and reused counts), ``settings``."""
    from .schedule import schedule_summary
    keep = ("record", "condition", "manoeuvre", "group", "mu", "status", "error",
            "missing_effect", "verdict", "accepted", "ladder_added", "final_structure",
            "warnings", "seconds", "key")

    def slim(d, extra=()):
        out = {k: d.get(k) for k in keep + tuple(extra) if k in d}
        base = d.get("base_fit")
        if base:
            out["estimates"] = base.get("parameters")
            out["fit_percent"] = base.get("fit_percent")
        return out

    return {"records": [slim(r) for r in result.records],
            "conditions": [slim(c, ("records",)) for c in result.conditions],
            "agreement": result.agreement,
            "schedule": schedule_summary(getattr(result, "schedule", None),
                                         getattr(result, "schedule_note", "")),
            "tables": dict(files or {}),
            "work": {"computed": result.computed, "reused": result.reused},
            "settings": result.settings}


def _fmt(v, sig=None):
    if v is None or v != v:
        return "-"
    s = f"{v:.4g}"
    return s if sig is None or sig != sig else f"{s} +- {sig:.2g}"


def _h(level, text):
    return {"kind": "heading", "level": level, "text": text}


def _p(text):
    return {"kind": "paragraph", "text": text}


def _table(header, rows, right=()):
    """A table block (:func:`inflowsim.report.document.render_page`); ``right``: the
    columns right-aligned (numbers)."""
    return {"kind": "table", "caption": None, "header": list(header),
            "rows": [[(str(c), k in right) for k, c in enumerate(r)] for r in rows]}


def _num(v):
    return None if v is None or v != v else float(v)


def report_blocks(result, df, figure=None) -> list:
    """The campaign report as data: headings, paragraphs, tables, the figure, lists
    (the kinds of :func:`inflowsim.report.document.render_page`), rendered as
    Markdown (:func:`report_markdown`) and HTML (:func:`report_html`).

    Parameters
    ----------
    result : CampaignResult
    df : pandas.DataFrame
        The campaign table (:func:`campaign_table`).
    figure : str, optional
        The figure's file name beside the report.
    """
    ag = result.agreement
    st = result.settings
    b = [_p(f"Plan: {st.get('plan')}; model {st['model']}, band {st['band'][0]:g}-"
            f"{st['band'][1]:g} Hz, inflowsim {st['version']}."),
         _p(f"{len(result.records)} records "
            f"({sum(r.get('status') == 'ok' for r in result.records)} analysed), "
            f"{len(result.conditions)} flight conditions.  Work: "
            f"{result.computed['records']} records and {result.computed['conditions']} "
            f"conditions computed, {result.reused['records']} and "
            f"{result.reused['conditions']} found from an earlier run."),
         _h(2, "The missing effect by condition")]
    rows = []
    for c in result.conditions:
        by = ag["by_condition"].get(c["condition"], {})
        names = ", ".join(f"{k} x{v}" for k, v in sorted(by.get("records", {}).items()))
        joint = c.get("missing_effect") if c.get("status") == "ok" else \
            f"error: {c.get('error')}"
        rows.append([c["condition"], _fmt(c.get("mu")), len(c.get("records") or []),
                     joint or "none", c.get("verdict") or "", names])
    b.append(_table(["condition", "mu [-]", "records", "joint fit names", "verdict",
                     "records name"], rows, right=(1, 2)))
    b.append(_p(f"Consensus across conditions: {ag['consensus'] or 'none'}"
                f"{' (every condition)' if ag['unanimous'] else ''}.  Verdicts: "
                "docs/interface.md, 'The verdict: one vocabulary'."))
    b.append(_table(["effect", "records naming it", "conditions naming it"],
                    [[e if e != "None" else "none", v["records"], v["conditions"]]
                     for e, v in sorted(ag["effects"].items(),
                                        key=lambda kv: -kv[1]["records"])], right=(1, 2)))
    if ag["disagreements"]:
        b.append(_h(3, "Where records disagree with their condition"))
        b.append({"kind": "list", "items": [
            f"{Path(d['record']).name} ({d['condition']}): names "
            f"{d['record_says'] or 'none'}, the condition "
            f"{d['condition_says'] or 'none'}: {d['why']}" for d in ag["disagreements"]]})
    conds = df[(df["kind"] == "condition") & (df["status"] == "ok")].sort_values("mu")
    est = [c[4:] for c in df.columns if c.startswith("est_")]
    if len(conds) and est:
        from ..report.units import parameter_label, parameter_value
        b.append(_h(2, "Estimates against mu (joint fit per condition, 1-sigma bounds)"))
        rows = []
        for n in est:
            vals = [_fmt(parameter_value(n, _num(r.get(f"est_{n}"))),
                         parameter_value(n, _num(r.get(f"sigma_{n}"))))
                    for _, r in conds.iterrows()]
            if any(v != "-" for v in vals):
                rows.append([parameter_label(n)] + vals)
        b.append(_table(["parameter"] + [f"mu {m:.3g}" for m in conds["mu"]], rows,
                        right=tuple(range(1, len(conds) + 1))))
    b += _schedule_blocks(getattr(result, "schedule", None),
                          getattr(result, "schedule_note", ""))
    if figure:
        b.append({"kind": "figure", "src": figure, "alt": "estimates against mu",
                  "caption": "Every estimate against the advance ratio: records (dots), "
                             "conditions' joint fits (squares), 1-sigma bars, the "
                             "schedule; a bound wider than the axis is marked, not drawn."})
    errs = [r for r in result.records if r.get("status") != "ok"]
    if errs:
        b.append(_h(2, "Records that could not be analysed"))
        b.append({"kind": "list", "items": [f"{r['record']}: {r.get('error')}"
                                            for r in errs]})
    return b


def report_markdown(result, df, figure=None) -> str:
    """The campaign report (Markdown), rendered from :func:`report_blocks`; the
    tables by pandas' ``to_markdown`` (tabulate).

    Parameters
    ----------
    result : CampaignResult
    df : pandas.DataFrame
        The campaign table.
    figure : str, optional
        The figure's file name beside the report.
    """
    import pandas as pd
    lines = ["# Campaign report", ""]
    for blk in report_blocks(result, df, figure):
        k = blk["kind"]
        if k == "heading":
            lines += ["#" * blk["level"] + " " + blk["text"], ""]
        elif k == "paragraph":
            lines += [blk["text"], ""]
        elif k == "list":
            lines += [f"- {x}" for x in blk["items"]] + [""]
        elif k == "figure":
            lines += [f"![{blk['alt']}]({blk['src']})", ""]
        elif k == "table":
            right = ([any(num for _, num in col) for col in zip(*blk["rows"])]
                     if blk["rows"] else [False] * len(blk["header"]))
            frame = pd.DataFrame([[t for t, _ in r] for r in blk["rows"]],
                                 columns=blk["header"])
            lines += [frame.to_markdown(index=False, disable_numparse=True, colalign=[
                "right" if r else "left" for r in right]), ""]
    return "\n".join(lines).rstrip("\n") + "\n"


def report_html(result, df, figure=None) -> str:
    """The campaign report as an HTML page (the demo's page template,
    :func:`inflowsim.report.document.render_page`), rendered from
    :func:`report_blocks`.

    Parameters
    ----------
    result, df, figure
        As :func:`report_markdown` (the figure beside the page).
    """
    from ..report.document import render_page
    return render_page("Campaign report", report_blocks(result, df, figure),
                       subtitle=f"{len(result.records)} records, "
                                f"{len(result.conditions)} flight conditions")


def _schedule_blocks(sch, note) -> list:
    if sch is None:
        return [_h(2, "Schedules"), _p(f"No schedule: {note or 'nothing to fit'}.")]
    lo, hi = sch.mu_range
    at = (lo, 0.5 * (lo + hi), hi)
    crit = {"aic": "AIC (chi-square + 2 k)", "aicc": "AICc", "bic": "BIC (chi-square + "
            "k ln n)", "chi2": f"the lowest order passing the chi-square test at "
            f"{sch.alpha:g}"}[sch.criterion]
    b = [_h(2, "Schedules (each parameter against mu, weighted by its bounds)"),
         _p(f"Structure {sch.structure}, mu {lo:.3g} to {hi:.3g} (held beyond); "
            f"polynomial order 0 to {sch.max_order} chosen by {crit}; bounds 1-sigma, "
            "widened by sqrt(chi2/dof) where the conditions scatter more than their "
            f"bounds.  A constant would do where its chi-square passes at "
            f"{sch.alpha:g}.  File: schedule.json "
            "(inflowsim fmu build --schedule schedule.json).")]
    rows = []
    for p in sch.parameters:
        red = f"{p.chi2 / p.dof:.3g}" if p.dof > 0 else "-"
        const = ("yes" if p.constant else "no") + (
            f" ({p.constant_p:.2g})" if p.constant_p is not None else "")
        rows.append([p.name, p.order] + [_fmt(p.value(m), p.bound(m)) for m in at]
                    + [red, const])
    b.append(_table(["parameter", "order"] + [f"mu {m:.3g}" for m in at]
                    + ["chi2/dof", "constant would do (p)"], rows,
                    right=tuple(range(1, len(at) + 3))))
    if sch.held:
        b.append(_p("Held (time shifts, or no bound): " + ", ".join(
            f"{n} = {_fmt(v, s)}" for n, v, s in sch.held) + "."))
    if sch.trim:
        b.append(_p("The trim the conditions flew at (measured totals, each a "
                    "least-squares polynomial in mu, held beyond the range; what the "
                    "effects linearised about trim are linearised about at each mu):"))
        b.append(_table(["trim total", "order"] + [f"mu {m:.3g}" for m in at]
                        + ["largest residual"],
                        [[t.column, t.order] + [_fmt(t.value(m)) for m in at]
                         + [f"{t.residual:.2g}"] for t in sch.trim],
                        right=tuple(range(1, len(at) + 3))))
    if note:
        b.append(_p(note + "."))
    return b


def write_outputs(result, out) -> dict:
    """Write the table (Parquet, CSV), the report and its figure, the schedule and
    the JSON document under ``out``; returns their paths."""
    from ..model.schedule import write_schedule
    from .schedule import campaign_schedule
    out = Path(out)
    df = campaign_table(result)
    opts = result.settings.get("schedule") or {}
    result.schedule, result.schedule_note = campaign_schedule(
        result.conditions, opts.get("criterion", "aic"), opts.get("max_order", 3),
        variables=tuple(opts.get("variables", ("mu",))))
    files = {"parquet": str(out / "campaign.parquet"), "csv": str(out / "campaign.csv"),
             "report": str(out / "report.md"), "html": str(out / "report.html"),
             "json": str(out / "campaign.json")}
    with atomic_path(files["parquet"]) as tmp:
        df.to_parquet(tmp, index=False)
    with atomic_path(files["csv"]) as tmp:
        df.to_csv(tmp, index=False)
    if result.schedule is not None:
        files["schedule"] = str(write_schedule(result.schedule, out / "schedule.json"))
    fig_name = None
    from ..report.campaign import estimates_vs_mu_plot
    from ..report.plots import save_png
    fig = estimates_vs_mu_plot(df, schedule=result.schedule)
    if fig is not None:
        fig_path = out / "estimates_vs_mu.png"
        with atomic_path(fig_path) as tmp:
            save_png(fig, tmp)
        fig_name, files["figure"] = fig_path.name, str(fig_path)
    with atomic_path(files["report"]) as tmp:
        Path(tmp).write_text(report_markdown(result, df, fig_name))
    with atomic_path(files["html"]) as tmp:
        Path(tmp).write_text(report_html(result, df, fig_name), encoding="utf-8")
    with atomic_path(files["json"]) as tmp:
        Path(tmp).write_text(json_text(json_document(result, files)))
    return files


__all__ = ["TABLE_COLUMNS", "TRIM_COLUMNS", "campaign_table", "json_document",
           "report_blocks", "report_markdown", "report_html", "write_outputs"]
