"""Per-iteration traces of Fuzzy-RRT as a pandas DataFrame with stable column names.

One row per iteration (``iteration`` = 1..iterations). Columns, in this order:

- ``iteration``, ``from_node`` (the paper's ``nearest_node`` whose end effector the fuzzy
  systems looked at), ``nearest_node`` (the node nearest to this iteration's sample, which
  becomes the next ``from_node``), ``new_node`` (index of the node added, the goal on success,
  or -1), ``tree_size`` (after the iteration);
- ``from_q1_deg``, ``from_q2_deg``; the four inputs ``angle_to_goal, dist_to_goal,
  angle_to_obstacle, dist_to_obstacle`` (radians, metres; as measured, before the engine clamps
  them to the input ranges); the six outputs ``goal_bias, bound_1 .. bound_4, step_size`` (raw
  FIS values); ``box_q1_lo, box_q1_hi, box_q2_lo, box_q2_hi`` (the sampling box actually used:
  ordered, offset for relative rulebooks, clipped to the joint limits); ``step_used_deg``;
  ``sample_q1_deg``, ``sample_q2_deg``, ``new_q1_deg``, ``new_q2_deg``;
- ``goal_sampled``, ``outcome`` (accepted, node_in_collision, edge_blocked, goal_reached,
  no_progress), ``on_path`` (the node added at this iteration lies on the returned path),
  ``rulebook``, ``rulebook_sha256`` (which rulebook made these decisions), and in a trace
  written by ``plan --trace`` ``rulebook_dir`` (the absolute directory it was read from:
  ``explain`` finds an edited copy there; :func:`with_rulebook_dir`);
- with a rulebook of another semantics (e.g. ``goal-frame``) the input and output columns carry
  that semantics' names instead, and the box is the bounding box of its sampling region;
- with more joints, one ``from_q<j>_deg``, ``box_q<j>_lo``/``_hi``, ``sample_q<j>_deg`` and
  ``new_q<j>_deg`` per joint ``j`` = 1..dof (all arms, arm after arm);
- with several arms and the paper's semantics (one fuzzy evaluation per arm) every input,
  output, rule and strength column is prefixed ``arm<a>_`` (``arm1_goal_bias``, ...);
  ``step_used_deg`` is then the smallest arm's step, as the planner used it;
- per FIS ``<output>_rule_<k>`` for k = 0..15, then per FIS ``<output>_strength_<k>``: the
  rules that fired (index into the rulebook's 625, ascending; -1 for unused slots) and their
  normalised strengths (summing to 1).
"""

from __future__ import annotations

import functools

import numpy as np
import pandas as pd

from xfuzzy_rrt.fuzzy.variables import MAX_FIRED
from xfuzzy_rrt.planners.result import OUTCOME_NAMES


def fired_columns(output: str) -> tuple[list[str], list[str]]:
    """Names of the rule-index and strength columns of one FIS."""
    return ([f"{output}_rule_{k}" for k in range(MAX_FIRED)],
            [f"{output}_strength_{k}" for k in range(MAX_FIRED)])


def _columns(names: list[str]) -> pd.Index:
    return pd.Index(names, dtype=object)


_OUTCOME_DTYPE = pd.CategoricalDtype([OUTCOME_NAMES[k] for k in sorted(OUTCOME_NAMES)])
_INT_HEAD = _columns(["iteration", "from_node", "nearest_node", "new_node", "tree_size"])


@functools.lru_cache(maxsize=32)
def _column_blocks(inputs: tuple[str, ...], outputs: tuple[str, ...], dof: int = 2,
                   groups: int = 1):
    """Precomputed column indexes of one semantics (float head, rule and strength blocks)."""
    def prefixed(names):
        if groups == 1:
            return list(names)
        return [f"arm{g + 1}_{n}" for g in range(groups) for n in names]

    joints = range(1, dof + 1)
    box = [c for j in joints for c in (f"box_q{j}_lo", f"box_q{j}_hi")]
    float_head = _columns([*(f"from_q{j}_deg" for j in joints), *prefixed(inputs),
                           *prefixed(outputs), *box, "step_used_deg",
                           *(f"sample_q{j}_deg" for j in joints),
                           *(f"new_q{j}_deg" for j in joints)])
    fis = prefixed(outputs)
    rules = _columns([c for out in fis for c in fired_columns(out)[0]])
    strengths = _columns([c for out in fis for c in fired_columns(out)[1]])
    return float_head, rules, strengths


@functools.lru_cache(maxsize=64)
def _constant_dtype(value: str) -> pd.CategoricalDtype:
    return pd.CategoricalDtype(_columns([value]))


def trace_frame(buffers, iterations: int, nodes: np.ndarray, parent: np.ndarray, last: int,
                rulebook, min_step_deg: float, groups: int = 1) -> pd.DataFrame:
    """Assemble the DataFrame from the kernel's buffers and the final tree.

    Built from a few homogeneous 2-D blocks with precomputed column indexes, in the final
    column order (no reordering copy): pandas' per-column work would otherwise cost more than
    the planning itself.
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

    int_head = np.stack([np.arange(1, n + 1, dtype=np.int64), from_node, buffers.nearest[:n],
                         new_node, buffers.tree[:n]], axis=1)
    n_out = buffers.y.shape[1] // groups
    # the step is each group's last output; the planner uses the smallest
    steps = buffers.y[:n, n_out - 1::n_out].min(axis=1)
    float_head = np.concatenate([
        nodes[from_node], buffers.x[:n], buffers.y[:n], buffers.box[:n],
        np.maximum(steps, min_step_deg)[:, None],
        buffers.sample[:n], buffers.new[:n],
    ], axis=1)
    zeros = np.zeros(n, dtype=np.int8)
    extras = pd.DataFrame({
        "goal_sampled": buffers.goal_sampled[:n].copy(),
        "outcome": pd.Categorical.from_codes(buffers.outcome[:n], dtype=_OUTCOME_DTYPE,
                                             validate=False),
        "on_path": on_path,
        "rulebook": pd.Categorical.from_codes(zeros, dtype=_constant_dtype(rulebook.name),
                                              validate=False),
        "rulebook_sha256": pd.Categorical.from_codes(
            zeros, dtype=_constant_dtype(rulebook.sha256), validate=False),
    })
    float_cols, rule_cols, strength_cols = _column_blocks(
        tuple(rulebook.inputs), tuple(rulebook.outputs), int(nodes.shape[1]), int(groups))
    return pd.concat([
        pd.DataFrame(int_head, columns=_INT_HEAD, copy=False),
        pd.DataFrame(float_head, columns=float_cols, copy=False),
        extras,
        # (reshaped by the column count: a run of no iteration, the start at the goal, has n = 0)
        pd.DataFrame(buffers.rule[:n].reshape(n, len(rule_cols)).astype(np.int64),
                     columns=rule_cols, copy=False),
        pd.DataFrame(buffers.w[:n].reshape(n, len(strength_cols)), columns=strength_cols,
                     copy=False),
    ], axis=1)


def with_rulebook_dir(frame: pd.DataFrame, directory) -> pd.DataFrame:
    """``frame`` with a constant ``rulebook_dir`` column (absolute path) after
    ``rulebook_sha256``; the input frame is not modified."""
    from pathlib import Path

    value = str(Path(directory).resolve())
    out = frame.drop(columns=["rulebook_dir"], errors="ignore")
    column = pd.Categorical.from_codes(np.zeros(len(out), dtype=np.int8),
                                       dtype=_constant_dtype(value), validate=False)
    out.insert(int(out.columns.get_loc("rulebook_sha256")) + 1, "rulebook_dir", column)
    return out
