"""Where fitness evaluations run: in this process, in local worker processes, or on Dask.

All three engines compute the same function, :func:`evaluate_chunk` (genes of a few individuals
-> iterations of every run), on chunks of the population, and return the chunks in population
order. Because each individual's runs depend only on its genes, the scenario and the seeds —
never on which chunk it was in or which worker ran it — the result is identical, number for
number, whatever the engine or the worker count (tested).

Local workers die with the training process: a ``kill -9`` of ``train`` gives its workers no
chance to be shut down, so each worker asks the kernel to kill it when its parent dies
(``prctl(PR_SET_PDEATHSIG)`` on Linux). A ``--scheduler`` address is checked (syntax, then a
plain TCP connection with a short timeout) before Dask is asked to connect, so a typo fails in
a few seconds with one line instead of Dask's retry loop and its clean-up tracebacks.
"""

from __future__ import annotations

import os
import signal
import sys
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Callable, Sequence

import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.training.evaluate import TrainingProblem, iterations_for, measure_shape
from xfuzzy_rrt.training.genome import decode

#: Chunks per worker per generation: enough to balance uneven runs, few enough to be cheap.
#: Why 16: one individual of a first generation can cost 2 % of the generation (five failed
#: 10,000-iteration runs) while most cost 0.01 %; replaying the measured per-run times of the
#: benchmark population, 4 chunks per worker (2 workers) end 4 % after the ideal, 16 about 1 %,
#: and a chunk's fixed cost (decoding, one tree, memo buffers) is well under a millisecond.
CHUNKS_PER_WORKER = 16

_PROBLEMS: list[TrainingProblem] | None = None  # set once per worker process by _init_worker
#: Seconds to reach a Dask scheduler before giving up.
CONNECT_TIMEOUT_S = 3.0
#: prctl(2) option: the signal this process gets when its parent dies (linux/prctl.h).
PR_SET_PDEATHSIG = 1


def evaluate_chunk(genes: np.ndarray, problems: Sequence[TrainingProblem], bounds_mode: str,
                   seeds: np.ndarray, max_iter: int, dof: int = 2,
                   measure: str = "iterations") -> np.ndarray:
    """Iterations int64[n, S, R] of the individuals ``genes`` [n, n_genes] (3,822 at 2 DOF;
    *dof* fixes the genome's outputs and ranges, see :func:`~.genome.decode`), or with
    ``measure="work"`` int64[n, S, R, 2] (iterations and work), ``"cost"`` int64[n, S, R, 3]
    (and path cost; :func:`~.evaluate.iterations_for`)."""
    knots, consts = decode(genes, bounds_mode, dof)
    return iterations_for(list(problems), knots, consts, bounds_mode, seeds, max_iter, measure)


def die_with_parent(parent_pid: int) -> bool:
    """Have the kernel SIGKILL this process when its parent dies (Linux); True if arranged.

    Why: workers of a ``kill -9``-ed parent would otherwise keep computing, orphaned, until
    their queue breaks. If the parent is already gone when this runs, exit at once.
    """
    if not sys.platform.startswith("linux"):
        return False
    import ctypes

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        if libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) != 0:
            return False
    except (OSError, AttributeError):
        return False
    if os.getppid() != parent_pid:  # the parent died before the request took effect
        os._exit(1)
    return True


def _init_worker(problems: list[TrainingProblem], parent_pid: int) -> None:
    global _PROBLEMS
    die_with_parent(parent_pid)
    _PROBLEMS = problems
    # load the compiled kernels now (from numba's cache) rather than inside the first task
    from xfuzzy_rrt.training.genome import constant_genome

    evaluate_chunk(constant_genome(0.05, (-180, 180, -180, 180), 10.0)[None], problems[:1],
                   "absolute", np.zeros(1, dtype=np.int64), 5)


def _warm_in_worker(genes, bounds_mode, dof, measure="iterations"):
    evaluate_chunk(genes, _PROBLEMS[:1], bounds_mode, np.zeros(1, dtype=np.int64), 5, dof,
                   measure)


def _evaluate_in_worker(genes, bounds_mode, seeds, max_iter, dof=2, measure="iterations"):
    return evaluate_chunk(genes, _PROBLEMS, bounds_mode, seeds, max_iter, dof, measure)


def _chunks(n: int, parts: int) -> list[slice]:
    parts = max(1, min(n, parts))
    edges = np.linspace(0, n, parts + 1).round().astype(int)
    return [slice(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]


class Evaluator:
    """Evaluates a population on fixed problems; subclasses choose where the work runs.

    Call ``evaluator(genes, seeds, progress)``: ``progress(done, total)`` is called as chunks
    finish (for the CLI's progress display). Use as a context manager to release workers.
    """

    def __init__(self, problems: list[TrainingProblem], bounds_mode: str, max_iter: int,
                 dof: int = 2, measure: str = "iterations"):
        self.problems = list(problems)
        self.bounds_mode = bounds_mode
        self.max_iter = int(max_iter)
        self.dof = int(dof)  # the rulebook DOF the genomes encode
        self.measure = measure  # what each run reports (evaluate.MEASURES)

    def _out(self, genes: np.ndarray, seeds: np.ndarray) -> np.ndarray:
        """The result array one call fills: [n, S, R], [n, S, R, 2] for work, [n, S, R, 3]
        for cost (:func:`~.evaluate.measure_shape`)."""
        shape = (genes.shape[0], len(self.problems), len(seeds))
        return np.empty(shape + measure_shape(self.measure), dtype=np.int64)

    description = "in-process"

    def warm_up(self, genes: np.ndarray) -> None:
        """Compile (or load from numba's cache) the kernels for these genes' semantics here,
        before anything is timed. Why: generation 1's ``runs_per_s`` used to include the first
        compile and read "0 runs/s"."""
        evaluate_chunk(np.asarray(genes[:1]), self.problems[:1], self.bounds_mode,
                       np.zeros(1, dtype=np.int64), 5, self.dof, self.measure)

    def __call__(self, genes: np.ndarray, seeds: np.ndarray,
                 progress: Callable[[int, int], None] | None = None) -> np.ndarray:
        out = self._out(genes, seeds)
        parts = _chunks(genes.shape[0], CHUNKS_PER_WORKER)
        for k, sl in enumerate(parts):
            out[sl] = evaluate_chunk(genes[sl], self.problems, self.bounds_mode, seeds,
                                     self.max_iter, self.dof, self.measure)
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

    def __init__(self, problems, bounds_mode, max_iter, workers: int, dof: int = 2,
                 measure: str = "iterations"):
        super().__init__(problems, bounds_mode, max_iter, dof, measure)
        self.workers = int(workers)
        self.description = f"{self.workers} local worker processes"
        self._pool = ProcessPoolExecutor(max_workers=self.workers, initializer=_init_worker,
                                         initargs=(self.problems, os.getpid()))

    def __call__(self, genes, seeds, progress=None):
        out = self._out(genes, seeds)
        parts = _chunks(genes.shape[0], CHUNKS_PER_WORKER * self.workers)
        futures = {self._pool.submit(_evaluate_in_worker, genes[sl], self.bounds_mode, seeds,
                                     self.max_iter, self.dof, self.measure): sl for sl in parts}
        for k, fut in enumerate(as_completed(futures), start=1):
            out[futures[fut]] = fut.result()
            if progress:
                progress(k, len(parts))
        return out

    def warm_up(self, genes: np.ndarray) -> None:
        """Compile here first (the workers then load numba's cache), then start every worker
        and load the kernels in it, so that no timed generation pays for either."""
        super().warm_up(genes)
        futures = [self._pool.submit(_warm_in_worker, np.asarray(genes[:1]), self.bounds_mode,
                                     self.dof, self.measure) for _ in range(self.workers)]
        for fut in futures:
            fut.result()

    def close(self) -> None:
        self._pool.shutdown(wait=True, cancel_futures=True)


def check_scheduler_address(address: str) -> None:
    """Refuse a ``--scheduler`` value that is not an address, or where nothing listens.

    Raises :class:`InputError` within about ``CONNECT_TIMEOUT_S`` seconds.
    """
    try:
        from distributed.comm import parse_address
        from distributed.comm.addressing import parse_host_port
    except ImportError:
        raise InputError("--scheduler", "Dask is not installed: pip install -e '.[dask]'") from None
    try:
        scheme, location = parse_address(address)
        host, port = parse_host_port(location) if scheme in ("tcp", "tls") else (None, None)
    except (ValueError, TypeError) as exc:
        raise InputError("--scheduler", f"{address!r} is not a scheduler address (expected "
                         f"tcp://HOST:PORT): {exc}") from None
    if host is None:
        return
    import socket

    try:
        socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S).close()
    except OSError as exc:
        reason = exc.strerror or str(exc) or type(exc).__name__
        raise InputError("--scheduler", f"cannot reach a Dask scheduler at {address!r}: "
                         f"{reason}") from None


class DaskEvaluator(Evaluator):
    """Tasks on a Dask distributed cluster (``--scheduler ADDRESS``)."""

    def __init__(self, problems, bounds_mode, max_iter, address: str, dof: int = 2,
                 measure: str = "iterations"):
        super().__init__(problems, bounds_mode, max_iter, dof, measure)
        check_scheduler_address(address)
        from distributed import Client

        try:
            self._client = Client(address, timeout=f"{CONNECT_TIMEOUT_S:g}s",
                                  set_as_default=False)
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError("--scheduler", f"cannot connect to Dask scheduler {address!r}: {exc}") from None
        n = max(1, sum(self._client.nthreads().values()))
        self.workers = n
        self.description = f"Dask scheduler {address} ({n} threads)"
        self._problems = self._client.scatter(self.problems, broadcast=True)

    def __call__(self, genes, seeds, progress=None):
        from distributed import as_completed

        out = self._out(genes, seeds)
        parts = _chunks(genes.shape[0], CHUNKS_PER_WORKER * self.workers)
        futures = []
        for sl in parts:
            fut = self._client.submit(evaluate_chunk, genes[sl], self._problems, self.bounds_mode,
                                      seeds, self.max_iter, self.dof, self.measure, pure=False)
            futures.append((fut, sl))
        where = {f.key: sl for f, sl in futures}
        for k, fut in enumerate(as_completed([f for f, _ in futures], loop=self._client.loop), start=1):
            out[where[fut.key]] = fut.result()
            if progress:
                progress(k, len(parts))
        return out

    def close(self) -> None:
        self._client.close()


def make_evaluator(problems: list[TrainingProblem], bounds_mode: str, max_iter: int,
                   workers: int | None = None, scheduler: str | None = None,
                   dof: int = 2, measure: str = "iterations") -> Evaluator:
    """The engine the options ask for: Dask with ``scheduler``, else ``workers`` processes
    (default: all cores; 1 means in-process). *dof*: the rulebook DOF being trained;
    *measure*: what each run reports (``evaluate.measure_of`` the fitness)."""
    if scheduler:
        return DaskEvaluator(problems, bounds_mode, max_iter, scheduler, dof, measure)
    if workers is None:
        workers = os.cpu_count() or 1
    if workers < 1:
        raise InputError("--workers", f"must be >= 1, got {workers}")
    if workers == 1:
        return Evaluator(problems, bounds_mode, max_iter, dof, measure)
    return ProcessEvaluator(problems, bounds_mode, max_iter, workers, dof, measure)
