"""Independent exact-geometry oracles (no project geometry code involved).

``Oracle`` (one arm, N links, built on shapely): forward kinematics is re-derived here in plain
numpy; link segments are shapely LineStrings; circle obstacles are measured exactly as
distance-to-centre minus radius (a buffered shapely circle would be a polygon approximation);
boxes are exact shapely rectangles. A configuration collides when a link comes within
``link_radius`` of an obstacle (touching counts), or two non-adjacent links of the arm come
within ``2 link_radius`` of each other (self-collision; links sharing a joint never count). A
scenario file with several arms is handed to the multi-arm oracle below (``Oracle.world``),
which adds arm-arm contact.

``World`` and the ``oracle_*`` functions (N links, several arms, plain numpy and math): exact
plane distances including capsule-capsule contact between arms, and a proven bracket of the
smallest clearance along whole joint-space segments (Lipschitz branch and bound with its own
velocity bound). Method, proof and tolerance are in the notes above :data:`DEFAULT_TOL_M`.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely


class Oracle:
    def __init__(self, scenario_file: str | Path):
        data = tomllib.loads(Path(scenario_file).read_text())
        self._world = None
        if "arm" not in data or data.get("arms"):
            # Several arms (the format's arm list): read the file through the scenario model and
            # decide with the multi-arm oracle, which knows arm-arm contact.
            from xfuzzy_rrt.geometry.scenario import load_scenario

            scenario = load_scenario(scenario_file)
            self._init_multi(World.from_scenario(scenario), scenario.start_deg, scenario.goal_deg)
            return
        arm = data["arm"]
        self.links = np.array(arm["links"], dtype=float)
        self.base = np.array(arm.get("base", [0.0, 0.0]), dtype=float)
        self.radius = float(arm.get("link_radius", 0.0))
        self.limits = np.array(arm.get("joint_limits_deg", [[-180.0, 180.0]] * len(self.links)))
        self.start = np.array(data["start"]["q_deg"], dtype=float)
        self.goal = np.array(data["goal"]["q_deg"], dtype=float)
        self.circles = []
        self.boxes = []
        for o in data.get("obstacles", []):
            if o["type"] == "circle":
                self.circles.append((shapely.Point(*o["center"]), float(o["radius"])))
            else:
                self.boxes.append(shapely.box(o["min"][0], o["min"][1], o["max"][0], o["max"][1]))

    def _init_multi(self, world: "World", start, goal) -> None:
        self._world = world
        self.links = np.concatenate([l for l, _, _ in world.arms])
        self.base = world.arms[0][1]
        self.radius = world.arms[0][2]
        self.limits = world.limits
        self.start = np.asarray(start, dtype=float)
        self.goal = np.asarray(goal, dtype=float)
        self.circles = [(shapely.Point(c[0], c[1]), float(c[2])) for c in world.circles]
        self.boxes = [shapely.box(*b) for b in world.boxes]

    @property
    def multi_arm(self) -> bool:
        return self._world is not None and len(self._world.arms) > 1

    @property
    def world(self) -> "World":
        """The same scene as a :class:`World` (the N-link, multi-arm oracle)."""
        if self._world is None:
            circles = [(c.x, c.y, r) for c, r in self.circles]
            boxes = [b.bounds for b in self.boxes]
            self._world = World([(self.links, self.base, self.radius)], circles, boxes, self.limits)
        return self._world

    def points(self, q_deg: np.ndarray) -> np.ndarray:
        """``[m, dof + 1, 2]`` joint points for ``m`` configurations ``[m, dof]`` (one arm)."""
        if self.multi_arm:
            raise ValueError("several arms: use Oracle.world.joint_points (one array per arm)")
        q = np.radians(np.atleast_2d(np.asarray(q_deg, dtype=float)))
        theta = np.cumsum(q, axis=1)
        steps = np.stack([self.links * np.cos(theta), self.links * np.sin(theta)], axis=-1)
        pts = np.concatenate([np.zeros((q.shape[0], 1, 2)), np.cumsum(steps, axis=1)], axis=1)
        return pts + self.base

    def clearance(self, q_deg: np.ndarray) -> np.ndarray:
        """Exact clearance per configuration (``inf`` without obstacles)."""
        if self.multi_arm:
            return self._world.clearance(q_deg)
        pts = self.points(q_deg)
        m, k = pts.shape[0], pts.shape[1] - 1
        best = np.full(m, np.inf)
        for i in range(k):
            segs = shapely.linestrings(np.stack([pts[:, i], pts[:, i + 1]], axis=1))
            for center, r in self.circles:
                best = np.minimum(best, np.maximum(shapely.distance(segs, center) - r, 0.0) - self.radius)
            for b in self.boxes:
                best = np.minimum(best, shapely.distance(segs, b) - self.radius)
        # Self-collision: links i and j >= i + 2 of the arm (exact shapely segment distances).
        for i in range(k):
            si = shapely.linestrings(np.stack([pts[:, i], pts[:, i + 1]], axis=1))
            for j in range(i + 2, k):
                sj = shapely.linestrings(np.stack([pts[:, j], pts[:, j + 1]], axis=1))
                best = np.minimum(best, shapely.distance(si, sj) - 2.0 * self.radius)
        return best

    def in_collision(self, q_deg: np.ndarray) -> np.ndarray:
        q = np.atleast_2d(np.asarray(q_deg, dtype=float))
        outside = np.any((q < self.limits[:, 0]) | (q > self.limits[:, 1]), axis=1)
        return outside | (self.clearance(q) <= 0.0)

    def densify(self, path_deg: np.ndarray, resolution_deg: float = 0.05) -> np.ndarray:
        """Configurations along every segment so no joint moves more than ``resolution_deg``."""
        path = np.asarray(path_deg, dtype=float)
        chunks = []
        for a, b in zip(path[:-1], path[1:]):
            n = max(1, int(math.ceil(np.max(np.abs(b - a)) / resolution_deg)))
            s = np.linspace(0.0, 1.0, n + 1)[:, None]
            chunks.append(a + s * (b - a))
        return np.concatenate(chunks) if chunks else path

    def path_problems(self, path_deg, resolution_deg: float = 0.05) -> list[str]:
        """Everything wrong with a path: endpoints and any colliding configuration on it."""
        path = np.asarray(path_deg, dtype=float)
        problems = []
        if path.ndim != 2 or path.shape[0] < 2:
            return ["path has fewer than two configurations"]
        if not np.array_equal(path[0], self.start):
            problems.append(f"path starts at {path[0]} not {self.start}")
        if not np.array_equal(path[-1], self.goal):
            problems.append(f"path ends at {path[-1]} not {self.goal}")
        dense = self.densify(path, resolution_deg)
        bad = self.in_collision(dense)
        if bad.any():
            problems.append(f"{int(bad.sum())} colliding configurations, first {dense[bad][0]}")
        return problems

    # ------------------------------------------------------------- clearance margins (issue 18)

    @classmethod
    def from_arrays(cls, links, base, radius, obstacles, limits=None) -> "Oracle":
        """An oracle for a random arm and obstacle rows ``[kind, a, b, c, d]`` (no file)."""
        self = cls.__new__(cls)
        self.links = np.asarray(links, dtype=float)
        self.base = np.asarray(base, dtype=float)
        self.radius = float(radius)
        n = len(self.links)
        self.limits = (np.array([[-1e9, 1e9]] * n) if limits is None
                       else np.asarray(limits, dtype=float))
        self.start = self.goal = None
        self._world = None
        self.circles, self.boxes = [], []
        for ob in np.asarray(obstacles, dtype=float).reshape(-1, 5):
            if ob[0] == 0.0:
                self.circles.append((shapely.Point(ob[1], ob[2]), float(ob[3])))
            else:
                self.boxes.append(shapely.box(ob[1], ob[2], ob[3], ob[4]))
        return self

    def motion_bound(self, qa, qb) -> float:
        """Largest speed (m per unit s) of any arm point on ``qa -> qb``, re-derived here:
        a point of link k moves at most ``Σ_{i<=k} l_i |θ̇_i|`` with ``|θ̇_i| <= Σ_{j<=i} |q̇_j|``.
        With several arms: the sum over arms of each arm's largest speed (it bounds both how fast
        a link nears an obstacle and how fast two arms' links near each other)."""
        if self.multi_arm:
            return float(sum(v.max() for v in self._world.link_speeds(qa, qb) if v.size))
        dq = np.abs(np.radians(np.asarray(qb, dtype=float) - np.asarray(qa, dtype=float)))
        return float(sum(self.links[i] * dq[: i + 1].sum() for i in range(len(self.links))))

    def min_distance_along(self, path_deg, resolution_deg: float = 0.02):
        """``(sampled minimum, configuration, proven lower bound)`` of the clearance along a
        path. The minimum is of exact distances at real configurations (so a value below a
        margin is a real violation); the lower bound subtracts, per segment, the most any arm
        point can move between two samples (half the sample spacing times the motion bound),
        so nothing on the path is closer than it."""
        path = np.atleast_2d(np.asarray(path_deg, dtype=float))
        best, where, lower = math.inf, path[0], math.inf
        if path.shape[0] == 1:
            c = float(self.clearance(path)[0])
            return c, path[0], c
        for a, b in zip(path[:-1], path[1:]):
            n = max(1, int(math.ceil(np.max(np.abs(b - a)) / resolution_deg)))
            s = np.linspace(0.0, 1.0, n + 1)[:, None]
            q = a + s * (b - a)
            c = self.clearance(q)
            i = int(np.argmin(c))
            if c[i] < best:
                best, where = float(c[i]), q[i]
            lower = min(lower, float(c.min()) - 0.5 * self.motion_bound(a, b) / n)
        return best, where, lower

    def keeps_margin(self, path_deg, margin: float, resolution_deg: float = 0.02) -> list[str]:
        """Violations of ``min distance >= margin`` along the path (empty: none found)."""
        best, where, _ = self.min_distance_along(path_deg, resolution_deg)
        if best < margin:
            return [f"clearance {best!r} m < margin {margin!r} m at q = {where}"]
        return []


# ================================================================================================
# N links, several arms: the exact-geometry oracle of issue 17 (plain numpy and math)
# ================================================================================================
#
# Everything below is written without the package's geometry code (no collision, path_check,
# clearance or kinematics import); it only reads the scenario *model* (Scenario, ScenarioArrays,
# or a scenario file through the package loader when the file holds several arms).
#
# **What is decided.** A configuration ``q`` (every arm's angles, arm after arm, degrees) is free
# when it is within the joint limits (closed) and its clearance is > 0, where the clearance is the
# smallest of
#
# - ``dist(link segment, obstacle) - r_a`` for every link of every arm ``a`` and every obstacle
#   (circles and axis-aligned boxes are closed sets: touching, clearance 0, is a collision), and
# - ``dist(link segment of arm a, link segment of arm b) - r_a - r_b`` for every pair of links of
#   two *different* arms, and
# - ``dist(link i, link j) - 2 r_a`` for every pair of links ``j >= i + 2`` of ONE arm ``a``
#   (self-collision). Adjacent links share a joint point, so they never count: how far a joint
#   folds (even to ±180°, one link on the other) is the joint limits' business.
#
# Distances are exact plane geometry evaluated in float64 (see the primitives):
#
# - point-segment: the clamped orthogonal projection;
# - segment-segment: 0 when the two segments cross properly (strict orientation tests), else the
#   smallest of the four endpoint-to-other-segment distances. This is exact: two plane segments
#   that do not cross properly reach their smallest distance at an endpoint of one of them (and
#   when they touch or overlap collinearly an endpoint lies on the other segment, distance 0);
# - segment-circle: ``max(dist(centre, segment) - R, 0)``;
# - segment-box: 0 when an endpoint lies in the closed box, else the smallest segment-segment
#   distance to the four edges (a segment with no endpoint inside a convex polygon meets the
#   polygon iff it meets its boundary, and the distance to a convex set from outside is the
#   distance to its boundary).
#
# **Along a joint segment** ``q(s) = qa + s (qb - qa)``, ``s in [0, 1]``, the minimum clearance is
# bracketed by Lipschitz branch and bound with a velocity bound derived here, independently of
# ``link_motion_bound``:
#
#   Write ``Δq`` in radians. Link ``i`` of an arm points along ``θ_i(s) = Σ_{j<=i} q_j(s)`` (local
#   joint indices), so ``θ_i' = Ω_i := Σ_{j<=i} Δq_j`` is *constant* along the segment (the
#   segment is straight in joint space). The point at fraction ``t`` of link ``k`` is
#   ``p(s) = base + Σ_{i<k} l_i e(θ_i) + t l_k e(θ_k)`` with ``e(θ) = (cos θ, sin θ)``, hence
#   ``p'(s) = Σ_{i<k} l_i Ω_i e⊥(θ_i) + t l_k Ω_k e⊥(θ_k)`` and
#
#       |p'(s)| <= V_k := Σ_{i<=k} l_i |Ω_i|          for every s and every t in [0, 1].
#
#   So no point of link ``k`` moves more than ``V_k |Δs|`` (integrate the speed). The link set at
#   ``s`` and at ``s'`` are then within Hausdorff distance ``V_k |s - s'|``, and a distance between
#   sets is 1-Lipschitz in each set under the Hausdorff distance: the link-obstacle clearance is
#   ``V_k``-Lipschitz in ``s`` and the link(a, k)-link(b, m) clearance is
#   ``(V^a_k + V^b_m)``-Lipschitz. (``|Ω_i| <= Σ_{j<=i} |Δq_j|`` shows ``V_k <= M_k``, the
#   package's bound; the property tests check the package's bound, not this one.)
#
#   Two links ``i < j`` of ONE arm: a distance is invariant under a rigid motion applied to both
#   sets, so measure it in link ``i``'s own frame, where link ``i`` is fixed and a point of link
#   ``j`` is ``l_i e(0) + Σ_{i<h<j} l_h e(ψ_h) + t l_j e(ψ_j)`` with ``ψ_h = Σ_{i<g<=h} q_g``;
#   its speed is at most ``W_ij := Σ_{i<h<=j} l_h |Σ_{i<g<=h} Δq_g|`` (the same computation with
#   the joints before ``i+1`` left out: they move both links together). So the self pair's
#   clearance is ``W_ij``-Lipschitz.
#
#   A function ``f`` that is ``L``-Lipschitz on ``[s0, s1]`` (width ``h``) with end values
#   ``f0, f1`` satisfies ``f(s) >= max(f0 - L (s - s0), f1 - L (s1 - s)) >= (f0 + f1 - L h) / 2``.
#   The clearance is the minimum over pairs, so on an interval it is at least
#   ``min_pairs (f0_p + f1_p - L_p h) / 2`` (each pair with its own constant, so a fast link far
#   away does not blur a slow one near an obstacle). Intervals whose bound is within ``tol`` of
#   the best exact value seen (or, when deciding, already above the threshold) are closed; the
#   others are halved. The result is a bracket ``lower <= min_s clearance(q(s)) <= upper`` where
#   ``upper`` is an exact clearance at a real configuration on the segment (``q_at_upper``), and,
#   unless the evaluation budget ran out (``exhausted``), ``upper - lower <= tol``.
#
#   Curvature (what closes *flat* minima: two links of a straight arm stay exactly one link
#   apart while a joint between them turns, so the clearance is constant over a whole segment
#   and the Lipschitz bound alone needs ``L / tol`` intervals). The points above move along
#   sums of ``l_h e(ψ_h)`` with every ``ψ_h`` linear in ``s``, so the vector ``u`` between a
#   point of one body and a point of the other has ``|u'| <= L_p`` and
#   ``|u''| <= A_p := Σ l_h (Σ Δq)²`` (the same sums as the speeds, the rates squared; for two
#   arms the two links' sums added). While ``|u| >= D > 0``,
#   ``|u|'' = (|u'|² - (u·u'/|u|)²) / |u| + u·u''/|u| <= L_p² / D + A_p =: K_p``, and a pair's
#   clearance is a minimum of such ``|u|`` over the two bodies' points (minus constants), so on
#   ``[s0, s1]`` it stays above its chord minus ``K_p/2 (s - s0)(s1 - s)``. ``D`` is the
#   Lipschitz bound itself plus the capsule radii (``-floor``; a circle's radius is left out,
#   which only lowers ``D``); where that is not positive only the Lipschitz bound is used. The
#   lowest point of that parabola on the interval is the second bound; a pair keeps the larger.
#
# **Tolerance.** Float64 rounding: coordinates are sums of at most 7 products of magnitude
# ``S`` (the scene's extent), so every computed distance is within ``FP_REL * max(S, 1)`` metres
# of the exact one, ``FP_REL = 1e-12`` (a generous multiple of the ~1e-15 accumulated error).
# ``lower`` has that slack subtracted (so it stays a proof); ``upper`` is the computed value.
# Conservatively for certification, a segment is reported *free* only if ``lower > threshold``
# and *colliding* only if ``upper <= threshold`` at a real configuration; in between it is
# undecided (``is_free`` says False, ``collides`` says False) - that only happens within
# ``tol + slack`` of touching (default ``tol`` 1e-9 m, a thousandth of the planners' 1 µm margin).

DEFAULT_TOL_M = 1e-9
FP_REL = 1e-12
MAX_EVALS = 4_000_000  # configurations evaluated per segment before giving up refining


def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


def point_segment_distance(px, py, ax, ay, bx, by):
    """Exact distance from points P to segments AB (broadcasting numpy arrays or floats)."""
    px, py, ax, ay, bx, by = np.broadcast_arrays(*map(np.asarray, (px, py, ax, ay, bx, by)))
    dx, dy = bx - ax, by - ay
    den = dx * dx + dy * dy
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(den > 0.0, ((px - ax) * dx + (py - ay) * dy) / np.where(den > 0, den, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    return np.hypot(ax + t * dx - px, ay + t * dy - py)


def segment_segment_distance(a, b, c, d):
    """Exact distance between plane segments AB and CD (arrays ``[..., 2]``, broadcasting)."""
    a, b, c, d = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (a, b, c, d)))
    ax, ay, bx, by = a[..., 0], a[..., 1], b[..., 0], b[..., 1]
    cx, cy, dx, dy = c[..., 0], c[..., 1], d[..., 0], d[..., 1]
    o1 = _cross(bx - ax, by - ay, cx - ax, cy - ay)
    o2 = _cross(bx - ax, by - ay, dx - ax, dy - ay)
    o3 = _cross(dx - cx, dy - cy, ax - cx, ay - cy)
    o4 = _cross(dx - cx, dy - cy, bx - cx, by - cy)
    proper = (((o1 > 0) & (o2 < 0)) | ((o1 < 0) & (o2 > 0))) & \
             (((o3 > 0) & (o4 < 0)) | ((o3 < 0) & (o4 > 0)))
    ends = np.minimum(
        np.minimum(point_segment_distance(ax, ay, cx, cy, dx, dy),
                   point_segment_distance(bx, by, cx, cy, dx, dy)),
        np.minimum(point_segment_distance(cx, cy, ax, ay, bx, by),
                   point_segment_distance(dx, dy, ax, ay, bx, by)))
    return np.where(proper, 0.0, ends)


def segment_circle_distance(a, b, center, r):
    """Exact distance from segments AB to the closed disc (0 when they meet)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    d = point_segment_distance(center[0], center[1], a[..., 0], a[..., 1], b[..., 0], b[..., 1])
    return np.maximum(d - r, 0.0)


def segment_box_distance(a, b, lo, hi):
    """Exact distance from segments AB to closed boxes ``[lo, hi]`` (0 when they meet;
    ``[..., 2]`` arrays, broadcasting)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    x0, y0, x1, y1 = lo[..., 0], lo[..., 1], hi[..., 0], hi[..., 1]
    corners = [np.stack([x, y], axis=-1) for x, y in ((x0, y0), (x1, y0), (x1, y1), (x0, y1))]
    best = None
    for i in range(4):
        e = segment_segment_distance(a, b, corners[i], corners[(i + 1) % 4])
        best = e if best is None else np.minimum(best, e)

    def inside(p):
        return (p[..., 0] >= x0) & (p[..., 0] <= x1) & (p[..., 1] >= y0) & (p[..., 1] <= y1)

    return np.where(inside(a) | inside(b), 0.0, best)


class World:
    """Arms, obstacles and joint limits, as this oracle's own plain data.

    ``arms`` is a list of ``(links [n], base (x, y), radius)``; joint columns of a configuration
    follow the arms in order. ``circles`` rows ``(cx, cy, R)``, ``boxes`` rows
    ``(x0, y0, x1, y1)``; ``limits`` ``[dof, 2]`` degrees (closed).
    """

    def __init__(self, arms, circles=(), boxes=(), limits=None):
        self.arms = [(np.asarray(l, dtype=float).reshape(-1), np.asarray(b, dtype=float).reshape(2),
                      float(r)) for l, b, r in arms]
        self.circles = np.asarray(circles, dtype=float).reshape(-1, 3)
        self.boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
        self.first = np.concatenate([[0], np.cumsum([len(l) for l, _, _ in self.arms])]).astype(int)
        self.dof = int(self.first[-1])
        self.limits = (np.tile([-np.inf, np.inf], (self.dof, 1)) if limits is None
                       else np.asarray(limits, dtype=float).reshape(self.dof, 2))
        pts = [b for _, b, _ in self.arms] + [c[:2] for c in self.circles] + \
              [bx[:2] for bx in self.boxes] + [bx[2:] for bx in self.boxes]
        extent = max([float(np.max(np.abs(p))) for p in pts] + [0.0])
        extent += sum(float(l.sum()) for l, _, _ in self.arms) + \
            max([float(c[2]) for c in self.circles] + [0.0])
        #: Float64 rounding allowance (m) subtracted from every proven lower bound.
        self.slack = FP_REL * max(extent, 1.0)
        # Pair layout (the columns of pair_clearances): per arm, its links x circles then its
        # links x boxes (link-major); then per pair of arms a < b, links of a x links of b.
        self._pairs = []
        for a, (links, _, _) in enumerate(self.arms):
            self._pairs += [("circle", a, k, o, -1) for k in range(len(links))
                            for o in range(len(self.circles))]
            self._pairs += [("box", a, k, o, -1) for k in range(len(links))
                            for o in range(len(self.boxes))]
        for a in range(len(self.arms)):
            for b in range(a + 1, len(self.arms)):
                self._pairs += [("arm", a, k, b, m) for k in range(len(self.arms[a][0]))
                                for m in range(len(self.arms[b][0]))]
        # then per arm its non-adjacent link pairs (i, j >= i + 2), i-major
        self._self = [[(i, j) for i in range(len(l)) for j in range(i + 2, len(l))]
                      for l, _, _ in self.arms]
        for a, pairs in enumerate(self._self):
            self._pairs += [("self", a, i, a, j) for i, j in pairs]

    # -------------------------------------------------------------------------- construction

    @classmethod
    def from_arrays(cls, arrays) -> "World":
        """From a :class:`ScenarioArrays` (several arms when it has ``arm_first``)."""
        links = np.asarray(arrays.links, dtype=float)
        first = np.asarray(getattr(arrays, "arm_first", [0, len(links)]), dtype=int)
        bases = np.asarray(getattr(arrays, "bases", np.asarray(arrays.base).reshape(1, 2)),
                           dtype=float).reshape(-1, 2)
        radii = np.asarray(getattr(arrays, "radii", [arrays.link_radius]), dtype=float)
        arms = [(links[first[i]:first[i + 1]], bases[i], radii[i]) for i in range(len(first) - 1)]
        circles, boxes = _split_obstacle_rows(arrays.obstacles)
        return cls(arms, circles, boxes, arrays.limits_deg)

    @classmethod
    def from_scenario(cls, scenario) -> "World":
        """From a :class:`Scenario` (its ``arms``; the first is ``scenario.arm``)."""
        arms = getattr(scenario, "arms", (scenario.arm,))
        circles, boxes = [], []
        for o in scenario.obstacles:
            if hasattr(o, "radius"):
                circles.append((o.center[0], o.center[1], o.radius))
            else:
                boxes.append((o.min[0], o.min[1], o.max[0], o.max[1]))
        limits = [lim for arm in arms for lim in arm.joint_limits_deg]
        return cls([(arm.links, arm.base, arm.link_radius) for arm in arms], circles, boxes,
                   limits if limits else None)

    @classmethod
    def from_obstacle_rows(cls, arms, obstacles, limits=None) -> "World":
        """From ``[(links, base, radius), ...]`` and ``[kind, a, b, c, d]`` obstacle rows."""
        circles, boxes = _split_obstacle_rows(obstacles)
        return cls(arms, circles, boxes, limits)

    # -------------------------------------------------------------------------- kinematics

    def joint_points(self, q_deg):
        """Per arm, ``[m, n + 1, 2]`` base, joints and tip for configurations ``[m, dof]``."""
        q = np.radians(np.atleast_2d(np.asarray(q_deg, dtype=float)))
        if q.shape[1] != self.dof:
            raise ValueError(f"configuration has {q.shape[1]} angles, the arms have {self.dof}")
        out = []
        for a, (links, base, _) in enumerate(self.arms):
            theta = np.cumsum(q[:, self.first[a]:self.first[a + 1]], axis=1)
            steps = np.stack([links * np.cos(theta), links * np.sin(theta)], axis=-1)
            pts = np.concatenate([np.zeros((q.shape[0], 1, 2)), np.cumsum(steps, axis=1)], axis=1)
            out.append(pts + base)
        return out

    def link_speeds(self, qa_deg, qb_deg):
        """Per arm, ``V_k = Σ_{i<=k} l_i |Σ_{j<=i} Δq_j|`` (module notes): no point of link k
        moves more than ``V_k |Δs|`` on ``qa -> qb``."""
        dq = np.radians(np.asarray(qb_deg, dtype=float) - np.asarray(qa_deg, dtype=float))
        out = []
        for a, (links, _, _) in enumerate(self.arms):
            omega = np.abs(np.cumsum(dq[self.first[a]:self.first[a + 1]]))
            out.append(np.cumsum(links * omega))
        return out

    # -------------------------------------------------------------------------- clearance

    @property
    def n_pairs(self) -> int:
        return len(self._pairs)

    def pair_clearances(self, q_deg) -> np.ndarray:
        """``[m, P]`` exact capsule clearance of every pair (link-obstacle, link-link of two
        arms) at configurations ``[m, dof]``; ``<= 0`` is contact."""
        pts = self.joint_points(q_deg)
        m = np.atleast_2d(q_deg).shape[0]
        cols = []
        for a, (links, _, radius) in enumerate(self.arms):
            A, B = pts[a][:, :-1, None, :], pts[a][:, 1:, None, :]  # [m, n, 1, 2]
            if len(self.circles):
                c = self.circles
                d = point_segment_distance(c[:, 0], c[:, 1], A[..., 0], A[..., 1],
                                           B[..., 0], B[..., 1])
                cols.append((np.maximum(d - c[:, 2], 0.0) - radius).reshape(m, -1))
            if len(self.boxes):
                d = segment_box_distance(A, B, self.boxes[:, :2], self.boxes[:, 2:])
                cols.append((d - radius).reshape(m, -1))
        for a in range(len(self.arms)):
            for b in range(a + 1, len(self.arms)):
                ra, rb = self.arms[a][2], self.arms[b][2]
                pa, pb = pts[a], pts[b]
                d = segment_segment_distance(pa[:, :-1, None, :], pa[:, 1:, None, :],
                                             pb[:, None, :-1, :], pb[:, None, 1:, :])
                cols.append((d - ra - rb).reshape(m, -1))
        for a, pairs in enumerate(self._self):
            if pairs:
                i = np.array([p[0] for p in pairs])
                j = np.array([p[1] for p in pairs])
                pa = pts[a]
                d = segment_segment_distance(pa[:, i], pa[:, i + 1], pa[:, j], pa[:, j + 1])
                cols.append((d - 2.0 * self.arms[a][2]).reshape(m, -1))
        if not cols:
            return np.zeros((m, 0))
        return np.concatenate(cols, axis=1)

    def pair_lipschitz(self, qa_deg, qb_deg) -> np.ndarray:
        """``[P]`` Lipschitz constant in ``s`` of every pair's clearance on ``qa -> qb``."""
        v = self.link_speeds(qa_deg, qb_deg)
        out = []
        for a in range(len(self.arms)):
            out.append(np.repeat(v[a], len(self.circles)))
            out.append(np.repeat(v[a], len(self.boxes)))
        for a in range(len(self.arms)):
            for b in range(a + 1, len(self.arms)):
                out.append((v[a][:, None] + v[b][None, :]).ravel())
        dq = np.radians(np.asarray(qb_deg, dtype=float) - np.asarray(qa_deg, dtype=float))
        for a, pairs in enumerate(self._self):
            links = self.arms[a][0]
            local = dq[self.first[a]:self.first[a + 1]]
            out.append(np.array([self.self_pair_speed(links, local, i, j) for i, j in pairs]))
        return np.concatenate(out) if out else np.zeros(0)

    def pair_accel(self, qa_deg, qb_deg) -> np.ndarray:
        """``[P]`` bound on the relative acceleration (m per unit ``s``²) of the two closest
        points of every pair on ``qa -> qb`` (module notes: the speeds' sums, rates squared)."""
        dq = np.radians(np.asarray(qb_deg, dtype=float) - np.asarray(qa_deg, dtype=float))
        acc = [np.cumsum(links * np.cumsum(dq[self.first[a]:self.first[a + 1]]) ** 2)
               for a, (links, _, _) in enumerate(self.arms)]
        out = []
        for a in range(len(self.arms)):
            out.append(np.repeat(acc[a], len(self.circles)))
            out.append(np.repeat(acc[a], len(self.boxes)))
        for a in range(len(self.arms)):
            for b in range(a + 1, len(self.arms)):
                out.append((acc[a][:, None] + acc[b][None, :]).ravel())
        for a, pairs in enumerate(self._self):
            links = self.arms[a][0]
            local = dq[self.first[a]:self.first[a + 1]]
            out.append(np.array([float(np.sum(links[i + 1:j + 1] *
                                              np.cumsum(local[i + 1:j + 1]) ** 2))
                                 for i, j in pairs]))
        return np.concatenate(out) if out else np.zeros(0)

    @staticmethod
    def self_pair_speed(links, dq_rad, i, j) -> float:
        """``W_ij = Σ_{i<h<=j} l_h |Σ_{i<g<=h} Δq_g|`` (module notes): how fast link ``j``
        moves in the frame of link ``i`` of the same arm."""
        omega = np.abs(np.cumsum(dq_rad[i + 1:j + 1]))
        return float(np.sum(links[i + 1:j + 1] * omega))

    def pair_floors(self) -> np.ndarray:
        """``[P]`` the least clearance a pair can have: distances are >= 0, so ``-r_a`` for a
        link of arm a and an obstacle, ``-r_a - r_b`` for two arms' links (a deep collision
        sits flat at this value, which the branch and bound would otherwise split forever)."""
        out = []
        for a, (_, _, r) in enumerate(self.arms):
            out.append(np.full(len(self.arms[a][0]) * (len(self.circles) + len(self.boxes)), -r))
        for a in range(len(self.arms)):
            for b in range(a + 1, len(self.arms)):
                out.append(np.full(len(self.arms[a][0]) * len(self.arms[b][0]),
                                   -self.arms[a][2] - self.arms[b][2]))
        for a, pairs in enumerate(self._self):
            out.append(np.full(len(pairs), -2.0 * self.arms[a][2]))
        return np.concatenate(out) if out else np.zeros(0)

    def pair_names(self) -> list[str]:
        """Readable names of the pairs, in :meth:`pair_clearances` column order."""
        names = []
        for kind, a, k, b, mm in self._pairs:
            names.append(f"arm {a} link {k} / arm {b} link {mm}" if kind in ("arm", "self")
                         else f"arm {a} link {k} / {kind} {b}")
        return names

    def clearance(self, q_deg) -> np.ndarray:
        """``[m]`` exact clearance (``inf`` with nothing to touch); ``<= 0`` is a collision."""
        c = self.pair_clearances(q_deg)
        return c.min(axis=1) if c.shape[1] else np.full(c.shape[0], np.inf)

    def within_limits(self, q_deg) -> np.ndarray:
        q = np.atleast_2d(np.asarray(q_deg, dtype=float))
        return np.all((q >= self.limits[:, 0]) & (q <= self.limits[:, 1]), axis=1)

    def in_collision(self, q_deg) -> np.ndarray:
        return ~self.within_limits(q_deg) | (self.clearance(q_deg) <= 0.0)

    # -------------------------------------------------------------------------- along a segment

    def segment_min_clearance(self, qa_deg, qb_deg, tol: float = DEFAULT_TOL_M,
                              threshold: float | None = None, max_evals: int = MAX_EVALS,
                              initial: int = 16) -> "Bracket":
        """Bracket the smallest clearance on ``qa -> qb`` (module notes). With ``threshold``,
        stop as soon as it is decided whether the minimum is above it (for yes/no use)."""
        qa = np.asarray(qa_deg, dtype=float)
        qb = np.asarray(qb_deg, dtype=float)
        if self.n_pairs == 0:
            return Bracket(math.inf, math.inf, qa, False)
        lip = self.pair_lipschitz(qa, qb)
        acc = self.pair_accel(qa, qb)[None, :]
        floor = self.pair_floors()[None, :]
        if not np.any(qb != qa):
            c = float(self.pair_clearances(qa)[0].min())
            return Bracket(c - self.slack, c, qa, False)
        s = np.linspace(0.0, 1.0, initial + 1)
        s[-1] = 1.0
        f = self.pair_clearances(self._at(qa, qb, s))
        evals = len(s)
        vals = f.min(axis=1)
        j = int(np.argmin(vals))
        upper, s_up = float(vals[j]), float(s[j])
        s0, s1, f0, f1 = s[:-1], s[1:], f[:-1], f[1:]
        closed_lower = math.inf
        exhausted = False
        while s0.size:
            h = s1 - s0
            low1 = np.maximum((f0 + f1 - lip[None, :] * h[:, None]) * 0.5, floor)
            low = np.min(np.maximum(low1, _curvature_bound(f0, f1, lip[None, :], acc, low1 - floor,
                                                           h[:, None])), axis=1)
            low = np.minimum(low, np.minimum(f0.min(axis=1), f1.min(axis=1)))
            done = low >= upper - tol
            if threshold is not None:
                if upper <= threshold:  # decided: a real configuration at or below it
                    done[:] = True
                done |= low > threshold + self.slack
            done |= h <= 1e-15  # s itself cannot be split further in float64
            if done.any():
                closed_lower = min(closed_lower, float(low[done].min()))
            keep = ~done
            if not keep.any():
                break
            if evals + int(keep.sum()) > max_evals:
                closed_lower = min(closed_lower, float(low[keep].min()))
                exhausted = True
                break
            s0, s1, f0, f1 = s0[keep], s1[keep], f0[keep], f1[keep]
            mid = 0.5 * (s0 + s1)
            fm = self.pair_clearances(self._at(qa, qb, mid))
            evals += mid.size
            vm = fm.min(axis=1)
            j = int(np.argmin(vm))
            if vm[j] < upper:
                upper, s_up = float(vm[j]), float(mid[j])
            s0, s1 = np.concatenate([s0, mid]), np.concatenate([mid, s1])
            f0, f1 = np.concatenate([f0, fm]), np.concatenate([fm, f1])
        lower = min(closed_lower, upper) - self.slack
        return Bracket(lower, upper, self._at(qa, qb, np.array([s_up]))[0], exhausted)

    @staticmethod
    def _at(qa, qb, s):
        q = qa[None, :] + np.asarray(s)[:, None] * (qb - qa)[None, :]
        q[np.asarray(s) >= 1.0] = qb  # the end of the segment is exactly qb
        return q

    def path_min_clearance(self, path_deg, tol: float = DEFAULT_TOL_M,
                           threshold: float | None = None) -> "Bracket":
        """The bracket over every segment of a path (a single row: that configuration)."""
        path = np.atleast_2d(np.asarray(path_deg, dtype=float))
        if path.shape[0] == 1:
            return self.segment_min_clearance(path[0], path[0], tol, threshold)
        best = None
        for qa, qb in zip(path[:-1], path[1:]):
            r = self.segment_min_clearance(qa, qb, tol, threshold)
            best = r if best is None else best.join(r)
            if threshold is not None and best.upper <= threshold:
                break
        return best


def _curvature_bound(f0, f1, lip, acc, dist, h):
    """Per pair, the lowest point of ``chord - K/2 (s - s0)(s1 - s)`` on intervals of width
    ``h`` (module notes), ``K = acc + lip² / dist``; ``-inf`` where ``dist`` (a lower bound on
    the bodies' distance) is not positive or a value is not finite."""
    ok = (dist > 0.0) & np.isfinite(f0) & np.isfinite(f1)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = 0.5 * (acc + lip * lip / np.where(ok, dist, 1.0)) * h * h
        d = f1 - f0
        inner = 0.5 * (f0 + f1) - 0.25 * a - d * d / (4.0 * a)
        out = np.where(np.abs(d) >= a, np.minimum(f0, f1), inner)
    return np.where(ok, out, -np.inf)


@dataclass(frozen=True)
class Bracket:
    """``lower <= min clearance <= upper`` (m); ``upper`` is exact at ``q_at_upper``."""

    lower: float
    upper: float
    q_at_upper: np.ndarray
    exhausted: bool = False

    def join(self, other: "Bracket") -> "Bracket":
        q = self.q_at_upper if self.upper <= other.upper else other.q_at_upper
        return Bracket(min(self.lower, other.lower), min(self.upper, other.upper), q,
                       self.exhausted or other.exhausted)


def _split_obstacle_rows(rows):
    rows = np.asarray(rows, dtype=float).reshape(-1, 5)
    circles = [(r[1], r[2], r[3]) for r in rows if r[0] == 0.0]
    boxes = [(r[1], r[2], r[3], r[4]) for r in rows if r[0] != 0.0]
    return circles, boxes


def as_world(x) -> World:
    """A :class:`World` from a World, an Oracle, a Scenario, ScenarioArrays or a scenario file."""
    if isinstance(x, World):
        return x
    if isinstance(x, Oracle):
        return x.world
    if isinstance(x, (str, Path)):
        return Oracle(x).world
    if hasattr(x, "obstacles") and hasattr(x, "limits_deg") and hasattr(x, "links"):
        return World.from_arrays(x)
    if hasattr(x, "arm") and hasattr(x, "obstacles"):
        return World.from_scenario(x)
    raise TypeError(f"cannot build an oracle world from {type(x).__name__}")


def oracle_clearance(x, q_deg) -> np.ndarray:
    """Exact clearance per configuration ``[m]`` (arm-obstacle and arm-arm)."""
    return as_world(x).clearance(q_deg)


def oracle_in_collision(x, q_deg) -> np.ndarray:
    """Per configuration: outside the joint limits or touching (clearance <= 0)."""
    return as_world(x).in_collision(q_deg)


def oracle_segment_min_clearance(x, qa_deg, qb_deg, tol: float = DEFAULT_TOL_M) -> tuple[float, float]:
    """``(lower, upper)``: the proven bracket of the smallest clearance on ``qa -> qb``."""
    r = as_world(x).segment_min_clearance(qa_deg, qb_deg, tol)
    return r.lower, r.upper


def oracle_path_min_clearance(x, path_deg, tol: float = DEFAULT_TOL_M) -> tuple[float, float]:
    """``(lower, upper)``: the proven bracket of the smallest clearance along the path."""
    r = as_world(x).path_min_clearance(path_deg, tol)
    return r.lower, r.upper


def oracle_path_is_free(x, path_deg, clearance_m: float = 0.0, tol: float = DEFAULT_TOL_M) -> bool:
    """Proven: every vertex within the joint limits and every configuration on every segment
    keeps clearance ``> clearance_m`` (0: not touching). False when it cannot be proven."""
    w = as_world(x)
    path = np.atleast_2d(np.asarray(path_deg, dtype=float))
    if path.shape[1] != w.dof or not np.all(w.within_limits(path)):
        return False
    return bool(w.path_min_clearance(path, tol, threshold=clearance_m).lower > clearance_m)


def oracle_path_collides(x, path_deg, tol: float = DEFAULT_TOL_M) -> bool:
    """Proven: some vertex is outside the limits or some configuration on the path touches
    (exact clearance <= 0 at a real configuration)."""
    w = as_world(x)
    path = np.atleast_2d(np.asarray(path_deg, dtype=float))
    if not np.all(w.within_limits(path)):
        return True
    return bool(w.path_min_clearance(path, tol, threshold=0.0).upper <= 0.0)


def oracle_path_problems(x, path_deg, start=None, goal=None, clearance_m: float = 0.0) -> list[str]:
    """Everything wrong with a path (empty: proven free, endpoints as given), readable."""
    w = as_world(x)
    path = np.atleast_2d(np.asarray(path_deg, dtype=float))
    if path.shape[0] < 2 or path.shape[1] != w.dof:
        return [f"path shape {path.shape} (need >= 2 rows of {w.dof} angles)"]
    problems = []
    if start is not None and not np.array_equal(path[0], np.asarray(start, dtype=float)):
        problems.append(f"path starts at {path[0]} not {start}")
    if goal is not None and not np.array_equal(path[-1], np.asarray(goal, dtype=float)):
        problems.append(f"path ends at {path[-1]} not {goal}")
    out = ~w.within_limits(path)
    if out.any():
        problems.append(f"{int(out.sum())} vertices outside the joint limits, first {path[out][0]}")
    r = w.path_min_clearance(path, threshold=clearance_m)
    if not r.lower > clearance_m:
        what = "touches or collides" if r.upper <= clearance_m else "cannot be proven clear"
        problems.append(f"path {what}: min clearance in [{r.lower!r}, {r.upper!r}] m "
                        f"(needs > {clearance_m!r}) near q = {r.q_at_upper}")
    return problems
