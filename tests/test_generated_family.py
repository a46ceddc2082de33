"""Safety on problems nobody tuned for: random scenarios of the shared family.

Scenarios are drawn like the shared ``sample-*`` files (two links of 0.14–0.20 m, 2–7 circles
and boxes around the arm, random start and goal that are free). Whatever a planner returns
must pass the independent exact-geometry check; failing to find a path is allowed (a random
problem may be unsolvable), returning a colliding path never is.
"""

from __future__ import annotations

import numpy as np
import pytest

from exact_geometry import Oracle
from xfuzzy_rrt.errors import ScenarioError
from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, load_rulebook
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.geometry.scenario import load_scenario


def _random_scenario_text(rng: np.random.Generator) -> str:
    l1, l2 = rng.uniform(0.14, 0.20), rng.uniform(0.09, 0.15)
    lines = [f'name = "generated-{rng.integers(1 << 30)}"', "[arm]",
             f"links = [{l1:.3f}, {l2:.3f}]", "link_radius = 0.005"]
    q = rng.uniform(-170, 170, size=4).round()
    lines += ["[start]", f"q_deg = [{q[0]}, {q[1]}]", "[goal]", f"q_deg = [{q[2]}, {q[3]}]"]
    for _ in range(rng.integers(2, 8)):
        r = rng.uniform(0.12, 0.34)
        a = rng.uniform(0, 2 * np.pi)
        cx, cy = r * np.cos(a), r * np.sin(a)
        if rng.random() < 0.7:
            lines += ["[[obstacles]]", 'type = "circle"', f"center = [{cx:.4f}, {cy:.4f}]",
                      f"radius = {rng.uniform(0.02, 0.06):.4f}"]
        else:
            w, h = rng.uniform(0.03, 0.08, size=2)
            lines += ["[[obstacles]]", 'type = "box"', f"min = [{cx:.4f}, {cy:.4f}]",
                      f"max = [{cx + w:.4f}, {cy + h:.4f}]"]
    return "\n".join(lines) + "\n"


def _generated(tmp_path, count: int, seed: int):
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        path = tmp_path / f"gen-{len(out)}.toml"
        path.write_text(_random_scenario_text(rng))
        try:
            out.append((path, load_scenario(path)))
        except ScenarioError:
            continue  # start or goal in collision: draw again
    return out


@pytest.mark.parametrize("planner", ["rrt", "fuzzy-rrt"])
def test_paths_on_random_family_scenarios_never_collide(tmp_path, planner):
    rulebook = load_rulebook(default_rulebook_path())
    successes = 0
    for path, scenario in _generated(tmp_path, 30, seed=2026):
        oracle = Oracle(path)
        for seed in range(3):
            if planner == "rrt":
                r = plan_rrt(scenario, seed=seed, max_iter=4000)
            else:
                r = plan_fuzzy_rrt(scenario, rulebook, seed=seed, max_iter=4000)
            if r.success:
                successes += 1
                assert oracle.path_problems(r.path_deg) == [], (scenario.name, seed)
            else:
                assert r.path_deg.shape == (0, 2)
    assert successes > 30  # most random problems are solvable; the check above must bite
