"""Random problems of the shared ``sample-*`` family, for training and for unseen-problem tests.

Why a generator: a rulebook trained on the files it is judged on proves nothing. Training and
evaluation need fresh problems *of the same family* as the shared ``sample-*`` files, and every
problem must be worth planning:

- **family**: a 2-link arm (link 1 of 0.14–0.20 m, link 2 of 0.09–0.15 m, capsules of 5 mm
  radius, joint limits ±180°), 2–7 obstacles (about 70 % circles of 2–6 cm radius, the rest
  axis-aligned boxes of 3–8 cm sides) placed 0.12–0.34 m from the base, i.e. inside the arm's
  reach, start and goal at whole degrees in [-170°, 170°];
- **valid**: start and goal are collision-free with the planners' 1 µm margin, and the file
  loads through the project's own validating loader;
- **non-trivial**: the straight joint-space segment from start to goal is *not* certified free
  (otherwise one step of any planner solves it);
- **solvable**: plain RRT finds a path within 20,000 iterations (seed 0) — a certified path is a
  proof, unlike a grid search whose cells may hide a thin obstacle.

Each file's description records, like the shared samples, the grid-optimal path length (shortest
8-connected path through free cells of a 2° C-space grid: an estimate of the optimum), the
straight-line length and the fraction of C-space in collision.

The problems depend only on ``seed``: draw ``k`` uses ``numpy.random.default_rng([seed, k])``,
so ``--count 24`` starts with the same problems as ``--count 8``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M, clearance_kernel
from xfuzzy_rrt.geometry.scenario import Arm, Box, Circle, Scenario

GRID_DEG = 2.0
RRT_BUDGET = 20_000
MAX_DRAWS_PER_PROBLEM = 200


@dataclass(frozen=True)
class GeneratedProblem:
    scenario: Scenario
    text: str  # the TOML file
    grid_optimal_deg: float
    straight_deg: float
    c_obstacle_fraction: float


#: Problem families: the shared ``sample-*`` family and two harder ones that cover what users
#: meet beyond it (training on a mixture is what lets a rulebook transfer; see rulebooks/README).
FAMILIES = ("sample", "hard", "mira")


def _draw(rng: np.random.Generator, name: str, family: str = "sample") -> Scenario:
    if family == "hard":
        return _draw_hard(rng, name)
    if family == "mira":
        return _draw_mira(rng, name)
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


@nb.njit(cache=True, nogil=True)
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
    """``(angles, free)``: grid angles and a boolean [n, n] map of free configurations."""
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


def scenario_toml(s: Scenario, description: str) -> str:
    """The TOML text of a generated scenario (the shared format, see FORMAT.md)."""
    def num(x: float) -> str:
        return repr(float(x))

    lines = [f'name = "{s.name}"', f'description = "{description}"', "", "[arm]",
             f"links = [{', '.join(num(v) for v in s.arm.links)}]",
             f"link_radius = {num(s.arm.link_radius)}", "", "[start]",
             f"q_deg = [{num(s.start_deg[0])}, {num(s.start_deg[1])}]", "", "[goal]",
             f"q_deg = [{num(s.goal_deg[0])}, {num(s.goal_deg[1])}]"]
    for o in s.obstacles:
        lines += ["", "[[obstacles]]"]
        if isinstance(o, Circle):
            lines += ['type = "circle"', f"center = [{num(o.center[0])}, {num(o.center[1])}]",
                      f"radius = {num(o.radius)}"]
        else:
            lines += ['type = "box"', f"min = [{num(o.min[0])}, {num(o.min[1])}]",
                      f"max = [{num(o.max[0])}, {num(o.max[1])}]"]
    return "\n".join(lines) + "\n"


def generate_one(seed: int, k: int, prefix: str = "gen", family: str = "sample") -> GeneratedProblem:
    """Problem ``k`` of generator ``seed`` in *family* (draws until one passes every check).

    The ``sample`` family draws from ``default_rng([seed, k])`` (as it always has); the other
    families from ``default_rng([seed, k, i])`` with ``i`` their index in :data:`FAMILIES`, so
    no two families share a stream.
    """
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r} (known: {', '.join(FAMILIES)})")
    from xfuzzy_rrt.errors import ScenarioError
    from xfuzzy_rrt.geometry.collision import config_free, segment_free
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
        problem = a.problem(CERT_MARGIN_M)
        if not (config_free(problem, a.start_deg, CERT_MARGIN_M)
                and config_free(problem, a.goal_deg, CERT_MARGIN_M)):
            continue  # free, but closer than the planners' margin
        if not plan_rrt(s, seed=0, max_iter=RRT_BUDGET).success:
            continue  # not shown solvable
        grid = c_space_grid(s)
        free = grid[1]
        straight = float(np.linalg.norm(a.goal_deg - a.start_deg))
        optimal = grid_optimal_deg(s, grid=grid)
        fraction = float(1.0 - free.mean())
        # a passage narrower than the 2 deg grid can hide the solution RRT just proved exists
        grid_text = (f"grid-optimal {optimal:.1f} deg" if math.isfinite(optimal)
                     else f"no grid path at {GRID_DEG:g} deg (passages narrower than the grid)")
        family_text = "" if family == "sample" else f", family {family}"
        desc = (f"generated (xfuzzy-rrt scenarios generate, seed {seed}, problem {k}{family_text}); "
                f"{grid_text}, straight {straight:.1f} deg, "
                f"C-obstacle fraction {fraction:.3f}")
        text = scenario_toml(s, desc)
        final = scenario_from_dict(tomllib.loads(text), name)
        return GeneratedProblem(scenario=final, text=text, grid_optimal_deg=optimal,
                                straight_deg=straight, c_obstacle_fraction=fraction)
    raise RuntimeError(f"no valid problem after {MAX_DRAWS_PER_PROBLEM} draws (seed {seed}, k {k})")


def generate(count: int, seed: int, prefix: str = "gen", family: str = "sample") -> list[GeneratedProblem]:
    """``count`` valid, solvable, non-trivial problems, determined by ``seed`` and *family*."""
    return [generate_one(seed, k, prefix, family) for k in range(count)]
