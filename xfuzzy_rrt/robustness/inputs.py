"""The planned paths a robustness analysis reads: a plan result JSON, or a bench folder.

A result JSON (``xfuzzy-rrt plan --out``) names its scenario but does not contain it, so the
scenario file is given beside it. A bench folder is self-contained: ``bench.json`` carries the
text of every scenario and ``examples/index.json`` the example path of each (scenario,
planner). Bad input is one :class:`~xfuzzy_rrt.errors.InputError` naming the file.
"""

from __future__ import annotations

import json
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from xfuzzy_rrt.errors import InputError


@dataclass(frozen=True)
class PlannedPath:
    """One path to analyse, with the scenario it was planned in."""

    scenario: object  # a Scenario
    planner: str
    seed: int
    path_deg: np.ndarray
    source: str

    @property
    def label(self) -> str:
        return f"{self.scenario.name} {self.planner} seed {self.seed}"


def _read_json(path: Path):
    try:
        return json.loads(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(str(path), "no such file") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(str(path), f"not a JSON file: {exc}") from None


def _path_array(value, dof: int, where: str) -> np.ndarray:
    try:
        path = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(where, "path_deg: must be a list of joint-angle lists") from None
    if path.ndim != 2 or path.shape[1] != dof or path.shape[0] < 1:
        raise InputError(where, f"path_deg: must be a non-empty [n, {dof}] list of angles "
                         f"(the run found no path?), got shape {path.shape}")
    if not np.all(np.isfinite(path)):
        raise InputError(where, "path_deg: contains non-finite angles")
    return path


def load_result_path(scenario, result_file: Path) -> PlannedPath:
    """The path of a ``plan`` result JSON planned in ``scenario`` (names must agree)."""
    data = _read_json(result_file)
    where = str(result_file)
    if not isinstance(data, dict) or "path_deg" not in data:
        raise InputError(where, "not a plan result (no 'path_deg')")
    name = data.get("scenario")
    if name is not None and name != scenario.name:
        raise InputError(where, f"scenario: this result was planned in {name!r}, not in "
                         f"{scenario.name!r} ({scenario.source or 'the scenario given'})")
    path = _path_array(data["path_deg"], scenario.dof, where)
    return PlannedPath(scenario, str(data.get("planner", "?")), int(data.get("seed", 0) or 0),
                       path, where)


def load_bench_paths(folder: Path) -> list[PlannedPath]:
    """Every example path of a bench folder (median-iteration run per scenario and planner)."""
    from xfuzzy_rrt.geometry.scenario import scenario_from_dict

    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(str(folder), "not a directory")
    meta = _read_json(folder / "bench.json")
    index = _read_json(folder / "examples" / "index.json")
    where = str(folder / "bench.json")
    scenarios = {}
    for entry in (meta.get("scenarios") or []) if isinstance(meta, dict) else []:
        text = entry.get("toml")
        if text is None:
            continue
        try:
            scenarios[entry["name"]] = scenario_from_dict(tomllib.loads(text),
                                                          entry.get("file") or entry["name"])
        except tomllib.TOMLDecodeError as exc:
            raise InputError(where, f"scenario {entry.get('name')!r}: {exc}") from None
    out = []
    for e in index if isinstance(index, list) else []:
        s = scenarios.get(str(e.get("scenario")))
        if s is None or not e.get("path_deg"):
            continue
        out.append(PlannedPath(s, str(e.get("planner")), int(e.get("seed", 0) or 0),
                               _path_array(e["path_deg"], s.dof, str(folder / "examples")),
                               str(folder)))
    if not out:
        raise InputError(str(folder), "no example path to analyse (examples/index.json)")
    return out
