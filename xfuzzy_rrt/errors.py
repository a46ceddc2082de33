"""Exceptions for bad input, shared by every layer.

Every user-facing failure caused by input (a scenario file, a rulebook, a CLI value) is an
:class:`InputError`. The CLI turns it into exactly one line ``error: <where>: <what>`` on stderr
and exit code 2; nothing else in the library prints. Keeping *where* separate from *what*
lets tests and tools check the location without parsing prose.
"""

from __future__ import annotations


class InputError(Exception):
    """Input that cannot be used. ``where`` names the file (and line or key) at fault."""

    def __init__(self, where: str, message: str) -> None:
        super().__init__(f"{where}: {message}" if where else message)
        self.where = where
        self.message = message


class ScenarioError(InputError):
    """A scenario file that is missing, malformed or describes an impossible problem."""

    def __init__(self, file: str, key: str, message: str) -> None:
        super().__init__(f"{file}: {key}" if key else file, message)
        self.file = file
        self.key = key


class RulebookError(InputError):
    """A rulebook that fails validation. Carries *all* problems found, not just the first.

    ``problems`` is a list of ``(file, line, message)``; ``line`` is ``None`` when the problem
    is not tied to one line (e.g. a missing file).
    """

    def __init__(self, problems: list[tuple[str, int | None, str]]) -> None:
        if not problems:
            raise ValueError("RulebookError needs at least one problem")
        self.problems = list(problems)
        file, line, message = self.problems[0]
        where = f"{file}:{line}" if line is not None else file
        extra = f" (and {len(self.problems) - 1} more)" if len(self.problems) > 1 else ""
        super().__init__(where, message + extra)

    def lines(self) -> list[str]:
        """Each problem as ``file:line: problem`` (``file: problem`` without a line)."""
        out = []
        for file, line, message in self.problems:
            where = f"{file}:{line}" if line is not None else file
            out.append(f"{where}: {message}")
        return out
