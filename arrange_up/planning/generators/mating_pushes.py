"""Mating pushes (:mod:`arrange_up.planning.mating`): for a part whose relative goal holds it
against the reference part ahead along the push.

* the goal-directed push stopped short by the goal tolerance, or by the part's spread relative
  to the reference where that is wider, while the part still misses its goal interval across
  the push (brought beside its notch, with room to slide into it from the side; only with
  ``clearance_pushes``, which the planner sets for a semantics of more than one particle: a
  single nominal state has no spread to make room for, and a deterministic plan would end with
  the part at its goal interval's edge);
* under the compliant controller, while the part misses its goal interval along the push, a
  seating push to the goal coordinate plus the part's
  :func:`~arrange_up.physics.stall.wall_overdrive` (pressed against the reference as against
  a wall).
"""

from __future__ import annotations

from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.model.problem import ArrangementProblem, Pose
from arrange_up.planning.generators.common import MIN_PUSH, PushOptions
from arrange_up.planning.generators.stall import PushStall
from arrange_up.planning.generators.targets import GoalTargets
from arrange_up.planning.mating import Mates


class MatingPushes:
    """The mating pushes of one problem's parts (see the module docstring)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        mates: Mates,
        targets: GoalTargets,
        stall: PushStall,
        options: PushOptions,
    ) -> None:
        self.problem = problem
        self.mates = mates
        self.targets = targets
        self.stall = stall
        self.options = options

    def pushes(
        self,
        name: str,
        interval: ObjectInterval,
        belief: IntervalBelief,
        target: Pose,
        axis: int,
        sign: int,
    ) -> list[tuple[float, float | None]]:
        """The pushes of a part whose relative goal holds it against its mate ahead along the
        push, as ``(travel of the set point beyond the free travel, travel of the part or
        None)``: while the part misses its goal interval across the push, the goal-directed
        push stopped short by the goal tolerance, or by the part's spread relative to its mate
        where that is wider (a travel, solved for like the goal-directed one); and under the
        compliant controller, while the part misses its goal interval along the push, the
        seating push to the goal coordinate plus the part's wall overdrive (None: it stops at
        the contact)."""
        mate = belief.get(self.mates.reference)
        if mate is None or not self.mates.ahead(name, target, mate.center, axis, sign):
            return []
        travel = sign * (target[axis] - interval.center[axis])
        pushes: list[tuple[float, float | None]] = []
        # Room for every state to slide in: the part's spread relative to its mate (both
        # intervals' half-widths along the push), and at least the goal tolerance.
        room = max(self.problem.goal.tolerance[axis], interval.half[axis] + mate.half[axis])
        clear = travel - room
        # Clearance only while the slide into the notch (along the other axis) is still to
        # come: after it, a push that stops at the goal interval's edge is no step forward.
        if (
            self.options.clearance_pushes
            and clear > MIN_PUSH
            and not self.targets.inside_goal(interval, target, 1 - axis)
        ):
            pushes.append((clear, clear))
        over = self.stall.overdrive(self.stall.areas[name], axis)
        if over is not None and not self.targets.inside_goal(interval, target, axis):
            pushes.append((travel + over, None))
        return pushes
