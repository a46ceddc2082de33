"""Random problems of the shared ``sample-*`` family, for training and for unseen-problem tests.

Why a generator: a rulebook trained on the files it is judged on proves nothing. Training and
evaluation need fresh problems *of the same family* as the shared ``sample-*`` files, and every
problem must be worth planning:

- **family**: a 2-link arm (link 1 of 0.14–0.20 m, link 2 of 0.09–0.15 m, capsules of 5 mm
  radius, joint limits ±180°), 2–7 obstacles (about 70 % circles of 2–6 cm radius, the rest
  axis-aligned boxes of 3–8 cm sides) placed 0.12–0.34 m from the base, i.e. inside the arm's
  reach, start and goal at whole degrees in [-170°, 170°];
- **valid**: start and goal keep :data:`ENDPOINT_CLEARANCE_M` (5 mm, the family's link radius)
  from every obstacle (and, with several arms, from the other arms), and the file loads through
  the project's own validating loader;
- **non-trivial**: the straight joint-space segment from start to goal is *not* certified free
  (otherwise one step of any planner solves it);
- **solvable**: plain RRT finds a path within 20,000 iterations (seed 0) — a certified path is a
  proof, unlike a grid search whose cells may hide a thin obstacle.

Each file's description records, like the shared samples, the grid-optimal path length (shortest
8-connected path through free cells of a 2° C-space grid: an estimate of the optimum), the
straight-line length and the fraction of C-space in collision.

``family="trap"`` (:func:`_draw_trap`) keeps only draws whose grid-optimal path is at least
:data:`TRAP_DETOUR` times the straight distance, and records that ratio in the description.

The problems depend only on ``seed``: draw ``k`` uses ``numpy.random.default_rng([seed, k])``,
so ``--count 24`` starts with the same problems as ``--count 8``.

``--dof N`` (joints per arm) and ``--arms K`` select the N-DOF / multi-arm family instead
(:func:`generate_nd`; docs/scenarios.md): no C-space grid there (the joint space is not a
plane), so solvability is shown by a certified RRT path alone, recorded in the description.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M, clearance, clearance_kernel
from xfuzzy_rrt.geometry.scenario import Arm, Box, Circle, Scenario
from xfuzzy_rrt.scenarios.writer import scenario_toml  # noqa: F401  (re-exported)

GRID_DEG = 2.0
#: Clearance every generated start and goal keeps (metres): the links' 5 mm radius again.
#: Why: with only the planners' 1 µm margin, ``gen-2000-020`` (a demo problem) had its goal
#: 2.61 µm from an obstacle, so the demo's "closest approach" described the problem, not the
#: planners, and a plan at a surgeon's clearance (``--clearance 0.005``) could not even start.
#: Rulebooks trained before this (every shipped one) saw problems without it.
ENDPOINT_CLEARANCE_M = 0.005
RRT_BUDGET = 20_000
#: Drafts drawn for one problem before giving up on it. Raising it changes no problem that was
#: ever generated (the drafts come one after another from the problem's own stream, so a problem
#: found within fewer draws is found at the same draw), only turns a failure into a problem:
#: 200 (until the twenty-first session) failed on ``--dof 2 --arms 4 --seed 9900`` at problem
#: 11, which needs 228 drafts (24 problems of that family took 1-228, a median of 42).
MAX_DRAWS_PER_PROBLEM = 2000


class NoProblemFound(InputError):
    """Every one of :data:`MAX_DRAWS_PER_PROBLEM` drafts of a problem failed a check (invalid,
    trivial or not shown solvable): that generator seed has no problem ``k`` to give, and
    another ``--seed`` is the way out (hence an :class:`~xfuzzy_rrt.errors.InputError` on
    ``--seed``: one line and exit code 2 from the command line)."""

    def __init__(self, seed: int, k: int, what: str) -> None:
        super().__init__("--seed", f"{seed} gives no valid, solvable problem {k} of {what} in "
                                   f"{MAX_DRAWS_PER_PROBLEM} draws; try another seed")


@dataclass(frozen=True)
class GeneratedProblem:
    scenario: Scenario
    text: str  # the TOML file
    grid_optimal_deg: float  # nan beyond one 2-DOF arm (no grid over the joint space)
    straight_deg: float
    c_obstacle_fraction: float  # nan beyond one 2-DOF arm
    #: For the N-DOF and multi-arm family: the RRT run that proved the problem solvable.
    solved_iterations: int | None = None
    solved_seed: int | None = None


#: Problem families: the shared ``sample-*`` family and two harder ones that cover what users
#: meet beyond it (training on a mixture is what lets a rulebook transfer; see rulebooks/README),
#: and ``trap`` (issue 25), where heading for the goal leads into a dead end. A new family goes
#: at the end: its index picks its random stream, so the others' files stay byte-identical.
FAMILIES = ("sample", "hard", "mira", "trap")

#: Least ratio of the grid-optimal path to the straight joint-space distance of a ``trap``
#: problem. Why 1.5: a detour of half the straight distance again cannot come from grazing one
#: obstacle's edge (the grid path then stays within a few cells of the straight line); it means
#: the way towards the goal is blocked and the path must first move *away* from it (fold the
#: elbow under an organ, go round a wall's end) — where goal-biased growth is wasted (issue 25).
TRAP_DETOUR = 1.5


def _draw(rng: np.random.Generator, name: str, family: str = "sample") -> Scenario:
    if family == "hard":
        return _draw_hard(rng, name)
    if family == "mira":
        return _draw_mira(rng, name)
    if family == "trap":
        return _draw_trap(rng, name)
    l1 = round(float(rng.uniform(0.14, 0.20)), 3)
    l2 = round(float(rng.uniform(0.09, 0.15)), 3)
    q = rng.integers(-170, 171, size=4).astype(float)
    obstacles = []
    for _ in range(int(rng.integers(2, 8))):
        r = rng.uniform(0.12, 0.34)
        a = rng.uniform(0.0, 2.0 * math.pi)
        cx, cy = r * math.cos(a), r * math.sin(a)
        if rng.random() < 0.7:
            obstacles.append(Circle(center=(round(cx, 4), round(cy, 4)),
                                    radius=round(float(rng.uniform(0.02, 0.06)), 4)))
        else:
            w, h = rng.uniform(0.03, 0.08, size=2)
            x0, y0 = round(cx - w / 2, 4), round(cy - h / 2, 4)
            obstacles.append(Box(min=(x0, y0), max=(round(x0 + w, 4), round(y0 + h, 4))))
    arm = Arm(links=(l1, l2), base=(0.0, 0.0), link_radius=0.005,
              joint_limits_deg=((-180.0, 180.0), (-180.0, 180.0)))
    return Scenario(name=name, arm=arm, start_deg=(q[0], q[1]), goal_deg=(q[2], q[3]),
                    obstacles=tuple(obstacles))


def _box(cx: float, cy: float, w: float, h: float) -> Box:
    x0, y0 = round(cx - w / 2, 4), round(cy - h / 2, 4)
    return Box(min=(x0, y0), max=(round(x0 + w, 4), round(y0 + h, 4)))


def _arm(l1: float, l2: float) -> Arm:
    return Arm(links=(round(l1, 3), round(l2, 3)), base=(0.0, 0.0), link_radius=0.005,
               joint_limits_deg=((-180.0, 180.0), (-180.0, 180.0)))


def _draw_hard(rng: np.random.Generator, name: str) -> Scenario:
    """Cluttered: the sample family's arm among 6-10 obstacles, a third of them thin walls
    (1-2 cm by 6-14 cm, any orientation of the two axes) that cut narrow passages and traps."""
    l1, l2 = rng.uniform(0.14, 0.20), rng.uniform(0.09, 0.15)
    q = rng.integers(-170, 171, size=4).astype(float)
    obstacles = []
    for _ in range(int(rng.integers(6, 11))):
        r = rng.uniform(0.10, 0.34)
        a = rng.uniform(0.0, 2.0 * math.pi)
        cx, cy = r * math.cos(a), r * math.sin(a)
        u = rng.random()
        if u < 0.35:
            t, length = rng.uniform(0.01, 0.02), rng.uniform(0.06, 0.14)
            obstacles.append(_box(cx, cy, t, length) if rng.random() < 0.5 else _box(cx, cy, length, t))
        elif u < 0.8:
            obstacles.append(Circle(center=(round(cx, 4), round(cy, 4)),
                                    radius=round(float(rng.uniform(0.02, 0.05)), 4)))
        else:
            w, h = rng.uniform(0.03, 0.07, size=2)
            obstacles.append(_box(cx, cy, w, h))
    return Scenario(name=name, arm=_arm(l1, l2), start_deg=(q[0], q[1]), goal_deg=(q[2], q[3]),
                    obstacles=tuple(obstacles))


def _draw_mira(rng: np.random.Generator, name: str) -> Scenario:
    """MIRA-like (the shipped ``demo-*`` setting): two similar links of 0.13-0.17 m, a pair of
    organs (circles of 3-5 cm) held 10-16 cm apart, which the forearm must thread or avoid,
    plus 1-3 retractor boxes."""
    l1, l2 = rng.uniform(0.14, 0.17), rng.uniform(0.12, 0.16)
    q = rng.integers(-170, 171, size=4).astype(float)
    a = rng.uniform(0.0, 2.0 * math.pi)
    r = rng.uniform(0.20, 0.27)
    gap = rng.uniform(0.10, 0.16) / 2
    cx, cy = r * math.cos(a), r * math.sin(a)
    nx, ny = -math.sin(a), math.cos(a)
    radius = float(rng.uniform(0.03, 0.05))
    obstacles = [Circle(center=(round(cx + s * gap * nx, 4), round(cy + s * gap * ny, 4)),
                        radius=round(radius, 4)) for s in (-1.0, 1.0)]
    for _ in range(int(rng.integers(1, 4))):
        rb = rng.uniform(0.15, 0.30)
        ab = rng.uniform(0.0, 2.0 * math.pi)
        w, h = rng.uniform(0.02, 0.07, size=2)
        obstacles.append(_box(rb * math.cos(ab), rb * math.sin(ab), w, h))
    return Scenario(name=name, arm=_arm(l1, l2), start_deg=(q[0], q[1]), goal_deg=(q[2], q[3]),
                    obstacles=tuple(obstacles))


def _draw_trap(rng: np.random.Generator, name: str) -> Scenario:
    """Trap-like: the sample family's arm, one large obstacle straight across the way from start
    to goal, plus 1-3 small clutter obstacles.

    The large obstacle is, half the time, an organ (circle of 6-10 cm radius) whose near edge is
    1-6 cm beyond link 1 (so a folded arm fits under it: nearer, the arm could never pass; and
    link 2 reaches into it), in a direction ``a`` within ±120° of joint 1's zero; else a radial
    wall (1-2 cm thick, 10-20 cm long, an axis-aligned box) pointing along -90°, 0° or 90°, its
    inner end likewise 1-6 cm beyond link 1. Joint 1 starts 25-100° on one side of ``a`` and
    ends 25-100° on the other (clipped to ±170°), joint 2 within ±130° (stretched enough for
    link 2 to reach the obstacle): sweeping straight across hits it, and the way round (fold
    under it, unfold beyond) is long. Whether
    a draw really is a trap is decided by :func:`generate_one` (straight segment blocked, grid
    detour ≥ :data:`TRAP_DETOUR`), not assumed here.
    """
    l1, l2 = rng.uniform(0.14, 0.20), rng.uniform(0.09, 0.15)
    inner = l1 + rng.uniform(0.01, 0.06)  # the big obstacle's nearest point to the base
    if rng.random() < 0.5:
        radius = float(rng.uniform(0.06, 0.10))
        a = math.radians(rng.uniform(-120.0, 120.0))
        r = inner + radius
        big = Circle(center=(round(r * math.cos(a), 4), round(r * math.sin(a), 4)),
                     radius=round(radius, 4))
    else:
        a = math.radians(90.0 * (int(rng.integers(0, 3)) - 1))
        t, length = rng.uniform(0.01, 0.02), rng.uniform(0.10, 0.20)
        r = inner + length / 2
        cx, cy = r * math.cos(a), r * math.sin(a)
        big = _box(cx, cy, length, t) if abs(math.cos(a)) > 0.5 else _box(cx, cy, t, length)
    side = 1.0 if rng.random() < 0.5 else -1.0
    d_start, d_goal = rng.uniform(25.0, 100.0, size=2)
    a_deg = math.degrees(a)
    q1 = [float(np.clip(round(a_deg - side * d_start), -170, 170)),
          float(np.clip(round(a_deg + side * d_goal), -170, 170))]
    q2 = rng.integers(-130, 131, size=2).astype(float)
    obstacles = [big]
    for _ in range(int(rng.integers(1, 4))):
        rc = rng.uniform(0.12, 0.34)
        ac = rng.uniform(0.0, 2.0 * math.pi)
        cx, cy = rc * math.cos(ac), rc * math.sin(ac)
        if rng.random() < 0.7:
            obstacles.append(Circle(center=(round(cx, 4), round(cy, 4)),
                                    radius=round(float(rng.uniform(0.02, 0.04)), 4)))
        else:
            w, h = rng.uniform(0.03, 0.06, size=2)
            obstacles.append(_box(cx, cy, float(w), float(h)))
    return Scenario(name=name, arm=_arm(l1, l2), start_deg=(q1[0], q2[0]), goal_deg=(q1[1], q2[1]),
                    obstacles=tuple(obstacles))


@nb.njit(cache=True, nogil=True, _nrt=True)
def _free_grid(P, angles, margin):
    free = np.empty((angles.size, angles.size), dtype=np.bool_)
    q = np.empty(2)
    for i in range(angles.size):
        q[0] = angles[i]
        for j in range(angles.size):
            q[1] = angles[j]
            free[i, j] = clearance_kernel(P, q) > margin
    return free


def c_space_grid(scenario: Scenario, step_deg: float = GRID_DEG) -> tuple[np.ndarray, np.ndarray]:
    """``(angles, free)``: grid angles and a boolean [n, n] map of free configurations.

    Only for a single 2-DOF arm (the map is then the whole joint space).
    """
    if len(scenario.arms) != 1 or scenario.arm.dof != 2:
        raise ValueError("the C-space grid needs one 2-DOF arm")
    a = scenario.arrays()
    angles = np.arange(-180.0, 180.0 + 1e-9, step_deg)
    return angles, _free_grid(a.problem(CERT_MARGIN_M), angles, CERT_MARGIN_M)


def grid_optimal_deg(scenario: Scenario, step_deg: float = GRID_DEG,
                     grid: tuple[np.ndarray, np.ndarray] | None = None) -> float:
    """Shortest 8-connected path through free cells from start to goal (inf if none)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import dijkstra

    angles, free = grid if grid is not None else c_space_grid(scenario, step_deg)
    n = angles.size
    idx = np.arange(n * n).reshape(n, n)
    rows, cols, w = [], [], []
    for di, dj in ((0, 1), (1, 0), (1, 1), (1, -1)):
        j0, j1 = max(0, -dj), n - max(0, dj)  # columns j with j + dj inside the grid
        ok = free[: n - di, j0:j1] & free[di:, j0 + dj: j1 + dj]
        rows.append(idx[: n - di, j0:j1][ok])
        cols.append(idx[di:, j0 + dj: j1 + dj][ok])
        w.append(np.full(int(ok.sum()), step_deg * math.hypot(di, dj)))
    graph = coo_matrix((np.concatenate(w), (np.concatenate(rows), np.concatenate(cols))),
                       shape=(n * n, n * n)).tocsr()

    def cell(q):
        i = int(np.argmin(np.abs(angles - q[0])))
        j = int(np.argmin(np.abs(angles - q[1])))
        return idx[i, j], np.array([angles[i], angles[j]])

    s, s_q = cell(scenario.start_deg)
    g, g_q = cell(scenario.goal_deg)
    dist = dijkstra(graph, directed=False, indices=s)[g]
    if not np.isfinite(dist):
        return float("inf")
    # account for the offsets between the exact endpoints and their grid cells
    return float(dist + np.linalg.norm(s_q - scenario.start_deg) + np.linalg.norm(g_q - scenario.goal_deg))


def _config_ok(a, q) -> bool:
    """Within the joint limits and at least :data:`ENDPOINT_CLEARANCE_M` from every obstacle."""
    q = np.asarray(q, dtype=np.float64)
    lim = a.limits_deg
    if np.any(q < lim[:, 0]) or np.any(q > lim[:, 1]):
        return False
    return clearance(a, q) >= max(ENDPOINT_CLEARANCE_M, CERT_MARGIN_M)


def generate_one(seed: int, k: int, prefix: str = "gen", family: str = "sample",
                 dof: int = 2, arms: int = 1) -> GeneratedProblem:
    """Problem ``k`` of generator ``seed`` in *family* (draws until one passes every check).

    The ``sample`` family draws from ``default_rng([seed, k])`` (as it always has); the other
    families from ``default_rng([seed, k, i])`` with ``i`` their index in :data:`FAMILIES`, so
    no two families share a stream. ``dof`` (joints per arm) other than 2 or ``arms`` other than
    1 selects the N-DOF / multi-arm family (:func:`generate_nd`); ``family`` is then ignored.
    """
    if dof != 2 or arms != 1:
        return generate_nd(seed, k, prefix, dof, arms)
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r} (known: {', '.join(FAMILIES)})")
    from xfuzzy_rrt.errors import ScenarioError
    from xfuzzy_rrt.geometry.collision import segment_free
    from xfuzzy_rrt.geometry.scenario import scenario_from_dict
    from xfuzzy_rrt.planners.rrt import plan_rrt

    import tomllib

    index = FAMILIES.index(family)
    rng = np.random.default_rng([int(seed), int(k)] if index == 0 else [int(seed), int(k), index])
    name = f"{prefix}-{seed}-{k:03d}"
    for _ in range(MAX_DRAWS_PER_PROBLEM):
        draft = _draw(rng, name, family)
        try:
            s = scenario_from_dict(tomllib.loads(scenario_toml(draft, "draft")), name)
        except ScenarioError:
            continue  # start or goal in collision
        a = s.arrays()
        if segment_free(a, a.start_deg, a.goal_deg):
            continue  # trivial: the straight segment is free
        if not (_config_ok(a, a.start_deg) and _config_ok(a, a.goal_deg)):
            continue  # free, but closer than ENDPOINT_CLEARANCE_M
        straight = float(np.linalg.norm(a.goal_deg - a.start_deg))
        if family == "trap":
            # the grid (milliseconds) before RRT (up to seconds when it fails): most trap drafts
            # fall on the detour, and a problem without a grid path has no detour to record
            grid = c_space_grid(s)
            optimal = grid_optimal_deg(s, grid=grid)
            if not (math.isfinite(optimal) and optimal >= TRAP_DETOUR * straight):
                continue  # no trap: the shortest way is (nearly) straight
        if not plan_rrt(s, seed=0, max_iter=RRT_BUDGET).success:
            continue  # not shown solvable
        if family != "trap":
            grid = c_space_grid(s)
            optimal = grid_optimal_deg(s, grid=grid)
        free = grid[1]
        fraction = float(1.0 - free.mean())
        # a passage narrower than the 2 deg grid can hide the solution RRT just proved exists
        grid_text = (f"grid-optimal {optimal:.1f} deg" if math.isfinite(optimal)
                     else f"no grid path at {GRID_DEG:g} deg (passages narrower than the grid)")
        family_text = "" if family == "sample" else f", family {family}"
        desc = (f"generated (xfuzzy-rrt scenarios generate, seed {seed}, problem {k}{family_text}); "
                f"{grid_text}, straight {straight:.1f} deg, "
                f"C-obstacle fraction {fraction:.3f}")
        if family == "trap":
            desc += f", detour ratio {optimal / straight:.2f} (grid-optimal / straight)"
        text = scenario_toml(s, desc)
        final = scenario_from_dict(tomllib.loads(text), name)
        return GeneratedProblem(scenario=final, text=text, grid_optimal_deg=optimal,
                                straight_deg=straight, c_obstacle_fraction=fraction)
    raise NoProblemFound(seed, k, f"the {family} family")


def generate(count: int, seed: int, prefix: str = "gen", family: str = "sample") -> list[GeneratedProblem]:
    """``count`` valid, solvable, non-trivial problems, determined by ``seed`` and *family*."""
    return [generate_one(seed, k, prefix, family) for k in range(count)]


# --------------------------------------------------------------------------------------------
# N-DOF and multi-arm problems (issue 17)
# --------------------------------------------------------------------------------------------

MIN_DOF, MAX_DOF = 2, 7
MIN_ARMS, MAX_ARMS = 1, 4
#: RRT budget and seeds of the solvability proof beyond one 2-DOF arm.
ND_RRT_BUDGET = 30_000
ND_RRT_SEEDS = (0, 1, 2)


def nd_prefix(dof: int, arms: int) -> str:
    """Default file-name prefix: ``dof5`` for one 5-DOF arm, ``arms2-dof3`` for two 3-DOF arms."""
    return f"dof{dof}" if arms == 1 else f"arms{arms}-dof{dof}"


def _chain_links(rng: np.random.Generator, dof: int, reach: float) -> tuple[float, ...]:
    """``dof`` link lengths summing to about ``reach``, longer near the base (like the samples)."""
    w = rng.uniform(0.7, 1.3, size=dof) * np.linspace(1.0, 0.6, dof)
    w = w / w.sum() * reach
    return tuple(round(max(float(v), 0.02), 3) for v in w)


def _random_obstacle(rng: np.random.Generator, cx: float, cy: float, scale: float):
    """A circle (70 %) or an axis-aligned box about ``(cx, cy)``; sizes scale with ``scale``."""
    if rng.random() < 0.7:
        return Circle(center=(round(cx, 4), round(cy, 4)),
                      radius=round(float(rng.uniform(0.02, 0.06) * scale), 4))
    w, h = rng.uniform(0.03, 0.08, size=2) * scale
    return _box(cx, cy, float(w), float(h))


def _draw_nd(rng: np.random.Generator, name: str, dof: int, arms: int) -> Scenario:
    """One draft of the N-DOF / multi-arm family (see :func:`generate_nd`)."""
    if arms == 1:
        reach = float(rng.uniform(0.23, 0.35))  # the sample family's l1 + l2
        arm = Arm(links=_chain_links(rng, dof, reach), link_radius=0.005,
                  joint_limits_deg=((-180.0, 180.0),) * dof)
        start = [float(rng.integers(-170, 171))] + rng.integers(-120, 121, dof - 1).astype(float).tolist()
        goal = [float(rng.integers(-170, 171))] + rng.integers(-120, 121, dof - 1).astype(float).tolist()
        obstacles = []
        for _ in range(int(rng.integers(3, 8))):
            r = rng.uniform(0.4, 1.1) * reach
            a = rng.uniform(0.0, 2.0 * math.pi)
            obstacles.append(_random_obstacle(rng, r * math.cos(a), r * math.sin(a), 1.0))
        return Scenario(name=name, arm=arm, start_deg=tuple(start), goal_deg=tuple(goal),
                        obstacles=tuple(obstacles))
    # Several arms side by side on the x axis, gap apart, all facing +y: the workspaces overlap
    # (each reach exceeds half the gap), so the arms can touch each other.
    gap = float(rng.uniform(0.25, 0.40))
    arm_list, start, goal = [], [], []
    for i in range(arms):
        reach = float(rng.uniform(0.22, 0.32))
        base = (round((i - (arms - 1) / 2) * gap, 4), 0.0)
        arm_list.append(Arm(links=_chain_links(rng, dof, reach), base=base, link_radius=0.005,
                            joint_limits_deg=((-180.0, 180.0),) * dof))
        for out in (start, goal):
            out.append(float(rng.integers(20, 161)))
            out.extend(rng.integers(-120, 121, dof - 1).astype(float).tolist())
    obstacles = []
    for _ in range(int(rng.integers(3, 8))):
        host = arm_list[int(rng.integers(0, arms))]
        r = rng.uniform(0.45, 1.0) * host.reach
        a = rng.uniform(math.radians(20.0), math.radians(160.0))
        obstacles.append(_random_obstacle(rng, host.base[0] + r * math.cos(a),
                                          host.base[1] + r * math.sin(a), 0.7))
    names = tuple(("left", "right")[i] if arms == 2 else f"arm{i + 1}" for i in range(arms))
    return Scenario(name=name, arm=arm_list[0], more_arms=tuple(arm_list[1:]), arm_names=names,
                    start_deg=tuple(start), goal_deg=tuple(goal), obstacles=tuple(obstacles))


def _rrt_proof(s: Scenario):
    """``(seed, iterations)`` of the first certified RRT path among :data:`ND_RRT_SEEDS`, or None."""
    from xfuzzy_rrt.planners.api import plan_scenario

    for plan_seed in ND_RRT_SEEDS:
        result = plan_scenario(s, "rrt", seed=plan_seed, max_iter=ND_RRT_BUDGET)
        if result.success:
            return plan_seed, int(result.iterations)
    return None


def check_nd_arguments(dof: int, arms: int) -> None:
    """Refuse a joint count or arm count outside the supported ranges (``ValueError``)."""
    if not MIN_DOF <= dof <= MAX_DOF:
        raise ValueError(f"--dof: must be {MIN_DOF} to {MAX_DOF} joints per arm, got {dof}")
    if not MIN_ARMS <= arms <= MAX_ARMS:
        raise ValueError(f"--arms: must be {MIN_ARMS} to {MAX_ARMS}, got {arms}")


def generate_nd(seed: int, k: int, prefix: str | None = None, dof: int = 3,
                arms: int = 1) -> GeneratedProblem:
    """Problem ``k`` of generator ``seed`` with ``arms`` arms of ``dof`` joints each.

    The family: each arm has ``dof`` links summing to 0.23–0.35 m (one arm; the reach of the
    2-DOF sample family) or 0.22–0.32 m (several arms), longer near the base, 5 mm capsules,
    joint limits ±180°. One arm sits at the origin among 3–7 obstacles (70 % circles of 2–6 cm
    radius, else boxes of 3–8 cm sides) 0.4–1.1 reach from the base. Several arms stand on the x
    axis 0.25–0.40 m apart, all facing +y, with 3–7 smaller obstacles (0.7×) in front of them:
    each reach exceeds half the gap, so the arms can touch each other and must take turns.
    Start and goal are whole degrees (joint 1 in [-170°, 170°], or [20°, 160°] facing the shared
    workspace; the others in [-120°, 120°]).

    Kept only when valid (the loader accepts it; start and goal clear by :data:`ENDPOINT_CLEARANCE_M`,
    arm-arm contact included), non-trivial (the straight joint segment is not certified free)
    and solvable: plain RRT (:func:`~xfuzzy_rrt.planners.api.plan_scenario`) returns a
    certified path for one of seeds :data:`ND_RRT_SEEDS` within :data:`ND_RRT_BUDGET`
    iterations; the description records which. Draws come from
    ``default_rng([seed, k, 1000 * arms + dof])``, a stream no 2-DOF family uses.
    """
    import tomllib

    from xfuzzy_rrt.errors import ScenarioError
    from xfuzzy_rrt.geometry.collision import segment_free
    from xfuzzy_rrt.geometry.scenario import scenario_from_dict

    check_nd_arguments(dof, arms)
    prefix = nd_prefix(dof, arms) if prefix is None else prefix
    rng = np.random.default_rng([int(seed), int(k), 1000 * int(arms) + int(dof)])
    name = f"{prefix}-{seed}-{k:03d}"
    what = f"one {dof}-DOF arm" if arms == 1 else f"{arms} arms of {dof} joints"
    for _ in range(MAX_DRAWS_PER_PROBLEM):
        draft = _draw_nd(rng, name, dof, arms)
        try:
            s = scenario_from_dict(tomllib.loads(scenario_toml(draft, "draft")), name)
        except ScenarioError:
            continue  # start or goal in collision
        a = s.arrays()
        if not (_config_ok(a, a.start_deg) and _config_ok(a, a.goal_deg)):
            continue  # free, but closer than ENDPOINT_CLEARANCE_M
        if segment_free(a, a.start_deg, a.goal_deg):
            continue  # trivial: the straight segment is free
        proof = _rrt_proof(s)
        if proof is None:
            continue  # not shown solvable
        plan_seed, iterations = proof
        straight = float(np.linalg.norm(a.goal_deg - a.start_deg))
        desc = (f"generated (xfuzzy-rrt scenarios generate, seed {seed}, problem {k}, {what}); "
                f"straight {straight:.1f} deg, blocked; rrt solved it in {iterations} iterations "
                f"(seed {plan_seed})")
        text = scenario_toml(s, desc)
        final = scenario_from_dict(tomllib.loads(text), name)
        return GeneratedProblem(scenario=final, text=text, grid_optimal_deg=math.nan,
                                straight_deg=straight, c_obstacle_fraction=math.nan,
                                solved_iterations=iterations, solved_seed=plan_seed)
    raise NoProblemFound(seed, k, what)
