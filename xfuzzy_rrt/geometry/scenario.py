"""The scenario model (arm, start, goal, obstacles) and its validated TOML loader.

A scenario is read once into frozen dataclasses; every later layer trusts it. So the loader is
strict about what matters (types, signs, dimensions, that start and goal are reachable
configurations) and names the file and key at fault in one line. An unknown key or table is an
error too, with its line and the nearest known name (see :mod:`xfuzzy_rrt.strict`): a typo such
as ``[[obstacle]]`` must never silently remove every obstacle.

The format is described in ``shared/scenarios/FORMAT.md``: metres for lengths, degrees for joint
angles, circles and axis-aligned boxes as obstacles, N links. The project's compatible extension
for several arms (an ``[[arms]]`` array, each arm with its own ``start_deg`` and ``goal_deg``) is
described in ``docs/scenarios.md``.
"""

from __future__ import annotations

import functools
import math
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from xfuzzy_rrt.errors import ScenarioError
from xfuzzy_rrt.strict import toml_key_line, unknown_key_message

CIRCLE = 0
BOX = 1

#: Largest length or coordinate (metres) a scenario may use. Beyond ~1e154 m the squared
#: distances overflow to inf and the certified check would step over obstacles; long before
#: that, float64 rounding outgrows the 1 µm certification margin. 1e6 m keeps rounding errors
#: below 1e-9 m while allowing any plausible unit mistake (millimetres for metres).
MAX_EXTENT_M = 1e6
#: Shortest link (metres). The certified check and the goal-frame inputs scale by sums of
#: squared link lengths, which underflow to 0 below ~1e-154 m (a subnormal 5e-324 m link made
#: a division by zero); a link a millionth of the 1 µm certification margin is no link a
#: planner can reason about either, so 1 nm is the floor.
MIN_LINK_M = 1e-9


@dataclass(frozen=True)
class Circle:
    center: tuple[float, float]
    radius: float


@dataclass(frozen=True)
class Box:
    min: tuple[float, float]
    max: tuple[float, float]


Obstacle = Circle | Box


@dataclass(frozen=True)
class Arm:
    """A planar serial arm: link *i* turns about the tip of link *i-1* (joint 1 about ``base``)."""

    links: tuple[float, ...]
    base: tuple[float, float] = (0.0, 0.0)
    link_radius: float = 0.0
    joint_limits_deg: tuple[tuple[float, float], ...] = ()

    @property
    def dof(self) -> int:
        return len(self.links)

    @property
    def reach(self) -> float:
        return float(sum(self.links))


@dataclass(frozen=True)
class Scenario:
    """A planning problem: one or more arms, their start and goal, and the obstacles.

    ``arm`` is the first arm and ``more_arms`` the others (empty for the format's single
    ``[arm]``), so every single-arm caller keeps reading ``scenario.arm``. ``start_deg`` and
    ``goal_deg`` hold every arm's joint angles, arm after arm: the planners search the joint
    space of all arms together (``dof`` angles).
    """

    name: str
    arm: Arm
    start_deg: tuple[float, ...]
    goal_deg: tuple[float, ...]
    obstacles: tuple[Obstacle, ...] = ()
    description: str = ""
    source: str = ""
    #: ``[safety] clearance_m``: the distance (m) every link should keep from every obstacle.
    clearance_m: float = 0.0
    #: Arms after the first (``[[arms]]`` entries 2, 3, ...); each is a collision object for
    #: the others.
    more_arms: tuple[Arm, ...] = ()
    #: Optional ``[[arms]] name`` of each arm (empty strings when unnamed).
    arm_names: tuple[str, ...] = ()

    @property
    def arms(self) -> tuple[Arm, ...]:
        return (self.arm, *self.more_arms)

    @property
    def dof(self) -> int:
        """Joint angles of all arms together (the dimension the planners search)."""
        return sum(a.dof for a in self.arms)

    @property
    def joint_limits_deg(self) -> tuple[tuple[float, float], ...]:
        return tuple(lim for a in self.arms for lim in a.joint_limits_deg)

    @functools.cached_property
    def one_two_joint_arm(self) -> bool:
        """One arm of two joints (the problems the shipped 2-joint default plans). Remembered
        on the object: plain ``fuzzy-rrt`` reads it on every call, and a read costs no Python
        call (each one ~3-10 us when a benchmark has evicted the caches)."""
        return not self.more_arms and len(self.arm.links) == 2

    def arm_slices(self) -> tuple[slice, ...]:
        """Where each arm's angles sit in ``start_deg``, ``goal_deg`` and every path row."""
        out, k = [], 0
        for a in self.arms:
            out.append(slice(k, k + a.dof))
            k += a.dof
        return tuple(out)

    def arrays(self) -> "ScenarioArrays":
        """The flat arrays compiled code works on (see :class:`ScenarioArrays`)."""
        return ScenarioArrays.from_scenario(self)


@dataclass(frozen=True)
class ScenarioArrays:
    """A scenario as contiguous float64 arrays for numba kernels.

    ``obstacles`` rows are ``[kind, a, b, c, d]``: circles ``[0, cx, cy, r, 0]``, boxes
    ``[1, xmin, ymin, xmax, ymax]``. ``limits_deg`` is ``[dof, 2]``. ``links`` lists every
    arm's links, arm after arm; arm ``a`` owns links (and joints) ``arm_first[a]`` to
    ``arm_first[a + 1] - 1``, turns about ``bases[a]`` and has capsule radius ``radii[a]``.
    ``base``/``link_radius`` are the first arm's (single-arm helpers read them).
    """

    links: np.ndarray
    base: np.ndarray
    link_radius: float
    obstacles: np.ndarray
    limits_deg: np.ndarray
    start_deg: np.ndarray
    goal_deg: np.ndarray
    arm_first: np.ndarray
    bases: np.ndarray
    radii: np.ndarray

    @property
    def n_arms(self) -> int:
        return int(self.arm_first.shape[0] - 1)

    @property
    def dof(self) -> int:
        return int(self.links.shape[0])

    @functools.cached_property
    def stop_width(self) -> int:
        """Columns of a tree node's stop record on this problem, what planners make their
        trees with (:func:`~xfuzzy_rrt.geometry.problem.stop_record_width`); worked out once
        (every plan call reads it)."""
        from xfuzzy_rrt.geometry.problem import stop_record_width

        return stop_record_width(self.arm_first)

    @classmethod
    def from_scenario(cls, s: Scenario) -> "ScenarioArrays":
        obs = np.zeros((len(s.obstacles), 5), dtype=np.float64)
        for i, o in enumerate(s.obstacles):
            if isinstance(o, Circle):
                obs[i] = (CIRCLE, o.center[0], o.center[1], o.radius, 0.0)
            else:
                obs[i] = (BOX, o.min[0], o.min[1], o.max[0], o.max[1])
        arms = s.arms
        first = np.zeros(len(arms) + 1, dtype=np.int64)
        for a, arm in enumerate(arms):
            first[a + 1] = first[a] + arm.dof
        return cls(
            links=np.asarray([v for arm in arms for v in arm.links], dtype=np.float64),
            base=np.asarray(s.arm.base, dtype=np.float64),
            link_radius=float(s.arm.link_radius),
            obstacles=obs,
            limits_deg=np.asarray(s.joint_limits_deg, dtype=np.float64).reshape(-1, 2),
            start_deg=np.asarray(s.start_deg, dtype=np.float64),
            goal_deg=np.asarray(s.goal_deg, dtype=np.float64),
            arm_first=first,
            bases=np.asarray([arm.base for arm in arms], dtype=np.float64).reshape(-1, 2),
            radii=np.asarray([arm.link_radius for arm in arms], dtype=np.float64),
        )

    def problem(self, margin: float, clearance: float | None = None):
        """The compiled problem bundle every kernel takes (:class:`~xfuzzy_rrt.geometry.problem.Problem`).

        ``clearance`` is the surgeon's clearance (m); by default the one ``margin`` stands for
        (``margin - CERT_MARGIN_M`` when positive, else 0: ``collision.clearance_of_margin``).
        Each call gets a fresh zeroed ``work`` counter, so a plan's count starts at 0.
        """
        from xfuzzy_rrt.geometry.collision import clearance_of_margin
        from xfuzzy_rrt.geometry.problem import Problem, new_work_counter

        clear = clearance_of_margin(margin) if clearance is None else float(clearance)
        return Problem(self.links, self.arm_first, self.bases, self.radii, self.obstacles,
                       self.limits_deg, self.start_deg, self.goal_deg, float(margin), clear,
                       new_work_counter())


# --------------------------------------------------------------------------------------------
# Loading and validation
# --------------------------------------------------------------------------------------------

#: Known keys, spelt as the format writes them (tables in brackets), for the "did you mean".
_TOP_KEYS = ("name", "description", "[arm]", "[safety]", "[start]", "[goal]", "[[obstacles]]",
             "[[arms]]")
_ARM_KEYS = ("links", "base", "link_radius", "joint_limits_deg")
#: Keys of one ``[[arms]]`` entry (the project's extension for several arms, docs/scenarios.md).
_ARMS_KEYS = ("name", "links", "base", "link_radius", "joint_limits_deg", "start_deg", "goal_deg")

#: The ``[[arms]]`` form's limits: the planners search at most 4 arms of at most 7 links each.
MAX_ARMS = 4
MAX_LINKS_PER_ARM = 7
_SAFETY_KEYS = ("clearance_m",)
_CONFIG_KEYS = ("q_deg",)
_CIRCLE_KEYS = ("type", "center", "radius")
_BOX_KEYS = ("type", "min", "max")


class _Reader:
    """Typed accessors that raise :class:`ScenarioError` naming the key."""

    def __init__(self, file: str, text: str | None = None) -> None:
        self.file = file
        self.text = text

    def fail(self, key: str, message: str) -> ScenarioError:
        return ScenarioError(self.file, key, message)

    def only(self, data: dict[str, Any], known: tuple[str, ...], path: tuple = (),
             where: str = "") -> None:
        """Refuse the first key of ``data`` not in ``known`` (FILE:LINE, nearest known name)."""
        bare = {k.strip("[]") for k in known}
        for key in data:
            if key not in bare:
                line = toml_key_line(self.text, (*path, key)) if self.text is not None else None
                file = f"{self.file}:{line}" if line is not None else self.file
                raise ScenarioError(file, "", unknown_key_message(key, known, where))

    def fail_at(self, path: tuple, key: str, message: str) -> ScenarioError:
        """:meth:`fail` with the line of ``path`` in the text, when the scan can place it."""
        line = toml_key_line(self.text, path) if self.text is not None else None
        return ScenarioError(f"{self.file}:{line}" if line is not None else self.file, key, message)

    def table(self, data: dict[str, Any], key: str, path: str, required: bool = True) -> dict | None:
        if key not in data:
            if required:
                raise self.fail(path, "missing required table")
            return None
        value = data[key]
        if not isinstance(value, dict):
            raise self.fail(path, f"must be a table, got {_typename(value)}")
        return value

    def number(self, value: Any, path: str) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.fail(path, f"must be a number, got {_typename(value)}")
        try:
            x = float(value)
        except OverflowError:  # a TOML integer has no size limit
            raise self.fail(path, "must be finite, got an integer too large for a float") from None
        if not math.isfinite(x):
            raise self.fail(path, f"must be finite, got {value}")
        return x

    def extent(self, value: float, path: str) -> float:
        """A length or coordinate in metres: also within ``±MAX_EXTENT_M``."""
        if abs(value) > MAX_EXTENT_M:
            raise self.fail(path, f"must lie within ±{MAX_EXTENT_M:g} m (larger geometry cannot "
                            f"be certified in float64), got {value:g}")
        return value

    def lengths(self, value: Any, path: str, length: int | None = None) -> tuple[float, ...]:
        """:meth:`numbers` that are lengths or coordinates in metres (see :meth:`extent`)."""
        values = self.numbers(value, path, length)
        return tuple(self.extent(v, f"{path}[{i}]") for i, v in enumerate(values))

    def numbers(self, value: Any, path: str, length: int | None = None) -> tuple[float, ...]:
        if not isinstance(value, list):
            raise self.fail(path, f"must be an array of numbers, got {_typename(value)}")
        if length is not None and len(value) != length:
            raise self.fail(path, f"must have {length} numbers, got {len(value)}")
        return tuple(self.number(v, f"{path}[{i}]") for i, v in enumerate(value))

    def required(self, data: dict[str, Any], key: str, path: str) -> Any:
        if key not in data:
            raise self.fail(path, "missing required key")
        return data[key]


def _typename(value: Any) -> str:
    return {
        bool: "a boolean", int: "an integer", float: "a float", str: "a string",
        list: "an array", dict: "a table",
    }.get(type(value), type(value).__name__)


def load_scenario(path: str | Path) -> Scenario:
    """Read and validate a scenario TOML file. Raises :class:`ScenarioError` on any problem."""
    path = Path(path)
    file = str(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise ScenarioError(file, "", "no such file") from None
    except IsADirectoryError:
        raise ScenarioError(file, "", "is a directory, expected a scenario .toml file") from None
    except OSError as exc:
        raise ScenarioError(file, "", f"cannot read: {exc.strerror}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ScenarioError(file, "", f"not valid UTF-8 (byte {exc.start})") from None
    try:
        data = tomllib.loads(text)
    except RecursionError:  # tomllib recurses per nesting level: "[[[[...]]]]" would crash it
        raise ScenarioError(file, "", "TOML syntax error: arrays or tables nested too deeply") from None
    except tomllib.TOMLDecodeError as exc:
        message = str(exc)
        m = re.search(r"\(at line (\d+), column (\d+)\)", message)
        if m:
            detail = message[: m.start()].strip()
            raise ScenarioError(f"{file}:{m.group(1)}", "", f"TOML syntax error: {detail} "
                                f"(column {m.group(2)})") from None
        raise ScenarioError(file, "", f"TOML syntax error: {message}") from None
    return scenario_from_dict(data, file, text)


def scenario_from_dict(data: dict[str, Any], file: str = "<scenario>",
                       text: str | None = None) -> Scenario:
    """Validate an already-parsed scenario mapping (the loader's second half).

    ``text``, the TOML it was parsed from, lets an unknown key be reported with its line.
    A file describes its arm(s) one of two ways (see ``docs/scenarios.md``): the format's
    ``[arm]`` with top-level ``[start]`` and ``[goal]``, or the project's ``[[arms]]`` array,
    each entry with its own ``start_deg`` and ``goal_deg``. Mixing them is an error.
    """
    r = _Reader(file, text)
    r.only(data, _TOP_KEYS)

    name = r.required(data, "name", "name")
    if not isinstance(name, str) or not name.strip():
        raise r.fail("name", "must be a non-empty string")
    description = data.get("description", "")
    if not isinstance(description, str):
        raise r.fail("description", f"must be a string, got {_typename(description)}")

    if "arms" in data:
        arms, names, start, goal = _read_arms(r, data)
    else:
        arm_t = r.table(data, "arm", "arm")
        r.only(arm_t, _ARM_KEYS, ("arm",), "[arm]")
        arm = _read_arm(r, arm_t, "arm")
        dof = arm.dof
        configs = {}
        for which in ("start", "goal"):
            t = r.table(data, which, which)
            r.only(t, _CONFIG_KEYS, (which,), f"[{which}]")
            q_raw = r.required(t, "q_deg", f"{which}.q_deg")
            if isinstance(q_raw, list) and len(q_raw) != dof:
                raise r.fail(f"{which}.q_deg", f"must have one angle per link ({dof}), got {len(q_raw)}")
            configs[which] = r.numbers(q_raw, f"{which}.q_deg", length=dof)
        arms, names, start, goal = (arm,), (), configs["start"], configs["goal"]

    safety_t = r.table(data, "safety", "safety", required=False) or {}
    r.only(safety_t, _SAFETY_KEYS, ("safety",), "[safety]")
    clearance_m = r.extent(r.number(safety_t.get("clearance_m", 0.0), "safety.clearance_m"),
                           "safety.clearance_m")
    if clearance_m < 0:
        raise r.fail("safety.clearance_m", f"must be >= 0, got {clearance_m:g}")

    obstacles: list[Obstacle] = []
    obs_raw = data.get("obstacles", [])
    if not isinstance(obs_raw, list):
        raise r.fail("obstacles", f"must be an array of tables ([[obstacles]]), got "
                     f"{_typename(obs_raw)}")
    for i, o in enumerate(obs_raw):
        key = f"obstacles[{i}]"
        if not isinstance(o, dict):
            raise r.fail(key, f"must be a table, got {_typename(o)}")
        kind = r.required(o, "type", f"{key}.type")
        where = f"[[obstacles]] #{i + 1} ({kind})"
        if kind == "circle":
            r.only(o, _CIRCLE_KEYS, ("obstacles", i), where)
            center = r.lengths(r.required(o, "center", f"{key}.center"), f"{key}.center", 2)
            radius = r.extent(r.number(r.required(o, "radius", f"{key}.radius"), f"{key}.radius"),
                              f"{key}.radius")
            if radius <= 0:
                raise r.fail(f"{key}.radius", f"must be > 0, got {radius:g}")
            obstacles.append(Circle(center=(center[0], center[1]), radius=radius))
        elif kind == "box":
            r.only(o, _BOX_KEYS, ("obstacles", i), where)
            lo = r.lengths(r.required(o, "min", f"{key}.min"), f"{key}.min", 2)
            hi = r.lengths(r.required(o, "max", f"{key}.max"), f"{key}.max", 2)
            for axis, name_ in ((0, "x"), (1, "y")):
                if not hi[axis] > lo[axis]:
                    raise r.fail(f"{key}.max", f"must exceed min on the {name_} axis, got "
                                 f"max {hi[axis]:g} <= min {lo[axis]:g}")
            obstacles.append(Box(min=(lo[0], lo[1]), max=(hi[0], hi[1])))
        else:
            raise r.fail(f"{key}.type", f"unknown obstacle type {kind!r} (expected 'circle' or 'box')")

    scenario = Scenario(
        name=name.strip(), arm=arms[0], start_deg=start, goal_deg=goal,
        obstacles=tuple(obstacles), description=description, source=file,
        clearance_m=clearance_m, more_arms=tuple(arms[1:]), arm_names=names,
    )
    _check_endpoints(scenario, r, "arms" in data)
    return scenario


def _read_arm(r: _Reader, arm_t: dict[str, Any], key: str) -> Arm:
    """One arm's ``links``, ``base``, ``link_radius`` and ``joint_limits_deg`` (``key``: where)."""
    links_raw = r.required(arm_t, "links", f"{key}.links")
    links = r.lengths(links_raw, f"{key}.links")
    if not links:
        raise r.fail(f"{key}.links", "must list at least one link length")
    for i, length in enumerate(links):
        if length <= 0:
            raise r.fail(f"{key}.links[{i}]", f"link length must be > 0, got {length:g}")
        if length < MIN_LINK_M:
            raise r.fail(f"{key}.links[{i}]", f"link length must be at least {MIN_LINK_M:g} m "
                         f"(shorter links underflow the certified check), got {length:g}")
    base = r.lengths(arm_t.get("base", [0.0, 0.0]), f"{key}.base", length=2)
    link_radius = r.extent(r.number(arm_t.get("link_radius", 0.0), f"{key}.link_radius"),
                           f"{key}.link_radius")
    if link_radius < 0:
        raise r.fail(f"{key}.link_radius", f"must be >= 0, got {link_radius:g}")
    dof = len(links)
    limits_raw = arm_t.get("joint_limits_deg", [[-180.0, 180.0]] * dof)
    if not isinstance(limits_raw, list):
        raise r.fail(f"{key}.joint_limits_deg", f"must be an array of [min, max] pairs, got "
                     f"{_typename(limits_raw)}")
    if len(limits_raw) != dof:
        raise r.fail(f"{key}.joint_limits_deg", f"must have one [min, max] pair per link "
                     f"({dof}), got {len(limits_raw)}")
    limits = []
    for i, pair in enumerate(limits_raw):
        lo, hi = r.numbers(pair, f"{key}.joint_limits_deg[{i}]", length=2)
        if not lo < hi:
            raise r.fail(f"{key}.joint_limits_deg[{i}]", f"min must be < max, got [{lo:g}, {hi:g}]")
        if lo < -180.0 or hi > 180.0:
            raise r.fail(f"{key}.joint_limits_deg[{i}]",
                         f"must lie within [-180, 180] (no wrap-around), got [{lo:g}, {hi:g}]")
        limits.append((lo, hi))
    return Arm(links=links, base=(base[0], base[1]), link_radius=link_radius,
               joint_limits_deg=tuple(limits))


def _read_arms(r: _Reader, data: dict[str, Any]):
    """The ``[[arms]]`` form: ``(arms, names, start_deg, goal_deg)``, angles arm after arm."""
    raw = data["arms"]
    if "arm" in data:
        raise r.fail_at(("arms",), "arms", "a file has either [arm] (with [start] and [goal]) or "
                        "[[arms]], not both")
    for which in ("start", "goal"):
        if which in data:
            raise r.fail_at((which,), which, f"[{which}] is not used with [[arms]]: each arm "
                            f"carries its own start_deg and goal_deg")
    if not isinstance(raw, list) or not all(isinstance(t, dict) for t in raw):
        got = _typename(raw) if not isinstance(raw, list) else "an array with a non-table entry"
        raise r.fail("arms", f"must be an array of tables ([[arms]]), got {got}")
    if not raw:
        raise r.fail("arms", "must list at least one arm")
    if len(raw) > MAX_ARMS:
        raise r.fail("arms", f"at most {MAX_ARMS} arms are supported, got {len(raw)}")
    arms, names, start, goal = [], [], [], []
    for i, t in enumerate(raw):
        key = f"arms[{i}]"
        r.only(t, _ARMS_KEYS, ("arms", i), f"[[arms]] #{i + 1}")
        arm_name = t.get("name", "")
        if not isinstance(arm_name, str) or ("name" in t and not arm_name.strip()):
            raise r.fail(f"{key}.name", "must be a non-empty string")
        arm_name = arm_name.strip()
        if arm_name and arm_name in names:
            raise r.fail(f"{key}.name", f"{arm_name!r} names two arms (arms[{names.index(arm_name)}] "
                         f"too)")
        arm = _read_arm(r, t, key)
        if arm.dof > MAX_LINKS_PER_ARM:
            raise r.fail(f"{key}.links", f"at most {MAX_LINKS_PER_ARM} links per arm are "
                         f"supported, got {arm.dof}")
        for which, out in (("start_deg", start), ("goal_deg", goal)):
            q_raw = r.required(t, which, f"{key}.{which}")
            if isinstance(q_raw, list) and len(q_raw) != arm.dof:
                raise r.fail(f"{key}.{which}", f"must have one angle per link ({arm.dof}), "
                             f"got {len(q_raw)}")
            out.extend(r.numbers(q_raw, f"{key}.{which}", length=arm.dof))
        arms.append(arm)
        names.append(arm_name)
    return tuple(arms), (tuple(names) if any(names) else ()), tuple(start), tuple(goal)


def _check_endpoints(s: Scenario, r: _Reader, arms_form: bool = False) -> None:
    """Start and goal must be within the joint limits and collision-free (touching counts).

    Each arm is checked on its own (so the message names the arm): first against itself (two
    non-adjacent links meeting, self-collision), then against the obstacles; then the whole
    configuration with :func:`~xfuzzy_rrt.geometry.collision.clearance`, which also counts
    contact between two arms.
    """
    from dataclasses import replace

    from xfuzzy_rrt.geometry.collision import clearance, self_contact

    arrays = s.arrays()
    slices = s.arm_slices()
    for which, q in (("start", s.start_deg), ("goal", s.goal_deg)):
        q = tuple(q)
        for a, (arm, sl) in enumerate(zip(s.arms, slices)):
            key = f"arms[{a}].{which}_deg" if arms_form else f"{which}.q_deg"
            for j, (angle, (lo, hi)) in enumerate(zip(q[sl], arm.joint_limits_deg)):
                if not lo <= angle <= hi:
                    raise r.fail(f"{key}[{j}]",
                                 f"{angle:g} deg is outside the joint limits [{lo:g}, {hi:g}]")
            alone = arrays if len(s.arms) == 1 else replace(
                s, arm=arm, more_arms=(), arm_names=(), start_deg=q[sl], goal_deg=q[sl]).arrays()
            own, k, m = self_contact(alone, np.asarray(q[sl], dtype=np.float64))
            if own <= 0.0:
                raise r.fail(key, f"configuration {list(q[sl])} is in self-collision: links "
                             f"{k} and {m} of the arm (counted from 0) touch or overlap")
            if clearance(alone, np.asarray(q[sl], dtype=np.float64)) <= 0.0:
                raise r.fail(key, f"configuration {list(q[sl])} is in collision "
                             f"(an arm link touches or overlaps an obstacle)")
        if len(s.arms) > 1 and clearance(arrays, np.asarray(q, dtype=np.float64)) <= 0.0:
            raise r.fail(f"arms.{which}_deg", f"the arms touch or overlap each other at "
                         f"{which} (arm-arm contact is a collision)")
