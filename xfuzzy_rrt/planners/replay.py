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
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook


def trace_for(source: Path, rulebook: Path | None = None):
    """Return ``(trace DataFrame, Rulebook)`` for a trace file or a plan-result JSON."""
    from xfuzzy_rrt.analysis.explain import NO_ITERATION, load_trace

    source = Path(source)
    if source.suffix.lower() == ".json":
        return _replay_result(source, rulebook)
    frame = load_trace(source)
    if len(frame) == 0:  # its rows name the rulebook; a run of no iteration has none
        raise InputError(str(source), NO_ITERATION)
    if rulebook is None:
        return frame, _rulebook_of_trace(frame, source)
    return frame, load_rulebook(rulebook)


def _rulebook_of_trace(frame, source: Path):
    """The rulebook that made a trace, found without the user's help when possible.

    Why: editing a copy of a shipped rulebook (``cp -r rulebooks/goal-frame mine``) keeps its
    name, so looking the name up among the shipped rulebooks found the *original* and blamed a
    ``--rulebook`` the user never passed. A trace written by ``plan --trace`` records the
    directory (``rulebook_dir``) and every trace the sha256; the recorded directory is used when
    its contents still hash to that sha256, else a shipped rulebook with that sha256; otherwise
    one line says which directory changed (or which name is unknown) and that ``--rulebook DIR``
    overrides.
    """
    name = str(frame["rulebook"].iloc[0]) if "rulebook" in frame and len(frame) else ""
    sha = str(frame["rulebook_sha256"].iloc[0]) if len(frame) else ""
    recorded = None
    if "rulebook_dir" in frame and len(frame) and isinstance(frame["rulebook_dir"].iloc[0], str):
        recorded = str(frame["rulebook_dir"].iloc[0]) or None
    if recorded is not None and Path(recorded).is_dir():
        rb = _load_or_none(Path(recorded))
        if rb is not None and rb.sha256 == sha:
            return rb
        now = f"sha256 now {rb.sha256[:12]}…" if rb is not None else "it no longer loads"
        raise InputError(str(source), f"rulebook_dir: the rulebook at {recorded} has changed since "
                         f"it made this trace ({now}, the trace's {sha[:12]}…); pass the "
                         "rulebook that made it with --rulebook DIR")
    shipped = _shipped_with_sha(name, sha)
    if shipped is not None:
        return shipped
    if recorded is not None:
        raise InputError(str(source), f"rulebook_dir: {recorded}, the rulebook that made this "
                         f"trace ({name!r}, sha256 {sha[:12]}…), no longer exists; pass it with "
                         "--rulebook DIR")
    raise InputError(str(source), f"rulebook: the trace was made with rulebook {name!r} (sha256 "
                     f"{sha[:12]}…), which is not a shipped rulebook; pass its directory with "
                     "--rulebook DIR")


def _load_or_none(directory: Path):
    from xfuzzy_rrt.errors import RulebookError

    try:
        return load_rulebook(directory)
    except RulebookError:
        return None


def _shipped_with_sha(name: str, sha: str):
    """The shipped rulebook whose contents hash to ``sha`` (the one named ``name`` first)."""
    from xfuzzy_rrt.fuzzy.rulebook import list_rulebooks

    candidates = sorted(list_rulebooks(), key=lambda p: p.name != name)
    for directory in candidates:
        rb = _load_or_none(directory)
        if rb is not None and rb.sha256 == sha:
            return rb
    return None


def _replay_result(path: Path, rulebook: Path | None):
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners import registry

    if not path.exists():
        raise InputError(str(path), "no such file")
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(str(path), f"not a JSON plan result: {exc}") from None
    # planner_used: what ran (plain fuzzy-rrt plans a problem that is not one 2-joint arm with
    # fuzzy-rrt-connect and goal-frame-any; planners/api.py:shipped_default)
    used = (data.get("planner_used") or data.get("planner")) if isinstance(data, dict) else None
    tracing = registry.exact_labels(traces=True)  # the planners that record traces
    if used not in tracing:
        raise InputError(str(path), f"planner: only {registry.either(tracing, 'and')} results can "
                         "be explained")
    for key in ("scenario_file", "rulebook_dir", "rulebook_sha256", "seed"):
        if key not in data:
            raise InputError(str(path), f"{key}: missing; re-run 'xfuzzy-rrt plan' to get a result "
                             "that records it, or pass a trace file")
    scenario = load_scenario(data["scenario_file"])
    sha = str(data["rulebook_sha256"])
    if rulebook is not None:
        rb = load_rulebook(rulebook)
        if rb.sha256 != sha:
            raise InputError("--rulebook", f"the rulebook at {rulebook} (sha256 {rb.sha256[:12]}…) "
                             f"is not the one that made {path} (sha256 {sha[:12]}…)")
    else:
        recorded = data["rulebook_dir"]
        rb = _load_or_none(Path(recorded)) if recorded and Path(recorded).is_dir() else None
        if rb is None or rb.sha256 != sha:
            rb = _shipped_with_sha(str(data.get("rulebook") or ""), sha)
        if rb is None:
            state = ("has changed since it made this result" if recorded and Path(recorded).is_dir()
                     else "no longer exists")
            raise InputError(str(path), f"rulebook_dir: the rulebook at {recorded} {state} (sha256 "
                             f"{sha[:12]}… recorded); pass the rulebook that made it with "
                             "--rulebook DIR")
    max_iter = int(data.get("params", {}).get("max_iter", 10_000))
    from xfuzzy_rrt.planners.api import plan_scenario

    # what ran (planner_used), with this rulebook, through the planner registry
    result = plan_scenario(scenario, used, rulebook=rb, seed=int(data["seed"]),
                           max_iter=max_iter, trace=True)
    if result.iterations != data.get("iterations"):
        raise InputError(str(path), "iterations: the replay does not reproduce this result")
    return result.trace, rb
