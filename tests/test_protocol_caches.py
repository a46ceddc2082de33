"""The fair protocol names the state of the caches every timed call starts from
(xfuzzy_rrt/bench/caches.py): ``cold`` evicts them before each timed call, ``warm`` runs a
planner's seeds of a problem in a row (in interleaved blocks, each after untimed calls),
``shuffled`` is the earlier order.
No neighbour decides it: in the shuffled order ``rrt:tuned`` started warm whenever ``rrt``,
its own kernel, had run before it in the seed's round. Only the timings depend on the mode."""

from pathlib import Path

import numpy as np
import pytest

from conftest import run_main
from xfuzzy_rrt.bench import caches, protocol
from xfuzzy_rrt.bench.caches import CacheEvictor, last_level_cache_bytes
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.scenario import load_scenario

DATA = Path(__file__).resolve().parents[1] / "xfuzzy_rrt" / "data" / "scenarios"
DEMO = DATA / "demo-gap.toml"
ENTRIES = [("rrt:tuned", "rrt:tuned", None), ("fuzzy-rrt", "fuzzy-rrt", None)]
TIMING = ["wall_s", "time_total_s"]


def _record(monkeypatch):
    """Every call the protocol makes, as ``(planner, seed, max_iter)``, and ``"evict"`` for
    every eviction, in order."""
    events = []
    real = protocol._one
    monkeypatch.setattr(protocol, "_one", lambda sc, planner, rb, seed, max_iter, cl:
                        events.append((sc.name, planner, seed, max_iter))
                        or real(sc, planner, rb, seed, max_iter, cl))
    monkeypatch.setattr(CacheEvictor, "__call__", lambda self: events.append("evict"))
    return events


def test_cold_caches_are_evicted_before_every_timed_call_and_only_then(monkeypatch):
    events = _record(monkeypatch)
    scenario = load_scenario(DEMO)
    protocol.run_protocol([scenario], ENTRIES, runs=4, max_iter=3000, caches="cold")
    warm_up = [e for e in events[:3]]
    assert "evict" not in warm_up and all(e[3] == 100 for e in warm_up)  # untimed warm-up
    timed = events[3:]
    assert len(timed) == 2 * 3 * 4
    assert timed[0::2] == ["evict"] * 12
    calls = timed[1::2]
    names = ["rrt", "rrt:tuned", "fuzzy-rrt"]
    assert [c[1] for c in calls] == [names[i] for k in range(4)
                                     for i in protocol.call_order(3, k)]


def test_warm_caches_run_each_planners_seeds_in_a_row_after_untimed_calls(monkeypatch):
    events = _record(monkeypatch)
    scenarios = [load_scenario(DEMO), load_scenario(DATA / "demo-tissue.toml")]
    result = protocol.run_protocol(scenarios, ENTRIES, runs=3, seed=5, max_iter=200,
                                   caches="warm")
    assert "evict" not in events
    timed = [e for e in events if e[3] == 200]  # not the process's warm-up (100 iterations)
    names = ["rrt", "rrt:tuned", "fuzzy-rrt"]
    expected = []
    for i, sc in enumerate(scenarios):
        for e in protocol.block_order(3, i):
            # untimed, then the first seed
            expected += [(sc.name, names[e], 5, 200)] * (protocol.WARM_UP_CALLS + 1)
            expected += [(sc.name, names[e], 5 + k, 200) for k in (1, 2)]
    assert timed == expected
    assert sorted(result.runs["seed"].unique()) == [5, 6, 7]
    assert len(result.runs) == 2 * 3 * 3  # the untimed calls are not recorded


def test_warm_blocks_interleave_the_planners_so_no_disturbance_slows_one_planner_only(
        monkeypatch):
    # A disturbance of the machine lasts as long as a block of calls: with one block per
    # planner it slowed every seed of one planner (trap-9800-024, twenty-ninth session).
    monkeypatch.setattr(protocol, "WARM_BLOCK", 2)
    events = _record(monkeypatch)
    scenario = load_scenario(DEMO)
    result = protocol.run_protocol([scenario], ENTRIES, runs=5, seed=5, max_iter=200,
                                   caches="warm")
    timed = [e for e in events if e[3] == 200]
    names = ["rrt", "rrt:tuned", "fuzzy-rrt"]
    expected = []
    for b, seeds in enumerate([(5, 6), (7, 8), (9,)]):
        for e in protocol.block_order(3, 0, b):
            # untimed: the block's first seed
            expected += [(scenario.name, names[e], seeds[0], 200)] * protocol.WARM_UP_CALLS
            expected += [(scenario.name, names[e], s, 200) for s in seeds]
    assert timed == expected
    # each planner's first timed call comes before any planner's second block
    firsts = [timed.index((scenario.name, n, 7, 200)) for n in names]
    lasts = [len(timed) - 1 - timed[::-1].index((scenario.name, n, 6, 200)) for n in names]
    assert max(lasts) < min(firsts)
    runs = result.runs
    assert len(runs) == 3 * 5
    for name in names:  # every seed once per planner, in seed order, as before
        assert runs.loc[runs["planner"] == name, "seed"].tolist() == [5, 6, 7, 8, 9]


def test_the_warm_blocks_order_differs_between_blocks_of_one_problem():
    orders = [protocol.block_order(4, 3, b) for b in range(12)]
    assert all(sorted(o) == list(range(4)) for o in orders)
    assert len({tuple(o) for o in orders}) > 3


def test_the_evaluate_help_and_output_name_the_warm_block_size():
    from xfuzzy_rrt.cli import evaluate

    said = evaluate._CACHES["warm"]
    assert f"blocks of {protocol.WARM_BLOCK} seeds" in said
    assert f"after {protocol.WARM_UP_CALLS} untimed calls" in said
    helped = " ".join(run_main("evaluate", "--help").stdout.split())
    assert f"blocks of {protocol.WARM_BLOCK} seeds, each after {protocol.WARM_UP_CALLS} untimed" \
        in helped


def test_block_orders_are_fixed_shuffles_that_vary_between_problems():
    orders = [protocol.block_order(5, i) for i in range(40)]
    assert all(sorted(o) == list(range(5)) for o in orders)
    assert orders == [protocol.block_order(5, i) for i in range(40)]
    assert len({tuple(o) for o in orders}) > 10
    firsts = [o[0] for o in orders]
    assert all(firsts.count(e) > 0 for e in range(5))  # every planner sometimes goes first


def test_plans_are_the_same_whatever_the_cache_mode():
    scenario = load_scenario(DEMO)
    frames = []
    for mode in ("cold", "warm", "shuffled"):
        result = protocol.run_protocol([scenario], ENTRIES, runs=3, max_iter=300, caches=mode)
        assert set(result.summary["caches"]) == {mode}
        runs = result.runs.drop(columns=TIMING).sort_values(["planner", "seed"])
        frames.append(runs.reset_index(drop=True))
    for other in frames[1:]:
        assert other.equals(frames[0])


def test_an_unknown_cache_mode_is_refused_before_anything_runs(monkeypatch, tmp_path):
    monkeypatch.setattr(protocol, "_one", lambda *a: pytest.fail("a planner ran"))
    with pytest.raises(InputError, match="--caches"):
        protocol.run_protocol([load_scenario(DEMO)], ENTRIES, runs=1, caches="tepid")
    proc = run_main("evaluate", DEMO, "--runs", "1", "--caches", "tepid",
                    "--out", tmp_path / "ev")
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "--caches" in lines[0] and "tepid" in lines[0]
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "ev").exists()


def test_evaluate_says_which_caches_its_times_were_measured_with(tmp_path):
    proc = run_main("evaluate", DEMO, "--runs", "2", "--max-iter", "300", "--caches", "warm",
                    "--out", tmp_path / "ev")
    assert proc.returncode == 0, proc.stderr
    assert "warm caches" in proc.stdout
    import pandas as pd

    summary = pd.read_csv(tmp_path / "ev" / "summary.csv")
    assert set(summary["caches"]) == {"warm"}


def _fake_sysfs(root: Path, entries: dict) -> Path:
    for name, (kind, size) in entries.items():
        (root / name).mkdir(parents=True)
        (root / name / "type").write_text(kind + "\n")
        (root / name / "size").write_text(size + "\n")
    return root


def test_the_last_level_cache_size_is_the_largest_data_cache_the_os_lists(tmp_path):
    root = _fake_sysfs(tmp_path / "cache", {"index0": ("Data", "32K"),
                                            "index1": ("Instruction", "64M"),
                                            "index2": ("Unified", "1024K"),
                                            "index3": ("Unified", "16M")})
    assert last_level_cache_bytes(root) == 16 * 2**20
    assert last_level_cache_bytes(tmp_path / "absent") == caches.FALLBACK_LLC_BYTES
    odd = _fake_sysfs(tmp_path / "odd", {"index0": ("Unified", "lots")})
    assert last_level_cache_bytes(odd) == caches.FALLBACK_LLC_BYTES


def test_an_eviction_writes_more_than_the_last_level_cache():
    evict = CacheEvictor(llc_bytes=2**20)
    assert evict.bytes >= caches.EVICT_FACTOR * 2**20 > 2**20
    before = evict.buffer.copy()
    evict()
    assert np.all(evict.buffer == before + 1.0)  # every byte written, none skipped


def test_the_eviction_buffer_is_capped_on_machines_that_report_huge_caches():
    assert caches.evict_bytes(64 * 2**30) == caches.MAX_EVICT_BYTES
    assert caches.evict_bytes(32 * 2**20) == 48 * 2**20
