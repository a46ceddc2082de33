"""``xfuzzy-rrt scenarios generate``: fresh problems of the shared ``sample-*`` family and of
the N-DOF (``--dof N``) and multi-arm (``--arms K``) family."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from xfuzzy_rrt.cli.common import check_seed_option

app = typer.Typer(help="Scenario files: generate problems of the sample-* family (or hard, mira, trap), N-DOF arms or several arms.",
                  no_args_is_help=True, add_completion=False, rich_markup_mode=None)


@app.command("generate")
def generate(
    count: int = typer.Option(..., "--count", min=1, max=10_000, help="How many problems."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, min=0, help="Generator seed: same seed, same files."),
    out: Path = typer.Option(..., "--out", help="Folder to write <name>.toml files into."),
    prefix: Optional[str] = typer.Option(None, "--prefix", help="Name prefix: <prefix>-<seed>-<k> (default: gen for the sample family, else the family's name)."),
    family: Optional[str] = typer.Option(None, "--family", help="2-DOF single-arm families: sample (the shared sample-* family; the default), hard (cluttered, thin walls, narrow passages), mira (MIRA-like arm threading a gap between organs) or trap (a large organ or wall across the way: shortest path at least 1.5x the straight one)."),
    dof: int = typer.Option(2, "--dof", help="Joints per arm, 2 to 7 (default 2). Other than 2 selects the N-DOF family (see docs/scenarios.md)."),
    arms: int = typer.Option(1, "--arms", help="Arms sharing the workspace, 1 to 4 (default 1). More than 1 writes [[arms]] files whose arms can touch each other."),
) -> int:
    """Write COUNT valid, solvable, non-trivial scenarios (straight segment blocked)."""
    import re

    from xfuzzy_rrt.atomic import write_text_atomic
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.scenarios.generate import (FAMILIES, MAX_ARMS, MAX_DOF, MIN_ARMS, MIN_DOF,
                                               generate_one, nd_prefix)

    if not MIN_DOF <= dof <= MAX_DOF:
        raise InputError("--dof", f"must be {MIN_DOF} to {MAX_DOF} joints per arm, got {dof}")
    if not MIN_ARMS <= arms <= MAX_ARMS:
        raise InputError("--arms", f"must be {MIN_ARMS} to {MAX_ARMS}, got {arms}")
    nd = dof != 2 or arms != 1
    if nd and family is not None:
        raise InputError("--family", f"applies to one 2-DOF arm; --dof {dof} --arms {arms} has "
                         f"its own family (leave --family out)")
    family = "sample" if family is None else family
    if family not in FAMILIES:
        raise InputError("--family", f"must be one of {', '.join(FAMILIES)}, got {family!r}")
    if prefix is None:
        prefix = nd_prefix(dof, arms) if nd else ("gen" if family == "sample" else family)
    if not re.fullmatch(r"[A-Za-z0-9_-]+", prefix):
        raise InputError("--prefix", f"must be letters, digits, '-' or '_', got {prefix!r}")
    if out.exists() and not out.is_dir():
        raise InputError(str(out), "exists and is not a directory")
    # every problem first, then the files: a seed that has no problem k (NoProblemFound, one
    # line and exit 2) leaves no part of the set behind. An N-DOF problem can take seconds to
    # minutes (each draft is proved solvable by RRT), so those say on stderr how far they are.
    problems = []
    for k in range(count):
        problems.append(generate_one(seed, k, prefix, family, dof=dof, arms=arms))
        if nd:
            typer.echo(f"drafted {k + 1} of {count}: {problems[-1].scenario.name}", err=True)
    for problem in problems:
        path = out / f"{problem.scenario.name}.toml"
        write_text_atomic(path, problem.text)
        if nd:
            typer.echo(f"{path}: {problem.scenario.dof} joints in all, straight "
                       f"{problem.straight_deg:.1f} deg, rrt solved it in "
                       f"{problem.solved_iterations} iterations (seed {problem.solved_seed})")
            continue
        grid = (f"grid-optimal {problem.grid_optimal_deg:.1f} deg"
                if problem.grid_optimal_deg < float("inf") else "no path on the 2 deg grid")
        typer.echo(f"{path}: {grid}, straight "
                   f"{problem.straight_deg:.1f} deg, C-obstacle fraction "
                   f"{problem.c_obstacle_fraction:.3f}")
    return 0
