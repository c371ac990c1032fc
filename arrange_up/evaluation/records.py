"""Record files: the resumable ``.jsonl`` of an evaluation's rollouts.

With ``record=PATH`` every finished rollout is appended to ``PATH`` at once as one JSON line
(flushed), after a header line identifying the evaluation (format, problem hash, plan hash,
seed, physics settings). Running again with the same file resumes: rollouts already recorded
are read back, not re-run, and the result is identical to an uninterrupted run's. A file whose
header identifies another evaluation is refused (:class:`RecordFileError`), never mixed. A run
killed halfway keeps every rollout that reached the file; with a process pool a rollout reaches
it when its chunk (a few rollouts, see :mod:`arrange_up.parallel`) comes back. A line cut off by
the kill is dropped on resume. The file is locked while a run writes to it. See
``docs/evaluation.md`` for the line format.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Sequence
from pathlib import Path
from typing import IO, Any

from arrange_up.counts import is_integer, is_number
from arrange_up.evaluation.outcomes import FAILURE_KINDS, GOAL_MISSED, RolloutRecord
from arrange_up.io.files import lock_exclusively, numbered_records, recorded_lines
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action, Pick, Place, Push

__all__ = ["RECORD_FORMAT", "RecordFile", "RecordFileError", "plan_hash", "record_header"]

RECORD_FORMAT = "arrange-up-rollouts/1"


class RecordFileError(ValueError):
    """A record file that belongs to another evaluation, is corrupt, or is in use."""


def plan_hash(actions: Sequence[Action]) -> str:
    """A content hash of a plan's actions (internal units, exact floats): ``"sha256:<hex>"``."""

    def canonical(action: Action) -> list[Any]:
        if isinstance(action, Place):
            return ["place", action.obj, [float(v) for v in action.pose]]
        if isinstance(action, Push):
            return [
                "push",
                action.manipulator,
                [float(v) for v in action.pose],
                float(action.distance),
            ]
        if isinstance(action, Pick):
            return ["pick", action.obj]
        raise TypeError(f"not an action: {action!r}")

    text = json.dumps([canonical(a) for a in actions], separators=(",", ":"))
    return "sha256:" + hashlib.sha256(text.encode("utf-8")).hexdigest()


def record_header(
    problem: ArrangementProblem, phash: str, lhash: str, n: int, seed: int, settings: object
) -> dict:
    """The header line of an evaluation's record file: ``phash`` and ``lhash`` are the problem
    and plan hashes, ``n`` the plan's length, ``settings`` the physics settings (hashed)."""
    return {
        "format": RECORD_FORMAT,
        "problem": {"name": problem.name, "hash": phash},
        "plan": {"hash": lhash, "actions": n},
        "seed": seed,
        "physics": hashlib.sha256(repr(settings).encode("utf-8")).hexdigest()[:16],
    }


_HEADER_KEYS: tuple[tuple[str, ...], ...] = (
    ("format",),
    ("problem", "hash"),
    ("plan", "hash"),
    ("seed",),
    ("physics",),
)


def _dig(data: Any, path: tuple[str, ...]) -> Any:
    for key in path:
        data = data.get(key) if isinstance(data, dict) else None
    return data


_DIMENSIONS = frozenset(("x", "y", "theta", "off table", "on table"))


def rollout_line_problem(data: Any, actions: Any, of: str | None = None) -> str | None:
    """What is wrong with the JSON ``data`` of one rollout line of a plan of ``actions``
    actions, or ``None`` (``of`` says what the actions are in a message: by default "the
    plan's N"). ``RolloutRecord.from_json`` checks the rollout index, the success
    flag and the failure kind; this checks the rest against the plan, so that a resumed
    evaluation never counts a line no rollout of this plan could have written."""
    if not isinstance(data, dict):
        return f"expected a JSON object, got {type(data).__name__}"
    for key in ("rollout", "success"):
        if key not in data:
            return f"no {key!r}"
    failure = data.get("failure")
    if failure is None:
        return None
    if not isinstance(failure, dict):
        return f"failure: expected a JSON object, got {failure!r}"
    if failure.get("kind") not in FAILURE_KINDS:
        return (
            f"failure.kind: unknown failure kind {failure.get('kind')!r}; expected one of "
            f"{', '.join(FAILURE_KINDS)}"
        )
    action = failure.get("action")
    if failure["kind"] == GOAL_MISSED:
        if action is not None:
            return f"failure.action: a missed goal names no action, got {action!r}"
    elif not is_integer(action) or not 0 <= action < (actions if is_integer(actions) else 0):
        whose = f"the plan's {actions}" if of is None else of
        return f"failure.action: expected the 0-based index of an action of {whose}, got {action!r}"
    for key in ("reason", "detail"):
        if failure.get(key) is not None and not isinstance(failure[key], str):
            return f"failure.{key}: expected text, got {failure[key]!r}"
    objects = failure.get("objects", [])
    if not isinstance(objects, list) or not all(isinstance(o, str) for o in objects):
        return f"failure.objects: expected a list of object names, got {objects!r}"
    misses = failure.get("misses", [])
    if not isinstance(misses, list):
        return f"failure.misses: expected a list, got {misses!r}"
    for k, miss in enumerate(misses):
        where = f"failure.misses[{k}]"
        if not isinstance(miss, dict) or not isinstance(miss.get("part"), str):
            return f"{where}: expected an object with a part name, got {miss!r}"
        dims = miss.get("dimensions")
        if not isinstance(dims, list) or not set(dims) <= _DIMENSIONS:
            return f"{where}.dimensions: expected some of {sorted(_DIMENSIONS)}, got {dims!r}"
        excess = miss.get("excess")
        if (
            not isinstance(excess, list)
            or len(excess) != 3
            or not all(is_number(e) and math.isfinite(e) for e in excess)
        ):
            return f"{where}.excess: expected three finite numbers, got {excess!r}"
    return None


class RecordFile:
    """An open, locked record file: its earlier records (``records``, by index), and an append
    handle (:meth:`write_line`). Opening a file of another evaluation, or one in use, raises
    :class:`RecordFileError`."""

    def __init__(self, path: Path, header: dict) -> None:
        self.path = path
        path.parent.mkdir(parents=True, exist_ok=True)
        self.handle: IO[bytes] = open(path, "a+b")  # noqa: SIM115 - closed by close()
        try:
            self._lock()
            self.records = self._read(header)
        except BaseException:
            self.handle.close()
            raise

    def _lock(self) -> None:
        if not lock_exclusively(self.handle):
            raise RecordFileError(f"{self.path}: the record file is in use by another evaluation")

    def _read(self, header: dict) -> dict[int, RolloutRecord]:
        lines = recorded_lines(
            self.handle, self.path, RECORD_FORMAT, "an arrange-up rollout record", RecordFileError
        )
        if not lines:  # a new file, or one killed while writing its header: start afresh
            self.write_line(header)
            return {}
        found = json.loads(lines[0])
        differ = [
            ".".join(path) for path in _HEADER_KEYS if _dig(found, path) != _dig(header, path)
        ]
        if differ:
            details = "; ".join(
                f"{'.'.join(p)}: file {_dig(found, p)!r}, this run {_dig(header, p)!r}"
                for p in _HEADER_KEYS
                if ".".join(p) in differ
            )
            raise RecordFileError(
                f"{self.path}: the record file belongs to another evaluation ({details}); its "
                "rollouts cannot be mixed with this one's: use another record file or delete it"
            )
        actions = _dig(header, ("plan", "actions"))

        def parse(line: bytes, number: int) -> RolloutRecord:
            try:
                data = json.loads(line)
                problem = rollout_line_problem(data, actions)
                record = None if problem else RolloutRecord.from_json(data)
            except (ValueError, KeyError, TypeError) as error:
                problem = str(error)
            if problem or record is None:
                raise RecordFileError(
                    f"{self.path}:{number}: not a rollout record of this evaluation: {problem}; "
                    "the file was edited or written by something else: use another record file "
                    "or delete it"
                ) from None
            return record

        return numbered_records(
            lines, self.path, parse, lambda r: r.index, "rollout", RecordFileError
        )

    def write_line(self, data: dict) -> None:
        self.handle.write(json.dumps(data, separators=(",", ":")).encode("utf-8") + b"\n")
        self.handle.flush()

    def close(self) -> None:
        self.handle.close()  # also releases the lock
