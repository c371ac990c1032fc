"""Diagnostics about problem files, and the error that carries them.

This module imports only the standard library, so the command line can use it without paying
for the loader's dependencies.

A :class:`Diagnostic` is one message about one place in a file, printed the way compilers do::

    blocks.yaml:12:19: error: objects.T.shape: unknown shape 'tea'; expected one of the shapes
    declared under 'shapes' (tee, zed) or an inline {box: [w, h]}, {polygon: [...]},
    {convex_parts: [...]}

A :class:`ProblemFormatError` is raised when a file has at least one error; it carries every
diagnostic found in the file (errors and warnings), so a user fixes a file in one pass.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal

Severity = Literal["error", "warning"]


@dataclass(frozen=True)
class Diagnostic:
    """One problem found in a problem file.

    ``line`` and ``column`` are 1-based and point where the offending YAML node starts (the key
    for unknown or duplicate keys); they are ``None`` when the problem concerns the file as a
    whole (for instance a file that cannot be read). ``path`` is the key path of the node, such
    as ``objects.T.shape`` or ``initial.C.pose[2]`` (``""`` for the whole file). ``message``
    says what is wrong and what was expected.
    """

    file: str
    line: int | None
    column: int | None
    path: str
    message: str
    severity: Severity = "error"

    @property
    def is_error(self) -> bool:
        return self.severity == "error"

    def __str__(self) -> str:
        where = self.file
        if self.line is not None:
            where += f":{self.line}"
            if self.column is not None:
                where += f":{self.column}"
        path = f"{self.path}: " if self.path else ""
        return f"{where}: {self.severity}: {path}{self.message}"


def sort_diagnostics(diagnostics: Iterable[Diagnostic]) -> list[Diagnostic]:
    """Diagnostics in file order (file-level ones first), stable for equal positions."""
    return sorted(diagnostics, key=lambda d: (d.file, d.line or 0, d.column or 0))


class ProblemFormatError(ValueError):
    """A problem file was refused. ``diagnostics`` lists everything found in it, in file order:
    at least one error, plus any warnings; ``str()`` gives one diagnostic per line."""

    def __init__(self, diagnostics: Iterable[Diagnostic]) -> None:
        self.diagnostics: tuple[Diagnostic, ...] = tuple(diagnostics)
        super().__init__("\n".join(str(d) for d in self.diagnostics))

    @property
    def errors(self) -> tuple[Diagnostic, ...]:
        return tuple(d for d in self.diagnostics if d.severity == "error")

    @property
    def warnings(self) -> tuple[Diagnostic, ...]:
        return tuple(d for d in self.diagnostics if d.severity == "warning")

    def __str__(self) -> str:
        return "\n".join(str(d) for d in self.diagnostics)
