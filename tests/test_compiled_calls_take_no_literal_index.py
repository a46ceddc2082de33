"""The clearance and stop-record helpers are never called with a constant node or row index.

Why: numba compiles a call whose argument is an integer constant as its own specialisation
(the argument typed ``Literal[int](0)``), so ``node_clearance(P, T, 0)`` made a second compiled
copy of ``node_clearance`` and of the stop-record code under it, beside the copy ``extend``
runs with a runtime index. Both copies are fetched from memory on a cold call: removing the
literal took a cold two-arm Fuzzy-RRT-Connect call from 4,517 to 4,420 last-level misses
(``benchmarks/cold_misses.py``, docs/peer-measurements.md, twenty-seventh session). Plans do not
change either way, so only this check keeps the copy from coming back.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "xfuzzy_rrt"
#: helper -> the position of its index argument
INDEXED = {"node_clearance": 2, "node_stop_into": 6, "stop_record_into": 6}


def _calls():
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                    and node.func.id in INDEXED and len(node.args) > INDEXED[node.func.id]:
                yield path.relative_to(PACKAGE.parent), node


def test_the_indexed_helpers_are_called_somewhere():
    assert {node.func.id for _, node in _calls()} == set(INDEXED)


def test_no_indexed_helper_is_called_with_a_constant_index():
    literal = [f"{path}:{node.lineno}: {ast.unparse(node)}" for path, node in _calls()
               if isinstance(node.args[INDEXED[node.func.id]], ast.Constant)]
    assert literal == []
