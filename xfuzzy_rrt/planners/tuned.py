"""Tuned planner parameters (placeholder until branch ``fair`` lands its version).

``tuned_params(label)`` returns the tuned settings of a planner label, or ``None`` when no tuned
file exists; branch ``fair`` owns this module and the shipped files (interfaces.md item 3).
"""

from __future__ import annotations


def tuned_params(label: str) -> dict[str, float] | None:
    """No tuned files on this branch yet: every label falls back to its defaults."""
    return None
