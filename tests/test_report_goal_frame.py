"""The audit report reads a goal-frame rulebook's own names, ranges and units."""

from __future__ import annotations

from conftest import FIXTURES

SCENARIO = FIXTURES / "scenarios" / "two-circles.toml"


def test_report_of_the_default_goal_frame_rulebook_names_its_inputs_and_units(tmp_path, run_cli):
    out = tmp_path / "b"
    proc = run_cli("bench", SCENARIO, "--planners", "rrt,fuzzy-rrt,fuzzy-rrt:paper", "--runs", "2",
                   "--workers", "1", "--out", out)
    assert proc.returncode == 0, proc.stderr
    pages = {p.name: p.read_text() for p in (out / "report").glob("*.html")}
    rulebook_pages = [t for name, t in pages.items() if name == "rulebook-fuzzy-rrt.html"]
    assert rulebook_pages, sorted(pages)
    page = rulebook_pages[0]
    for name in ("joint_dist_to_goal", "stagnation", "clearance_deg", "reject_rate",
                 "uniform_share", "ahead_deg", "side_deg", "step_deg"):
        assert name in page, name
    assert "angle_to_goal" not in page
    scenario_pages = [t for name, t in pages.items() if "two-circles" in name]
    assert scenario_pages and "Follow one plan" in scenario_pages[0]
    assert "joint_dist_to_goal" in scenario_pages[0]
