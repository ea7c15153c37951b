"""A small HTML report writer: title, paragraphs, tables, PNG figures.

Usage::

    from inflowsim.report import Report
    rep = Report("Validation of glauert", subtitle="record flight.csv")
    rep.paragraph("Trim: mean of the 200 samples before the first control movement.")
    rep.table([["beta0", 1.2e-4, 0.05, 97.1]], header=["channel", "rms [rad]", "TIC", "fit [%]"])
    rep.figure(fig, "time", caption="Measured and predicted flap")   # a matplotlib Figure
    path = rep.write("report-dir")          # -> report-dir/index.html (+ time.png)

``attach(name, text)`` adds a text file (a record, a fit) beside the page, with a
link.  ``write`` creates the directory, writes ``index.html`` (self-contained except the
PNG files beside it, or with ``embed=True`` nothing beside it) and returns its
path.  It never replaces a file it did not write itself: the files of a report
are listed in ``DIR/.inflowsim-report``, and an existing file not listed there
(a user's file) is refused with :class:`~inflowsim.errors.InputError` before
anything is written.  A directory argument that is an existing regular file is
refused too.  Every method but ``write`` returns the report, so calls chain.
"""
from __future__ import annotations

import base64
import html
import io
import math
import os
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

from ..errors import InputError
from ..fileio import atomic_path, check_folder, check_replaceable, safe_write_text

MANIFEST = ".inflowsim-report"
_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1100px;
margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
h1{font-size:1.6em;margin-bottom:.1em}.sub{color:#666;margin-top:0}
table{border-collapse:collapse;margin:.8em 0}th,td{border:1px solid #ccc;padding:.25em .6em}
th{background:#f3f3f3;text-align:left}td.n{text-align:right;font-variant-numeric:tabular-nums}
caption{caption-side:top;text-align:left;font-weight:600;padding:.2em 0}
figure{margin:1em 0}figure img{max-width:100%;border:1px solid #eee}
figcaption{color:#555;font-size:.92em}pre{background:#f7f7f7;padding:.6em;overflow-x:auto}
footer{color:#888;font-size:.85em;margin-top:2em;border-top:1px solid #eee}
"""


@dataclass(frozen=True)
class _Figure:
    name: str
    source: object          # matplotlib Figure or path of an existing PNG
    caption: str | None
    embed: bool


@dataclass(frozen=True)
class _Attachment:
    name: str
    text: str
    caption: str | None


def format_cell(v, digits: int = 4) -> str:
    """Text of one table cell: floats to ``digits`` significant digits."""
    if v is None:
        return ""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float) or type(v).__name__.startswith("float"):
        v = float(v)
        return "nan" if math.isnan(v) else f"{v:.{digits}g}"
    return str(v)


class Report:
    """An HTML report built block by block, then written with :meth:`write`.

    Parameters
    ----------
    title : str
        Page title and top heading.
    subtitle : str, optional
        One line under the title (the record, the model ...).
    """

    def __init__(self, title: str, subtitle: str | None = None):
        self.title = str(title)
        self.subtitle = subtitle
        self._blocks: list = []

    # -- content ------------------------------------------------------------
    def heading(self, text: str, level: int = 2) -> "Report":
        """A section heading (``level`` 2-4)."""
        lv = min(max(int(level), 2), 4)
        self._blocks.append(f"<h{lv}>{html.escape(str(text))}</h{lv}>")
        return self

    def paragraph(self, text: str) -> "Report":
        """A paragraph of plain text (escaped)."""
        self._blocks.append(f"<p>{html.escape(str(text))}</p>")
        return self

    def preformatted(self, text: str) -> "Report":
        """Monospaced text kept as is (a command line, a table printed by the CLI)."""
        self._blocks.append(f"<pre>{html.escape(str(text))}</pre>")
        return self

    def table(self, rows, header=None, caption: str | None = None,
              digits: int = 4) -> "Report":
        """A table from ``rows`` (sequences of cells); numbers right-aligned.

        Floats are shown to ``digits`` significant digits, ``None`` as empty.
        """
        out = ["<table>"]
        if caption:
            out.append(f"<caption>{html.escape(caption)}</caption>")
        if header:
            out.append("<tr>" + "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
                       + "</tr>")
        for row in rows:
            cells = []
            for v in row:
                num = isinstance(v, (int, float)) and not isinstance(v, bool) or \
                    type(v).__module__ == "numpy"
                cls = ' class="n"' if num else ""
                cells.append(f"<td{cls}>{html.escape(format_cell(v, digits))}</td>")
            out.append("<tr>" + "".join(cells) + "</tr>")
        out.append("</table>")
        self._blocks.append("\n".join(out))
        return self

    def figure(self, fig, name: str, caption: str | None = None,
               embed: bool = False) -> "Report":
        """A PNG figure: a matplotlib ``Figure`` or the path of an existing PNG.

        Written as ``DIR/<name>.png`` beside ``index.html`` (``name``: letters,
        digits, ``-`` and ``_``), or embedded in the HTML when ``embed``.
        """
        name = str(name)
        if not name or not all(ch.isalnum() or ch in "-_" for ch in name):
            raise InputError(f"figure name {name!r}: use letters, digits, - and _")
        if any(isinstance(b, _Figure) and b.name == name for b in self._blocks):
            raise InputError(f"figure name {name!r} used twice in one report")
        self._blocks.append(_Figure(name, fig, caption, bool(embed)))
        return self

    def attach(self, filename: str, text: str, caption: str | None = None) -> "Report":
        """A text file (a record, a parameter file) written beside ``index.html``
        under the same ownership rules as the figures, with a link to it."""
        name = str(filename)
        if not name or not all(ch.isalnum() or ch in "-_." for ch in name) \
                or name.startswith(".") or name in self.files():
            raise InputError(f"attachment name {name!r}: use a new plain file name")
        self._blocks.append(_Attachment(name, str(text), caption))
        return self

    # -- output ---------------------------------------------------------------
    def files(self) -> list[str]:
        """Names of the files :meth:`write` puts in the directory."""
        return ["index.html"] + [f"{b.name}.png" for b in self._blocks
                                 if isinstance(b, _Figure) and not b.embed] + \
            [b.name for b in self._blocks if isinstance(b, _Attachment)]

    def write(self, directory, protect=()) -> Path:
        """Write ``directory/index.html`` and its PNG files; return the HTML path.

        Refuses (``InputError``, nothing written) when ``directory`` is a regular
        file, when it would replace a file that an earlier report did not write,
        or a file in ``protect`` (the command's inputs).
        """
        d = Path(directory)
        names = self.files()
        check_report_folder(d, names, protect)
        owned = _manifest(d)
        try:
            d.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"{d}: cannot create the report folder ({exc.strerror})") \
                from None
        body = [self._render(b, d) for b in self._blocks]
        safe_write_text(d / MANIFEST, "\n".join(sorted(set(names) | owned)) + "\n",
                        overwrite=True)
        stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
        sub = f'<p class="sub">{html.escape(self.subtitle)}</p>' if self.subtitle else ""
        page = (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
                f"<meta name=\"generator\" content=\"inflowsim\">\n"
                f"<title>{html.escape(self.title)}</title><style>{_CSS}</style></head>\n"
                f"<body>\n<h1>{html.escape(self.title)}</h1>{sub}\n" + "\n".join(body)
                + f"\n<footer>Written by inflowsim, {stamp}.</footer>\n</body></html>\n")
        return safe_write_text(d / "index.html", page, overwrite=True)

    def _render(self, block, d: Path) -> str:
        if isinstance(block, _Attachment):
            safe_write_text(d / block.name, block.text, overwrite=True)
            label = html.escape(block.caption or block.name)
            return f'<p><a href="{html.escape(block.name, quote=True)}">{label}</a></p>'
        if not isinstance(block, _Figure):
            return block
        png = _png_bytes(block.source)
        if block.embed:
            src = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
        else:
            _write_bytes(d / f"{block.name}.png", png)
            src = f"{block.name}.png"
        cap = (f"<figcaption>{html.escape(block.caption)}</figcaption>"
               if block.caption else "")
        alt = html.escape(block.caption or block.name, quote=True)
        return f'<figure><img src="{src}" alt="{alt}">{cap}</figure>'


def check_report_folder(directory, names=("index.html",), protect=()) -> Path:
    """Refuse (``InputError``) a report folder that :meth:`Report.write` would refuse:
    a regular file, a file of ``names`` there that no earlier report wrote, or one
    of the ``protect`` files.  Commands call it before long work."""
    d = Path(directory)
    if d.exists() and not d.is_dir():
        raise InputError(f"{d}: exists and is not a directory; choose a report folder")
    check_folder(d)
    owned = _manifest(d)
    check_replaceable(d / MANIFEST)
    for n in set(names) | {"index.html"}:
        p = d / n
        check_replaceable(p)
        for q in protect:
            if p.exists() and Path(q).exists() and os.path.samefile(p, q):
                raise InputError(f"{p}: refusing to write a report over the input "
                                 f"file {q}")
        if p.exists() and n not in owned:
            raise InputError(f"{p}: exists and is not part of an earlier inflowsim "
                             "report; choose another folder")
    return d


def _manifest(d: Path) -> set:
    m = d / MANIFEST
    if not m.is_file():
        return set()
    return {ln.strip() for ln in m.read_text(encoding="utf-8").splitlines() if ln.strip()}


def _png_bytes(source) -> bytes:
    if hasattr(source, "savefig"):
        buf = io.BytesIO()
        source.savefig(buf, format="png", dpi=110, metadata={"Software": "inflowsim"})
        return buf.getvalue()
    p = Path(source)
    try:
        data = p.read_bytes()
    except OSError as exc:
        raise InputError(f"{p}: cannot read figure ({exc.strerror})") from None
    if not data.startswith(b"\x89PNG"):
        raise InputError(f"{p}: not a PNG file")
    return data


def _write_bytes(path: Path, data: bytes):
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as f:
            f.write(data)


__all__ = ["Report", "format_cell", "MANIFEST"]
