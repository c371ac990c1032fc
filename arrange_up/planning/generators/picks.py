"""Picks: fixtures and manipulators on the table may be picked up, except a fence that holds a
part at its goal while the part still misses its goal along the other axis
(:meth:`~arrange_up.planning.fences.Fences.holding`); parts are never picked by the planner (a
part must end on the table)."""

from __future__ import annotations

from arrange_up.belief.states import IntervalBelief
from arrange_up.model.problem import ArrangementProblem, ObjectKind
from arrange_up.model.world import Pick
from arrange_up.planning.fences import Fences
from arrange_up.planning.generators.targets import GoalTargets


class PickGenerator:
    """The pick candidates of one problem's beliefs (see the module docstring)."""

    def __init__(self, problem: ArrangementProblem, fences: Fences, targets: GoalTargets) -> None:
        self.problem = problem
        self.fences = fences
        self.targets = targets

    def picks(self, belief: IntervalBelief) -> list[Pick]:
        """Picks of the fixtures and manipulators on the table, except a fence that holds a
        goal part at its goal while that part still has pushes to come."""
        kinds = (ObjectKind.FIXTURE, ObjectKind.MANIPULATOR)
        keep = (
            self.fences.holding(belief, self.targets.part_inside(belief))
            if self.fences.needs
            else ()
        )
        return [
            Pick(name)
            for name in belief.names()
            if self.problem.object(name).kind in kinds and name not in keep
        ]
