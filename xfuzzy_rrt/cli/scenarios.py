"""``xfuzzy-rrt scenarios generate``: fresh problems of the shared ``sample-*`` family."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

app = typer.Typer(help="Scenario files: generate problems of the sample-* family.",
                  no_args_is_help=True, add_completion=False, rich_markup_mode=None)


@app.command("generate")
def generate(
    count: int = typer.Option(..., "--count", min=1, max=10_000, help="How many problems."),
    seed: int = typer.Option(0, "--seed", min=0, help="Generator seed: same seed, same files."),
    out: Path = typer.Option(..., "--out", help="Folder to write <name>.toml files into."),
    prefix: Optional[str] = typer.Option(None, "--prefix", help="Name prefix: <prefix>-<seed>-<k> (default: gen for the sample family, else the family's name)."),
    family: str = typer.Option("sample", "--family", help="sample (the shared sample-* family), hard (cluttered, thin walls, narrow passages) or mira (MIRA-like arm threading a gap between organs)."),
) -> int:
    """Write COUNT valid, solvable, non-trivial scenarios (straight segment blocked)."""
    import re

    from xfuzzy_rrt.atomic import write_text_atomic
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.scenarios.generate import FAMILIES, generate_one

    if family not in FAMILIES:
        raise InputError("--family", f"must be one of {', '.join(FAMILIES)}, got {family!r}")
    if prefix is None:
        prefix = "gen" if family == "sample" else family
    if not re.fullmatch(r"[A-Za-z0-9_-]+", prefix):
        raise InputError("--prefix", f"must be letters, digits, '-' or '_', got {prefix!r}")
    if out.exists() and not out.is_dir():
        raise InputError(str(out), "exists and is not a directory")
    for k in range(count):
        problem = generate_one(seed, k, prefix, family)
        path = out / f"{problem.scenario.name}.toml"
        write_text_atomic(path, problem.text)
        grid = (f"grid-optimal {problem.grid_optimal_deg:.1f} deg"
                if problem.grid_optimal_deg < float("inf") else "no path on the 2 deg grid")
        typer.echo(f"{path}: {grid}, straight "
                   f"{problem.straight_deg:.1f} deg, C-obstacle fraction "
                   f"{problem.c_obstacle_fraction:.3f}")
    return 0
