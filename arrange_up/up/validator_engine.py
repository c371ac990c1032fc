"""The reliability validator engine ``PlanValidator(name="arrange-up-reliability")``.

The validator (:class:`ArrangeUpReliability`) judges a plan by Monte Carlo
rollouts under the problem's full noise (:func:`arrange_up.evaluation.evaluate.evaluate_plan`):
it answers ``VALID`` only when every rollout reaches the goal, ``INVALID`` otherwise (with a log
message breaking the failures down, and ``reason`` set from the most frequent failure:
``UNSATISFIED_GOALS`` when that is a missed goal, else ``INAPPLICABLE_ACTION`` naming the action
that failed most often), ``UNKNOWN`` when the problem or the plan cannot be converted or the
evaluation fails. Metrics: ``successes``, ``trials``, ``rate``, ``interval`` (the 95% Wilson
interval as ``[low, high]``), ``interval_low``, ``interval_high``, ``seed``, ``elapsed`` and the
failure counts per kind. Parameters: ``rollouts`` (1000), ``seed`` (0), ``workers`` (``None``:
all cores), ``backend`` (``"local"`` or ``"dask"``), ``scheduler`` (a Dask scheduler address),
``timeout`` (seconds, ``None``: none). unified-planning's ``validate`` takes no timeout, so it
is a parameter; it is checked as rollouts finish, and when it runs out the answer is ``UNKNOWN``
with a log message saying how many rollouts were done.

    >>> from unified_planning.shortcuts import OneshotPlanner, PlanValidator
    >>> from arrange_up.io.domains import load
    >>> from arrange_up.up.compile import to_up
    >>> problem = to_up(load("blocks-1"))
    >>> with OneshotPlanner(name="arrange-up", params={"semantics": "deterministic"}) as p:
    ...     result = p.solve(problem, timeout=60)
    >>> with PlanValidator(name="arrange-up-reliability", params={"rollouts": 100}) as v:
    ...     check = v.validate(problem, result.plan)
    >>> check.metrics["successes"], check.metrics["interval"]     # doctest: +SKIP
    ('100', '[0.963, 1]')

What every engine shares (answers instead of exceptions, kinds, registration):
:mod:`arrange_up.up.engine_base`.
"""

from __future__ import annotations

import time
from typing import Any

from unified_planning.engines import Engine, LogLevel, LogMessage, ValidationResult
from unified_planning.engines.mixins import PlanValidatorMixin
from unified_planning.engines.results import FailedValidationReason, ValidationResultStatus
from unified_planning.model import AbstractProblem
from unified_planning.plans import Plan

from arrange_up.counts import check_count
from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.evaluation.outcomes import GOAL_MISSED
from arrange_up.evaluation.reliability import EvaluationProgress
from arrange_up.parallel import RunnerConfig
from arrange_up.up.engine_base import (
    ArrangeUpEngine,
    check_parallel_params,
    check_seed,
    check_timeout,
)
from arrange_up.up.engine_io import Refusal, read_problem_and_plan
from arrange_up.up.registration import VALIDATOR_NAME

__all__ = ["ArrangeUpReliability"]


class ArrangeUpReliability(ArrangeUpEngine, PlanValidatorMixin):
    """Monte Carlo reliability of a plan under the problem's noise (see the module doc)."""

    _NAME = VALIDATOR_NAME
    _PARAMETERS = ("rollouts", "seed", "workers", "backend", "scheduler", "timeout")

    def __init__(
        self,
        rollouts: int = 1000,
        seed: int = 0,
        workers: int | None = None,
        backend: str = "local",
        scheduler: str | None = None,
        timeout: float | None = None,
        **unknown: Any,
    ) -> None:
        self._refuse_unknown(unknown)
        Engine.__init__(self)
        PlanValidatorMixin.__init__(self)
        _check_validator_params(rollouts, seed, workers, backend, scheduler)
        check_timeout(VALIDATOR_NAME, timeout)
        self._rollouts = rollouts
        self._seed = seed
        self._runner = RunnerConfig(workers, backend, scheduler)
        self._timeout = timeout

    def _validate(self, problem: AbstractProblem, plan: Plan) -> ValidationResult:
        started = time.monotonic()

        def unknown(
            message: str, level: LogLevel = LogLevel.ERROR, metrics: dict[str, str] | None = None
        ) -> ValidationResult:
            return ValidationResult(
                ValidationResultStatus.UNKNOWN,
                VALIDATOR_NAME,
                log_messages=[LogMessage(level, message)],
                metrics=metrics,
            )

        read = read_problem_and_plan(problem, plan)
        if isinstance(read, Refusal):
            return unknown(read.message)
        arrangement, actions = read
        deadline = None if self._timeout is None else started + self._timeout
        seen: list[EvaluationProgress] = []

        def watch(progress: EvaluationProgress) -> None:
            seen[:] = [progress]
            if deadline is not None and time.monotonic() >= deadline:
                raise _OutOfTime

        try:
            outcome = evaluate_plan(
                arrangement,
                actions,
                rollouts=self._rollouts,
                seed=self._seed,
                runner=self._runner,
                progress=watch,
            )
        except _OutOfTime:
            done = seen[0].done if seen else 0
            successes = seen[0].successes if seen else 0
            message = (
                f"timeout of {self._timeout} s reached after {done} of {self._rollouts} "
                f"rollouts ({successes} reached the goal): no verdict"
            )
            metrics = {
                "done": str(done),
                "successes": str(successes),
                "rollouts": str(self._rollouts),
            }
            return unknown(message, LogLevel.INFO, metrics)
        except Exception as error:  # the engine must answer, not raise
            return unknown(f"the evaluation failed: {type(error).__name__}: {error}")

        failures = outcome.failures
        low, high = outcome.interval
        metrics = {
            "successes": str(outcome.successes),
            "trials": str(outcome.trials),
            "rate": f"{outcome.rate:.6g}",
            "interval": f"[{low:.6g}, {high:.6g}]",
            "interval_low": f"{low:.6g}",
            "interval_high": f"{high:.6g}",
            "seed": str(outcome.seed),
            "elapsed": f"{outcome.elapsed:.6g}",
            "goal_missed": str(failures.goal_missed),
            "action_failed": str(failures.action_failed),
            "not_at_rest": str(failures.not_at_rest),
            "off_table": str(failures.off_table),
        }
        summary = (
            f"{outcome.successes} of {outcome.trials} rollouts reached the goal (rate "
            f"{outcome.rate:.4g}, 95% Wilson interval [{low:.4g}, {high:.4g}], "
            f"seed {outcome.seed})"
        )
        if outcome.successes == outcome.trials:
            return ValidationResult(
                ValidationResultStatus.VALID,
                VALIDATOR_NAME,
                log_messages=[LogMessage(LogLevel.INFO, summary)],
                metrics=metrics,
            )
        # the most frequent failure decides UP's reason
        per_action: dict[int, int] = {}
        for entry in (
            *failures.action_failures,
            *failures.not_at_rest_actions,
            *failures.off_table_actions,
        ):
            per_action[entry.action] = per_action.get(entry.action, 0) + entry.rollouts
        worst_action = max(per_action, key=lambda a: (per_action[a], -a), default=None)
        lines = [summary + "; failures:"]
        if failures.goal_missed:
            parts = ", ".join(f"{m.part} {m.dimension} {m.rollouts}" for m in failures.goal_misses)
            lines.append(f"  {GOAL_MISSED}: {failures.goal_missed} ({parts})")
        for entry in failures.action_failures:
            lines.append(f"  action {entry.action} failed in {entry.rollouts}: {entry.reason}")
        for entry in failures.not_at_rest_actions:
            lines.append(f"  action {entry.action} did not come to rest in {entry.rollouts}")
        for entry in failures.off_table_actions:
            lines.append(
                f"  action {entry.action} put {entry.object} off the table in {entry.rollouts}"
            )
        if worst_action is None or failures.goal_missed >= per_action[worst_action]:
            reason, inapplicable = FailedValidationReason.UNSATISFIED_GOALS, None
        else:
            reason = FailedValidationReason.INAPPLICABLE_ACTION
            inapplicable = plan.actions[worst_action]
        return ValidationResult(
            ValidationResultStatus.INVALID,
            VALIDATOR_NAME,
            log_messages=[LogMessage(LogLevel.INFO, "\n".join(lines))],
            reason=reason,
            inapplicable_action=inapplicable,
            metrics=metrics,
        )


def _check_validator_params(
    rollouts: Any, seed: Any, workers: Any, backend: Any, scheduler: Any
) -> None:
    check_count(f"{VALIDATOR_NAME}: rollouts", rollouts)
    check_seed(VALIDATOR_NAME, seed)
    check_parallel_params(VALIDATOR_NAME, workers, backend, scheduler)


class _OutOfTime(Exception):
    """Raised from an evaluation's progress callback when the validator's timeout ran out."""
