"""Per-iteration traces of Fuzzy-RRT as a pandas DataFrame with stable column names.

One row per iteration (``iteration`` = 1..iterations). Columns:

- ``from_node``, ``from_q1_deg``, ``from_q2_deg``: the paper's ``nearest_node`` whose end
  effector the fuzzy systems looked at;
- the four inputs ``angle_to_goal, dist_to_goal, angle_to_obstacle, dist_to_obstacle``
  (radians, metres; as measured, before the engine clamps them to the input ranges);
- the six outputs ``goal_bias, bound_1 .. bound_4, step_size`` (raw FIS values);
- ``box_q1_lo, box_q1_hi, box_q2_lo, box_q2_hi``: the sampling box actually used (ordered,
  offset for relative rulebooks, clipped to the joint limits); ``step_used_deg``;
- ``goal_sampled``, ``sample_q1_deg``, ``sample_q2_deg``, ``nearest_node``, ``new_q1_deg``,
  ``new_q2_deg``, ``outcome`` (accepted, node_in_collision, edge_blocked, goal_reached,
  no_progress), ``new_node`` (index or -1), ``tree_size`` (after the iteration), ``on_path``
  (the node added at this iteration lies on the returned path);
- per FIS ``<output>_rule_<k>`` and ``<output>_strength_<k>`` for k = 0..15: the rules that
  fired (index into the rulebook's 625, ascending; -1 for unused slots) and their normalised
  strengths (summing to 1);
- ``rulebook``, ``rulebook_sha256``: which rulebook made these decisions.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from xfuzzy_rrt.fuzzy.variables import INPUTS, MAX_FIRED, OUTPUTS
from xfuzzy_rrt.planners.result import OUTCOME_NAMES


def fired_columns(output: str) -> tuple[list[str], list[str]]:
    """Names of the rule-index and strength columns of one FIS."""
    return ([f"{output}_rule_{k}" for k in range(MAX_FIRED)],
            [f"{output}_strength_{k}" for k in range(MAX_FIRED)])


def trace_frame(buffers, iterations: int, nodes: np.ndarray, parent: np.ndarray, last: int,
                rulebook, min_step_deg: float) -> pd.DataFrame:
    """Assemble the DataFrame from the kernel's buffers and the final tree.

    Built from a few 2-D blocks rather than 200+ separate columns: pandas' per-column checks
    would otherwise cost more than the planning itself.
    """
    n = int(iterations)
    from_node = buffers.from_node[:n]
    on_path_nodes = np.zeros(len(parent), dtype=bool)
    i = int(last)
    while i >= 0:
        on_path_nodes[i] = True
        i = int(parent[i])
    new_node = buffers.node[:n]
    on_path = np.zeros(n, dtype=bool)
    added = new_node >= 0
    on_path[added] = on_path_nodes[new_node[added]]

    rule_names: list[str] = []
    w_names: list[str] = []
    for name in OUTPUTS:
        r_cols, w_cols = fired_columns(name)
        rule_names += r_cols
        w_names += w_cols
    # Two homogeneous 2-D blocks (ints, floats) plus a few typed columns: building 200+
    # separate columns would make pandas' per-column checks cost more than the planning.
    int_block = np.concatenate([
        np.arange(1, n + 1, dtype=np.int64)[:, None], from_node[:, None],
        buffers.nearest[:n, None], new_node[:, None], buffers.tree[:n, None],
        buffers.rule[:n].reshape(n, -1).astype(np.int64),
    ], axis=1)
    int_names = ["iteration", "from_node", "nearest_node", "new_node", "tree_size", *rule_names]
    float_block = np.concatenate([
        nodes[from_node], buffers.x[:n], buffers.y[:n], buffers.box[:n],
        np.maximum(buffers.y[:n, OUTPUTS.index("step_size")], min_step_deg)[:, None],
        buffers.sample[:n], buffers.new[:n], buffers.w[:n].reshape(n, -1),
    ], axis=1)
    float_names = ["from_q1_deg", "from_q2_deg", *INPUTS, *OUTPUTS, "box_q1_lo", "box_q1_hi",
                   "box_q2_lo", "box_q2_hi", "step_used_deg", "sample_q1_deg", "sample_q2_deg",
                   "new_q1_deg", "new_q2_deg", *w_names]
    ints = pd.DataFrame(int_block, columns=pd.Index(int_names, dtype=object), copy=False)
    floats = pd.DataFrame(float_block, columns=pd.Index(float_names, dtype=object), copy=False)
    outcome = pd.Categorical.from_codes(buffers.outcome[:n].astype(np.int64),
                                        categories=[OUTCOME_NAMES[k] for k in sorted(OUTCOME_NAMES)])
    frame = pd.concat([ints, floats], axis=1)
    frame["goal_sampled"] = buffers.goal_sampled[:n].copy()
    frame["outcome"] = outcome
    frame["on_path"] = on_path
    frame["rulebook"] = pd.Categorical.from_codes(np.zeros(n, dtype=np.int64), [rulebook.name])
    frame["rulebook_sha256"] = pd.Categorical.from_codes(np.zeros(n, dtype=np.int64),
                                                         [rulebook.sha256])
    order = [*TRACE_HEAD, *rule_names, *w_names, "rulebook", "rulebook_sha256"]
    return frame[order]


#: The leading columns of a trace, in order (the fired-rule columns follow).
TRACE_HEAD = ["iteration", "from_node", "from_q1_deg", "from_q2_deg", *INPUTS, *OUTPUTS,
              "box_q1_lo", "box_q1_hi", "box_q2_lo", "box_q2_hi", "step_used_deg",
              "goal_sampled", "sample_q1_deg", "sample_q2_deg", "nearest_node", "new_q1_deg",
              "new_q2_deg", "outcome", "new_node", "tree_size", "on_path"]
