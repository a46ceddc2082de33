"""The state of the CPU caches a timed call starts from: what the fair protocol controls.

Why this matters: a short plan takes 20-200 us when repeated, and a call whose code and data
are out of the caches takes several times as long (docs/peer-measurements.md, twelfth
session: 164 against 26 us at 2 joints). A protocol that calls several planners in turn leaves
each call with whatever the previous calls left, so a planner that shares its compiled kernel
with another one in the run (``rrt:tuned`` and the paper's ``rrt`` are one kernel) starts warm
whenever its sibling ran before it, and a planner with no sibling never does. Measured in the
eleventh session's runs: ``rrt:tuned`` right after ``rrt`` took 0.69-0.82x its time after any
other planner on 2- and 3-joint problems, the default planner 0.85-1.02x. So the protocol names
the state every timed call starts from (:data:`CACHE_MODES`), and no neighbour decides it:

- ``cold``: a buffer larger than the last-level cache is written before every timed call, so
  every call starts with its code and data evicted (a user who plans once in a while, between
  other work);
- ``warm``: each planner runs its seeds of a problem in a row, in blocks of ten (the planners'
  blocks interleaved, so a disturbance of the machine never slows all of one planner's seeds),
  each block after three untimed calls (a user who plans in a loop);
- ``shuffled``: the order of the tenth and eleventh sessions (planners shuffled per seed, no
  eviction), kept to compare with the figures measured that way.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

CACHE_MODES = ("cold", "warm", "shuffled")
DEFAULT_CACHE_MODE = "cold"

#: Used when the operating system does not say how large the last-level cache is.
FALLBACK_LLC_BYTES = 32 * 2**20

#: The eviction buffer is this many times the last-level cache (a streamed write of exactly
#: its size leaves some lines of a non-LRU cache in place).
EVICT_FACTOR = 1.5

#: ...but never more than this (a machine that reports a very large cache would otherwise get
#: a buffer of gigabytes and seconds of writing per call).
MAX_EVICT_BYTES = 512 * 2**20


def last_level_cache_bytes(root: Path = Path("/sys/devices/system/cpu/cpu0/cache")) -> int:
    """Size in bytes of the largest data or unified cache the OS lists for CPU 0 (Linux
    sysfs), else :data:`FALLBACK_LLC_BYTES`."""
    best = 0
    for index in sorted(root.glob("index*")) if root.is_dir() else []:
        try:
            kind = (index / "type").read_text().strip()
            size = (index / "size").read_text().strip().upper()
        except OSError:
            continue
        if kind == "Instruction" or not size:
            continue
        unit = {"K": 2**10, "M": 2**20, "G": 2**30}.get(size[-1], 1)
        digits = size[:-1] if size[-1] in "KMG" else size
        if digits.isdigit():
            best = max(best, int(digits) * unit)
    return best or FALLBACK_LLC_BYTES


def evict_bytes(llc_bytes: int) -> int:
    """How many bytes an eviction writes on a machine whose last-level cache has
    *llc_bytes*."""
    return min(int(EVICT_FACTOR * llc_bytes), MAX_EVICT_BYTES)


class CacheEvictor:
    """Writes a buffer of :data:`EVICT_FACTOR` times the last-level cache (at most
    :data:`MAX_EVICT_BYTES`) on each call (~2 ms for 48 MB), pushing every earlier call's code
    and data out of all cache levels."""

    def __init__(self, llc_bytes: int | None = None):
        size = evict_bytes(llc_bytes or last_level_cache_bytes())
        self.buffer = np.zeros(max(size // 8, 1))
        self.bytes = self.buffer.nbytes

    def __call__(self) -> None:
        self.buffer += 1.0


def check_cache_mode(mode: str) -> str:
    """*mode* if it is one of :data:`CACHE_MODES`, else an :class:`InputError` naming
    ``--caches``."""
    from xfuzzy_rrt.errors import InputError

    if mode not in CACHE_MODES:
        raise InputError("--caches", f"must be one of {', '.join(CACHE_MODES)}, got {mode!r}")
    return mode
