#!/usr/bin/env python3
"""Write ``goal-frame``'s knots and rules as a ``goal-frame-any`` rulebook: what the first
shipped ``rulebooks/goal-frame-any/`` was (until ``b08627d``), and what the trained one now
starts from (``train --bounds goal-frame-any --seed-rulebook rulebooks/goal-frame`` encodes
the same genome; rulebooks/README.md has the command).

Why this is a faithful starting point: ``goal-frame-any`` measures every joint-space length in
normalised degrees (Euclidean degrees divided by ``sqrt(N/2)``, ``N`` joints in all; see
:mod:`xfuzzy_rrt.fuzzy.semantics`), which are exactly goal-frame's degrees at two joints, and
its input and output ranges are goal-frame's 2-joint ranges (but for the step: goal-frame's
reaches 360 since the eighteenth session, goal-frame-any's stays at 120, and longer steps are
clipped; the provenance counts them). So the same knots and rule
constants make the same decisions at two joints and the *same per-joint* decisions at any
other number of joints: a step of 15 normalised degrees moves each of N joints about as far as
a 15-degree step moves each of two. Nothing here was trained for N > 2; the shipped
``goal-frame-any`` is, on a mixture of 3 to 7 joints and two arms.

Usage::

    python scripts/make_goal_frame_any_rulebook.py --out DIR [--source rulebooks/goal-frame]
        [--date YYYY-MM-DD]
"""

from __future__ import annotations

import argparse
import datetime as dt
import sys
from pathlib import Path

import numpy as np

from xfuzzy_rrt.fuzzy import semantics as sem
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, load_rulebook, rulebooks_dir, save_rulebook


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--source", default=str(rulebooks_dir() / "goal-frame"))
    # no default: the shipped rulebooks/goal-frame-any is trained now, not this copy
    p.add_argument("--out", required=True)
    p.add_argument("--date", default=dt.date.today().isoformat())
    args = p.parse_args(argv)
    src = load_rulebook(args.source)
    if src.semantics.name != "goal-frame" or src.dof != 2:
        print(f"error: {args.source}: need a 2-joint goal-frame rulebook, got "
              f"{src.semantics.name} at dof {src.dof}", file=sys.stderr)
        return 2
    knots, consts = src.arrays()
    # goal-frame's 2-joint steps reach 360 since the eighteenth session; goal-frame-any's stay
    # at the [0, 120] it was trained with, so longer steps are clipped (and counted)
    lo = np.array([sem.GOAL_FRAME_ANY.output_ranges[o][0] for o in sem.GOAL_FRAME_ANY.outputs])
    hi = np.array([sem.GOAL_FRAME_ANY.output_ranges[o][1] for o in sem.GOAL_FRAME_ANY.outputs])
    clipped = int(((consts < lo[:, None]) | (consts > hi[:, None])).sum())
    consts = np.clip(consts, lo[:, None], hi[:, None])
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
                              "Euclidean joint-space degrees / sqrt(N/2)"
                              + (f"; {clipped} rule constant(s) clipped to goal-frame-any's "
                                 "output ranges" if clipped else "")},
    )
    out = save_rulebook(rb, args.out)
    print(f"wrote {out} (sha256 {load_rulebook(out).sha256[:12]})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
