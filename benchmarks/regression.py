"""Kernel (or whole-call) time now against a pinned earlier commit, in one run, as a ratio.

Why: golden files pin results, nothing pinned speed, and the N-DOF core change made 2-DOF
kernels 1.4-2.1x slower unnoticed (issue 24). Timing two versions in two sessions compares two
machine loads; this script times both in the same session, interleaved call by call, on the
same problems and seeds, so load changes hit both alike.

How: the old commit is checked out in a temporary worktree (``git worktree add``) and each
version runs in its own worker processes (``PYTHONPATH`` = its tree, its own shipped rulebooks);
each worker prints where it imported ``xfuzzy_rrt`` from, and the script refuses to go on if
that is not the tree it asked for.

**Processes differ.** Two worker processes of the *same* tree, interleaved call by call, timed
30 us calls 0.67x and 1.25x apart on this machine (2026-12-04; the same calls in one process
vary by a few per cent): which process was started first, where its memory and code landed.
One pair of workers therefore measures its two processes as much as the two versions. The
factor is the process's, not the code's (both planners of one pair moved alike), and a
pure-Python loop run before every call sees it: each time is divided by that reference time
(``--raw``: not), which took the same control from 0.63-1.47x per pair to 1.01-1.11x. And the
seeds are shared out over ``--pairs`` fresh pairs of workers (seed ``k`` to pair
``k % pairs``), started old-first and new-first by turns; the per-problem medians pool every
pair, and the geometric mean of each pair is printed too: their spread is the noise a
difference must clear. The measure is the planner's own kernel timer
(``PlanResult.wall_s``), or with ``--measure call`` the whole ``plan_scenario`` call (what a
user waits for); both versions must need the same iterations (same seeds, same results), else
the line is flagged. Printed: per planner and problem the median kernel time of
both and their ratio, the ratio of their deterministic work counts (``PlanResult.work``, summed
over the seeds; ``-`` when a version does not count), then the geometric mean of the time
ratios per planner.

    nice python benchmarks/regression.py                       # 8782882, paper-reference + 12
    nice python benchmarks/regression.py --problems /tmp/eval9100 --count 24 --seeds 10
    python benchmarks/regression.py --commit HEAD~1 --problems /tmp/dof5 --planners fuzzy-rrt
    nice python benchmarks/regression.py --commit HEAD --measure call --seeds 16 --pairs 8
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BASELINE = "8782882"
PLANNERS = ("rrt", "fuzzy-rrt")

WORKER = r"""
import json, sys, time
import xfuzzy_rrt
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario
print(json.dumps({"file": xfuzzy_rrt.__file__}), flush=True)
cache = {}
for line in sys.stdin:
    job = json.loads(line)
    s = cache.get(job["scenario"]) or cache.setdefault(job["scenario"], load_scenario(job["scenario"]))
    walls = []
    refs = []
    for _ in range(job["repeat"]):
        t0 = time.perf_counter()  # the process's own speed: the same pure-Python work in both
        sum(i * i for i in range(300))
        refs.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        r = plan_scenario(s, job["planner"], seed=job["seed"])
        call = time.perf_counter() - t0
        walls.append(call if job["measure"] == "call" else r.wall_s)
    print(json.dumps({"wall": min(walls), "ref": min(refs), "iterations": r.iterations,
                      "success": bool(r.success), "work": getattr(r, "work", None)}),
          flush=True)
"""


class Worker:
    def __init__(self, tree: Path):
        env = dict(os.environ, PYTHONPATH=str(tree),
                   XFUZZY_RRT_RULEBOOKS=str(tree / "rulebooks"))
        self.proc = subprocess.Popen([sys.executable, "-c", WORKER], cwd=str(tree), env=env,
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        hello = json.loads(self.proc.stdout.readline())
        where = Path(hello["file"]).resolve()
        if not where.is_relative_to(tree.resolve()):
            raise SystemExit(f"error: the worker for {tree} imported xfuzzy_rrt from {where}")
        self.tree = tree

    def run(self, scenario: Path, planner: str, seed: int, repeat: int,
            measure: str = "kernel") -> dict:
        self.proc.stdin.write(json.dumps({"scenario": str(scenario), "planner": planner,
                                          "seed": seed, "repeat": repeat,
                                          "measure": measure}) + "\n")
        self.proc.stdin.flush()
        return json.loads(self.proc.stdout.readline())

    def close(self):
        self.proc.stdin.close()
        self.proc.wait()


def old_tree(commit: str) -> Path:
    """A worktree of ``commit`` under /tmp, named by its hash (a name such as ``HEAD`` moves, so
    a checkout made under it earlier would be a stale one), made when missing."""
    full = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--verify",
                           f"{commit}^{{commit}}"],
                          check=True, capture_output=True, text=True).stdout.strip()
    path = Path(f"/tmp/old{full[:12]}")
    if not (path / "xfuzzy_rrt").is_dir():
        subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(path), full],
                       check=True, stdout=subprocess.DEVNULL)
    head = subprocess.run(["git", "-C", str(path), "rev-parse", "HEAD"], check=True,
                          capture_output=True, text=True).stdout.strip()
    if head != full:
        raise SystemExit(f"error: {path} holds {head[:12]}, not {commit} ({full[:12]})")
    return path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--commit", default=BASELINE)
    ap.add_argument("--problems", type=Path, default=Path("/tmp/eval9100"),
                    help="folder of scenario files (any arms) (paper-reference is always added)")
    ap.add_argument("--count", type=int, default=12, help="problems taken from --problems")
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--repeat", type=int, default=3, help="runs per call; the minimum counts")
    ap.add_argument("--planners", default=",".join(PLANNERS))
    ap.add_argument("--raw", action="store_true",
                    help="do not divide each time by the worker's reference loop time")
    ap.add_argument("--pairs", type=int, default=4,
                    help="fresh pairs of worker processes the seeds are shared out over")
    ap.add_argument("--measure", choices=("kernel", "call"), default="kernel",
                    help="kernel: the planner's own timer (wall_s); call: the whole "
                         "plan_scenario call, what a user waits for")
    args = ap.parse_args(argv)
    problems = [REPO / "xfuzzy_rrt" / "data" / "reference" / "paper-reference.toml"]
    if args.problems.is_dir():
        problems += sorted(args.problems.glob("*.toml"))[:args.count]
    if args.pairs < 1:
        raise SystemExit("error: --pairs must be >= 1")

    def timed(run: dict) -> float:
        return run["wall"] if args.raw else run["wall"] / run["ref"]

    old_path = old_tree(args.commit)
    print(f"old: {old_path} ({args.commit}); new: {REPO}; {args.pairs} pairs of workers")
    planners = args.planners.split(",")
    rows = {}
    by_pair = {}
    for k in range(args.pairs):
        seeds = range(k, args.seeds, args.pairs)
        if not seeds:
            continue
        if k % 2 == 0:  # started old-first and new-first by turns
            old = Worker(old_path)
            new = Worker(REPO)
        else:
            new = Worker(REPO)
            old = Worker(old_path)
        try:
            for p in planners:  # warm-up: compile or load both versions' kernels
                for w in (old, new):
                    w.run(problems[0], p, 0, 1)
            for i, seed in enumerate(seeds):
                for sc in problems:
                    for p in planners:
                        pair = (old, new) if i % 2 == 0 else (new, old)
                        got = {id(w): w.run(sc, p, seed, args.repeat, args.measure)
                               for w in pair}
                        both = (got[id(old)], got[id(new)])
                        rows.setdefault((p, sc.stem), []).append(both)
                        by_pair.setdefault((k, p), []).append(
                            math.log(timed(both[1]) / timed(both[0])))
        finally:
            old.close()
            new.close()
    print(f"{'planner':<10} {'problem':<24} {'old ms':>8} {'new ms':>8} {'new/old':>8} "
          f"{'work new/old':>12}  iterations   (new/old: of times divided by the reference "
          f"loop's{', not here' if args.raw else ''})")
    logs = {p: [] for p in planners}
    for (p, name), pairs in rows.items():
        o = statistics.median(a["wall"] for a, _ in pairs) * 1e3
        n = statistics.median(b["wall"] for _, b in pairs) * 1e3
        ratio = (statistics.median(timed(b) for _, b in pairs)
                 / statistics.median(timed(a) for a, _ in pairs))
        same = all(a["iterations"] == b["iterations"] for a, b in pairs)
        logs[p].append(math.log(ratio))
        works = [(a["work"], b["work"]) for a, b in pairs if a["work"] and b["work"]]
        work = (f"{sum(b for _, b in works) / sum(a for a, _ in works):>12.3f}" if works
                else f"{'-':>12}")
        print(f"{p:<10} {name:<24} {o:>8.3f} {n:>8.3f} {ratio:>8.2f} {work}  "
              f"{'same' if same else 'DIFFERENT'}")
    for p in planners:
        pairs = " ".join(f"{math.exp(statistics.fmean(v)):.2f}"
                         for (_, q), v in sorted(by_pair.items()) if q == p)
        print(f"{p}: geometric mean new/old = {math.exp(statistics.fmean(logs[p])):.2f} "
              f"over {len(logs[p])} problems x {args.seeds} seeds (per pair of workers, "
              f"call by call: {pairs})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
