"""Evidence sections shared by the report's scenario pages: the scenario's definition, the
rules that drove a Fuzzy-RRT run, and *Follow one plan* (rule firing, inputs and outputs per
iteration, and a drill-down that explains single expansions with the numbers ``xfuzzy-rrt
explain`` prints). The pages themselves are assembled by :mod:`.site`.
"""

from __future__ import annotations

import platform
import shlex

import numpy as np
import pandas as pd

from xfuzzy_rrt.geometry.scenario import Box, Circle
from xfuzzy_rrt.report import figures as F
from xfuzzy_rrt.report.html import Page, esc, kv_table, table


def _reproduce_line(cmd: str) -> str:
    return f'<p class="muted">Reproduce: <code>{esc(cmd)}</code></p>'


# ----------------------------------------------------------------------------------------------
# Sections
# ----------------------------------------------------------------------------------------------


def _version() -> str:
    from xfuzzy_rrt import __version__

    return __version__


def _versions() -> list[tuple[str, str]]:
    import numba
    import plotly

    return [("xfuzzy-rrt", _version()), ("python", platform.python_version()),
            ("numpy", np.__version__), ("numba", numba.__version__),
            ("pandas", pd.__version__), ("plotly", plotly.__version__)]


def _describe_obstacle(o) -> str:
    if isinstance(o, Circle):
        return (f"circle centre ({o.center[0]:g}, {o.center[1]:g}) m, radius {o.radius:g} m")
    if isinstance(o, Box):
        return (f"box x [{o.min[0]:g}, {o.max[0]:g}] m, y [{o.min[1]:g}, {o.max[1]:g}] m")
    return str(o)


def _scenario_details(s) -> str:
    deg = lambda q: "(" + ", ".join(f"{v:g}\u00b0" for v in q) + ")"  # noqa: E731
    pairs = [("file", s.source or None), ("description", s.description or None)]
    arms = getattr(s, "arms", (s.arm,))
    for a, arm in enumerate(arms):
        # one arm: the rows as always; several: each row names its arm ("arm 2 (right) links")
        who = ""
        if len(arms) > 1:
            names = getattr(s, "arm_names", ())
            who = f"arm {a + 1}" + (f" ({names[a]})" if a < len(names) and names[a] else "") + " "
        pairs += [
            (f"{who}links", ", ".join(f"{v:g} m" for v in arm.links)),
            (f"{who}base", f"({arm.base[0]:g}, {arm.base[1]:g}) m"),
            (f"{who}link radius", f"{arm.link_radius:g} m"),
            (f"{who}joint limits", ", ".join(f"[{lo:g}\u00b0, {hi:g}\u00b0]"
                                             for lo, hi in arm.joint_limits_deg)),
        ]
        if len(arms) > 1:
            sl = s.arm_slices()[a]
            pairs += [(f"{who}start", deg(s.start_deg[sl])), (f"{who}goal", deg(s.goal_deg[sl]))]
    if len(arms) == 1:
        pairs += [("start", deg(s.start_deg)), ("goal", deg(s.goal_deg))]
    pairs += [(f"obstacle {i + 1}", _describe_obstacle(o)) for i, o in enumerate(s.obstacles)]
    if not s.obstacles:
        pairs.append(("obstacles", "none"))
    return kv_table(pairs)


def cli_planner(label: str) -> str:
    """The ``plan --planner`` value that reruns a benchmark label whose rulebook is passed as
    ``--rulebook``: ``fuzzy-rrt:NAME`` -> ``fuzzy-rrt``, ``fuzzy-rrt-connect:NAME`` ->
    ``fuzzy-rrt-connect`` (Fuzzy-RRT refuses a Connect rulebook), anything else itself
    (:meth:`xfuzzy_rrt.planners.registry.Planner.cli_name`)."""
    from xfuzzy_rrt.planners.registry import lookup

    entry = lookup(label)
    return label if entry is None else entry.cli_name(label)


def takes_rulebook(label: str) -> bool:
    """A planner label whose planner plans with a rulebook (the registry says)."""
    from xfuzzy_rrt.planners.registry import lookup

    entry = lookup(label)
    return entry is not None and entry.takes_rulebook


def _plan_cmd(s, planner: str, seed: int, settings: dict) -> str:
    src = getattr(s, "source", "") or f"{s.name}.toml"
    planner = cli_planner(planner)
    cmd = (f"xfuzzy-rrt plan {shlex.quote(src)} --planner {shlex.quote(planner)} "
           f"--seed {int(seed)}")
    if settings.get("max_iter") is not None:
        cmd += f" --max-iter {int(settings['max_iter'])}"
    if takes_rulebook(planner) and settings.get("rulebook_dir"):
        cmd += f" --rulebook {shlex.quote(str(settings['rulebook_dir']))}"
    return cmd


def _follow_one_plan(page: Page, idx: int, s, run, rulebook, grid, settings: dict,
                     n_drill: int) -> None:
    """Rule-firing heatmap, inputs/outputs per iteration, and the drill-down of one run."""
    from xfuzzy_rrt.report.drilldown import drilldown_payload, per_scenario, select_iterations
    from xfuzzy_rrt.report.fuzzy_figures import firing_heatmap, io_series

    trace = run.trace
    page.heading(f"Rule firing, inputs and outputs, drill-down (seed {int(run.seed)})", level=3,
                 anchor=f"follow-{idx}")
    plan = _plan_cmd(s, settings.get("planner", "fuzzy-rrt"), run.seed, settings)
    page.add(page.figure(firing_heatmap(trace, rulebook), f"fig-s{idx}-firing"))
    page.add(page.figure(io_series(trace, rulebook=rulebook), f"fig-s{idx}-io"))
    page.add(_reproduce_line(f"{plan} --trace trace.parquet"))
    its = select_iterations(trace, per_scenario(n_drill))
    if not its:
        return
    key = f"drill-s{idx}-data"
    page.json_data(key, drilldown_payload(trace, rulebook, its))
    fig_id = f"fig-s{idx}-drill"
    fig = F.drilldown_figure(s, run, grid=grid)
    rb_flag = (f" --rulebook {shlex.quote(str(settings['rulebook_dir']))}"
               if settings.get("rulebook_dir") else "")
    explain = f"{plan} --trace trace.parquet && xfuzzy-rrt explain trace.parquet{rb_flag} --iteration"
    page.add(
        f'<div class="xf-drill" data-json="{esc(key)}" data-fig="{esc(fig_id)}" '
        f'data-cmd="{esc(explain)}">'
        f'<p class="note">Drill-down: {len(its)} of {int(run.iterations)} iterations (the first, '
        "the expansions that built the path, and some rejected samples), with the numbers "
        "<code>xfuzzy-rrt explain</code> prints: the inputs, the active terms with their "
        "degrees, every fired rule with its strength and contribution, the output, and what the "
        "planner did with it. Any other iteration: run the reproduce command with its number."
        "</p>"
        f'<label>Iteration <input type="range" min="0" max="{len(its) - 1}" value="0" '
        f'step="1" style="width: 60%;" aria-label="iteration"></label> '
        '<span class="xf-drill-label"></span>'
        '<div class="grid" style="grid-template-columns: minmax(0, 1fr) minmax(0, 1fr);">'
        f'<div class="cell">{page.figure(fig, fig_id)}</div>'
        '<div class="cell xf-drill-panel"></div></div>'
        '<div class="grid xf-drill-systems" style="grid-template-columns: repeat(2, minmax(0, 1fr));"></div>'
        '<p class="muted">Reproduce: <code class="xf-drill-cmd"></code></p></div>')


def _influence_table(run, rulebook, k: int = 3) -> str:
    """The rules that drove the example Fuzzy-RRT run: top ``k`` per output by influence."""
    from xfuzzy_rrt.analysis.firing import top_rules
    from xfuzzy_rrt.fuzzy.text_format import rule_sentence
    from xfuzzy_rrt.report.fuzzy_figures import semantics
    from xfuzzy_rrt.report.numbers import readable_numbers

    top = top_rules(run.trace, k=k)
    rows = []
    for _, row in top.iterrows():
        fis = rulebook.systems[list(semantics(rulebook)[1]).index(row["output"])]
        rows.append((row["output"], f"r{int(row['rule'])}",
                     readable_numbers(rule_sentence(fis, int(row["rule"]))),
                     f"{100 * row['share']:.1f}%", int(row["iterations_fired"])))
    intro = (f"<p>Rules that drove the example Fuzzy-RRT run (seed {int(run.seed)}, "
             f"{int(run.iterations)} iterations): for each output, the {k} rules with the largest "
             "share of the summed normalised firing strength over all iterations.</p>")
    return intro + table(rows, ["output", "rule", "sentence", "share", "iterations fired"])
