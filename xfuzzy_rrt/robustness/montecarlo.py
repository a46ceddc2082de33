"""Path robustness: Monte Carlo over obstacle and joint perturbations of one planned path.

The model a plan is certified against is never exactly the patient: organs sit a few
millimetres away from where imaging put them, they are a little larger or smaller, and the
joints track their set points with an error. This module executes a planned path under many
sampled versions of that uncertainty and reports how often the *executed* motion touches an
obstacle (with a 95 % Clopper–Pearson interval), the distribution of its minimum clearance and
which obstacle is hit most.

The noise model (one trial = one sample of all of it):

- **obstacle centre offset**: every obstacle is translated by ``(dx, dy)``, each drawn with
  standard deviation ``sigma_obstacle_m`` (a box moves rigidly);
- **obstacle size change**: a circle's radius, and each side of a box (the box grows by ``e``
  on every side), change by ``e`` with standard deviation ``sigma_size_m``; sizes never go
  below zero;
- **joint tracking error**: every waypoint of the path is executed at ``q + e``, ``e`` per
  joint with standard deviation ``sigma_joint_deg``; the arm moves straight in joint space
  between the executed waypoints, as the planner assumed.

``distribution`` is ``normal`` or ``uniform``: the bounded uniform on ``[-√3σ, √3σ]`` has the
same standard deviation σ, so the two are comparable at equal σ.

Each trial's minimum clearance is measured along the continuous executed motion
(:func:`~xfuzzy_rrt.geometry.clearance.min_clearance_kernel`, signed: negative values are
penetration depths), not sampled at the waypoints: it is a distance attained at a real
configuration, within 1 µm of the true minimum, and whether it is ``<= 0`` -- the trial
*collides*, touching counts as everywhere in this project -- is decided exactly (the search
keeps refining wherever a contact is still possible). Trials it could not decide within its
evaluation budget are counted in ``undecided`` (0 in every run we made). All noise is drawn up front from one
``numpy`` generator seeded by ``seed`` in a fixed order, and the trials are independent
computations spread over numba threads, so the same seed gives the same numbers whatever
``workers`` is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.clearance import min_clearance_kernel
from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M
from xfuzzy_rrt.geometry.problem import with_obstacles
from xfuzzy_rrt.geometry.signed import signed_clearance_kernel

DISTRIBUTIONS = ("normal", "uniform")
#: Tolerance (m) of each trial's minimum clearance (whether it is <= 0 is decided exactly).
TRIAL_TOL_M = 1e-6
#: Distance evaluations per trial before the search reports its proven lower bound.
TRIAL_MAX_EVALS = 200_000
#: Most trials one call accepts (memory: 10 floats per obstacle and waypoint per trial).
MAX_TRIALS = 10_000_000


@dataclass(frozen=True)
class Perturbation:
    """The uncertainty a path is executed under (standard deviations; see the module doc)."""

    sigma_obstacle_m: float = 0.0
    sigma_size_m: float = 0.0
    sigma_joint_deg: float = 0.0
    distribution: str = "normal"

    def __post_init__(self) -> None:
        for name in ("sigma_obstacle_m", "sigma_size_m", "sigma_joint_deg"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not (
                    math.isfinite(v) and v >= 0.0):
                raise InputError(f"--{name.replace('_', '-')}",
                                 f"must be a non-negative number, got {v!r}")
        if self.distribution not in DISTRIBUTIONS:
            raise InputError("--distribution", f"must be one of {', '.join(DISTRIBUTIONS)}, "
                             f"got {self.distribution!r}")


def draw(rng: np.random.Generator, shape, sigma: float, distribution: str) -> np.ndarray:
    """Zero-mean noise of standard deviation ``sigma`` (``normal`` or bounded ``uniform``)."""
    if sigma == 0.0:
        return np.zeros(shape)
    if distribution == "uniform":
        half = math.sqrt(3.0) * sigma
        return rng.uniform(-half, half, size=shape)
    return rng.normal(0.0, sigma, size=shape)


def perturb_obstacles(obstacles: np.ndarray, n: int, p: Perturbation,
                      rng: np.random.Generator) -> np.ndarray:
    """``[n, m, 5]`` obstacle rows, one perturbed copy of ``obstacles`` ([m, 5]) per trial."""
    m = obstacles.shape[0]
    shift = draw(rng, (n, m, 2), p.sigma_obstacle_m, p.distribution)
    grow = draw(rng, (n, m), p.sigma_size_m, p.distribution)
    out = np.repeat(obstacles[None, :, :], n, axis=0)
    circle = obstacles[:, 0] == 0.0
    box = ~circle
    out[:, :, 1] += shift[:, :, 0]
    out[:, :, 2] += shift[:, :, 1]
    out[:, circle, 3] = np.maximum(obstacles[circle, 3][None, :] + grow[:, circle], 0.0)
    if np.any(box):
        out[:, box, 3] += shift[:, box, 0]
        out[:, box, 4] += shift[:, box, 1]
        g = grow[:, box]
        # A box shrinks at most to its centre line (never inverted).
        half_w = 0.5 * (obstacles[box, 3] - obstacles[box, 1])[None, :]
        half_h = 0.5 * (obstacles[box, 4] - obstacles[box, 2])[None, :]
        gx = np.maximum(g, -half_w)
        gy = np.maximum(g, -half_h)
        out[:, box, 1] -= gx
        out[:, box, 3] += gx
        out[:, box, 2] -= gy
        out[:, box, 4] += gy
    return out


def perturb_paths(path: np.ndarray, n: int, p: Perturbation,
                  rng: np.random.Generator) -> np.ndarray:
    """``[n, k, dof]`` executed waypoints: the path plus the joint tracking error."""
    return path[None, :, :] + draw(rng, (n,) + path.shape, p.sigma_joint_deg, p.distribution)


@nb.njit(cache=True, nogil=True, parallel=True, _nrt=True)
def trials_kernel(P, obstacles_t, paths_t, tol, max_evals, value, lower, hit):
    """Per trial: exact min signed clearance, its lower bound, and the obstacle it is to."""
    n = obstacles_t.shape[0]
    m = obstacles_t.shape[1]
    for t in nb.prange(n):
        path = paths_t[t]
        obs = obstacles_t[t]
        v, seg, s, lb = min_clearance_kernel(with_obstacles(P, obs), path, tol, max_evals,
                                             True)
        value[t] = v
        lower[t] = lb
        hit[t] = -1
        if seg >= 0 and m > 0:
            q = np.empty(path.shape[1])
            j = seg + 1 if seg + 1 < path.shape[0] else seg
            for d in range(path.shape[1]):
                q[d] = path[seg, d] + s * (path[j, d] - path[seg, d])
            best = np.inf
            for o in range(m):
                c = signed_clearance_kernel(with_obstacles(P, obs[o:o + 1]), q)
                if c < best:
                    best = c
                    hit[t] = o


@dataclass
class PathRobustness:
    """Outcome of :func:`path_robustness` (all numbers; the CLI renders them)."""

    trials: int
    collisions: int
    p_collision: float
    ci_low: float
    ci_high: float
    #: Per trial (arrays of length ``trials``): exact min signed clearance (m), proven lower
    #: bound, index of the obstacle at the minimum (-1: none).
    min_clearance_m: np.ndarray
    lower_bound_m: np.ndarray
    obstacle: np.ndarray
    #: Trials whose search ran out of budget with a contact still possible (value > 0,
    #: proven bound <= 0): neither counted as collisions nor certain.
    undecided: int
    #: The unperturbed path's exact minimum clearance.
    nominal_clearance_m: float
    #: Collisions per obstacle index (length m).
    hits_per_obstacle: np.ndarray
    #: Index of the trial with the smallest clearance, and its perturbed obstacles and path.
    worst_trial: int
    worst_obstacles: np.ndarray
    worst_path_deg: np.ndarray

    @property
    def most_hit(self) -> int:
        """Obstacle index with the most collisions (-1 when nothing was hit)."""
        if self.collisions == 0:
            return -1
        return int(np.argmax(self.hits_per_obstacle))


def clopper_pearson(k: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Exact (Clopper–Pearson) binomial interval for ``k`` successes in ``n`` trials."""
    from scipy.stats import binomtest

    ci = binomtest(int(k), int(n)).proportion_ci(confidence_level=confidence, method="exact")
    return float(ci.low), float(ci.high)


def path_robustness(arrays, path_deg, perturbation: Perturbation, trials: int = 10_000,
                    seed: int = 0, workers: int | None = None) -> PathRobustness:
    """Execute ``path_deg`` in ``arrays`` (a ``ScenarioArrays``) under ``trials`` samples of
    ``perturbation``; see the module docstring. ``workers``: numba threads (``None``: all)."""
    path = np.ascontiguousarray(np.asarray(path_deg, dtype=np.float64))
    dof = arrays.links.shape[0]
    if path.ndim != 2 or path.shape[0] == 0 or path.shape[1] != dof:
        raise InputError("path_deg", f"must be a non-empty path of shape [n, {dof}], got "
                         f"{path.shape}")
    if not np.all(np.isfinite(path)):
        raise InputError("path_deg", "contains non-finite angles")
    if isinstance(trials, bool) or not isinstance(trials, (int, np.integer)) or not (
            1 <= trials <= MAX_TRIALS):
        raise InputError("--trials", f"must be an integer in [1, {MAX_TRIALS}], got {trials!r}")
    rng = np.random.default_rng(int(seed))
    obstacles = np.ascontiguousarray(arrays.obstacles, dtype=np.float64)
    obs_t = perturb_obstacles(obstacles, int(trials), perturbation, rng)
    paths_t = perturb_paths(path, int(trials), perturbation, rng)
    value = np.empty(trials)
    lower = np.empty(trials)
    hit = np.empty(trials, dtype=np.int64)
    previous = nb.get_num_threads()
    if workers is not None:
        if isinstance(workers, bool) or not isinstance(workers, int) or not (
                1 <= workers <= nb.config.NUMBA_NUM_THREADS):
            raise InputError("--workers", f"must be an integer in [1, "
                             f"{nb.config.NUMBA_NUM_THREADS}], got {workers!r}")
        nb.set_num_threads(workers)
    try:
        trials_kernel(arrays.problem(CERT_MARGIN_M), obs_t, paths_t, TRIAL_TOL_M,
                      TRIAL_MAX_EVALS, value, lower, hit)
    finally:
        nb.set_num_threads(previous)
    nominal = min_clearance_kernel(arrays.problem(CERT_MARGIN_M)._replace(obstacles=obstacles),
                                   path, 1e-9, TRIAL_MAX_EVALS, True)[0]
    collided = value <= 0.0
    k = int(collided.sum())
    lo, hi = clopper_pearson(k, int(trials))
    per = np.bincount(hit[collided & (hit >= 0)], minlength=obstacles.shape[0])
    worst = int(np.argmin(value)) if np.isfinite(value).any() else 0
    return PathRobustness(
        trials=int(trials), collisions=k, p_collision=k / trials, ci_low=lo, ci_high=hi,
        min_clearance_m=value, lower_bound_m=lower, obstacle=hit,
        undecided=int(np.sum((lower <= 0.0) & (value > 0.0) & (lower < value - TRIAL_TOL_M))),
        nominal_clearance_m=float(nominal), hits_per_obstacle=per, worst_trial=worst,
        worst_obstacles=obs_t[worst].copy(), worst_path_deg=paths_t[worst].copy())
