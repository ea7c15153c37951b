"""Report layer: figures (every function returns a matplotlib ``Figure``, drawn on
its own canvas; no global backend switch), tables and the HTML document."""
from .document import MANIFEST, Report, format_cell

__all__ = ["Report", "format_cell", "MANIFEST"]
