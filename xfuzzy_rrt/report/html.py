"""Page assembly for the HTML audit reports: offline, escaped, deterministic.

Why these rules (DESIGN.md, "Reports"):

- *Offline*: an audit report must open years later on an air-gapped machine, so plotly.js is
  embedded once in the page head; figures are JSON drawn by one loader script (see
  :mod:`.plotjson`: compact typed arrays, shared values stored once, drawn lazily as they
  scroll into view); no ``<script src=...>`` and no CDN.
- *Escaped*: scenario names, descriptions, commands and paths come from user files; every piece
  of text goes through :func:`esc` before it reaches the page (figure titles too, since plotly
  renders a subset of HTML in them).
- *Deterministic*: every figure gets an explicit ``div_id`` (plotly would otherwise draw a
  random UUID), so two reports of the same inputs differ only in the date line and can be
  diffed.

Other pages (rule coverage, rulebook diff) reuse :class:`Page` and :func:`table`.
"""

from __future__ import annotations

import html
import math
import re
from typing import Any, Callable, Iterable, Sequence

import numpy as np

#: Small stylesheet shared by all reports (print-friendly, no external fonts).
CSS = """
body { font-family: -apple-system, "Segoe UI", Roboto, Helvetica, Arial, sans-serif;
       color: #222; margin: 0 auto; max-width: 1400px; padding: 16px 24px; line-height: 1.45; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { font-size: 1.3em; border-bottom: 1px solid #ccc; padding-bottom: 4px; margin-top: 1.8em; }
h3 { font-size: 1.1em; margin-top: 1.2em; }
code, pre { font-family: Menlo, Consolas, "DejaVu Sans Mono", monospace; font-size: 0.92em; }
pre { background: #f5f5f5; padding: 8px 10px; overflow-x: auto; white-space: pre-wrap;
      word-break: break-all; }
table.data { border-collapse: collapse; margin: 8px 0 12px 0; font-size: 0.92em; }
table.data th, table.data td { border: 1px solid #ccc; padding: 3px 8px; }
table.data th { background: #f0f0f0; text-align: center; }
table.data td.num { text-align: right; font-variant-numeric: tabular-nums; }
table.data td.txt { text-align: left; }
table.kv td:first-child { font-weight: 600; background: #fafafa; white-space: nowrap; }
table.kv td { word-break: break-all; }
.note { color: #444; font-size: 0.95em; max-width: 70em; }
.muted { color: #777; }
.grid { display: grid; gap: 12px; }
.cell { min-width: 0; border: 1px solid #eee; padding: 4px; }
.fig { width: 100%; }
details > summary { cursor: pointer; color: #0550ae; }
.xf-drill { border-top: 1px solid #eee; padding-top: 6px; }
.xf-drill h4 { margin: 6px 0 2px 0; font-size: 0.95em; }
.xf-drill-systems table.data { font-size: 0.78em; }
.scroll { overflow-x: auto; max-width: 100%; }
.xf-nav { font-size: 0.9em; padding: 4px 0; border-bottom: 1px solid #eee; }
h1.xf-title { font-size: 1.35em; margin: 6px 0 0 0; }
p.xf-sub { margin: 2px 0 6px 0; font-size: 0.9em; }
ul.xf-verdict { margin: 6px 0; padding: 6px 12px 6px 28px; background: #f4f8fc;
                border-left: 4px solid #0072B2; line-height: 1.35; }
ul.xf-verdict li { margin: 1px 0; }
.xf-lose { color: #b2182b; font-weight: 600; }
table.xf-planners { margin: 4px 0; }
table.xf-planners th, table.xf-planners td { padding: 2px 7px; }
table.xf-planners td:first-child { white-space: nowrap; font-weight: 600; }
@page { size: A4 landscape; margin: 10mm; }
@media print { .xf-nav { display: none; } body { padding: 0; max-width: none; }
               .scroll { overflow: visible; } table.data { font-size: 0.8em; }
               h2 { break-after: avoid; } .cell, svg, .fig { break-inside: avoid; }
               .modebar-container { display: none !important; } }
"""

#: Sets plotly's global config before plotly.js loads (as plotly's own full-page output does):
#: MathJax 'local' so plotly never tries to fetch MathJax from the network.
_PLOTLY_CONFIG = "window.PlotlyConfig = {MathJaxConfig: 'local'};"


def esc(value: Any) -> str:
    """HTML-escape ``str(value)`` (quotes included); ``None`` becomes an empty string."""
    return "" if value is None else html.escape(str(value), quote=True)


def slug(text: str) -> str:
    """A lowercase ``[a-z0-9-]`` identifier fragment (for div ids and anchors)."""
    s = re.sub(r"[^a-z0-9]+", "-", str(text).lower()).strip("-")
    return s or "x"


def fmt_num(value: Any, digits: int = 1) -> str:
    """Format a number for a table: integers without decimals, others with ``digits``.

    A median of integer counts is an integer or ends in ``.5``, so ``fmt_num(142.0) == '142'``
    and ``fmt_num(142.5) == '142.5'``. NaN/None render as an em dash.
    """
    if value is None:
        return "\u2014"
    if isinstance(value, bool):
        return "yes" if value else "no"
    try:
        x = float(value)
    except (TypeError, ValueError):
        return str(value)
    if math.isnan(x):
        return "\u2014"
    if math.isinf(x):
        return "\u221e" if x > 0 else "-\u221e"
    if x.is_integer() and abs(x) < 1e15:
        return str(int(x))
    return f"{x:.{digits}f}"


def table(rows: Iterable[Sequence[Any]], header: Sequence[str] | None,
          formats: Sequence[Callable[[Any], str] | None] | None = None,
          css_class: str = "data", raw_html: bool = False) -> str:
    """An HTML table. ``formats[i]`` formats column *i* (``None``: :func:`fmt_num` for numbers).

    Cells are escaped unless ``raw_html`` (for callers that build escaped markup themselves).
    Numbers are right-aligned. ``header=None`` omits the header row.
    """
    out = [f'<table class="{esc(css_class)}">']
    if header is not None:
        out.append("<thead><tr>")
        out += [f"<th>{esc(h)}</th>" for h in header]
        out.append("</tr></thead>")
    out.append("<tbody>")
    for row in rows:
        out.append("<tr>")
        for i, v in enumerate(row):
            f = formats[i] if formats is not None and i < len(formats) else None
            numeric = isinstance(v, (int, float, np.number)) and not isinstance(v, (bool, np.bool_))
            text = f(v) if f is not None else (fmt_num(v) if numeric else str(v))
            cls = "num" if numeric else "txt"
            out.append(f'<td class="{cls}">{text if raw_html else esc(text)}</td>')
        out.append("</tr>")
    out.append("</tbody></table>")
    return "".join(out)


def kv_table(pairs: Iterable[tuple[str, Any]]) -> str:
    """A two-column key/value table (keys and values escaped)."""
    return table(((k, "\u2014" if v is None else str(v)) for k, v in pairs), None,
                 css_class="data kv")


class Page:
    """Collects HTML fragments and renders one self-contained page.

    Fragments passed to :meth:`add` must already be escaped (use :func:`esc`); :meth:`heading`
    and :meth:`paragraph` escape for you. Figures go through :meth:`figure`: their JSON is
    compacted and deduplicated (:mod:`.plotjson`) and drawn by one loader script at the end.
    """

    def __init__(self, title: str, eager: bool = False) -> None:
        from xfuzzy_rrt.report.plotjson import SharedStore

        self.title = title
        #: Draw every figure at load (a short page, or one that is printed) instead of as it
        #: scrolls into view.
        self.eager = eager
        self.parts: list[str] = []
        self.shared = SharedStore()
        self.figures: dict[str, Any] = {}
        self.data: dict[str, Any] = {}
        self.scripts: list[str] = []

    def add(self, fragment: str) -> None:
        self.parts.append(fragment)

    def heading(self, text: str, level: int = 2, anchor: str | None = None) -> None:
        ident = f' id="{esc(anchor)}"' if anchor else ""
        self.parts.append(f"<h{level}{ident}>{esc(text)}</h{level}>")

    def paragraph(self, text: str, css_class: str = "note") -> None:
        self.parts.append(f'<p class="{esc(css_class)}">{esc(text)}</p>')

    def figure(self, fig, div_id: str, height: int | None = None, links: bool = False) -> str:
        """Register ``fig`` under the fixed ``div_id``; return its placeholder ``<div>``.

        ``links``: a click on a point opens the relative URL in the point's ``customdata``.
        """
        from xfuzzy_rrt.report.plotjson import figure_spec

        if div_id in self.figures:
            raise ValueError(f"duplicate figure id {div_id!r}")
        if height is not None:
            fig.update_layout(height=height)
        h = int(fig.layout.height or 450)
        self.figures[div_id] = figure_spec(fig, self.shared)
        if links:
            self.figures[div_id]["links"] = True
        return (f'<div class="fig"><div id="{esc(div_id)}" class="plotly-graph-div" '
                f'style="height:{h}px; width:100%;"></div></div>')

    def json_data(self, key: str, value: Any) -> None:
        """Embed ``value`` as JSON (script-safe) under element id ``key``."""
        self.data[key] = value

    def script(self, js: str) -> None:
        """Page script run after the figure loader (no user text may be interpolated here)."""
        self.scripts.append(js)

    def render(self, plotly_src: str | None = None) -> str:
        """The page, with plotly.js embedded exactly once in the head -- or, with
        ``plotly_src``, loaded asynchronously from that *relative* path (the report site's one
        shared copy)."""
        from plotly.offline import get_plotlyjs

        from xfuzzy_rrt.report.plotjson import LOADER_JS, script_json

        blocks = [f'<script type="application/json" id="xf-shared">'
                  f"{script_json(self.shared.values)}</script>",
                  f'<script type="application/json" id="xf-figs">'
                  f"{script_json(self.figures)}</script>"]
        blocks += [f'<script type="application/json" id="{esc(k)}">{script_json(v)}</script>'
                   for k, v in self.data.items()]
        return "".join([
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n",
            f"<title>{esc(self.title)}</title>\n",
            f"<style>{CSS}</style>\n",
            f"<script>{_PLOTLY_CONFIG}</script>\n",
            ('<script type="text/javascript">' + get_plotlyjs() + "</script>\n")
            if plotly_src is None else
            # Loaded without blocking the page: text, tables and links are usable at once; the
            # loader draws figures when plotly.js has arrived.
            (f'<script async src="{esc(plotly_src)}" '
             'onload="window.__xfPlotly &amp;&amp; window.__xfPlotly()"></script>\n'),
            "</head>\n<body>\n",
            "\n".join(self.parts),
            "\n", "\n".join(blocks),
            "\n<script>", LOADER_JS, "\n".join(self.scripts),
            "\nXF.renderAll();" if self.eager else "", "</script>",
            "\n</body>\n</html>\n",
        ])
