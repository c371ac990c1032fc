"""Places of parts (thesis Figure 2-10).

For every goal part off the table, candidates at the part's goal target
(:mod:`~arrange_up.planning.generators.targets`) plus offsets from a 3 x 3 grid
(``planning.place_offsets`` replaces the grid). The default step is the growth of the part's
place shadow over its nominal footprint plus 0.1 in: just enough for the place precondition to
hold next to walls and neighbours, and no more, since every extra inch must be pushed and
pushing accrues uncertainty. The angle is the target's (``planning.place_angles`` adds
alternatives).

The precondition is tested on belief shadows (:mod:`arrange_up.geometry.collision`): the
placed part's shadow (target +- place uncertainty) must lie on the table and touch no shadow of
an object on the table, no wall and no obstacle.
"""

from __future__ import annotations

from collections.abc import Iterator

from arrange_up.belief.states import IntervalBelief
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem, ObjectSpec, Pose
from arrange_up.model.world import Place
from arrange_up.planning.generators.common import clean_pose
from arrange_up.planning.generators.targets import GoalTargets


class PlaceGenerator:
    """The place candidates of the parts off the table (see the module docstring)."""

    def __init__(
        self, problem: ArrangementProblem, checker: CollisionChecker, targets: GoalTargets
    ) -> None:
        self.problem = problem
        self.checker = checker
        self.targets = targets
        hints = problem.planning
        self.place_angles = tuple(hints.place_angles or ())
        self.place_unc = problem.uncertainty.place
        #: Part name -> its place offsets ``(dx, dy)`` from the target, in the order tried.
        self.offsets = {
            spec.name: tuple(hints.place_offsets) if hints.place_offsets else self._grid(spec)
            for spec in problem.parts
        }

    def _grid(self, spec: ObjectSpec) -> tuple[tuple[float, float], ...]:
        nominal = self.checker.shadow_box(spec.name, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        shadow = self.checker.shadow_box(spec.name, (0.0, 0.0, 0.0), self.place_unc)
        growth = max(nominal[0] - shadow[0], nominal[1] - shadow[1])
        step = round(growth + 0.1, 3)
        return tuple((i * step, j * step) for j in (1, 0, -1) for i in (-1, 0, 1))

    def places(self, belief: IntervalBelief, only: str | None = None) -> list[Place]:
        """Place candidates of every goal part off the table (or of ``only``)."""
        on_table = [(name, iv.center, iv.half) for name, iv in belief.objects]
        boxes = None  # their shadow boxes, once a place is tested
        actions = []
        for spec in self.problem.parts:
            if spec.name in belief or (only is not None and spec.name != only):
                continue
            for target in self.targets.place_targets(spec.name, belief):
                found = len(actions)
                for pose in self._place_grid(spec.name, target):
                    if boxes is None:
                        boxes = [self.checker.shadow_box(*shadow) for shadow in on_table]
                    if self._place_ok(spec.name, pose, self.place_unc, on_table, boxes):
                        actions.append(Place(spec.name, clean_pose(pose)))
                if len(actions) > found:
                    break
        return actions

    def place_poses(self, belief: IntervalBelief, name: str) -> list[Pose]:
        """Candidate place poses of ``name`` that fit the table, walls and obstacles, whatever
        the objects on the table (those are the precondition's other half); for a relative
        goal's reference, about the first of :attr:`Mates.homes` that has any."""
        for target in self.targets.place_targets(name, belief):
            poses = [
                pose
                for pose in self._place_grid(name, target)
                if self.checker.shadow_inside_table(name, pose, self.place_unc)
                and not self.checker.shadow_hits_fixed(name, pose, self.place_unc)
            ]
            if poses:
                return poses
        return []

    def _place_grid(self, name: str, target: Pose) -> Iterator[Pose]:
        """The place poses of ``name`` about ``target``: each of its grid offsets, at each of
        :meth:`_place_angles`, in that order."""
        angles = self._place_angles(target)
        for dx, dy in self.offsets[name]:
            for theta in angles:
                yield (target[0] + dx, target[1] + dy, theta)

    def _place_angles(self, target: Pose) -> tuple[float, ...]:
        """The target's angle, then each ``planning.place_angles`` offset from it, once each."""
        return tuple(dict.fromkeys((target[2],) + tuple(target[2] + a for a in self.place_angles)))

    def _place_ok(self, name, pose, half, on_table, boxes) -> bool:
        return self.checker.shadow_inside_table(name, pose, half) and self.checker.shadow_clear(
            name, pose, half, on_table, boxes
        )
