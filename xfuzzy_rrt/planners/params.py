"""Named planner parameters with defaults and ranges (OMPL's ``ParamSet``, in small).

Each planner declares its parameters here once; :func:`resolve_params` fills defaults and
validates values with one clear error naming the parameter, and results and manifests record
the resolved set (``PlanResult.params``), so a run says exactly how it was configured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.planners.termination import MAX_ITER_LIMIT, MAX_TIME_LIMIT_S


@dataclass(frozen=True)
class Param:
    name: str
    default: float | int | None
    lo: float
    hi: float
    unit: str
    doc: str
    integer: bool = False
    #: ``lo`` itself allowed (``[lo, hi]``) or not (``(lo, hi]``).
    lo_closed: bool = True


_COMMON = (
    Param("max_iter", 10_000, 1, MAX_ITER_LIMIT, "iterations",
          "iteration budget: every sample counts, accepted or not", integer=True),
    Param("max_time_s", None, 0.0, MAX_TIME_LIMIT_S, "s",
          "wall-clock budget (none by default); whichever budget ends first stops the run",
          lo_closed=False),
)

PARAMS: dict[str, tuple[Param, ...]] = {
    "rrt": _COMMON + (
        # Up to 1440 degrees (360 until the thirty-first session): the joint-space diameter
        # is 360 * sqrt(joints), 952 degrees at 7 joints, and RRT's best step there lies past
        # 360 (xfuzzy_rrt.planners.tuned, "Per arm shape"); 1440 covers 16 joints.
        Param("step_deg", 10.0, 0.0, 1440.0, "deg", "largest joint-space extension",
              lo_closed=False),
        Param("goal_bias", 0.05, 0.0, 1.0, "", "probability of sampling the goal"),
    ),
    "fuzzy-rrt": _COMMON + (
        Param("min_step_deg", 0.5, 0.0, 30.0, "deg",
              "smallest step whatever the rulebook says (a rulebook answering 0 cannot stall "
              "the search)", lo_closed=False),
    ),
}


def default(planner: str, name: str):
    """The declared default of parameter ``name`` (the one place a default is written)."""
    return next(p.default for p in PARAMS[planner] if p.name == name)


def describe(planner: str) -> list[Param]:
    """The parameters of ``planner``: ``rrt`` or ``fuzzy-rrt``, or any registered planner label
    whose registration declares them (:attr:`xfuzzy_rrt.planners.registry.Planner.params`: a
    key of :data:`PARAMS` or the declaration itself)."""
    declared = PARAMS.get(planner)
    if declared is None:
        from xfuzzy_rrt.planners.registry import lookup

        form = lookup(planner)
        declared = getattr(form, "params", None)
        if isinstance(declared, str):
            declared = PARAMS.get(declared)
    if declared is None:
        raise InputError("planner", f"no parameters are declared for {planner!r} "
                         f"(known: {', '.join(PARAMS)})")
    return list(declared)


def resolve_params(planner: str, **given) -> dict:
    """Defaults filled in, every value checked against its range; one InputError otherwise."""
    known = {p.name: p for p in describe(planner)}
    for name in given:
        if name not in known:
            raise InputError(name, f"is not a parameter of {planner} (parameters: "
                             f"{', '.join(known)})")
    out = {}
    for name, p in known.items():
        value = given.get(name)
        if value is None:
            out[name] = p.default
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                (p.integer and not float(value).is_integer()):
            kind = "an integer" if p.integer else "a number"
            raise InputError(name, f"must be {kind}, got {value!r}")
        v = float(value)
        ok = math.isfinite(v) and (v >= p.lo if p.lo_closed else v > p.lo) and v <= p.hi
        if not ok:
            left = "[" if p.lo_closed else "("
            raise InputError(name, f"must lie in {left}{p.lo:g}, {p.hi:g}] {p.unit}".rstrip()
                             + f", got {value!r}")
        out[name] = int(v) if p.integer else v
    return out
