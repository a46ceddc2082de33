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
