"""Mates: where a relative goal holds a part against its reference part, and how to push it there.

In a relative goal (``goal.relative``) a part's target is a pose in the frame of the reference
part, and in an interlocking goal (the thesis's TZ and TT matings) the part's goal footprint
touches the reference's with no clearance at all. A push that brings the part straight to its
goal coordinate then jams about half its states against the reference's edge (the Z's column
butting the end of the T's bar instead of sliding under it). The action generator
(:mod:`arrange_up.planning.actions`) asks this module two things. First, whether along a push
the goal holds the part against its *mate* (the reference) *ahead*: its goal footprint, moved
``CONTACT_PROBE`` along the push, overlaps the reference's footprint at the reference's belief
centre. For such a part and direction it offers two pushes:

* **with clearance**: the goal-directed push stopped short by the goal tolerance along the
  push, or by the part's spread relative to its mate (the two intervals' half-widths) where
  that is wider, so that every state of the part is brought beside its notch with room to
  slide into it from the side; only while the part still misses its goal interval across the
  push (that slide is still to come: after it, a push that ends at the goal interval's edge
  would only finish a plan that half the world's states fail);
* **seating**: a push past the goal coordinate by the controller's
  :func:`~arrange_up.physics.stall.wall_overdrive` for the part (its worst-case stall plus the
  approach noise plus a margin), which presses the part against its mate as a push to a wall
  does: the compliant controller stalls at the contact with a force about that of the part's
  own friction, so the part is seated whatever the friction and density, and the reference is
  not shoved far. Only under the compliant controller (the servo ends where it is sent, so its
  push to the goal coordinate is already the seating push) and only while the part's interval
  along the push is not yet inside its goal interval (pressing a seated part again only
  perturbs it, a plateau without end).

Second, how far to push the reference itself to *gather* it. It has no goal position, but
every part's goal is relative to it, so its spread is every mate's: where the reference's
interval along an axis is wider than the goal tolerance, :meth:`Mates.gather` gives the travel
(its half-width) of a push that sweeps every state of it to the far edge of that interval,
leaving only the push's own noise and stall (create-a-t's top bar starts +-0.35 in wide
against a tolerance of +-0.25 in: no placement of the stem relative to its centre can succeed
in every state).

Third, whether to *square* the reference (:meth:`Mates.square`): where its angle spread,
times the lever of its farthest mate's target, is what takes that target's spread beyond the
goal's position tolerance (its position spread alone within it: else gathering comes first),
the generator presses it against the wall ahead, centred and as a turning push on either side
(:mod:`arrange_up.planning.actions`), which turns it flat against the wall
(m-rotated-reference-pair's bar, turned 30 degrees +-5, its mates 8.5 cm away with +-8 mm).

Fourth, where to put the reference down when it starts off the table (:attr:`Mates.home`): its
goal lets it end anywhere, so the goal gives no place; it is placed (with the usual grid of
offsets) where the goal arrangement, the reference and its mates at their targets, is centred
on the table, which leaves the most room around it for the mates' places and pushes. Where
none of those places is clear (an obstacle in the middle of the table, or a part there), the
generator tries :attr:`Mates.homes` after it, in order: a deterministic set of other poses
(at most ``MAX_HOMES - 1``) from a ``HOME_GRID`` x ``HOME_GRID`` grid over the table at which
the whole arrangement, grown by the reference's place noise plus ``HOME_MARGIN``, stays on the
table and clear of every obstacle, nearest the centre first. The first of them with a clear
place is used, so wherever the centre has one nothing changes.

Nothing of this is offered for an absolute goal, whose parts are seated against walls, fences
and the trains of parts ahead of them instead.
"""

from __future__ import annotations

import math
from functools import lru_cache

import shapely
import shapely.affinity

from arrange_up.geometry.shapes import footprint
from arrange_up.model.problem import ArrangementProblem, Pose

#: How far (in) a part's goal footprint is moved along a push to test whether its mate is ahead.
CONTACT_PROBE = 0.05
#: The side of the grid of alternative homes (:attr:`Mates.homes`), and how many homes at most.
HOME_GRID = 5
MAX_HOMES = 9
#: Room (in) kept between the arrangement at an alternative home and the table's edges and the
#: obstacles, beyond the reference's place noise.
HOME_MARGIN = 0.1
#: Overlap area (square inches) the probe must add for the mate to count as ahead: a contact
#: face of 0.02 in or more (a corner touching only grazes, and a float's worth is noise).
PROBE_AREA = 1e-3


class Mates:
    """The mate contacts of one problem's relative goal (see the module docstring)."""

    def __init__(self, problem: ArrangementProblem) -> None:
        goal = problem.goal
        self.reference = goal.reference
        self._tolerance = goal.tolerance
        #: The farthest a relative target lies from the reference's origin (in): the lever by
        #: which the reference's angle spread moves its mates' targets.
        self._lever = max(
            (
                math.hypot(pose[0], pose[1])
                for name, pose in goal.targets
                if goal.reference is not None and name != goal.reference
            ),
            default=0.0,
        )
        self._parts = {spec.name: spec.shape.parts for spec in problem.parts}
        self._ahead = lru_cache(maxsize=50_000)(self._ahead_uncached)
        #: Where the reference is placed when it starts off the table (:meth:`_home`), then
        #: the alternatives tried where it has no clear place (:meth:`_homes`).
        self.home: Pose | None = None
        self.homes: tuple[Pose, ...] = ()
        if goal.reference is not None:
            arrangement = self._arrangement(problem)
            self.home = self._home(problem, arrangement)
            self.homes = self._homes(problem, arrangement, self.home)

    def __bool__(self) -> bool:
        return self.reference is not None

    def ahead(self, name: str, target: Pose, mate: Pose, axis: int, sign: int) -> bool:
        """Whether part ``name`` at its goal ``target`` has the reference part (at ``mate``, its
        belief centre) ahead of it along ``axis`` in direction ``sign``, touching it: moving the
        part's footprint ``CONTACT_PROBE`` along the push adds more than ``PROBE_AREA`` to its
        overlap with the reference's footprint. False for the reference itself and for an
        absolute goal."""
        if self.reference is None or name == self.reference:
            return False
        return self._ahead(name, _rounded(target), _rounded(mate), axis, sign)

    def gather(self, name: str, half: float, axis: int) -> float | None:
        """The travel of a push that gathers the reference part ``name``, ``half`` its
        interval's half-width along ``axis``: ``half`` where that is wider than the goal
        tolerance, else None (and None for every other part)."""
        if name != self.reference or half <= self._tolerance[axis]:
            return None
        return half

    def square(self, name: str, half: tuple[float, float, float]) -> bool:
        """Whether to press the reference part ``name`` against a wall to square it: with the
        half-widths ``half`` of its interval (in, in, rad), its farthest mate's target spreads
        by more than the goal's position tolerance, and the angle's share of that is what
        tips it over (False for every other part)."""
        if name != self.reference:
            return False
        turned = self._lever * math.sin(min(half[2], 0.5 * math.pi))
        tolerance = min(self._tolerance[0], self._tolerance[1])
        return max(half[0], half[1]) <= tolerance < max(half[0], half[1]) + turned

    def _arrangement(self, problem: ArrangementProblem) -> shapely.Geometry:
        """The goal arrangement's nominal footprint, the reference and every mate at its
        target, with the reference at the origin at angle 0 (the frame its mates' targets are
        given in)."""
        shapes = [footprint(self._parts[self.reference], (0.0, 0.0, 0.0))]
        shapes += [
            footprint(self._parts[name], pose)
            for name, pose in problem.goal.targets
            if name != self.reference
        ]
        return shapely.union_all(shapes)

    @staticmethod
    def _home(problem: ArrangementProblem, arrangement: shapely.Geometry) -> Pose:
        """The reference's pose (at angle 0) that centres the goal ``arrangement``
        (:meth:`_arrangement`) on the table: a goal that lets the reference end anywhere gives
        no place to put it down, and the middle of the table leaves the most room around the
        arrangement for the places and pushes of its mates."""
        x0, y0, x1, y1 = arrangement.bounds
        width, depth = problem.table.size
        return (0.5 * width - 0.5 * (x0 + x1), 0.5 * depth - 0.5 * (y0 + y1), 0.0)

    def _homes(
        self, problem: ArrangementProblem, arrangement: shapely.Geometry, home: Pose
    ) -> tuple[Pose, ...]:
        """``home``, then up to ``MAX_HOMES - 1`` other poses of the reference (angle 0)
        from a ``HOME_GRID`` x ``HOME_GRID`` grid spanning the positions that keep the
        ``arrangement`` on the table, at which it, grown by the reference's place noise plus
        ``HOME_MARGIN``, stays on the table and clear of the obstacles; nearest ``home`` first
        (ties: lower y, then lower x). Deterministic: the same problem gives the same homes."""
        dx, dy, dtheta = problem.uncertainty.place
        radius = problem.object(self.reference).shape.radius
        margin = max(dx, dy) + radius * math.sin(min(dtheta, 0.5 * math.pi)) + HOME_MARGIN
        grown = arrangement.buffer(margin)
        x0, y0, x1, y1 = grown.bounds
        width, depth = problem.table.size
        if x1 - x0 > width or y1 - y0 > depth:
            return (home,)
        obstacles = [
            footprint(spec.shape.parts, spec.pose)
            for spec in problem.obstacles
            if spec.pose is not None
        ]
        hx, hy, _ = home
        found = []
        for j in range(HOME_GRID):
            for i in range(HOME_GRID):
                x = -x0 + (width - (x1 - x0)) * i / (HOME_GRID - 1)
                y = -y0 + (depth - (y1 - y0)) * j / (HOME_GRID - 1)
                if math.hypot(x - hx, y - hy) < 1e-9:
                    continue
                moved = shapely.affinity.translate(grown, x, y)
                if any(moved.intersects(obstacle) for obstacle in obstacles):
                    continue
                found.append((round(math.hypot(x - hx, y - hy), 9), y, x))
        found.sort()
        return (home, *((x, y, 0.0) for _, y, x in found[: MAX_HOMES - 1]))

    def _ahead_uncached(self, name, target, mate, axis, sign) -> bool:
        other = footprint(self._parts[self.reference], mate)
        moved = list(target)
        moved[axis] += sign * CONTACT_PROBE
        before = footprint(self._parts[name], target).intersection(other).area
        after = footprint(self._parts[name], tuple(moved)).intersection(other).area
        return after - before > PROBE_AREA


def _rounded(pose: Pose) -> Pose:
    """``pose`` to 1e-4 (in, rad), so that the cache meets the same contact again across
    beliefs whose centres differ by float noise only."""
    return (round(pose[0], 4), round(pose[1], 4), round(pose[2], 4))
