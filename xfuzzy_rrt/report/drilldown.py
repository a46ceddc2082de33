"""The report's drill-down: one Fuzzy-RRT expansion, from inputs to sampled point, in the page.

Why it reuses :mod:`xfuzzy_rrt.analysis.explain` instead of computing anything: the auditor
must see *the same numbers* ``xfuzzy-rrt explain`` prints. So each selected iteration is
explained by :func:`~xfuzzy_rrt.analysis.explain.explain_row` and its numbers are formatted with
the very format functions of :mod:`.explain_text` that the command uses (4 significant digits,
units from the rulebook; the tests check every string against its output).

Why only some iterations: one iteration costs ~2 kB (six systems, up to 16 rules each), and a
report may hold dozens of scenarios. :func:`select_iterations` keeps
the expansions that built the returned path (plus the first iteration and a few rejections),
within a per-report budget; any other iteration is one ``explain`` command away (the page
gives it).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from xfuzzy_rrt.analysis.explain import Explanation, explain_row, render_text

#: Drill-down iterations for the whole report, shared between scenarios...
BUDGET_ITERATIONS = 120
#: ...with at least / at most this many per scenario.
MIN_PER_SCENARIO = 5
MAX_PER_SCENARIO = 40


def per_scenario(n_scenarios: int) -> int:
    return int(np.clip(BUDGET_ITERATIONS // max(1, n_scenarios), MIN_PER_SCENARIO,
                       MAX_PER_SCENARIO))


def _even(values: np.ndarray, k: int) -> list[int]:
    if k <= 0 or values.size == 0:
        return []
    if values.size <= k:
        return [int(v) for v in values]
    idx = np.unique(np.round(np.linspace(0, values.size - 1, k)).astype(int))
    return [int(values[i]) for i in idx]


def select_iterations(trace: pd.DataFrame, k: int) -> list[int]:
    """Up to ``k`` iterations: the first, the expansions on the returned path (evenly spread,
    the last one included), then evenly spread rejected ones; ascending."""
    its = trace["iteration"].to_numpy()
    on_path = its[trace["on_path"].to_numpy(dtype=bool)] if "on_path" in trace else its[:0]
    chosen = {int(its[0])} if its.size else set()
    n_path = max(0, min(on_path.size, k - 1 - max(1, k // 5)))
    chosen.update(_even(on_path, n_path))
    outcome = trace["outcome"].astype(str).to_numpy()
    rejected = np.setdiff1d(its[outcome != "accepted"], on_path)
    chosen.update(_even(np.setdiff1d(rejected, np.fromiter(chosen, dtype=its.dtype,
                                                            count=len(chosen))),
                        k - len(chosen)))
    if len(chosen) < k:
        rest = np.setdiff1d(its, np.fromiter(chosen, dtype=its.dtype, count=len(chosen)))
        chosen.update(_even(rest, k - len(chosen)))
    return sorted(chosen)[:k]


def _num(x: Any) -> float | None:
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if np.isfinite(v) else None


def iteration_record(e: Explanation, consts: dict[str, dict[str, Any]],
                     units: dict[str, str] | None = None) -> dict[str, Any]:
    """One iteration for the page: strings as ``xfuzzy-rrt explain`` prints them (readable
    numbers, :mod:`.explain_text`), coordinates as numbers.

    Per system: ``[output, active, rules, value, recorded]`` where ``active`` is ``None`` when
    identical to the previous system's (the usual case: shared partitions) and each rule is
    ``[index, strength, contribution]``; rule constants go once into ``consts`` (per output).
    """
    from xfuzzy_rrt.report.explain_text import (decision_lines, fmt_constant, fmt_degree,
                                                fmt_input, fmt_strength, fmt_value, input_note)

    units = units or {}
    systems = []
    previous = None
    for s in e.systems:
        book = consts.setdefault(s.output, {})
        for r in s.rules:
            book.setdefault(str(r.index), fmt_constant(r.constant))
        active = [[name, ", ".join(f"{t.term} {fmt_degree(t.degree)}" for t in terms)]
                  for name, terms in s.active.items()]
        systems.append([s.output, None if active == previous else active,
                        [[r.index, fmt_strength(r.strength), fmt_strength(r.contribution)]
                         for r in s.rules],
                        fmt_value(s.value), fmt_value(s.traced_value)])
        previous = active
    d = e.decision
    return {
        "iteration": e.iteration,
        "inputs": [[n, fmt_input(e.clamped_inputs[n], units.get(n, "")),
                    input_note(e.inputs[n], e.clamped_inputs[n], units.get(n, ""))]
                   for n in e.inputs],
        "systems": systems,
        "decision": decision_lines(render_text(e)),
        "outcome": str(d.get("outcome", "")),
        "box": [_num(d.get(k)) for k in ("box_q1_lo", "box_q1_hi", "box_q2_lo", "box_q2_hi")],
        "from": [_num(d.get("from_q1_deg")), _num(d.get("from_q2_deg"))],
        "sample": [_num(d.get("sample_q1_deg")), _num(d.get("sample_q2_deg"))],
        "new": [_num(d.get("new_q1_deg")), _num(d.get("new_q2_deg"))],
        "discrepancy": f"{e.max_discrepancy:.3g}",
    }


def drilldown_payload(trace: pd.DataFrame, rulebook, iterations: list[int]) -> dict[str, Any]:
    """The JSON the page's drill-down script reads, for the given iterations of ``trace``.

    Rule sentences are not stored: the script writes them from the term names given here
    exactly as :func:`~xfuzzy_rrt.fuzzy.text_format.rule_sentence` does (rule index
    ``((t0*5 + t1)*5 + t2)*5 + t3``) -- the browser test compares the two.
    """
    from xfuzzy_rrt.analysis.explain import trace_row

    from xfuzzy_rrt.report.explain_text import units_of

    consts: dict[str, dict[str, Any]] = {}
    units = units_of(rulebook)
    records = [iteration_record(explain_row(trace_row(trace, it), rulebook), consts, units)
               for it in iterations]
    terms = {s.output: [[i.name, list(i.terms)] for i in s.inputs] for s in rulebook.systems}
    return {"rulebook": rulebook.name, "bounds_mode": rulebook.bounds_mode,
            "iterations": records, "consts": consts, "terms": terms}


#: Renders a drill-down from its JSON with DOM text nodes only (no innerHTML: rule sentences
#: and term names come from user files). One instance per ``.xf-drill`` element.
DRILL_JS = r"""
(function () {
  function el(tag, text, cls) { var e = document.createElement(tag);
    if (text !== undefined && text !== null) e.textContent = text; if (cls) e.className = cls; return e; }
  function row(cells, header) { var tr = el('tr');
    cells.forEach(function (c) { tr.appendChild(el(header ? 'th' : 'td', c)); }); return tr; }
  function tableOf(header, rows) { var t = el('table', null, 'data'), th = el('thead'), tb = el('tbody');
    th.appendChild(row(header, true)); rows.forEach(function (r) { tb.appendChild(row(r)); });
    t.appendChild(th); t.appendChild(tb); return t; }
  document.querySelectorAll('.xf-drill').forEach(function (root) {
    var data = JSON.parse(document.getElementById(root.dataset.json).textContent);
    var slider = root.querySelector('input[type=range]');
    var label = root.querySelector('.xf-drill-label');
    var panel = root.querySelector('.xf-drill-panel');
    var systems = root.querySelector('.xf-drill-systems');
    var cmd = root.querySelector('.xf-drill-cmd');
    var figId = root.dataset.fig;
    function sentence(out, r, constText) {
      var t = [], k = r;
      for (var i = 0; i < 4; i++) { t.unshift(k % 5); k = Math.floor(k / 5); }
      var ins = data.terms[out];
      return 'if ' + ins.map(function (inp, i) { return inp[0] + ' is ' + inp[1][t[i]]; }).join(' and ')
        + ' then ' + out + ' = ' + constText;
    }
    function show(k) {
      var it = data.iterations[k];
      label.textContent = 'iteration ' + it.iteration + ' (' + it.outcome + '), ' + (k + 1) + ' of ' + data.iterations.length + ' shown';
      cmd.textContent = root.dataset.cmd + ' ' + it.iteration;
      panel.textContent = '';
      panel.appendChild(el('h4', 'Inputs (clamped to the ranges)'));
      panel.appendChild(tableOf(['input', 'value', 'note'], it.inputs));
      panel.appendChild(el('h4', 'Decision'));
      var pre = el('pre', it.decision.join('\n')); panel.appendChild(pre);
      panel.appendChild(el('p', 'max |recomputed - recorded| = ' + it.discrepancy, 'muted'));
      systems.textContent = '';
      var active = null;
      it.systems.forEach(function (s) {
        var out = s[0]; active = s[1] || active;
        var box = el('div', null, 'cell');
        box.appendChild(el('h4', out + ' = ' + s[3] + ' (planner recorded ' + s[4] + ')'));
        box.appendChild(tableOf(['input', 'active terms (degree)'], active));
        box.appendChild(tableOf(['rule', 'sentence', 'strength', 'constant', 'contribution'],
          s[2].map(function (r) { var c = data.consts[out][String(r[0])];
            return ['r' + r[0], sentence(out, r[0], c), r[1], c, r[2]]; })));
        systems.appendChild(box);
      });
      var p = XF.render(figId);
      if (p && p.then) p.then(function () {
        var b = it.box;
        Plotly.relayout(figId, {shapes: [{type: 'rect', xref: 'x', yref: 'y', x0: b[0], x1: b[1], y0: b[2], y1: b[3],
          line: {color: '#D55E00', width: 2, dash: 'dash'}, fillcolor: 'rgba(213,94,0,0.08)'}]});
        var n = document.getElementById(figId).data.length;
        Plotly.restyle(figId, {x: [[it.from[0], it.sample[0], it.new[0]]], y: [[it.from[1], it.sample[1], it.new[1]]]}, [n - 1]);
      });
    }
    slider.addEventListener('input', function () { show(parseInt(slider.value, 10)); });
    show(parseInt(slider.value, 10));
  });
})();
"""
