"""The tools that plan many problems (evaluate, bench) read ``rrt:tuned``'s settings once, as
they load the default's rulebooks once, so the peer's time carries no per-call file check the
default does not carry (planners/api.py, ``TunedRRT``); the plans are the same. And the protocol
shuffles its call order per seed, so no planner always runs right after another one (whose
identical kernel would have warmed the caches for it)."""

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


def test_the_protocol_does_not_call_one_planner_always_right_after_another():
    from xfuzzy_rrt.bench.protocol import call_order

    orders = [call_order(5, k) for k in range(50)]
    assert all(sorted(o) == list(range(5)) for o in orders)
    assert orders == [call_order(5, k) for k in range(50)]  # the same shuffles every run
    # rrt (entry 0) is followed by rrt:tuned (entry 1) in some seeds, not in all
    after_rrt = [o[o.index(0) + 1] if o.index(0) < 4 else None for o in orders]
    assert 0 < after_rrt.count(1) < 25


def test_the_protocol_calls_planners_in_the_shuffled_order(monkeypatch):
    from xfuzzy_rrt.bench import protocol

    calls = []
    real = protocol._one
    monkeypatch.setattr(protocol, "_one", lambda sc, planner, *a: calls.append(planner)
                        or real(sc, planner, *a))
    scenario = load_scenario(DEMO)
    entries = [("rrt:tuned", "rrt:tuned", None), ("fuzzy-rrt", "fuzzy-rrt", None)]
    protocol.run_protocol([scenario], entries, runs=6, max_iter=200)
    timed = calls[-18:]
    names = ["rrt", "rrt:tuned", "fuzzy-rrt"]
    assert [timed[3 * k:3 * k + 3] for k in range(6)] == \
        [[names[i] for i in protocol.call_order(3, k)] for k in range(6)]


def test_a_rulebook_planner_compared_as_a_peer_gets_its_rulebook_loaded_once(monkeypatch):
    # evaluate --peer fuzzy-rrt-connect used to pass no rulebook, so every timed call resolved
    # the shipped folder again (a stat; ~100 us of a 3-joint call with cold caches) while the
    # default it was compared with had its rulebooks preloaded
    from xfuzzy_rrt.fuzzy import rulebook as rb_module
    from xfuzzy_rrt.fuzzy.rulebook import Rulebook

    scenario = load_scenario(DEMO)
    alone = plan_scenario(scenario, "fuzzy-rrt-connect", seed=3, max_iter=500)
    resolved = []
    real = rb_module.load_rulebook_cached
    monkeypatch.setattr(rb_module, "load_rulebook_cached",
                        lambda *a, **k: resolved.append(a) or real(*a, **k))
    given = api.preloaded("fuzzy-rrt-connect", None)
    assert isinstance(given, Rulebook) and given.name == "goal-frame-any"
    result = run_protocol([scenario], [("fuzzy-rrt-connect", "fuzzy-rrt-connect", None)],
                          runs=3, max_iter=500)
    assert resolved == []  # no run resolved a rulebook folder
    runs = result.runs[result.runs["planner"] == "fuzzy-rrt-connect"]
    assert len(runs) == 3 and set(runs["rulebook"]) == {"goal-frame-any"}
    same = plan_scenario(scenario, "fuzzy-rrt-connect", rulebook=given, seed=3, max_iter=500)
    assert same.work == alone.work and (same.path_deg == alone.path_deg).all()


def test_a_label_naming_its_rulebook_gets_that_folder_loaded_once():
    from xfuzzy_rrt.fuzzy.rulebook import Rulebook

    for label, name in (("fuzzy-rrt:goal-frame", "goal-frame"),
                        ("fuzzy-rrt-connect:goal-frame-any", "goal-frame-any")):
        got = api.preloaded(label, None)
        assert isinstance(got, Rulebook) and got.name == name
    assert api.preloaded("rrt", None) is None
    assert api.preloaded("fuzzy-rrt", None) is None  # plain: the caller loads the default
