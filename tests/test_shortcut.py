"""Certified shortcutting shortens paths without ever creating an edge that collides."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import FIXTURES, PROJECT
from exact_geometry import Oracle
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, load_rulebook
from xfuzzy_rrt.geometry.path_check import certify_path
from xfuzzy_rrt.geometry.scenario import load_scenario, scenario_from_dict
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.planners.result import path_cost_deg
from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.planners.shortcut import shortcut_path

SCENARIOS = [FIXTURES / "scenarios" / "two-circles.toml",
             FIXTURES / "scenarios" / "boxes-and-circle.toml",
             PROJECT / "xfuzzy_rrt" / "data" / "scenarios" / "demo-gap.toml"]


@pytest.fixture(scope="module")
def expert():
    return load_rulebook(default_rulebook_path())


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_shortcut_paths_pass_the_oracle_are_never_longer_and_keep_start_and_goal(path, expert):
    s = load_scenario(path)
    a = s.arrays()
    oracle = Oracle(path)
    shortened = 0
    for seed in range(6):
        for result in (plan_rrt(s, seed=seed), plan_fuzzy_rrt(s, rulebook=expert, seed=seed)):
            assert result.success
            raw = result.path_deg
            short = shortcut_path(a, raw, seed=seed)
            assert np.array_equal(short[0], raw[0]) and np.array_equal(short[-1], raw[-1])
            assert path_cost_deg(short) <= path_cost_deg(raw)
            assert oracle.path_problems(short) == [], f"{result.planner} seed {seed}"
            assert certify_path(a, short).certified
            assert np.array_equal(short, shortcut_path(a, raw, seed=seed))
            shortened += path_cost_deg(short) < 0.9 * path_cost_deg(raw)
    assert shortened >= 6, "shortcutting should cut most RRT zig-zags by more than 10 %"


def test_in_free_space_a_zigzag_becomes_nearly_straight():
    s = scenario_from_dict({"name": "free", "arm": {"links": [0.2, 0.1]},
                            "start": {"q_deg": [0.0, 0.0]}, "goal": {"q_deg": [100.0, 0.0]}})
    zigzag = np.array([[x, 30.0 * (-1) ** i if 0 < i < 10 else 0.0]
                       for i, x in enumerate(np.linspace(0.0, 100.0, 11))])
    short = shortcut_path(s.arrays(), zigzag, seed=1, attempts=400)
    assert path_cost_deg(short) < 1.01 * 100.0 < path_cost_deg(zigzag)
    assert np.array_equal(short[0], zigzag[0]) and np.array_equal(short[-1], zigzag[-1])


def test_different_seeds_draw_different_shortcuts():
    path = FIXTURES / "scenarios" / "two-circles.toml"
    s = load_scenario(path)
    raw = plan_rrt(s, seed=3).path_deg
    results = {shortcut_path(s.arrays(), raw, seed=k).tobytes() for k in range(5)}
    assert len(results) > 1


def test_a_shortcut_through_an_obstacle_is_refused():
    # Detour around a circle that sits right on the straight line: the only shortcut that
    # would help crosses it, and no certified shortcut may.
    path = FIXTURES / "scenarios" / "two-circles.toml"
    s = load_scenario(path)
    a = s.arrays()
    raw = plan_rrt(s, seed=0).path_deg
    straight = np.array([raw[0], raw[-1]])
    assert not certify_path(a, straight).certified, "fixture: the straight line must collide"
    for seed in range(10):
        short = shortcut_path(a, raw, seed=seed, attempts=1000)
        assert len(short) > 2 and certify_path(a, short).certified


SMALL_BOX = {"name": "small-box", "arm": {"links": [0.18, 0.12], "link_radius": 0.005},
             "start": {"q_deg": [-60.0, 0.0]}, "goal": {"q_deg": [-60.0, -150.0]},
             "obstacles": [{"type": "box", "min": [0.168, -0.172], "max": [0.172, -0.168]}]}


def test_every_output_edge_is_an_input_edge_or_certified_even_on_a_colliding_input():
    # The first input edge sweeps the straight arm through a small box at -45 deg early on (as
    # a sampled motion check may accept); a shortcut starting after the box must not keep the
    # colliding part of that edge as an unchecked "partial" edge.
    s = scenario_from_dict(SMALL_BOX)
    a = s.arrays()
    raw = np.array([[-60.0, 0.0], [60.0, 0.0], [60.0, -150.0], [-60.0, -150.0]])
    assert not certify_path(a, raw[:2]).certified and certify_path(a, raw[1:]).certified
    input_edges = {(tuple(p), tuple(q)) for p, q in zip(raw[:-1], raw[1:])}
    changed = 0
    for seed in range(20):
        for attempts in (1, 3, 200):  # few attempts: later shortcuts cannot hide an early slip
            short = shortcut_path(a, raw, seed=seed, attempts=attempts)
            changed += not np.array_equal(short, raw)
            for p, q in zip(short[:-1], short[1:]):
                assert ((tuple(p), tuple(q)) in input_edges
                        or certify_path(a, np.array([p, q])).certified), (seed, attempts)
    assert changed > 0


def test_a_two_vertex_path_comes_back_unchanged_even_if_it_collides():
    # Nothing to shorten; the shortcutter never claims to repair a path, only to shorten it.
    s = load_scenario(FIXTURES / "scenarios" / "two-circles.toml")
    raw = np.array([s.start_deg, s.goal_deg])
    assert np.array_equal(shortcut_path(s.arrays(), raw, seed=0), raw)


def test_bad_arguments_are_rejected():
    a = load_scenario(FIXTURES / "scenarios" / "two-circles.toml").arrays()
    with pytest.raises(InputError):
        shortcut_path(a, np.zeros((4, 3)), seed=0)
    with pytest.raises(InputError):
        shortcut_path(a, np.zeros((4, 2)), seed=0, attempts=-1)
    assert shortcut_path(a, np.zeros((0, 2)), seed=0).shape == (0, 2)
