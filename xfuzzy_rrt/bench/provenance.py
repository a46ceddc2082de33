"""What a benchmark needs to be reproduced elsewhere: versions, git commit, machine, hashes.

Why collected at bench time and stored in ``bench.json``: a report rebuilt later (``xfuzzy-rrt
report DIR``) must state where the numbers came from, not where the report was rebuilt. Every
probe degrades to ``None`` instead of failing (no git, not a checkout, a missing module), because
missing provenance must never cost a benchmark.

Reading a ``bench.json`` back is strict (:func:`check_bench_json`): a key this version does not
write is an error naming its line and the nearest known key, never silently ignored.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import os
import platform
import subprocess
from pathlib import Path
from typing import Any

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.strict import json_key_line, unknown_key_message

#: Libraries whose versions the numbers (and the byte-exact training claim) depend on.
VERSION_DISTS = ("numpy", "numba", "scipy", "pymoo", "pandas", "plotly", "ompl")


def sha256_file(path: str | os.PathLike[str]) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _git(*args: str) -> str | None:
    root = Path(__file__).resolve().parents[2]
    try:
        out = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True,
                             timeout=5)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() if out.returncode == 0 else None


def _running_from_checkout() -> bool:
    """Whether this package is the source folder of a git checkout (an editable install).

    An installed wheel sits in ``site-packages``, which may itself lie inside some unrelated
    repository (a virtualenv in a project folder): its commit says nothing about this code.
    """
    root = Path(__file__).resolve().parents[2]
    if not (root / "pyproject.toml").is_file():
        return False
    top = _git("rev-parse", "--show-toplevel")
    return top is not None and Path(top).resolve() == root


def git_state() -> dict[str, Any]:
    """Commit of the checkout the package runs from, and whether tracked files differ from it.

    ``None`` for both when the package is not running from a checkout (an installed wheel).
    """
    if not _running_from_checkout():
        return {"commit": None, "dirty": None}
    commit = _git("rev-parse", "HEAD")
    if not commit:
        return {"commit": None, "dirty": None}
    status = _git("status", "--porcelain", "--untracked-files=no")
    return {"commit": commit, "dirty": bool(status) if status is not None else None}


def versions() -> dict[str, str | None]:
    """Versions of the package and of the libraries whose behaviour the numbers depend on."""
    from importlib import metadata

    from xfuzzy_rrt import __version__

    out: dict[str, str | None] = {"xfuzzy-rrt": __version__,
                                  "python": platform.python_version()}
    for dist in VERSION_DISTS:
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = None
    return out


def machine() -> dict[str, Any]:
    return {"hostname": platform.node(), "system": platform.platform(),
            "machine": platform.machine(), "cpus": os.cpu_count()}


def collect(command: str) -> dict[str, Any]:
    """The provenance block of ``bench.json``."""
    return {"command": command,
            "date": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC"),
            "versions": versions(), "git": git_state(), "machine": machine()}


# ------------------------------------------------------------------------------ reading back

#: Every key ``bench.json`` may hold, level by level (what bench/store.py and :func:`collect`
#: write). ``None`` marks a list whose items are checked with the named entry.
BENCH_JSON_KEYS: dict[str, tuple[str, ...]] = {
    "": ("format", "format_version", "command", "date", "versions", "git", "machine",
         "settings", "scenarios", "rulebook", "rulebooks"),
    "versions": ("xfuzzy-rrt", "python", *VERSION_DISTS),
    "git": ("commit", "dirty"),
    "machine": ("hostname", "system", "machine", "cpus"),
    "settings": ("runs", "seed", "max_iter", "planners", "shortcut", "workers", "rulebook",
                 "rulebook_dir", "rulebook_sha256", "rulebooks", "tuned"),
    "scenarios": ("name", "file", "sha256", "toml"),
    "rulebook": ("name", "dir", "sha256", "history"),
    "rulebooks": ("planner", "name", "dir", "sha256", "history"),
}


def check_bench_json(meta: dict[str, Any], path: str | os.PathLike[str]) -> None:
    """Refuse a ``bench.json`` holding a key this version does not write.

    Raises :class:`InputError` ``FILE:LINE: unknown key 'K' in SECTION (did you mean 'X'?)``.
    """
    text = None

    def refuse(key: str, known: tuple[str, ...], section: str) -> None:
        nonlocal text
        if text is None:
            try:
                text = Path(path).read_text(encoding="utf-8")
            except (OSError, UnicodeDecodeError):
                text = ""
        line = json_key_line(text, key)
        where = f"{path}:{line}" if line is not None else str(path)
        raise InputError(where, unknown_key_message(key, known, section))

    def check(obj: Any, section: str) -> None:
        known = BENCH_JSON_KEYS[section]
        for key in obj:
            if key not in known:
                refuse(key, known, section or "bench.json")

    check(meta, "")
    for section in ("versions", "git", "machine", "settings", "rulebook"):
        if isinstance(meta.get(section), dict):
            check(meta[section], section)
    for entry in meta.get("scenarios") or []:
        if isinstance(entry, dict):
            check(entry, "scenarios")
    for entry in meta.get("rulebooks") or []:
        if isinstance(entry, dict):
            check(entry, "rulebooks")
