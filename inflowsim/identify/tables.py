"""Parameter tables like the paper's Tables 1-3: rows, and Markdown."""
from __future__ import annotations

from ..model.presets import theory_parameters


def _fmt(v, digits=4):
    if v is None:
        return "n/d"
    return f"{v:.{digits}g}"


def table_rows(result) -> list:
    """``[(name, estimate, sigma, sigma_colored, sigma_robust, theory, note)]`` per
    parameter; an estimate conditional on an incomplete structure
    (``result.conditional``) says so in its note."""
    theory = theory_parameters(result.structure, result.constants[0])
    rows = []
    for n, v in result.parameters.items():
        note = "fixed" if n in result.fixed else next(
            ("tied " + "=".join(t) for t in result.ties if n in t), "")
        if n not in result.fixed and result.sigma.get(n) is None:
            note = (note + "; " if note else "") + "not determined by the data: no bound"
        if n not in result.fixed and getattr(result, "conditional", None):
            note = (note + "; " if note else "") + "conditional"
        rows.append((n, v, result.sigma.get(n), result.sigma_colored.get(n),
                     getattr(result, "sigma_robust", {}).get(n), theory.get(n), note))
    return rows


def _header(result):
    return (f"Structure `{result.structure.name}`, band {result.band_hz[0]:.4g}-"
            f"{result.band_hz[1]:.4g} Hz ({result.n_freq} frequencies, "
            f"{len(result.records)} record(s)), cost {result.cost:.4f}, "
            f"{'converged' if result.converged else 'NOT converged'} in "
            f"{result.iterations} iterations.")


def markdown_table(result) -> str:
    """The parameter table (estimate, 1-sigma CR bound, coloured-residual bound,
    robust bound, theory value) and the per-channel fit, in Markdown; below the
    table, why the estimates are conditional where they are.

    Parameters
    ----------
    result : FitResult
        The fit.
    """
    # written here, not by pandas' to_markdown (the campaign's reports use it): the
    # commands print this table and pandas' import alone costs 1.6 s (measured
    # after NumPy, under the shared machine's load), longer than many fits
    out = [_header(result), "",
           "| parameter | estimate | 1-sigma | 1-sigma (coloured) | 1-sigma (robust) "
           "| theory | note |",
           "| --- | ---: | ---: | ---: | ---: | ---: | --- |"]
    for n, v, s, sc, sr, th, note in table_rows(result):
        free = n not in result.fixed
        out.append(f"| `{n}` | {_fmt(v, 5)} | {_fmt(s, 3) if free else ''} "
                   f"| {_fmt(sc, 3) if free else ''} | {_fmt(sr, 3) if free else ''} "
                   f"| {_fmt(th)} | {note} |")
    if getattr(result, "conditional", None):
        out += ["", f"Every estimate is {result.conditional}."]
    out += ["", "| channel | magnitude error (RMS dB) | phase error (RMS deg) | fit % |",
            "| --- | ---: | ---: | ---: |"]
    for ch, f in result.fit.items():
        out.append(f"| `{ch}` | {_fmt(f['mag_rms_db'], 3)} | {_fmt(f['phase_rms_deg'], 3)} "
                   f"| {_fmt(f['fit_percent'], 5)} |")
    if result.warnings:
        out += ["", "Warnings:", ""] + [f"- {w}" for w in result.warnings]
    return "\n".join(out) + "\n"


__all__ = ["table_rows", "markdown_table"]
