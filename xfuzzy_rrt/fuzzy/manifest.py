"""The rulebook manifest ``rulebook.toml``: name, format version, bounds mode, provenance.

Why TOML: it is what the scenario files use, people can edit it, and Python reads it with the
standard library (:mod:`tomllib`). Writing uses the tiny canonical writer below (no new
dependency): fixed key order at the top (``format``, ``format_version``, ``name``,
``bounds_mode``, ``description``), then ``[provenance]`` with its keys in the order given.
Reading a canonical manifest and writing it back gives identical bytes.

Example::

    # xfuzzy-rrt rulebook manifest; the six FIS files (goal_bias.fis ... step_size.fis) sit beside it.
    format = "xfuzzy-rrt-rulebook"
    format_version = 1
    name = "expert"
    bounds_mode = "relative"
    description = "Hand-written default rulebook."

    [provenance]
    kind = "hand-written"
    command = "python scripts/make_expert_rulebook.py"
    date = "2025-01-01"

``bounds_mode`` says how the four bound outputs are meant: ``"absolute"`` joint limits in
degrees (the paper's reading) or ``"relative"`` offsets from the current nearest tree node.
``dof`` (an integer 2..7, the arm's joints) is written only when it is not 2, so every 2-DOF
manifest keeps its bytes and its SHA-256; a missing key means 2. It fixes the FIS files the
directory must hold (see :mod:`.semantics`: a paper rulebook of ``dof = 5`` has
``bound_1.fis … bound_10.fis``). A DOF-free semantics (``goal-frame-any``) writes ``dof = "any"``
instead, and requires it: its rulebook plans every arm.

``provenance`` records what produced the rulebook: at least ``kind`` (e.g. ``"hand-written"``,
``"ga"``, ``"imported-fll"``), typically also ``command``, ``seed``, ``fitness``,
``scenarios`` and ``date``. Any TOML value is allowed there.
"""

from __future__ import annotations

import datetime as _dt
import difflib
import math
import re
import tomllib
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, Mapping

from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.fuzzy.text_format import SUFFIX

MANIFEST_NAME = "rulebook.toml"
FORMAT_NAME = "xfuzzy-rrt-rulebook"
FORMAT_VERSION = 1
BOUNDS_MODES = ("absolute", "relative")
TOP_KEYS = ("format", "format_version", "name", "semantics", "dof", "bounds_mode", "description")
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+\Z")

Problem = tuple[str, "int | None", str]


def _freeze(value: Any) -> Any:
    """Read-only view of nested provenance values (so a frozen Rulebook stays frozen)."""
    if isinstance(value, Mapping):
        return MappingProxyType({str(k): _freeze(v) for k, v in value.items()})
    if isinstance(value, (list, tuple)):
        return tuple(_freeze(v) for v in value)
    return value


def thaw(value: Any) -> Any:
    """Plain ``dict``/``list`` copy of a (frozen) provenance value."""
    if isinstance(value, Mapping):
        return {k: thaw(v) for k, v in value.items()}
    if isinstance(value, tuple):
        return [thaw(v) for v in value]
    return value


@dataclass(frozen=True)
class Manifest:
    """The validated contents of ``rulebook.toml``."""

    name: str
    bounds_mode: str | None
    provenance: Mapping[str, Any] = field(default_factory=dict)
    description: str = ""
    semantics: str = "paper"
    dof: int = _sem.DEFAULT_DOF

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise ValueError("rulebook name must be a non-empty string")
        _sem.get(self.semantics, self.dof)  # raises ValueError when unknown or a bad dof
        if self.semantics == _sem.PAPER.name:
            if self.bounds_mode not in BOUNDS_MODES:
                raise ValueError(f"bounds_mode must be one of {BOUNDS_MODES}, got {self.bounds_mode!r}")
        elif self.bounds_mode is not None:
            raise ValueError(f"bounds_mode belongs to the paper's semantics; a {self.semantics} "
                             f"rulebook has none (got {self.bounds_mode!r})")
        if not isinstance(self.description, str):
            raise ValueError("description must be a string")
        if not isinstance(self.provenance, Mapping):
            raise ValueError("provenance must be a mapping")
        for key in self.provenance:
            if not isinstance(key, str):
                raise ValueError(f"provenance keys must be strings, got {key!r}")
        # validate representability now, not at save time
        _toml_table_lines(["provenance"], thaw(self.provenance))
        object.__setattr__(self, "provenance", _freeze(self.provenance))


# ------------------------------------------------------------------------------ writing


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.match(key) else _toml_string(key)


def _toml_string(s: str) -> str:
    out = ['"']
    for ch in s:
        o = ord(ch)
        if ch == '"':
            out.append('\\"')
        elif ch == "\\":
            out.append("\\\\")
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif o < 0x20 or o == 0x7F:
            out.append(f"\\u{o:04X}")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, (_dt.datetime, _dt.date, _dt.time)):
        return v.isoformat()
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, Mapping):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}" for k, x in v.items()) + " }" if v else "{}"
    # numpy scalars and the like: accept if they are plain numbers underneath
    for kind in (int, float):
        try:
            if hasattr(v, "item") and isinstance(v.item(), kind) and not isinstance(v.item(), bool):
                return _toml_value(v.item())
        except (TypeError, ValueError):
            pass
    raise ValueError(f"cannot write {type(v).__name__} value {v!r} to TOML")


def _toml_table_lines(path: list[str], table: Mapping[str, Any]) -> list[str]:
    """``[path]`` followed by its scalar keys, then its sub-tables (TOML requires that order)."""
    lines = ["[" + ".".join(_toml_key(p) for p in path) + "]"]
    subtables = []
    for k, v in table.items():
        if not isinstance(k, str):
            raise ValueError(f"TOML keys must be strings, got {k!r}")
        if isinstance(v, Mapping):
            subtables.append((k, v))
        else:
            lines.append(f"{_toml_key(k)} = {_toml_value(v)}")
    for k, v in subtables:
        lines.append("")
        lines.extend(_toml_table_lines(path + [k], v))
    return lines


_COUNT_WORDS = {6: "six", 8: "eight", 10: "ten", 12: "twelve", 14: "fourteen", 16: "sixteen"}


def format_manifest(m: Manifest) -> str:
    """Canonical text of a manifest (``semantics`` is written only when it is not the paper's
    and ``dof`` only when it is not 2, so every 2-DOF paper-semantics rulebook keeps its bytes
    and its SHA-256)."""
    outputs = _sem.get(m.semantics, m.dof).outputs
    first, last = outputs[0], outputs[-1]
    count = _COUNT_WORDS.get(len(outputs), str(len(outputs)))
    lines = [
        f"# xfuzzy-rrt rulebook manifest; the {count} FIS files ({first}{SUFFIX} ... {last}{SUFFIX}) sit beside it.",
        f"format = {_toml_string(FORMAT_NAME)}",
        f"format_version = {FORMAT_VERSION}",
        f"name = {_toml_string(m.name)}",
    ]
    if m.semantics != _sem.PAPER.name:
        lines.append(f"semantics = {_toml_string(m.semantics)}")
    if _sem.get(m.semantics, m.dof).dof_free:
        lines.append(f"dof = {_toml_string(_sem.ANY_DOF)}")
    elif m.dof != _sem.DEFAULT_DOF:
        lines.append(f"dof = {m.dof}")
    if m.bounds_mode is not None:
        lines.append(f"bounds_mode = {_toml_string(m.bounds_mode)}")
    if m.description:
        lines.append(f"description = {_toml_string(m.description)}")
    lines.append("")
    lines.extend(_toml_table_lines(["provenance"], thaw(m.provenance)))
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------------ reading


def _key_line(lines: list[str], key: str, table: str | None = None) -> int | None:
    """1-based line where *key* is assigned (within ``[table]`` if given).

    Falls back to the ``[table]`` header line, else ``None``. tomllib reports no positions
    for valid documents, so this small scan gives lint its line numbers.
    """
    current: str | None = None
    header: int | None = None
    pattern = re.compile(r"\s*(?:" + re.escape(key) + r'|"' + re.escape(key) + r'")\s*=')
    for n, line in enumerate(lines, start=1):
        stripped = line.strip()
        if stripped.startswith("["):
            current = stripped.strip("[]").strip()
            if current == table and header is None:
                header = n
            continue
        if current == table and pattern.match(line):
            return n
    return header


def parse_manifest(data: bytes, file: str) -> tuple[Manifest | None, list[Problem]]:
    """Parse and validate ``rulebook.toml``; return the manifest (or None) and all problems."""
    problems: list[Problem] = []
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        return None, [(file, line, f"not valid UTF-8 (byte 0x{data[exc.start]:02x})")]
    try:
        doc = tomllib.loads(text)
    except RecursionError:  # tomllib recurses per nesting level: "[[[[...]]]]" would crash it
        return None, [(file, None, "not valid TOML: arrays or tables nested too deeply")]
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        m = re.search(r"\(at line (\d+), column \d+\)", msg)
        line = int(m.group(1)) if m else None
        if m is None and "end of document" in msg:
            line = text.count("\n") + 1
        msg = re.sub(r"\s*\(at (line \d+, column \d+|end of document)\)", "", msg)
        return None, [(file, line, f"not valid TOML: {msg}")]
    lines = text.splitlines()

    def problem(key: str, message: str, table: str | None = None) -> None:
        problems.append((file, _key_line(lines, key, table) or 1, message))

    for key in doc:
        if key not in TOP_KEYS and key != "provenance":
            near = difflib.get_close_matches(key, [*TOP_KEYS, "provenance"], n=1)
            hint = f" (did you mean {near[0]!r}?)" if near else ""
            problem(key, f"unknown key {key!r}{hint}; known: {', '.join(TOP_KEYS)} and [provenance]")
    fmt = doc.get("format")
    if fmt is None:
        problems.append((file, 1, f'missing key format = "{FORMAT_NAME}"'))
    elif fmt != FORMAT_NAME:
        problem("format", f"format must be {FORMAT_NAME!r}, got {fmt!r}")
    version = doc.get("format_version")
    if version is None:
        problems.append((file, 1, f"missing key format_version = {FORMAT_VERSION}"))
    elif type(version) is not int or version != FORMAT_VERSION:
        problem("format_version", f"unsupported format_version {version!r} (this version reads {FORMAT_VERSION})")
    name = doc.get("name")
    if name is None:
        problems.append((file, 1, "missing key name"))
    elif not isinstance(name, str) or not name.strip():
        problem("name", f"name must be a non-empty string, got {name!r}")
    sem_name = doc.get("semantics", _sem.PAPER.name)
    if sem_name not in _sem.SEMANTICS:
        problem("semantics", f"semantics must be one of {', '.join(map(repr, _sem.SEMANTICS))}, got {sem_name!r}")
        sem_name = _sem.PAPER.name
    dof = doc.get("dof", _sem.DEFAULT_DOF)
    if _sem.SEMANTICS[sem_name].dof_free:  # one rulebook for every arm: it says so
        if dof != _sem.ANY_DOF:
            problem("dof", f'a {sem_name} rulebook plans any arm: write dof = "{_sem.ANY_DOF}"'
                    + (f", not {dof!r}" if "dof" in doc else ""))
        dof = _sem.DEFAULT_DOF
    elif dof == _sem.ANY_DOF:
        problem("dof", f'dof = "{_sem.ANY_DOF}" needs a DOF-free semantics '
                f"({', '.join(n for n, s in _sem.SEMANTICS.items() if s.dof_free)}); "
                f"a {sem_name} rulebook is for one number of joints")
        dof = _sem.DEFAULT_DOF
    dof_problem = _sem.dof_problem(dof)
    if dof_problem:
        problem("dof", dof_problem)
        dof = _sem.DEFAULT_DOF
    mode = doc.get("bounds_mode")
    if sem_name != _sem.PAPER.name:
        if mode is not None:
            problem("bounds_mode", f"bounds_mode belongs to the paper's semantics; remove it "
                                   f"from a {sem_name} rulebook")
    elif mode is None:
        problems.append((file, 1, f"missing key bounds_mode ({' or '.join(BOUNDS_MODES)})"))
    elif mode not in BOUNDS_MODES:
        problem("bounds_mode", f"bounds_mode must be {' or '.join(repr(b) for b in BOUNDS_MODES)}, got {mode!r}")
    description = doc.get("description", "")
    if not isinstance(description, str):
        problem("description", "description must be a string")
    prov = doc.get("provenance")
    if prov is None:
        problems.append((file, len(lines) or 1, "missing [provenance] table (at least kind = ...)"))
    elif not isinstance(prov, dict):
        problem("provenance", "provenance must be a table")
    else:
        kind = prov.get("kind")
        if not isinstance(kind, str) or not kind:
            problems.append(
                (file, _key_line(lines, "kind", "provenance") or len(lines) or 1,
                 "provenance needs kind = \"...\" (e.g. \"hand-written\", \"ga\")")
            )
    if problems:
        return None, problems
    return Manifest(name=name, bounds_mode=mode, provenance=prov, description=description,
                    semantics=sem_name, dof=dof), []
