"""Files read back (a bench folder's bench.json) refuse keys they do not know, with line and hint.

(Scenarios: tests/test_scenario_loading.py; checkpoints: tests/test_training.py.) A key this
version does not write is either a typo or a file from another version: ignoring it would let
a report state provenance that is not there.
"""

from __future__ import annotations

import json
import sys

import pytest

from conftest import FIXTURES

TWO_CIRCLES = FIXTURES / "scenarios" / "two-circles.toml"


@pytest.fixture(scope="module")
def bench_folder(tmp_path_factory):
    from xfuzzy_rrt.bench.provenance import collect
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.bench.store import write_bench_dir
    from xfuzzy_rrt.geometry.scenario import load_scenario

    result = run_benchmark([load_scenario(TWO_CIRCLES)], ["rrt"], runs=1, max_iter=300)
    out = tmp_path_factory.mktemp("bench")
    write_bench_dir(result, out, collect("test"))
    return out


def test_bench_json_records_the_versions_the_numbers_depend_on(bench_folder):
    import numba
    import numpy
    import pymoo
    import scipy

    versions = json.loads((bench_folder / "bench.json").read_text())["versions"]
    assert versions["python"] == ".".join(map(str, sys.version_info[:3]))
    for module in (numpy, numba, scipy):
        assert versions[module.__name__] == module.__version__
    assert versions["pymoo"] == pymoo.__version__


def test_a_bench_folder_reads_back_as_written(bench_folder):
    from xfuzzy_rrt.bench.store import load_bench_dir

    assert load_bench_dir(bench_folder).provenance["command"] == "test"


@pytest.mark.parametrize("where,key,hint", [
    ((), "comand", "'command'"),
    (("git",), "comit", "'commit'"),
    (("settings",), "max_iters", "'max_iter'"),
])
def test_an_unknown_key_in_bench_json_is_an_error_with_line_and_nearest_name(
        bench_folder, tmp_path, where, key, hint):
    import shutil

    from xfuzzy_rrt.bench.store import load_bench_dir
    from xfuzzy_rrt.errors import InputError

    folder = tmp_path / "b"
    shutil.copytree(bench_folder, folder)
    path = folder / "bench.json"
    meta = json.loads(path.read_text())
    node = meta
    for part in where:
        node = node[part]
    node[key] = 1
    text = json.dumps(meta, indent=1)
    path.write_text(text)
    line = next(n for n, s in enumerate(text.splitlines(), 1) if f'"{key}":' in s)
    with pytest.raises(InputError) as info:
        load_bench_dir(folder)
    message = str(info.value)
    assert message.startswith(f"{path}:{line}: unknown key '{key}'"), message
    assert f"(did you mean {hint}?)" in message


def test_report_on_a_bench_json_with_an_unknown_key_is_one_error_line(bench_folder, tmp_path,
                                                                      run_cli):
    import shutil

    folder = tmp_path / "b"
    shutil.copytree(bench_folder, folder)
    path = folder / "bench.json"
    meta = json.loads(path.read_text())
    meta["rulebok"] = None
    path.write_text(json.dumps(meta, indent=1))
    proc = run_cli("report", folder)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {path}:"), proc.stderr
    assert "unknown key 'rulebok' in bench.json (did you mean 'rulebook'?)" in lines[0]
