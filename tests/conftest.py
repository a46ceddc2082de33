"""Shared test fixtures: locations of fixtures and a runner for the real console script."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
FIXTURES = TESTS / "fixtures"
PROJECT = TESTS.parent
SHARED_SCENARIOS = PROJECT.parent / "shared" / "scenarios"


def console_script() -> str:
    """The installed ``xfuzzy-rrt`` entry point of the interpreter running the tests."""
    candidate = Path(sys.executable).parent / "xfuzzy-rrt"
    if not candidate.exists():
        raise RuntimeError(f"console script not installed next to {sys.executable}")
    return str(candidate)


@pytest.fixture
def run_cli():
    """Run ``xfuzzy-rrt ARGS...`` as a subprocess; return the CompletedProcess (text mode)."""

    def _run(*args: str, cwd: str | os.PathLike[str] | None = None, timeout: float = 300):
        return subprocess.run(
            [console_script(), *map(str, args)],
            capture_output=True,
            text=True,
            cwd=cwd,
            timeout=timeout,
        )

    return _run


def shared_scenarios() -> list[Path]:
    """The shared scenario files when ``../shared/scenarios`` is present, else empty."""
    if not SHARED_SCENARIOS.is_dir():
        return []
    return sorted(SHARED_SCENARIOS.glob("*.toml"))


THIN_BOX_TOML = """
name = "thin-box"
description = "a thin box lying across the sweep of a straight arm, between coarse motion samples"
[arm]
links = [0.18, 0.12]
link_radius = 0.005
joint_limits_deg = [[-180.0, 180.0], [-180.0, 180.0]]
[start]
q_deg = [-60.0, 0.0]
[goal]
q_deg = [60.0, 0.0]
[[obstacles]]
type = "box"
min = [0.2, {ylo}]
max = [0.28, {yhi}]
"""


def thin_box(tmp_path: Path, ylo: float = -0.002, yhi: float = 0.002) -> Path:
    """Write the thin-box scenario (a grazing case for sampled motion checks); return its path."""
    path = tmp_path / "thin-box.toml"
    path.write_text(THIN_BOX_TOML.format(ylo=ylo, yhi=yhi))
    return path
