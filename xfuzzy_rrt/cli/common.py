"""Small rendering helpers shared by the CLI modules (the only place that prints)."""

from __future__ import annotations

import json
import os
import signal
import sys
import tempfile
from pathlib import Path
from typing import Any

from xfuzzy_rrt.atomic import write_text_atomic
from xfuzzy_rrt.errors import InputError


def warn(message: str) -> None:
    sys.stderr.write(f"warning: {message}\n")


def check_seed_option(value: int) -> int:
    """Typer callback of every ``--seed`` option: one line naming ``--seed`` and the valid
    range (:func:`xfuzzy_rrt.planners.rng.check_seed`) instead of a numba traceback."""
    from xfuzzy_rrt.planners.rng import check_seed

    return check_seed(value)


#: Most worker processes any command starts. Why a cap: ``--workers 100000`` used to be taken
#: at its word and recorded in bench.json; more workers than this (or than 8 per core) only
#: adds start-up time and memory on any machine this runs on.
MAX_WORKERS = 256


def check_workers(value: int | None, option: str = "--workers") -> int | None:
    """``None`` (the command's default) or 1 .. min(256, 8 x cores); else one InputError."""
    if value is None:
        return None
    cores = os.cpu_count() or 1
    cap = min(MAX_WORKERS, 8 * cores)
    if value < 1:
        raise InputError(option, f"must be >= 1, got {value}")
    if value > cap:
        why = (f"the maximum is {MAX_WORKERS}" if cap == MAX_WORKERS
               else f"at most 8 per core ({cores} cores here)")
        raise InputError(option, f"{value} workers is too many: {why}, so at most {cap}")
    return value


def check_workers_option(value: int | None) -> int | None:
    """Typer callback of every ``--workers`` option (:func:`check_workers`)."""
    return check_workers(value)


def split_planners(text: str, option: str = "--planners") -> list[str]:
    """A comma list of planner labels; an empty entry (``rrt,,fuzzy-rrt``, a trailing comma)
    is refused rather than skipped, since it is usually a typo for a missing name."""
    names = [p.strip() for p in text.split(",")]
    if any(not n for n in names):
        raise InputError(option, f"empty planner name in {text!r} (remove the extra comma)")
    return names


def load_scenario_warn(path: Path):
    """Load a scenario (an unknown key is an error there, not a warning: see xfuzzy_rrt.strict)."""
    from xfuzzy_rrt.geometry.scenario import load_scenario

    return load_scenario(path)


def format_json(obj: dict[str, Any]) -> str:
    """One top-level key per line, values compact (a path stays one readable line per key)."""
    lines = [f"  {json.dumps(k)}: {json.dumps(v)}" for k, v in obj.items()]
    return "{\n" + ",\n".join(lines) + "\n}\n"


def emit_json(obj: dict[str, Any], out: Path | None) -> None:
    """Write JSON to ``out`` atomically, or to stdout."""
    text = format_json(obj)
    if out is None:
        sys.stdout.write(text)
    else:
        write_text_atomic(out, text)


def check_output_file(path: Path | None, option: str) -> None:
    """Fail before any work when ``path`` (an output file) cannot be written.

    Creates and removes a probe file in the nearest existing folder (permission bits say
    nothing to root, and a read-only mount only shows on writing), so the error names the
    user's path and comes before planning, not after.
    """
    if path is None:
        return
    path = Path(path)
    if path.is_dir():
        raise InputError(str(path), f"is a directory ({option} names a file)")
    anchor = Path(os.path.abspath(path.parent))
    while not anchor.exists() and anchor != anchor.parent:
        anchor = anchor.parent
    if not anchor.is_dir():
        raise InputError(str(path), f"cannot create it: {anchor} is not a directory")
    try:
        fd, probe = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".probe", dir=anchor)
    except OSError as exc:
        raise InputError(str(path), f"cannot write here: {exc.strerror or exc}") from None
    os.close(fd)
    os.unlink(probe)


#: Test hook: ``SIG@POINT`` (``INT@runs:3``, ``KILL@report``, ...) signals this process at a
#: named point of a command, so interruption tests hit a known moment instead of racing a
#: poll. Unset in normal use; see :func:`test_signal`.
TEST_SIGNAL_ENV = "XFUZZY_RRT_TEST_SIGNAL"


def test_signal(point: str) -> None:
    """If ``$XFUZZY_RRT_TEST_SIGNAL`` is ``SIG@point``, send SIG (``INT`` or ``KILL``) now.

    ``INT`` goes to the whole process group when this process leads one (as a terminal's
    Ctrl-C reaches the workers too), else to this process only.
    """
    spec = os.environ.get(TEST_SIGNAL_ENV)
    if not spec or spec.partition("@")[2] != point:
        return
    name = spec.partition("@")[0]
    if name == "KILL":
        os.kill(os.getpid(), signal.SIGKILL)
    elif name == "INT":
        if os.getpgrp() == os.getpid():
            os.killpg(os.getpgrp(), signal.SIGINT)
        else:
            os.kill(os.getpid(), signal.SIGINT)


def rulebook_arg(value):
    """Typer callback of every argument that names a rulebook to read: a shipped rulebook's name
    is taken where a directory is (:func:`xfuzzy_rrt.fuzzy.rulebook.rulebook_path`); ``None``
    and lists (repeatable options) pass through it element by element."""
    from xfuzzy_rrt.fuzzy.rulebook import rulebook_path

    if value is None:
        return None
    if isinstance(value, (list, tuple)):
        return [rulebook_path(v) for v in value]
    return rulebook_path(value)
