"""Forward kinematics matches poses computed by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from xfuzzy_rrt.geometry.kinematics import end_effector, joint_points

LINKS = np.array([0.18, 0.12])
BASE = np.zeros(2)


@pytest.mark.parametrize("q,expected", [
    ((0.0, 0.0), [(0.0, 0.0), (0.18, 0.0), (0.30, 0.0)]),
    ((90.0, 0.0), [(0.0, 0.0), (0.0, 0.18), (0.0, 0.30)]),
    ((90.0, -90.0), [(0.0, 0.0), (0.0, 0.18), (0.12, 0.18)]),
    ((180.0, 90.0), [(0.0, 0.0), (-0.18, 0.0), (-0.18, -0.12)]),
    ((-45.0, 45.0), [(0.0, 0.0), (0.18 / math.sqrt(2), -0.18 / math.sqrt(2)),
                     (0.18 / math.sqrt(2) + 0.12, -0.18 / math.sqrt(2))]),
])
def test_joint_points_match_hand_computed_poses(q, expected):
    np.testing.assert_allclose(joint_points(LINKS, BASE, q), expected, atol=1e-15)


def test_base_offset_translates_every_point():
    q = (30.0, 60.0)
    shifted = joint_points(LINKS, np.array([0.01, -0.02]), q)
    np.testing.assert_allclose(shifted - joint_points(LINKS, BASE, q), [[0.01, -0.02]] * 3,
                               atol=1e-15)


def test_end_effector_is_the_last_joint_point():
    q = np.array([12.5, -77.0])
    assert end_effector(LINKS, BASE, q) == pytest.approx(tuple(joint_points(LINKS, BASE, q)[-1]),
                                                         abs=1e-15)


def test_three_link_arm_accumulates_relative_angles():
    pts = joint_points([0.1, 0.1, 0.1], [0.0, 0.0], (90.0, 90.0, 90.0))
    np.testing.assert_allclose(pts[-1], [-0.1, 0.0], atol=1e-15)
