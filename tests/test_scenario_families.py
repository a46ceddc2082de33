"""Generated training and evaluation families: valid, solvable, non-trivial, deterministic.

``scenarios generate --family hard|mira`` extends the ``sample`` family with cluttered problems
(thin walls, narrow passages) and MIRA-like problems (a forearm threading a gap between two
organs) — the mixture the goal-frame rulebook is trained on. Every file must load through the
project's validating loader, have a blocked straight segment, and be proven solvable by a
certified RRT path; the same seed gives the same bytes, and the families never share a stream.
"""

from __future__ import annotations

import math

import pytest

from xfuzzy_rrt.geometry.collision import segment_free
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.scenarios.generate import generate_one


@pytest.mark.parametrize("family", ["hard", "mira"])
def test_family_problems_are_valid_solvable_nontrivial_and_deterministic(tmp_path, run_cli, family):
    for folder in ("a", "b"):
        proc = run_cli("scenarios", "generate", "--family", family, "--count", "3", "--seed", "9",
                       "--out", tmp_path / folder)
        assert proc.returncode == 0, proc.stderr
    files = sorted((tmp_path / "a").glob("*.toml"))
    assert [f.name for f in files] == [f"{family}-9-{k:03d}.toml" for k in range(3)]
    for f in files:
        assert f.read_bytes() == (tmp_path / "b" / f.name).read_bytes()
        s = load_scenario(f)
        a = s.arrays()
        assert not segment_free(a, a.start_deg, a.goal_deg)
        assert plan_rrt(s, seed=0, max_iter=20_000).success
        assert f"family {family}" in s.description
        if family == "hard":
            assert 6 <= len(s.obstacles) <= 10
        else:
            circles = [o for o in s.obstacles if hasattr(o, "radius")]
            assert len(circles) >= 2


def test_families_draw_from_separate_streams_and_sample_is_unchanged():
    sample = generate_one(5, 0)
    assert sample.scenario.name == "gen-5-0" + "00"
    hard = generate_one(5, 0, "hard", "hard")
    mira = generate_one(5, 0, "mira", "mira")
    assert len({sample.text.split("\n", 2)[2], hard.text.split("\n", 2)[2],
                mira.text.split("\n", 2)[2]}) == 3


def test_a_passage_narrower_than_the_grid_is_described_not_called_infinite(monkeypatch):
    import xfuzzy_rrt.scenarios.generate as gen

    monkeypatch.setattr(gen, "grid_optimal_deg", lambda *a, **k: math.inf)
    p = gen.generate_one(3, 1)
    assert "inf" not in p.scenario.description
    assert "no grid path at 2 deg" in p.scenario.description


def test_unknown_family_is_one_line(run_cli, tmp_path):
    proc = run_cli("scenarios", "generate", "--family", "easy", "--count", "1", "--out", tmp_path / "x")
    assert proc.returncode == 2
    assert proc.stderr.strip() == "error: --family: must be one of sample, hard, mira, trap, got 'easy'"
    assert not (tmp_path / "x").exists()
