"""Small file helpers shared by the readers and the resumable result files: where a file stops
being UTF-8, and an exclusive lock that refuses a second writer."""

from __future__ import annotations

from typing import IO

try:
    import fcntl
except ImportError:  # pragma: no cover - not on POSIX: files are not locked
    fcntl = None

__all__ = ["lock_exclusively", "undecodable_place"]


def undecodable_place(data: bytes, error: UnicodeDecodeError) -> tuple[int, int]:
    """The 1-based ``(line, column)`` in ``data`` of the byte ``error`` (from decoding ``data``)
    says is not UTF-8."""
    before = data[: error.start]
    line = before.count(b"\n") + 1
    column = len(before) - (before.rfind(b"\n") + 1) + 1
    return line, column


def lock_exclusively(handle: IO[bytes]) -> bool:
    """Take an exclusive lock on the open file ``handle`` without waiting; False when another
    process holds one (the lock ends when the handle is closed). Where the platform has no
    ``fcntl``, files are not locked and this returns True."""
    if fcntl is None:  # pragma: no cover - not on POSIX
        return True
    try:
        fcntl.flock(handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return False
    return True
