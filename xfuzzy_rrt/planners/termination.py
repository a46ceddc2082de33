"""When a planner stops: an iteration budget, a wall-clock budget, or whichever comes first.

OMPL's ``PlannerTerminationCondition`` is the model: a timed condition is a flag that a timer
thread raises, and the planner loop polls it. Here the flag is a one-element ``int64`` array
the compiled kernels read once per iteration (a memory load; the kernels run with the GIL
released, so a Python timer thread can set it while they run). Every planner honours both
budgets the same way, so a time-limited comparison means the same for RRT and Fuzzy-RRT.

A plan stopped by its wall-clock budget is not reproducible iteration for iteration (it
depends on the machine's speed); a plan that ends within its iteration budget is, byte for
byte, whatever the wall-clock budget was. Results record which budget ended the run
(``params["stopped_by"]``: ``goal``, ``iterations`` or ``time``).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

import numpy as np

from xfuzzy_rrt.errors import InputError

#: Largest iteration budget accepted. Tree storage is preallocated per plan (and a trace needs
#: about 1.3 kB per iteration), so an absurd budget must fail cleanly, not exhaust memory.
MAX_ITER_LIMIT = 1_000_000
#: Largest wall-clock budget accepted (seconds): a day.
MAX_TIME_LIMIT_S = 86_400.0


@dataclass(frozen=True)
class Termination:
    """Stop after ``max_iter`` iterations or ``max_time_s`` seconds (``None``: no time limit)."""

    max_iter: int = 10_000
    max_time_s: float | None = None

    def __post_init__(self) -> None:
        check_max_iter(self.max_iter)
        if self.max_time_s is not None:
            check_max_time(self.max_time_s)


def check_max_iter(max_iter: int, where: str = "max_iter") -> int:
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)):
        raise InputError(where, f"must be an integer, got {max_iter!r}")
    if not 1 <= max_iter <= MAX_ITER_LIMIT:
        raise InputError(where, f"must lie in [1, {MAX_ITER_LIMIT}], got {max_iter}")
    return int(max_iter)


def check_max_time(max_time_s, where: str = "--max-time") -> float:
    if isinstance(max_time_s, bool) or not isinstance(max_time_s, (int, float, np.floating)):
        raise InputError(where, f"must be a number of seconds, got {max_time_s!r}")
    t = float(max_time_s)
    if not (math.isfinite(t) and 0.0 < t <= MAX_TIME_LIMIT_S):
        raise InputError(where, f"must be a number of seconds in (0, {MAX_TIME_LIMIT_S:g}], "
                         f"got {max_time_s!r}")
    return t


#: The stop flag of a call without a time budget: kernels only read it and nothing raises it,
#: so every such call (any thread) shares this one array (kept writable: numba types a
#: read-only array differently and would compile every kernel a second time).
NEVER_STOPPED = np.zeros(1, dtype=np.int64)


class StopFlag:
    """The flag a kernel polls; raised by a timer thread after ``max_time_s`` (if any).

    Use as a context manager around the kernel call: ``with StopFlag(t) as flag: kernel(...,
    flag.array)``. ``fired`` says whether the time budget ended the run.
    """

    def __init__(self, max_time_s: float | None):
        self.array = np.zeros(1, dtype=np.int64)
        self._timer = None
        if max_time_s is not None:
            self._timer = threading.Timer(float(max_time_s), self._raise)
            self._timer.daemon = True

    def _raise(self) -> None:
        self.array[0] = 1

    @property
    def fired(self) -> bool:
        return bool(self.array[0])

    def __enter__(self) -> "StopFlag":
        if self._timer is not None:
            self._timer.start()
        return self

    def __exit__(self, *exc) -> None:
        if self._timer is not None:
            self._timer.cancel()


def stopped_by(ok: bool, iterations: int, max_iter: int, flag: StopFlag) -> str:
    """``goal``, ``time`` or ``iterations``: what ended a run."""
    if ok:
        return "goal"
    if flag.fired and iterations < max_iter:
        return "time"
    return "iterations"
