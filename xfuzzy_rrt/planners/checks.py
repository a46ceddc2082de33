"""Validation of planner arguments, shared by every planner (real exceptions, never assert)."""

from __future__ import annotations

import math

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.scenario import MAX_LINKS_PER_ARM, Scenario
from xfuzzy_rrt.planners.termination import MAX_ITER_LIMIT, check_max_iter  # noqa: F401


def check_dof(scenario: Scenario) -> None:
    """Every arm has 2..7 joints and the problem's configurations have one angle per joint."""
    where = scenario.source or scenario.name
    for a, arm in enumerate(scenario.arms):
        if not 2 <= arm.dof <= MAX_LINKS_PER_ARM:
            key = "arm.links" if len(scenario.arms) == 1 else f"arms[{a}].links"
            raise InputError(where, f"{key}: the planners handle arms of 2 to {MAX_LINKS_PER_ARM} "
                             f"joints, this arm has {arm.dof}")
    for which, q in (("start", scenario.start_deg), ("goal", scenario.goal_deg)):
        if len(q) != scenario.dof:
            raise InputError(where, f"{which}: {len(q)} angles for {scenario.dof} joints")


def check_plan_call(planner: str, scenario: Scenario, max_iter, margin, clearance_m,
                    **given) -> tuple[float, dict]:
    """The checks every tree planner's call opens with, in the order their errors are reported:
    the arms' joints, the clearance (against the start and goal), ``max_iter``, then every
    parameter of ``planner`` (``given``, with ``max_iter``). Returns the kernels' margin and
    the resolved parameters (:func:`~xfuzzy_rrt.planners.params.resolve_params`)."""
    from xfuzzy_rrt.geometry.clearance import planning_margin
    from xfuzzy_rrt.planners.params import resolve_params

    check_dof(scenario)
    margin = planning_margin(scenario, clearance_m, margin)
    check_max_iter(max_iter)
    return margin, resolve_params(planner, max_iter=max_iter, **given)


def check_positive(name: str, value: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise InputError(name, f"must be a positive number, got {value!r}")
