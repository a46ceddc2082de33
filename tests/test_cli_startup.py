"""The console script starts without loading the heavy numeric stack."""

from __future__ import annotations

import subprocess
import sys


def test_cli_module_import_does_not_load_numba_pandas_or_plotly():
    code = ("import sys, xfuzzy_rrt.cli.main; "
            "print(','.join(m for m in ('numba', 'pandas', 'plotly', 'numpy') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_help_lists_the_commands(run_cli):
    proc = run_cli("--help")
    assert proc.returncode == 0
    for command in ("plan", "rules"):
        assert command in proc.stdout
