"""A rulebook sent to a worker process (pickled with every benchmark job) arrives as one object
per process that keeps its hash: a new object per job would render every file again to hash it
and miss every set-up remembered for it, on every call, inside the time the benchmark reports."""

from __future__ import annotations

import pickle

import pytest

from conftest import FIXTURES
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario


@pytest.mark.parametrize("name", ["goal-frame", "paper"])
def test_an_unpickled_rulebook_is_one_object_per_process_that_keeps_its_hash(name):
    rb = load_rulebook(rulebooks_dir() / name)
    blob = pickle.dumps(rb)
    a = pickle.loads(blob)
    assert "sha256" in vars(a)  # carried, not computed again (the cached property's slot)
    b = pickle.loads(pickle.dumps(a))
    assert a is b and a == rb and a.sha256 == rb.sha256
    label = "fuzzy-rrt" if name == "goal-frame" else "fuzzy-rrt:paper"
    r = plan_scenario(load_scenario(FIXTURES / "scenarios" / "two-circles.toml"), label,
                      rulebook=a, seed=0)
    direct = plan_scenario(load_scenario(FIXTURES / "scenarios" / "two-circles.toml"), label,
                           rulebook=rb, seed=0)
    assert r.rulebook_sha256 == rb.sha256
    assert r.path_deg.tobytes() == direct.path_deg.tobytes() and r.iterations == direct.iterations


def test_rulebooks_that_differ_unpickle_as_different_objects():
    a = pickle.loads(pickle.dumps(load_rulebook(rulebooks_dir() / "goal-frame")))
    b = pickle.loads(pickle.dumps(load_rulebook(rulebooks_dir() / "expert")))
    assert a is not b and a.sha256 != b.sha256 and a.name == "goal-frame" and b.name == "expert"
