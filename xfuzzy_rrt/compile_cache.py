"""Whether numba's on-disk cache already holds the planners' compiled kernels.

Why: the first command after an install (or after a source change) compiles every kernel,
which takes tens of seconds with no output at all; the CLI says so in one line instead of
looking hung. The check asks numba's own cache for each top-level kernel's index (the file
numba reads before loading a compiled kernel, checked against the source file's timestamp), so
it costs a few small file reads, never a compilation. Kernels called by these compile with
them, so checking the entry points is enough.
"""

from __future__ import annotations

from importlib import import_module

#: (module, kernel) entry points of the compiled code: plan/bench (RRT, Fuzzy-RRT, the path
#: certificate) and training (the population evaluator).
KERNELS = (
    ("xfuzzy_rrt.planners.rrt", "rrt_kernel"),
    ("xfuzzy_rrt.planners.fuzzy_rrt", "fuzzy_rrt_kernel"),
    ("xfuzzy_rrt.geometry.path_check", "certify_kernel"),
    ("xfuzzy_rrt.training.evaluate", "run_population"),
)


def kernel_cached(dispatcher) -> bool:
    """True when numba's cache has a current compiled version of ``dispatcher``.

    Reads numba's private cache objects; if they change shape in a numba release, answer
    "cached" (the worst case is a missing notice, never a wrong result).
    """
    try:
        return bool(dispatcher._cache._cache_file._load_index())
    except Exception:  # noqa: BLE001 — a notice must never break a command
        return True


def cold_kernels() -> list[str]:
    """``module.kernel`` names of the entry points numba would have to compile now."""
    out = []
    for module, name in KERNELS:
        if not kernel_cached(getattr(import_module(module), name)):
            out.append(f"{module}.{name}")
    return out
