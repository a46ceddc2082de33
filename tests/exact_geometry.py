"""An independent exact-geometry oracle built on shapely (no project code involved).

Forward kinematics is re-derived here in plain numpy; link segments are shapely LineStrings;
circle obstacles are measured exactly as distance-to-centre minus radius (a buffered shapely
circle would be a polygon approximation); boxes are exact shapely rectangles. A configuration
collides when a link comes within ``link_radius`` of an obstacle (touching counts).
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import shapely


class Oracle:
    def __init__(self, scenario_file: str | Path):
        data = tomllib.loads(Path(scenario_file).read_text())
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

    def points(self, q_deg: np.ndarray) -> np.ndarray:
        """``[m, dof + 1, 2]`` joint points for ``m`` configurations ``[m, dof]``."""
        q = np.radians(np.atleast_2d(np.asarray(q_deg, dtype=float)))
        theta = np.cumsum(q, axis=1)
        steps = np.stack([self.links * np.cos(theta), self.links * np.sin(theta)], axis=-1)
        pts = np.concatenate([np.zeros((q.shape[0], 1, 2)), np.cumsum(steps, axis=1)], axis=1)
        return pts + self.base

    def clearance(self, q_deg: np.ndarray) -> np.ndarray:
        """Exact clearance per configuration (``inf`` without obstacles)."""
        pts = self.points(q_deg)
        m, k = pts.shape[0], pts.shape[1] - 1
        best = np.full(m, np.inf)
        for i in range(k):
            segs = shapely.linestrings(np.stack([pts[:, i], pts[:, i + 1]], axis=1))
            for center, r in self.circles:
                best = np.minimum(best, np.maximum(shapely.distance(segs, center) - r, 0.0) - self.radius)
            for b in self.boxes:
                best = np.minimum(best, shapely.distance(segs, b) - self.radius)
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
        self.circles, self.boxes = [], []
        for ob in np.asarray(obstacles, dtype=float).reshape(-1, 5):
            if ob[0] == 0.0:
                self.circles.append((shapely.Point(ob[1], ob[2]), float(ob[3])))
            else:
                self.boxes.append(shapely.box(ob[1], ob[2], ob[3], ob[4]))
        return self

    def motion_bound(self, qa, qb) -> float:
        """Largest speed (m per unit s) of any arm point on ``qa -> qb``, re-derived here:
        a point of link k moves at most ``Σ_{i<=k} l_i |θ̇_i|`` with ``|θ̇_i| <= Σ_{j<=i} |q̇_j|``."""
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
