"""Tuned parameters of the peer planners, read from the files shipped in ``data/tuned/``.

Why: a planner compared at the paper's settings (RRT at 10°) is a handicapped baseline. The
project compares its rulebooks against peers *at their best*: ``xfuzzy-rrt tune`` searches a
planner's parameters on training problems only (:mod:`xfuzzy_rrt.bench.tuning`) and writes one
small TOML file per planner with the chosen values, the whole objective table and the command
that made it. This module only reads those files, so planning never depends on the tuner.

File names: the planner label with ``:`` turned into ``-`` (``rrt`` -> ``rrt.toml``,
``ompl:RRTConnect`` -> ``ompl-RRTConnect.toml``).

**Per arm shape.** A peer's best settings depend on the problem's shape: RRT's best step on one
2-joint arm is not its best on a 7-joint arm or two 3-joint arms (thirty-first session, on
training problems: the 2-joint settings needed 1.2-4.3x the work of the best ones at 3-7 joints
and with two to four arms). Our default is trained on every shape it plans, so a peer tuned
on 2-joint problems only is a handicapped peer there. A shape is ``(arms, joints)``, the number of arms and
of joints of all arms together; ``xfuzzy-rrt tune --dof D --arms A`` tunes one and writes its
own file, named with a suffix (``rrt.2-arms-6-joints.toml``; one 2-joint arm keeps the plain
``rrt.toml``). A problem whose shape has no file takes the nearest shape that has one
(:func:`nearest_shape`: the same number of arms and the closest number of joints, fewer on a
tie; else the closest number of joints), and a result says which shape's settings it ran with.
RRT and OMPL's RRTConnect ship files for one arm of 2 to 7 joints and two, three and four
2-joint arms and two 3-joint arms (thirty-first and thirty-second sessions). A file whose name
looks like no shape, or whose ``[provenance]`` was tuned for another shape than its name's, is
refused with one error naming it (passed over, its shape would silently run another's settings).
"""

from __future__ import annotations

import os
import re
import stat
import tomllib
from functools import lru_cache
from pathlib import Path

from xfuzzy_rrt.errors import InputError


@lru_cache(maxsize=1)
def tuned_dir() -> Path:
    """The folder of the shipped tuned-parameter files (package data; resolved once: it is
    looked up on every plan of a tuned planner)."""
    return Path(__file__).resolve().parent.parent / "data" / "tuned"


#: ``(arms, joints)``: how many arms a problem has and how many joints all of them have together.
Shape = tuple[int, int]
#: One 2-joint arm: the shape whose file has no suffix (``rrt.toml``).
TWO_JOINT: Shape = (1, 2)


def shape_of(scenario) -> Shape:
    """``(arms, joints)`` of a scenario (joints: of all arms together)."""
    return (1 + len(scenario.more_arms), int(scenario.dof))


def arm_shape(joints_per_arm: int, arms: int = 1) -> Shape:
    """The shape of ``arms`` arms of ``joints_per_arm`` joints each (what ``tune --dof --arms``
    and a tuned file's ``[provenance]`` give): ``(arms, arms * joints_per_arm)``."""
    return (int(arms), int(arms) * int(joints_per_arm))


def shape_text(shape: Shape) -> str:
    """``(2, 6)`` -> ``"2 arms, 6 joints"``; ``(1, 2)`` -> ``"1 arm, 2 joints"``."""
    arms, joints = shape
    return f"{arms} arm{'s' if arms != 1 else ''}, {joints} joints"


def shape_suffix(shape: Shape) -> str:
    """``""`` for one 2-joint arm, else ``".2-arms-6-joints"`` (the part of a file name after
    the label)."""
    if tuple(shape) == TWO_JOINT:
        return ""
    arms, joints = shape
    return f".{arms}-arm{'s' if arms != 1 else ''}-{joints}-joints"


def tuned_file_name(label: str, shape: Shape = TWO_JOINT) -> str:
    """``rrt`` -> ``rrt.toml``; ``ompl:RRTConnect`` -> ``ompl-RRTConnect.toml``; with a shape
    other than one 2-joint arm, ``rrt.1-arm-5-joints.toml``."""
    return label.replace(":", "-") + shape_suffix(shape) + ".toml"


def tuned_path(label: str, shape: Shape = TWO_JOINT) -> Path:
    return tuned_dir() / tuned_file_name(label, shape)


_SHAPE_NAME = re.compile(r"^\.(\d+)-arms?-(\d+)-joints$")


def tuned_shapes(label: str) -> tuple[Shape, ...]:
    """The shapes that have a tuned file of ``label`` in :func:`tuned_dir`, sorted. The folder
    is listed again only when it changed (its ``mtime_ns``): ``rrt:tuned`` looks here on every
    plan that was not given its settings."""
    folder = tuned_dir()
    try:
        st = os.stat(folder)
    except (FileNotFoundError, NotADirectoryError):
        return ()
    return _shapes(str(folder), label.replace(":", "-"), (st.st_mtime_ns, st.st_ino))


@lru_cache(maxsize=128)
def nearest_row(rows: tuple, shape: Shape) -> tuple:
    """The row of ``rows`` (``((shape, value, ...), ...)``, a shape first in each) whose shape
    is :func:`nearest_shape` of ``shape``, remembered: what a peer's settings read once
    (:class:`~xfuzzy_rrt.planners.api.TunedRRT`,
    :class:`~xfuzzy_rrt.planners.ompl_bridge.TunedRange`) give a problem, at the cost of one
    dict look-up when a problem's run is bound."""
    near = nearest_shape(tuple(shape), [row[0] for row in rows])
    return next(row for row in rows if row[0] == near)


def tuned_source(shape: Shape) -> str:
    """How a result names the tuned settings it ran with: ``"tuned"`` (one 2-joint arm's,
    the plain file) or ``"tuned for 2 arms, 6 joints"``."""
    return "tuned" if tuple(shape) == TWO_JOINT else f"tuned for {shape_text(shape)}"


@lru_cache(maxsize=16)
def _shapes(folder: str, stem: str, identity: tuple) -> tuple[Shape, ...]:
    found = set()
    for name in os.listdir(folder):
        if not name.startswith(stem) or not name.endswith(".toml"):
            continue
        rest = name[len(stem):-len(".toml")]
        if rest == "":
            found.add(TWO_JOINT)
        elif rest.startswith("."):  # another label's file starts with a letter or "-"
            found.add(_named_shape(os.path.join(folder, name), stem, rest))
    return tuple(sorted(found))


def _named_shape(path: str, stem: str, rest: str) -> Shape:
    """The shape a tuned file's name (``stem`` + ``rest`` + ``.toml``) gives; a name that looks
    like a shape's file but is not one is an :class:`InputError` naming the file. Why refuse:
    a file the planners cannot match to a shape would be passed over in silence, and its shape
    would run the nearest shape's settings while the user believes it runs the file's."""
    m = _SHAPE_NAME.match(rest)
    arms, joints = (int(m.group(1)), int(m.group(2))) if m else (0, 0)
    if arms < 1 or joints < 1 or shape_suffix((arms, joints)) != rest:
        raise InputError(path, f"not a tuned file name: expected {stem}.toml (one 2-joint arm) "
                         f"or {stem}.<A>-arm(s)-<J>-joints.toml (e.g. {stem}.1-arm-5-joints.toml, "
                         f"{stem}.2-arms-6-joints.toml)")
    return (arms, joints)


def nearest_shape(shape: Shape, available) -> Shape | None:
    """The shape in ``available`` whose settings a problem of ``shape`` runs with: the shape
    itself; else, among those with as many arms, the closest number of joints (fewer on a
    tie); else, among all, the closest number of joints, then the closest number of arms,
    fewer of each on a tie. ``None`` when nothing is available."""
    available = tuple(available)
    if not available:
        return None
    arms, joints = shape
    if (arms, joints) in available:
        return (arms, joints)
    same = [s for s in available if s[0] == arms]
    if same:
        return min(same, key=lambda s: (abs(s[1] - joints), s[1]))
    return min(available, key=lambda s: (abs(s[1] - joints), abs(s[0] - arms), s[1], s[0]))


def tuned_params(label: str, shape: Shape = TWO_JOINT) -> dict[str, float] | None:
    """The tuned parameters of planner ``label`` for problems of ``shape`` (e.g.
    ``{"step_deg": 60.0, "goal_bias": 0.1}`` for ``rrt``, ``{"range_deg": ...}`` for
    ``ompl:RRTConnect``), from the file of :func:`nearest_shape`, or ``None`` when no tuned file
    ships for it. A file that exists but cannot be read is an :class:`InputError` naming it (a
    broken shipped file must not silently fall back to untuned settings)."""
    record = tuned_record(label, shape)
    return None if record is None else dict(record["params"])


def tuned_by_shape(label: str) -> dict[Shape, dict[str, float]]:
    """Every shipped shape's tuned parameters of ``label`` (one InputError for a broken file):
    what a caller that plans many problems reads once and picks from per problem
    (:func:`nearest_shape`)."""
    out = {}
    for shape in tuned_shapes(label):
        record = tuned_record(label, shape, exact=True)
        if record is not None:
            out[shape] = dict(record["params"])
    return out


def tuned_record(label: str, shape: Shape = TWO_JOINT, exact: bool = False) -> dict | None:
    """The whole parsed tuned file of ``label`` (params, objective, provenance, table) for
    problems of ``shape``: its own file, else (unless ``exact``) the nearest shape's
    (:func:`nearest_shape`).

    Looked up on every plan of a tuned planner (``rrt:tuned`` twice: when its label is parsed
    and when it plans), so it costs one ``os.stat`` of a remembered path string: the parse is
    cached on the file's identity (size, ``mtime_ns``, ``ctime_ns``, inode; a same-size edit
    that restores the mtime still changes the ctime). It was ~30 us of pathlib a call, a fifth
    of ``rrt:tuned``'s whole overhead.
    """
    if not exact and tuple(shape) != TWO_JOINT:
        shape = nearest_shape(tuple(shape), tuned_shapes(label))
        if shape is None:
            return None
    path = _path_str(tuned_dir(), label, tuple(shape))
    try:
        st = os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        return None
    if not stat.S_ISREG(st.st_mode):
        return None
    return _read(path, (st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino), tuple(shape))


@lru_cache(maxsize=64)
def _path_str(folder: Path, label: str, shape: Shape = TWO_JOINT) -> str:
    return str(folder / tuned_file_name(label, shape))


@lru_cache(maxsize=16)
def _read(path: str, identity: tuple, shape: Shape = TWO_JOINT) -> dict:
    """Parsed and checked (cached per file identity, :func:`tuned_record`): a file whose
    ``[provenance]`` says it was tuned for another shape than its name's is refused (a renamed
    file would run one shape's settings on another)."""
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise InputError(path, f"cannot read tuned parameters: {exc}") from None
    params = data.get("params")
    if not isinstance(params, dict) or not params:
        raise InputError(path, "no [params] table of tuned parameters")
    for key, value in params.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(path, f"[params] {key} must be a number, got {value!r}")
    data["params"] = {k: float(v) for k, v in params.items()}
    prov = data.get("provenance")
    if isinstance(prov, dict) and "arms" in prov and "joints_per_arm" in prov:
        arms, per_arm = prov["arms"], prov["joints_per_arm"]
        if not all(isinstance(v, int) and not isinstance(v, bool) for v in (arms, per_arm)):
            raise InputError(path, "[provenance] arms and joints_per_arm must be integers")
        tuned_for = arm_shape(per_arm, arms)
        if tuned_for != tuple(shape):
            name = tuned_file_name(str(data.get("planner", "rrt")), tuned_for)
            raise InputError(path, f"tuned for {shape_text(tuned_for)} (its [provenance]) but "
                             f"named for {shape_text(shape)}: rename it {name}")
    return data


def tuned_for_shapes(label: str, shapes) -> list[tuple[Shape, dict[str, float]]]:
    """``[(tuned shape, its parameters), ...]``: the settings problems of ``shapes`` run with,
    one entry per tuned shape used (sorted; a problem shape without its own file counts under
    :func:`nearest_shape`'s). Empty when no tuned file ships."""
    available = tuned_shapes(label)
    used = sorted({nearest_shape(tuple(s), available) for s in shapes} - {None})
    return [(s, dict(tuned_record(label, s, exact=True)["params"])) for s in used]


def describe_tuned_rrt(shapes, degree: str = " deg") -> str:
    """``"step 300 deg, goal bias 0.05"`` when problems of ``shapes`` run with one tuned
    shape's settings, else each tuned shape's: ``"1 arm, 2 joints: step 300 deg, goal bias
    0.05; 1 arm, 5 joints: step 480 deg, goal bias 0.1"`` (what a report or header names the
    tuned RRT with)."""
    rows = tuned_for_shapes("rrt", shapes)
    if not rows:
        return rrt_settings_text({}, degree)
    if len(rows) == 1:
        return rrt_settings_text(rows[0][1], degree)
    return "; ".join(f"{shape_text(s)}: {rrt_settings_text(p, degree)}" for s, p in rows)


def rrt_settings_text(params: dict, degree: str = " deg", number=None) -> str:
    """``"step 300 deg, goal bias 0.05"``: RRT's two settings as every header, log and report
    names them (``number`` formats a value, ``None`` when missing: ``format(value, "g")``
    and ``nan`` unless given)."""
    number = number or (lambda v: "nan" if v is None else format(v, "g"))
    return (f"step {number(params.get('step_deg'))}{degree}, goal bias "
            f"{number(params.get('goal_bias'))}")
