"""``xfuzzy-rrt scenarios generate``: fresh problems of the shared ``sample-*`` family."""

from __future__ import annotations

from pathlib import Path

import typer

app = typer.Typer(help="Scenario files: generate problems of the sample-* family.",
                  no_args_is_help=True, add_completion=False, rich_markup_mode=None)


@app.command("generate")
def generate(
    count: int = typer.Option(..., "--count", min=1, max=10_000, help="How many problems."),
    seed: int = typer.Option(0, "--seed", min=0, help="Generator seed: same seed, same files."),
    out: Path = typer.Option(..., "--out", help="Folder to write <name>.toml files into."),
    prefix: str = typer.Option("gen", "--prefix", help="Name prefix: <prefix>-<seed>-<k>."),
) -> int:
    """Write COUNT valid, solvable, non-trivial scenarios (straight segment blocked)."""
    import re

    from xfuzzy_rrt.atomic import write_text_atomic
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.scenarios.generate import generate_one

    if not re.fullmatch(r"[A-Za-z0-9_-]+", prefix):
        raise InputError("--prefix", f"must be letters, digits, '-' or '_', got {prefix!r}")
    if out.exists() and not out.is_dir():
        raise InputError(str(out), "exists and is not a directory")
    for k in range(count):
        problem = generate_one(seed, k, prefix)
        path = out / f"{problem.scenario.name}.toml"
        write_text_atomic(path, problem.text)
        typer.echo(f"{path}: grid-optimal {problem.grid_optimal_deg:.1f} deg, straight "
                   f"{problem.straight_deg:.1f} deg, C-obstacle fraction "
                   f"{problem.c_obstacle_fraction:.3f}")
    return 0
