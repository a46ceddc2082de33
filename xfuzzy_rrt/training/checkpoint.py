"""Training checkpoints: one file, written atomically after every generation.

Why one ``.npz`` file: ``os.replace`` of a single file is atomic, so after a crash, Ctrl-C or
``kill -9`` the checkpoint on disk is always a complete one — the previous generation's or this
one's, never half of each. It holds the population to evaluate next, the GA's generator state,
the history, the hall of fame and the fingerprint of the configuration (so resuming with other
options, or from another run's checkpoint, is refused instead of silently mixing runs).

Nothing in it is pickled: arrays plus one JSON document, so loading a foreign or corrupt file
can only fail with a clear message, never execute code.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np

from xfuzzy_rrt.atomic import atomic_path
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.strict import unknown_key_message
from xfuzzy_rrt.training.ga import GAConfig, TrainState

FORMAT = "xfuzzy-rrt-train-checkpoint"
VERSION = 1
FILE_NAME = "state.npz"
#: Every array a checkpoint holds, and every key of its ``meta`` document: anything else is
#: refused (a file this version did not write must not be half-understood).
ARRAYS = ("meta", "population", "hall_of_fame", "last_fitness", "last_population")
META_KEYS = ("format", "version", "fingerprint", "generation", "done", "rng_state", "history")


def checkpoint_file(directory: Path) -> Path:
    return Path(directory) / FILE_NAME


def save_checkpoint(directory: Path, state: TrainState, config: GAConfig) -> Path:
    """Write ``directory/state.npz`` atomically; return its path."""
    meta = {
        "format": FORMAT,
        "version": VERSION,
        "fingerprint": config.fingerprint(),
        "generation": state.generation,
        "done": state.done,
        "rng_state": state.rng_state,
        "history": state.history,
    }
    arrays = {
        "meta": np.array(json.dumps(meta, sort_keys=True)),
        "population": state.population,
        "hall_of_fame": np.array(state.hall_of_fame).reshape(-1, config.n_genes),
    }
    if state.last_fitness is not None:
        arrays["last_fitness"] = state.last_fitness
        arrays["last_population"] = state.last_population
    dest = checkpoint_file(directory)
    with atomic_path(dest) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
    return dest


def load_checkpoint(directory: Path, config: GAConfig) -> TrainState:
    """Read a checkpoint written by :func:`save_checkpoint` for the same configuration.

    Raises :class:`InputError` (one line naming the file) when it is missing, corrupt, of
    another format or version, or made by a different training configuration.
    """
    path = checkpoint_file(directory)
    where = str(path)
    if not path.is_file():
        raise InputError(where, "no checkpoint to resume from (run without --resume to start)")
    try:
        data = path.read_bytes()
        with np.load(io.BytesIO(data), allow_pickle=False) as z:
            for name in z.files:
                if name not in ARRAYS:
                    raise InputError(where, unknown_key_message(name, ARRAYS, "the arrays"))
            meta = json.loads(str(z["meta"][()]))
            population = np.array(z["population"], dtype=np.float64)
            hof = np.array(z["hall_of_fame"], dtype=np.float64)
            last_fit = np.array(z["last_fitness"]) if "last_fitness" in z.files else None
            last_pop = np.array(z["last_population"]) if "last_population" in z.files else None
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 — any failure to parse untrusted bytes is "corrupt"
        # (numpy's header parser alone can raise ValueError, SyntaxError or tokenize.TokenError)
        raise InputError(where, f"corrupt checkpoint ({type(exc).__name__}: {exc})") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise InputError(where, "not an xfuzzy-rrt training checkpoint")
    for key in meta:
        if key not in META_KEYS:
            raise InputError(where, unknown_key_message(key, META_KEYS, "meta"))
    if meta.get("version") != VERSION:
        raise InputError(where, f"checkpoint version {meta.get('version')!r} is not supported "
                         f"(this version reads {VERSION})")
    if meta.get("fingerprint") != config.fingerprint():
        raise InputError(where, "checkpoint belongs to a different training run (scenarios, "
                         "seed or GA options differ); resume with the options it was made with")
    generation = meta.get("generation")
    history = meta.get("history")
    size = config.n_genes  # the genome of the configuration's DOF (the fingerprint holds it)
    if (not isinstance(generation, int) or not isinstance(history, list)
            or len(history) != generation or hof.shape != (generation, size)
            or population.shape != (config.population, size)
            or not np.all(np.isfinite(population))):
        raise InputError(where, "corrupt checkpoint (inconsistent contents)")
    return TrainState(
        generation=generation, population=population, rng_state=meta["rng_state"],
        history=history, hall_of_fame=list(hof), last_fitness=last_fit,
        last_population=last_pop, done=bool(meta.get("done")),
    )
