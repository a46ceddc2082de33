"""Files shipped inside the package, found through :mod:`importlib.resources`.

Why not paths relative to ``__file__``: the rulebooks live in the project's top-level
``rulebooks/`` folder and are *mapped* into the package (``xfuzzy_rrt.rulebooks``, see
pyproject.toml), so "two folders up from this module" is right in a checkout and wrong in an
installed wheel. ``importlib.resources`` asks the import system where the package really is:
the source folder for an editable install, ``site-packages`` for a wheel. Nothing here looks
outside the package (no ``../shared``): what the commands need is shipped.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

#: The package holding the shipped rulebooks (pyproject.toml maps it to ``rulebooks/``).
RULEBOOKS_PACKAGE = "xfuzzy_rrt.rulebooks"
#: The paper's reference problem, a copy of ``shared/scenarios/paper-reference.toml`` kept
#: apart from the demo scenarios (nothing is tuned or trained on it).
PAPER_REFERENCE = ("data", "reference", "paper-reference.toml")


def _as_path(traversable) -> Path:
    """A real file-system path: the package is always installed unpacked (wheel or editable),
    never imported from a zip file."""
    return Path(str(traversable))


def shipped_rulebooks_dir() -> Path:
    """Folder of the shipped rulebooks (``general``, ``expert``, ``paper``, README.md)."""
    return _as_path(resources.files(RULEBOOKS_PACKAGE))


def paper_reference_scenario() -> Path:
    """The paper's reference problem (a MIRA-like arm weaving around five tissue obstacles)."""
    return _as_path(resources.files("xfuzzy_rrt").joinpath(*PAPER_REFERENCE))


def demo_scenarios() -> list[Path]:
    """The hand-made demo scenarios shipped with the package, sorted by name."""
    folder = _as_path(resources.files("xfuzzy_rrt").joinpath("data", "scenarios"))
    return sorted(folder.glob("*.toml"))
