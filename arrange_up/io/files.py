"""Small file helpers shared by the readers and the resumable result files: where a file stops
being UTF-8, an exclusive lock that refuses a second writer, and the complete lines of a
``.jsonl`` record (a line cut off by a kill dropped, a file of another kind refused) and its
records by number (one recorded twice with different outcomes refused)."""

from __future__ import annotations

import json
import os
import stat
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import IO, TypeVar

try:
    import fcntl

    _HAS_FCNTL = True
except ImportError:  # pragma: no cover - not on POSIX: files are not locked
    _HAS_FCNTL = False

__all__ = [
    "MAX_PROBLEM_BYTES",
    "ProblemFileTooLarge",
    "lock_exclusively",
    "numbered_records",
    "read_problem_bytes",
    "recorded_lines",
    "text_place",
    "undecodable_place",
]

R = TypeVar("R")

#: The largest problem file (YAML or PDDL) read, in bytes: 1 MiB. A real problem is a few
#: kilobytes; the parsers' time and memory grow with the file (docs/design/io.md), so a file
#: hundreds of times bigger than any real problem is refused before it is parsed.
MAX_PROBLEM_BYTES = 1024 * 1024


class ProblemFileTooLarge(ValueError):
    """A problem file holds more than :data:`MAX_PROBLEM_BYTES`; ``size`` is its size in bytes
    (for a stream without a size, such as a pipe, ``stream`` is set and ``size`` is the limit:
    the message says "more than"). ``str()`` is the message, without the file's name (the
    caller adds it)."""

    def __init__(self, size: int, limit: int, *, stream: bool = False) -> None:
        self.size = size
        self.limit = limit
        more = "more than " if stream else ""
        super().__init__(
            f"the file is too large: {more}{size:,} bytes; expected a problem file of at most "
            f"{limit:,} bytes (a real problem is a few kilobytes)"
        )


def read_problem_bytes(path: Path, limit: int = MAX_PROBLEM_BYTES) -> bytes:
    """The bytes of the problem file ``path``, raising :class:`ProblemFileTooLarge` *before*
    reading it when it is larger than ``limit`` bytes. A regular file's size is known up front;
    anything else (a pipe, ``/dev/stdin``) is read up to ``limit + 1`` bytes and refused if
    that much arrives, so an endless stream is never read to its end. Raises ``OSError`` as
    ``Path.read_bytes`` does (missing file, a directory, no permission)."""
    with path.open("rb") as handle:
        status = os.fstat(handle.fileno())
        if stat.S_ISREG(status.st_mode) and status.st_size > limit:
            raise ProblemFileTooLarge(status.st_size, limit)
        data = handle.read(limit + 1)
    if len(data) > limit:
        raise ProblemFileTooLarge(limit, limit, stream=True)
    return data


def text_place(text: str | bytes, index: int) -> tuple[int, int]:
    """The 1-based ``(line, column)`` of position ``index`` in ``text`` (characters of a
    string, bytes of bytes)."""
    before = text[:index]
    if isinstance(before, bytes):
        newlines, line_start = before.count(b"\n"), before.rfind(b"\n") + 1
    else:
        newlines, line_start = before.count("\n"), before.rfind("\n") + 1
    return newlines + 1, len(before) - line_start + 1


def undecodable_place(data: bytes, error: UnicodeDecodeError) -> tuple[int, int]:
    """The 1-based ``(line, column)`` in ``data`` of the byte ``error`` (from decoding ``data``)
    says is not UTF-8."""
    return text_place(data, error.start)


def lock_exclusively(handle: IO[bytes]) -> bool:
    """Take an exclusive lock on the open file ``handle`` without waiting; False when another
    process holds one (the lock ends when the handle is closed). Where the platform has no
    ``fcntl``, files are not locked and this returns True."""
    if not _HAS_FCNTL:  # pragma: no cover - not on POSIX
        return True
    try:
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return False
    return True


def recorded_lines(
    handle: IO[bytes],
    path: Path,
    record_format: str,
    what: str,
    error: type[Exception] = ValueError,
) -> list[bytes]:
    """The complete lines of the ``.jsonl`` record open (read and append) in ``handle``, its
    header first; a last line cut off by a run killed while writing it is dropped from the
    file. An empty file, or one holding only the start of a cut-off header, is emptied and
    ``[]`` returned. A file whose first line is not a header of ``record_format`` (``what``
    names such a file in the message: "an arrange-up rollout record") raises
    ``error`` (the caller's exception class) *before anything is truncated*: it is someone
    else's file (a plan, notes, another kind of record), and nothing of it may be lost. Shared
    by the rollout records, the closed loop's episode records and CBST's training data."""
    if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):
        # /dev/null, a FIFO: nothing can be read back to resume, and truncating fails
        raise error(
            f"{path}: not a regular file; a record is read back to resume a run, so it must be "
            "a file: use another record file"
        )
    handle.seek(0)
    data = handle.read()
    *complete, cut = data.split(b"\n")
    refused = error(
        f"{path}:1: not {what} (its first line must be a {record_format!r} header); use "
        "another record file"
    )
    if not any(line.strip() for line in complete):
        if cut.strip() and not _cut_header(cut, record_format):
            raise refused
        handle.truncate(0)
        return []
    try:
        found = json.loads(complete[0])
    except ValueError:
        found = None
    if not isinstance(found, dict) or found.get("format") != record_format:
        raise refused
    if cut:
        handle.truncate(len(data) - len(cut))
    return complete


def numbered_records(
    lines: Sequence[bytes],
    path: Path,
    parse: Callable[[bytes, int], R],
    number_of: Callable[[R], int],
    noun: str,
    error: type[Exception] = ValueError,
) -> dict[int, R]:
    """The records of :func:`recorded_lines` ``lines`` after the header (blank lines skipped),
    by their number (``number_of``: a rollout's index, an episode's number). ``parse(line,
    line_number)`` reads one line and raises the caller's error for one it cannot. A number
    recorded twice with different outcomes raises ``error`` at the second copy's line (``noun``
    names what is numbered): the last copy winning would change a count silently; the same
    record twice is harmless and read once."""
    records: dict[int, R] = {}
    for line_number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        record = parse(line, line_number)
        number = number_of(record)
        earlier = records.get(number)
        if earlier is not None and earlier != record:
            raise error(
                f"{path}:{line_number}: {noun} {number} is recorded twice with different "
                "outcomes; the file was edited or written by something else: use another "
                "record file or delete it"
            )
        records[number] = record
    return records


def _cut_header(cut: bytes, record_format: str) -> bool:
    """Whether ``cut`` can be the start of a header line of ``record_format`` cut off by a
    killed write (its format key comes first, with or without spaces after the separators)."""
    start = '{"format":"' + record_format + '"'
    text = cut.decode("utf-8", errors="replace").replace(" ", "")
    return start.startswith(text) or text.startswith(start)
