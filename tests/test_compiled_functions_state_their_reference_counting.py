"""Every compiled function says whether it may allocate (``_nrt=True``) or not (``_nrt=False``).

Why: the planner and training loops and the geometry and tree helpers they call are compiled
without numba's reference counting (``_nrt=False``), which made 2-joint RRT and the training
loop 1.7-1.8x faster (its atomic increments and decrements were a third of their time). numba
gives a function that does not state the flag the flag of whichever compilation first reaches
it: a helper that allocates would then compile when a counted caller reached it first and fail
("NRT required") when an uncounted loop did, depending on the order of first calls and on what
numba's cache held. Stating the flag everywhere makes each function's compilation the same
whoever calls it.
Functions inlined at numba's IR level (``inline="always"``) take their caller's flag and are
exempt.
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "xfuzzy_rrt"


def _compiled_functions():
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef):
                for dec in node.decorator_list:
                    text = ast.unparse(dec)
                    if "njit" in text or "jit(" in text:
                        yield path.relative_to(PACKAGE.parent), node.name, text


def test_the_package_has_compiled_functions_to_check():
    assert sum(1 for _ in _compiled_functions()) > 100


def test_every_compiled_function_not_inlined_states_its_reference_counting():
    missing = [f"{path}: {name} ({text})" for path, name, text in _compiled_functions()
               if "inline" not in text and "_nrt=" not in text]
    assert missing == []


def test_the_planner_and_training_loops_run_without_reference_counting():
    loops = {("xfuzzy_rrt/planners/rrt.py", "_rrt_loop"),
             ("xfuzzy_rrt/planners/fuzzy_rrt.py", "_fuzzy_rrt_loop"),
             ("xfuzzy_rrt/planners/goal_frame.py", "_goal_frame_loop"),
             ("xfuzzy_rrt/planners/connect.py", "_connect_loop"),
             ("xfuzzy_rrt/training/memo.py", "paper_run"),
             ("xfuzzy_rrt/geometry/collision.py", "edge_free_two_link"),
             ("xfuzzy_rrt/planners/tree.py", "_grid_nearest_occ"),
             ("xfuzzy_rrt/fuzzy/engine.py", "infer")}
    flags = {(str(path), name): text for path, name, text in _compiled_functions()}
    for key in loops:
        assert "_nrt=False" in flags[key], key
