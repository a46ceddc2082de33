"""Reports draw every arm of a scenario, each from its own slice of the configuration, and the
joint-space view of an N-DOF or multi-arm problem shows the first arm's first two joints with a
note instead of failing. The runs here are built by hand (no planner), so only drawing is tested.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from conftest import FIXTURES
from xfuzzy_rrt.geometry.kinematics import joint_points
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.report import figures as F

ARMS = FIXTURES / "arms"


def _run(s, n_mid: int = 3):
    """A made-up run from start to goal through ``n_mid`` interpolated configurations."""
    start, goal = np.asarray(s.start_deg), np.asarray(s.goal_deg)
    t = np.linspace(0.0, 1.0, n_mid + 2)[:, None]
    path = start + t * (goal - start)
    return SimpleNamespace(planner="rrt", seed=3, iterations=40, nodes=path.shape[0],
                           cost_deg=float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1))),
                           path_deg=path, tree_nodes_deg=path,
                           tree_parent=np.arange(-1, path.shape[0] - 1), min_clearance_m=0.01)


def _link_traces(fig, group):
    return [t for t in fig.data if t.legendgroup == group]


@pytest.mark.parametrize("file,arms,links", [("five-dof.toml", 1, (5,)),
                                             ("dual-2dof.toml", 2, (2, 2)),
                                             ("dual-3dof.toml", 2, (3, 3))])
def test_workspace_draws_each_arm_at_start_goal_and_along_the_path(file, arms, links):
    s = load_scenario(ARMS / file)
    fig = F.workspace_figure(s, _run(s), n_poses=4)
    for group, q in (("start", s.start_deg), ("goal", s.goal_deg)):
        traces = _link_traces(fig, group)
        assert len(traces) == arms
        for a, (t, sl) in enumerate(zip(traces, s.arm_slices())):
            assert len(t.x) == links[a] + 1  # base, joints, tip
            expected = joint_points(s.arms[a].links, s.arms[a].base, np.asarray(q)[sl])
            np.testing.assert_allclose(np.c_[t.x, t.y], expected)
    assert len(_link_traces(fig, "poses")) == 4 * arms
    ee = [t for t in fig.data if "end-effector trace" in (t.name or "")]
    assert len(ee) == arms
    bases = [t for t in fig.data if t.name == "base"]
    assert len(bases) == 1 and len(bases[0].x) == arms
    reach_circles = [sh for sh in fig.layout.shapes if sh.layer == "below"]
    assert len(reach_circles) == arms
    # every arm's disc fits in the axes
    xr, yr = fig.layout.xaxis.range, fig.layout.yaxis.range
    for arm in s.arms:
        assert xr[0] <= arm.base[0] - arm.reach and arm.base[0] + arm.reach <= xr[1]
        assert yr[0] <= arm.base[1] - arm.reach and arm.base[1] + arm.reach <= yr[1]


def test_two_arms_are_told_apart_by_name_and_line_style():
    s = load_scenario(ARMS / "dual-2dof.toml")
    fig = F.workspace_figure(s, _run(s))
    start = _link_traces(fig, "start")
    assert [t.name for t in start] == ["left at start", "right at start"]
    assert [t.line.dash for t in start] == ["solid", "dash"]
    unnamed = load_scenario(ARMS / "dual-3dof.toml")
    fig = F.workspace_figure(unnamed, None)
    assert [t.name for t in _link_traces(fig, "goal")] == ["arm 1 at goal", "arm 2 at goal"]


def test_a_single_arm_figure_keeps_its_old_traces():
    s = load_scenario(FIXTURES / "scenarios" / "two-circles.toml")
    fig = F.workspace_figure(s, _run(s), n_poses=2)
    names = [t.name for t in fig.data]
    assert names == ["obstacle", "arm along path", "arm along path", "end-effector trace",
                     "arm at start", "arm at goal", "base"]
    assert all(t.line.dash is None for t in fig.data if t.legendgroup == "start")


@pytest.mark.parametrize("file", ["five-dof.toml", "dual-2dof.toml", "dual-3dof.toml"])
def test_joint_space_view_shows_the_first_two_joints_with_a_note(file):
    s = load_scenario(ARMS / file)
    r = _run(s)
    fig = F.joint_space_figure(s, r)
    assert not any(t.type == "heatmap" for t in fig.data)  # no C-obstacle map
    assert "first two joints of" in fig.layout.title.text
    path = next(t for t in fig.data if t.name == "path")
    np.testing.assert_allclose(path.x, r.path_deg[:, 0])
    np.testing.assert_allclose(path.y, r.path_deg[:, 1])
    custom = F.joint_space_figure(s, r, title="replay")  # a caller's title: the note is above
    assert any("first two joints" in a.text for a in custom.layout.annotations)
    with pytest.raises(ValueError, match="one 2-DOF arm"):
        F.cspace_grid(s)
    drill = F.drilldown_figure(s, r)  # the evidence page's joint-space view
    assert drill.data[-1].name == "this iteration"


def test_the_worst_path_figure_draws_every_arm_at_its_closest_configuration(monkeypatch):
    from xfuzzy_rrt.report import site

    s = load_scenario(ARMS / "dual-2dof.toml")
    monkeypatch.setattr(site, "worst_pose",
                        lambda scenario, path: (np.asarray(scenario.start_deg), 0.01))
    fig = site.worst_path_figure(s, _run(s))
    closest = _link_traces(fig, "closest")
    assert [len(t.x) for t in closest] == [3, 3]


def test_scenario_details_list_each_arm():
    from xfuzzy_rrt.report.evidence import _scenario_details

    html = _scenario_details(load_scenario(ARMS / "dual-2dof.toml"))
    for text in ("arm 1 (left) links", "arm 2 (right) joint limits", "arm 2 (right) start",
                 "(60\u00b0, 0\u00b0)"):
        assert text in html


def test_robustness_page_draws_each_arm_from_its_own_angles():
    from xfuzzy_rrt.robustness.figure import _arms_points

    s = load_scenario(ARMS / "dual-3dof.toml")
    a = s.arrays()
    pts = _arms_points(a, s.start_deg)
    assert [p.shape for p in pts] == [(4, 2), (4, 2)]
    for arm, sl, p in zip(s.arms, s.arm_slices(), pts):
        np.testing.assert_allclose(p, joint_points(arm.links, arm.base, np.asarray(s.start_deg)[sl]))
    single = load_scenario(ARMS / "five-dof.toml")
    assert [p.shape for p in _arms_points(single.arrays(), single.start_deg)] == [(6, 2)]
