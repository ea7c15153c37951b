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
import io
import math
import os
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path

from ..errors import InputError
from ..fileio import atomic_path, check_folder, check_replaceable, safe_write_text

MANIFEST = ".inflowsim-report"
CSS = """
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


#: The page: the title, the blocks in order (each a dict with its ``kind``), the
#: stamp.  Jinja2 escapes every text (autoescape); figures' ``src`` is a file name
#: or a data URL.
PAGE = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="generator" content="inflowsim">
<title>{{ title }}</title><style>{{ css | safe }}</style></head>
<body>
<h1>{{ title }}</h1>{% if subtitle %}<p class="sub">{{ subtitle }}</p>{% endif %}
{% for b in blocks -%}
{% if b.kind == "heading" -%}
<h{{ b.level }}>{{ b.text }}</h{{ b.level }}>
{%- elif b.kind == "paragraph" -%}
<p>{{ b.text }}</p>
{%- elif b.kind == "pre" -%}
<pre>{{ b.text }}</pre>
{%- elif b.kind == "list" -%}
<ul>{% for item in b["items"] %}<li>{{ item }}</li>{% endfor %}</ul>
{%- elif b.kind == "table" -%}
<table>
{% if b.caption %}<caption>{{ b.caption }}</caption>
{% endif %}{% if b.header %}<tr>{% for h in b.header %}<th>{{ h }}</th>{% endfor %}</tr>
{% endif %}{% for row in b.rows %}<tr>{% for text, num in row %}<td{% if num %} class="n"{% endif %}>{{ text }}</td>{% endfor %}</tr>
{% endfor %}</table>
{%- elif b.kind == "figure" -%}
<figure><img src="{{ b.src }}" alt="{{ b.alt }}">{% if b.caption %}<figcaption>{{ b.caption }}</figcaption>{% endif %}</figure>
{%- elif b.kind == "link" -%}
<p><a href="{{ b.href }}">{{ b.label }}</a></p>
{%- endif %}
{% endfor -%}
<footer>Written by inflowsim, {{ stamp }}.</footer>
</body></html>
"""


def render_page(title: str, blocks, subtitle: str | None = None, stamp: str | None = None
                ) -> str:
    """The HTML page of ``blocks`` (:data:`PAGE`, a Jinja2 template; every text
    escaped).

    Parameters
    ----------
    title : str
        Page title and top heading.
    blocks : sequence of dict
        ``{"kind": "heading", "level", "text"}``, ``{"kind": "paragraph", "text"}``,
        ``{"kind": "pre", "text"}``, ``{"kind": "list", "items"}``,
        ``{"kind": "table", "caption", "header", "rows"}`` (rows of ``(text,
        numeric)`` cells), ``{"kind": "figure", "src", "alt", "caption"}``,
        ``{"kind": "link", "href", "label"}``.
    subtitle : str, optional
        One line under the title.
    stamp : str, optional
        When it was written (default now, UTC).
    """
    from jinja2 import Environment
    if stamp is None:
        stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    env = Environment(autoescape=True, keep_trailing_newline=True)
    return env.from_string(PAGE).render(title=str(title), subtitle=subtitle,
                                        blocks=list(blocks), css=CSS, stamp=stamp)


def table_block(rows, header=None, caption: str | None = None, digits: int = 4) -> dict:
    """A table block of :func:`render_page`: cells as text (:func:`format_cell`),
    numbers marked to be right-aligned.

    Parameters
    ----------
    rows : sequence of sequence
        The cells.
    header : sequence of str, optional
    caption : str, optional
    digits : int
        Significant digits of floats.
    """
    out = []
    for row in rows:
        cells = []
        for v in row:
            num = isinstance(v, (int, float)) and not isinstance(v, bool) or \
                type(v).__module__ == "numpy"
            cells.append((format_cell(v, digits), bool(num)))
        out.append(cells)
    return {"kind": "table", "caption": caption,
            "header": [str(h) for h in header] if header else None, "rows": out}


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
    """Text of one table cell: floats to ``digits`` significant digits.

    Parameters
    ----------
    v : object
        The cell's value (a number, text, a bool or ``None``).
    digits : int
        Significant digits of a float [-].
    """
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
        self._blocks.append({"kind": "heading", "level": lv, "text": str(text)})
        return self

    def paragraph(self, text: str) -> "Report":
        """A paragraph of plain text (escaped)."""
        self._blocks.append({"kind": "paragraph", "text": str(text)})
        return self

    def preformatted(self, text: str) -> "Report":
        """Monospaced text kept as is (a command line, a table printed by the CLI)."""
        self._blocks.append({"kind": "pre", "text": str(text)})
        return self

    def table(self, rows, header=None, caption: str | None = None,
              digits: int = 4) -> "Report":
        """A table from ``rows`` (sequences of cells); numbers right-aligned.

        Floats are shown to ``digits`` significant digits, ``None`` as empty.
        """
        self._blocks.append(table_block(rows, header, caption, digits))
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
        page = render_page(self.title, body, self.subtitle)
        return safe_write_text(d / "index.html", page, overwrite=True)

    def _render(self, block, d: Path) -> dict:
        if isinstance(block, _Attachment):
            safe_write_text(d / block.name, block.text, overwrite=True)
            return {"kind": "link", "href": block.name,
                    "label": block.caption or block.name}
        if not isinstance(block, _Figure):
            return block
        png = _png_bytes(block.source)
        if block.embed:
            src = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
        else:
            _write_bytes(d / f"{block.name}.png", png)
            src = f"{block.name}.png"
        return {"kind": "figure", "src": src, "alt": block.caption or block.name,
                "caption": block.caption}


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


__all__ = ["Report", "format_cell", "MANIFEST", "CSS", "PAGE", "render_page",
           "table_block", "check_report_folder"]
