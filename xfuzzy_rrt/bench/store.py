"""The on-disk bench folder: everything ``xfuzzy-rrt report DIR`` needs, without re-planning.

Layout (written into a hidden sibling folder, then swapped in as a whole -- see
:func:`staged_folder` -- so a folder never mixes two benchmarks' files)::

    runs.csv              one row per run (SPEC.md columns + certified, penetration_m, ...)
    summary.csv           one row per (scenario, planner), recomputable from runs.csv
    ratios.csv            per planner pair: median-iteration ratio distribution over scenarios
    bench.json            settings, provenance (command, date, versions, git, machine), every
                          scenario file (path, SHA-256 and its TOML text) and the rulebook
                          (directory, SHA-256, training history)
    examples/index.json   the example runs per scenario and planner -- the median-iteration
                          run (role "median") and the returned path closest to an obstacle
                          (role "worst") -- bookkeeping and path
    examples/eNN-tree.parquet   their search trees
    examples/eNN-trace.parquet  Fuzzy-RRT traces (what the drill-down explains)

Why the scenario text is copied into ``bench.json``: it is a few hundred bytes and makes the
folder self-contained (the files may move or change after the benchmark; the SHA-256 records
which version was used). The rulebook is *referenced* (directory + SHA-256; 0.5 MB of text is
not worth copying): rebuilding the report checks that the rulebook found is the same one.
"""

from __future__ import annotations

import contextlib
import json
import os
import secrets
import shutil
import signal
import tempfile
import tomllib
from pathlib import Path
from typing import Any, Iterable, Iterator

import numpy as np
import pandas as pd

from xfuzzy_rrt.atomic import atomic_path, write_text_atomic
from xfuzzy_rrt.bench.runner import BenchResult
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.planners.result import PlanResult

FORMAT = "xfuzzy-rrt-bench"
FORMAT_VERSION = 1
BENCH_JSON = "bench.json"
EXAMPLES = "examples"


def _json(obj: Any) -> str:
    return json.dumps(obj, indent=1, ensure_ascii=False, allow_nan=False) + "\n"


def _plain(x: Any) -> Any:
    """numpy scalars and NaN to JSON-able values."""
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return _plain(x.tolist())
    if isinstance(x, (np.bool_, bool)):
        return bool(x)
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(x) if np.isfinite(x) else None
    return x


def history_path(rulebook, rulebook_dir: str | None) -> str | None:
    """The training history the rulebook manifest names (``[provenance] history``), if present."""
    if rulebook is None or not rulebook_dir:
        return None
    rel = (rulebook.provenance or {}).get("history")
    if not isinstance(rel, str) or not rel:
        return None
    path = (Path(rulebook_dir) / rel).resolve()
    return str(path) if path.is_file() else None


def bench_json(result: BenchResult, provenance: dict[str, Any]) -> dict[str, Any]:
    from xfuzzy_rrt.bench.provenance import sha256_file

    scenarios = []
    for name, s in result.scenarios.items():
        entry: dict[str, Any] = {"name": name, "file": s.source or None, "sha256": None,
                                 "toml": None}
        if s.source and Path(s.source).is_file():
            entry["file"] = str(Path(s.source).resolve())
            entry["sha256"] = sha256_file(s.source)
            entry["toml"] = Path(s.source).read_text(encoding="utf-8")
        scenarios.append(entry)
    settings = dict(result.settings)
    rb = None
    if result.rulebook is not None:
        rb = {"name": result.rulebook.name, "dir": settings.get("rulebook_dir"),
              "sha256": result.rulebook.sha256,
              "history": history_path(result.rulebook, settings.get("rulebook_dir"))}
    dirs = {e["planner"]: e.get("dir") for e in settings.get("rulebooks") or []}
    rulebooks = [{"planner": label, "name": book.name, "dir": dirs.get(label),
                  "sha256": book.sha256, "history": history_path(book, dirs.get(label))}
                 for label, book in (result.rulebooks or {}).items()]
    return _plain({"format": FORMAT, "format_version": FORMAT_VERSION, **provenance,
                   "settings": settings, "scenarios": scenarios, "rulebook": rb,
                   "rulebooks": rulebooks})


def write_bench_dir(result: BenchResult, out: Path, provenance: dict[str, Any]) -> BenchResult:
    """Write the tables, ``bench.json`` and the example runs; return ``result`` with its
    provenance filled in (for the report)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with atomic_path(out / "runs.csv") as tmp:
        result.runs.to_csv(tmp, index=False, float_format="%.17g")
    with atomic_path(out / "summary.csv") as tmp:
        result.summary.to_csv(tmp, index=False, float_format="%.17g")
    ratios = result.ratios if result.ratios is not None else pd.DataFrame()
    with atomic_path(out / "ratios.csv") as tmp:
        ratios.to_csv(tmp, index=False, float_format="%.17g")
    meta = bench_json(result, provenance)
    _write_examples(result, out / EXAMPLES)
    write_text_atomic(out / BENCH_JSON, _json(meta))
    return _with_provenance(result, meta)


def _with_provenance(result: BenchResult, meta: dict[str, Any]) -> BenchResult:
    import dataclasses

    prov = {k: meta.get(k) for k in ("command", "date", "versions", "git", "machine")}
    prov["scenarios"] = {e["name"]: {"file": e.get("file"), "sha256": e.get("sha256")}
                         for e in meta.get("scenarios", [])}
    prov["rulebook"] = meta.get("rulebook")
    prov["history"] = (meta.get("rulebook") or {}).get("history")
    return dataclasses.replace(result, provenance=prov)


def _write_examples(result: BenchResult, folder: Path) -> None:
    """The median run (``role: median``) and the closest-to-an-obstacle run (``role: worst``)
    of each (scenario, planner); a worst run that is the median run shares its files."""
    folder.mkdir(parents=True, exist_ok=True)
    order = list(result.scenarios)

    def key(kv):
        (scen, planner), _ = kv
        return (order.index(scen) if scen in order else 1 << 30, planner)

    index = []
    stems: dict[tuple[str, str, int], tuple[str, str | None]] = {}
    entries = [("median", kv) for kv in sorted(result.examples.items(), key=key)]
    entries += [("worst", kv) for kv in sorted((result.worst_examples or {}).items(), key=key)]
    for role, ((scen, planner), r) in entries:
        known = stems.get((scen, planner, int(r.seed)))
        if known is None:
            stem = f"e{len(stems):03d}"
            nodes = np.asarray(r.tree_nodes_deg, dtype=np.float64)
            # every joint (q1_deg .. qN_deg): an N-DOF example reads back whole
            tree = pd.DataFrame({**{f"q{j + 1}_deg": nodes[:, j] for j in range(nodes.shape[1])},
                                 "parent": np.asarray(r.tree_parent, dtype=np.int64)})
            with atomic_path(folder / f"{stem}-tree.parquet") as tmp:
                tree.to_parquet(tmp, index=False)
            trace_file = None
            if isinstance(r.trace, pd.DataFrame):
                trace_file = f"{stem}-trace.parquet"
                with atomic_path(folder / trace_file) as tmp:
                    r.trace.to_parquet(tmp, index=False)
            known = stems[(scen, planner, int(r.seed))] = (f"{stem}-tree.parquet", trace_file)
        index.append({
            "role": role, "scenario": scen, "planner": planner,
            "planner_used": r.planner_used or r.planner, "seed": int(r.seed),
            "success": bool(r.success), "found": bool(r.found), "certified": bool(r.certified),
            "min_clearance_m": r.min_clearance_m, "penetration_m": r.penetration_m,
            "violation": r.violation, "iterations": int(r.iterations), "nodes": int(r.nodes),
            "cost_deg": r.cost_deg, "wall_s": float(r.wall_s), "work": r.work,
            "rulebook": r.rulebook,
            "rulebook_sha256": r.rulebook_sha256, "params": _plain(dict(r.params or {})),
            "path_deg": np.asarray(r.path_deg, dtype=np.float64).tolist(),
            "tree": known[0], "trace": known[1],
        })
    write_text_atomic(folder / "index.json", _json(_plain(index)))


# ----------------------------------------------------------------------------------------------
# Replacing a folder as a set
# ----------------------------------------------------------------------------------------------

def _nearest_existing(path: Path) -> Path:
    path = Path(os.path.abspath(path))
    while not path.exists() and path != path.parent:
        path = path.parent
    return path


def check_out_dir(out: Path, inputs: Iterable[Path] = (), keep: Iterable[str] = ()) -> None:
    """Refuse, before any planning, an ``--out`` the bench could not (or must not) replace.

    ``out`` must be a directory or not exist; an existing one must be empty or a bench folder
    (it holds ``bench.json``), because a bench replaces the whole folder and must never delete
    files it did not write -- entries named in ``keep`` (e.g. the demo's ``scenarios``) are
    carried over and exempt. For the same reason no input file may lie inside it, outside
    ``keep``. Whether the place is writable is checked by :func:`staged_folder`, which creates
    the new folder's sibling at once.
    """
    out = Path(out)
    keep = set(keep)
    if out.exists() and not out.is_dir():
        raise InputError(str(out), "exists and is not a directory (--out names a folder)")
    if out.is_dir():
        try:
            entries = [e for e in out.iterdir() if e.name not in keep]
        except OSError as exc:
            raise InputError(str(out), f"cannot read: {exc.strerror or exc}") from None
        if entries and not (out / BENCH_JSON).is_file():
            raise InputError(str(out), "is not empty and not a bench folder (no bench.json); "
                             "a bench replaces its output folder as a whole, so choose a new "
                             "or empty folder")
    root = out.resolve()
    for p in inputs:
        p = Path(p).resolve()
        if root in p.parents and p.relative_to(root).parts[0] not in keep:
            raise InputError(str(p), f"lies inside --out {out}, which the bench replaces; "
                             "move it or choose another --out")


@contextlib.contextmanager
def staged_folder(out: Path, keep: Iterable[str] = ()) -> Iterator[Path]:
    """Yield an empty hidden folder beside ``out``; on success it *becomes* ``out``.

    Why: a bench folder is one consistent set of files (tables, examples, report). Writing them
    in place, a second bench into the same folder would leave stale ``examples/`` beside new
    tables, and an interruption would mix two benchmarks. Here everything is written into the
    hidden sibling; only when the block succeeds are the ``keep`` entries of the old folder
    moved into it and the old folder swapped out by two renames (Ctrl-C is held back during the
    swap, so the result is the previous complete folder or the new one). On any failure,
    Ctrl-C included, the sibling is removed and ``out`` is untouched.

    The sibling is created at once, so an unwritable ``out`` fails here, before any planning,
    with one error naming ``out`` (not the hidden folder).
    """
    out = Path(out)
    keep = tuple(keep)
    anchor = _nearest_existing(out.parent)
    if not anchor.is_dir():
        raise InputError(str(out), f"cannot create it: {anchor} is not a directory")
    try:
        stage = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".staging", dir=anchor))
    except OSError as exc:
        raise InputError(str(out), f"cannot write here: {exc.strerror or exc}") from None
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(stage, 0o777 & ~umask)
        yield stage
        _swap_in(stage, out, keep)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise


def _swap_in(stage: Path, out: Path, keep: tuple[str, ...]) -> None:
    """Make ``stage`` the folder ``out`` (the old one's ``keep`` entries carried over)."""
    old_mask = None
    with contextlib.suppress(AttributeError, ValueError):
        old_mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
            if stage.parent.resolve() != out.parent.resolve():
                moved = out.parent / stage.name
                os.rename(stage, moved)
                stage = moved
            if out.is_dir():
                for name in keep:
                    if (out / name).exists() and not (stage / name).exists():
                        os.rename(out / name, stage / name)
                old = out.parent / f".{out.name}.{secrets.token_hex(4)}.old"
                os.rename(out, old)
                os.rename(stage, out)
                shutil.rmtree(old, ignore_errors=True)
            else:
                os.rename(stage, out)
        except OSError as exc:
            shutil.rmtree(stage, ignore_errors=True)
            raise InputError(str(out), f"cannot replace it: {exc.strerror or exc}") from None
    finally:
        if old_mask is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, old_mask)


# ----------------------------------------------------------------------------------------------
# Reading
# ----------------------------------------------------------------------------------------------

def _read_json(path: Path) -> Any:
    if not path.is_file():
        raise InputError(str(path), "missing (not a folder written by 'xfuzzy-rrt bench')")
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(str(path), f"not valid JSON: {exc}") from None


def _read_csv(path: Path) -> pd.DataFrame:
    if not path.is_file():
        raise InputError(str(path), "missing (not a folder written by 'xfuzzy-rrt bench')")
    try:
        return pd.read_csv(path, keep_default_na=True)
    except Exception as exc:  # pandas raises many types for unreadable files
        raise InputError(str(path), f"cannot read: {exc}") from None


def read_runs(path: Path) -> pd.DataFrame:
    """``runs.csv`` with its booleans typed (``certified`` is empty for failed runs)."""
    runs = _read_csv(path)
    missing = [c for c in ("scenario", "planner", "seed", "success", "iterations") if c not in runs]
    if missing:
        raise InputError(str(path), f"missing column(s) {', '.join(missing)}")
    runs["scenario"] = runs["scenario"].astype(str)
    runs["success"] = runs["success"].astype(bool)
    for col in ("found", "certified"):
        if col in runs:
            runs[col] = runs[col].astype("boolean").fillna(False).astype(bool)
    return runs


def _scenario(entry: dict[str, Any], where: str):
    from xfuzzy_rrt.geometry.scenario import load_scenario, scenario_from_dict

    text = entry.get("toml")
    file = entry.get("file") or entry.get("name", "<scenario>")
    if text is None:
        if entry.get("file") and Path(entry["file"]).is_file():
            return load_scenario(entry["file"])
        return None
    try:
        return scenario_from_dict(tomllib.loads(text), file)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(where, f"scenario {entry.get('name')!r}: {exc}") from None


def load_bench_dir(folder: Path, rulebook: Path | None = None,
                   history: Path | None = None) -> BenchResult:
    """Rebuild a :class:`BenchResult` from a bench folder (no planning).

    ``rulebook`` overrides the recorded rulebook directory (it must have the recorded SHA-256);
    ``history`` names a training ``history.csv`` to show instead of the rulebook's own.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(str(folder), "not a directory")
    meta = _read_json(folder / BENCH_JSON)
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise InputError(str(folder / BENCH_JSON), f"format: expected {FORMAT!r}")
    from xfuzzy_rrt.bench.provenance import check_bench_json

    check_bench_json(meta, folder / BENCH_JSON)
    runs = read_runs(folder / "runs.csv")
    summary = _read_csv(folder / "summary.csv")
    summary["scenario"] = summary["scenario"].astype(str)
    ratios_path = folder / "ratios.csv"
    ratios = None
    if ratios_path.is_file() and ratios_path.stat().st_size > 1:
        ratios = _read_csv(ratios_path)
    where = str(folder / BENCH_JSON)
    scenarios = {}
    for entry in meta.get("scenarios", []):
        s = _scenario(entry, where)
        if s is not None:
            scenarios[entry["name"]] = s
    rb = None
    rb_meta = meta.get("rulebook")
    if rb_meta:
        rb = _load_recorded_rulebook(rb_meta, rulebook, where)
    rulebooks = {}
    for entry in meta.get("rulebooks") or []:
        if rb is not None and entry.get("sha256") == rb.sha256:
            rulebooks[entry["planner"]] = rb
        else:
            rulebooks[entry["planner"]] = _load_recorded_rulebook(entry, None, where)
    if history is not None:
        if not Path(history).is_file():
            raise InputError(str(history), "no such file")
    examples, worst = _read_examples(folder / EXAMPLES)
    result = BenchResult(runs=runs, summary=summary, examples=examples, scenarios=scenarios,
                         settings=dict(meta.get("settings") or {}), rulebook=rb, ratios=ratios,
                         rulebooks=rulebooks, worst_examples=worst)
    result = _with_provenance(result, meta)
    if history is not None:
        result.provenance["history"] = str(Path(history).resolve())
    return result


def _load_recorded_rulebook(entry: dict[str, Any], override, where: str):
    """The rulebook a bench recorded, found at its directory (or ``override``) with its SHA-256."""
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    rb_dir = override if override is not None else entry.get("dir")
    if not rb_dir or not Path(rb_dir).is_dir():
        raise InputError(str(rb_dir or where), "the rulebook this benchmark used is not "
                         "there; pass its directory with --rulebook")
    rb = load_rulebook(rb_dir)
    if rb.sha256 != entry.get("sha256"):
        raise InputError(str(rb_dir), f"rulebook sha256 {rb.sha256[:12]}… is not the one "
                         f"this benchmark used ({str(entry.get('sha256'))[:12]}…)")
    return rb


def _read_examples(folder: Path) -> tuple[dict[tuple[str, str], PlanResult],
                                          dict[tuple[str, str], PlanResult]]:
    """``(median examples, worst examples)``; entries without a role are median runs."""
    index = _read_json(folder / "index.json")
    out: dict[tuple[str, str], PlanResult] = {}
    worst: dict[tuple[str, str], PlanResult] = {}
    for e in index:
        try:
            tree = pd.read_parquet(folder / e["tree"])
            trace = pd.read_parquet(folder / e["trace"]) if e.get("trace") else None
        except Exception as exc:  # missing or unreadable parquet
            raise InputError(str(folder), f"example {e.get('tree')}: cannot read: {exc}") from None
        joints = [c for c in tree.columns if c.startswith("q") and c.endswith("_deg")]
        joints.sort(key=lambda c: int(c[1:-4]))  # q1_deg .. qN_deg (folders before: q1, q2)
        path = np.asarray(e["path_deg"], dtype=np.float64).reshape(-1, len(joints))
        # Folders written before found/certified existed: their "success" meant "found", and
        # only certified examples were drawn.
        found = bool(e.get("found", e["success"]))
        target = worst if e.get("role") == "worst" else out
        target[(str(e["scenario"]), str(e["planner"]))] = PlanResult(
            scenario=str(e["scenario"]), planner=str(e["planner"]), seed=int(e["seed"]),
            found=found, certified=found and bool(e.get("certified", e["success"])),
            min_clearance_m=e.get("min_clearance_m"), penetration_m=e.get("penetration_m"),
            violation=e.get("violation"), iterations=int(e["iterations"]), nodes=int(e["nodes"]),
            cost_deg=e["cost_deg"], wall_s=float(e["wall_s"]), path_deg=path,
            tree_nodes_deg=tree[joints].to_numpy(dtype=np.float64),
            tree_parent=tree["parent"].to_numpy(dtype=np.int64), rulebook=e.get("rulebook"),
            rulebook_sha256=e.get("rulebook_sha256"), params=dict(e.get("params") or {}),
            trace=trace, work=None if e.get("work") is None else int(e["work"]),
            planner_used=e.get("planner_used"))
    return out, worst
