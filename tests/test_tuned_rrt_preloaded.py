"""The tools that plan many problems (evaluate, bench) read ``rrt:tuned``'s settings once, as
they load the default's rulebooks once, so the peer's time carries no per-call file check the
default does not carry (planners/api.py, ``TunedRRT``); the plans are the same."""

from pathlib import Path

import pytest

from xfuzzy_rrt.bench.protocol import run_protocol
from xfuzzy_rrt.bench.runner import job_rulebooks
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners import api
from xfuzzy_rrt.planners.api import TunedRRT, load_tuned_rrt, plan_scenario

DEMO = Path(__file__).resolve().parents[1] / "xfuzzy_rrt" / "data" / "scenarios" / "demo-gap.toml"


def test_tuned_rrt_with_its_settings_read_once_plans_exactly_as_with_its_label_alone():
    scenario = load_scenario(DEMO)
    settings = load_tuned_rrt()
    for seed in range(5):
        alone = plan_scenario(scenario, "rrt:tuned", seed=seed, max_iter=2000)
        given = plan_scenario(scenario, "rrt:tuned", rulebook=settings, seed=seed, max_iter=2000)
        assert given.planner == alone.planner == "rrt:tuned"
        assert given.params == alone.params
        assert given.work == alone.work and given.iterations == alone.iterations
        assert (given.path_deg == alone.path_deg).all()


def test_settings_read_once_are_used_as_given_not_read_again(monkeypatch):
    scenario = load_scenario(DEMO)
    monkeypatch.setattr(api, "_tuned_rrt", lambda where: pytest.fail("tuned file read again"))
    r = plan_scenario(scenario, "rrt:tuned", rulebook=TunedRRT(45.0, 0.2), seed=1, max_iter=500)
    assert r.params["step_deg"] == 45.0 and r.params["goal_bias"] == 0.2


def test_the_protocol_reads_the_tuned_file_once_not_on_every_run(monkeypatch):
    reads = []
    real = api._tuned_rrt
    monkeypatch.setattr(api, "_tuned_rrt", lambda where: reads.append(where) or real(where))
    scenario = load_scenario(DEMO)
    result = run_protocol([scenario], [("rrt:tuned", "rrt:tuned", None)], runs=4, max_iter=300)
    assert len(result.runs[result.runs["planner"] == "rrt:tuned"]) == 4
    assert len(reads) == 1


def test_bench_jobs_get_the_tuned_settings_read_once():
    jobs = job_rulebooks(["rrt", "rrt:tuned"], {})
    assert jobs["rrt:tuned"] == load_tuned_rrt()
    assert "rrt" not in jobs


def test_tuned_settings_given_to_a_fuzzy_planner_are_refused_with_one_line():
    scenario = load_scenario(DEMO)
    with pytest.raises(InputError, match="not a rulebook"):
        plan_scenario(scenario, "fuzzy-rrt", rulebook=load_tuned_rrt(), seed=1, max_iter=50)
