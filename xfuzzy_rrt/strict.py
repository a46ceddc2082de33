"""Unknown keys in the files the project reads back: the line they sit on and the nearest known name.

Why unknown keys are errors, never warnings: a misspelt key is silently *missing* data. A
scenario with ``[[obstacle]]`` instead of ``[[obstacles]]`` would otherwise plan through an
empty workspace and report success. So every reader (scenarios, ``bench.json``, training
checkpoints) refuses a key it does not know, naming the file, the line when the format has
lines, and the closest key it does know (``difflib``), e.g.::

    error: typo.toml:14: unknown key 'obstacle' (did you mean '[[obstacles]]'?)

The line is found by a small scan of the text rather than by the parser (``tomllib`` and
``json`` do not report positions of keys); when the scan cannot place a key (an inline table,
an unusual layout) the message names the file alone — the key itself is always named.
"""

from __future__ import annotations

import difflib
import json
import re
from typing import Iterable, Sequence

__all__ = ["json_key_line", "nearest", "toml_key_line", "unknown_key_message"]


def nearest(name: str, known: Iterable[str]) -> str | None:
    """The known name closest to ``name`` (``difflib``), compared without TOML brackets."""
    labels = list(known)
    bare = {label.strip("[]"): label for label in labels}
    match = difflib.get_close_matches(name.strip("[]"), list(bare), n=1, cutoff=0.6)
    if not match:
        match = difflib.get_close_matches(name.strip("[]").lower(), list(bare), n=1, cutoff=0.6)
    return bare[match[0]] if match else None


def unknown_key_message(name: str, known: Sequence[str], where: str = "") -> str:
    """``unknown key 'NAME'[ in WHERE] (did you mean 'X'?)`` — or the list of known keys."""
    place = f" in {where}" if where else ""
    guess = nearest(name, known)
    if guess is not None:
        return f"unknown key {name!r}{place} (did you mean {guess!r}?)"
    return f"unknown key {name!r}{place} (known: {', '.join(known)})"


# ------------------------------------------------------------------------------ TOML lines

_BARE_OR_QUOTED = r'(?:[A-Za-z0-9_-]+|"[^"]*"|\'[^\']*\')'
_DOTTED = rf"{_BARE_OR_QUOTED}(?:\s*\.\s*{_BARE_OR_QUOTED})*"
_ARRAY_HEADER = re.compile(rf"^\s*\[\[\s*({_DOTTED})\s*\]\]\s*(?:#.*)?$")
_TABLE_HEADER = re.compile(rf"^\s*\[\s*({_DOTTED})\s*\]\s*(?:#.*)?$")
_KEY_LINE = re.compile(rf"^\s*({_DOTTED})\s*=")


def _parts(dotted: str) -> tuple[str, ...]:
    parts = re.findall(_BARE_OR_QUOTED, dotted)
    return tuple(p[1:-1] if p[:1] in "\"'" else p for p in parts)


def toml_key_line(text: str, path: Sequence[str | int]) -> int | None:
    """1-based line where the key ``path`` is written, or ``None`` when the scan cannot tell.

    ``path`` is the key's place in the parsed document: ``("arm", "linkz")``, ``("obstacle",)``
    for a ``[[obstacle]]`` header, ``("obstacles", 2, "colour")`` for a key of the third
    ``[[obstacles]]`` table. The first line defining anything under ``path`` is returned.
    """
    target = tuple(path)
    counts: dict[tuple, int] = {}
    current: tuple = ()
    for number, line in enumerate(text.splitlines(), start=1):
        m = _ARRAY_HEADER.match(line)
        if m:
            name = _parts(m.group(1))
            counts[name] = counts.get(name, -1) + 1
            current = name + (counts[name],)
            here = current
        else:
            m = _TABLE_HEADER.match(line)
            if m:
                current = _parts(m.group(1))
                here = current
            else:
                m = _KEY_LINE.match(line)
                if not m:
                    continue
                here = current + _parts(m.group(1))
        if here[: len(target)] == target:
            return number
    return None


def json_key_line(text: str, key: str) -> int | None:
    """1-based line of the first ``"key":`` in a JSON text (``None`` when not found)."""
    needle = json.dumps(key) + ":"
    for number, line in enumerate(text.splitlines(), start=1):
        if needle in line.replace('": ', '":'):
            return number
    return None
