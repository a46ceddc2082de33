"""Self-contained, offline HTML audit reports built with plotly.

Why a separate layer: reports are for people (safety auditors, researchers) who read results
after the fact, so nothing here is ever on the planning path. The package is imported lazily by
the CLI (plotly is heavy) and only reads the stable objects and tables the lower layers produce
(``BenchResult``, ``PlanResult``, ``Scenario``, trace/run DataFrames) -- never a planner's
internals.

Modules:

- :mod:`.html` -- page assembly: one ``<script>`` with plotly.js in the head (no network, no
  CDN), escaped text, formatted tables, figures with fixed div ids so that the output is
  deterministic.
- :mod:`.plotjson` -- compact, deduplicated, script-safe figure JSON and the loader that draws
  it (why a 24-scenario report stays under 10 MB).
- :mod:`.figures` -- reusable figures: joint-space map (C-obstacles, tree, path), workspace
  (obstacles, arm poses, end-effector trace), box plots of runs, outcome counts of a trace,
  the drill-down's joint-space map.
- :mod:`.fuzzy_figures` -- rule firing over a run, inputs/outputs per iteration, membership
  functions, rule surfaces, training curve, ratio distribution.
- :mod:`.drilldown` -- one expansion explained in the page, with ``explain``'s numbers.
- :mod:`.bench_report` -- the ``xfuzzy-rrt bench`` report (``report.html``).
"""
