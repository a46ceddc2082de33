"""The fair protocol behind every "N x fewer iterations than RRT" this project states.

Why a protocol of its own: a ratio claimed for a rulebook means nothing unless it is measured the
same way every time — on problems no training or tuning saw, against RRT run with the *same*
seeds, with failures counted (as ``max_iter`` iterations, never dropped), per problem first and
only then summarised, because a handful of hard problems dominate any pooled mean. So:

1. Every planner runs on every problem with seeds ``seed .. seed + runs - 1`` (common random
   numbers across planners).
2. Per problem and planner: median iterations (failures = ``max_iter``), success rate (a run
   succeeds only with a path that passed the certified check), median cost of the successful
   paths, median wall time to the first path.
3. Per problem, ratios to RRT: ``rrt_median_iterations / planner_median_iterations`` (> 1: the
   planner needs fewer), ``planner_median_cost / rrt_median_cost`` (< 1: shorter paths) and
   ``rrt_median_time / planner_median_time``.
4. Per planner over problems: median, geometric mean, worst and best iteration ratio, how many
   problems it loses (ratio < 1), worst success rate and how often it falls below RRT's, median
   cost ratio, median time ratio.

OMPL planners count iterations differently, so they are ranked on time only (their iteration
ratio is left empty).

**Time and work as the measure** (issue 23). Iterations are the paper's measure, but a 60°
edge costs more certified stops than a 10° one, so every planner is also ranked on

- *end-to-end time to the first certified path* (``time_total_s``): ``time.perf_counter()``
  around the whole :func:`~xfuzzy_rrt.planners.api.plan_scenario` call, as a user waits for it
  (set-up, planning, certification of the path);
- *end-to-end work* (``work_total``): the planner's deterministic work count
  (``PlanResult.work``: distance evaluations plus nearest-neighbour visits of the search, also
  in ``work``) plus that of certifying its path (``certify_work``), identical on any machine;
  empty for planners that do not count. End to end like the time, and the measure the tuned
  RRT was tuned on.

A run without a certified path counts with the time and the work it spent until its budget
ran out (as its iterations count ``max_iter``): the user waited that long for nothing, and the
success rate beside it says how often. These ratios are taken against the *peer at its best*,
the tuned RRT (``rrt:tuned``, shipped tuned file) when it runs -- by default it does -- else
against RRT; the summary names that baseline (``time_work_baseline``) and ranks planners by
their median end-to-end time ratio (``time_rank``, 1 = fastest).

**Against the fastest tuned peer per problem** (issue 25's measure): a user does not care which
peer is fastest on a problem, only how long the fastest one takes. Given the labels that are
*peers* (``evaluate``: ``rrt:tuned`` and every ``--peer``; the paper's RRT never is one), each
problem's ``best_peer`` is the peer with the smallest median end-to-end time, and
``best_peer_ratio`` is that time over the planner's (> 1: faster than every peer);
``success_below_peer`` says whether the planner's certified success rate is below some peer's.
Per planner: median, geometric mean and worst (smallest) ratio, problems lost (ratio < 1),
problems with success below a peer, and which peers were fastest where (``best_peers``). Each
ratio comes with its 95 % bootstrap interval over the seeds (``best_peer_ratio_lo``/``_hi``,
:mod:`xfuzzy_rrt.bench.interval`), and a problem counts as *surely* lost (won) only when the
whole interval lies below (above) 1: with a few dozen seeds of runs lasting microseconds, a
ratio of 0.8x can be a coin toss. The medians over problems of the ratio to the fastest peer
and of ``cost_peer_ratio`` come with the 95 % bootstrap interval over problems
(``median_best_peer_ratio_lo``/``_hi``, ``median_cost_peer_ratio_lo``/``_hi``): how far the
median would move on other problems of the same family. Path length is compared with
the same peer too (``cost_peer_ratio`` = planner's median cost / the peer's, < 1: shorter;
summarised as median, worst = largest, and how many problems are longer): issue 25's aim is a
median path cost no higher than the tuned RRT's, and ``cost_ratio`` compares with the paper's
RRT only. Iteration ratios stay
against the paper's RRT (10°, goal bias 0.05).

**The caches a timed call starts from** (:mod:`xfuzzy_rrt.bench.caches`) are named, not left
to the neighbours: ``cold`` (default: evicted before every timed call), ``warm`` (a planner's
seeds in a row, in interleaved blocks of :data:`WARM_BLOCK` seeds) or ``shuffled`` (the earlier
order); the summary's ``caches`` column says which.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from xfuzzy_rrt.bench.caches import DEFAULT_CACHE_MODE, CacheEvictor, check_cache_mode
from xfuzzy_rrt.bench.interval import median_interval, median_ratio_interval

PROBLEM_COLUMNS = ["scenario", "planner", "runs", "success_rate", "median_iterations",
                   "median_cost_deg", "median_time_s", "iteration_ratio", "cost_ratio",
                   "time_ratio", "median_time_total_s", "median_work", "median_work_total",
                   "time_total_ratio", "work_total_ratio", "cost_peer_ratio", "best_peer",
                   "best_peer_ratio", "best_peer_ratio_lo", "best_peer_ratio_hi",
                   "success_below_peer"]
SUMMARY_COLUMNS = ["planner", "problems", "median_ratio", "geomean_ratio", "worst_ratio",
                   "best_ratio", "problems_lost", "worst_success_rate",
                   "problems_success_below_rrt", "median_cost_ratio", "median_time_ratio",
                   "median_time_s", "time_work_baseline", "time_rank", "median_time_total_ratio",
                   "worst_time_total_ratio", "problems_lost_time", "median_work_total_ratio",
                   "worst_work_total_ratio", "problems_lost_work_total", "median_time_total_s",
                   "median_work", "median_work_total", "caches", "median_cost_peer_ratio",
                   "median_cost_peer_ratio_lo", "median_cost_peer_ratio_hi",
                   "worst_cost_peer_ratio", "problems_longer_than_peer", "best_peers",
                   "median_best_peer_ratio", "median_best_peer_ratio_lo",
                   "median_best_peer_ratio_hi", "geomean_best_peer_ratio", "worst_best_peer_ratio",
                   "problems_lost_best_peer", "problems_surely_lost_best_peer",
                   "problems_surely_won_best_peer", "problems_success_below_peer"]
RUN_COLUMNS = ["scenario", "planner", "seed", "success", "iterations", "cost_deg", "wall_s",
               "time_total_s", "work", "work_total", "planner_used", "rulebook",
               "rulebook_sha256"]
BASELINE = "rrt"
TUNED_BASELINE = "rrt:tuned"


@dataclass(frozen=True)
class ProtocolResult:
    runs: pd.DataFrame  # one row per run: scenario, planner, seed, success, iterations, cost_deg, wall_s
    problems: pd.DataFrame  # PROBLEM_COLUMNS
    summary: pd.DataFrame  # SUMMARY_COLUMNS


def _one(scenario, planner: str, rulebook, seed: int, max_iter: int, clearance_m) -> dict:
    import time

    from xfuzzy_rrt.planners.api import plan_scenario

    t0 = time.perf_counter()
    r = plan_scenario(scenario, planner=planner, rulebook=rulebook, seed=seed, max_iter=max_iter,
                      clearance_m=clearance_m)
    total = time.perf_counter() - t0
    ok = bool(getattr(r, "success", False))
    work = getattr(r, "work", None)
    return {"success": ok, "iterations": int(r.iterations) if ok else int(max_iter),
            "cost_deg": float(r.cost_deg) if ok and r.cost_deg is not None else np.nan,
            "wall_s": float(r.wall_s), "time_total_s": total,
            "work": np.nan if work is None else float(work),
            "work_total": np.nan if work is None else float(work + r.certify_work),
            # what ran (plain fuzzy-rrt's shipped default differs per problem: api.shipped_default)
            "planner_used": getattr(r, "planner_used", None) or r.planner,
            "rulebook": getattr(r, "rulebook", None),
            "rulebook_sha256": getattr(r, "rulebook_sha256", None)}


def call_order(n: int, k: int) -> list[int]:
    """The order in which the protocol calls its ``n`` planners for the ``k``-th seed: a
    shuffle fixed by ``k`` (so a rerun times the calls in the same order)."""
    return [int(i) for i in np.random.default_rng([0x5EED, k]).permutation(n)]


#: Seeds per block of the ``warm`` cache mode: each planner's seeds of a problem run in blocks
#: of this many, the planners' blocks interleaved (:func:`run_protocol`).
#:
#: Why not one block per planner: a disturbance of the machine (another process, a page-cache
#: flush) lasts milliseconds, as long as a whole block of 2-joint calls, so with one block it
#: slowed every seed of one planner on one problem and set that problem's ratio by itself. The
#: twenty-ninth session saw it: ``trap-9800-024`` measured 0.46x, its default's 50 calls taking
#: 11-327 us where every other sitting had 12-41 us, and the family's worst case was that one
#: disturbed block. Interleaved, a disturbance touches one block of each planner it overlaps:
#: at most a fifth of a planner's 50 seeds, which a median over the seeds absorbs.
WARM_BLOCK = 10

#: Untimed calls (of the block's first seed) before each ``warm`` block. One was not enough once
#: the blocks were interleaved: after another planner's block, the first two timed calls of the
#: default's block were ~8 % slower than mid-block (its loop is larger than the tuned RRT's and
#: takes more than one call to warm), so blocks of 10 after one untimed call gave the default a
#: 1-2 % lower geomean ratio than one block of 50 (sample 1.08x against 1.10x, three runs each,
#: thirtieth session); after three untimed calls, 1.09x and on ``mira`` 1.11x against 1.10x.
WARM_UP_CALLS = 3


def block_order(n: int, i: int, b: int = 0) -> list[int]:
    """The order of the ``n`` planners' ``b``-th blocks of runs on the ``i``-th problem under
    the ``warm`` cache mode: a shuffle fixed by ``i`` and ``b``."""
    return [int(x) for x in np.random.default_rng([0x5EED, 0xB10C, i, b]).permutation(n)]


def run_protocol(scenarios: list, planners: list[tuple[str, str, object]], runs: int = 50,
                 seed: int = 0, max_iter: int = 10_000, progress=None,
                 clearance_m: float | None = None,
                 caches: str = DEFAULT_CACHE_MODE, peers=None) -> ProtocolResult:
    """Run RRT and every ``(label, planner, rulebook)`` of *planners* on every scenario (put
    ``("rrt:tuned", "rrt:tuned", None)`` among them to rank against the tuned RRT).

    ``clearance_m`` is the certified margin every planner must keep (``None``: each scenario's).
    ``caches``: the state each timed call starts from (:mod:`xfuzzy_rrt.bench.caches`):
    ``cold`` (evicted before every call), ``warm`` (each planner's seeds of a problem in a row,
    in blocks of :data:`WARM_BLOCK` seeds, each block after :data:`WARM_UP_CALLS` untimed calls
    of its first seed, the planners' blocks interleaved) or ``shuffled`` (planners shuffled per
    seed, nothing evicted). Only the timings depend on it.

    ``peers``: the labels that count as tuned peers for the best-peer columns (default: every
    label of *planners* that is not a Fuzzy-RRT one, i.e. ``rrt:tuned`` and ``ompl:...``).

    ``planner`` is a name :func:`~xfuzzy_rrt.planners.api.plan_scenario` takes (``fuzzy-rrt``
    with a loaded ``rulebook`` or the :class:`~xfuzzy_rrt.planners.api.ShippedDefault`, or
    ``ompl:NAME``); ``label`` names it in the tables, ``planner_used``/``rulebook`` in the runs
    say what ran.
    """
    from xfuzzy_rrt.planners.api import preloaded

    check_cache_mode(caches)
    # rrt:tuned's settings read once, as the default's rulebooks are (api.TunedRRT)
    entries = [("rrt", "rrt", None), *((label, planner, preloaded(planner, rb))
                                       for label, planner, rb in planners)]
    rows = []
    total = len(scenarios) * len(entries)
    done = 0
    # Warm-up, not recorded: each planner's first call in a process loads (or compiles) its
    # kernels, OMPL's too, which is not the time a user waits for a plan.
    # Plain fuzzy-rrt runs another planner on a problem that is not one 2-joint arm, so the
    # first problem of the other kind warms up too.
    if scenarios:
        kind = scenarios[0].one_two_joint_arm
        warm = [scenarios[0], *[s for s in scenarios if s.one_two_joint_arm != kind][:1]]
        for sc in warm:
            for _label, planner, rb in entries:
                _one(sc, planner, rb, seed, min(max_iter, 100), clearance_m)
    evict = CacheEvictor() if caches == "cold" else None
    n = len(entries)
    for i, sc in enumerate(scenarios):
        per = {label: [] for label, _, _ in entries}

        def timed(e: int, k: int) -> None:
            label, planner, rb = entries[e]
            if evict is not None:
                evict()
            per[label].append({"scenario": sc.name, "planner": label, "seed": seed + k,
                               **_one(sc, planner, rb, seed + k, max_iter, clearance_m)})

        if caches == "warm":
            # Each planner's seeds in a row, each block after untimed calls of its first seed
            # (WARM_UP_CALLS): the calls a user who plans in a loop makes. The blocks are
            # interleaved (the first block of every planner, then the second...), so a
            # disturbance of the machine slows a block of each planner it overlaps, never all
            # of one planner's seeds (WARM_BLOCK); their order is shuffled per problem and
            # block, so no planner always follows another.
            for b, first in enumerate(range(0, runs, WARM_BLOCK)):
                for e in block_order(n, i, b):
                    label, planner, rb = entries[e]
                    for _ in range(WARM_UP_CALLS):
                        _one(sc, planner, rb, seed + first, max_iter, clearance_m)
                    for k in range(first, min(first + WARM_BLOCK, runs)):
                        timed(e, k)
        else:
            # Seeds outer, planners inner: every planner runs seed k under the same machine
            # conditions, so a burst of load blurs all planners alike, not one planner's
            # block. The order is shuffled per seed (the same shuffles in every run: timing
            # only, the results do not depend on it): in a fixed order rrt:tuned always ran
            # right after rrt, whose identical kernel, arrays and tree had just warmed the
            # caches for it; a rotation keeps that neighbour (README, "the order of calls").
            # Shuffled, each planner follows each other one as often -- yet rrt:tuned still
            # starts warm whenever rrt ran before it in the seed's round, which is why the
            # default mode (cold) evicts the caches before every timed call.
            for k in range(runs):
                for e in call_order(n, k):
                    timed(e, k)
        for label, _, _ in entries:
            rows.extend(per[label])
            done += 1
            if progress:
                progress(done, total)
    frame = pd.DataFrame(rows, columns=RUN_COLUMNS)
    for col in ("work", "work_total"):
        frame[col] = frame[col].astype("Int64")
    if peers is None:
        peers = [label for label, planner, _ in planners if not planner.startswith("fuzzy-rrt")]
    problems = problem_table(frame, [e[0] for e in entries], peers)
    return ProtocolResult(runs=frame, problems=problems,
                          summary=summary_table(problems, caches=caches))


def problem_table(runs: pd.DataFrame, order: list[str], peers=()) -> pd.DataFrame:
    """Per (scenario, planner) medians and ratios to RRT, to the tuned peer and to the fastest
    of the *peers* (labels; see the module docstring)."""
    runs = runs.copy()
    for col in ("time_total_s", "work", "work_total"):
        runs[col] = (pd.to_numeric(runs[col], errors="coerce").astype(float) if col in runs
                     else np.nan)
    g = runs.groupby(["scenario", "planner"], sort=False)
    per = g.agg(runs=("seed", "size"), success_rate=("success", "mean"),
                median_iterations=("iterations", "median"),
                median_cost_deg=("cost_deg", "median"),
                median_time_s=("wall_s", "median"),
                median_time_total_s=("time_total_s", "median"),
                median_work=("work", "median"),
                median_work_total=("work_total", "median")).reset_index()
    rrt = per[per["planner"] == "rrt"].set_index("scenario")
    base_it = per["scenario"].map(rrt["median_iterations"])
    base_cost = per["scenario"].map(rrt["median_cost_deg"])
    base_time = per["scenario"].map(rrt["median_time_s"])
    is_ompl = per["planner"].str.startswith("ompl:")
    per["iteration_ratio"] = np.where(is_ompl, np.nan, base_it / per["median_iterations"])
    per["cost_ratio"] = per["median_cost_deg"] / base_cost
    per["time_ratio"] = base_time / per["median_time_s"]
    peer = per[per["planner"] == time_work_baseline(order)].set_index("scenario")
    per["time_total_ratio"] = (per["scenario"].map(peer["median_time_total_s"])
                               / per["median_time_total_s"])
    per["work_total_ratio"] = (per["scenario"].map(peer["median_work_total"])
                               / per["median_work_total"])
    # path length against the same peer, planner / peer (< 1: shorter), like cost_ratio
    per["cost_peer_ratio"] = per["median_cost_deg"] / per["scenario"].map(peer["median_cost_deg"])
    _best_peer_columns(per, peers, runs)
    per["planner"] = pd.Categorical(per["planner"], categories=order, ordered=True)
    per = per.sort_values(["planner", "scenario"], kind="stable").reset_index(drop=True)
    per["planner"] = per["planner"].astype(str)
    return per[PROBLEM_COLUMNS]


def _best_peer_columns(per: pd.DataFrame, peers, runs: pd.DataFrame) -> None:
    """``best_peer``, ``best_peer_ratio`` (with its bootstrap interval ``best_peer_ratio_lo``
    .. ``_hi``, :mod:`xfuzzy_rrt.bench.interval`, from the *runs*) and ``success_below_peer``
    of each row of *per* (one row per scenario and planner), in place; empty without peers
    among the planners that ran. A failed run counts with the time it spent (as
    ``time_total_ratio``)."""
    peers = [p for p in dict.fromkeys(peers) if p in set(per["planner"]) and p != BASELINE]
    if not peers:
        per["best_peer"], per["best_peer_ratio"], per["success_below_peer"] = None, np.nan, False
        per["best_peer_ratio_lo"] = per["best_peer_ratio_hi"] = np.nan
        return
    mine = per[per["planner"].isin(peers)]
    times = mine.pivot(index="scenario", columns="planner", values="median_time_total_s")
    success = mine.pivot(index="scenario", columns="planner", values="success_rate")
    fastest = times.idxmin(axis=1)
    per["best_peer"] = per["scenario"].map(fastest)
    per["best_peer_ratio"] = per["scenario"].map(times.min(axis=1)) / per["median_time_total_s"]
    per["success_below_peer"] = (per["success_rate"]
                                 < per["scenario"].map(success.max(axis=1)) - 1e-12)
    times_of = {k: g.to_numpy(dtype=float)
                for k, g in runs.groupby(["scenario", "planner"], sort=False)["time_total_s"]}
    none = np.empty(0)  # a problem no peer ran on (a partial runs table): no interval
    bounds = [median_ratio_interval(times_of.get((sc, peer), none),
                                    times_of.get((sc, planner), none), f"{sc}\0{planner}")
              for sc, planner, peer in zip(per["scenario"], per["planner"], per["best_peer"])]
    per["best_peer_ratio_lo"] = [lo for lo, _ in bounds]
    per["best_peer_ratio_hi"] = [hi for _, hi in bounds]


def time_work_baseline(planners) -> str:
    """The baseline of the time and work ratios: the tuned RRT when it ran, else RRT."""
    return TUNED_BASELINE if TUNED_BASELINE in set(planners) else BASELINE


def _dist(values) -> tuple[float, float, int]:
    """Median, worst (smallest) and number below 1 of finite ratios (NaN, NaN, 0 without)."""
    r = np.asarray(values, dtype=float)
    r = r[np.isfinite(r)]
    if r.size == 0:
        return np.nan, np.nan, 0
    return float(np.median(r)), float(r.min()), int((r < 1.0).sum())


def summary_table(problems: pd.DataFrame, caches: str = "") -> pd.DataFrame:
    """One row per planner (RRT included, whose ratios are 1 by construction); ``caches``
    names the cache mode the times were measured in (:mod:`xfuzzy_rrt.bench.caches`).
    The best-peer columns summarise ``best_peer_ratio`` (:func:`_best_peer_columns`)."""
    rows = []
    peer = time_work_baseline(problems["planner"])
    rrt_success = problems[problems["planner"] == "rrt"].set_index("scenario")["success_rate"]
    for planner, g in problems.groupby("planner", sort=False):
        r = g["iteration_ratio"].to_numpy(dtype=float)
        has = np.isfinite(r).any()
        below = (g["success_rate"].to_numpy() < g["scenario"].map(rrt_success).to_numpy()).sum()
        rows.append({
            "planner": planner, "problems": len(g),
            "median_ratio": float(np.nanmedian(r)) if has else np.nan,
            "geomean_ratio": float(np.exp(np.nanmean(np.log(r)))) if has else np.nan,
            "worst_ratio": float(np.nanmin(r)) if has else np.nan,
            "best_ratio": float(np.nanmax(r)) if has else np.nan,
            "problems_lost": int((r < 1.0).sum()) if has else 0,
            "worst_success_rate": float(g["success_rate"].min()),
            "problems_success_below_rrt": int(below),
            "median_cost_ratio": _nanmedian(g["cost_ratio"]),
            "median_time_ratio": _nanmedian(g["time_ratio"]),
            "median_time_s": _nanmedian(g["median_time_s"]),
        })
        t_med, t_worst, t_lost = _dist(g["time_total_ratio"])
        w_med, w_worst, w_lost = _dist(g["work_total_ratio"])
        rows[-1].update({
            "time_work_baseline": peer, "median_time_total_ratio": t_med,
            "worst_time_total_ratio": t_worst, "problems_lost_time": t_lost,
            "median_work_total_ratio": w_med, "worst_work_total_ratio": w_worst,
            "problems_lost_work_total": w_lost,
            "median_time_total_s": _nanmedian(g["median_time_total_s"]),
            "median_work": _nanmedian(g["median_work"]),
            "median_work_total": _nanmedian(g["median_work_total"]),
            "caches": caches,
        })
        c = g["cost_peer_ratio"].to_numpy(dtype=float)
        c = c[np.isfinite(c)]
        c_lo, c_hi = median_interval(c, f"{planner}\0cost")
        rows[-1].update({
            "median_cost_peer_ratio": float(np.median(c)) if c.size else np.nan,
            "median_cost_peer_ratio_lo": c_lo, "median_cost_peer_ratio_hi": c_hi,
            "worst_cost_peer_ratio": float(c.max()) if c.size else np.nan,
            "problems_longer_than_peer": int((c > 1.0).sum()),
        })
        b = g["best_peer_ratio"].to_numpy(dtype=float)
        b = b[np.isfinite(b) & (b > 0)]
        b_lo, b_hi = median_interval(b, f"{planner}\0time")
        rows[-1].update({
            "median_best_peer_ratio_lo": b_lo, "median_best_peer_ratio_hi": b_hi,
            "best_peers": ", ".join(f"{k} {v}" for k, v in
                                    g["best_peer"].dropna().value_counts().items()),
            "median_best_peer_ratio": float(np.median(b)) if b.size else np.nan,
            "geomean_best_peer_ratio": float(np.exp(np.log(b).mean())) if b.size else np.nan,
            "worst_best_peer_ratio": float(b.min()) if b.size else np.nan,
            "problems_lost_best_peer": int((b < 1.0).sum()),
            "problems_surely_lost_best_peer": int((g["best_peer_ratio_hi"] < 1.0).sum()),
            "problems_surely_won_best_peer": int((g["best_peer_ratio_lo"] > 1.0).sum()),
            "problems_success_below_peer": int(g["success_below_peer"].astype(bool).sum()),
        })
    frame = pd.DataFrame(rows, columns=SUMMARY_COLUMNS)
    # Rank on end-to-end time (1 = the largest median ratio to the baseline); ties share.
    key = frame["median_time_total_ratio"].fillna(-np.inf)
    frame["time_rank"] = key.rank(ascending=False, method="min").astype(int)
    return frame


def _nanmedian(values) -> float:
    v = pd.to_numeric(pd.Series(values), errors="coerce").to_numpy(dtype=float)
    v = v[np.isfinite(v)]
    return float(np.median(v)) if v.size else np.nan


def write_protocol(result: ProtocolResult, out: Path) -> None:
    """``runs.csv``, ``problems.csv`` and ``summary.csv`` into *out* (each written atomically)."""
    from xfuzzy_rrt.atomic import atomic_path

    out.mkdir(parents=True, exist_ok=True)
    for name, frame in (("runs.csv", result.runs), ("problems.csv", result.problems),
                        ("summary.csv", result.summary)):
        with atomic_path(out / name) as tmp:
            frame.to_csv(tmp, index=False, float_format="%.10g")
