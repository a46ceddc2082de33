"""``scenarios generate --family trap`` (issue 25): problems where heading for the goal is a dead end.

Every trap problem has its straight joint-space segment blocked, a 2° grid-optimal path at least
:data:`TRAP_DETOUR` times the straight distance (recorded in the description), loads through the
validating loader, and the same seed writes the same bytes.
"""

from __future__ import annotations

import re

from xfuzzy_rrt.geometry.collision import segment_free
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.scenarios.generate import (FAMILIES, TRAP_DETOUR, _config_ok, generate_one,
                                           grid_optimal_deg)


def test_trap_files_are_blocked_detours_that_load_and_repeat_per_seed(tmp_path, run_cli):
    for folder in ("a", "b"):
        proc = run_cli("scenarios", "generate", "--family", "trap", "--count", "3", "--seed", "9700",
                       "--out", tmp_path / folder)
        assert proc.returncode == 0, proc.stderr
    files = sorted((tmp_path / "a").glob("*.toml"))
    assert [f.name for f in files] == [f"trap-9700-{k:03d}.toml" for k in range(3)]
    for f in files:
        assert f.read_bytes() == (tmp_path / "b" / f.name).read_bytes()
        s = load_scenario(f)  # the validating loader
        a = s.arrays()
        assert not segment_free(a, a.start_deg, a.goal_deg)
        assert _config_ok(a, a.start_deg) and _config_ok(a, a.goal_deg)
        straight = float(((a.goal_deg - a.start_deg) ** 2).sum() ** 0.5)
        optimal = grid_optimal_deg(s)
        assert optimal >= TRAP_DETOUR * straight
        m = re.search(r"detour ratio (\d+\.\d\d) \(grid-optimal / straight\)", s.description)
        assert m is not None, s.description
        assert float(m.group(1)) == round(optimal / straight, 2)
        assert "family trap" in s.description


def test_trap_problem_has_one_large_organ_or_wall_and_its_detour_in_the_fields():
    p = generate_one(9700, 5, "trap", "trap")
    assert p.grid_optimal_deg >= TRAP_DETOUR * p.straight_deg
    big = p.scenario.obstacles[0]
    if hasattr(big, "radius"):
        assert 0.06 <= big.radius <= 0.10
    else:
        sides = sorted(hi - lo for lo, hi in zip(big.min, big.max))
        assert sides[0] <= 0.02 + 1e-3 and sides[1] >= 0.10 - 1e-3


def test_trap_is_a_new_stream_and_leaves_the_other_families_alone():
    assert FAMILIES[:3] == ("sample", "hard", "mira")  # their stream index, hence their bytes
    trap = generate_one(5, 0, "x", "trap").text.split("\n", 2)[2]
    others = {generate_one(5, 0, "x", f).text.split("\n", 2)[2] for f in ("sample", "hard", "mira")}
    assert trap not in others


def test_unknown_family_names_trap_among_the_choices_in_one_line(run_cli, tmp_path):
    proc = run_cli("scenarios", "generate", "--family", "traps", "--count", "1", "--out", tmp_path / "x")
    assert proc.returncode == 2
    assert proc.stderr.strip() == ("error: --family: must be one of sample, hard, mira, trap, "
                                   "got 'traps'")
    assert not (tmp_path / "x").exists()
