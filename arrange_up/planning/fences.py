"""Fences: fixtures the planner puts down for a goal part to be pushed against where the table
has no wall (thesis §4.2.3 and §5.2's future work: construction and improvement combined).

**When a fence is needed.** A push that ends in the open stops its part no more precisely than
the push itself: the manipulator's approach lands within ``push`` uncertainty along the push,
and under the compliant controller the stall (``mu g rho A / Kp``) varies with the friction
and part density drawn for the action. A part pressed against something fixed ends where that
thing is. So along an axis of an absolute goal, a goal part *needs a fence* when

* the free push's end spread, ``push[axis] + (stall_max - stall_min) / 2``, exceeds the goal
  tolerance along the axis;
* the goal does not hold the part against a wall of the table along that axis (that wall
  would do the job: :func:`~arrange_up.planning.generators.wall_trains.wall_trains`);
* a fixture pressed against would do better than the tolerance: its own place spread,
  ``place[axis]`` plus the shift of its face over half the part's width for a place turned by
  ``place[theta]``, is below the tolerance; or a fixed obstacle already stands as a fence: its
  near face within the tolerance of the part's goal face, its box covering the goal's
  coordinate across with ``COVER`` of the part to spare (a post flush with the goal). An
  obstacle is used as a fence on the table is (*Using it*); it is never placed or picked.

Only problems with fixtures or obstacles and an absolute goal can need one, and no shipped
problem does (their plans are unchanged).

**Where a fence goes** (:meth:`Fences.placements`): from the goal, each fixture off the table,
at each of its distinct right-angle turns (:func:`fixture_angles`, the repair's grid angles),
with its near face flush with the goal footprint's face on the side the part is pushed
towards, so that the part pressed against it ends at its target (for a part that goal parts
touch ahead in a row, the face of the row's last part, :meth:`Fences.train`: the part presses
the row against the fence, as a wall train is pressed against its wall; the row must be on
the table for that push). Across the push its footprint
covers the part's goal coordinate with ``COVER`` of the part's width to spare on either side
(the part must be held there at the end), its place shadow ``GAP`` from the table's edges and
walls: centred on the goal's coordinate as far as that allows, and as near the part's present
coordinate as it can (a fence that covers the part there too presses it now, and the part
slides along it to its goal: a corner of two fences is built so, one pressed, the other slid
onto, the first pressed again); only where neither stands, at either end of that range (clear
of another fence). A fence centred on the part's present coordinate alone would be left
behind by the pushes still to come. The place precondition is the planner's (the fixture's
place shadow on the table, touching no shadow, wall or obstacle). Offered only for a part that
needs the fence, is not already within its goal along the axis, and would not be pushed away
from its goal (the push rule of :mod:`arrange_up.planning.actions`).

**Using it** (:meth:`Fences.face_ahead`): any fixture on the table or obstacle whose near
face lies within the tolerance of the part's goal face, ahead of the part's shadow, and whose
nominal footprint covers the part's centre across the push (as above), is offered as the wall
is: a push to the face (the compliant controller's set point then lies beyond it, and the force
clip presses the part against it); it is a squeeze, never cut short before the obstacle.

**Open pushes give way to a fence only where it can press the part**
(:meth:`Fences.replaces_open_pushes`): along an axis that needs a fence, the pushes that end in
the open are not offered while a fence on the table holds the part there (``face_ahead``) or
one can be put down that covers the part's centre across the push (as above). For a part that
needs a fence along both axes any fence place will do (a corner: see *Levelling*).

**Passing** (:meth:`Fences.ahead`, :meth:`Fences.passing_aim`): a part that needs a fence
along one axis only, and that no fence can press yet (it lies beyond every fence's reach
across the push: a block above another, which must move along the row before it can come down
to it), gets the open push towards its goal along that axis, but short of the fence still to
be put down: to where its shadow at its angle spread, widened by the free push's end spread
and by the push noise of a push across still to come, clears the place shadow of a fence at
its goal face by ``GAP`` (a part pushed onto its goal coordinate lies where the fence must
stand, and the fence can no longer be put down). No narrowing push is offered along that
axis: the fence does the narrowing once the part is in front of it. A passing push is also
offered with the manipulator centred where it clips no shadow ahead (the part it passes: a
clipped part is dragged along in some states and not in others).

**Levelling** (:meth:`Fences.level`): where both axes need a fence and no fence of the other
axis stands, or can stand, in front of the part (its footprint would not cover the part's
centre across), the generator offers, along this axis, the one push that ends in the open: to
the nearest coordinate such a fence would cover, with that push's own end spread inside. The
corner is built from there: the part pressed against that fence and slid along it onto the
fence of this axis.

**Keeping the manipulator's path clear** (:meth:`Fences.clear_paths`): the approach shadow is
checked where a push starts, but a manipulator centred on the part would run into a fence of
the other axis standing beside the part's path (the first fence of a corner) and stall there;
for a part that needs a fence, a centre whose path meets a fixture on the table is moved to
the nearest that misses them all while still covering the part's centre.

A bar placed at 90 degrees is one belief of angles around 90 degrees
(:func:`~arrange_up.belief.states.fixture_turns` centres a fixture's angle period on its
turns); wrapped around 0 its particles would lie at both ends of the period, the bar would be
seen at 0 degrees, and no push would take it for a fence.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from arrange_up.belief.states import IntervalBelief, fixture_turns
from arrange_up.geometry.boxes import box_row
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem, Pose
from arrange_up.model.world import Place
from arrange_up.physics.stall import stall_spread

_ZERO = (0.0, 0.0, 0.0)
#: A fence must cover the part's centre across the push with this fraction of the part's width
#: to spare on either side (half the face pressed against it, at least).
COVER = 0.25
#: Gap kept between a fence's place shadow and the table's edges (inches), as the manipulator's
#: approach keeps from what it passes.
GAP = 0.02


def _round(value: float) -> float:
    """A generated coordinate rounded to 1e-6 in (never ``-0.0``), as the generator's are."""
    return round(float(value), 6) + 0.0


def _clamp(value: float, low: float, high: float) -> float:
    return min(max(value, low), high)


def fixture_angles(problem: ArrangementProblem, name: str) -> list[float]:
    """The distinct right-angle turns at which fixture ``name`` is placed, by the repair's grid
    and by fences (:func:`~arrange_up.belief.states.fixture_turns`)."""
    return list(fixture_turns(problem.object(name).shape))


@dataclass(frozen=True)
class FenceAhead:
    """What fences mean for the pushes of one part in one direction (:meth:`Fences.ahead`):
    ``face``, the face of a fence on the table ahead that can press the part
    (:meth:`Fences.face_ahead`, ``None`` if none); ``fenced``, whether the pushes that end in
    the open give way to a fence (:meth:`Fences.replaces_open_pushes`); ``passing``, whether
    they are *passing* pushes (module docstring, *Passing*: the part needs a fence along this
    axis only, a fixture is still to be put down for it, and no fence can press it now)."""

    face: float | None = None
    fenced: bool = False
    passing: bool = False


#: A part no fence concerns.
NO_FENCE = FenceAhead()


class Fences:
    """Which goal parts need a fence along which axis, where fences go and which fixture on the
    table holds a part at its goal (see the module docstring).

    ``held_by_wall`` says for a part and an axis whether the goal holds the part against a wall
    the table has (the generator's wall trains decide that)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        checker: CollisionChecker,
        held_by_wall: dict[tuple[str, int], bool],
    ) -> None:
        self.problem = problem
        self.checker = checker
        self.place_unc = problem.uncertainty.place
        goal = problem.goal
        self.goal_boxes: dict[str, tuple[float, ...]] = {}
        #: (part, axis) -> the free push's end spread, for the axes that need a fence.
        self.needs: dict[tuple[str, int], float] = {}
        self._trains: dict[tuple[str, int, int], tuple[str, ...]] = {}
        if goal.is_relative or not (problem.fixtures or checker.obstacle_boxes):
            return
        spread = stall_spread(problem)
        push = problem.uncertainty.push
        for part in goal.parts:
            self.goal_boxes[part] = checker.shadow_box(part, goal.target(part), _ZERO)
        for part, box in self.goal_boxes.items():
            area = problem.object(part).shape.area
            for axis in (0, 1):
                other = 1 - axis
                free = push[axis] + spread * area
                width = box[other + 2] - box[other]
                fence = self.place_unc[axis] + 0.5 * width * math.sin(self.place_unc[2])
                tolerance = goal.tolerance[axis]
                if (
                    free > tolerance
                    and not held_by_wall.get((part, axis), False)
                    and (
                        (problem.fixtures and tolerance > fence)
                        or self._obstacle_at_goal(part, axis)
                    )
                ):
                    self.needs[(part, axis)] = free

    def _obstacle_at_goal(self, part: str, axis: int) -> bool:
        """Whether a fixed obstacle stands as a fence for ``part`` along ``axis``: its near
        face within the tolerance of the part's goal face (either way along the axis) and its
        box covering the goal's coordinate across with ``COVER`` of the part to spare."""
        tolerance = self.problem.goal.tolerance[axis]
        at_goal = self.problem.goal.target(part)[1 - axis]
        for sign in (1, -1):
            goal_face = self.goal_face(part, axis, sign)
            for box in self.checker.obstacle_boxes.values():
                face = box[axis] if sign > 0 else box[axis + 2]
                if abs(face - goal_face) <= tolerance and self._covers(
                    part, box, 1 - axis, at_goal
                ):
                    return True
        return False

    def level(
        self,
        part: str,
        interval,
        belief: IntervalBelief,
        axis: int,
        routes: dict[tuple[str, int, int], list[Place]],
    ) -> float | None:
        """Where a *levelling* push along ``axis`` takes ``part``'s centre, or None when none
        is needed: the part needs a fence along the other axis too, no fence for that axis
        (on the table, or among ``routes``) stands in front of the part now, and one would if
        the part were moved along ``axis`` to the nearest coordinate it covers (with ``COVER``
        of the part to spare, and the levelling push's own end spread, the free push's along
        ``axis``, inside that). A corner is built from there: the part pressed against that
        fence and slid along it onto the fence of this axis."""
        other = 1 - axis
        if not self.needed(part, axis) or not self.needed(part, other):
            return None
        target = self.problem.goal.target(part)
        if (
            abs(interval.center[other] - target[other]) + interval.half[other]
            <= (self.problem.goal.tolerance[other])
        ):
            return None  # within its goal along the other axis: no fence needed there now
        sign = 1 if target[other] > interval.center[other] else -1
        boxes = [
            self.checker.shadow_box(place.obj, place.pose, _ZERO)
            for place in routes.get((part, other, sign), ())
        ]
        goal_face = self.goal_face(part, other, sign)
        tolerance = self.problem.goal.tolerance[other]
        for spec in self.problem.fixtures:
            fixture = belief.get(spec.name)
            if fixture is not None:
                box = self.checker.shadow_box(spec.name, fixture.center, _ZERO)
                if abs((box[other] if sign > 0 else box[other + 2]) - goal_face) <= tolerance:
                    boxes.append(box)
        goal_box = self.goal_boxes[part]
        spare = COVER * (goal_box[axis + 2] - goal_box[axis])
        centre = interval.center[axis]
        if any(b[axis] + spare <= centre + 1e-9 <= b[axis + 2] - spare + 2e-9 for b in boxes):
            return None  # level with a fence already
        inset = spare + self.needs[(part, axis)]
        best = None
        for box in boxes:
            low, high = box[axis] + inset, box[axis + 2] - inset
            if low <= high:
                at = _clamp(centre, low, high)
                if best is None or abs(at - centre) < abs(best - centre):
                    best = at
        return best

    def needed(self, part: str, axis: int) -> bool:
        return (part, axis) in self.needs

    def replaces_open_pushes(
        self,
        part: str,
        interval,
        axis: int,
        sign: int,
        face: float | None,
        routes: dict[tuple[str, int, int], list[Place]],
    ) -> bool:
        """Whether the pushes of ``part`` along ``axis`` towards ``sign`` that end in the open
        give way to a fence (module docstring, *Using it*): the part needs one along the axis,
        and one holds it there now (``face``, from :meth:`face_ahead`) or can be put down
        where it would press it now (one of ``routes`` covers the part's centre across the
        push). For a part that needs a fence along both axes any fence place will do: a corner
        is built by sliding the part onto its second fence (:meth:`level` brings it level
        with its first)."""
        if not self.needed(part, axis):
            return False
        if face is not None:
            return True
        places = routes.get((part, axis, sign), ())
        if self.needed(part, 1 - axis):
            return bool(places)
        return any(
            self._covers(
                part,
                self.checker.shadow_box(p.obj, p.pose, _ZERO),
                1 - axis,
                interval.center[1 - axis],
            )
            for p in places
        )

    def ahead(
        self,
        part: str,
        interval,
        belief: IntervalBelief,
        axis: int,
        sign: int,
        routes: dict[tuple[str, int, int], list[Place]],
    ) -> FenceAhead:
        """The fences' say on the pushes of ``part`` along ``axis`` towards ``sign``
        (:class:`FenceAhead`), each test made once: :data:`NO_FENCE` for a part with no fenced
        goal face."""
        if part not in self.goal_boxes:
            return NO_FENCE
        face = self.face_ahead(part, interval, belief, axis, sign)
        fenced = self.replaces_open_pushes(part, interval, axis, sign, face, routes)
        passing = (
            bool(self.problem.fixtures)
            and self.needed(part, axis)
            and not self.needed(part, 1 - axis)
            and not fenced
        )
        return FenceAhead(face, fenced, passing)

    def passing_aim(self, part: str, interval, axis: int, sign: int) -> float:
        """The farthest coordinate along ``axis`` (towards ``sign``) a passing push takes
        ``part``'s centre to: where its shadow at its angle spread, widened by the free push's
        end spread and by the push noise of a push across still to come, clears by ``GAP``
        the place shadow of a fence at its goal face (the fence must still be put down there)."""
        turned = self.checker.shadow_box(part, interval.center, (0.0, 0.0, interval.half[2]))
        reach = 0.0  # how far a fixture's place shadow reaches beyond its nominal face
        for spec in self.problem.fixtures:
            for theta in fixture_angles(self.problem, spec.name):
                box = self.checker.shadow_box(spec.name, (0.0, 0.0, theta), _ZERO)
                shadow = self.checker.shadow_box(spec.name, (0.0, 0.0, theta), self.place_unc)
                reach = max(reach, box[axis] - shadow[axis])
        margin = (
            0.5 * (turned[axis + 2] - turned[axis])
            + self.needs[(part, axis)]
            + self.problem.uncertainty.push[axis]
            + reach
            + GAP
        )
        return self.goal_face(part, axis, sign) - sign * margin

    def _covers(self, part: str, box, other: int, centre: float) -> bool:
        """Whether a fence's nominal footprint ``box`` covers ``centre``, ``part``'s coordinate
        across the push (along ``other``), with ``COVER`` of the part's width to spare on
        either side."""
        goal_box = self.goal_boxes[part]
        spare = COVER * (goal_box[other + 2] - goal_box[other])
        return box[other] <= centre - spare + 1e-9 and centre + spare <= box[other + 2] + 1e-9

    def goal_face(self, part: str, axis: int, sign: int) -> float:
        """Where a fence holding ``part`` pushed along ``axis`` towards ``sign`` stands: the
        goal footprint's face on that side of the last part of its goal train (the part
        itself when no goal part touches it ahead; :meth:`train`)."""
        end = self.train(part, axis, sign)[-1:] or (part,)
        box = self.goal_boxes[end[0]]
        return box[axis + 2] if sign > 0 else box[axis]

    def train(self, part: str, axis: int, sign: int) -> tuple[str, ...]:
        """The goal parts ahead of ``part`` along ``axis`` towards ``sign`` that touch in a row
        in the goal arrangement (within twice the tolerance): pushed, the part presses them
        against the fence, as a wall train is pressed against its wall."""
        key = (part, axis, sign)
        if key not in self._trains:
            slack = 2.0 * max(self.problem.goal.tolerance[:2]) + 1e-6
            self._trains[key] = box_row(self.goal_boxes, part, axis, sign, slack)[0]
        return self._trains[key]

    # -- where fences go -----------------------------------------------------------------------
    def placements(
        self,
        belief: IntervalBelief,
        on_table: Sequence[tuple[str, Pose, tuple[float, float, float]]],
    ) -> dict[tuple[str, int, int], list[Place]]:
        """The fence places of ``belief``, keyed by ``(part, axis, sign)``: the part they are
        for and the push (along ``axis``, towards ``sign``) that presses it against them."""
        routes: dict[tuple[str, int, int], list[Place]] = {}
        if not self.needs:
            return routes
        goal = self.problem.goal
        # Fixtures of one shape are interchangeable: only the first of them off the table is
        # offered (each would give the same belief under another name).
        shapes: dict[object, str] = {}
        for spec in self.problem.fixtures:
            if spec.name not in belief:
                shapes.setdefault(spec.shape.parts, spec.name)
        free = list(shapes.values())
        if not free:
            return routes
        for (part, axis), _ in self.needs.items():
            interval = belief.get(part)
            target = goal.target(part)
            tolerance = goal.tolerance[axis]
            other = 1 - axis
            if interval is not None and (
                abs(interval.center[axis] - target[axis]) + interval.half[axis] <= tolerance
            ):
                continue  # already within its goal along the axis
            present = interval.center[other] if interval is not None else target[other]
            width = self.goal_boxes[part][other + 2] - self.goal_boxes[part][other]
            for sign in (1, -1):
                if (
                    interval is not None
                    and sign * (target[axis] - interval.center[axis]) < -tolerance
                ):
                    continue  # the fence would have the part pushed away from its goal
                face = self.goal_face(part, axis, sign)
                places = []
                for fixture in free:
                    for theta in fixture_angles(self.problem, fixture):
                        box = self.checker.shadow_box(fixture, (0.0, 0.0, theta), _ZERO)
                        shadow = self.checker.shadow_box(fixture, (0.0, 0.0, theta), self.place_unc)
                        along = face - (box[axis] if sign > 0 else box[axis + 2])
                        size = self.problem.table.size[other]
                        # Across: covering the goal's coordinate (where the part must be held
                        # at the end), with COVER of the part to spare either side.
                        low = max(
                            target[other] + COVER * width - box[other + 2], GAP - shadow[other]
                        )
                        high = min(
                            target[other] - COVER * width - box[other],
                            size - GAP - shadow[other + 2],
                        )
                        if low > high:
                            continue
                        # centred on the goal, and nearest the part's present coordinate (a part
                        # it covers there too is pressed against it now and slides along it
                        # to its goal); only where neither can stand, at either end of the
                        # range (clear of another fence there: two fences make a corner). An
                        # end is offered last because a part that drifts across the push
                        # leaves a fence it covers by no more than COVER.
                        centred = (_clamp(target[other], low, high), _clamp(present, low, high))
                        found = self._standing(fixture, axis, along, theta, centred, on_table)
                        if not found:
                            found = self._standing(
                                fixture, axis, along, theta, (low, high), on_table
                            )
                        places += found
                if places:
                    routes[(part, axis, sign)] = places
        return routes

    def _standing(self, fixture, axis, along, theta, across, on_table) -> list[Place]:
        """The places of ``fixture`` at ``along`` and each of ``across`` (once each) that meet
        the place precondition."""
        places = []
        for at in dict.fromkeys(across):
            pose = (along, at, theta) if axis == 0 else (at, along, theta)
            pose = (_round(pose[0]), _round(pose[1]), theta)
            if self.checker.shadow_inside_table(
                fixture, pose, self.place_unc
            ) and self.checker.shadow_clear(fixture, pose, self.place_unc, on_table):
                places.append(Place(fixture, pose))
        return places

    # -- using a fence -------------------------------------------------------------------------
    def face_ahead(
        self, part: str, interval, belief: IntervalBelief, axis: int, sign: int
    ) -> float | None:
        """The near face of a fixture on the table that holds ``part`` at its goal when pushed
        along ``axis`` towards ``sign`` and lies ahead of its shadow (module docstring), or
        None."""
        found = self._fence_at(part, interval, belief, axis, sign)
        if found is None:
            return None
        shadow = self.checker.shadow_box(part, interval.center, interval.half)
        front = shadow[axis + 2] if sign > 0 else -shadow[axis]
        return found[1] if sign * found[1] >= front - 1e-9 else None

    def clear_paths(
        self,
        part: str,
        belief: IntervalBelief,
        axis: int,
        sign: int,
        centres: Sequence[float],
        span: tuple[float, float],
        approach: tuple[float, float],
        manipulator: tuple[float, float],
        travel: float,
    ) -> list[float]:
        """The manipulator's centres across a push of ``part`` moved, where needed, so that its
        path misses the fixtures on the table (a fence for the other axis, say): the approach
        shadow is checked at the start only, and a manipulator that runs into a fence stalls
        there.

        ``centres`` are the generator's, ``span`` the range a centre may take (the part's
        centre covered, the walls cleared), ``approach`` the approach shadow's extent along the
        push and ``manipulator`` its extent across, both relative to the commanded centre
        across; ``travel`` the longest distance pushed. The path runs from the approach to
        where the manipulator stops, a part's depth short of its set point (the part is between).
        A centre whose path meets a fixture is replaced by the nearest one in ``span`` that
        misses them all (dropped if none does)."""
        interval = belief.get(part)
        if interval is None:
            return list(centres)
        other = 1 - axis
        nominal = self.checker.shadow_box(part, interval.center, _ZERO)
        depth = nominal[axis + 2] - nominal[axis]
        reach = max(travel - depth, 0.0)
        low, high = (
            (approach[0], approach[1] + reach) if sign > 0 else (approach[0] - reach, approach[1])
        )
        forbidden = []
        for spec in self.problem.fixtures:
            fixture = belief.get(spec.name)
            if fixture is None:
                continue
            box = self.checker.shadow_box(spec.name, fixture.center, fixture.half)
            if box[axis + 2] > low and box[axis] < high:
                forbidden.append(
                    (box[other] - manipulator[1] - GAP, box[other + 2] - manipulator[0] + GAP)
                )
        if not forbidden:
            return list(centres)

        def clear(value: float) -> bool:
            return all(not (lo < value < hi) for lo, hi in forbidden)

        edges = [v for bounds in forbidden for v in bounds if span[0] <= v <= span[1]]
        result: list[float] = []
        for centre in centres:
            if not clear(centre):
                options = sorted((v for v in edges if clear(v)), key=lambda v: abs(v - centre))
                if not options:
                    continue
                centre = options[0]
            if all(abs(centre - r) > 1e-6 for r in result):
                result.append(centre)
        return result

    def holding(self, belief: IntervalBelief, inside) -> set[str]:
        """The fixtures on the table that hold a goal part at its goal along an axis that needs
        a fence while the part still misses its goal along the other axis: picking one would
        let the pushes still to come undo the fence's work. ``inside(part, axis)`` says
        whether the part lies within its goal along ``axis``."""
        held: set[str] = set()
        for part, axis in self.needs:
            interval = belief.get(part)
            if interval is None or not inside(part, axis) or inside(part, 1 - axis):
                continue
            for sign in (1, -1):
                found = self._fence_at(part, interval, belief, axis, sign)
                if found is not None:
                    held.add(found[0])
        return held

    def _fence_at(
        self, part: str, interval, belief: IntervalBelief, axis: int, sign: int
    ) -> tuple[str, float] | None:
        """A fixture on the table (and its near face) whose near face, seen from ``part``
        pushed along ``axis`` towards ``sign``, lies within the tolerance of the part's goal
        face, and whose footprint covers the part's centre across the push."""
        if part not in self.goal_boxes or any(
            q not in belief for q in self.train(part, axis, sign)
        ):
            return None  # its train (if any) must be on the table to be pressed against it
        goal_face = self.goal_face(part, axis, sign)
        tolerance = self.problem.goal.tolerance[axis]
        boxes = [
            (spec.name, self.checker.shadow_box(spec.name, fixture.center, _ZERO))
            for spec in self.problem.fixtures
            if (fixture := belief.get(spec.name)) is not None
        ]
        for name, box in boxes + list(self.checker.obstacle_boxes.items()):
            face = box[axis] if sign > 0 else box[axis + 2]
            if abs(face - goal_face) <= tolerance and self._covers(
                part, box, 1 - axis, interval.center[1 - axis]
            ):
                return name, face
        return None
