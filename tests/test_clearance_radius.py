"""``clearance_deg`` of the goal-frame semantics is a certified joint-space radius.

The goal-frame rulebooks read ``clearance_deg``: the clearance at the current node divided by
the lever ``sqrt(Σ_j (Σ_{i>=j} l_i)^2)`` (how far any arm point moves per radian of Euclidean
joint-space motion). The claim (``planners/goal_frame.py``) is that within that radius, in any
joint-space direction, nothing is reached. The tight case: a straight arm whose tip sits right
under an obstacle edge, moved in the direction of the lever (every joint in proportion to the
length it swings), moves its tip straight at the obstacle at the lever's full rate. There the
radius must hold (independent oracle), and 5 % more than it must not, so a radius weakened
1.05x fails this file (``scripts/mutation_test.sh --weaken 1.05``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exact_geometry import World
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt

LINKS = (0.2, 0.1)


def _scenario(tmp_path, gap: float, links=LINKS):
    reach = sum(links)
    f = tmp_path / f"radius-{gap:g}-{len(links)}.toml"
    zeros = ", ".join("0" for _ in links)
    goal = ", ".join(["90"] + ["0"] * (len(links) - 1))
    f.write_text(
        f'name = "radius"\n[arm]\nlinks = [{", ".join(map(str, links))}]\nlink_radius = 0.0\n'
        f"[start]\nq_deg = [{zeros}]\n[goal]\nq_deg = [{goal}]\n"
        f'[[obstacles]]\ntype = "box"\nmin = [{reach - 0.01}, {gap}]\n'
        f"max = [{reach + 0.01}, {gap + 0.02}]\n")
    return load_scenario(f)


def _lever_direction(links):
    tails = np.cumsum(np.asarray(links)[::-1])[::-1]
    return tails / np.linalg.norm(tails)


@pytest.mark.parametrize("gap", [0.001, 0.003])
def test_clearance_deg_is_a_radius_nothing_is_reached_within(tmp_path, gap):
    links = LINKS
    s = _scenario(tmp_path, gap, links)
    trace = plan_fuzzy_rrt(s, max_iter=1, trace=True).trace  # the shipped goal-frame rulebook
    radius_deg = float(trace["clearance_deg"].iloc[0])
    assert int(trace["from_node"].iloc[0]) == 0  # read at the start configuration
    q0 = np.zeros(len(links))
    u = _lever_direction(links)
    w = World([(np.array(links), (0.0, 0.0), 0.0)],
              boxes=[(sum(links) - 0.01, gap, sum(links) + 0.01, gap + 0.02)])
    # within the radius, in the worst direction: never reached (a proven lower bound > 0)
    assert w.segment_min_clearance(q0, q0 + radius_deg * u).lower > 0.0
    # random directions too
    rng = np.random.default_rng(3)
    for _ in range(20):
        v = rng.normal(size=len(links))
        v /= np.linalg.norm(v)
        assert w.segment_min_clearance(q0, q0 + radius_deg * v).lower > 0.0
    # and the radius is tight there: 5 % more reaches the obstacle
    assert w.segment_min_clearance(q0, q0 + 1.05 * radius_deg * u).upper <= 0.0


def test_clearance_deg_at_the_start_is_the_clearance_over_the_lever(tmp_path):
    s = _scenario(tmp_path, 0.002)
    trace = plan_fuzzy_rrt(s, max_iter=1, trace=True).trace
    lever = math.hypot(0.3, 0.1)
    assert float(trace["clearance_deg"].iloc[0]) == pytest.approx(math.degrees(0.002 / lever),
                                                                  rel=1e-9)
