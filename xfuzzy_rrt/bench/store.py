"""The on-disk bench folder: everything ``xfuzzy-rrt report DIR`` needs, without re-planning.

Layout (all written atomically, file by file)::

    runs.csv              one row per run (SPEC.md columns + certified, penetration_m, ...)
    summary.csv           one row per (scenario, planner), recomputable from runs.csv
    ratios.csv            per planner pair: median-iteration ratio distribution over scenarios
    bench.json            settings, provenance (command, date, versions, git, machine), every
                          scenario file (path, SHA-256 and its TOML text) and the rulebook
                          (directory, SHA-256, training history)
    examples/index.json   the example runs (median-iteration run per scenario and planner):
                          bookkeeping and path
    examples/eNN-tree.parquet   their search trees
    examples/eNN-trace.parquet  Fuzzy-RRT traces (what the drill-down explains)
    examples/worst.json   per planner, the found run closest to (or deepest into) an obstacle:
                          bookkeeping and path (the report's certification panel)

Why the scenario text is copied into ``bench.json``: it is a few hundred bytes and makes the
folder self-contained (the files may move or change after the benchmark; the SHA-256 records
which version was used). The rulebook is *referenced* (directory + SHA-256; 0.5 MB of text is
not worth copying): rebuilding the report checks that the rulebook found is the same one.
"""

from __future__ import annotations

import json
import tomllib
from pathlib import Path
from typing import Any

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
WORST_JSON = "worst.json"


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
    return _plain({"format": FORMAT, "format_version": FORMAT_VERSION, **provenance,
                   "settings": settings, "scenarios": scenarios, "rulebook": rb})


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
    folder.mkdir(parents=True, exist_ok=True)
    index = []
    for k, ((scen, planner), r) in enumerate(sorted(
            result.examples.items(), key=lambda kv: (list(result.scenarios).index(kv[0][0])
                                                     if kv[0][0] in result.scenarios else 1 << 30,
                                                     kv[0][1]))):
        stem = f"e{k:03d}"
        tree = pd.DataFrame({"q1_deg": np.asarray(r.tree_nodes_deg, dtype=np.float64)[:, 0],
                             "q2_deg": np.asarray(r.tree_nodes_deg, dtype=np.float64)[:, 1],
                             "parent": np.asarray(r.tree_parent, dtype=np.int64)})
        with atomic_path(folder / f"{stem}-tree.parquet") as tmp:
            tree.to_parquet(tmp, index=False)
        trace_file = None
        if isinstance(r.trace, pd.DataFrame):
            trace_file = f"{stem}-trace.parquet"
            with atomic_path(folder / trace_file) as tmp:
                r.trace.to_parquet(tmp, index=False)
        index.append({
            "scenario": scen, "planner": planner, "seed": int(r.seed), "success": bool(r.success),
            "iterations": int(r.iterations), "nodes": int(r.nodes), "cost_deg": r.cost_deg,
            "wall_s": float(r.wall_s), "rulebook": r.rulebook,
            "rulebook_sha256": r.rulebook_sha256, "params": _plain(dict(r.params or {})),
            "path_deg": np.asarray(r.path_deg, dtype=np.float64).tolist(),
            "tree": f"{stem}-tree.parquet", "trace": trace_file,
        })
    write_text_atomic(folder / "index.json", _json(_plain(index)))
    # The worst-clearance found run of each planner (the report's certification panel): the
    # path only, no tree.
    worst = [{"planner": p, "scenario": r.scenario, "seed": int(r.seed),
              "success": bool(r.success), "iterations": int(r.iterations), "nodes": int(r.nodes),
              "cost_deg": r.cost_deg, "wall_s": float(r.wall_s), "rulebook": r.rulebook,
              "rulebook_sha256": r.rulebook_sha256, "params": _plain(dict(r.params or {})),
              "path_deg": np.asarray(r.path_deg, dtype=np.float64).tolist()}
             for p, r in getattr(result, "worst", {}).items()]
    write_text_atomic(folder / WORST_JSON, _json(_plain(worst)))


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
    if "certified" in runs:
        runs["certified"] = runs["certified"].astype("boolean")
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
        from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

        rb_dir = rulebook if rulebook is not None else rb_meta.get("dir")
        if not rb_dir or not Path(rb_dir).is_dir():
            raise InputError(str(rb_dir or where), "the rulebook this benchmark used is not "
                             "there; pass its directory with --rulebook")
        rb = load_rulebook(rb_dir)
        if rb.sha256 != rb_meta.get("sha256"):
            raise InputError(str(rb_dir), f"rulebook sha256 {rb.sha256[:12]}… is not the one "
                             f"this benchmark used ({str(rb_meta.get('sha256'))[:12]}…)")
    if history is not None:
        if not Path(history).is_file():
            raise InputError(str(history), "no such file")
    examples = _read_examples(folder / EXAMPLES)
    result = BenchResult(runs=runs, summary=summary, examples=examples, scenarios=scenarios,
                         settings=dict(meta.get("settings") or {}), rulebook=rb, ratios=ratios,
                         worst=_read_worst(folder / EXAMPLES / WORST_JSON))
    result = _with_provenance(result, meta)
    if history is not None:
        result.provenance["history"] = str(Path(history).resolve())
    return result


def _read_worst(path: Path) -> dict[str, PlanResult]:
    """The worst-clearance runs (absent in folders written before they were stored)."""
    if not path.is_file():
        return {}
    out = {}
    for e in _read_json(path):
        out[str(e["planner"])] = PlanResult(
            scenario=str(e["scenario"]), planner=str(e["planner"]), seed=int(e["seed"]),
            success=bool(e["success"]), iterations=int(e["iterations"]), nodes=int(e["nodes"]),
            cost_deg=e["cost_deg"], wall_s=float(e["wall_s"]),
            path_deg=np.asarray(e["path_deg"], dtype=np.float64).reshape(-1, 2),
            tree_nodes_deg=np.empty((0, 2)), tree_parent=np.empty(0, dtype=np.int64),
            rulebook=e.get("rulebook"), rulebook_sha256=e.get("rulebook_sha256"),
            params=dict(e.get("params") or {}))
    return out


def _read_examples(folder: Path) -> dict[tuple[str, str], PlanResult]:
    index = _read_json(folder / "index.json")
    out = {}
    for e in index:
        try:
            tree = pd.read_parquet(folder / e["tree"])
            trace = pd.read_parquet(folder / e["trace"]) if e.get("trace") else None
        except Exception as exc:  # missing or unreadable parquet
            raise InputError(str(folder), f"example {e.get('tree')}: cannot read: {exc}") from None
        path = np.asarray(e["path_deg"], dtype=np.float64).reshape(-1, 2)
        out[(str(e["scenario"]), str(e["planner"]))] = PlanResult(
            scenario=str(e["scenario"]), planner=str(e["planner"]), seed=int(e["seed"]),
            success=bool(e["success"]), iterations=int(e["iterations"]), nodes=int(e["nodes"]),
            cost_deg=e["cost_deg"], wall_s=float(e["wall_s"]), path_deg=path,
            tree_nodes_deg=tree[["q1_deg", "q2_deg"]].to_numpy(dtype=np.float64),
            tree_parent=tree["parent"].to_numpy(dtype=np.int64), rulebook=e.get("rulebook"),
            rulebook_sha256=e.get("rulebook_sha256"), params=dict(e.get("params") or {}),
            trace=trace)
    return out
