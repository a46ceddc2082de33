"""Validation of planner arguments, shared by every planner (real exceptions, never assert)."""

from __future__ import annotations

import math

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.scenario import Scenario

#: Largest iteration budget accepted. Tree storage is preallocated per plan (and a trace needs
#: about 1.3 kB per iteration), so an absurd budget must fail cleanly, not exhaust memory.
MAX_ITER_LIMIT = 1_000_000


def check_planar_2dof(scenario: Scenario) -> None:
    if scenario.arm.dof != 2:
        raise InputError(scenario.source or scenario.name,
                         f"arm.links: the planners handle 2-DOF arms, this arm has {scenario.arm.dof}")


def check_positive(name: str, value: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise InputError(name, f"must be a positive number, got {value!r}")


def check_max_iter(max_iter: int) -> int:
    if isinstance(max_iter, bool) or not isinstance(max_iter, int):
        raise InputError("max_iter", f"must be an integer, got {max_iter!r}")
    if not 1 <= max_iter <= MAX_ITER_LIMIT:
        raise InputError("max_iter", f"must lie in [1, {MAX_ITER_LIMIT}], got {max_iter}")
    return max_iter
