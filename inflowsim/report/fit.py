"""The report of an identification: tables (Markdown, HTML) and plots of the fit
(what ``inflowsim identify --report`` writes)."""
from __future__ import annotations

from pathlib import Path

from ..errors import InputError
from ..fileio import safe_write_text


def write_report(result, folder, force=False, protect=()):
    """Tables (``table.md``, ``table.html``), plots (``fit_frequency.png``,
    ``fit_time.png``) and ``fit.json`` into ``folder`` (created)."""
    import json

    from ..identify.tables import html_table, markdown_table
    from .fit_plots import fit_plot, reconstruction_plot
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
