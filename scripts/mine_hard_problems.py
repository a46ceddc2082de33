"""Copy the generated problems on which the default does more work than the tuned RRT.

Why: the work-cvar fitness weighs the worst quarter of the training problems, but a mixture
drawn from the generator holds few problems of the kind the default loses on (in the
thirteenth session's measurements: 3-joint problems where its search is no shorter, 5- and
7-joint ones where one tree sits in a cramped corner and rejects nearly every extension). A
fourth round of training on the generator's mixture alone did not move the rulebook; this
script mines fresh generated problems (never the evaluation's) for those cases, so that a
training round sees them. It is part of how the shipped ``goal-frame-any`` was made
(``rulebooks/README.md``)::

    python scripts/mine_hard_problems.py OUT DIR [DIR ...] [--rulebook DIR] [--seeds 5]

For every ``*.toml`` in each DIR (sorted by name) the default (``fuzzy-rrt`` with its shipped
rulebooks as loaded now; with ``--rulebook``, ``fuzzy-rrt-connect`` with that ``goal-frame-any``
rulebook -- the same planner on problems that are not one 2-joint arm, so a later session can mine
with the rulebook a training round started from) and ``rrt:tuned`` plan seeds ``0 .. --seeds - 1``
with the training budget ``--max-iter``; a failed run of the default counts three times its work. A
problem whose tuned RRT's median work over the default's is below ``--below`` (1.0) is copied to
``OUT/<DIR's name>/``. Prints every problem's ratio and the count; deterministic (work counts, not
times). The work is the search's (``PlanResult.work``), not end to end (``evaluate``'s
``work_total`` adds the path's certification): it is what the training's work-cvar fitness compares
(``training/evaluate.py``), and the problems are mined for that fitness.
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import sys
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("dirs", nargs="+", type=Path)
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--max-iter", type=int, default=3000)
    parser.add_argument("--below", type=float, default=1.0)
    parser.add_argument("--rulebook", type=Path, default=None)
    args = parser.parse_args(argv)

    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.training.run import expand_scenarios
    from xfuzzy_rrt.planners.api import load_shipped_default, load_tuned_rrt, plan_scenario

    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    if args.rulebook is None:
        planner, default = "fuzzy-rrt", load_shipped_default()
    else:
        planner, default = "fuzzy-rrt-connect", load_rulebook(args.rulebook)
    tuned = load_tuned_rrt()
    kept = total = 0
    for folder in args.dirs:
        if not folder.is_dir():
            print(f"{folder}: not a folder", file=sys.stderr)
            return 2
        try:  # the training command's reading of a folder (one line for a bad one)
            files = expand_scenarios([folder])
        except InputError as err:
            print(err, file=sys.stderr)
            return 2
        for path in files:
            scenario = load_scenario(path)
            ours, theirs = [], []
            for seed in range(args.seeds):
                a = plan_scenario(scenario, planner, rulebook=default, seed=seed,
                                  max_iter=args.max_iter)
                b = plan_scenario(scenario, "rrt:tuned", rulebook=tuned, seed=seed,
                                  max_iter=args.max_iter)
                ours.append(a.work if a.success else 3 * a.work)
                theirs.append(b.work)
            ratio = statistics.median(theirs) / statistics.median(ours)
            total += 1
            print(f"{folder.name}/{path.name} {ratio:.3f}", flush=True)
            if ratio < args.below:
                kept += 1
                dest = args.out / folder.name
                dest.mkdir(parents=True, exist_ok=True)
                shutil.copy(path, dest / path.name)
    print(f"{kept} of {total} problems with a work ratio below {args.below} -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
