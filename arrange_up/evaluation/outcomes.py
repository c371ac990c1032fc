"""What one rollout ended with: success, or the :class:`Failure` that ended it (its kind, the
failing action, the reason); as values and as the JSON of a record file's lines.

The failure kinds (see :mod:`arrange_up.evaluation.rollouts` for when each happens):
``action_failed``, ``not_at_rest``, ``off_table`` and ``goal_missed``.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, NamedTuple

from arrange_up.counts import is_integer

__all__ = [
    "ACTION_FAILED",
    "FAILURE_KINDS",
    "GOAL_MISSED",
    "NOT_AT_REST",
    "OFF_TABLE",
    "Failure",
    "FailureKind",
    "GoalMiss",
    "RolloutRecord",
]


class FailureKind(enum.StrEnum):
    """Why a rollout failed. A ``str`` (its value), so JSON and comparisons with the plain
    strings of a record file are unchanged."""

    GOAL_MISSED = "goal_missed"
    ACTION_FAILED = "action_failed"
    NOT_AT_REST = "not_at_rest"
    OFF_TABLE = "off_table"


GOAL_MISSED = FailureKind.GOAL_MISSED
ACTION_FAILED = FailureKind.ACTION_FAILED
NOT_AT_REST = FailureKind.NOT_AT_REST
OFF_TABLE = FailureKind.OFF_TABLE
FAILURE_KINDS: tuple[FailureKind, ...] = (GOAL_MISSED, ACTION_FAILED, NOT_AT_REST, OFF_TABLE)


class GoalMiss(NamedTuple):
    """One goal part's miss at the end of a rollout: the dimensions beyond the tolerance
    (``x``, ``y``, ``theta``, or ``off table``) and the excess per dimension (in, in, rad)."""

    part: str
    dimensions: tuple[str, ...]
    excess: tuple[float, float, float]


@dataclass(frozen=True)
class Failure:
    """Why one rollout failed (:class:`FailureKind`).

    ``action`` is the 0-based index of the failing action in the plan (``None`` for
    ``goal_missed``); ``reason`` says why an action failed (stable across rollouts, so failures
    can be counted by it), ``detail`` adds this rollout's particulars (an overlap's depth);
    ``objects`` lists what ended off the table; ``misses`` the goal parts that missed.
    """

    kind: FailureKind
    action: int | None = None
    reason: str | None = None
    detail: str | None = None
    objects: tuple[str, ...] = ()
    misses: tuple[GoalMiss, ...] = ()

    def to_json(self) -> dict[str, Any]:
        data: dict[str, Any] = {"kind": str(self.kind)}
        if self.action is not None:
            data["action"] = self.action
        if self.reason is not None:
            data["reason"] = self.reason
        if self.detail is not None:
            data["detail"] = self.detail
        if self.objects:
            data["objects"] = list(self.objects)
        if self.misses:
            data["misses"] = [
                {"part": m.part, "dimensions": list(m.dimensions), "excess": list(m.excess)}
                for m in self.misses
            ]
        return data

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Failure:
        if data.get("kind") not in FAILURE_KINDS:
            raise ValueError(f"unknown failure kind {data.get('kind')!r}")
        return cls(
            kind=FailureKind(data["kind"]),
            action=data.get("action"),
            reason=data.get("reason"),
            detail=data.get("detail"),
            objects=tuple(data.get("objects", ())),
            misses=tuple(
                GoalMiss(m["part"], tuple(m["dimensions"]), tuple(m["excess"]))
                for m in data.get("misses", ())
            ),
        )


@dataclass(frozen=True)
class RolloutRecord:
    """The outcome of rollout ``index``: success, or the :class:`Failure` that ended it."""

    index: int
    success: bool
    failure: Failure | None = None

    def to_json(self) -> dict[str, Any]:
        data: dict[str, Any] = {"rollout": self.index, "success": self.success}
        if self.failure is not None:
            data["failure"] = self.failure.to_json()
        return data

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> RolloutRecord:
        index, success = data["rollout"], data["success"]
        if not is_integer(index) or index < 0:
            raise ValueError(f"rollout: expected a non-negative integer, got {index!r}")
        if not isinstance(success, bool):
            raise ValueError(f"success: expected true or false, got {success!r}")
        failure = data.get("failure")
        if success == (failure is not None):
            raise ValueError("a rollout has a failure exactly when it did not succeed")
        return cls(index, success, None if failure is None else Failure.from_json(failure))
