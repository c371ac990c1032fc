"""Where the goal wants each part, given a belief, and whether a part is there yet.

For an absolute goal a part's target is its goal pose. For a relative goal it is the goal pose
composed with the reference part's current belief centre; the reference itself, when it starts
off the table, is put down about :attr:`~arrange_up.planning.mating.Mates.home` (its goal is
anywhere: there, the goal arrangement is centred on the table), or, where no place there is
clear, about the first of the other :attr:`~arrange_up.planning.mating.Mates.homes` that has a
clear place. Every generator asks this module; none asks the goal directly.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from arrange_up.belief.states import IntervalBelief, ObjectInterval, symmetry_period, wrap_angle
from arrange_up.model.problem import ArrangementProblem, Pose
from arrange_up.planning.mating import Mates


class GoalTargets:
    """The goal targets of one problem's parts (see the module docstring)."""

    def __init__(self, problem: ArrangementProblem, mates: Mates) -> None:
        self.problem = problem
        self.mates = mates
        self.periods = {spec.name: symmetry_period(spec.shape) for spec in problem.parts}

    def place_target(self, name: str, belief: IntervalBelief) -> Pose | None:
        """Where ``name`` should end according to the goal, given ``belief`` (None if unknown);
        for a relative goal's reference off the table, where to put it down
        (:attr:`Mates.home`: its goal is anywhere)."""
        goal = self.problem.goal
        if name == goal.reference and name not in belief:
            return self.mates.home
        if name not in goal.parts:
            return None
        target = goal.target(name)
        if goal.reference is None:
            return target
        ref = belief.get(goal.reference)
        if ref is None:
            return None
        rx, ry, rt = ref.center
        c, s = math.cos(rt), math.sin(rt)
        return (
            rx + c * target[0] - s * target[1],
            ry + s * target[0] + c * target[1],
            rt + target[2],
        )

    def place_targets(self, name: str, belief: IntervalBelief) -> tuple[Pose, ...]:
        """The poses about which ``name`` is placed, to be tried in order: its
        :meth:`place_target`, or for a relative goal's reference off the table every one of
        :attr:`Mates.homes` (the first with a clear place is used)."""
        if name == self.problem.goal.reference and name not in belief:
            return self.mates.homes
        target = self.place_target(name, belief)
        return () if target is None else (target,)

    def inside_goal(self, interval: ObjectInterval, target: Pose, axis: int) -> bool:
        """Whether ``interval`` lies inside ``target`` +- the goal tolerance along ``axis``."""
        tolerance = self.problem.goal.tolerance[axis] + 1e-9
        return abs(interval.center[axis] - target[axis]) + interval.half[axis] <= tolerance

    def settled(self, parts: tuple[str, ...], belief: IntervalBelief, axis: int) -> bool:
        """Whether every one of ``parts`` lies within its goal interval along ``axis`` in every
        state of ``belief`` (its interval inside the target +- the tolerance)."""
        for part in parts:
            target = self.place_target(part, belief)
            interval = belief.get(part)
            if target is None or interval is None:
                return False
            if not self.inside_goal(interval, target, axis):
                return False
        return True

    def part_inside(self, belief: IntervalBelief) -> Callable[[str, int], bool]:
        """``inside(part, axis)``: whether ``part`` lies within its goal along ``axis``."""

        def inside(part: str, axis: int) -> bool:
            target, interval = self.place_target(part, belief), belief.get(part)
            return (
                target is not None
                and interval is not None
                and self.inside_goal(interval, target, axis)
            )

        return inside

    def turned_away(self, name: str, interval: ObjectInterval, belief: IntervalBelief) -> bool:
        """Whether part ``name``'s belief is centred on an angle outside its goal angle's
        tolerance (the difference taken modulo the part's symmetry period, as the goal test
        does). A belief only wider than the tolerance is not: pressing it against a wall with
        the centred pushes narrows it."""
        target = self.place_target(name, belief)
        if target is None:
            return False
        period = self.periods[name]
        tolerance = self.problem.goal.tolerance[2]
        if tolerance is None or tolerance >= 0.5 * period:
            return False  # any angle will do
        off = wrap_angle(interval.center[2], target[2], period) - target[2]
        return abs(off) > tolerance + 1e-9
