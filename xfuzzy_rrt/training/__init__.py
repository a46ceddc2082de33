"""Genetic training of rulebooks (the paper's GA section), fast enough to run at its scale.

Modules: :mod:`.genome` (3,822 genes <-> six always-valid fuzzy systems), :mod:`.evaluate`
(compiled runs of a whole population: genes go straight to the planner kernel's arrays, no
text, no DataFrames, no Python per iteration), :mod:`.memo` (the paper-semantics loop that
remembers per-node work within a run: the planner's exact iterations, less work),
:mod:`.workers` (in-process, local processes or Dask — same numbers from each),
:mod:`.operators` (selection, crossover, mutation), :mod:`.ga` (the generational loop),
:mod:`.checkpoint` (atomic, self-checking state files) and :mod:`.run` (a whole job: outputs
and provenance).

**Which evolutionary library, and why.** Selection, crossover and mutation are pymoo 0.6.2's
(``TournamentSelection``, ``SBX``, ``PM``), written again in :mod:`.operators` — the same draws
from an explicit ``numpy.random.Generator`` and the same arithmetic, tested bit for bit against
pymoo — because pymoo's general machinery made breeding 0.17-0.37 s of a generation whose
evaluation takes ~1 s (ours: ~0.08 s, 400 x 3,822 genes), serial in the main process while the
workers wait. The random state stays one JSON-serialisable dict in the checkpoint. DEAP was
measured as the alternative: its operators loop in Python per gene — ``cxSimulatedBinaryBounded``
and ``mutPolynomialBounded`` on 400 individuals x 3,822 genes took 6.2 s per generation against
2.3 s for pymoo's (an earlier, slower host) — and draw from the global ``random`` module, which a
checkpoint would have to capture and which any other library could disturb. pymoo's own ``GA``
driver is not used: its (mu + lambda) survival keeps parents with the fitness they drew on *old*
seeds, while the paper's scheme — re-evaluate everybody on the same fresh seeds each generation —
needs a generational loop with elitism, which :class:`.ga.Trainer` is.

One operator has no pymoo counterpart; it is ours because it was measured to matter: *term-block mutation*
(:func:`.ga.term_blocks`), which shifts a FIS's constants by a separable function of the four
terms ("more goal bias wherever the goal is near"). Per-gene mutation alone changes one of 625
cells at a time, each individually almost neutral. A short comparison on ``paper-reference``
(not a study): 12 generations without it validated at 495 median iterations, 15 generations
with it at 361 (RRT: ~800).

**A second algorithm** (sep-CMA-ES through pycma, ``CMA_diagonal``, population 400, started
from the RRT-equivalent rulebook) was compared at an equal number of planner runs: after 15
generations its mean rulebook needed 871 median iterations on validation seeds, the GA's best
~360 (RRT: ~800). With 3,822 dimensions and noisy five-run fitness its diagonal adaptation is
too slow, so it is not offered; the GA stays the default and only algorithm.
"""
