"""The result of an evaluation: how many rollouts succeeded, the rate's 95% Wilson score
interval, and the failures broken down by kind.

A :class:`Reliability`: ``successes`` of ``trials``, ``rate`` and its 95% **Wilson score
interval** (:func:`wilson_interval`). Wilson's interval rather than the normal ("Wald") one:
it stays inside [0, 1] and is not degenerate at 0 or ``trials`` successes (a plan that never
failed in 1000 rollouts gets [0.996, 1], not [1, 1]), and its coverage is close to nominal even
for small counts, which the Wald interval's is not. ``failures`` breaks the failures down by
kind (:class:`FailureBreakdown`).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any, NamedTuple

from arrange_up.evaluation.outcomes import (
    ACTION_FAILED,
    GOAL_MISSED,
    NOT_AT_REST,
    OFF_TABLE,
    RolloutRecord,
)

__all__ = [
    "Z95",
    "ActionCount",
    "ActionFailureCount",
    "EvaluationProgress",
    "FailureBreakdown",
    "GoalMissCount",
    "OffTableCount",
    "ProgressCallback",
    "Reliability",
    "wilson_interval",
]

#: The standard normal quantile of a two-sided 95% interval.
Z95 = 1.959963984540054


def wilson_interval(successes: int, trials: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a binomial proportion (95% with the default ``z``).

    ``(centre ± half) / (1 + z²/n)`` with ``centre = p + z²/2n`` and
    ``half = z sqrt(p(1-p)/n + z²/4n²)``; ``(0, 1)`` when there are no trials.

    >>> [round(v, 4) for v in wilson_interval(1000, 1000)]
    [0.9962, 1.0]
    """
    if trials <= 0:
        return (0.0, 1.0)
    if not 0 <= successes <= trials:
        raise ValueError(f"successes must be within [0, {trials}], got {successes}")
    n = float(trials)
    p = successes / n
    z2 = z * z
    denominator = 1.0 + z2 / n
    centre = (p + z2 / (2.0 * n)) / denominator
    half = z * math.sqrt(p * (1.0 - p) / n + z2 / (4.0 * n * n)) / denominator
    low = 0.0 if successes == 0 else max(0.0, centre - half)
    high = 1.0 if successes == trials else min(1.0, centre + half)
    return (low, high)


class GoalMissCount(NamedTuple):
    part: str
    dimension: str
    rollouts: int
    worst: float
    """Largest excess beyond the tolerance over those rollouts (in or rad; 0 for off table)."""


class ActionFailureCount(NamedTuple):
    action: int
    reason: str
    rollouts: int


class ActionCount(NamedTuple):
    action: int
    rollouts: int


class OffTableCount(NamedTuple):
    action: int
    object: str
    rollouts: int


@dataclass(frozen=True)
class FailureBreakdown:
    """Failed rollouts counted by kind (:class:`~arrange_up.evaluation.outcomes.FailureKind`).

    ``goal_missed`` etc. count rollouts of each kind; the tuples break them down (sorted by
    action index, then name): per goal part and dimension (a rollout that missed a part in two
    dimensions counts in both), per action and reason, per action, per action and object.
    Action indices are 0-based positions in the plan.
    """

    goal_missed: int = 0
    action_failed: int = 0
    not_at_rest: int = 0
    off_table: int = 0
    goal_misses: tuple[GoalMissCount, ...] = ()
    action_failures: tuple[ActionFailureCount, ...] = ()
    not_at_rest_actions: tuple[ActionCount, ...] = ()
    off_table_actions: tuple[OffTableCount, ...] = ()

    @property
    def total(self) -> int:
        return self.goal_missed + self.action_failed + self.not_at_rest + self.off_table

    @classmethod
    def from_records(cls, records: Iterable[RolloutRecord]) -> FailureBreakdown:
        kinds: Counter[str] = Counter()
        misses: Counter[tuple[str, str]] = Counter()
        worst: dict[tuple[str, str], float] = {}
        failed: Counter[tuple[int, str]] = Counter()
        rest: Counter[int] = Counter()
        off: Counter[tuple[int, str]] = Counter()
        dims = ("x", "y", "theta")
        for record in records:
            f = record.failure
            if f is None:
                continue
            kinds[f.kind] += 1
            if f.kind == GOAL_MISSED:
                for miss in f.misses:
                    for dim in miss.dimensions:
                        key = (miss.part, dim)
                        misses[key] += 1
                        excess = miss.excess[dims.index(dim)] if dim in dims else 0.0
                        worst[key] = max(worst.get(key, 0.0), float(excess))
            elif f.kind == ACTION_FAILED:
                failed[(int(f.action or 0), f.reason or "")] += 1
            elif f.kind == NOT_AT_REST:
                rest[int(f.action or 0)] += 1
            elif f.kind == OFF_TABLE:
                for name in f.objects:
                    off[(int(f.action or 0), name)] += 1
        return cls(
            goal_missed=kinds[GOAL_MISSED],
            action_failed=kinds[ACTION_FAILED],
            not_at_rest=kinds[NOT_AT_REST],
            off_table=kinds[OFF_TABLE],
            goal_misses=tuple(
                GoalMissCount(p, d, n, worst[(p, d)]) for (p, d), n in sorted(misses.items())
            ),
            action_failures=tuple(
                ActionFailureCount(a, r, n) for (a, r), n in sorted(failed.items())
            ),
            not_at_rest_actions=tuple(ActionCount(a, n) for a, n in sorted(rest.items())),
            off_table_actions=tuple(OffTableCount(a, o, n) for (a, o), n in sorted(off.items())),
        )

    def to_json(self) -> dict[str, Any]:
        """Counts for ``--json`` output (excess in inches and radians)."""
        parts: dict[str, dict[str, dict[str, float | int]]] = {}
        for m in self.goal_misses:
            parts.setdefault(m.part, {})[m.dimension] = {"rollouts": m.rollouts, "worst": m.worst}
        return {
            "total": self.total,
            GOAL_MISSED.value: {"rollouts": self.goal_missed, "parts": parts},
            ACTION_FAILED.value: {
                "rollouts": self.action_failed,
                "actions": [c._asdict() for c in self.action_failures],
            },
            NOT_AT_REST.value: {
                "rollouts": self.not_at_rest,
                "actions": [c._asdict() for c in self.not_at_rest_actions],
            },
            OFF_TABLE.value: {
                "rollouts": self.off_table,
                "actions": [c._asdict() for c in self.off_table_actions],
            },
        }


@dataclass(frozen=True)
class Reliability:
    """The reliability of a plan estimated from ``trials`` rollouts.

    ``rate`` is ``successes / trials`` and ``interval`` its 95% Wilson score interval.
    ``elapsed`` (seconds of this call), ``resumed`` (rollouts read back from a record file),
    ``backend`` and ``workers`` describe the run, not the result: they are left out of ``==``,
    so a resumed evaluation compares equal to an uninterrupted one. ``records`` holds every
    rollout's :class:`RolloutRecord` in index order when asked for (``keep_records=True``).
    ``landing`` is the evaluation's landing rule (``fail`` or ``shove``,
    :mod:`arrange_up.evaluation.rollouts`); the JSON names it when it is not ``fail``.
    """

    successes: int
    trials: int
    failures: FailureBreakdown
    seed: int
    rate: float = field(init=False)
    interval: tuple[float, float] = field(init=False)
    elapsed: float = field(default=0.0, compare=False)
    resumed: int = field(default=0, compare=False)
    backend: str = field(default="local", compare=False)
    workers: int = field(default=1, compare=False)
    records: tuple[RolloutRecord, ...] | None = None
    landing: str = "fail"

    def __post_init__(self) -> None:
        object.__setattr__(self, "rate", self.successes / self.trials if self.trials else 0.0)
        object.__setattr__(self, "interval", wilson_interval(self.successes, self.trials))

    def to_json(self) -> dict[str, Any]:
        data: dict[str, Any] = {
            "successes": self.successes,
            "trials": self.trials,
            "rate": self.rate,
            "interval": list(self.interval),
            "failures": self.failures.to_json(),
            "seed": self.seed,
            "elapsed": self.elapsed,
            "resumed": self.resumed,
            "backend": self.backend,
            "workers": self.workers,
        }
        if self.landing != "fail":
            data["landing"] = self.landing
        return data


@dataclass(frozen=True)
class EvaluationProgress:
    """What a progress callback is told after each rollout (and once at the start)."""

    done: int
    total: int
    successes: int
    elapsed: float
    resumed: int = 0

    @property
    def rate(self) -> float:
        return self.successes / self.done if self.done else 0.0


ProgressCallback = Callable[[EvaluationProgress], None]
