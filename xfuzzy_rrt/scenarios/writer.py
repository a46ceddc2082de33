"""Scenario TOML text: ``[arm]`` for one arm (the shared format), ``[[arms]]`` for several.

The one writer every generated file goes through. A single-arm scenario is written exactly as
the generator always wrote it (``[arm]``, ``[start]``, ``[goal]``; ``base`` and
``joint_limits_deg`` only when they differ from the format's defaults), so old outputs stay
byte-identical. A scenario with several arms is written in the project's extension
(``docs/scenarios.md``): one ``[[arms]]`` table per arm carrying its own ``start_deg`` and
``goal_deg``. Either text loads back into an equal :class:`~xfuzzy_rrt.geometry.scenario.Scenario`
(numbers are written with ``repr``, which round-trips a float exactly).
"""

from __future__ import annotations

from xfuzzy_rrt.geometry.scenario import Arm, Circle, Scenario

__all__ = ["scenario_toml"]

_DEFAULT_LIMIT = (-180.0, 180.0)


def _num(x: float) -> str:
    return repr(float(x))


def _nums(values) -> str:
    return f"[{', '.join(_num(v) for v in values)}]"


def _string(text: str) -> str:
    """A TOML basic string (plain text comes out as ``"text"``)."""
    out = text.replace("\\", "\\\\").replace('"', '\\"')
    out = out.replace("\n", "\\n").replace("\r", "\\r").replace("\t", "\\t")
    return f'"{out}"'


def _arm_lines(arm: Arm) -> list[str]:
    lines = [f"links = {_nums(arm.links)}"]
    if tuple(arm.base) != (0.0, 0.0):
        lines.append(f"base = {_nums(arm.base)}")
    lines.append(f"link_radius = {_num(arm.link_radius)}")
    limits = tuple(tuple(p) for p in arm.joint_limits_deg)
    if limits and any(p != _DEFAULT_LIMIT for p in limits):
        lines.append(f"joint_limits_deg = [{', '.join(_nums(p) for p in limits)}]")
    return lines


def scenario_toml(s: Scenario, description: str) -> str:
    """The TOML text of ``s`` with ``description`` (``[arm]`` or ``[[arms]]``, see module doc)."""
    lines = [f"name = {_string(s.name)}", f"description = {_string(description)}"]
    if len(s.arms) == 1:
        lines += ["", "[arm]", *_arm_lines(s.arm),
                  "", "[start]", f"q_deg = {_nums(s.start_deg)}",
                  "", "[goal]", f"q_deg = {_nums(s.goal_deg)}"]
    else:
        names = s.arm_names or ("",) * len(s.arms)
        for arm, sl, arm_name in zip(s.arms, s.arm_slices(), names):
            lines += ["", "[[arms]]"]
            if arm_name:
                lines.append(f"name = {_string(arm_name)}")
            lines += [*_arm_lines(arm), f"start_deg = {_nums(s.start_deg[sl])}",
                      f"goal_deg = {_nums(s.goal_deg[sl])}"]
    if s.clearance_m:
        lines += ["", "[safety]", f"clearance_m = {_num(s.clearance_m)}"]
    for o in s.obstacles:
        lines += ["", "[[obstacles]]"]
        if isinstance(o, Circle):
            lines += ['type = "circle"', f"center = {_nums(o.center)}", f"radius = {_num(o.radius)}"]
        else:
            lines += ['type = "box"', f"min = {_nums(o.min)}", f"max = {_nums(o.max)}"]
    return "\n".join(lines) + "\n"
