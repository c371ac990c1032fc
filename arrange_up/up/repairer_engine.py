"""The fixture-placement plan repairer engine ``PlanRepairer(name="arrange-up-fixtures")``
(:class:`ArrangeUpFixtureRepairer`, whose docstring gives its parameters and answers: it answers
``SOLVED_SATISFICING`` only with a plan that reaches the goal in the deterministic semantics), and
the nominal replay that checks both the plan it is given and the plan it returns.

What every engine shares (answers instead of exceptions, kinds, registration):
:mod:`arrange_up.up.engine_base`.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Sequence
from typing import Any

from unified_planning.engines import Engine, LogLevel, LogMessage, PlanGenerationResult
from unified_planning.engines import PlanGenerationResultStatus as Status
from unified_planning.engines.mixins import PlanRepairerMixin
from unified_planning.model import AbstractProblem
from unified_planning.plans import Plan

from arrange_up.belief.goals import GoalTest
from arrange_up.counts import check_count
from arrange_up.model.problem import ArrangementProblem, ObjectKind
from arrange_up.model.world import Action, Place, Push
from arrange_up.repair import METHODS, TIMEOUT, repair_plan
from arrange_up.transitions.particles import DeterministicSemantics
from arrange_up.up.compile import plan_from_up
from arrange_up.up.engine_base import (
    ArrangeUpEngine,
    Satisficing,
    check_seed,
    check_timeout,
)
from arrange_up.up.engine_io import (
    Refusal,
    answer_plan,
    generation_result,
    metric_text,
    read_problem_and_plan,
)
from arrange_up.up.registration import REPAIRER_NAME

__all__ = ["ArrangeUpFixtureRepairer"]


class ArrangeUpFixtureRepairer(Satisficing, ArrangeUpEngine, PlanRepairerMixin):
    """Fixture-placement plan repair (thesis ch. 4,
    :func:`arrange_up.repair.repair_plan`):
    ``PlanRepairer(name="arrange-up-fixtures", params={...}).repair(problem, plan)``.

    Parameters: ``particles`` (150), ``seed`` (0), ``method`` (``"enhanced"`` or
    ``"naive"``), ``workers`` (1), ``timeout`` (seconds, ``None``: none; unified-planning's
    ``repair`` takes no timeout, so it is an engine parameter). The plan is the nominal plan to
    repair (a ``SequentialPlan`` of place/push/pick) and must reach the goal in the
    deterministic semantics: fixtures make a nominal plan robust, they do not complete one.
    The result is a ``PlanGenerationResult``:

    * ``SOLVED_SATISFICING`` with the repaired plan, which reaches the goal in the
      deterministic semantics (replayed before answering);
    * ``UNSOLVABLE_INCOMPLETELY`` when the given plan does not reach the goal nominally (an
      action fails or is inapplicable, or the goal is missed: nothing is repaired), when a step
      could not be repaired, or when the repaired plan misses the goal nominally; the log
      message says which and why (the repair is greedy, so nothing is proven);
    * ``TIMEOUT`` when ``timeout`` ran out (checked between batches of candidates);
    * ``UNSUPPORTED_PROBLEM`` when the problem or the plan is not arrange-up's;
    * ``INTERNAL_ERROR`` when the repair raised.

    Metrics: ``status``, ``elapsed``, ``simulations``, ``pushes``, ``fixtures_placed``,
    ``plan_length``, ``method``, ``particles``, ``seed`` and ``step_K`` (the choice made for
    nominal step K).
    """

    _NAME = REPAIRER_NAME
    _PARAMETERS = ("particles", "seed", "method", "workers", "timeout")

    def __init__(
        self,
        particles: int = 150,
        seed: int = 0,
        method: str = "enhanced",
        workers: int = 1,
        timeout: float | None = None,
        **unknown: Any,
    ) -> None:
        self._refuse_unknown(unknown)
        Engine.__init__(self)
        PlanRepairerMixin.__init__(self)
        _check_repairer_params(particles, seed, method, workers)
        check_timeout(REPAIRER_NAME, timeout)
        self._particles = particles
        self._seed = seed
        self._method = method
        self._workers = workers
        self._timeout = timeout

    def _repair(self, problem: AbstractProblem, plan: Plan) -> PlanGenerationResult:
        started = time.monotonic()

        result = functools.partial(generation_result, REPAIRER_NAME)

        def refuse(
            message: str, status: Status = Status.UNSUPPORTED_PROBLEM
        ) -> PlanGenerationResult:
            return result(status, logs=[LogMessage(LogLevel.ERROR, message)])

        read = read_problem_and_plan(problem, plan)
        if isinstance(read, Refusal):
            status = Status.INTERNAL_ERROR if read.internal else Status.UNSUPPORTED_PROBLEM
            return refuse(read.message, status)
        arrangement, nominal = read
        shortfall = _nominal_shortfall(arrangement, nominal)
        if isinstance(shortfall, Refusal):
            return refuse(shortfall.message, Status.INTERNAL_ERROR)
        if shortfall is not None:
            return refuse(
                f"the plan is not a nominal plan of {arrangement.name!r}, so there is nothing "
                f"to repair: {shortfall} in the deterministic semantics. {REPAIRER_NAME} makes a "
                "plan that reaches the goal nominally robust with fixtures; it does not complete "
                "plans (plan one with OneshotPlanner(name='arrange-up', params={'semantics': "
                "'deterministic'}))",
                Status.UNSOLVABLE_INCOMPLETELY,
            )
        remaining = None
        if self._timeout is not None:
            remaining = max(0.0, started + self._timeout - time.monotonic())
        try:
            outcome = repair_plan(
                arrangement,
                nominal,
                particles=self._particles,
                seed=self._seed,
                method=self._method,
                workers=self._workers,
                timeout=remaining,
            )
        except ValueError as error:
            return refuse(f"the plan cannot be repaired: {error}", Status.UNSOLVABLE_INCOMPLETELY)
        except Exception as error:  # the engine must answer, not raise
            return result(
                Status.INTERNAL_ERROR,
                logs=[
                    LogMessage(
                        LogLevel.ERROR, f"{REPAIRER_NAME} failed: {type(error).__name__}: {error}"
                    )
                ],
            )
        stats = outcome.stats()
        metrics = {key: metric_text(value) for key, value in stats.items()}
        metrics.update(
            status=outcome.status,
            method=outcome.method,
            particles=str(outcome.particles),
            seed=str(outcome.seed),
        )
        for record in outcome.steps:
            if record.kind != "push":
                metrics[f"step_{record.index + 1}"] = f"{record.kind} kept"
            elif record.status != "ok":
                metrics[f"step_{record.index + 1}"] = "failed"
            else:
                where = (
                    "no fixture" if record.pose is None else f"{record.fixture} at {record.pose}"
                )
                metrics[f"step_{record.index + 1}"] = f"{where}, x{record.multiplier:g}"
        if outcome.status == TIMEOUT:
            message = f"timeout of {self._timeout} s reached before the plan was repaired"
            return result(Status.TIMEOUT, None, [LogMessage(LogLevel.INFO, message)], metrics)
        if not outcome.solved or outcome.actions is None:
            return result(
                Status.UNSOLVABLE_INCOMPLETELY,
                None,
                [LogMessage(LogLevel.INFO, f"the repair {outcome.status}: {outcome.reason}")],
                metrics,
            )
        repaired, logs = answer_plan(problem, arrangement, outcome.actions)
        # the plan handed out, as exact decimals, must reach the goal nominally: check it
        shortfall = _nominal_shortfall(arrangement, plan_from_up(repaired))
        if isinstance(shortfall, Refusal):
            return refuse(shortfall.message, Status.INTERNAL_ERROR)
        if shortfall is not None:
            metrics["status"] = "missed-goal"
            message = (
                f"the repair made a plan, but it does not reach the goal in the deterministic "
                f"semantics: {shortfall}; no plan is returned"
            )
            return result(
                Status.UNSOLVABLE_INCOMPLETELY, None, [LogMessage(LogLevel.INFO, message)], metrics
            )
        return result(Status.SOLVED_SATISFICING, repaired, logs, metrics)


def _check_repairer_params(particles: Any, seed: Any, method: Any, workers: Any) -> None:
    check_count(f"{REPAIRER_NAME}: particles", particles)
    check_seed(REPAIRER_NAME, seed)
    if method not in METHODS:
        expected = " or ".join(repr(m) for m in METHODS)
        raise ValueError(f"{REPAIRER_NAME}: method must be {expected}, got {method!r}")
    check_count(f"{REPAIRER_NAME}: workers", workers)


def _nominal_shortfall(
    problem: ArrangementProblem, actions: Sequence[Action]
) -> str | Refusal | None:
    """Why ``actions`` do not reach ``problem``'s goal in the deterministic semantics (the
    nominal planner's transition: no noise, nominal initial poses), ``None`` when they do, or a
    :class:`Refusal` when the replay itself failed.

    The replay applies the symbolic preconditions of :func:`arrange_up.up.compile.to_up`'s
    actions (place an off-table part or fixture, push with an off-table manipulator, pick an
    on-table object), then each action's deterministic outcome
    (:class:`~arrange_up.transitions.particles.DeterministicSemantics`), then the planner's goal
    test (:class:`~arrange_up.belief.goals.GoalTest`)."""
    try:
        return _replay_shortfall(problem, actions)
    except Exception as error:  # the engines answer, they never raise
        message = f"the nominal replay failed: {type(error).__name__}: {error}"
        return Refusal(message, internal=True)


def _replay_shortfall(problem: ArrangementProblem, actions: Sequence[Action]) -> str | None:
    kinds = {spec.name: spec.kind for spec in problem.objects}
    model = DeterministicSemantics(problem)
    try:
        belief = model.initial_belief()
        for k, action in enumerate(actions):
            on_table = belief.particles[0].names()
            refusal = _precondition_failure(action, kinds, on_table)
            if refusal:
                return f"action {k + 1} ({_describe(action)}) {refusal}"
            after = model.apply(belief, action)
            if after is None:
                return (
                    f"action {k + 1} ({_describe(action)}) fails: an object leaves the table or "
                    "never comes to rest"
                )
            belief = after
    finally:
        model.close()
    misses = GoalTest(problem).misses(belief.particles[0])
    if not misses:
        return None
    where = "; ".join(
        f"{miss.part} {', '.join(miss.dimensions())}"
        + (
            ""
            if miss.missing
            else " (by " + ", ".join(f"{e:.4g}" for e in miss.excess if e > 0) + ")"
        )
        for miss in misses
    )
    return f"after its {len(actions)} action(s) the goal is not reached: {where}"


def _precondition_failure(
    action: Action, kinds: dict[str, ObjectKind], on_table: Sequence[str]
) -> str | None:
    name = action.manipulator if isinstance(action, Push) else action.obj
    kind = kinds.get(name)
    if kind is None:
        return f"names {name!r}, which is not an object of the problem"
    if isinstance(action, Place):
        if kind not in (ObjectKind.PART, ObjectKind.FIXTURE):
            return f"places {name}, a {kind.value}: only parts and fixtures are placed"
        if name in on_table:
            return f"places {name}, which is already on the table"
    elif isinstance(action, Push):
        if kind is not ObjectKind.MANIPULATOR:
            return f"pushes with {name}, a {kind.value}, not a manipulator"
        if name in on_table:
            return f"pushes with {name}, which is on the table"
    elif kind is ObjectKind.OBSTACLE or name not in on_table:
        return f"picks {name}, which is not a movable object on the table"
    return None


def _describe(action: Action) -> str:
    if isinstance(action, Push):
        return f"push with {action.manipulator}"
    return f"{type(action).__name__.lower()} {action.obj}"
