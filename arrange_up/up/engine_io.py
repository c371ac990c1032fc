"""What arrange-up's engines read and answer: the arrange-up problem and plan of a
unified-planning problem and plan, or a :class:`Refusal` saying why there are none (an engine
answers with it, it never raises); the unified-planning plan of an arrange-up plan; metrics as
strings; and the planner's and the repairer's ``PlanGenerationResult``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

from unified_planning.engines import LogLevel, LogMessage, PlanGenerationResult
from unified_planning.engines import PlanGenerationResultStatus as Status
from unified_planning.model import AbstractProblem
from unified_planning.plans import Plan

from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action, Push
from arrange_up.up.compile import (
    equip_pddl_problem,
    from_up,
    made_by_to_up,
    plan_from_up,
    plan_to_up,
)


@dataclass(frozen=True)
class Refusal:
    """Why a problem or plan cannot be read: ``internal`` False when it is not arrange-up's,
    True when reading it failed (an arrange-up defect). Engines answer with the message, they
    never raise."""

    message: str
    internal: bool = False


def read_problem(problem: AbstractProblem) -> ArrangementProblem | Refusal:
    """The arrange-up problem of a unified-planning ``problem``, or why there is none."""
    try:
        return from_up(problem)
    except ValueError as error:  # ProblemFormatError is a ValueError
        return Refusal(f"not an arrange-up problem: {error}")
    except Exception as error:  # from_up refuses foreign problems with ValueError; anything
        # else is a defect of the reader, reported as such rather than raised
        return Refusal(f"reading the problem failed: {type(error).__name__}: {error}", True)


def read_problem_and_plan(
    problem: AbstractProblem, plan: Plan
) -> tuple[ArrangementProblem, tuple[Action, ...]] | Refusal:
    """The arrange-up problem and action list of a unified-planning ``problem`` and ``plan``,
    or why not (the validator and the repairer answer with it; engines never raise)."""
    arrangement = read_problem(problem)
    if isinstance(arrangement, Refusal):
        return arrangement
    try:
        actions = plan_from_up(plan, arrangement)
    except ValueError as error:
        return Refusal(f"not a sequential plan of place/push/pick actions: {error}")
    except Exception as error:  # plan_from_up refuses foreign plans with ValueError
        return Refusal(f"reading the plan failed: {type(error).__name__}: {error}", True)
    return arrangement, actions


def answer_plan(
    problem: AbstractProblem, arrangement: ArrangementProblem, actions: Sequence[Action]
) -> tuple[Plan, list[LogMessage]]:
    """The unified-planning plan of ``actions`` for ``problem``, over ``problem``'s own actions,
    and the log messages to return with it. A problem read from PDDL, whose actions have no
    real parameters, is first given them and their simulated effects, in place
    (:func:`arrange_up.up.compile.equip_pddl_problem`), and a log message says so."""
    logs = []
    if not made_by_to_up(problem):
        equip_pddl_problem(problem, arrangement)
        logs.append(
            LogMessage(
                LogLevel.INFO,
                "the problem came from PDDL, whose actions have no real parameters: its place "
                "and push actions were given the poses and distances (and the simulated "
                "effects) of arrange_up.up.compile.to_up's model, in place",
            )
        )
    return plan_to_up(problem, [plain_action(a) for a in actions]), logs


def plain_action(action: Action) -> Action:
    """The action with plain Python floats (the planner may hand out numpy scalars)."""
    pose = tuple(float(v) for v in getattr(action, "pose", ()))
    if isinstance(action, Push):
        return replace(action, pose=pose, distance=float(action.distance))
    if pose:
        return replace(action, pose=pose)
    return action


def metric_text(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def generation_result(
    engine: str,
    status: Status,
    plan: Plan | None = None,
    logs: Sequence[LogMessage] = (),
    metrics: dict[str, str] | None = None,
) -> PlanGenerationResult:
    """The planner's or the repairer's answer, named ``engine`` (no log list when empty)."""
    return PlanGenerationResult(
        status, plan, engine, metrics=metrics, log_messages=list(logs) or None
    )
