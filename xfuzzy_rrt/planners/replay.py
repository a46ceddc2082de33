"""Recover a Fuzzy-RRT trace from what a user has at hand: a trace file or a plan result.

A plan result (``plan --out result.json``) records the scenario file, the rulebook directory
and its sha256; because planning is deterministic, re-running it with tracing on reproduces the
exact trace of that run. The rulebook's sha256 is checked so that an edited rulebook cannot be
mistaken for the one that made the decisions.
"""

from __future__ import annotations

import json
from pathlib import Path

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir


def trace_for(source: Path, rulebook: Path | None = None):
    """Return ``(trace DataFrame, Rulebook)`` for a trace file or a plan-result JSON."""
    from xfuzzy_rrt.analysis.explain import load_trace

    source = Path(source)
    if source.suffix.lower() == ".json":
        return _replay_result(source, rulebook)
    frame = load_trace(source)
    if rulebook is None:
        # The trace names its rulebook; look for a shipped one of that name.
        name = str(frame["rulebook"].iloc[0]) if "rulebook" in frame and len(frame) else ""
        candidate = rulebooks_dir() / name
        if not name or not candidate.is_dir():
            raise InputError("--rulebook", f"the trace was made with rulebook {name!r}, which is not "
                             "shipped; pass its directory with --rulebook")
        rulebook = candidate
    return frame, load_rulebook(rulebook)


def _replay_result(path: Path, rulebook: Path | None):
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt

    if not path.exists():
        raise InputError(str(path), "no such file")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(str(path), f"not a JSON plan result: {exc}") from None
    if not isinstance(data, dict) or data.get("planner") not in ("fuzzy-rrt", "fuzzy-rrt-connect"):
        raise InputError(str(path), "planner: only fuzzy-rrt and fuzzy-rrt-connect results can "
                         "be explained")
    for key in ("scenario_file", "rulebook_dir", "rulebook_sha256", "seed"):
        if key not in data:
            raise InputError(str(path), f"{key}: missing; re-run 'xfuzzy-rrt plan' to get a result "
                             "that records it, or pass a trace file")
    scenario = load_scenario(data["scenario_file"])
    rulebook_dir = rulebook if rulebook is not None else data["rulebook_dir"]
    rb = load_rulebook(rulebook_dir)
    if rb.sha256 != data["rulebook_sha256"]:
        raise InputError(str(path), f"rulebook_sha256: the rulebook at {rulebook_dir} is not the "
                         "one that made this result (it was edited or replaced)")
    max_iter = int(data.get("params", {}).get("max_iter", 10_000))
    plan = plan_fuzzy_rrt
    if data["planner"] == "fuzzy-rrt-connect":
        from xfuzzy_rrt.planners.connect import plan_fuzzy_rrt_connect as plan
    result = plan(scenario, rb, seed=int(data["seed"]), max_iter=max_iter, trace=True)
    if result.iterations != data.get("iterations"):
        raise InputError(str(path), "iterations: the replay does not reproduce this result")
    return result.trace, rb
