"""Small rendering helpers shared by the CLI modules (the only place that prints)."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from xfuzzy_rrt.atomic import write_text_atomic


def warn(message: str) -> None:
    sys.stderr.write(f"warning: {message}\n")


def load_scenario_warn(path: Path):
    """Load a scenario (an unknown key is an error there, not a warning: see xfuzzy_rrt.strict)."""
    from xfuzzy_rrt.geometry.scenario import load_scenario

    return load_scenario(path)


def format_json(obj: dict[str, Any]) -> str:
    """One top-level key per line, values compact (a path stays one readable line per key)."""
    lines = [f"  {json.dumps(k)}: {json.dumps(v)}" for k, v in obj.items()]
    return "{\n" + ",\n".join(lines) + "\n}\n"


def emit_json(obj: dict[str, Any], out: Path | None) -> None:
    """Write JSON to ``out`` atomically, or to stdout."""
    text = format_json(obj)
    if out is None:
        sys.stdout.write(text)
    else:
        write_text_atomic(out, text)
