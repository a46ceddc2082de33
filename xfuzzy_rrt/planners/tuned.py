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

import os
import stat
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
    record = tuned_record(label)
    return None if record is None else dict(record["params"])


def tuned_record(label: str) -> dict | None:
    """The whole parsed tuned file of ``label`` (params, objective, provenance, table).

    Looked up on every plan of a tuned planner (``rrt:tuned`` twice: when its label is parsed
    and when it plans), so it costs one ``os.stat`` of a remembered path string: the parse is
    cached on the file's identity (size, ``mtime_ns``, ``ctime_ns``, inode; a same-size edit
    that restores the mtime still changes the ctime). It was ~30 us of pathlib a call, a fifth
    of ``rrt:tuned``'s whole overhead.
    """
    path = _path_str(tuned_dir(), label)
    try:
        st = os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        return None
    if not stat.S_ISREG(st.st_mode):
        return None
    return _read(path, (st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino))


@lru_cache(maxsize=64)
def _path_str(folder: Path, label: str) -> str:
    return str(folder / tuned_file_name(label))


@lru_cache(maxsize=16)
def _read(path: str, identity: tuple) -> dict:
    """Parsed and checked (cached per file identity, :func:`tuned_record`)."""
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
