"""Compact, deduplicated, script-safe plotly figure JSON for the self-contained reports.

Why not ``fig.to_html``: a report with 24 scenarios and 3 planners holds ~300 figures, and the
naive output repeats the same bytes again and again -- plotly's 7 kB template in every figure,
the same C-obstacle map under every planner's run and the drill-down, float64 coordinates
where a drawing needs float32. Measured on the first edition: 5.1 MB for one scenario, of
which 4.8 MB plotly.js and 0.27 MB figures. Here:

- numeric arrays are plotly's typed-array form (``{"dtype", "bdata"}``, decoded by plotly.js
  itself); float64 becomes float32 (1e-5 degrees is far below a pixel);
- a 0/1 ``uint8`` matrix (a collision map) is bit-packed (``{"$bits", "shape"}``), 8x smaller;
- the layout template and any large array are stored once in a shared table and referenced
  (``{"$ref": key}``); the page's loader (:data:`LOADER_JS`) resolves references into fresh
  objects before ``Plotly.newPlot``;
- the JSON is made safe inside ``<script>``: ``<``, ``>`` and ``&`` are written as ``\\u003c``
  etc., so a user-supplied string such as ``</script>`` cannot end the script element.
"""

from __future__ import annotations

import base64
import contextlib
import hashlib
import json
import math
from typing import Any, Iterator

import numpy as np

#: Arrays whose encoding is at least this long (characters) are shared by reference.
SHARE_MIN_CHARS = 600


class SharedStore:
    """Values referenced from several figures, keyed by a short content hash."""

    def __init__(self) -> None:
        self.values: dict[str, Any] = {}

    def ref(self, value: Any) -> dict[str, str]:
        text = json.dumps(value, sort_keys=True, separators=(",", ":"))
        key = hashlib.sha1(text.encode("utf-8")).hexdigest()[:10]
        self.values.setdefault(key, value)
        return {"$ref": key}


def _b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii")


def _typed(array: np.ndarray) -> dict[str, Any]:
    """plotly.js typed-array spec of ``array`` (float64 demoted to float32)."""
    a = np.asarray(array)
    if a.dtype == np.bool_:
        a = a.astype(np.uint8)
    if a.dtype.kind == "f":
        a = a.astype("<f4")
        dtype = "f4"
    elif a.dtype.kind in "iu":
        lo, hi = (int(a.min()), int(a.max())) if a.size else (0, 0)
        for dt, name in (("<u1", "u1"), ("<i1", "i1"), ("<u2", "u2"), ("<i2", "i2"),
                         ("<i4", "i4")):
            info = np.iinfo(dt)
            if info.min <= lo and hi <= info.max:
                a = a.astype(dt)
                dtype = name
                break
        else:
            a = a.astype("<f8")
            dtype = "f8"
    else:
        raise TypeError(f"cannot encode array of dtype {a.dtype}")
    out: dict[str, Any] = {"dtype": dtype, "bdata": _b64(np.ascontiguousarray(a).tobytes())}
    if a.ndim > 1:
        out["shape"] = ",".join(str(n) for n in a.shape)
    return out


def _decode(spec: dict[str, Any]) -> np.ndarray:
    """plotly's own ``{"dtype", "bdata", "shape"}`` back to numpy."""
    dt = {"f8": "<f8", "f4": "<f4", "i1": "<i1", "u1": "<u1", "i2": "<i2", "u2": "<u2",
          "i4": "<i4", "u4": "<u4", "u1c": "<u1"}[spec["dtype"]]
    a = np.frombuffer(base64.b64decode(spec["bdata"]), dtype=dt)
    shape = spec.get("shape")
    if shape:
        a = a.reshape([int(n) for n in str(shape).split(",")])
    return a


def _bits(a: np.ndarray) -> dict[str, Any]:
    return {"$bits": _b64(np.packbits(a.astype(np.uint8).ravel()).tobytes()),
            "shape": [int(n) for n in a.shape]}


def _encode_array(a: np.ndarray, shared: SharedStore) -> Any:
    if a.dtype.kind in "iub" and a.ndim == 2 and a.size >= 256 and np.isin(a, (0, 1)).all():
        spec: Any = _bits(a)
    else:
        spec = _typed(a)
    size = len(spec.get("bdata", spec.get("$bits", "")))
    return shared.ref(spec) if size >= SHARE_MIN_CHARS else spec


def compact(value: Any, shared: SharedStore) -> Any:
    """Walk a ``fig.to_plotly_json()`` dict: typed arrays, bit maps, shared references."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fiub":
            return _encode_array(value, shared)
        return [compact(v, shared) for v in value.tolist()]
    if isinstance(value, dict):
        if set(value) >= {"dtype", "bdata"} and isinstance(value.get("bdata"), str):
            return _encode_array(_decode(value), shared)
        return {k: compact(v, shared) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [compact(v, shared) for v in value]
    if isinstance(value, (np.floating, float)):
        x = float(value)
        return x if math.isfinite(x) else None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    return value


#: What ``template="none"`` serialises to.
_EMPTY_TEMPLATE = {"data": {"scatter": [{"type": "scatter"}]}}
_PAGE_TEMPLATE: list[dict] = []


def page_template() -> dict[str, Any]:
    """The report's look (:data:`xfuzzy_rrt.report.figures.PAGE_TEMPLATE`), built once."""
    if not _PAGE_TEMPLATE:
        import plotly.io as pio

        from xfuzzy_rrt.report.figures import PAGE_TEMPLATE

        _PAGE_TEMPLATE.append(pio.templates[PAGE_TEMPLATE].to_plotly_json())
    return _PAGE_TEMPLATE[0]


@contextlib.contextmanager
def no_default_template() -> Iterator[None]:
    """Build figures without plotly's default template object (see ``figures.TEMPLATE``)."""
    import plotly.io as pio

    previous = pio.templates.default
    pio.templates.default = "none"
    try:
        yield
    finally:
        pio.templates.default = previous


def figure_spec(fig, shared: SharedStore, config: dict[str, Any] | None = None) -> dict[str, Any]:
    """``{"data", "layout", "config"}`` for ``Plotly.newPlot``, compacted; the template shared."""
    raw = fig.to_plotly_json()
    layout = dict(raw.get("layout") or {})
    template = layout.pop("template", None)
    if not template or template == _EMPTY_TEMPLATE:
        template = page_template()
    spec = {"data": compact(raw.get("data") or [], shared), "layout": compact(layout, shared),
            "config": config or {"displaylogo": False, "responsive": True}}
    if template is not None:
        spec["layout"]["template"] = shared.ref(compact(template, SharedStore()))
    return spec


def script_json(value: Any) -> str:
    """JSON text safe to embed in ``<script type="application/json">``."""
    text = json.dumps(value, separators=(",", ":"), ensure_ascii=False, allow_nan=False)
    return (text.replace("&", "\\u0026").replace("<", "\\u003c").replace(">", "\\u003e")
            .replace("\u2028", "\\u2028").replace("\u2029", "\\u2029"))


#: The page's figure loader: resolves references and bit maps, renders each figure when it
#: comes near the viewport (a 24-scenario report has hundreds), all of them before printing.
#: ``XF.renderAll()`` is also what the browser test calls.
LOADER_JS = r"""
window.XF = (function () {
  var shared = JSON.parse(document.getElementById('xf-shared').textContent);
  var figs = JSON.parse(document.getElementById('xf-figs').textContent);
  var done = {};
  function bytes(s) { var b = atob(s), u = new Uint8Array(b.length);
    for (var i = 0; i < b.length; i++) u[i] = b.charCodeAt(i); return u; }
  function resolve(v) {
    if (Array.isArray(v)) return v.map(resolve);
    if (v && typeof v === 'object') {
      if ('$ref' in v) return resolve(shared[v['$ref']]);
      if ('$bits' in v) {
        var by = bytes(v['$bits']), r = v.shape[0], c = v.shape[1], rows = [];
        for (var i = 0; i < r; i++) { var row = new Uint8Array(c);
          for (var j = 0; j < c; j++) { var k = i * c + j; row[j] = (by[k >> 3] >> (7 - (k & 7))) & 1; }
          rows.push(row); }
        return rows;
      }
      var o = {}; for (var key in v) o[key] = resolve(v[key]); return o;
    }
    return v;
  }
  // plotly.js may arrive after this script (loaded async from the report folder).
  var plotly = window.Plotly ? Promise.resolve() : new Promise(function (ok) { window.__xfPlotly = ok; });
  function render(id) {
    if (done[id] || !figs[id]) return done[id] || null;
    var f = resolve(figs[id]);
    done[id] = plotly.then(function () { return Plotly.newPlot(id, f.data, f.layout, f.config); }).then(function (gd) {
      if (f.links) gd.on('plotly_click', function (e) {
        var u = e.points && e.points[0] && e.points[0].customdata;
        if (typeof u === 'string' && u) window.location.href = u;
      });
      return gd;
    });
    return done[id];
  }
  function renderAll() { return Promise.all(Object.keys(figs).map(render)); }
  if ('IntersectionObserver' in window) {
    var io = new IntersectionObserver(function (entries) {
      entries.forEach(function (e) { if (e.isIntersecting) { io.unobserve(e.target); render(e.target.id); } });
    }, {rootMargin: '1200px 0px'});
    Object.keys(figs).forEach(function (id) { var el = document.getElementById(id); if (el) io.observe(el); });
  } else { renderAll(); }
  window.addEventListener('beforeprint', renderAll);
  return {render: render, renderAll: renderAll, resolve: resolve, figs: figs, done: done,
          plotly: plotly};
})();
"""
