"""Issue 17's acceptance check: N-DOF and dual-arm paths against the independent oracle.

Every path a planner reports as a success on 3-, 5- and 7-DOF arms and on two arms sharing a
workspace is proven collision-free (arm-obstacle and arm-arm, touching counts) by the exact
geometry oracle of tests/exact_geometry.py, which shares no geometry code with the package.
The certified edge check is held to the oracle both ways on random segments near obstacles and
near the other arm: whatever ``segment_free`` certifies keeps its clearance everywhere (the
oracle's proven lower bound), and whatever the oracle proves to keep more than the margin
everywhere ``segment_free`` accepts (conservative advancement only stops at real
configurations, so it can only refuse a segment that comes within the margin somewhere).

Problems are built here (``scenarios generate`` has no ``--dof``/``--arms`` yet): a seeded
family of N-link arms sweeping past a circle and under a box, and two arms whose straight
start-goal motion runs one through the other. Each is checked valid (start and goal within
the limits and free, by the oracle and by the package) and non-trivial (the straight segment
collides, by the oracle).
"""

from __future__ import annotations

import numpy as np
import pytest

from exact_geometry import as_world, oracle_path_is_free, oracle_path_problems
from xfuzzy_rrt.geometry.collision import effective_margin, in_collision, segment_free
from xfuzzy_rrt.geometry.scenario import Arm, Box, Circle, Scenario
from xfuzzy_rrt.planners.api import plan_scenario

MAX_ITER = 20_000
SEEDS = range(3)


def _arm(n: int, base=(0.0, 0.0), reach: float = 1.0, radius: float = 0.01) -> Arm:
    return Arm(links=tuple([reach / n] * n), base=base, link_radius=radius,
               joint_limits_deg=((-180.0, 180.0),) * n)


def single_arm(n: int, variant: int) -> Scenario:
    """An N-link arm (reach 1 m) turning from -60 to +60 degrees past a circle near its reach
    and under a box: the straight motion hits the circle, so the arm must curl."""
    rng = np.random.default_rng(100 * n + variant)
    cx = rng.uniform(0.8, 0.9)
    start = (-60.0,) + tuple(rng.uniform(-5, 5, n - 1))
    goal = (60.0,) + tuple(rng.uniform(-5, 5, n - 1))
    return Scenario(name=f"arm{n}-{variant}", arm=_arm(n), start_deg=start, goal_deg=goal,
                    obstacles=(Circle((cx, rng.uniform(-0.05, 0.05)), 0.06),
                               Box((-0.2, 0.75), (0.2, 0.85))))


def dual_arm(n: int, variant: int) -> Scenario:
    """Two N-link arms (reach 0.5 m each, bases 0.9 m apart): arm A swings from up to down
    through the space where arm B points at it, and a circle sits above."""
    rng = np.random.default_rng(1000 * n + variant)
    a, b = _arm(n, (-0.45, 0.0), 0.5), _arm(n, (0.45, 0.0), 0.5)
    rest = tuple(rng.uniform(-5, 5, n - 1))
    start = (90.0,) + rest + (180.0,) + tuple(rng.uniform(-5, 5, n - 1))
    goal = (-90.0,) + rest + (170.0,) + tuple(rng.uniform(-5, 5, n - 1))
    return Scenario(name=f"dual{n}-{variant}", arm=a, more_arms=(b,), start_deg=start,
                    goal_deg=goal, obstacles=(Circle((0.0, rng.uniform(0.55, 0.65)), 0.08),))


PROBLEMS = [single_arm(n, v) for n in (3, 5, 7) for v in range(2)] + \
           [dual_arm(n, v) for n in (2, 3, 5) for v in range(2)]


def planners_for(s: Scenario) -> list[str]:
    """RRT always; Fuzzy-RRT with each shipped rulebook of matching DOF (paper-semantics
    rulebooks are per arm: ``expert`` for 2-link arms, ``expert-5dof`` for 5-link arms;
    goal-frame rulebooks read all joints at once: ``goal-frame-5dof`` for one 5-link arm,
    ``goal-frame-dual3`` for two 3-link arms); OMPL RRTConnect when installed."""
    per_arm = {a.dof for a in s.arms}
    out = ["rrt"]
    if per_arm == {2}:
        out.append("fuzzy-rrt:expert")
    if per_arm == {5}:
        out.append("fuzzy-rrt:expert-5dof")
    if s.dof == 2:
        out.append("fuzzy-rrt:goal-frame")
    if len(s.arms) == 1 and s.dof == 5:
        out.append("fuzzy-rrt:goal-frame-5dof")
    if len(s.arms) == 2 and per_arm == {3}:
        out.append("fuzzy-rrt:goal-frame-dual3")
    try:
        import ompl  # noqa: F401
        out.append("ompl:RRTConnect")
    except ImportError:
        pass
    return out


@pytest.mark.parametrize("s", PROBLEMS, ids=lambda s: s.name)
def test_problems_are_valid_and_non_trivial(s):
    w = as_world(s)
    ends = np.array([s.start_deg, s.goal_deg])
    assert w.dof == s.dof == len(s.start_deg)
    assert not w.in_collision(ends).any()
    assert not in_collision(s.arrays(), ends[0]) and not in_collision(s.arrays(), ends[1])
    # Non-trivial: the straight motion collides (proven by the oracle), so the planner's check
    # must refuse it.
    assert w.path_min_clearance(ends, threshold=0.0).upper <= 0.0
    assert not segment_free(s.arrays(), s.start_deg, s.goal_deg)


@pytest.mark.parametrize("s", PROBLEMS, ids=lambda s: s.name)
def test_every_successful_path_passes_the_oracle(s):
    successes = 0
    for planner in planners_for(s):
        for seed in SEEDS:
            r = plan_scenario(s, planner, seed=seed, max_iter=MAX_ITER)
            if not r.success:
                if getattr(r, "found", False) and getattr(r, "penetration_m", None):
                    # A path found but refused (OMPL samples its motions): the oracle agrees it
                    # is not free.
                    assert not oracle_path_is_free(s, r.path_deg), (planner, seed)
                continue
            successes += 1
            problems = oracle_path_problems(s, r.path_deg, s.start_deg, s.goal_deg)
            assert problems == [], (s.name, planner, seed, problems)
            # The package's own minimum clearance (proven to 0.1 µm) lies in the oracle's
            # bracket (also 0.1 µm), flat minima included: two links of a straight arm one link
            # apart over a whole segment are closed by both searches' curvature bound.
            if r.min_clearance_m is not None:
                b = as_world(s).path_min_clearance(r.path_deg, tol=1e-7)
                assert not b.exhausted, (planner, seed)
                assert b.lower - 1e-7 <= r.min_clearance_m <= b.upper + 1e-7, (planner, seed)
    assert successes > 0, f"no planner solved {s.name}: the check would be vacuous"


# ------------------------------------------------------------------------- certified edges


def near_contact_segments(s: Scenario, rng, count: int):
    """Random short joint segments starting at free configurations close to an obstacle or to
    the other arm (clearance below 5 cm), most of them grazing or crossing something. Drawn
    around the start and goal (uniform draws of two 5-link arms mostly overlap)."""
    w = as_world(s)
    lim = np.asarray(s.joint_limits_deg)
    centres = np.array([s.start_deg, s.goal_deg])
    out = []
    while len(out) < count:
        q = centres[rng.integers(2, size=512)] + rng.normal(0.0, 40.0, (512, s.dof))
        q = np.clip(q, lim[:, 0], lim[:, 1])
        c = w.clearance(q)
        for qa in q[(c > 0.0) & (c < 0.05)]:
            qb = np.clip(qa + rng.normal(0.0, rng.choice([2.0, 8.0, 25.0]), s.dof),
                         lim[:, 0], lim[:, 1])
            out.append((qa, qb))
            if len(out) == count:
                break
    return out


@pytest.mark.parametrize("s", PROBLEMS, ids=lambda s: s.name)
@pytest.mark.parametrize("clearance_m", [0.0, 0.01])
def test_segment_free_never_certifies_what_the_oracle_finds_colliding(s, clearance_m):
    rng = np.random.default_rng(17 + s.dof + int(clearance_m * 1000))
    arrays = s.arrays()
    w = as_world(s)
    margin = effective_margin(clearance_m)
    certified = refused = 0
    for qa, qb in near_contact_segments(s, rng, 120):
        ok = segment_free(arrays, qa, qb, margin)
        b = w.segment_min_clearance(qa, qb, tol=1e-9, threshold=clearance_m)
        if ok:
            certified += 1
            # Sound: every configuration keeps the clearance (collision-free when it is 0).
            assert b.lower > clearance_m, (s.name, qa.tolist(), qb.tolist(), b)
        else:
            refused += 1
            # Complete up to the margin: refusing means some real stop came within it.
            c = w.segment_min_clearance(qa, qb, tol=1e-9, threshold=margin)
            assert not c.lower > margin + 1e-12, (s.name, qa.tolist(), qb.tolist(), c)
    assert certified >= 10 and refused >= 10, (certified, refused)
