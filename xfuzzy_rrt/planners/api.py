"""One entry point for every planner, used by the CLI, the benchmark runner and the trainer."""

from __future__ import annotations

import functools
import os
import weakref
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.rulebook import rulebooks_env
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners import registry as _registry
from xfuzzy_rrt.planners import setup_memo as _setup_memo
from xfuzzy_rrt.planners.result import PlanResult, replace_result
from xfuzzy_rrt.planners.rng import check_seed
from xfuzzy_rrt.planners.rrt import plan_rrt, plan_rrt_as
from xfuzzy_rrt.planners.tuned import TWO_JOINT, tuned_path, tuned_record

#: The built-in exact planner names (every accepted label form is in planners/registry.py).
PLANNERS = ("rrt", "fuzzy-rrt", "fuzzy-rrt-connect")
TRACE_SUFFIXES = (".parquet", ".csv")
#: ``ompl:NAME`` runs OMPL's geometric planner NAME (optional extra; see planners/ompl_bridge.py).
OMPL_PREFIX = "ompl:"
#: ``fuzzy-rrt:NAME`` (a shipped rulebook) or ``fuzzy-rrt:DIR`` (a rulebook directory).
FUZZY_PREFIX = "fuzzy-rrt:"
#: RRT with the step and goal bias of the shipped tuned file (planners/tuned.py); ``rrt``
#: keeps the paper's 10° and 0.05.
RRT_TUNED = "rrt:tuned"
#: ``fuzzy-rrt-connect:NAME|DIR``: Fuzzy-RRT-Connect with that goal-frame(-any) rulebook.
CONNECT_PREFIX = "fuzzy-rrt-connect:"
#: What plain ``fuzzy-rrt`` runs, with no rulebook named, on a problem that is not one 2-joint
#: arm (see :func:`shipped_default`), with that planner's own default, the DOF-free
#: ``goal-frame-any``.
ANY_ARM_PLANNER = "fuzzy-rrt-connect"
#: The key under which a benchmark lists the any-arm rulebook of plain ``fuzzy-rrt`` beside the
#: 2-joint one (``BenchResult.rulebooks``, ``bench.json``): the runs keep the label ``fuzzy-rrt``.
ANY_ARM_KEY = "fuzzy-rrt (any arm)"


@dataclass(frozen=True)
class PlannerSpec:
    """One planner as the user wrote it.

    ``label`` is the text itself (``"fuzzy-rrt:paper"``): it names the planner in every table
    so that several rulebooks can stand side by side. ``kind`` is ``rrt``, ``fuzzy-rrt``,
    ``fuzzy-rrt-connect`` or ``ompl`` (or a registered planner's kind); ``rulebook_dir`` is
    the directory a ``fuzzy-rrt:...`` or ``fuzzy-rrt-connect:...`` label names (``None`` for
    the plain names: the caller's rulebook or the planner's shipped default). ``planner`` is
    the registration of the label's form (:class:`~xfuzzy_rrt.planners.registry.Planner`):
    what the planner can do (``takes_rulebook``, ``traces``, ...).
    """

    label: str
    kind: str
    rulebook_dir: Path | None = None
    planner: _registry.Planner | None = field(default=None, compare=False, repr=False)


def is_known_planner(name: str) -> bool:
    """A registered planner label: ``rrt``, ``fuzzy-rrt:...``, ``ompl:NAME``, ... (the part
    after the colon is checked by :func:`parse_planner`). Cheap and import-free, for argument
    parsing."""
    return _registry.lookup(name) is not None


def default_rulebook_dir(kind: str) -> Path:
    """The shipped rulebook a planner kind uses without one: the default rulebook for
    ``fuzzy-rrt``, the DOF-free ``goal-frame-any`` for ``fuzzy-rrt-connect`` (any arm)."""
    from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, rulebooks_dir

    if kind == "fuzzy-rrt-connect":
        from xfuzzy_rrt.planners.connect import DEFAULT_RULEBOOK

        return rulebooks_dir() / DEFAULT_RULEBOOK
    return default_rulebook_path()


def label_rulebook_dir(spec: "PlannerSpec") -> Path:
    """The rulebook folder a rulebook label plans with when no rulebook is passed: the one the
    label names (``fuzzy-rrt:NAME``, ``fuzzy-rrt-connect:DIR``), else its kind's shipped
    default (:func:`default_rulebook_dir`)."""
    return spec.rulebook_dir if spec.rulebook_dir is not None else default_rulebook_dir(spec.kind)


def shipped_default(scenario: Scenario) -> tuple[str, Path]:
    """``(planner, rulebook directory)`` that plain ``fuzzy-rrt`` runs on *scenario* when the
    user names no rulebook (no ``--rulebook``, no ``fuzzy-rrt:NAME``, ``rulebook=None``).

    The rule: one 2-joint arm -> ``fuzzy-rrt`` with the shipped default (``goal-frame``); any
    other problem (one arm of 3-7 joints, or 2-4 arms) -> ``fuzzy-rrt-connect`` with the
    DOF-free ``goal-frame-any``. Why per problem (the fair protocol, end-to-end time against
    ``rrt:tuned``, medians over 48 unseen problems per family; README): at 2 joints goal-frame
    Fuzzy-RRT is the faster of the two (warm, nineteenth session: 1.00-1.07x against Connect's
    0.80-0.94x with its rulebook loaded once; docs/peer-measurements.md); beyond two it
    does not fit at all, and Connect with ``goal-frame-any`` beats the per-DOF rulebooks there
    (5 joints 1.33x and 100 % certified success against ``goal-frame-5dof``'s 0.91x and 64 %;
    two 3-joint arms 2.09x against ``goal-frame-dual3``'s 1.25x).
    Only this default adapts: a rulebook the user names that does not fit stays an error.
    """
    if scenario.one_two_joint_arm:
        return "fuzzy-rrt", default_rulebook_dir("fuzzy-rrt")
    return ANY_ARM_PLANNER, default_rulebook_dir(ANY_ARM_PLANNER)


@dataclass(frozen=True)
class ShippedDefault:
    """The shipped default of plain ``fuzzy-rrt``, both rulebooks loaded once (``two_joint``,
    ``any_arm``), for callers that plan many problems (bench, evaluate): pass it as
    ``plan_scenario(..., rulebook=...)`` and each problem gets :func:`shipped_default`'s choice
    without re-reading a rulebook inside the timed call. ``rulebook=None`` means the same."""

    two_joint: Any
    any_arm: Any

    def for_scenario(self, scenario: Scenario) -> tuple[str, Any]:
        """``(planner, loaded rulebook)`` of :func:`shipped_default` for *scenario*."""
        if scenario.one_two_joint_arm:
            return "fuzzy-rrt", self.two_joint
        return ANY_ARM_PLANNER, self.any_arm


@dataclass(frozen=True)
class TunedRRT:
    """The settings of ``rrt:tuned`` read once (:func:`load_tuned_rrt`), for callers that plan
    many problems (evaluate, bench): passed as ``plan_scenario(..., "rrt:tuned",
    rulebook=...)``, a call does not look at the tuned file again.

    Why: those tools load the default's rulebooks once (:class:`ShippedDefault`), so its calls
    check no file, while ``rrt:tuned`` stat-ed its file on every call (one ``os.stat``, ~3 us
    warm and tens of microseconds after a long run has evicted the caches): a handicap of the
    peer, not of the planner. A library user of a tuned RRT passes its two numbers; so do these
    tools now. Plain ``plan_scenario(..., "rrt:tuned")`` still reads the file (a removed or
    broken file is refused at once)."""

    step_deg: float
    goal_bias: float
    #: ``((shape, step_deg, goal_bias), ...)``: every shipped shape's settings
    #: (:mod:`xfuzzy_rrt.planners.tuned`, "Per arm shape"); a problem runs with those of its
    #: nearest shape. Empty: ``step_deg``/``goal_bias`` for every problem (a caller's own).
    by_shape: tuple = ()

    def settings_for(self, shape) -> tuple[float, float, tuple | None]:
        """``(step_deg, goal_bias, shape whose settings these are, or None)`` for a problem
        of ``shape``."""
        if not self.by_shape:
            return self.step_deg, self.goal_bias, None
        from xfuzzy_rrt.planners.tuned import nearest_row

        near, step_deg, goal_bias = nearest_row(self.by_shape, tuple(shape))
        return step_deg, goal_bias, near


def load_tuned_rrt(where: str = "--planner") -> TunedRRT:
    """``rrt:tuned``'s settings as the shipped tuned files give them now, every shape's (one
    InputError naming ``where`` when the 2-joint file is missing or a file is broken)."""
    from xfuzzy_rrt.planners.tuned import tuned_by_shape

    tuned = _tuned_rrt(where)
    rows = []
    for shape, params in tuned_by_shape("rrt").items():
        _check_tuned_rrt(params, where, shape)
        rows.append((shape, float(params["step_deg"]), float(params["goal_bias"])))
    if not any(r[0] == TWO_JOINT for r in rows):
        rows.append((TWO_JOINT, float(tuned["step_deg"]), float(tuned["goal_bias"])))
    return TunedRRT(float(tuned["step_deg"]), float(tuned["goal_bias"]), tuple(sorted(rows)))


def preloaded(planner: str, rulebook: Any) -> Any:
    """What a caller that plans ``planner`` many times passes as ``rulebook``: ``rrt:tuned``'s
    settings read once (:class:`TunedRRT`), an ``ompl:NAME`` label's tuned range read once
    (:class:`~xfuzzy_rrt.planners.ompl_bridge.TunedRange`), or the rulebook of a label that
    takes one, loaded once (``fuzzy-rrt-connect``: its shipped default; ``fuzzy-rrt:NAME``,
    ``fuzzy-rrt-connect:DIR``: the folder the label names) when it passes nothing, else
    ``rulebook`` as given (the shipped default of plain ``fuzzy-rrt`` is loaded by its callers:
    :func:`load_shipped_default`).

    Why every kind: a call given no rulebook resolves it again (the folder is stat-ed to notice
    an edit), ~2 us warm and ~100 us of a 3-joint call that starts with cold caches; a planner
    compared as a peer (``evaluate --peer fuzzy-rrt-connect``) paid that in every timed call
    while the planners it was compared with did not."""
    if planner == RRT_TUNED and rulebook is None:
        return load_tuned_rrt()
    if rulebook is None and planner.startswith("ompl:"):
        from xfuzzy_rrt.planners.ompl_bridge import load_tuned_range, parse_ompl_label

        spec = parse_ompl_label(planner, "--planner")
        if spec.range_deg is None:  # the label's own range needs nothing read
            return load_tuned_range(spec.base)
    if rulebook is None and planner != "fuzzy-rrt":
        spec = parse_planner(planner, "--planner")
        if spec.planner.takes_rulebook:
            from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

            return load_rulebook(label_rulebook_dir(spec))
    return rulebook


def load_shipped_default() -> ShippedDefault:
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    return ShippedDefault(load_rulebook(default_rulebook_dir("fuzzy-rrt")),
                          load_rulebook(default_rulebook_dir(ANY_ARM_PLANNER)))


def shipped_rulebook_names() -> list[str]:
    from xfuzzy_rrt.fuzzy.rulebook import list_rulebooks

    return [p.name for p in list_rulebooks()]


def rulebook_dir_of(arg: str, where: str, prefix: str = FUZZY_PREFIX) -> Path:
    """The directory ``fuzzy-rrt:ARG`` names.

    A bare word is a shipped rulebook (``general``, ``paper``, ...); anything with a path
    separator, or starting with ``.`` or ``~``, is a directory. So ``fuzzy-rrt:paper`` never
    silently picks up a folder that happens to be called ``paper`` in the current directory
    (write ``fuzzy-rrt:./paper`` for that).
    """
    from xfuzzy_rrt.fuzzy.rulebook import rulebooks_dir

    if "/" in arg or "\\" in arg or arg.startswith((".", "~")):
        path = Path(arg).expanduser()
        if not path.is_dir():
            raise InputError(where, f"rulebook directory {arg!r} does not exist")
        return path
    path = rulebooks_dir() / arg
    if not path.is_dir():
        names = shipped_rulebook_names()
        raise InputError(where, f"unknown rulebook {arg!r} in {prefix}{arg} (shipped: "
                         f"{', '.join(names) or 'none'}; a directory needs a '/', e.g. "
                         f"{prefix}./{arg})")
    return path


def parse_planner(name: str, where: str = "--planners", recheck: bool = True) -> PlannerSpec:
    """Validate a planner label fully, before any run: raises one InputError naming ``where``.

    The label's form is looked up in the planner registry (:mod:`xfuzzy_rrt.planners.registry`),
    whose ``parse`` hook checks the rest: for ``ompl:NAME`` this imports OMPL, so a missing
    extra or an unknown OMPL planner fails here with the same line it would give when planning;
    for ``fuzzy-rrt:NAME`` the rulebook directory must exist (loading it, which validates every
    rule, is the caller's next step). ``recheck=False`` (:func:`plan_scenario`): a label
    accepted before whose plan hook repeats the parse hook's checks (``plan_rechecks``) is not
    checked twice in one call.
    """
    entry = _registry.lookup(name)
    if entry is None:
        raise InputError(where, f"unknown planner {name!r} (expected one of "
                         f"{_registry.expected_text()})")
    if entry.parse is None:
        spec = _PLAIN_SPECS.get(name)
        if spec is None or spec.planner is not entry:
            spec = _PLAIN_SPECS[name] = PlannerSpec(name, entry.kind, None, entry)
        return spec
    arg = name[len(entry.label):] if entry.is_prefix else None
    spec = _CHECKED_SPECS.get(name)
    if spec is not None and spec.planner is entry:
        if recheck or not entry.plan_rechecks:
            entry.parse_fn(name, arg, where)  # the hook checks again: its verdict may change
        return spec
    key = (name, rulebooks_env())  # a shipped name's folder follows the variable
    spec = _PARSED_SPECS.get(key)
    if spec is not None and spec.planner is entry:
        return spec
    spec = PlannerSpec(name, entry.kind, entry.parse_fn(name, arg, where), entry)
    if spec.rulebook_dir is not None:  # the folder is checked again where it is loaded
        _PARSED_SPECS[key] = spec
    else:
        _CHECKED_SPECS[name] = spec
    return spec


#: The spec of each exact label without a parse hook (immutable, so made once: plan_scenario
#: parses its label on every call).
_PLAIN_SPECS: dict = {}
#: The spec of each rulebook label (``fuzzy-rrt:NAME``, ``fuzzy-rrt-connect:DIR``) its parse
#: hook accepted, per value of ``$XFUZZY_RRT_RULEBOOKS`` (which moves the shipped rulebooks; a
#: relative directory stays relative). Why: ``plan_scenario`` parses its label on every call,
#: and resolving and stat-ing the folder was 10-15 us of a 30 us two-joint call. The folder is
#: checked again where it is loaded or compared
#: (:func:`~xfuzzy_rrt.fuzzy.rulebook.load_rulebook_cached`), with the same one-line error.
#: Other hooks run every time (``ompl:NAME`` must say "needs the extra" under the caller's
#: option name). Errors are never remembered.
_PARSED_SPECS: dict = {}
#: The spec of each label whose hook names no rulebook (``rrt:tuned``, ``ompl:NAME``): the hook
#: still runs on every call (the tuned file may go, the extra may be missing), but the spec it
#: vouched for is made once, so such a label costs its peers no more than its hook (fair
#: comparisons: ``rrt:tuned`` paid ~5 us a call more than the default; README).
_CHECKED_SPECS: dict = {}


def check_planner(name: str, where: str = "--planners") -> str:
    """:func:`parse_planner`, returning the label."""
    return parse_planner(name, where).label


def plan_scenario(scenario: Scenario, planner: str = "fuzzy-rrt", rulebook=None, seed: int = 0,
                  max_iter: int = 10_000, step_deg: float = 10.0, goal_bias: float = 0.05,
                  trace: bool = False, clearance_m: float | None = None,
                  max_time_s: float | None = None) -> PlanResult:
    """Plan ``scenario`` with the named planner (a label :func:`parse_planner` accepts).

    ``rulebook`` (fuzzy-rrt and fuzzy-rrt-connect) is a loaded rulebook, a directory path, or
    ``None`` (or a :class:`ShippedDefault`) for the planner's shipped default, or for the one a
    ``...:NAME`` label names. Plain ``fuzzy-rrt`` without a rulebook follows
    :func:`shipped_default`: on a problem that is not one 2-joint arm it runs
    ``fuzzy-rrt-connect`` with ``goal-frame-any``; the result's ``planner`` stays the label
    (``fuzzy-rrt``) and ``planner_used`` says what ran, ``rulebook``/``rulebook_sha256`` which
    rulebook.
    ``step_deg``/``goal_bias`` configure plain RRT; ``goal_bias`` also the OMPL planners that
    have one. Fuzzy-RRT takes both from its rulebook. ``ompl:NAME[:sampled][:range=DEG]`` runs
    OMPL's geometric planner NAME with our collision checker and, unless ``:sampled``, our
    certified edge check; its range is the label's, else the tuned one
    (:func:`xfuzzy_rrt.planners.ompl_bridge.plan_ompl`; needs the optional 'ompl' extra). The
    result's ``planner`` is the label. ``clearance_m``: the
    certified clearance in metres (default: the scenario's ``clearance_m``, else 0).
    ``max_time_s``: a wall-clock budget on top of ``max_iter`` (whichever ends first;
    :mod:`xfuzzy_rrt.planners.termination`).
    Every planner goes through its registration's ``plan`` (:mod:`.registry`): one dict
    look-up, no chain of names. A call that repeats an earlier one's very objects (see
    :data:`_LANES`) goes straight to the run its registration's ``bind`` made then.
    """
    if not trace and max_time_s is None:
        hit = _LANES.get((planner, id(scenario)))
        if hit is not None and hit[0]() is scenario:
            lane = hit[1]
            if lane[0] is rulebook and lane[1] is max_iter and lane[2] is step_deg and \
                    lane[3] is goal_bias and lane[4] is clearance_m:
                return lane[5](check_seed(seed))
    check_seed(seed)
    spec = parse_planner(planner, "--planner", recheck=False)
    entry = spec.planner
    if trace and not entry.traces:
        raise InputError("--trace", "traces record fuzzy decisions; use --planner "
                         f"{_registry.either(_registry.exact_labels(traces=True))}")
    if not trace and max_time_s is None and entry.bind is not None:
        run = entry.bind_fn(scenario, spec, rulebook, max_iter=max_iter, step_deg=step_deg,
                            goal_bias=goal_bias, clearance_m=clearance_m)
        if run is not None:
            _setup_memo.remember((planner, id(scenario)), scenario,
                                 (rulebook, max_iter, step_deg, goal_bias, clearance_m, run),
                                 _LANES, MAX_LANES)
            return run(seed)
    return entry.plan_fn(scenario, spec, rulebook, seed=seed, max_iter=max_iter,
                         step_deg=step_deg, goal_bias=goal_bias, trace=trace,
                         clearance_m=clearance_m, max_time_s=max_time_s)


#: ``(label, id(scenario))`` -> ``(weak reference to the scenario, (rulebook, max_iter,
#: step_deg, goal_bias, clearance_m, run))``: the run (``run(seed) -> PlanResult``) that a
#: registration's ``bind`` made for a call without a trace or a time budget, used again by a
#: call that passes the very same objects (``is``, one by one, as
#: :func:`~xfuzzy_rrt.planners.setup_memo.last_call` matches).
#:
#: Why: a loop of plans (``evaluate``, ``bench``, a library user's seeds) passes the same objects
#: every time, and each call still went through the label's parse, its registration's ``plan``,
#: the rulebook choice, the core's keyword call and the set-up memo: ~60-80 us of a call that
#: starts with cold caches (a fifth of a 3-joint call) and ~3 us warm, the same for every planner
#: (docs/peer-measurements.md, twenty-second session). A run is made only where nothing a later
#: call could change is read again: a loaded rulebook, the preloaded shipped default or tuned
#: settings, or a label that reads nothing (``rrt``); ``bind`` returns None otherwise (a rulebook
#: given as a folder or ``None`` is resolved again on every call, so an edit is noticed), and
#: the call takes the registration's ``plan``. Kept by the set-up memo's own
#: :func:`~xfuzzy_rrt.planners.setup_memo.remember`: an entry goes with its scenario (a weak
#: reference whose callback drops it, so a recycled ``id`` never finds a dead scenario's run),
#: and at most :data:`MAX_LANES` are kept, the oldest dropped.
_LANES: dict = {}
MAX_LANES = 1024


def clear_lanes() -> None:
    """Forget every kept run (tests; nothing else needs it)."""
    _LANES.clear()


# --- The built-in planners' hooks (registered in planners/registry.py) -------------------------

def parse_tuned(label: str, arg, where: str) -> None:
    """``rrt:tuned`` needs the shipped tuned file."""
    _tuned_rrt(where)


def parse_rulebook_arg(label: str, arg: str, where: str) -> Path:
    """``fuzzy-rrt:ARG`` / ``fuzzy-rrt-connect:ARG``: the rulebook directory ARG names."""
    return rulebook_dir_of(arg, where, label[:-len(arg)])


def parse_ompl_arg(label: str, arg: str, where: str) -> None:
    from xfuzzy_rrt.planners.ompl_bridge import check_ompl_planner

    check_ompl_planner(label, where)


def plan_rrt_label(scenario: Scenario, spec: PlannerSpec, rulebook, *, seed, max_iter, step_deg,
                   goal_bias, trace, clearance_m, max_time_s) -> PlanResult:
    """``rrt`` with ``step_deg``/``goal_bias``; ``rrt:tuned`` with the tuned file's."""
    if spec.label == RRT_TUNED:  # the label fixes the settings: the tuned file's
        from xfuzzy_rrt.planners.tuned import nearest_shape, shape_of, tuned_shapes

        if type(rulebook) is TunedRRT:  # read once by the caller (evaluate, bench)
            step, bias, near = rulebook.settings_for(shape_of(scenario))
            return plan_rrt_as(RRT_TUNED, _tuned_result_params(near), scenario, seed=seed,
                               max_iter=max_iter, clearance_m=clearance_m,
                               max_time_s=max_time_s, step_deg=step, goal_bias=bias)
        shape = shape_of(scenario)
        near = nearest_shape(shape, tuned_shapes("rrt")) if shape != TWO_JOINT else shape
        tuned = _tuned_rrt("--planner", near or TWO_JOINT)
        return plan_rrt_as(RRT_TUNED, _tuned_result_params(near), scenario, seed=seed,
                           max_iter=max_iter, clearance_m=clearance_m, max_time_s=max_time_s,
                           **tuned)
    return plan_rrt(scenario, seed=seed, max_iter=max_iter, step_deg=step_deg,
                    goal_bias=goal_bias, clearance_m=clearance_m, max_time_s=max_time_s)


#: What ``rrt:tuned`` adds to its result's ``params``, per shape whose settings it ran with
#: (``tuned_shape``: e.g. ``"2 arms, 6 joints"``; none for a caller's own settings). One dict
#: per shape, made once: the result keeps it (read-only by convention, as before).
_TUNED_PARAMS: dict = {}


def _tuned_result_params(shape) -> dict:
    params = _TUNED_PARAMS.get(shape)
    if params is None:
        from xfuzzy_rrt.planners.tuned import shape_text

        params = {"tuned": True}
        if shape is not None:
            params["tuned_shape"] = shape_text(shape)
        _TUNED_PARAMS[shape] = params
    return params


def bind_rrt_label(scenario: Scenario, spec: PlannerSpec, rulebook, *, max_iter, step_deg,
                   goal_bias, clearance_m):
    """The run :func:`plan_rrt_label` makes of these arguments, for every seed (see
    :data:`_LANES`): ``rrt`` with ``step_deg``/``goal_bias``, ``rrt:tuned`` with the settings a
    caller read once (:class:`TunedRRT`); None for ``rrt:tuned`` without them (its file is
    read on every call)."""
    from xfuzzy_rrt.planners.rrt import bind_rrt_as

    if spec.label == RRT_TUNED:
        if type(rulebook) is not TunedRRT:
            return None
        from xfuzzy_rrt.planners.tuned import shape_of

        step, bias, near = rulebook.settings_for(shape_of(scenario))
        return bind_rrt_as(RRT_TUNED, _tuned_result_params(near), scenario, max_iter=max_iter,
                           step_deg=step, goal_bias=bias, clearance_m=clearance_m)
    return bind_rrt_as("rrt", None, scenario, max_iter=max_iter, step_deg=step_deg,
                       goal_bias=goal_bias, clearance_m=clearance_m)


def plan_rulebook_label(scenario: Scenario, spec: PlannerSpec, rulebook, *, seed, max_iter,
                        step_deg, goal_bias, trace, clearance_m, max_time_s) -> PlanResult:
    """``fuzzy-rrt[:RULEBOOK]`` and ``fuzzy-rrt-connect[:RULEBOOK]``: the rulebook the label or
    the caller names, else the shipped default (:func:`shipped_default`'s rule for plain
    ``fuzzy-rrt``); the kind that runs calls its registration's ``core``."""
    core, rulebook = _rulebook_core(scenario, spec, rulebook)
    # the core names its result with the label (planner_used: its own kind), as rrt:tuned's
    # does: no finished result is copied to relabel it
    return core.core_fn(scenario, rulebook=rulebook, seed=seed, max_iter=max_iter, trace=trace,
                        clearance_m=clearance_m, max_time_s=max_time_s, label=spec.label)


def bind_rulebook_label(scenario: Scenario, spec: PlannerSpec, rulebook, *, max_iter, step_deg,
                        goal_bias, clearance_m):
    """The run :func:`plan_rulebook_label` makes of these arguments, for every seed (see
    :data:`_LANES`), when the rulebook is one nothing can change: a loaded rulebook (for a
    ``...:NAME|DIR`` label, one read from that very folder) or the preloaded
    :class:`ShippedDefault`; else None."""
    if isinstance(rulebook, ShippedDefault):
        if spec.rulebook_dir is not None:
            return None
    elif not hasattr(rulebook, "compiled") or (
            spec.rulebook_dir is not None and not _read_from(rulebook, spec.rulebook_dir)):
        return None
    core, rulebook = _rulebook_core(scenario, spec, rulebook)
    if core.core_bind is None:
        return None
    return core.core_bind_fn(scenario, rulebook, max_iter=max_iter, clearance_m=clearance_m,
                             label=spec.label)


def _rulebook_core(scenario: Scenario, spec: PlannerSpec, rulebook):
    """``(registration, rulebook)``: which rulebook planner runs a rulebook label's call and
    with what (the label's rulebook, the caller's, or :func:`shipped_default`'s choice)."""
    kind = spec.kind
    if type(rulebook) is TunedRRT:
        raise InputError("--rulebook", f"tuned RRT settings are not a rulebook ({spec.label} "
                         "takes a rulebook)")
    default = rulebook if isinstance(rulebook, ShippedDefault) else None
    if default is not None:  # the shipped default, preloaded: the same as rulebook=None
        rulebook = None
    if spec.rulebook_dir is not None:
        if rulebook is not None and not _same_rulebook(rulebook, spec.rulebook_dir):
            raise InputError("--rulebook", f"conflicts with --planner {spec.label} (which "
                             "names its own rulebook); give only one")
        rulebook = rulebook if rulebook is not None else spec.rulebook_dir
    elif rulebook is None and kind == "fuzzy-rrt":
        # No rulebook named: the shipped default, per problem (shipped_default's rule).
        if default is not None:
            kind, rulebook = default.for_scenario(scenario)
        else:
            # rulebook None: that planner's own default (the rule without its ~0.1 ms
            # rulebook-directory look-up, which the planner does anyway)
            kind = "fuzzy-rrt" if scenario.one_two_joint_arm else ANY_ARM_PLANNER
    elif rulebook is None and default is not None:
        rulebook = default.any_arm
    return (spec.planner if kind == spec.kind else _registry.lookup(kind)), rulebook


def plan_ompl_label(scenario: Scenario, spec: PlannerSpec, rulebook, *, seed, max_iter, step_deg,
                    goal_bias, trace, clearance_m, max_time_s) -> PlanResult:
    from xfuzzy_rrt.planners.ompl_bridge import TunedRange, plan_ompl

    # OMPL's range comes from the label (ompl:NAME:range=DEG) or the tuned file (read once by
    # a caller that passes its TunedRange), not step_deg.
    return plan_ompl(scenario, spec.label, seed=seed, max_iter=max_iter, goal_bias=goal_bias,
                     clearance_m=clearance_m, time_limit_s=max_time_s,
                     tuned=rulebook if type(rulebook) is TunedRange else None)


def bind_ompl_label(scenario: Scenario, spec: PlannerSpec, rulebook, *, max_iter, step_deg,
                    goal_bias, clearance_m):
    """The run :func:`plan_ompl_label` makes of these arguments, for every seed (see
    :data:`_LANES`), when its range needs nothing read: the label's own (``:range=DEG``) or the
    tuned range a caller read once (:class:`~xfuzzy_rrt.planners.ompl_bridge.TunedRange`);
    else None. The peers' calls skip what ours skip (fair comparisons): the label's parse and
    the registration's ``plan``; every check of ``plan_ompl`` still runs in each call."""
    from xfuzzy_rrt.planners.ompl_bridge import TunedRange, parse_ompl_label

    tuned = rulebook if type(rulebook) is TunedRange else None
    if tuned is None and parse_ompl_label(spec.label, "--planner").range_deg is None:
        return None
    # the scenario by weak reference: a kept run must not keep it alive (the run is used only
    # by a call that passes this very scenario)
    return functools.partial(_ompl_run, weakref.ref(scenario), spec.label, max_iter, goal_bias,
                             clearance_m, tuned)


def _ompl_run(scenario_ref, label, max_iter, goal_bias, clearance_m, tuned, seed) -> PlanResult:
    from xfuzzy_rrt.planners.ompl_bridge import plan_ompl

    return plan_ompl(scenario_ref(), label, seed=seed, max_iter=max_iter, goal_bias=goal_bias,
                     clearance_m=clearance_m, time_limit_s=None, tuned=tuned)


def _tuned_rrt(where: str, shape=TWO_JOINT) -> dict[str, float]:
    """``step_deg`` and ``goal_bias`` of the shipped ``rrt.toml`` (or of ``shape``'s own file,
    :mod:`~xfuzzy_rrt.planners.tuned`), or one InputError.

    The file is stat-ed on every call and parsed only when it changed
    (:func:`~xfuzzy_rrt.planners.tuned.tuned_record`); its parameters are returned as parsed,
    not copied (read-only: callers unpack them)."""
    record = tuned_record("rrt", shape, exact=True)
    tuned = None if record is None else record["params"]
    _check_tuned_rrt(tuned, where, shape)
    return tuned


def _check_tuned_rrt(tuned, where: str, shape) -> None:
    if tuned is None or set(tuned) != {"step_deg", "goal_bias"}:
        raise InputError(where, f"{RRT_TUNED} needs the tuned file {tuned_path('rrt', shape)} "
                         "with step_deg and goal_bias (make it with 'xfuzzy-rrt tune rrt --out "
                         "FILE')")


#: The last ``(rulebook, folder)`` :func:`_same_rulebook` found read from that folder: a loop of
#: plans passes the same two objects every time (the folder is the cached label spec's), and
#: the verdict cannot change while they live, so the next call skips the path comparison.
_PROVEN: list = [None, None]


def _same_rulebook(rulebook, directory: Path) -> bool:
    """A loaded rulebook or a path that is the rulebook in ``directory``.

    A rulebook :func:`~xfuzzy_rrt.fuzzy.rulebook.load_rulebook` read from ``directory`` (the
    same absolute path) is that folder's rulebook as the caller loaded it, even if the folder
    changed since: no file is touched (``loaded_from``). Any other is compared by content with
    the folder's current rulebook."""
    if rulebook is _PROVEN[0] and directory is _PROVEN[1]:
        return True
    if hasattr(rulebook, "sha256"):
        from xfuzzy_rrt.fuzzy.rulebook import load_rulebook_cached

        if _read_from(rulebook, directory):
            _PROVEN[:] = (rulebook, directory)
            return True
        return rulebook.sha256 == load_rulebook_cached(directory).sha256
    return Path(rulebook).resolve() == Path(directory).resolve()


def _read_from(rulebook, directory: Path) -> bool:
    """A loaded rulebook :func:`~xfuzzy_rrt.fuzzy.rulebook.load_rulebook` read from
    ``directory`` (the same absolute path; no file is touched)."""
    from xfuzzy_rrt.fuzzy.rulebook import loaded_from

    return loaded_from(rulebook) == os.path.abspath(directory)


def write_trace_checked(path: Path) -> None:
    """Fail early (before planning) when the trace file's suffix is not supported."""
    if Path(path).suffix.lower() not in TRACE_SUFFIXES:
        raise InputError(str(path), "trace file must end in .parquet or .csv")


def write_trace(result: PlanResult, path: Path, rulebook_dir: str | Path | None = None) -> None:
    """Write ``result.trace`` (a DataFrame) atomically as Parquet or CSV by suffix.

    ``rulebook_dir``: the directory the rulebook was read from, recorded as the trace's
    ``rulebook_dir`` column so that ``explain`` finds an edited copy of a shipped rulebook
    (whose name is the original's) without being told.
    """
    from xfuzzy_rrt.atomic import atomic_path

    write_trace_checked(path)
    if result.trace is None:
        raise InputError(str(path), "this result has no trace")
    if rulebook_dir is not None:
        from xfuzzy_rrt.planners.trace import with_rulebook_dir

        result = replace_result(result, trace=with_rulebook_dir(result.trace, rulebook_dir))
    with atomic_path(path) as tmp:
        if Path(path).suffix.lower() == ".parquet":
            result.trace.to_parquet(tmp, index=False)
        else:
            result.trace.to_csv(tmp, index=False, float_format="%.17g")
