#!/usr/bin/env python3
"""Generate ``rulebooks/goal-frame-any/``: the first rulebook of the DOF-free ``goal-frame-any``
semantics, carried over from the shipped (trained, 2-joint) ``goal-frame`` rulebook.

Why this is a faithful starting point: ``goal-frame-any`` measures every joint-space length in
normalised degrees (Euclidean degrees divided by ``sqrt(N/2)``, ``N`` joints in all; see
:mod:`xfuzzy_rrt.fuzzy.semantics`), which are exactly goal-frame's degrees at two joints, and
its input and output ranges are goal-frame's 2-joint ranges. So the same knots and rule
constants make the same decisions at two joints and the *same per-joint* decisions at any
other number of joints: a step of 15 normalised degrees moves each of N joints about as far as
a 15-degree step moves each of two. Nothing here was trained for N > 2 (training a
goal-frame-any rulebook on a mixture of arms is the next step, see issue 25).

Usage::

    python scripts/make_goal_frame_any_rulebook.py [--source rulebooks/goal-frame]
        [--out rulebooks/goal-frame-any] [--date YYYY-MM-DD]
"""

from __future__ import annotations

import argparse
import datetime as dt
import sys
from pathlib import Path

from xfuzzy_rrt.fuzzy import semantics as sem
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, load_rulebook, rulebooks_dir, save_rulebook


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--source", default=str(rulebooks_dir() / "goal-frame"))
    p.add_argument("--out", default=str(rulebooks_dir() / "goal-frame-any"))
    p.add_argument("--date", default=dt.date.today().isoformat())
    args = p.parse_args(argv)
    src = load_rulebook(args.source)
    if src.semantics.name != "goal-frame" or src.dof != 2:
        print(f"error: {args.source}: need a 2-joint goal-frame rulebook, got "
              f"{src.semantics.name} at dof {src.dof}", file=sys.stderr)
        return 2
    knots, consts = src.arrays()
    command = "python scripts/make_goal_frame_any_rulebook.py" + "".join(
        f" {a}" for a in (argv if argv is not None else sys.argv[1:]))
    rb = Rulebook.from_arrays(
        knots, consts, name=Path(args.out).name, bounds_mode=None,
        semantics=sem.GOAL_FRAME_ANY,
        description=(f"The {src.name!r} rulebook read in normalised degrees: the same decisions "
                     "at 2 joints, the same per-joint decisions at any number of joints "
                     "(not trained beyond 2 joints); see [provenance]."),
        provenance={"kind": "derived", "command": command, "date": args.date,
                    "source": src.name, "source_sha256": src.sha256,
                    "method": "knots and rule constants copied; lengths reinterpreted as "
                              "Euclidean joint-space degrees / sqrt(N/2)"},
    )
    out = save_rulebook(rb, args.out)
    print(f"wrote {out} (sha256 {load_rulebook(out).sha256[:12]})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
