"""Self-contained, offline HTML audit reports built with plotly.

Why a separate layer: reports are for people (safety auditors, researchers) who read results
after the fact, so nothing here is ever on the planning path. The package is imported lazily by
the CLI (plotly is heavy) and only reads the stable objects and tables the lower layers produce
(``BenchResult``, ``PlanResult``, ``Scenario``, trace/run DataFrames) -- never a planner's
internals.

Modules:

- :mod:`.html` -- page assembly: plotly.js embedded once, or loaded from the report folder's
  one shared copy (no network, no CDN), escaped text, formatted tables, figures with fixed div
  ids so that the output is deterministic.
- :mod:`.plotjson` -- compact, deduplicated, script-safe figure JSON and the loader that draws
  it (why a 24-scenario report stays under 10 MB).
- :mod:`.figures` -- reusable figures: joint-space map (C-obstacles, tree, path), workspace
  (obstacles, arm poses, end-effector trace), box plots of runs, outcome counts of a trace,
  the drill-down's joint-space map.
- :mod:`.fuzzy_figures` -- rule firing over a run, inputs/outputs per iteration, membership
  functions, rule surfaces, training curve, ratio distribution.
- :mod:`.drilldown` -- one expansion explained in the page, with ``explain``'s numbers.
- :mod:`.site` -- the ``xfuzzy-rrt bench`` report: ``report.html`` (the overview that answers
  on the first screen) and ``report/`` (a page per scenario and per rulebook, plotly.js).
- :mod:`.overview` -- the first screen's numbers and verdict sentences, from ``runs.csv``.
- :mod:`.ratio_svg` -- the overview's ratio plot as inline SVG (drawn before any script).
- :mod:`.evidence` -- scenario definition, rules that drove a run, *Follow one plan*.
- :mod:`.numbers` -- numbers as people read them (3-4 significant digits with units).
- :mod:`.pdf` -- ``report --pdf`` through headless Chromium.
"""
