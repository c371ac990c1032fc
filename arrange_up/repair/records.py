"""What a repair reports: its status, one record per nominal step, its statistics, and the
plan file it writes (a plan document of semantics ``fixtures`` with a ``repair`` object), and
reading that record back (:func:`plan_groups`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from enum import StrEnum
from typing import Any

from arrange_up.belief.states import ParticleBelief
from arrange_up.io.planfile import PlanFileError, action_from_json, action_to_json, plan_document
from arrange_up.model.problem import ArrangementProblem, Pose
from arrange_up.model.units import Units
from arrange_up.model.world import Action, Push
from arrange_up.repair.candidates import (
    BLOCKED,
    GRID_STEP,
    INVALID,
    MULTIPLIERS,
    StepScores,
    json_float,
    json_round,
)

#: The ``semantics`` a repaired plan file records.
REPAIR_SEMANTICS = "fixtures"


class RepairStatus(StrEnum):
    """How a repair ended (its JSON form is the string)."""

    SOLVED = "solved"
    """Every step repaired; ``actions`` is the repaired plan."""
    FAILED = "failed"
    """A step could not be propagated; ``reason`` says which and why."""
    TIMEOUT = "timeout"
    """The wall-clock limit was reached."""


class StepRepairStatus(StrEnum):
    """How the repair of one nominal step ended (its JSON form is the string)."""

    OK = "ok"
    FAILED = "failed"


SOLVED = RepairStatus.SOLVED
FAILED = RepairStatus.FAILED
TIMEOUT = RepairStatus.TIMEOUT


@dataclass(frozen=True)
class StepRecord:
    """What the repair did with one action of the nominal plan.

    ``kind`` is the nominal action's type; ``actions`` what replaced it (the action itself for a
    place or pick). For a push: the chosen ``fixture``, ``pose`` and ``multiplier``, the chosen
    candidate's ``distance`` and the bare nominal push's (``nominal_distance``, multiplier 1,
    ``inf`` if invalid), the chosen candidate's ``reliability`` and the bare nominal push's
    (``nominal_reliability``; ``None`` when not estimated), the approach ``backoff`` (see
    :class:`StepScores`) and candidate counts (``rejected``: valid candidates refused because
    the plan would no longer be a nominal plan with them; ``stops``: placements made to stop a
    part where its end is uncertain, blocked ones left out). ``status`` is ``"ok"`` or
    ``"failed"``.
    """

    index: int
    kind: str
    nominal: Action
    actions: tuple[Action, ...]
    status: str = StepRepairStatus.OK
    reason: str = ""
    fixture: str | None = None
    pose: Pose | None = None
    multiplier: float | None = None
    distance: float | None = None
    nominal_distance: float | None = None
    score: float | None = None
    reliability: float | None = None
    nominal_reliability: float | None = None
    placements: int = 0
    stops: int = 0
    blocked: int = 0
    invalid: int = 0
    unreachable: int = 0
    rejected: int = 0
    selection_multiplier: float | None = None
    backoff: float = 0.0
    simulations: int = 0
    elapsed: float = 0.0

    @classmethod
    def of_push(cls, index: int, push: Push, scores: StepScores) -> StepRecord:
        """The record of a push from its one-step fixture problem's ``scores``."""
        best = scores.best
        bare = next(c for c in scores.refined if c.fixture is None and c.multiplier == 1.0)
        placements = [c for c in scores.placements if c.fixture is not None]
        common = {
            "placements": len(placements),
            "blocked": sum(1 for c in placements if c.status == BLOCKED),
            "invalid": sum(1 for c in scores.placements if c.status == INVALID),
            "unreachable": sum(1 for c in placements if not c.reachable),
            "rejected": len(scores.rejected),
            "selection_multiplier": scores.selection_multiplier,
            "backoff": scores.backoff,
            "nominal_distance": bare.distance,
            "nominal_reliability": bare.reliability,
            "stops": len({(c.fixture, c.pose) for c in scores.refined if c.stop}),
            "simulations": scores.simulations,
            "elapsed": scores.elapsed,
        }
        if best is None and any(c.valid for c in scores.refined):
            reasons = sorted({why for _, why in scores.rejected})
            return cls(
                index,
                "push",
                push,
                (),
                status=StepRepairStatus.FAILED,
                reason="every valid candidate would make the plan fail nominally, or is a "
                "fixture scoring worse than the bare push (no fixture "
                f"and {len(placements) - common['blocked']} placements, multipliers "
                f"{', '.join(f'{m:g}' for m in MULTIPLIERS)}): " + "; ".join(reasons),
                **common,
            )
        if best is None:
            reasons = sorted({c.reason for c in scores.refined if c.reason})
            return cls(
                index,
                "push",
                push,
                (),
                status=StepRepairStatus.FAILED,
                reason="every candidate is invalid (no fixture and "
                f"{len(placements) - common['blocked']} placements, multipliers "
                f"{', '.join(f'{m:g}' for m in MULTIPLIERS)}): " + "; ".join(reasons),
                **common,
            )
        return cls(
            index,
            "push",
            push,
            best.actions(),
            fixture=best.fixture,
            pose=best.pose,
            multiplier=best.multiplier,
            distance=best.distance,
            score=best.score,
            reliability=best.reliability,
            **common,
        )

    def describe_choice(self, problem: ArrangementProblem) -> str:
        """A short text of what was chosen (for progress lines)."""
        if self.kind != "push":
            return f"{self.kind} kept"
        units = problem.units
        # the score, not a push length: the mean distance of the outcomes from the nominal
        # next state, the bare nominal push's beside it (None when that push was invalid)
        bare = "invalid" if self.nominal_distance is None else f"{self.nominal_distance:.3f}"
        distance = f"mean distance to the nominal state {self.distance:.3f} (bare push {bare})"
        if self.reliability is not None:
            nominal = (
                "invalid"
                if self.nominal_reliability is None
                else f"{100 * self.nominal_reliability:.0f} %"
            )
            distance = (
                f"the rest of the plan reaches the goal from {100 * self.reliability:.0f} % "
                f"(bare push {nominal}), {distance}"
            )
        if self.fixture is None or self.pose is None:
            return f"no fixture, x{self.multiplier:g}, {distance}"
        x, y, theta = units.pose_out(self.pose)
        where = f"{self.fixture} at ({x:.3g}, {y:.3g}, {theta:.3g})"
        return f"{where}, x{self.multiplier:g}, {distance}"

    def to_json(self, units: Any, first: int) -> dict[str, Any]:
        """JSON of the record; ``first`` is the index of its first action in the plan."""
        data: dict[str, Any] = {
            "step": self.index + 1,
            "kind": self.kind,
            "status": self.status,
            "nominal": action_to_json(self.nominal, units),
            "plan_actions": [first, first + len(self.actions)],
        }
        if self.reason:
            data["reason"] = self.reason
        if self.kind == "push":
            data.update(
                fixture=self.fixture,
                pose=None
                if self.pose is None
                else [json_round(v) for v in units.pose_out(self.pose)],
                multiplier=self.multiplier,
                distance=json_float(self.distance),
                nominal_distance=json_float(self.nominal_distance),
                reliability=json_float(self.reliability),
                nominal_reliability=json_float(self.nominal_reliability),
                selection_multiplier=self.selection_multiplier,
                backoff=json_round(self.backoff),
                placements=self.placements,
                stops=self.stops,
                blocked=self.blocked,
                invalid=self.invalid,
                unreachable=self.unreachable,
                rejected=self.rejected,
                simulations=self.simulations,
                elapsed=json_round(self.elapsed),
            )
        return data


@dataclass(frozen=True)
class RepairStats:
    """Summary statistics of a repair; :meth:`to_json` is the plan file's ``search`` object.

    ``steps`` and ``nominal_length`` both count the nominal plan's actions; ``plan_length`` is
    ``None`` unless the repair solved.
    """

    elapsed: float
    simulations: int
    steps: int
    pushes: int
    fixtures_placed: int
    nominal_length: int
    plan_length: int | None

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


@dataclass(frozen=True)
class RepairResult:
    """The outcome of :func:`~arrange_up.repair.repairer.repair_plan`.

    ``actions`` is the repaired plan when ``status == "solved"``, else ``None`` (``partial``
    holds what was repaired before the failure). ``steps`` has one record per nominal action
    handled (the failing one last). ``beliefs`` holds the particle belief before the first
    action and after each step. ``fixtures`` is ``False`` for the fixtures' ablation (no
    placement was a candidate); the plan file's ``repair`` object then says
    ``"fixtures": false`` (it names no ``fixtures`` key otherwise).
    """

    status: RepairStatus
    actions: tuple[Action, ...] | None
    nominal: tuple[Action, ...]
    steps: tuple[StepRecord, ...]
    elapsed: float
    method: str
    particles: int
    seed: int
    reason: str = ""
    simulations: int = 0
    partial: tuple[Action, ...] = ()
    beliefs: tuple[ParticleBelief, ...] = field(default=(), repr=False, compare=False)
    fixtures: bool = True

    @property
    def solved(self) -> bool:
        return self.status == SOLVED

    @property
    def statistics(self) -> RepairStats:
        pushes = [s for s in self.steps if s.kind == "push"]
        return RepairStats(
            elapsed=self.elapsed,
            simulations=self.simulations,
            steps=len(self.nominal),
            pushes=len(pushes),
            fixtures_placed=sum(1 for s in pushes if s.fixture is not None),
            nominal_length=len(self.nominal),
            plan_length=None if self.actions is None else len(self.actions),
        )

    def stats(self) -> dict[str, Any]:
        """The statistics' JSON form (the plan file's ``search`` object)."""
        return self.statistics.to_json()

    def repair_json(self, problem: ArrangementProblem) -> dict[str, Any]:
        """The plan file's ``repair`` object: settings, the nominal plan, per-step choices."""
        steps, first = [], 0
        for record in self.steps:
            steps.append(record.to_json(problem.units, first))
            first += len(record.actions)
        data: dict[str, Any] = {
            "method": self.method,
            "particles": self.particles,
            "seed": self.seed,
        }
        if not self.fixtures:  # absent for a full repair: its record is as it always was
            data["fixtures"] = False
        data.update(
            {
                "multipliers": list(MULTIPLIERS),
                "grid_step": GRID_STEP,
                "nominal": [action_to_json(a, problem.units) for a in self.nominal],
                "steps": steps,
            }
        )
        if self.reason:
            data["reason"] = self.reason
        return data

    def document(self, problem: ArrangementProblem) -> dict[str, Any]:
        """The plan file (:func:`arrange_up.io.planfile.plan_document`, semantics ``fixtures``)."""
        return plan_document(
            problem,
            self.actions,
            status=self.status,
            semantics=REPAIR_SEMANTICS,
            seed=self.seed,
            search=self.stats(),
            extra={"particles": self.particles, "repair": self.repair_json(problem)},
        )


def plan_groups(
    problem: ArrangementProblem, actions: Sequence[Action], document: dict[str, Any] | None
) -> tuple[tuple[Action, ...], tuple[tuple[Action, ...], ...], dict[str, Any]]:
    """Split a plan read from a file into ``(nominal, groups, settings)``.

    For a repaired plan (its document has a ``repair`` object) ``nominal`` is the nominal plan
    recorded there, ``groups[k]`` the actions that replaced nominal action ``k`` and
    ``settings`` the repair's ``particles``, ``seed``, ``method`` and, for the fixtures'
    ablation, ``fixtures`` (false). For any other plan the
    plan is its own nominal plan, one action per group, and ``settings`` is empty.
    """
    actions = tuple(actions)
    repair = (document or {}).get("repair")
    if not isinstance(repair, dict):
        return actions, tuple((a,) for a in actions), {}
    raw_units = (document or {}).get("units", {})
    units = Units(raw_units.get("length", "in"), raw_units.get("angle", "deg"))
    try:
        nominal = tuple(
            action_from_json(item, units, problem, f"repair.nominal[{i}]")
            for i, item in enumerate(repair["nominal"])
        )
        groups = []
        for record in repair["steps"]:
            start, stop = record["plan_actions"]
            groups.append(actions[start:stop])
    except (KeyError, TypeError, ValueError) as error:
        raise PlanFileError(f"repair: malformed repair record: {error}") from None
    settings = {
        key: repair[key] for key in ("particles", "seed", "method", "fixtures") if key in repair
    }
    return nominal, tuple(groups), settings
