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

import unicodedata
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal

Severity = Literal["error", "warning"]


def printable(text: str, *, keep_newlines: bool = False) -> str:
    """``text`` with every control or format character (ANSI escapes, a bidi override, a NUL)
    written as Python writes it in a string literal (``\\x1b``, ``\\u202e``), every other
    character unchanged: a name from a file, echoed in a message, cannot then recolour or
    rewrite the user's terminal, and an ordinary name reads exactly as written. With
    ``keep_newlines`` a newline stays a line break (a message of several lines)."""
    if text.isprintable():  # the usual case: nothing to escape, no per-character work
        return text
    return "".join(
        char
        if (char == "\n" and keep_newlines)
        or unicodedata.category(char) not in _UNPRINTABLE_CATEGORIES
        else repr(char)[1:-1]
        for char in text
    )


# Control (C0, DEL, C1) and format characters (bidi overrides, zero-width ones): the ones a
# terminal acts on or that hide what a name really is. Spaces and letters of any script stay.
_UNPRINTABLE_CATEGORIES = frozenset({"Cc", "Cf"})


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
        # Every part may hold text from the user's file (a key path holds key names, a
        # message quotes them): all are made printable here, the one place diagnostics are
        # turned into text.
        where = printable(self.file)
        if self.line is not None:
            where += f":{self.line}"
            if self.column is not None:
                where += f":{self.column}"
        path = f"{printable(self.path)}: " if self.path else ""
        return f"{where}: {self.severity}: {path}{printable(self.message, keep_newlines=True)}"


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
