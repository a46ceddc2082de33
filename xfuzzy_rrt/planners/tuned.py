"""Tuned parameters of the peer planners, read from the files shipped in ``data/tuned/``.

Why: a planner compared at the paper's settings (RRT at 10°) is a handicapped baseline. The
project compares its rulebooks against peers *at their best*: ``xfuzzy-rrt tune`` searches a
planner's parameters on training problems only (:mod:`xfuzzy_rrt.bench.tuning`) and writes one
small TOML file per planner with the chosen values, the whole objective table and the command
that made it. This module only reads those files, so planning never depends on the tuner.

File names: the planner label with ``:`` turned into ``-`` (``rrt`` -> ``rrt.toml``,
``ompl:RRTConnect`` -> ``ompl-RRTConnect.toml``).
"""

from __future__ import annotations

import tomllib
from functools import lru_cache
from pathlib import Path

from xfuzzy_rrt.errors import InputError


@lru_cache(maxsize=1)
def tuned_dir() -> Path:
    """The folder of the shipped tuned-parameter files (package data; resolved once: it is
    looked up on every plan of a tuned planner)."""
    return Path(__file__).resolve().parent.parent / "data" / "tuned"


def tuned_file_name(label: str) -> str:
    """``rrt`` -> ``rrt.toml``; ``ompl:RRTConnect`` -> ``ompl-RRTConnect.toml``."""
    return label.replace(":", "-") + ".toml"


def tuned_path(label: str) -> Path:
    return tuned_dir() / tuned_file_name(label)


def tuned_params(label: str) -> dict[str, float] | None:
    """The tuned parameters of planner ``label`` (e.g. ``{"step_deg": 60.0, "goal_bias":
    0.1}`` for ``rrt``, ``{"range_deg": ...}`` for ``ompl:RRTConnect``), or ``None`` when no
    tuned file ships for it. A file that exists but cannot be read is an :class:`InputError`
    naming it (a broken shipped file must not silently fall back to untuned settings)."""
    path = tuned_path(label)
    if not path.is_file():
        return None
    return dict(_read(str(path), path.stat().st_mtime_ns)["params"])


def tuned_record(label: str) -> dict | None:
    """The whole parsed tuned file of ``label`` (params, objective, provenance, table)."""
    path = tuned_path(label)
    return _read(str(path), path.stat().st_mtime_ns) if path.is_file() else None


@lru_cache(maxsize=16)
def _read(path: str, mtime_ns: int) -> dict:
    """Parsed and checked (cached per modification time)."""
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise InputError(path, f"cannot read tuned parameters: {exc}") from None
    params = data.get("params")
    if not isinstance(params, dict) or not params:
        raise InputError(path, "no [params] table of tuned parameters")
    for key, value in params.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(path, f"[params] {key} must be a number, got {value!r}")
    data["params"] = {k: float(v) for k, v in params.items()}
    return data
