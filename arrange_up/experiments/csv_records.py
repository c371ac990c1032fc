"""The experiments' raw measurements as CSV records, written so an interrupted run resumes.

An experiment appends each row as soon as it is measured (:class:`CsvAppender`, flushed per
row), and a rerun skips the rows whose key columns a previous run already wrote
(:func:`done_keys`). Values read back are strings, as :class:`csv.DictReader` gives them.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

__all__ = ["CsvAppender", "Progress", "done_keys", "mean", "read_csv"]

#: Receives one line of progress text at a time.
Progress = Callable[[str], None]


def read_csv(path: Path) -> list[dict[str, str]]:
    """Every row of the CSV at ``path``, keyed by its header."""
    with Path(path).open(newline="") as handle:
        return list(csv.DictReader(handle))


def done_keys(path: Path, fields: Sequence[str]) -> set[tuple[str, ...]]:
    """The ``fields`` columns of every row already in ``path`` (none when it does not exist)."""
    if not path.exists():
        return set()
    return {tuple(row[f] for f in fields) for row in read_csv(path)}


class CsvAppender:
    """A context manager appending rows to a CSV: the header is written once (when the file is
    new or empty), and the file is flushed after every row.

    ``with CsvAppender(path, fields) as write: write(row)``.
    """

    def __init__(self, path: Path, fields: Sequence[str]) -> None:
        self.path = Path(path)
        self.fields = list(fields)

    def __enter__(self) -> Callable[[dict[str, Any]], None]:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        new = not self.path.exists() or self.path.stat().st_size == 0
        self.handle = self.path.open("a", newline="")
        self.writer = csv.DictWriter(self.handle, self.fields)
        if new:
            self.writer.writeheader()

        def write(row: dict[str, Any]) -> None:
            self.writer.writerow(row)
            self.handle.flush()

        return write

    def __exit__(self, *exc: object) -> None:
        self.handle.close()


def mean(values: Iterable[float]) -> float:
    """The mean of ``values``; NaN when there are none (a plot leaves the point out)."""
    values = list(values)
    return sum(values) / len(values) if values else math.nan
