"""The experiments' raw measurements as CSV records, written so an interrupted run resumes.

An experiment appends each row as soon as it is measured (:class:`CsvAppender`, flushed per
row), and a rerun skips the rows whose key columns a previous run already wrote (the
appender's ``done``). The CSV gets the care of the evaluation's record files
(:mod:`arrange_up.evaluation.records`):

* it is locked while a run appends to it: a second run on the same file is refused
  (:class:`CsvRecordsError`) rather than measuring the same keys again;
* a last line cut off by a kill is dropped when the file is opened again;
* a CSV with other columns, or made with other settings, is refused: the settings that
  change a measurement without being a key column (node limits, rollouts, timeouts, ...) are
  kept beside the CSV in ``NAME.settings.json`` and compared on every rerun (a CSV written
  before settings were kept has none to compare; its first rerun records them);
* a key is measured once: writing a row whose key is already in the file raises;
* a file that is not UTF-8, or a cell of a number column (the appender's ``numbers``) that is
  not a finite number of its kind, is refused with its ``file:line`` before anything is
  measured: a word, ``nan`` or ``-inf`` there would otherwise be resumed into the results.

Values read back are strings, as :class:`csv.DictReader` gives them.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import IO, Any

from arrange_up.io.files import lock_exclusively

__all__ = [
    "CsvAppender",
    "CsvRecordsError",
    "Numbers",
    "Progress",
    "done_keys",
    "mean",
    "read_csv",
    "settings_path",
]

#: The kind of each number column of a CSV: ``int`` or ``float`` (finite); an empty cell is
#: a value not measured and passes.
Numbers = Mapping[str, type[int] | type[float]]
#: Receives one line of progress text at a time.
Progress = Callable[[str], None]


class CsvRecordsError(ValueError):
    """An experiment CSV that is in use by another run, has other columns, was made with other
    settings, holds a cell that is not UTF-8 or not a number where one belongs, or would get a
    key measured twice."""


def read_csv(path: Path) -> list[dict[str, str]]:
    """Every row of the CSV at ``path``, keyed by its header (a cut-off last line left out).

    Raises :class:`CsvRecordsError` with ``file:line`` for bytes that are not UTF-8."""
    text = _whole_text(Path(path), Path(path).read_bytes())
    return list(csv.DictReader(io.StringIO(text, newline="")))


def _whole_text(path: Path, data: bytes) -> str:
    """The whole lines of ``data`` (a kill may cut the last one, even inside a character),
    decoded; :class:`CsvRecordsError` with ``path:line`` for bytes that are not UTF-8."""
    if data and not data.endswith(b"\n"):
        data = data[: data.rfind(b"\n") + 1]
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n") + 1
        raise CsvRecordsError(
            f"{path}:{line}: byte 0x{data[error.start]:02x} is not UTF-8 text; the CSV was "
            "changed by something other than the experiment: repair that line or write to "
            "another output directory"
        ) from None


def _check_numbers(path: Path, line: int, row: Mapping[str, str], numbers: Numbers) -> None:
    """Refuse (with ``path:line``) a cell of a number column that is not a finite number of
    its kind."""
    for column, kind in numbers.items():
        cell = row.get(column) or ""
        if not cell:
            continue
        try:
            value = kind(cell)
        except ValueError:
            value = None
        if value is None or not math.isfinite(value):
            what = "an integer" if kind is int else "a finite number"
            raise CsvRecordsError(
                f"{path}:{line}: column {column} holds {cell[:40]!r}, not {what}; the CSV was "
                "changed by something other than the experiment: repair that line or write "
                "to another output directory"
            )


def done_keys(path: Path, fields: Sequence[str]) -> set[tuple[str, ...]]:
    """The ``fields`` columns of every row already in ``path`` (none when it does not exist)."""
    if not Path(path).exists():
        return set()
    rows = read_csv(path)
    header = list(rows[0]) if rows else []
    missing = [f for f in fields if rows and f not in header]
    if missing:  # another file's columns (a renamed or lost header): not this experiment's CSV
        raise CsvRecordsError(
            f"{path}: its columns ({', '.join(str(c) for c in header)}) lack "
            f"{', '.join(missing)}, expected in this experiment's CSV; repair the header or "
            "write to another output directory"
        )
    return {tuple(row[f] or "" for f in fields) for row in rows}


def settings_path(path: Path) -> Path:
    """Where the settings of the CSV ``path`` are kept: ``NAME.settings.json`` beside it."""
    path = Path(path)
    return path.with_name(f"{path.stem}.settings.json")


def _whole_lines(text: str) -> str:
    """``text`` without a last line that was cut off (no line ending after it)."""
    if text and not text.endswith("\n"):
        return text[: text.rfind("\n") + 1]
    return text


class CsvAppender:
    """A context manager appending rows to a CSV (see the module docstring).

    ``with CsvAppender(path, fields, key=("problem", "run"), settings={...}) as write:``
    locks the file, drops a cut-off last line, refuses other columns or settings, and gives
    ``write.done`` (the keys already measured, as tuples of strings); ``write(row)`` appends a
    row and flushes it, and raises :class:`CsvRecordsError` for a key already measured. The
    header is written when the file is new or empty. ``numbers`` names the number columns
    whose cells the rows already there must hold (see :data:`Numbers`).
    """

    def __init__(
        self,
        path: Path,
        fields: Sequence[str],
        *,
        key: Sequence[str] = (),
        settings: Mapping[str, Any] | None = None,
        numbers: Numbers | None = None,
    ) -> None:
        self.path = Path(path)
        self.numbers = dict(numbers or {})
        self.fields = list(fields)
        self.key = tuple(key)
        self.settings = dict(settings or {})
        self.done: set[tuple[str, ...]] = set()

    def __enter__(self) -> CsvAppender:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.handle: IO[bytes] = open(self.path, "a+b")  # noqa: SIM115 - closed by __exit__
        try:
            self._lock()
            self._open()
        except BaseException:
            self.handle.close()
            raise
        return self

    def _lock(self) -> None:
        if not lock_exclusively(self.handle):
            raise CsvRecordsError(
                f"{self.path}: the CSV is in use by another run of the experiment; wait for it "
                "or write to another output directory"
            )

    def _open(self) -> None:
        self.handle.seek(0)
        data = self.handle.read()
        text = data.decode("utf-8", errors="replace")
        whole = _whole_lines(text)
        rows = list(csv.reader(io.StringIO(whole, newline="")))
        # The columns are checked before anything is dropped: a file that is not this
        # experiment's CSV is refused untouched, with or without a final newline.
        header = ",".join(self.fields)
        if rows and rows[0] != self.fields or not rows and not header.startswith(text.strip()):
            found = ", ".join(rows[0]) if rows else text.strip()[:60]
            raise CsvRecordsError(
                f"{self.path}: its columns ({found}) are not this experiment's "
                f"({', '.join(self.fields)}); write to another output directory"
            )
        self._check_cells(_whole_text(self.path, data))
        if whole != text:  # a run killed while writing a row: drop the cut-off line
            self.handle.truncate(len(whole.encode("utf-8")))
        self._check_settings(has_rows=len(rows) > 1)
        self.writer = csv.DictWriter(_Text(self.handle), self.fields)
        if not rows:
            self.writer.writeheader()
            self.handle.flush()
        index = {name: k for k, name in enumerate(self.fields)}
        for row in rows[1:]:
            self.done.add(tuple(row[index[f]] if index[f] < len(row) else "" for f in self.key))

    def _check_cells(self, text: str) -> None:
        reader = csv.DictReader(io.StringIO(text, newline=""))
        for row in reader:
            _check_numbers(self.path, reader.line_num, row, self.numbers)

    def _check_settings(self, *, has_rows: bool) -> None:
        where = settings_path(self.path)
        if has_rows and where.exists():
            try:
                kept = json.loads(where.read_text(encoding="utf-8"))
            except ValueError as error:
                raise CsvRecordsError(f"{where}: not a settings file: {error}") from None
            ours = json.loads(json.dumps(self.settings))
            differ = sorted(k for k in set(kept) | set(ours) if kept.get(k) != ours.get(k))
            if differ:
                details = "; ".join(
                    f"{k}: the CSV's {kept.get(k)!r}, this run's {ours.get(k)!r}" for k in differ
                )
                raise CsvRecordsError(
                    f"{self.path}: its rows were measured with other settings ({details}); "
                    "rows of different settings cannot be mixed: run with the CSV's settings or "
                    "write to another output directory"
                )
            return
        where.write_text(json.dumps(self.settings, indent=2, sort_keys=True) + "\n", "utf-8")

    def __call__(self, row: dict[str, Any]) -> None:
        key = tuple(str(row[f]) for f in self.key)
        if self.key and key in self.done:
            raise CsvRecordsError(
                f"{self.path}: the row of {dict(zip(self.key, key, strict=True))} is already "
                "measured; a key is measured once"
            )
        self.writer.writerow(row)
        self.handle.flush()
        self.done.add(key)

    def __exit__(self, *exc: object) -> None:
        self.handle.close()  # also releases the lock


class _Text:
    """A text ``write`` over a binary handle, for :class:`csv.DictWriter`."""

    def __init__(self, handle: IO[bytes]) -> None:
        self.handle = handle

    def write(self, text: str) -> int:
        return self.handle.write(text.encode("utf-8"))


def mean(values: Iterable[float]) -> float:
    """The mean of ``values``; NaN when there are none (a plot leaves the point out)."""
    values = list(values)
    return sum(values) / len(values) if values else math.nan
