"""A rulebook: the frozen model of six FIS plus manifest, and its directory on disk.

On disk a rulebook is a directory::

    rulebook.toml      manifest: name, format version, semantics, dof, bounds mode, provenance
    goal_bias.fis      one text file per output FIS (see .text_format)
    bound_1.fis ... bound_4.fis     (paper semantics: bound_1 ... bound_2N for dof = N)
    step_size.fis

Other files in the directory (e.g. a trainer's ``history.csv``) are left alone; an unknown
``*.fis`` file is reported, because it is almost certainly a misnamed output.

:func:`load_rulebook` validates everything and raises :class:`~xfuzzy_rrt.errors.RulebookError`
with *all* problems as ``(file, line, message)``. :func:`save_rulebook` writes the canonical
text; a canonical directory loads and saves back to identical bytes.

``Rulebook.sha256`` identifies a rulebook in results: the SHA-256 over the canonical bytes of
the manifest and the FIS files, in the order ``rulebook.toml``, then output order, each
fed as ``<file name>\\n<byte length>\\n<bytes>`` (so file boundaries are unambiguous). For a
canonical directory (every shipped or saved one) these are exactly the bytes on disk; a
hand-edited file with extra comments hashes as its canonical form, i.e. comments do not change
a rulebook's identity, numbers do.
"""

from __future__ import annotations

import errno
import functools
import hashlib
import os
import re
import tempfile
import time
import weakref
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any, Mapping, NamedTuple

import numpy as np

from xfuzzy_rrt.errors import RulebookError
from xfuzzy_rrt.fuzzy.manifest import (
    BOUNDS_MODES,
    MANIFEST_NAME,
    Manifest,
    _key_line,
    format_manifest,
    parse_manifest,
)
from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.fuzzy.system import FuzzySystem, InputPartition
from xfuzzy_rrt.fuzzy.text_format import SUFFIX, format_fis, parse_fis
from xfuzzy_rrt.fuzzy.variables import N_INPUTS, N_RULES, N_TERMS

#: Environment variable naming a folder of rulebooks that replaces the shipped one.
RULEBOOKS_ENV = "XFUZZY_RRT_RULEBOOKS"
#: The default of plan, bench and demo: the shipped rulebook that wins the fair protocol
#: (``xfuzzy-rrt evaluate``) on problems no training or tuning saw (see rulebooks/README.md).
DEFAULT_RULEBOOK = "goal-frame"

__all__ = [
    "FuzzySystem",
    "InputPartition",
    "Rulebook",
    "default_rulebook_path",
    "fis_file_name",
    "list_rulebooks",
    "load_rulebook",
    "load_rulebook_cached",
    "rulebooks_dir",
    "save_rulebook",
]


def fis_file_name(output: str) -> str:
    """File name of the FIS for *output* inside a rulebook directory."""
    return output + SUFFIX


@dataclass(frozen=True)
class Rulebook:
    """Single-output TSK systems (the semantics' output order) with a name, semantics,
    bounds mode (paper semantics only; ``None`` otherwise) and provenance.

    ``semantics`` is a :class:`~.semantics.Semantics` (or its name): it fixes the input and
    output names, ranges and units every tool reads, and carries the rulebook's DOF
    (:attr:`dof`). A name alone means the DOF of the systems (2 when there are none).
    """

    name: str
    bounds_mode: str | None
    systems: tuple[FuzzySystem, ...]
    provenance: Mapping[str, Any] = field(default_factory=dict)
    description: str = ""
    semantics: "_sem.Semantics | str | None" = None  # None: the systems' own semantics

    def __post_init__(self) -> None:
        first = self.systems[0] if len(self.systems) else None
        dof = first.dof if isinstance(first, FuzzySystem) else _sem.DEFAULT_DOF
        if self.semantics is None:
            sem = first.semantics if isinstance(first, FuzzySystem) else _sem.PAPER
        elif isinstance(self.semantics, _sem.Semantics):
            sem = self.semantics
        else:
            sem = _sem.get(self.semantics, dof)
        object.__setattr__(self, "semantics", sem)
        object.__setattr__(self, "systems", tuple(self.systems))
        for s in self.systems:
            if not isinstance(s, FuzzySystem):
                raise ValueError(f"systems must be FuzzySystem objects, got {type(s).__name__}")
        outputs = tuple(s.output for s in self.systems)
        if outputs != sem.outputs or any(s.semantics is not sem for s in self.systems):
            raise ValueError(f"systems must be {sem.outputs} of the {sem.name} semantics at dof "
                             f"{sem.dof} in that order, got {outputs} (dof "
                             f"{sorted({s.dof for s in self.systems})})")
        manifest = Manifest(
            name=self.name, bounds_mode=self.bounds_mode,
            provenance=self.provenance, description=self.description, semantics=sem.name,
            dof=sem.dof,
        )  # validates; also freezes provenance
        object.__setattr__(self, "provenance", manifest.provenance)

    def __reduce__(self):
        """Pickle via plain values: benchmark and training workers receive rulebooks, and the
        read-only provenance views cannot be pickled as they are.

        The pickle carries the rulebook's SHA-256 too, and unpickling gives one object per
        rulebook and process (:func:`_rebuild`): a benchmark worker receives the rulebook
        with every job, and a new object would pay for its hash (the canonical text of every
        file: ~10-60 ms) and miss every set-up remembered for it, on every call -- 9-17 ms
        of a ~0.1 ms plan, in the very ``time_total_s`` the benchmark reports."""
        from xfuzzy_rrt.fuzzy.manifest import thaw

        return (_rebuild, (self.name, self.bounds_mode, self.systems, thaw(self.provenance),
                           self.description, self.semantics.name, self.semantics.dof,
                           self.sha256))

    # ------------------------------------------------------------------ views

    @property
    def manifest(self) -> Manifest:
        return Manifest(
            name=self.name, bounds_mode=self.bounds_mode,
            provenance=self.provenance, description=self.description,
            semantics=self.semantics.name, dof=self.semantics.dof,
        )

    @property
    def dof(self) -> int:
        """The arm's degrees of freedom this rulebook is for (2..7; manifest key ``dof``).

        For the paper semantics, the DOF of each arm (the box has 2 bounds per joint); for
        goal-frame, the total joints planned together.
        """
        return self.semantics.dof

    @property
    def n_outputs(self) -> int:
        """Number of FIS: the first axis of the compiled ``knots``/``consts``."""
        return len(self.systems)

    @property
    def inputs(self) -> tuple[str, ...]:
        """Input names, in rule-index order."""
        return self.semantics.inputs

    @property
    def outputs(self) -> tuple[str, ...]:
        """Output names, in system order."""
        return self.semantics.outputs

    def system(self, output: str) -> FuzzySystem:
        """The FIS for *output* (one of :attr:`outputs`)."""
        try:
            return self.systems[self.outputs.index(output)]
        except ValueError:
            raise KeyError(f"unknown output {output!r}; outputs are {self.outputs}") from None

    def texts(self, compact: bool = False) -> dict[str, str]:
        """Canonical text of every file, keyed by file name (manifest first, then outputs).

        ``compact=True`` writes the FIS files with ``any`` rules (same constants, fewer lines;
        see :mod:`.text_format`); ``sha256`` always hashes the default full form.
        """
        out = {MANIFEST_NAME: format_manifest(self.manifest)}
        for s in self.systems:
            out[fis_file_name(s.output)] = format_fis(s, compact=compact)
        return out

    @cached_property
    def sha256(self) -> str:
        """Hex SHA-256 of the canonical files (see the module docstring for the exact recipe)."""
        h = hashlib.sha256()
        for file, text in self.texts().items():
            data = text.encode("utf-8")
            h.update(f"{file}\n{len(data)}\n".encode("ascii"))
            h.update(data)
        return h.hexdigest()

    @cached_property
    def compiled(self) -> tuple[np.ndarray, np.ndarray]:
        """Read-only engine arrays, built once per rulebook (the planners pass writable copies of
        them: :attr:`kernel_arrays`).

        A rulebook is immutable, so planning with the same object many times (the Python API,
        benchmarks) must not rebuild 3,750 (at 2 DOF) constants per call.
        """
        knots, consts = self.arrays()
        knots.setflags(write=False)
        consts.setflags(write=False)
        return knots, consts

    @cached_property
    def kernel_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """:attr:`compiled`'s arrays as writable copies, made once: what the planners pass to
        their compiled kernels, and nothing writes into them.

        Why not the read-only ones: numba's dispatcher types a writable aligned array from a
        small cache, but fingerprints a read-only one on every call (a string built and looked
        up), code that a cold call fetches from memory (28 last-level misses of ~3,700 a cold
        2-joint call, counted by ``benchmarks/cold_misses.py``); and a read-only array is
        another numba type, so every kernel would be compiled a second time for it (the
        problem's block and the stop flag stay writable for the same reason:
        :mod:`xfuzzy_rrt.planners.problem_arena`).
        """
        knots, consts = self.compiled
        return knots.copy(), consts.copy()

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """Fresh C-contiguous ``(knots float64[n_out, 4, 5], consts float64[n_out, 625])`` for
        the engine, ``n_out = len(self.outputs)`` (6 at 2 DOF; 2N + 2 for the paper's at N)."""
        n_out = len(self.systems)
        knots = np.empty((n_out, N_INPUTS, N_TERMS), dtype=np.float64)
        consts = np.empty((n_out, N_RULES), dtype=np.float64)
        for f, s in enumerate(self.systems):
            for i, inp in enumerate(s.inputs):
                knots[f, i, :] = inp.peaks
            consts[f, :] = s.consts
        return knots, consts

    # ------------------------------------------------------------ construction

    @classmethod
    def from_arrays(
        cls,
        knots,
        consts,
        *,
        name: str,
        bounds_mode: str | None,
        provenance: Mapping[str, Any] | None = None,
        description: str = "",
        term_names: Mapping[str, tuple[str, ...]] | None = None,
        semantics: "_sem.Semantics | str" = _sem.PAPER,
        dof: int | None = None,
    ) -> "Rulebook":
        """Build a rulebook from engine arrays (what the GA trainer evolves).

        ``knots[f, i]`` must be ``[lo, p1, p2, p3, hi]`` with the input's exact range ends and
        strictly increasing peaks; ``consts`` must lie within each output's range (clip them
        before calling). Term names default to :data:`~.variables.DEFAULT_TERMS`. The DOF is
        *dof* if given, else that of *semantics* (a :class:`~.semantics.Semantics` carries
        one; a name means 2); the arrays must have ``len(outputs)`` rows at that DOF. Raises
        ``ValueError`` naming the offending FIS, input or rule.
        """
        knots = np.asarray(knots, dtype=np.float64)
        consts = np.asarray(consts, dtype=np.float64)
        sem = semantics if isinstance(semantics, _sem.Semantics) else _sem.get(semantics)
        if dof is not None:
            sem = sem.for_dof(dof)
        n_out = len(sem.outputs)
        if knots.shape != (n_out, N_INPUTS, N_TERMS):
            raise ValueError(f"knots must have shape {(n_out, N_INPUTS, N_TERMS)} ({sem.name} "
                             f"semantics at dof {sem.dof}), got {knots.shape}")
        if consts.shape != (n_out, N_RULES):
            raise ValueError(f"consts must have shape {(n_out, N_RULES)} ({sem.name} semantics "
                             f"at dof {sem.dof}), got {consts.shape}")
        names = dict(sem.default_terms)
        if term_names:
            names.update({k: tuple(v) for k, v in term_names.items()})
        systems = []
        for f, output in enumerate(sem.outputs):
            inputs = tuple(
                InputPartition(name=inp, terms=names[inp], peaks=tuple(knots[f, i].tolist()),
                               dof=sem.dof)
                for i, inp in enumerate(sem.inputs)
            )
            systems.append(FuzzySystem(output=output, inputs=inputs,
                                       consts=tuple(consts[f].tolist()), dof=sem.dof))
        return cls(
            name=name, bounds_mode=bounds_mode, systems=tuple(systems),
            provenance=dict(provenance or {}), description=description, semantics=sem,
        )


#: Rulebooks unpickled in this process, by SHA-256 (:meth:`Rulebook.__reduce__`).
_REBUILT: "weakref.WeakValueDictionary[str, Rulebook]" = weakref.WeakValueDictionary()


def _rebuild(name, bounds_mode, systems, provenance, description, semantics="paper",
             dof=_sem.DEFAULT_DOF, sha256=None) -> "Rulebook":
    """A pickled rulebook: the one already rebuilt in this process with the same SHA-256 (the
    same files, hence equal in every field), else a new one that keeps the pickled hash."""
    if sha256 is not None:
        hit = _REBUILT.get(sha256)
        if hit is not None:
            return hit
    rb = Rulebook(name=name, bounds_mode=bounds_mode, systems=systems, provenance=provenance,
                  description=description, semantics=_sem.get(semantics, dof))
    if sha256 is not None:
        rb.__dict__["sha256"] = sha256  # what the cached property would compute
        _REBUILT[sha256] = rb
    return rb


# ------------------------------------------------------------------------- locations


def rulebooks_dir() -> Path:
    """Folder holding the shipped rulebooks (``$XFUZZY_RRT_RULEBOOKS`` overrides it).

    The shipped ones are package data (``xfuzzy_rrt.rulebooks``, the top-level ``rulebooks/``
    folder of a checkout), located through ``importlib.resources`` so that an installed wheel
    finds its own copy (see :mod:`xfuzzy_rrt.resources`).
    """
    env = os.environ.get(RULEBOOKS_ENV)
    if env:
        return Path(env)
    return _shipped_rulebooks_dir()


def rulebook_path(spec: str | os.PathLike[str]) -> Path:
    """The directory a rulebook argument names: ``spec`` itself when it exists; else, for a bare
    name (no path separator, not starting with ``.`` or ``~``), the shipped rulebook of that
    name when there is one; else ``spec`` as given (:func:`load_rulebook` then says it does
    not exist).

    Why: ``evaluate --rulebook`` took a shipped name and ``plan --rulebook``, ``rules``,
    ``explain --rulebook`` and ``train --seed-rulebook`` did not, so ``xfuzzy-rrt rules show
    goal-frame`` failed anywhere but in the project's root. A folder of that name in the
    current directory still wins (it is what the path names)."""
    path = Path(spec)
    text = os.fspath(spec)
    if path.exists() or not _bare_name(text):
        return path
    shipped = rulebooks_dir() / text
    return shipped if shipped.is_dir() else path


def _bare_name(text: str) -> bool:
    """A word that can name a shipped rulebook: no path separator, not ``.``/``~``-led."""
    return bool(text) and "/" not in text and "\\" not in text and not text.startswith((".", "~"))


def _shipped_hint(text: str) -> str:
    """`` (did you mean the shipped 'goal-frame'?)`` for a bare word close to a shipped
    rulebook's name (a typo of one, :func:`rulebook_path` having found no such folder), else
    ``""``."""
    if not _bare_name(text):
        return ""
    import difflib

    close = difflib.get_close_matches(text, [p.name for p in list_rulebooks()], n=1, cutoff=0.8)
    return f" (did you mean the shipped {close[0]!r}?)" if close else ""


@functools.cache
def _shipped_rulebooks_dir() -> Path:
    """The package's own folder: asked of ``importlib.resources`` once per process (~0.5 ms a
    call, as much as a whole plan)."""
    from xfuzzy_rrt.resources import shipped_rulebooks_dir

    return shipped_rulebooks_dir()


def default_rulebook_path() -> Path:
    """Directory of the default rulebook (``goal-frame``: trained on generated problems only)."""
    return rulebooks_dir() / DEFAULT_RULEBOOK


@functools.lru_cache(maxsize=32)
def _shipped_dir_str(env: str | None, name: str) -> str:
    return os.path.abspath(Path(env) / name if env else _shipped_rulebooks_dir() / name)


try:  # os.environ's own store (CPython): what os.environ.get reads, without its key encoding
    _ENV_DATA = os.environ._data
    _ENV_KEY = os.environ.encodekey(RULEBOOKS_ENV)
    _ENV_DECODE = os.environ.decodevalue
except AttributeError:  # another implementation: the public way
    _ENV_DATA = None


def rulebooks_env() -> str | None:
    """``os.environ.get(RULEBOOKS_ENV) or None``, read on every call (the environment may
    change) but ~10x cheaper: ``os.environ.get`` encodes its key each time (~2 us in a VM, a
    fiftieth of a plan call's budget) and, with cold caches, its Python frames and the KeyError
    it catches for an unset variable took ~40 us, more than half of a rulebook label's parse
    (docs/peer-measurements.md, sixteenth session). Assignments to ``os.environ`` update the
    same store."""
    if _ENV_DATA is None:
        return os.environ.get(RULEBOOKS_ENV) or None
    raw = _ENV_DATA.get(_ENV_KEY)
    return _ENV_DECODE(raw) if raw else None


def shipped_rulebook_str(name: str = DEFAULT_RULEBOOK) -> str:
    """``rulebooks_dir() / name`` as an absolute string, what every plan call without a
    rulebook looks up: the environment is read on every call (it may change), the path built
    once per value of it (a ``Path`` join and ``abspath`` cost more than the look-up's stats)."""
    return _shipped_dir_str(rulebooks_env(), name)


def default_rulebook_str() -> str:
    """:func:`default_rulebook_path` as :func:`shipped_rulebook_str` gives it."""
    return shipped_rulebook_str(DEFAULT_RULEBOOK)


def _content_key(root: Path) -> str:
    """SHA-256 over the bytes of the manifest and every FIS file (a missing one counts).

    Why the bytes and not only (mtime, size, inode): ``cp -p``, ``rsync -t`` or ``tar x`` can
    put different bytes of the same size under the same modification time. The bytes are hashed
    only when :func:`_unchanged` says a file may have changed (see :func:`load_rulebook_cached`).
    """
    h = hashlib.sha256()
    fis_names = sorted(p.name for p in root.glob("*" + SUFFIX)) if root.is_dir() else []
    for name in [MANIFEST_NAME, *fis_names]:
        try:
            data = (root / name).read_bytes()
        except OSError:
            h.update(f"{name}\n-\n".encode())
            continue
        h.update(f"{name}\n{len(data)}\n".encode())
        h.update(data)
    return h.hexdigest()


def _stamp(st: os.stat_result) -> tuple[int, int, int, int]:
    return st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino


def _unchanged(paths: tuple[str, ...], stamps: tuple) -> bool:
    """Every one of ``paths`` (the directory first) still has its recorded stamps.

    The stamps are (size, mtime_ns, ctime_ns, inode). Why ctime too: a same-size edit whose
    mtime is put back (``os.utime``, ``touch -r``, ``cp -p``) still sets the ctime to *now*,
    which no user call can forge. The directory's own stamps change when a file is added,
    removed or renamed over (an atomic save), so every file of the directory counts without
    listing it again on every look-up. This is the look-up every plan call makes: one ``stat``
    per path and nothing else (in a VM a stat costs ~3 us, a call's whole budget ~100 us).
    Stops at the first difference."""
    stat = os.stat
    try:
        for p, (size, mtime, ctime, ino) in zip(paths, stamps):
            st = stat(p)
            if st.st_mtime_ns != mtime or st.st_ctime_ns != ctime or st.st_size != size \
                    or st.st_ino != ino:
                return False
    except OSError:
        return False
    return True


def _content_files(root: str) -> tuple[str, ...]:
    """The directory's files whose bytes make the rulebook: its manifest and FIS files.

    Other files (a training ``history.csv``, notes) are not watched one by one: none of them is
    read by :func:`load_rulebook`, and adding, removing or renaming any file changes the
    directory's own stamps anyway."""
    return tuple(n for n in sorted(os.listdir(root)) if n == MANIFEST_NAME or n.endswith(SUFFIX))


#: A file stamped this close to the moment its directory was looked at could be edited again
#: within the same timestamp tick (coarse kernel clocks; 2 s on FAT): such an entry is
#: "racy" and is re-hashed on every look-up until its files are older (as git does). An entry
#: with a kernel watch (:mod:`.watch`) is never racy: the watch was armed before the read.
RACY_WINDOW_NS = 2_000_000_000
#: Directories remembered (each holds its watch's few inotify watches).
MAX_CACHED_DIRS = 64


class _Seen(NamedTuple):
    """The last look-up of one directory path."""

    paths: tuple[str, ...]   # the path as given, then its manifest and FIS files
    stamps: tuple            # (size, mtime_ns, ctime_ns, inode) of each
    root: str                # the real path
    content: str             # the content key of the bytes read
    racy: bool
    rulebook: "Rulebook"
    watch: Any               # a watch.Watch armed before the read, or None (stamps decide)
    place: tuple[int, int]   # (st_dev, st_ino) the path resolved to


#: ``path as given (absolute) -> _Seen``.
_STAT_CACHE: dict[str, _Seen] = {}


@functools.lru_cache(maxsize=16)
def _load_cached(root: str, content: str) -> "Rulebook":
    return load_rulebook(root)


def _still_there(seen: _Seen) -> bool:
    """The path still resolves to the watched directory: a parent renamed or a symlink on the
    path pointed elsewhere sends no notice to a watch on the directory itself (one stat)."""
    try:
        st = os.stat(seen.paths[0])
    except OSError:
        return False
    return st.st_ino == seen.place[1] and st.st_dev == seen.place[0]


def load_rulebook_cached(path: str | os.PathLike[str]) -> "Rulebook":
    """:func:`load_rulebook`, but parse a directory only once while its files' bytes are unchanged.

    Why: library callers plan many times with the default rulebook; parsing 3,750 rules costs
    ~50-130 ms, a plan well under 1 ms. Where the kernel can report changes (Linux inotify on a
    local file system, :mod:`.watch`), a look-up polls the watch armed on the directory and its
    files before they were last read, and stats the path itself (~4 us in all). Elsewhere it
    stats the directory and its manifest and FIS files (:func:`_unchanged`, ~3 us each in a
    VM). Only when a watch reported anything, or a size, mtime, ctime or inode changed, or the
    files are too young to trust their stamps (:data:`RACY_WINDOW_NS`), are the bytes re-read
    and re-hashed, and only new bytes are parsed again. Rulebooks are immutable, so sharing
    one object between calls is safe. An absolute path given as a string is its own key (no
    normalisation on the hot path); any other is made absolute first, so a relative path
    follows the current directory.
    """
    key = path if type(path) is str and path[:1] == "/" else os.path.abspath(path)
    seen = _STAT_CACHE.get(key)
    if seen is not None:
        if seen.watch is not None:
            if seen.watch.fresh() and _still_there(seen):
                return seen.rulebook
        elif not seen.racy and _unchanged(seen.paths, seen.stamps):
            return seen.rulebook
    root = os.path.realpath(path)
    if not os.path.isdir(root):
        return load_rulebook(root)  # raises the usual one-line error
    from xfuzzy_rrt.fuzzy.watch import arm

    # armed before anything is read: a change from here on is reported
    watch = arm(root, lambda d: [os.path.join(d, n) for n in _content_files(d)])
    now = time.time_ns()
    try:
        names = _content_files(root)
        paths = (key, *(os.path.join(key, n) for n in names))
        stamps = tuple(_stamp(os.stat(p)) for p in paths)
        place = os.stat(root)  # what the watch is on; the path must keep resolving to it
    except OSError:
        return load_rulebook(root)
    newest = max(max(st[1], st[2]) for st in stamps)
    content = _content_key(Path(root))
    rulebook = _load_cached(root, content)
    _STAT_CACHE.pop(key, None)
    _STAT_CACHE[key] = _Seen(paths, stamps, root, content,
                             watch is None and newest >= now - RACY_WINDOW_NS, rulebook, watch,
                             (place.st_dev, place.st_ino))
    while len(_STAT_CACHE) > MAX_CACHED_DIRS:
        try:
            del _STAT_CACHE[next(iter(_STAT_CACHE))]
        except (KeyError, StopIteration, RuntimeError):  # another thread trimmed it first
            break
    return rulebook


def list_rulebooks() -> list[Path]:
    """Rulebook directories (those with a manifest) in :func:`rulebooks_dir`, sorted by name."""
    root = rulebooks_dir()
    if not root.is_dir():
        return []
    return sorted(p for p in root.iterdir() if (p / MANIFEST_NAME).is_file())


# ------------------------------------------------------------------------- load / save


def _read(path: Path, problems: list) -> bytes | None:
    try:
        return path.read_bytes()
    except FileNotFoundError:
        problems.append((str(path), None, "missing file"))
    except IsADirectoryError:
        problems.append((str(path), None, "is a directory, expected a file"))
    except OSError as exc:
        problems.append((str(path), None, f"cannot read: {exc.strerror or exc}"))
    return None


def load_rulebook(path: str | os.PathLike[str]) -> Rulebook:
    """Read and validate the rulebook directory *path*.

    Raises :class:`RulebookError` listing every problem found in every file (the directory
    itself missing or unreadable is reported the same way).
    """
    root = Path(path)
    if not root.exists():
        raise RulebookError([(str(root), None, "rulebook directory does not exist"
                              + _shipped_hint(os.fspath(path)))])
    if not root.is_dir():
        raise RulebookError([(str(root), None, "not a directory (a rulebook is a directory)")])
    problems: list[tuple[str, int | None, str]] = []
    try:
        fis_stems = {p.stem for p in root.iterdir() if p.suffix == SUFFIX}
    except OSError as exc:
        raise RulebookError([(str(root), None, f"cannot list directory: {exc.strerror or exc}")]) from None
    known = {o for s in _sem.SEMANTICS.values()
             for d in range(_sem.MIN_DOF, _sem.MAX_DOF + 1) for o in _sem.get(s.name, d).outputs}
    if not (fis_stems & known) and not (root / MANIFEST_NAME).exists():
        # Not a damaged rulebook but no rulebook at all: one line, not seven "missing file"s.
        raise RulebookError([(str(root), None, f"not a rulebook directory (no {MANIFEST_NAME} "
                              f"and no {SUFFIX} files)")])
    manifest = None
    dof_line = None
    data = _read(root / MANIFEST_NAME, problems)
    if data is not None:
        manifest, found = parse_manifest(data, str(root / MANIFEST_NAME))
        problems.extend(found)
        if manifest is not None:
            dof_line = _key_line(data.decode("utf-8").splitlines(), "dof")
    if manifest is not None:
        sem = _sem.get(manifest.semantics, manifest.dof)
    else:  # the manifest's own problems are reported; read the files as what they look like
        sem = _sem.PAPER.for_dof(_sem.dof_of_outputs(_sem.PAPER.name, fis_stems) or _sem.DEFAULT_DOF)
    skip: set[str] = set()
    if sem.name == _sem.PAPER.name:
        skip = _check_bound_files(sem, fis_stems, str(root / MANIFEST_NAME), dof_line, problems)
    for stem in sorted(fis_stems - set(sem.outputs) - skip):
        problems.append(
            (str(root / fis_file_name(stem)), None, f"unexpected FIS file (the {sem.name} "
                                                    f"semantics' outputs are {', '.join(sem.outputs)})")
        )
    systems = []
    for output in sem.outputs:
        if output in skip:
            continue
        file = root / fis_file_name(output)
        data = _read(file, problems)
        if data is None:
            continue
        fis, found = parse_fis(data, str(file), output, sem)
        problems.extend(found)
        systems.append(fis)
    if problems:
        raise RulebookError(problems)
    rulebook = Rulebook(
        name=manifest.name, bounds_mode=manifest.bounds_mode, systems=tuple(systems),
        provenance=manifest.provenance, description=manifest.description, semantics=sem,
    )
    _LOADED_FROM[id(rulebook)] = os.path.abspath(root)
    weakref.finalize(rulebook, _LOADED_FROM.pop, id(rulebook), None)
    return rulebook


#: ``id(rulebook) -> the absolute directory`` :func:`load_rulebook` read it from; an entry
#: leaves with its rulebook (``weakref.finalize``), so an id is never reused while listed.
_LOADED_FROM: dict[int, str] = {}


def loaded_from(rulebook: Any) -> str | None:
    """The absolute directory :func:`load_rulebook` read *rulebook* from (as it was named,
    symlinks kept), or None for one built in memory.

    Why: a caller that loads a rulebook once and plans with a label naming the same folder
    (``bench``, library loops: ``fuzzy-rrt:goal-frame`` with the loaded object) is known to
    pass that folder's rulebook without touching the file system; with cold caches the
    folder's freshness check (a poll and a stat) cost ~120 us of a ~480 us 2-joint call
    (docs/peer-measurements.md, sixteenth session)."""
    return _LOADED_FROM.get(id(rulebook))


_BOUND_FILE = re.compile(r"bound_([1-9][0-9]*)\Z")


def _file_run(stems: list[str]) -> str:
    """``bound_5.fis … bound_10.fis`` for a consecutive run of bound files, else a list."""
    nums = [int(_BOUND_FILE.match(s).group(1)) for s in stems]
    if len(nums) > 2 and nums == list(range(nums[0], nums[0] + len(nums))):
        return f"{fis_file_name(stems[0])} \u2026 {fis_file_name(stems[-1])}"
    return ", ".join(fis_file_name(s) for s in stems)


def _check_bound_files(sem: "_sem.Semantics", stems: set[str], manifest_file: str,
                       dof_line: int | None, problems: list) -> set[str]:
    """Compare the ``bound_K.fis`` files present with those the declared DOF needs.

    Why one line in the manifest rather than one per file: a wrong or missing ``dof`` key is
    the usual cause, and it is the manifest that must be fixed (or the files). Returns the
    bound stems already reported (missing or extra), which the caller then skips.
    """
    want = _sem.bound_outputs(sem.dof)
    have = sorted((s for s in stems if _BOUND_FILE.match(s)),
                  key=lambda s: int(_BOUND_FILE.match(s).group(1)))
    missing = [b for b in want if b not in stems]
    extra = [b for b in have if b not in want]
    if not (missing or extra):
        return set()
    declared = f"dof = {sem.dof}" if dof_line is not None else f"dof = {sem.dof} (no dof key)"
    parts = []
    if missing:
        parts.append(f"{_file_run(missing)} {'is' if len(missing) == 1 else 'are'} missing")
    if extra:
        parts.append(f"{_file_run(extra)} {'is' if len(extra) == 1 else 'are'} extra")
    fits = _sem.dof_of_outputs(sem.name, [o for o in sem.outputs if o not in want] + have)
    hint = f" (the files present fit dof = {fits})" if fits is not None and fits != sem.dof else ""
    problems.append((manifest_file, dof_line,
                     f"{declared} needs {_file_run(list(want))}; {'; '.join(parts)}{hint}"))
    return set(missing) | set(extra)


def save_rulebook(rulebook: Rulebook, path: str | os.PathLike[str], compact: bool = False) -> Path:
    """Write *rulebook* canonically into directory *path* (created if needed); return it.

    All seven texts are rendered first, then written to temporary files beside their
    destinations, then renamed into place; a failure before the renames leaves the directory
    as it was (no partial files). Files other than the rulebook's own are not touched.
    """
    if not isinstance(rulebook, Rulebook):
        raise TypeError(f"expected a Rulebook, got {type(rulebook).__name__}")
    return write_files(path, rulebook.texts(compact=compact))


def write_files(path: str | os.PathLike[str], texts: Mapping[str, str]) -> Path:
    """Write several text files into directory *path* all-or-nothing (as far as POSIX allows).

    Every text goes to a temporary file beside its destination first; only when all are
    written are they renamed into place (``os.replace``, atomic per file).
    """
    root = Path(path)
    if root.exists() and not root.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, "exists and is not a directory", str(root))
    root.mkdir(parents=True, exist_ok=True)
    temps: list[tuple[Path, Path]] = []
    try:
        for file, text in texts.items():
            fd, tmp = tempfile.mkstemp(prefix=f".{file}.", suffix=".tmp", dir=root)
            temps.append((Path(tmp), root / file))
            with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as fh:
                fh.write(text)
            os.chmod(tmp, 0o644)  # mkstemp makes 0600; rulebooks are meant to be shared
        for tmp, dest in temps:
            os.replace(tmp, dest)
    except BaseException:
        for tmp, _ in temps:
            try:
                tmp.unlink()
            except FileNotFoundError:
                pass
        raise
    return root


__all__ += ["BOUNDS_MODES"]
