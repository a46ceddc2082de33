"""A small, explicit random number generator for compiled planner loops.

Why not ``np.random`` inside numba: its state is hidden, per-thread and tied to numba's
implementation. Planning results must be reproducible byte for byte from ``(seed)`` alone,
whatever the number of worker processes and whichever numba version runs them, and an auditor
should be able to replay the stream in plain Python. So the planners carry their own
xoshiro256** state (Blackman & Vigna, 2018), seeded through SplitMix64 as its authors recommend.

The state is a ``uint64[4]`` array owned by the caller; functions advance it in place.
"""

from __future__ import annotations

import numba as nb
import numpy as np

_MASK = (1 << 64) - 1

#: The largest seed any command accepts. :func:`seed_state` reads a seed's low 64 bits, but a
#: seed is also a numba ``int64`` argument, an ``int64`` column of ``runs.csv`` and, for
#: training, a ``SeedSequence`` entry kept below 2^63 (``TrainConfig``): one range, 0..2^63 - 1,
#: keeps every consumer exact (a bench's ``seed + runs - 1`` included).
SEED_MAX = (1 << 63) - 1


def check_seed(seed, count: int = 1, where: str = "--seed") -> int:
    """Return ``seed`` when ``seed .. seed + count - 1`` are all valid seeds, else raise one
    :class:`~xfuzzy_rrt.errors.InputError` naming ``where`` and the valid range.

    Why one check for every command: without it a seed of 2^64 reached numba as an untyped
    integer (a TypingError traceback) and 10^23 overflowed a NumPy array."""
    if type(seed) is int and count == 1 and 0 <= seed <= SEED_MAX:  # every plan call's case
        return seed
    from xfuzzy_rrt.errors import InputError

    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise InputError(where, f"must be an integer in 0..{SEED_MAX} (2^63 - 1), got {seed!r}")
    seed = int(seed)
    last = SEED_MAX - max(int(count), 1) + 1
    if not 0 <= seed <= last:
        runs = f" so that all {count} run seeds fit" if count > 1 else ""
        raise InputError(where, f"must be an integer in 0..{last}{runs} (seeds are 0..2^63 - 1), "
                         f"got {seed}")
    return seed


@nb.njit(cache=True, nogil=True, inline="always")
def _rotl(x, k):
    return (x << np.uint64(k)) | (x >> np.uint64(64 - k))


@nb.njit(cache=True, nogil=True, _nrt=False)
def seed_state(seed, state):
    """Fill ``state`` (uint64[4]) from an integer seed via SplitMix64."""
    z = np.uint64(seed & 0xFFFFFFFFFFFFFFFF)
    for i in range(4):
        z = z + np.uint64(0x9E3779B97F4A7C15)
        x = z
        x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        state[i] = x ^ (x >> np.uint64(31))


@nb.njit(cache=True, nogil=True, _nrt=False)
def next_u64(state):
    """Advance the generator; return the next 64-bit output."""
    s0 = state[0]
    s1 = state[1]
    s2 = state[2]
    s3 = state[3]
    result = _rotl(s1 * np.uint64(5), 7) * np.uint64(9)
    t = s1 << np.uint64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, 45)
    state[0] = s0
    state[1] = s1
    state[2] = s2
    state[3] = s3
    return result


@nb.njit(cache=True, nogil=True, _nrt=False)
def uniform(state):
    """A double in [0, 1) with 53 random bits."""
    return np.float64(next_u64(state) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


def new_state(seed: int) -> np.ndarray:
    """A freshly seeded state array (Python convenience)."""
    state = np.zeros(4, dtype=np.uint64)
    seed_state(int(seed) & _MASK, state)
    return state


def reference_stream(seed: int, n: int) -> list[float]:
    """Pure-Python replay of :func:`uniform` (for audits and tests)."""
    z = seed & _MASK
    s = []
    for _ in range(4):
        z = (z + 0x9E3779B97F4A7C15) & _MASK
        x = z
        x = ((x ^ (x >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
        x = ((x ^ (x >> 27)) * 0x94D049BB133111EB) & _MASK
        s.append(x ^ (x >> 31))

    def rotl(x: int, k: int) -> int:
        return ((x << k) | (x >> (64 - k))) & _MASK

    out = []
    for _ in range(n):
        result = (rotl((s[1] * 5) & _MASK, 7) * 9) & _MASK
        t = (s[1] << 17) & _MASK
        s[2] ^= s[0]
        s[3] ^= s[1]
        s[1] ^= s[2]
        s[0] ^= s[3]
        s[2] ^= t
        s[3] = rotl(s[3], 45)
        out.append((result >> 11) * (1.0 / 9007199254740992.0))
    return out
