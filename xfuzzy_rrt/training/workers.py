"""Where fitness evaluations run: in this process, in local worker processes, or on Dask.

All three engines compute the same function, :func:`evaluate_chunk` (genes of a few individuals
-> iterations of every run), on chunks of the population, and return the chunks in population
order. Because each individual's runs depend only on its genes, the scenario and the seeds —
never on which chunk it was in or which worker ran it — the result is identical, number for
number, whatever the engine or the worker count (tested).
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Callable, Sequence

import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.training.evaluate import Problem, iterations_for
from xfuzzy_rrt.training.genome import decode

#: Chunks per worker per generation: enough to balance uneven runs, few enough to be cheap.
CHUNKS_PER_WORKER = 4

_PROBLEMS: list[Problem] | None = None  # set once per worker process by _init_worker


def evaluate_chunk(genes: np.ndarray, problems: Sequence[Problem], bounds_mode: str,
                   seeds: np.ndarray, max_iter: int) -> np.ndarray:
    """Iterations int64[n, S, R] of the individuals ``genes`` [n, 3822]."""
    knots, consts = decode(genes, bounds_mode)
    return iterations_for(list(problems), knots, consts, bounds_mode, seeds, max_iter)


def _init_worker(problems: list[Problem]) -> None:
    global _PROBLEMS
    _PROBLEMS = problems
    # load the compiled kernels now (from numba's cache) rather than inside the first task
    from xfuzzy_rrt.training.genome import constant_genome

    evaluate_chunk(constant_genome(0.05, (-180, 180, -180, 180), 10.0)[None], problems[:1],
                   "absolute", np.zeros(1, dtype=np.int64), 5)


def _evaluate_in_worker(genes, bounds_mode, seeds, max_iter):
    return evaluate_chunk(genes, _PROBLEMS, bounds_mode, seeds, max_iter)


def _chunks(n: int, parts: int) -> list[slice]:
    parts = max(1, min(n, parts))
    edges = np.linspace(0, n, parts + 1).round().astype(int)
    return [slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]


class Evaluator:
    """Evaluates a population on fixed problems; subclasses choose where the work runs.

    Call ``evaluator(genes, seeds, progress)``: ``progress(done, total)`` is called as chunks
    finish (for the CLI's progress display). Use as a context manager to release workers.
    """

    def __init__(self, problems: list[Problem], bounds_mode: str, max_iter: int):
        self.problems = list(problems)
        self.bounds_mode = bounds_mode
        self.max_iter = int(max_iter)

    description = "in-process"

    def __call__(self, genes: np.ndarray, seeds: np.ndarray,
                 progress: Callable[[int, int], None] | None = None) -> np.ndarray:
        out = np.empty((genes.shape[0], len(self.problems), len(seeds)), dtype=np.int64)
        parts = _chunks(genes.shape[0], CHUNKS_PER_WORKER)
        for k, sl in enumerate(parts):
            out[sl] = evaluate_chunk(genes[sl], self.problems, self.bounds_mode, seeds,
                                     self.max_iter)
            if progress:
                progress(k + 1, len(parts))
        return out

    def close(self) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class ProcessEvaluator(Evaluator):
    """Local worker processes (the default: one per core)."""

    def __init__(self, problems, bounds_mode, max_iter, workers: int):
        super().__init__(problems, bounds_mode, max_iter)
        self.workers = int(workers)
        self.description = f"{self.workers} local worker processes"
        self._pool = ProcessPoolExecutor(max_workers=self.workers, initializer=_init_worker,
                                         initargs=(self.problems,))

    def __call__(self, genes, seeds, progress=None):
        out = np.empty((genes.shape[0], len(self.problems), len(seeds)), dtype=np.int64)
        parts = _chunks(genes.shape[0], CHUNKS_PER_WORKER * self.workers)
        futures = {self._pool.submit(_evaluate_in_worker, genes[sl], self.bounds_mode, seeds,
                                     self.max_iter): sl for sl in parts}
        for k, fut in enumerate(as_completed(futures), start=1):
            out[futures[fut]] = fut.result()
            if progress:
                progress(k, len(parts))
        return out

    def close(self) -> None:
        self._pool.shutdown(wait=True, cancel_futures=True)


class DaskEvaluator(Evaluator):
    """Tasks on a Dask distributed cluster (``--scheduler ADDRESS``)."""

    def __init__(self, problems, bounds_mode, max_iter, address: str):
        super().__init__(problems, bounds_mode, max_iter)
        try:
            from distributed import Client
        except ImportError:
            raise InputError("--scheduler", "Dask is not installed: pip install -e '.[dask]'") from None
        try:
            self._client = Client(address, timeout="10s", set_as_default=False)
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError("--scheduler", f"cannot connect to Dask scheduler {address!r}: {exc}") from None
        n = max(1, sum(self._client.nthreads().values()))
        self.workers = n
        self.description = f"Dask scheduler {address} ({n} threads)"
        self._problems = self._client.scatter(self.problems, broadcast=True)

    def __call__(self, genes, seeds, progress=None):
        from distributed import as_completed

        out = np.empty((genes.shape[0], len(self.problems), len(seeds)), dtype=np.int64)
        parts = _chunks(genes.shape[0], CHUNKS_PER_WORKER * self.workers)
        futures = []
        for sl in parts:
            fut = self._client.submit(evaluate_chunk, genes[sl], self._problems, self.bounds_mode,
                                      seeds, self.max_iter, pure=False)
            futures.append((fut, sl))
        where = {f.key: sl for f, sl in futures}
        for k, fut in enumerate(as_completed([f for f, _ in futures], loop=self._client.loop), start=1):
            out[where[fut.key]] = fut.result()
            if progress:
                progress(k, len(parts))
        return out

    def close(self) -> None:
        self._client.close()


def make_evaluator(problems: list[Problem], bounds_mode: str, max_iter: int,
                   workers: int | None = None, scheduler: str | None = None) -> Evaluator:
    """The engine the options ask for: Dask with ``scheduler``, else ``workers`` processes
    (default: all cores; 1 means in-process)."""
    if scheduler:
        return DaskEvaluator(problems, bounds_mode, max_iter, scheduler)
    if workers is None:
        workers = os.cpu_count() or 1
    if workers < 1:
        raise InputError("--workers", f"must be >= 1, got {workers}")
    if workers == 1:
        return Evaluator(problems, bounds_mode, max_iter)
    return ProcessEvaluator(problems, bounds_mode, max_iter, workers)
