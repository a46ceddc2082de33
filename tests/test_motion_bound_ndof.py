"""The motion bound behind the certified edge check, for N links (N = 2..7) and for two arms.

``link_motion_bound(links, qa, qb, k)`` = ``M_k`` promises that no point of link *k* moves more
than ``M_k * |Δs|`` while the joints travel ``Δs`` of the straight segment ``qa -> qb``. The
multi-arm certified check (issue 17) bounds how fast link *k* of arm A and link *m* of arm B
can approach each other by ``M_k^A + M_m^B``, each computed on that arm's own links and joint
slice with the *local* link index. If either under-promises, conservative advancement can step
over an obstacle or through the other arm.

Checked here against an independent plain-numpy forward kinematics (``World.joint_points`` of
tests/exact_geometry.py) on seeded random arms and segments, measured densely: every link end
and interior point, between consecutive samples (the speed) and across random sub-intervals
(the displacement). The bound is also shown to be *tight* (ratios above 0.97 with one joint
moving, with a straight arm, and for two arms whose tips pass each other head-on), so a bound
scaled down by a few per cent would fail here.
"""

from __future__ import annotations

import numpy as np
import pytest

from exact_geometry import World, segment_segment_distance
from xfuzzy_rrt.geometry.collision import link_motion_bound

#: Floating-point allowance on a comparison ``displacement <= M * Δs`` (relative, absolute m).
REL = 1e-9
ABS = 1e-12
#: Fractions along a link where points are followed (both ends and the interior).
FRACTIONS = np.array([0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0])
S = np.linspace(0.0, 1.0, 257)


def bounds(links, qa, qb) -> np.ndarray:
    """``[n]`` the package's ``M_k`` for every link of one arm."""
    links = np.ascontiguousarray(links, dtype=np.float64)
    qa = np.ascontiguousarray(qa, dtype=np.float64)
    qb = np.ascontiguousarray(qb, dtype=np.float64)
    return np.array([link_motion_bound(links, qa, qb, k) for k in range(links.shape[0])])


def link_points(world: World, arm: int, q) -> np.ndarray:
    """``[len(q), n, len(FRACTIONS), 2]`` followed points of every link of ``arm``."""
    p = world.joint_points(q)[arm]
    a, b = p[:, :-1, None, :], p[:, 1:, None, :]
    return a + FRACTIONS[None, None, :, None] * (b - a)


def along(qa, qb, s) -> np.ndarray:
    return qa[None, :] + np.asarray(s)[:, None] * (qb - qa)[None, :]


def random_arm(rng, n):
    links = rng.uniform(0.01, 0.5, n)
    base = rng.uniform(-1.0, 1.0, 2)
    return links, base


def random_segment(rng, n):
    """Segments of every kind: long, short, one joint only, opposite joint motions."""
    kind = rng.integers(4)
    qa = rng.uniform(-180.0, 180.0, n)
    if kind == 0:
        qb = rng.uniform(-180.0, 180.0, n)
    elif kind == 1:
        qb = qa + rng.normal(0.0, 3.0, n)
    elif kind == 2:
        qb = qa.copy()
        qb[rng.integers(n)] += rng.uniform(-120.0, 120.0)
    else:  # joints turning against each other (partial cancellation of absolute angles)
        step = rng.uniform(10.0, 90.0)
        qb = qa + step * np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    return qa, qb


def max_ratio_one_arm(world, arm, qa, qb, m, rng):
    """Largest (displacement / (M_k Δs)) over links, followed points, consecutive samples and
    random sub-intervals. Must be <= 1."""
    pts = link_points(world, arm, along(qa, qb, S))  # [S, n, F, 2]
    worst = 0.0
    # Consecutive samples: the speed.
    disp = np.linalg.norm(np.diff(pts, axis=0), axis=-1)  # [S-1, n, F]
    allowed = m[None, :, None] * np.diff(S)[:, None, None]
    assert np.all(disp <= allowed * (1 + REL) + ABS), (
        f"link moved {disp.max()} > bound on {qa} -> {qb}")
    worst = max(worst, float(np.max(disp / np.maximum(allowed, 1e-300))))
    # Random sub-intervals (any two parameters, including long jumps).
    s1, s2 = rng.uniform(0, 1, 40), rng.uniform(0, 1, 40)
    p1 = link_points(world, arm, along(qa, qb, s1))
    p2 = link_points(world, arm, along(qa, qb, s2))
    disp = np.linalg.norm(p2 - p1, axis=-1)
    allowed = m[None, :, None] * np.abs(s2 - s1)[:, None, None]
    assert np.all(disp <= allowed * (1 + REL) + ABS)
    return worst


@pytest.mark.parametrize("n", [2, 3, 4, 5, 6, 7])
def test_every_point_of_every_link_moves_at_most_m_k_ds(n):
    rng = np.random.default_rng(1700 + n)
    cases = 0
    for _ in range(60):
        links, base = random_arm(rng, n)
        world = World([(links, base, 0.0)])
        for _ in range(2):
            qa, qb = random_segment(rng, n)
            m = bounds(links, qa, qb)
            # The package's bound is the textbook one: Σ_{j<=k} |Δq_j| Σ_{i=j..k} l_i.
            dq = np.abs(np.radians(qb - qa))
            ref = np.array([sum(dq[j] * links[j:k + 1].sum() for j in range(k + 1))
                            for k in range(n)])
            np.testing.assert_allclose(m, ref, rtol=1e-12, atol=0.0)
            # ... and no smaller than the oracle's own (tighter) velocity bound.
            assert np.all(world.link_speeds(qa, qb)[0] <= m * (1 + REL) + ABS)
            max_ratio_one_arm(world, 0, qa, qb, m, rng)
            cases += 1
    assert cases == 120


TWO_ARM_SIZES = [(2, 2), (2, 5), (3, 3), (4, 7), (5, 5), (7, 7)]


@pytest.mark.parametrize("na, nb", TWO_ARM_SIZES)
def test_two_arms_relative_displacement_is_at_most_mka_plus_mmb(na, nb):
    """For every link pair (k of A, m of B) and every followed point pair, the relative
    displacement over Δs is at most ``(M_k^A + M_m^B) Δs``, each bound taken on the arm's own
    slice of the joint vector with its local link index; so is the change of the segment-segment
    distance between the two links (what the certified check's step relies on)."""
    rng = np.random.default_rng(1717 + 10 * na + nb)
    for _ in range(40):
        la, ba = random_arm(rng, na)
        lb, bb = random_arm(rng, nb)
        world = World([(la, ba, 0.0), (lb, bb, 0.0)])
        qa_a, qb_a = random_segment(rng, na)
        qa_b, qb_b = random_segment(rng, nb)
        qa, qb = np.concatenate([qa_a, qa_b]), np.concatenate([qb_a, qb_b])
        sa, sb = slice(0, na), slice(na, na + nb)
        ma, mb = bounds(la, qa[sa], qb[sa]), bounds(lb, qa[sb], qb[sb])
        q = along(qa, qb, S)
        pa = link_points(world, 0, q)  # [S, na, F, 2]
        pb = link_points(world, 1, q)  # [S, nb, F, 2]
        rel = pa[:, :, None, :, None, :] - pb[:, None, :, None, :, :]  # [S, na, nb, F, F, 2]
        disp = np.linalg.norm(np.diff(rel, axis=0), axis=-1)  # [S-1, na, nb, F, F]
        pair = ma[:, None] + mb[None, :]
        allowed = pair[None, :, :, None, None] * np.diff(S)[:, None, None, None, None]
        assert np.all(disp <= allowed * (1 + REL) + ABS), (na, nb, qa, qb)
        # The link-link distance moves no faster than the relative bound.
        j = world.joint_points(q)
        d = segment_segment_distance(j[0][:, :-1, None, :], j[0][:, 1:, None, :],
                                     j[1][:, None, :-1, :], j[1][:, None, 1:, :])  # [S, na, nb]
        change = np.abs(np.diff(d, axis=0))
        assert np.all(change <= pair[None] * np.diff(S)[:, None, None] * (1 + REL) + ABS)
        # Each arm's own bound also holds arm by arm on the concatenated vector.
        max_ratio_one_arm(world, 0, qa, qb, ma, rng)
        max_ratio_one_arm(world, 1, qa, qb, mb, rng)


# ------------------------------------------------------------------------------- tightness


@pytest.mark.parametrize("n", [2, 3, 5, 7])
def test_bound_is_tight_with_the_first_joint_moving_a_straight_arm(n):
    """Only joint 1 turns and the arm is straight: the tip moves on a circle of radius Σ l_i at
    |Δq_1| Σ l_i per unit s, which is exactly M_{n-1}. Over a small Δs the chord is within
    0.1 % of the bound (a bound 3 % smaller would be violated)."""
    rng = np.random.default_rng(99 + n)
    links = rng.uniform(0.05, 0.4, n)
    world = World([(links, (0.3, -0.2), 0.0)])
    qa = np.zeros(n)
    qb = qa.copy()
    qb[0] = 40.0
    m = bounds(links, qa, qb)
    s = np.array([0.5, 0.51])
    tip = world.joint_points(along(qa, qb, s))[0][:, -1]
    ratio = np.linalg.norm(tip[1] - tip[0]) / (m[-1] * 0.01)
    assert 0.999 < ratio <= 1.0 + REL
    assert ratio > 1 / 1.03


@pytest.mark.parametrize("n", [3, 5, 7])
def test_bound_is_tight_for_one_middle_joint(n):
    """Joint j (not the first) alone turns: the points of link k >= j move at most
    |Δq_j| * (distance to joint j) <= |Δq_j| Σ_{i=j..k} l_i, attained at the tip of a straight
    sub-chain."""
    links = np.linspace(0.1, 0.3, n)
    world = World([(links, (0.0, 0.0), 0.0)])
    j = n // 2
    qa = np.zeros(n)
    qa[0] = 30.0
    qb = qa.copy()
    qb[j] = -25.0
    m = bounds(links, qa, qb)
    assert np.all(m[:j] == 0.0)  # links before the joint do not move at all
    s = np.array([0.2, 0.205])
    pts = world.joint_points(along(qa, qb, s))[0]
    for k in range(j, n):
        ratio = np.linalg.norm(pts[1, k + 1] - pts[0, k + 1]) / (m[k] * 0.005)
        assert 0.999 < ratio <= 1.0 + REL, (k, ratio)
    # The links before the moving joint really stand still.
    assert np.array_equal(pts[0, : j + 1], pts[1, : j + 1])


def test_relative_bound_is_tight_for_two_tips_passing_head_on():
    """Two straight arms facing each other turn the same way: arm A's tip moves up, arm B's
    down, so their relative speed is M^A + M^B exactly (within 0.1 % over a small Δs)."""
    la, lb = np.array([0.3, 0.2, 0.25]), np.array([0.15, 0.35, 0.2, 0.1, 0.2])
    world = World([(la, (0.0, 0.0), 0.0), (lb, (la.sum() + lb.sum() + 0.1, 0.0), 0.0)])
    qa = np.concatenate([[-10.0, 0, 0], [170.0, 0, 0, 0, 0]])
    qb = np.concatenate([[10.0, 0, 0], [190.0, 0, 0, 0, 0]])
    ma = bounds(la, qa[:3], qb[:3])
    mb = bounds(lb, qa[3:], qb[3:])
    s = np.array([0.5, 0.505])
    j = world.joint_points(along(qa, qb, s))
    rel = (j[0][:, -1] - j[1][:, -1])
    ratio = np.linalg.norm(rel[1] - rel[0]) / ((ma[-1] + mb[-1]) * 0.005)
    assert 0.999 < ratio <= 1.0 + REL


def test_random_cases_come_close_to_the_bound():
    """Over the random segments with one joint moving, the largest measured speed ratio is
    within a few per cent of 1: the property tests above would catch a bound scaled by 0.97."""
    rng = np.random.default_rng(4242)
    best = 0.0
    for n in range(2, 8):
        for _ in range(20):
            links, base = random_arm(rng, n)
            world = World([(links, base, 0.0)])
            qa = rng.uniform(-180, 180, n)
            qa[1:] = rng.normal(0.0, 3.0, n - 1)  # nearly straight
            qb = qa.copy()
            qb[0] += rng.uniform(-90, 90)
            best = max(best, max_ratio_one_arm(world, 0, qa, qb, bounds(links, qa, qb), rng))
    assert best > 0.97
