"""The reproduce commands in rulebooks/README.md are the commands the manifests record.

A README that says ``--generations 40`` for a rulebook whose manifest records 120 reproduces a
different rulebook; this test compares every command the README gives for a shipped rulebook
(``--out rulebooks/NAME``) with that rulebook's ``[provenance] command``, token by token.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from xfuzzy_rrt.fuzzy.rulebook import list_rulebooks, load_rulebook

PROJECT = Path(__file__).resolve().parents[1]
README = PROJECT / "rulebooks" / "README.md"


def readme_commands(text: str) -> dict[str, list[str]]:
    """``{rulebook name: tokens}`` of each command in a ```bash block writing rulebooks/NAME."""
    out: dict[str, list[str]] = {}
    for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S):
        for command in block.replace("\\\n", " ").splitlines():
            tokens = shlex.split(command)
            if "--out" in tokens:
                target = tokens[tokens.index("--out") + 1]
                m = re.fullmatch(r"rulebooks/([\w-]+)/?", target)
                if m:
                    assert m.group(1) not in out, f"two commands write rulebooks/{m.group(1)}"
                    out[m.group(1)] = tokens
    return out


COMMANDS = readme_commands(README.read_text(encoding="utf-8"))
SHIPPED = list_rulebooks()


@pytest.mark.parametrize("folder", SHIPPED, ids=lambda p: p.name)
def test_readme_reproduce_command_is_the_manifests(folder):
    recorded = shlex.split(load_rulebook(folder).provenance["command"])
    assert folder.name in COMMANDS, f"rulebooks/README.md gives no command for {folder.name}/"
    given = COMMANDS[folder.name]
    if recorded[:2] == ["xfuzzy-rrt", "train"]:
        assert given == recorded
    else:  # a script: the manifest records it without the output folder
        assert given[: len(recorded)] == recorded


def test_every_readme_command_names_a_shipped_rulebook():
    assert set(COMMANDS) == {p.name for p in SHIPPED}


def test_a_changed_option_is_caught():
    # the case: the README said --generations 40, the manifest 120
    text = README.read_text(encoding="utf-8").replace("--generations 120", "--generations 40")
    general = load_rulebook(PROJECT / "rulebooks" / "general").provenance["command"]
    assert readme_commands(text)["general"] != shlex.split(general)
