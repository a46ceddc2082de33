"""What a benchmark needs to be reproduced elsewhere: versions, git commit, machine, hashes.

Why collected at bench time and stored in ``bench.json``: a report rebuilt later (``xfuzzy-rrt
report DIR``) must state where the numbers came from, not where the report was rebuilt. Every
probe degrades to ``None`` instead of failing (no git, not a checkout, a missing module), because
missing provenance must never cost a benchmark.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import os
import platform
import subprocess
from pathlib import Path
from typing import Any


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


def git_state() -> dict[str, Any]:
    """Commit of the checkout the package runs from, and whether tracked files differ from it."""
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
    for dist in ("numpy", "numba", "pandas", "plotly", "ompl"):
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
