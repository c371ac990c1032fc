"""Places of parts (thesis Figure 2-10).

For every goal part off the table, candidates at the part's goal target
(:mod:`~arrange_up.planning.generators.targets`) plus offsets from a 3 x 3 grid
(``planning.place_offsets`` replaces the grid). The default step is the growth of the part's
place shadow over its nominal footprint plus 0.1 in: just enough for the place precondition to
hold next to walls and neighbours, and no more, since every extra inch must be pushed and
pushing accrues uncertainty. The angle is the target's (``planning.place_angles`` adds
alternatives).

Where no offset of the grid is clear at any target (a part whose goal is pressed against a
part already built, whose shadow has grown with its pushes, or a clearance fit narrower than
the place uncertainty), the places are sought on *rings* farther out, one ring at a time, up to
the first with a clear place (:func:`rings`): ring k holds the offsets k grid steps from the
target, out to the table's size. From such a place a push brings the part in. Only then, so
that parts with a clear place nearby keep the shortest pushes. A relative goal's parts get no
rings: a part must end beside its reference, which may move, and where no place beside it is
clear the reference is moved first (the reference ladder,
:mod:`~arrange_up.planning.generators.distances`). But where the reference's own shadow is
what blocks every place of a mate's grid (each would be clear without it: a goal flush against
the reference, whose shadow is wider than the grid's step), moving the reference moves the grid
with it, so the mate gets the rings up to :data:`FULL_RINGS` (:meth:`PlaceGenerator._mate_rings`).
The same holds where the shadows of the reference and of the other mates block it together (a
mate flush against another mate, as in a row of mates on the reference).

The precondition is tested on belief shadows (:mod:`arrange_up.geometry.collision`): the
placed part's shadow (target +- place uncertainty) must lie on the table and touch no shadow of
an object on the table, no wall and no obstacle.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator

from arrange_up.belief.states import IntervalBelief
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem, ObjectSpec, Pose
from arrange_up.model.world import Place
from arrange_up.planning.generators.common import clean_pose
from arrange_up.planning.generators.targets import GoalTargets

#: The rings (in steps of the grid) tried at every point of the lattice; farther rings try the
#: grid's eight directions only, so that a part with no clear place anywhere costs few tests.
FULL_RINGS = 3

#: At most this many rings, however large the table is against the grid's step (a table of
#: 1e300 would otherwise have rings without end before the search starts, past any timeout);
#: a shipped problem has tens.
MAX_RINGS = 1000


@functools.lru_cache(maxsize=256)
def rings(
    grid: tuple[tuple[float, float], ...], reach: float
) -> tuple[tuple[tuple[float, float], ...], ...]:
    """The rings about a place grid (the module docstring): ring k, for k = 2, 3, ... while k
    of the grid's steps stay within ``reach``, is the lattice of the grid's step at k steps
    from the target (Chebyshev distance), every point of it up to :data:`FULL_RINGS`, the
    grid's eight directions beyond; nearest first, ties in the grid's order (up before down,
    left before right)."""
    step = max(max(abs(dx), abs(dy)) for dx, dy in grid)
    found = []
    for k in range(2, int(min(reach / step, MAX_RINGS + 1)) + 1):
        if k <= FULL_RINGS:
            points = [
                (i, j)
                for i in range(-k, k + 1)
                for j in range(-k, k + 1)
                if max(abs(i), abs(j)) == k
            ]
        else:
            points = [(i * k, j * k) for i in (-1, 0, 1) for j in (-1, 0, 1) if i or j]
        points.sort(key=lambda p: (p[0] ** 2 + p[1] ** 2, -p[1], p[0]))
        found.append(tuple((round(i * step, 6), round(j * step, 6)) for i, j in points))
    return tuple(found)


class PlaceGenerator:
    """The place candidates of the parts off the table (see the module docstring)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        checker: CollisionChecker,
        targets: GoalTargets,
        *,
        with_rings: bool = True,
    ) -> None:
        """``with_rings=False`` offers the grid's places only: no part (no mate of a relative
        goal either) gets rings."""
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
        #: Part name -> the offsets of each ring (none for a relative goal, none where the
        #: problem gives ``planning.place_offsets``, which replace the grid whole, and none
        #: where the caller asks for no rings).
        every = {
            spec.name: ()
            if hints.place_offsets or not with_rings
            else rings(self.offsets[spec.name], max(problem.table.size))
            for spec in problem.parts
        }
        self.rings = {name: () if problem.goal.is_relative else r for name, r in every.items()}
        #: A relative goal's mates: the rings up to :data:`FULL_RINGS`, tried only where the
        #: reference's own shadow is what blocks every place of the grid (:meth:`_mate_rings`).
        self.reference = problem.goal.reference
        self.mate_rings = {
            name: r[: FULL_RINGS - 1]
            for name, r in every.items()
            if self.reference is not None and name in problem.goal.parts and name != self.reference
        }
        #: The parts that move with the grid: the reference and its mates (a mate flush
        #: against another mate is blocked by that mate's shadow as it would be by the
        #: reference's).
        self.arrangement = frozenset(problem.goal.parts) | {self.reference}

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
            targets = self.targets.place_targets(spec.name, belief)
            for offsets in (self.offsets[spec.name], *self.rings[spec.name]):
                found = len(actions)
                for target in targets:
                    for pose in self._place_grid(target, offsets):
                        if boxes is None:
                            boxes = [self.checker.shadow_box(*shadow) for shadow in on_table]
                        if self._place_ok(spec.name, pose, self.place_unc, on_table, boxes):
                            actions.append(Place(spec.name, clean_pose(pose)))
                    if len(actions) > found:
                        break
                if len(actions) > found:
                    break
            else:
                actions.extend(self._mate_rings(spec.name, targets, on_table, boxes))
        return actions

    def _mate_rings(self, name: str, targets, on_table, boxes) -> list[Place]:
        """Places of a relative goal's mate ``name`` on the rings about its target (nearest
        ring with a clear place first), where no place of its grid is clear but some would be
        without the reference and the other mates on the table: its goal is flush against
        them, whose shadows cover the grid (two cubes squared in the open: the grid's step
        clears the part's own shadow, not the reference's). Moving the reference (its ladder)
        moves the grid with it, and the mates with the reference, so only a place farther
        out, and a push in, can bring the part there.
        ``boxes`` are the shadow boxes of ``on_table`` (None when :meth:`places` built none)."""
        offsets_rings = self.mate_rings.get(name)
        if not offsets_rings:
            return []
        kept = [k for k, shadow in enumerate(on_table) if shadow[0] not in self.arrangement]
        if len(kept) == len(on_table):
            return []
        if boxes is None:  # the grid tested no pose (``places`` builds them lazily)
            boxes = [self.checker.shadow_box(*shadow) for shadow in on_table]
        others = [on_table[k] for k in kept]
        other_boxes = [boxes[k] for k in kept]
        if not any(
            self._place_ok(name, pose, self.place_unc, others, other_boxes)
            for target in targets
            for pose in self._place_grid(target, self.offsets[name])
        ):
            return []  # not the reference's doing: the ladder may still help
        for offsets in offsets_rings:
            found = [
                Place(name, clean_pose(pose))
                for target in targets
                for pose in self._place_grid(target, offsets)
                if self._place_ok(name, pose, self.place_unc, on_table, boxes)
            ]
            if found:
                return found
        return []

    def place_poses(self, belief: IntervalBelief, name: str) -> list[Pose]:
        """Candidate place poses of ``name`` that fit the table, walls and obstacles, whatever
        the objects on the table (those are the precondition's other half); for a relative
        goal's reference, about the first of :attr:`Mates.homes` that has any."""
        for target in self.targets.place_targets(name, belief):
            poses = [
                pose
                for pose in self._place_grid(target, self.offsets[name])
                if self.checker.shadow_inside_table(name, pose, self.place_unc)
                and not self.checker.shadow_hits_fixed(name, pose, self.place_unc)
            ]
            if poses:
                return poses
        return []

    def _place_grid(self, target: Pose, offsets: tuple[tuple[float, float], ...]) -> Iterator[Pose]:
        """The place poses about ``target``: each of ``offsets``, at each of
        :meth:`_place_angles`, in that order."""
        angles = self._place_angles(target)
        for dx, dy in offsets:
            for theta in angles:
                yield (target[0] + dx, target[1] + dy, theta)

    def _place_angles(self, target: Pose) -> tuple[float, ...]:
        """The target's angle, then each ``planning.place_angles`` offset from it, once each."""
        return tuple(dict.fromkeys((target[2],) + tuple(target[2] + a for a in self.place_angles)))

    def _place_ok(self, name, pose, half, on_table, boxes) -> bool:
        return self.checker.shadow_inside_table(name, pose, half) and self.checker.shadow_clear(
            name, pose, half, on_table, boxes
        )
