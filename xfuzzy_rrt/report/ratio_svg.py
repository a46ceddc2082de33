"""The overview's ratio plot as inline SVG: drawn with the page, before any script runs.

Why not plotly here: the ratio plot is half of the answer on the first screen, and plotly.js
(4.8 MB) takes 0.5-3 s to parse and start on a busy two-core machine. An SVG of a few dozen
points is in the HTML itself, so the first screen is complete and clickable as soon as the page
is parsed; each point is a real link (``<a href>``) to its scenario's page, which also works in
the printed PDF and lets a test check that every link resolves.

One panel per planner: its per-scenario ratios to RRT sorted ascending, on a log axis with the
ticks a person reads (0.5 1 2 5 10 ...), a dashed line at 1, losing scenarios (ratio below 1)
in red. Hovering a point shows its scenario and ratio (``<title>``).
"""

from __future__ import annotations

import math

from xfuzzy_rrt.report.html import esc
from xfuzzy_rrt.report.numbers import ratio as fmt_ratio
from xfuzzy_rrt.report.numbers import sig

#: Log-axis ticks a person reads at a glance.
TICKS = (0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100, 200,
         500, 1000, 2000, 5000)
LOSE = "#b2182b"


def axis_range(values: list[float]) -> tuple[float, float, list[float]]:
    """``(lo, hi, ticks)``: a log range holding every value and 1, padded, and the ticks in it
    (at least 0.5, 1 and 2 around 1)."""
    fin = [v for v in values if v > 0 and math.isfinite(v)]
    lo = min(fin + [0.5])
    hi = max(fin + [2.0])
    lo, hi = lo / 1.25, hi * 1.25
    ticks = [t for t in TICKS if lo <= t <= hi]
    if len(ticks) > 9:  # keep 1-2-5 steps readable: only powers of ten and 1
        ticks = [t for t in ticks if math.log10(t).is_integer()]
    return lo, hi, ticks


def ratio_svg(panels: list[dict], width: int = 1340, height: int = 250) -> str:
    """An ``<svg>`` with one panel per entry of ``panels``: ``{"title", "color", "points":
    [(scenario, ratio, href), ...]}`` (points in any order; drawn sorted)."""
    values = [r for p in panels for _, r, _ in p["points"]]
    lo, hi, ticks = axis_range(values)
    n = max(1, len(panels))
    left, gap, top, bottom = 56, 24, 30, 26
    pw = (width - left - gap * (n - 1) - 8) / n
    ph = height - top - bottom
    ly0, ly1 = math.log10(lo), math.log10(hi)

    def y(v: float) -> float:
        return top + ph * (1 - (math.log10(v) - ly0) / (ly1 - ly0))

    out = [f'<svg class="xf-ratio" id="ratio-plot" xmlns="http://www.w3.org/2000/svg" '
           f'viewBox="0 0 {width} {height}" width="100%" role="img" '
           'aria-label="per-scenario ratio to RRT, one panel per planner" '
           'style="max-width: 100%; font: 11px sans-serif;">']
    out.append(f'<text x="12" y="{top + ph / 2:.1f}" transform="rotate(-90 12 {top + ph / 2:.1f})" '
               'text-anchor="middle" fill="#444">RRT / planner (log; &gt; 1: better)</text>')
    for k, panel in enumerate(panels):
        x0 = left + k * (pw + gap)
        out.append(f'<g class="xf-panel" data-planner="{esc(panel["title"])}">')
        out.append(f'<text x="{x0:.1f}" y="{top - 10}" font-weight="600" fill="#222">'
                   f'{esc(panel["title"])}</text>')
        out.append(f'<rect x="{x0:.1f}" y="{top}" width="{pw:.1f}" height="{ph}" fill="#fbfbfb" '
                   'stroke="#ccc"/>')
        for t in ticks:
            yt = y(t)
            dash = ' stroke-dasharray="5 4" stroke="#444"' if t == 1 else ' stroke="#e6e6e6"'
            out.append(f'<line x1="{x0:.1f}" x2="{x0 + pw:.1f}" y1="{yt:.1f}" y2="{yt:.1f}"{dash}/>')
            if k == 0:
                out.append(f'<text x="{x0 - 6:.1f}" y="{yt + 4:.1f}" text-anchor="end" '
                           f'fill="#444">{esc(sig(t, 3))}</text>')
        pts = sorted(((r, s, h) for s, r, h in panel["points"]
                      if r > 0 and math.isfinite(r)), key=lambda p: p[0])
        m = len(pts)
        for i, (r, s, h) in enumerate(pts):
            cx = x0 + pw * (i + 0.5) / max(m, 1)
            color = panel["color"] if r >= 1 else LOSE
            out.append(f'<a href="{esc(h)}" class="xf-point"><circle cx="{cx:.1f}" '
                       f'cy="{y(r):.1f}" r="5" fill="{color}" stroke="white" stroke-width="1">'
                       f'<title>{esc(s)}: {esc(fmt_ratio(r))}</title></circle></a>')
        losses = sum(1 for r, _, _ in pts if r < 1)
        out.append(f'<text x="{x0 + pw / 2:.1f}" y="{height - 8}" text-anchor="middle" '
                   f'fill="#666">{m} scenarios, sorted; {losses} below 1 (red)</text>')
        out.append("</g>")
    out.append("</svg>")
    return "".join(out)
