"""The single-arm positional forms of the geometry kernels, for tests written before the
compiled :class:`~xfuzzy_rrt.geometry.problem.Problem` bundle: each call builds a one-arm
problem and runs the real kernel, so these tests keep exercising the code the planners use."""

from __future__ import annotations

import numpy as np

from xfuzzy_rrt.geometry import collision as _c
from xfuzzy_rrt.geometry.problem import single_arm_problem


def _problem(links, base, radius, obstacles, limits=None, margin=1e-6):
    links = np.asarray(links, dtype=np.float64)
    if limits is None:
        limits = np.tile([-180.0, 180.0], (links.shape[0], 1))
    return single_arm_problem(links, base, radius, obstacles, limits, margin=margin)


def clearance_kernel(links, base, radius, obstacles, q_deg):
    return _c.clearance_kernel(_problem(links, base, radius, obstacles),
                               np.asarray(q_deg, dtype=np.float64))


def edge_free(links, base, radius, obstacles, qa_deg, qb_deg, margin):
    # the bundle carries the clearance this margin stands for, as ScenarioArrays.problem does
    return _c.edge_free(_problem(links, base, radius, obstacles, margin=margin),
                        np.asarray(qa_deg, dtype=np.float64),
                        np.asarray(qb_deg, dtype=np.float64), margin)


def config_free(links, base, radius, obstacles, limits, q_deg, margin):
    return _c.config_free(_problem(links, base, radius, obstacles, limits, margin=margin),
                          np.asarray(q_deg, dtype=np.float64), margin)


def arrays_of(links, base, radius, obstacles, limits=None, **extra):
    """A stand-in for ``ScenarioArrays`` of one arm (what the Python helpers read)."""
    from types import SimpleNamespace

    links = np.asarray(links, dtype=np.float64)
    obstacles = np.asarray(obstacles, dtype=np.float64).reshape(-1, 5)
    if limits is None:
        limits = np.tile([-180.0, 180.0], (links.shape[0], 1))
    limits = np.asarray(limits, dtype=np.float64)
    base = np.asarray(base, dtype=np.float64)
    return SimpleNamespace(
        links=links, base=base, link_radius=float(radius), obstacles=obstacles,
        limits_deg=limits, arm_first=np.array([0, links.shape[0]]), bases=base.reshape(1, 2),
        radii=np.array([float(radius)]), n_arms=1, dof=links.shape[0],
        problem=lambda margin: single_arm_problem(links, base, radius, obstacles, limits,
                                                  margin=margin), **extra)
