"""Forward kinematics of a planar serial arm.

Joint 1 turns link 1 about ``base`` measured from +x; joint *i* is relative to link *i-1*, so
link *k*'s absolute angle is the sum of the first *k* joint angles. Inputs in degrees (the unit
of scenario files and results), computation in radians.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True, nogil=True)
def joint_points_into(links, base, q_deg, out):
    """Write the base, every joint and the end effector (``[dof + 1, 2]``) into ``out``."""
    x = base[0]
    y = base[1]
    theta = 0.0
    out[0, 0] = x
    out[0, 1] = y
    for k in range(links.shape[0]):
        theta += math.radians(q_deg[k])
        x += links[k] * math.cos(theta)
        y += links[k] * math.sin(theta)
        out[k + 1, 0] = x
        out[k + 1, 1] = y


@nb.njit(cache=True, nogil=True)
def end_effector(links, base, q_deg):
    """The tip of the last link as ``(x, y)``."""
    x = base[0]
    y = base[1]
    theta = 0.0
    for k in range(links.shape[0]):
        theta += math.radians(q_deg[k])
        x += links[k] * math.cos(theta)
        y += links[k] * math.sin(theta)
    return x, y


def joint_points(links, base, q_deg) -> np.ndarray:
    """Python convenience wrapper: ``[dof + 1, 2]`` points from base to end effector."""
    links = np.asarray(links, dtype=np.float64)
    out = np.empty((links.shape[0] + 1, 2), dtype=np.float64)
    joint_points_into(links, np.asarray(base, dtype=np.float64),
                      np.asarray(q_deg, dtype=np.float64), out)
    return out
