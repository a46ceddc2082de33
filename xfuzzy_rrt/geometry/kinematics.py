"""Forward kinematics of a planar serial arm.

Joint 1 turns link 1 about ``base`` measured from +x; joint *i* is relative to link *i-1*, so
link *k*'s absolute angle is the sum of the first *k* joint angles. Inputs in degrees (the unit
of scenario files and results), computation in radians.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True, nogil=True, inline="always")
def fk_step(x, y, theta, length, q_deg):
    """Forward kinematics, one link: the only place a joint angle becomes a link position.

    Joint angles are relative to the previous link (``theta`` accumulates them); returns the
    link's far end and its absolute angle.
    """
    theta += math.radians(q_deg)
    return x + length * math.cos(theta), y + length * math.sin(theta), theta


@nb.njit(cache=True, nogil=True, _nrt=False)
def joint_points_into(links, base, q_deg, out):
    """Write the base, every joint and the end effector (``[dof + 1, 2]``) into ``out``."""
    x = base[0]
    y = base[1]
    theta = 0.0
    out[0, 0] = x
    out[0, 1] = y
    for k in range(links.shape[0]):
        x, y, theta = fk_step(x, y, theta, links[k], q_deg[k])
        out[k + 1, 0] = x
        out[k + 1, 1] = y


@nb.njit(cache=True, nogil=True, _nrt=False)
def end_effector(links, base, q_deg):
    """The tip of the last link as ``(x, y)``."""
    x = base[0]
    y = base[1]
    theta = 0.0
    for k in range(links.shape[0]):
        x, y, theta = fk_step(x, y, theta, links[k], q_deg[k])
    return x, y


def joint_points(links, base, q_deg) -> np.ndarray:
    """Python convenience wrapper: ``[dof + 1, 2]`` points from base to end effector."""
    links = np.asarray(links, dtype=np.float64)
    out = np.empty((links.shape[0] + 1, 2), dtype=np.float64)
    joint_points_into(links, np.asarray(base, dtype=np.float64),
                      np.asarray(q_deg, dtype=np.float64), out)
    return out


@nb.njit(cache=True, nogil=True, _nrt=False)
def arm_end_effector(P, arm, q_deg):
    """The tip of arm ``arm`` of a :class:`~xfuzzy_rrt.geometry.problem.Problem`."""
    x = P.bases[arm, 0]
    y = P.bases[arm, 1]
    theta = 0.0
    for k in range(P.arm_first[arm], P.arm_first[arm + 1]):
        x, y, theta = fk_step(x, y, theta, P.links[k], q_deg[k])
    return x, y


def arm_points(arrays, q_deg) -> list[np.ndarray]:
    """Every arm's ``[dof_a + 1, 2]`` points (base, joints, tip) for configuration ``q_deg``."""
    q = np.asarray(q_deg, dtype=np.float64)
    out = []
    for a in range(arrays.n_arms):
        f0, f1 = int(arrays.arm_first[a]), int(arrays.arm_first[a + 1])
        out.append(joint_points(arrays.links[f0:f1], arrays.bases[a], q[f0:f1]))
    return out
