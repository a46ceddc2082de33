"""FLL interop: export -> import is exact; pyfuzzylite 8 agrees with ``rules eval`` (≤ 1e-9)."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from xfuzzy_rrt.errors import RulebookError
from xfuzzy_rrt.fuzzy.fll import export_fll, import_fll
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
from xfuzzy_rrt.fuzzy.variables import INPUTS

from _rulebook_helpers import EXPERT, random_inputs, random_rulebook

PROJECT = Path(__file__).resolve().parents[1]
PYFUZZYLITE_ENV = "XFUZZY_PYFUZZYLITE_PYTHON"


@pytest.mark.parametrize("which", ["expert", "random"])
def test_export_then_import_reproduces_the_arrays_exactly(which, tmp_path):
    rb = load_rulebook(EXPERT) if which == "expert" else random_rulebook(np.random.default_rng(8))
    paths = export_fll(rb, tmp_path / "fll")
    assert [p.name for p in paths] == [f"{s.output}.fll" for s in rb.systems]
    back = import_fll(tmp_path / "fll")
    for a, b in zip(rb.arrays(), back.arrays()):
        assert np.array_equal(a, b)
    assert back.name == rb.name and back.bounds_mode == rb.bounds_mode
    assert back.provenance["kind"] == "imported-fll"
    assert back.provenance["source_sha256"] == rb.sha256
    assert [s.inputs for s in back.systems] == [s.inputs for s in rb.systems]  # term names too


def test_export_follows_the_spec_interop_notes(tmp_path):
    export_fll(load_rulebook(EXPERT), tmp_path)
    text = (tmp_path / "goal_bias.fll").read_text()
    for needle in ("aggregation: none", "defuzzifier: WeightedAverage TakagiSugeno",
                   "conjunction: AlgebraicProduct", "activation: General",
                   "term: east_0 Ramp 1.5707963267948966 0", "term: r624 Constant"):
        assert needle in text
    assert "0.14999999999999999" in text  # 17 significant digits


def test_import_reports_unsupported_semantics_with_file_and_line(tmp_path):
    export_fll(load_rulebook(EXPERT), tmp_path)
    f = tmp_path / "bound_1.fll"
    f.write_text(f.read_text().replace("aggregation: none", "aggregation: Maximum")
                 .replace("term: north Triangle 0 ", "term: north Trapezoid 0 0 "))
    (tmp_path / "step_size.fll").unlink()
    with pytest.raises(RulebookError) as info:
        import_fll(tmp_path)
    msgs = info.value.lines()
    assert any("bound_1.fll:" in m and "aggregation 'Maximum'" in m for m in msgs)
    assert any("bound_1.fll:" in m and "Trapezoid" in m for m in msgs)
    assert any("step_size.fll: missing file" in m for m in msgs)


def test_import_accepts_infinite_triangle_shoulders(tmp_path):
    rb = load_rulebook(EXPERT)
    export_fll(rb, tmp_path)
    f = tmp_path / "step_size.fll"
    text = f.read_text().replace("term: very_near Ramp 0.14999999999999999 0",
                                 "term: very_near Triangle -inf 0 0.14999999999999999")
    f.write_text(text.replace("term: very_far Ramp 0.45000000000000001 0.59999999999999998",
                              "term: very_far Triangle 0.45000000000000001 0.59999999999999998 inf"))
    assert np.array_equal(import_fll(tmp_path).arrays()[1], rb.arrays()[1])


def test_pyfuzzylite_agrees_with_rules_eval(tmp_path, run_cli):
    python = os.environ.get(PYFUZZYLITE_ENV)
    if not python:
        pytest.skip(f"set {PYFUZZYLITE_ENV} to a Python with pyfuzzylite 8 installed "
                    "(python3 -m venv /tmp/fll-env && /tmp/fll-env/bin/pip install 'pyfuzzylite==8.*')")
    for name, rb_dir in (("expert", EXPERT), ("random", None)):
        if rb_dir is None:
            from xfuzzy_rrt.fuzzy.rulebook import save_rulebook

            rb_dir = save_rulebook(random_rulebook(np.random.default_rng(21)), tmp_path / "random")
        X = random_inputs(np.random.default_rng(4), 3000, margin=0.2)
        inp = tmp_path / f"{name}-in.csv"
        inp.write_text(",".join(INPUTS) + "\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in X) + "\n")
        out = tmp_path / f"{name}-out.csv"
        assert run_cli("rules", "eval", rb_dir, "--input", inp, "--output", out).returncode == 0
        assert run_cli("rules", "export", rb_dir, "--format", "fll", "--out", tmp_path / name).returncode == 0
        proc = subprocess.run(
            [python, str(PROJECT / "scripts" / "check_fll_pyfuzzylite.py"), str(tmp_path / name), str(out)],
            capture_output=True, text=True, timeout=600,
        )
        assert proc.returncode == 0, proc.stdout + proc.stderr
        result = json.loads(proc.stdout)
        assert result["pyfuzzylite"].startswith("8.")
        assert result["max"] <= 1e-9


def test_import_names_a_term_named_twice_with_its_file_and_line(tmp_path):
    # found by the FLL fuzzer: a ValueError traceback from the partition's own check
    export_fll(load_rulebook(EXPERT), tmp_path)
    f = tmp_path / "bound_1.fll"
    text = f.read_text()
    south = "term: south Triangle 3.1415926535897931 4.7123889803846897 6.2831853071795862"
    assert south in text
    f.write_text(text.replace(south, south.replace("south", "north"), 1))
    with pytest.raises(RulebookError) as info:
        import_fll(tmp_path)
    msgs = info.value.lines()
    line = next(n for n, row in enumerate(f.read_text().splitlines(), 1)
                if row.strip().startswith("term: north Triangle 3.14"))
    assert any(f"bound_1.fll:{line}:" in m and "'north' is named twice" in m for m in msgs), msgs
