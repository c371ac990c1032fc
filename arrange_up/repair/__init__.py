"""Fixture-placement plan repair (thesis ch. 4): make a nominal plan robust by placing fixtures.

One module per concern:

* :mod:`~arrange_up.repair.nominal`: distinct nominal plans (:func:`nominal_plans`);
* :mod:`~arrange_up.repair.candidates`: the candidates of a one-step fixture problem, their
  scores and the winner (:class:`Candidate`, :class:`StepScores`, the tuning constants);
* :mod:`~arrange_up.repair.reliability`: how reliably the rest of the plan reaches the goal
  from a candidate's outcome, the score candidates are ranked by (:class:`RemainingPlan`);
* :mod:`~arrange_up.repair.repairer`: the repair itself (:func:`repair_plan`,
  :func:`step_scores`);
* :mod:`~arrange_up.repair.records`: what a repair reports and the plan file it writes
  (:class:`RepairResult`, :class:`StepRecord`, :class:`RepairStats`, :func:`plan_groups`).

Every public name is importable from here.
"""

from arrange_up.repair.candidates import (
    BACKOFF_GAP,
    BACKOFF_STEP,
    BLOCKED,
    GRID_STEP,
    INVALID,
    MAX_BACKOFF,
    MIN_FIXTURE_GAIN,
    MULTIPLIERS,
    OK,
    REFINE,
    SELECTION_MULTIPLIER,
    Candidate,
    CandidateStatus,
    StepScores,
)
from arrange_up.repair.nominal import nominal_plans
from arrange_up.repair.records import (
    FAILED,
    REPAIR_SEMANTICS,
    SOLVED,
    TIMEOUT,
    RepairResult,
    RepairStats,
    RepairStatus,
    StepRecord,
    StepRepairStatus,
    plan_groups,
)
from arrange_up.repair.reliability import MIN_ROLLOUTS, RemainingPlan
from arrange_up.repair.repairer import (
    DEFAULT_PARTICLES,
    METHODS,
    ProgressCallback,
    repair_plan,
    step_scores,
)

__all__ = [
    "BACKOFF_GAP",
    "BACKOFF_STEP",
    "BLOCKED",
    "DEFAULT_PARTICLES",
    "FAILED",
    "GRID_STEP",
    "INVALID",
    "MAX_BACKOFF",
    "METHODS",
    "MIN_ROLLOUTS",
    "MIN_FIXTURE_GAIN",
    "MULTIPLIERS",
    "OK",
    "REFINE",
    "REPAIR_SEMANTICS",
    "SELECTION_MULTIPLIER",
    "SOLVED",
    "TIMEOUT",
    "Candidate",
    "CandidateStatus",
    "ProgressCallback",
    "RemainingPlan",
    "RepairResult",
    "RepairStats",
    "RepairStatus",
    "StepRecord",
    "StepScores",
    "StepRepairStatus",
    "nominal_plans",
    "plan_groups",
    "repair_plan",
    "step_scores",
]
