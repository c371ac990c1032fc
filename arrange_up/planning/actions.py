"""Action generators and preconditions (thesis §2.1.3, §2.2.1).

The action space is continuous; these generators propose a small discrete set per belief.

**Place** (Figure 2-10): for every goal part off the table, candidates at the part's goal
target plus offsets from a 3 x 3 grid (``planning.place_offsets`` replaces the grid). The
default step is the growth of the part's place shadow over its nominal footprint plus 0.1 in:
just enough for the place precondition to hold next to walls and neighbours, and no more,
since every extra inch must be pushed and pushing accrues uncertainty. The angle is the
target's (``planning.place_angles`` adds alternatives). For a relative goal the target is the
goal pose composed with the reference part's current belief centre; the reference itself, when
it starts off the table, is placed about :attr:`~arrange_up.planning.mating.Mates.home` (its
goal is anywhere: there, the goal arrangement is centred on the table), or, where no place there
is clear, about the first of the other :attr:`~arrange_up.planning.mating.Mates.homes` that has
a clear place.

**Push** (Figure 2-11): "object-centric" pushes. For every part on the table and every axis
direction (``planning.push_directions`` restricts them), the manipulator is put behind the
part's belief shadow, turned so that it pushes along the direction, centred on the part's
belief centre across the direction — shifted along its long side just enough to stay clear of
walls and of the shadows beside it, as long as it still covers the part's centre.

With ``unclipped_pushes`` (the planner sets it for semantics that refuse uncertain contacts,
i.e. CBST), when that position *clips* a shadow ahead (its long side overlaps the shadow's side
without covering it whole, so whether it touches that part is uncertain), the same push is
offered a second time from the nearest position that misses or wholly covers every shadow
ahead. The first position keeps plans that move a neighbouring row along; the second makes
contacts certain where CBST must refuse a clipped one (a row of blocks built against a wall,
where each new block's push down clips the block beside it). Particle semantics simulate
clipped contacts, and for them the extra pushes only widen the search, so it is off by default
(the cases that motivate both positions are in docs/design/planning.md).

**Turning pushes**: a part whose belief is centred on an angle outside its goal's tolerance
(modulo its symmetry period), and a relative goal's reference that
:meth:`~arrange_up.planning.mating.Mates.square` says to square, are also offered their pushes
that press them against what stops them (the distances below with no part travel of their
own) with the manipulator shifted across by ``TURN_OFFSET`` of its length to either side: it
presses one side, and the part turns until its face lies flat against the wall (a centred
push leaves a turned part resting on two corners, still turned).

Distances:

* to the wall ahead (the controller stalls when the train of parts is compressed against it),
  generated only when the goal holds the part against that wall, directly or through a train
  of touching goal parts that are all on the table already — never towards an edge without a
  wall, where it would only push parts off; under the compliant controller not once the part
  and that train all lie within their goal intervals along the push (pressing them into the
  wall again only perturbs them, a new belief each time, a plateau without end; under the
  servo the repeat is a no-op the search prunes as a duplicate), unless
  ``settled_wall_pushes`` (the planner sets it for semantics that predict rather than simulate
  a push, i.e. CBST: there a repeat is a duplicate, and it narrows intervals until later
  contacts are certain). The manipulator's front is sent to the wall itself, except with
  ``compressed_wall_pushes`` (the planner sets it for CBST too) under the compliant
  controller: then to the front of the compressed train (the part and its train, by their
  nominal extents) plus :func:`~arrange_up.physics.stall.wall_overdrive`, the worst-case
  stall of the train and the push's pose uncertainty, because a set point at the wall presses
  the train with the full force clip and buckles trains of two or three blocks (docs/cbst.md),
  and because CBST's model is trained on pushes to the wall drawn so;
* to the part's goal coordinate along the direction, when that lies ahead;
* **narrowing**: when the part's centre is already (within ``MIN_PUSH``) at its goal
  coordinate but its spread along the direction misses the goal interval, to where the
  nominal part would sit at the target, in both directions: the states behind the target are
  swept up to it, those ahead left alone, and the push from the other side does the rest
  (a squeeze between two pushes where no wall can do it);
* **gathering** the reference of a relative goal
  (:meth:`~arrange_up.planning.mating.Mates.gather`): where its spread along the push is wider
  than the goal tolerance, a push that moves its centre by its half-width, so that every
  state is swept to the far edge of the interval (the parts placed relative to it inherit
  its spread, and it has no goal position to narrow it to);
* **squaring** the reference of a relative goal: to the wall ahead (as a press, compressed
  like a wall push), where :meth:`~arrange_up.planning.mating.Mates.square` says its angle
  spread takes its mates' targets beyond the tolerance;
* **a ladder** of travels (``LADDER``) for a part without a goal position of its own (the
  reference of a relative goal), keeping its nominal footprint on the table, offered only
  while some goal part cannot be placed at all (the reference may have to make room);
* each of ``planning.push_distances`` (how far the part should travel);
* **a squeeze**, where the narrowing push is offered: to the face of the nearest obstacle, or
  of a fixture's shadow on the table, ahead of the part that covers its centre across the push
  with a quarter of the part to spare (the paddle's front set at that face, as for a wall:
  the controller stalls with the part pressed against it);
* **mating** (:mod:`arrange_up.planning.mating`), for a part whose relative goal holds it
  against the reference part ahead along the push: the goal-directed push stopped short by
  the goal tolerance, or by the part's spread relative to the reference where that is wider,
  while the part still misses its goal interval across the push (brought beside its notch,
  with room to slide into it from the side; only with ``clearance_pushes``, which the planner
  sets for a semantics of more than one particle: a single nominal state has no spread to
  make room for, and a deterministic plan would end with the part at its goal interval's
  edge); and under the compliant controller, while the part misses its goal interval along
  the push, a seating push to the goal coordinate plus the part's
  :func:`~arrange_up.physics.stall.wall_overdrive` (pressed against the reference as against
  a wall);
* **a detour** round obstacles (:mod:`arrange_up.planning.obstacles`): where the straight push
  to the part's goal coordinate along one axis is blocked (an obstacle's box lies across the
  part's shadow, widened by ``obstacles.GAP``, before the goal), a push along the other axis,
  to the nearer side where the shadow (with the spread a push leaves across it) clears the
  blocking boxes by ``GAP`` and stays on the table, even away from the goal along that axis;
  not where the goal-directed push across already clears them;
* **cut short** before an obstacle: where one of the distances above (but a squeeze) would
  bring the part's shadow within ``GAP`` of an obstacle ahead in its swath, the distance that
  stops it ``GAP`` short (allowing for the part's depth at its angle spread and the approach
  noise). The pushes that would drive a state of the part into the obstacle stay offered only
  where no detour push of the part fits (a part lying on a wall cannot be pushed off it, so
  running it into a post and round its corner is its only way on).

A paddle whose travel would sweep it into an obstacle outside the part's swath is shifted along
its long side, as beside walls and shadows, to pass it clear with its approach shadow, or else
with its nominal outline, or else (no such position covers the part's centre) left where it
was. None of the obstacle rules changes anything on a table without obstacles (every shipped
problem), and fixtures on the table give only squeezes.

Under the compliant controller (``problem.controller.kind == "compliant"``) a resisted push
stops short of its set point by about the resisting friction / Kp, so the distances to a goal
coordinate and the ``push_distances`` are lengthened by the nominal stall of what the push
moves: ``mu g rho A / Kp`` at the middle of the friction and part-density ranges, ``A`` the area
of the pushed part and of the parts in a row ahead of it whose shadows it would reach within
``CONTACT_GAP`` (pushes to a wall need none: their set point lies at the wall, or with
``compressed_wall_pushes`` beyond the compressed train by more than its worst-case stall;
:mod:`arrange_up.physics.stall`). Under the servo the stall is zero and the distances are as
before.

A push meant to move a part by a given travel then has its distance solved for in up to
``SOLVER_STEPS`` noise-free simulations from the belief's centres, unless ``solve_distances``
is off (the planner turns it off for semantics that do not simulate pushes, i.e. CBST: its
model predicts only pushes that compress a train against a wall, and the simulations took
half of a CBST search's time).

A part is never pushed away from its own goal (beyond the goal tolerance along the direction),
but for a detour: such a push cannot help it, and it multiplies the search's plateaus.

**Fences** (:mod:`arrange_up.planning.fences`): where a goal part needs one (its goal is
tighter along an axis than a free push can stop it, and the table has no wall the goal holds it
against there), places of a fixture at the part's goal face, after the places of parts; a push
to a fence on the table (or to an obstacle standing at the goal face), as to a wall (with
``compressed_wall_pushes``, the part's own extent plus its overdrive short of the face); and
along that axis no push that ends in the open (to the goal coordinate, or narrowing) while a
fence stands there or can be put down where it presses the part (any fence place, for a part
that needs one along both axes), but for a levelling push where a corner needs the part
brought level with its other fence first; where no fence can press it yet and a fixture is
still to be put down, a *passing* push towards the goal that stops short of the fence's place,
also centred where it clips no shadow ahead; and for such a part, the manipulator centred
across so that its path misses the fixtures on the table. Nothing of this is offered for a
problem whose parts need no fence (every shipped problem).

**Pick**: fixtures and manipulators on the table may be picked up, except a fence that holds a
part at its goal while the part still misses its goal along the other axis; parts are never
picked by the planner (a part must end on the table).

Preconditions are tested on belief shadows (:mod:`arrange_up.geometry.collision`): a placed object's
shadow (target ± place uncertainty) and a manipulator's approach shadow (approach pose ± push
uncertainty) must not touch any shadow of an object on the table, a wall or an obstacle, and a
placed object's shadow must lie on the table.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

from arrange_up.belief.states import IntervalBelief, symmetry_period, wrap_angle
from arrange_up.geometry.boxes import box_row
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import (
    ArrangementProblem,
    ControllerKind,
    ObjectKind,
    ObjectSpec,
    Pose,
)
from arrange_up.model.world import Action, Pick, Place, Push, WorldState
from arrange_up.physics.stall import stall_per_area, wall_overdrive, wall_push_front
from arrange_up.planning.fences import NO_FENCE, FenceAhead, Fences
from arrange_up.planning.mating import Mates
from arrange_up.planning.obstacles import GAP, Obstacles, far_face

#: The wall each push direction heads for.
_WALL_AHEAD = {"+x": "right", "-x": "left", "+y": "top", "-y": "bottom"}
#: Direction name -> unit vector in the world frame.
DIRECTIONS: dict[str, tuple[float, float]] = {
    "+x": (1.0, 0.0),
    "-x": (-1.0, 0.0),
    "+y": (0.0, 1.0),
    "-y": (0.0, -1.0),
}
#: ``(axis, sign)`` -> direction name.
_DIRECTION_OF = {(0 if ux else 1, int(ux + uy)): name for name, (ux, uy) in DIRECTIONS.items()}
#: Gap kept between the manipulator's approach shadow and the part's shadow (inches).
APPROACH_GAP = 0.02
#: Minimum useful push (inches): shorter candidates are dropped.
MIN_PUSH = 0.05
#: Candidate distances closer than this are considered the same (inches).
DISTANCE_RESOLUTION = 0.01
#: Travels (in) offered to a part with no goal position of its own (the reference of a
#: relative goal), which goal-directed distances never move.
LADDER = (0.5, 1.0, 2.0)
#: Parts ahead of a pushed part within this gap (in) count as moved with it by the push, for
#: the compliant controller's stall.
CONTACT_GAP = 0.1
#: Turning pushes (a part turned away from its goal angle): the manipulator's centre shifted
#: across the push from the part's centre by this fraction of the manipulator's length, to
#: either side, so that it presses one side of the part and turns it (docs/design/planning.md,
#: "Turning pushes").
TURN_OFFSET = 0.3
#: Under the compliant controller: simulations per candidate push spent solving for its
#: distance, and the error in the part's travel (in) at which the solver stops.
SOLVER_STEPS = 3
SOLVER_TOLERANCE = 0.002


@dataclass(frozen=True)
class _Manipulator:
    spec: ObjectSpec
    length: float  # along the long side
    thickness: float  # along the push direction
    push_angle: float  # angle of the push direction in the manipulator's frame


class ActionGenerator:
    """Proposes the candidate actions of a belief (see the module docstring)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        checker: CollisionChecker,
        *,
        unclipped_pushes: bool = False,
        settled_wall_pushes: bool = False,
        compressed_wall_pushes: bool = False,
        solve_distances: bool = True,
        clearance_pushes: bool = True,
    ) -> None:
        self.problem = problem
        self.checker = checker
        self.unclipped_pushes = unclipped_pushes
        self.settled_wall_pushes = settled_wall_pushes
        self.compressed_wall_pushes = compressed_wall_pushes
        self.solve_distances = solve_distances
        self.clearance_pushes = clearance_pushes
        hints = problem.planning
        self.directions = tuple(hints.push_directions or DIRECTIONS)
        self.push_distances = tuple(hints.push_distances or ())
        self.place_angles = tuple(hints.place_angles or ())
        self.place_unc = problem.uncertainty.place
        self.push_unc = problem.uncertainty.push
        self.manipulators = tuple(_describe(spec) for spec in problem.manipulators)
        self.compliant = problem.controller.kind is ControllerKind.COMPLIANT
        self.stall_per_area = stall_per_area(problem)
        self.areas = {spec.name: spec.shape.area for spec in problem.parts}
        self.periods = {spec.name: symmetry_period(spec.shape) for spec in problem.parts}
        self.wall_trains = self._wall_trains()
        self._limits = (self._across_limits(0), self._across_limits(1))
        walls = set(problem.table.walls)
        held = {
            (part, 0 if DIRECTIONS[direction][0] else 1): True
            for (part, direction), train in self.wall_trains.items()
            if train is not None and _WALL_AHEAD[direction] in walls
        }
        self.fences = Fences(problem, checker, held)
        self.obstacles = Obstacles(checker)
        self.mates = Mates(problem)
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

    def _wall_trains(self) -> dict[tuple[str, str], tuple[str, ...] | None]:
        """For each part with an absolute goal and each direction: the train of goal parts
        that holds it against the wall ahead in the goal arrangement (parts touching in a row
        or column, ending at the wall), or None when the goal does not hold it there.

        Pushing a part to a wall is a step towards the goal only when the goal holds it there
        and the whole train ahead of it is already on the table; otherwise the push carries it
        (and whatever is ahead) past the targets.
        """
        goal = self.problem.goal
        if goal.is_relative:
            return {}
        slack = 2.0 * max(goal.tolerance[0], goal.tolerance[1]) + 1e-6
        boxes = {p: self.checker.shadow_box(p, goal.target(p), (0.0, 0.0, 0.0)) for p in goal.parts}
        width, depth = self.problem.table.size
        trains: dict[tuple[str, str], tuple[str, ...] | None] = {}
        for part in goal.parts:
            for direction, (ux, uy) in DIRECTIONS.items():
                axis, sign = (0, int(ux)) if ux else (1, int(uy))
                train, front = box_row(boxes, part, axis, sign, slack)
                wall = (width if axis == 0 else depth) if sign > 0 else 0.0
                held = abs(sign * wall - front) <= slack
                trains[(part, direction)] = train if held else None
        return trains

    # -- all candidates --------------------------------------------------------------------
    def candidates(self, belief: IntervalBelief) -> list[Action]:
        """Every applicable candidate action of ``belief`` (preconditions hold), in a fixed
        order: places of parts, places of fences (:mod:`arrange_up.planning.fences`), then
        pushes, then picks."""
        places = self.places(belief)
        routes = self.fence_routes(belief)
        fences = list(dict.fromkeys(a for options in routes.values() for a in options))
        return [*places, *fences, *self.pushes(belief, places, routes), *self.picks(belief)]

    def fence_routes(self, belief: IntervalBelief) -> dict[tuple[str, int, int], list[Place]]:
        """The fence places of ``belief``, keyed by the ``(part, axis, sign)`` of the push
        that would press the part against them (empty unless a goal part needs a fence)."""
        if not self.fences.needs:
            return {}
        return self.fences.placements(belief, self._shadows(belief))

    # -- place -----------------------------------------------------------------------------
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

    def _place_targets(self, name: str, belief: IntervalBelief) -> tuple[Pose, ...]:
        """The poses about which ``name`` is placed, to be tried in order: its
        :meth:`place_target`, or for a relative goal's reference off the table every one of
        :attr:`Mates.homes` (the first with a clear place is used)."""
        if name == self.problem.goal.reference and name not in belief:
            return self.mates.homes
        target = self.place_target(name, belief)
        return () if target is None else (target,)

    def places(self, belief: IntervalBelief, only: str | None = None) -> list[Place]:
        """Place candidates of every goal part off the table (or of ``only``)."""
        on_table = self._shadows(belief)
        boxes = None  # their shadow boxes, once a place is tested
        actions = []
        for spec in self.problem.parts:
            if spec.name in belief or (only is not None and spec.name != only):
                continue
            for target in self._place_targets(spec.name, belief):
                found = len(actions)
                for pose in self._place_grid(spec.name, target):
                    if boxes is None:
                        boxes = [self.checker.shadow_box(*shadow) for shadow in on_table]
                    if self._place_ok(spec.name, pose, self.place_unc, on_table, boxes):
                        actions.append(Place(spec.name, _clean(pose)))
                if len(actions) > found:
                    break
        return actions

    def place_poses(self, belief: IntervalBelief, name: str) -> list[Pose]:
        """Candidate place poses of ``name`` that fit the table, walls and obstacles, whatever
        the objects on the table (those are the precondition's other half); for a relative
        goal's reference, about the first of :attr:`Mates.homes` that has any."""
        for target in self._place_targets(name, belief):
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

    # -- push ------------------------------------------------------------------------------
    def pushes(
        self,
        belief: IntervalBelief,
        places: list[Place] | None = None,
        routes: dict[tuple[str, int, int], list[Place]] | None = None,
    ) -> list[Push]:
        """The push candidates of ``belief``; ``places`` and ``routes``, its place candidates
        and fence routes if the caller has them already (:meth:`candidates`), save computing
        them again."""
        on_table = self._shadows(belief)
        routes = self.fence_routes(belief) if routes is None else routes
        # The ladder for parts without a goal position only when a goal part cannot be placed:
        # otherwise the goal-directed actions make progress, and the ladder only widens the
        # search (relative matings expanded 13 times the nodes with it always on).
        placeable = {a.obj for a in (self.places(belief) if places is None else places)}
        ladder = any(
            spec.name not in belief and spec.name not in placeable
            for spec in self.problem.parts
            if spec.name in self.problem.goal.parts
        )
        boxes = [(name, self.checker.shadow_box(name, c, h)) for name, c, h in on_table]
        # The approach's clearance across is sought against each convex part of a concave
        # shadow: its whole box would close the notch a part is pushed into.
        pieces = boxes
        if any(name in self.checker.concave for name, _, _ in on_table):
            pieces = [
                (name, box)
                for name, c, h in on_table
                for box in self.checker.piece_boxes(name, c, h)
            ]
        actions: list[Push] = []
        for manip in self.manipulators:
            if manip.spec.name in belief:
                continue
            for spec in self.problem.parts:
                interval = belief.get(spec.name)
                if interval is None:
                    continue
                detours = self._detours(spec.name, interval, belief) if self.obstacles else {}
                turning = self._turned_away(spec.name, interval, belief) or (
                    bool(self.mates) and self.mates.square(spec.name, interval.half)
                )
                jams: list[Push] = []
                mine: list[Push] = []
                detoured = False
                for direction in self.directions:
                    pushes = self._pushes_of(
                        manip,
                        spec.name,
                        interval,
                        direction,
                        belief,
                        on_table,
                        boxes,
                        pieces,
                        ladder,
                        routes,
                        detours.get(direction),
                        jams,
                        turning,
                    )
                    detoured = detoured or (direction in detours and bool(pushes))
                    mine.extend(pushes)
                # A push that drives the part into an obstacle only where it cannot go round.
                if detoured and jams:
                    mine = [push for push in mine if push not in jams]
                actions.extend(mine)
        return actions

    def _detours(self, name: str, interval, belief: IntervalBelief) -> dict[str, float]:
        """The sideways travels that take ``name`` round the obstacles blocking its straight
        push to its goal coordinate, by direction (module docstring: at most one per blocked
        axis, to the nearer side where its shadow clears them by ``GAP`` and stays on the
        table)."""
        target = self.place_target(name, belief)
        if target is None:
            return {}
        shadow = self.checker.shadow_box(name, interval.center, interval.half)
        detours: dict[str, float] = {}
        for axis in (0, 1):
            travel = target[axis] - interval.center[axis]
            if abs(travel) <= MIN_PUSH:
                continue
            sign, other = (1 if travel > 0 else -1), 1 - axis
            band = (shadow[other] - GAP, shadow[other + 2] + GAP)
            blocks = self.obstacles.blocking(
                far_face(shadow, axis, sign), band, axis, sign, abs(travel)
            )
            if not blocks:
                continue
            # The shadow after a sideways push: its spread across the push is the push's own.
            half = list(interval.half)
            half[other] = self.push_unc[other]
            end = self.checker.shadow_box(name, interval.center, tuple(half))
            size = self.problem.table.size[other]
            sides = (
                (max(b[other + 2] for b in blocks) + GAP - end[other], 1),
                (end[other + 2] - (min(b[other] for b in blocks) - GAP), -1),
            )
            feasible = [
                (t, side)
                for t, side in sides
                if t > MIN_PUSH
                and end[other] + side * t >= 0.0
                and end[other + 2] + side * t <= size
            ]
            # None where the goal-directed push across already takes the shadow clear.
            across = target[other] - interval.center[other]
            if feasible and not any(side * across >= t for t, side in sides):
                t, side = min(feasible)
                detours[_DIRECTION_OF[(other, side)]] = t
        return detours

    def _pushes_of(
        self,
        manip,
        name,
        interval,
        direction,
        belief,
        on_table,
        boxes,
        pieces,
        ladder=False,
        routes=None,
        detour: float | None = None,
        jams: list[Push] | None = None,
        turning: bool = False,
    ) -> list[Push]:
        """The pushes of part ``name`` along ``direction``; ``on_table`` are the belief's
        shadows ``(name, centre, half)``, ``boxes`` their ``(name, shadow box)`` and ``pieces``
        the same with a concave shadow's box split into its parts'. Those that
        would drive a state of the part into an obstacle (:meth:`_cut_short`) are also appended
        to ``jams``. ``turning``: the part is also offered turning pushes (the module
        docstring; decided once per part by :meth:`pushes`)."""
        ux, uy = DIRECTIONS[direction]
        axis = 0 if ux else 1
        sign = int(ux + uy)  # +1 or -1
        target = self.place_target(name, belief)
        tolerance = self.problem.goal.tolerance[axis]
        away = target is not None and sign * (target[axis] - interval.center[axis]) < -tolerance
        if away and detour is None:
            return []  # it would push the part away from where it must end
        theta = wrap_angle(math.atan2(uy, ux) - manip.push_angle, 0.0, 2.0 * math.pi)
        part_box = self.checker.shadow_box(name, interval.center, interval.half)
        # Extents of the manipulator's approach shadow relative to its commanded centre.
        m_box = self.checker.shadow_box(manip.spec.name, (0.0, 0.0, theta), self.push_unc)
        # Along the push: the manipulator's shadow front stops APPROACH_GAP short of the part's.
        if sign > 0:
            along = part_box[axis] - APPROACH_GAP - m_box[axis + 2]
        else:
            along = part_box[axis + 2] + APPROACH_GAP - m_box[axis]
        front_nominal = sign * along + 0.5 * manip.thickness  # signed coordinate of the front
        fence = (
            self.fences.ahead(name, interval, belief, axis, sign, routes or {})
            if self.fences.needs
            else NO_FENCE
        )
        # An open push of a part that needs a fence no fence can press yet is a passage (past
        # another part, say): it is also offered where it clips no shadow ahead.
        passing = fence.passing
        distances, jammed = self._distances(
            name, interval, belief, axis, sign, front_nominal, ladder, routes, detour, away, fence
        )
        pushes = []
        for sweep, group in self._sweeps(distances, along, m_box, part_box, axis, sign):
            # Clear of the obstacles the paddle would sweep into where its approach shadow can
            # be; else where the nominal paddle can (the obstacles' boxes shrunk by the margin
            # the shadow and APPROACH_GAP add across: only a noisy approach grazes them); else
            # where it was (it stops on one as the part reaches its end).
            centres = self._across(
                manip, name, interval, axis, sign, along, m_box, pieces, sweep, passing
            )
            if sweep and not centres:
                other = 1 - axis
                margin = 0.5 * (m_box[other + 2] - m_box[other] - manip.length) + APPROACH_GAP
                shrunk = tuple(_shrink(box, other, margin) for box in sweep)
                centres = self._across(
                    manip, name, interval, axis, sign, along, m_box, pieces, shrunk, passing
                )
            if sweep and not centres:
                centres = self._across(
                    manip, name, interval, axis, sign, along, m_box, pieces, (), passing
                )
            if self.fences.needs and group:
                centres = self._clear_of_fences(
                    manip, name, interval, belief, axis, sign, along, m_box, centres, group
                )
            turns = self._turning_centres(manip, interval, axis, m_box, centres) if turning else []
            for across in centres + turns:
                pose = (along, across, theta) if axis == 0 else (across, along, theta)
                if self.checker.shadow_clear(
                    manip.spec.name, pose, self.push_unc, on_table, [box for _, box in boxes]
                ):
                    for d, travel in group:
                        if travel is not None and across in turns:
                            continue  # a turning push presses the part against what stops it
                        push = Push(manip.spec.name, _clean(pose), round(float(d), 4))
                        if self.stall_per_area and self.solve_distances and travel is not None:
                            distance = self._solve_distance(push, name, axis, sign, travel, belief)
                            push = Push(push.manipulator, push.pose, distance)
                        pushes.append(push)
                        if d in jammed and jams is not None:
                            jams.append(push)
        return pushes

    def _turned_away(self, name: str, interval, belief: IntervalBelief) -> bool:
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

    def _turning_centres(self, manip, interval, axis: int, m_box, centres) -> list[float]:
        """Turning pushes: centres across the push shifted from the part's centre by
        :data:`TURN_OFFSET` of the manipulator's length to either side (within the span at
        which it still covers the part's centre and clears the walls), so that it presses one
        side of a part turned away from its goal angle and turns it flat against the wall,
        fence or obstacle it is pressed against (only the distances that press a part are
        offered with them: a free push on one side leaves the angle to chance); those not
        already in ``centres``. The approach's clearance is checked with every other centre's."""
        other = 1 - axis
        low, high = self._across_span(manip, interval, other, m_box)
        shift = TURN_OFFSET * manip.length
        found = []
        for side in (-1.0, 1.0):
            value = interval.center[other] + side * shift
            if low <= value <= high and all(abs(value - c) > 1e-6 for c in (*centres, *found)):
                found.append(value)
        return found

    def _clear_of_fences(
        self, manip, name, interval, belief, axis, sign, along, m_box, centres, distances
    ) -> list[float]:
        """``centres`` moved so that the manipulator's path misses the fences of the other axis
        on the table (:meth:`~arrange_up.planning.fences.Fences.clear_paths`), for a part that
        needs a fence."""
        other = 1 - axis
        return self.fences.clear_paths(
            name,
            belief,
            axis,
            sign,
            centres,
            self._across_span(manip, interval, other, m_box),
            (along + m_box[axis], along + m_box[axis + 2]),
            (m_box[other], m_box[other + 2]),
            max(d for d, _ in distances),
        )

    def _sweeps(self, distances, along, m_box, part_box, axis, sign):
        """``distances`` grouped by the obstacles the paddle's approach shadow would sweep into
        (outside the part's swath) on the way, in order: ``(obstacle boxes, distances)``. With
        no obstacle on the way (every distance of a problem without obstacles) one group."""
        if not self.obstacles:
            return [((), distances)]
        start = (along + m_box[axis], along + m_box[axis + 2])
        rear, front = (start[0], start[1]) if sign > 0 else (-start[1], -start[0])
        other = 1 - axis
        swath = (part_box[other], part_box[other + 2])
        groups: dict[tuple, list] = {}
        for d, travel in distances:
            hits = tuple(self.obstacles.swept(rear, front, d, swath, axis, sign))
            groups.setdefault(hits, []).append((d, travel))
        return list(groups.items())

    def _across(
        self, manip, name, interval, axis, sign, along, m_box, boxes, sweep=(), unclipped=False
    ) -> list[float]:
        """Where to centre the manipulator across the push (at most two centres).

        The first is as near the part's centre as the walls, the shadows beside the approach
        and the obstacle boxes in ``sweep`` (those its travel would meet) allow, while the
        manipulator's long side still covers the part's centre (with 0.1 in to spare). With
        ``unclipped_pushes`` (or ``unclipped``: a passing push, :mod:`~arrange_up.planning.fences`),
        when it clips the side of a shadow *ahead* of the approach (the
        manipulator's span overlaps that shadow's span without covering it whole, so the
        contact may or may not happen), the second is the nearest centre at which every
        shadow ahead is either missed or covered whole. Empty if no centre fits.
        """
        other = 1 - axis
        centre = interval.center[other]
        low, high = self._across_span(manip, interval, other, m_box)
        if low > high:
            return []
        a_lo, a_hi = along + m_box[axis], along + m_box[axis + 2]
        boxes = [box for other_name, box in boxes if other_name != name]
        # Shadows (and obstacles) level with the approach forbid the centres that would make
        # them overlap: each gives the open interval of such centres.
        forbidden = [
            (
                box[other] - m_box[other + 2] - APPROACH_GAP,
                box[other + 2] - m_box[other] + APPROACH_GAP,
            )
            for box in boxes + list(self.checker.obstacle_boxes.values())
            if box[axis + 2] > a_lo - APPROACH_GAP and box[axis] < a_hi + APPROACH_GAP
        ] + [
            (
                box[other] - m_box[other + 2] - APPROACH_GAP,
                box[other + 2] - m_box[other] + APPROACH_GAP,
            )
            for box in sweep
        ]
        # Shadows ahead (only with unclipped_pushes): the centres at which the approach shadow
        # touches one (the interval it is forbidden from when level) and those at which the
        # nominal manipulator covers it whole. Touching without covering is clipping.
        half_length = 0.5 * manip.length
        ahead = [
            (
                box[other] - m_box[other + 2] - APPROACH_GAP,
                box[other + 2] - m_box[other] + APPROACH_GAP,
                box[other + 2] - half_length,
                box[other] + half_length,
            )
            for box in (boxes if self.unclipped_pushes or unclipped else [])
            if (
                box[axis] >= a_hi - APPROACH_GAP
                if sign > 0
                else box[axis + 2] <= a_lo + APPROACH_GAP
            )
        ]
        # Candidate centres: the preferred one and the edges of every interval above.
        candidates = [min(max(centre, low), high)]
        candidates += [v for bounds in forbidden + ahead for v in bounds if low <= v <= high]
        candidates.sort(key=lambda v: abs(v - centre))
        # The nearest allowed centre, and the nearest allowed one that clips no shadow ahead.
        first = None
        for value in candidates:
            if any(lo < value < hi for lo, hi in forbidden):
                continue
            if first is None:
                first = value
            if not any(
                touch_lo < value < touch_hi and not cover_lo <= value <= cover_hi
                for touch_lo, touch_hi, cover_lo, cover_hi in ahead
            ):
                return [first] if abs(value - first) <= 1e-6 else [first, value]
        return [] if first is None else [first]

    def _across_span(self, manip, interval, other: int, m_box) -> tuple[float, float]:
        """The range of centres across the push (along axis ``other``) at which the
        manipulator's long side covers the part's centre with 0.1 in to spare and its approach
        shadow (extents ``m_box``) keeps clear of the walls; empty (low > high) if none."""
        reach = 0.5 * manip.length - 0.1
        low_lim, high_lim = self._limits[other]
        return (
            max(interval.center[other] - reach, low_lim - m_box[other]),
            min(interval.center[other] + reach, high_lim - m_box[other + 2]),
        )

    def _across_limits(self, other: int) -> tuple[float, float]:
        """The coordinate range across a push that keeps clear of walls on that axis."""
        walls = set(self.problem.table.walls)
        size = self.problem.table.size[other]
        low_name, high_name = ("left", "right") if other == 0 else ("bottom", "top")
        low = 0.0 + APPROACH_GAP if low_name in walls else -math.inf
        high = size - APPROACH_GAP if high_name in walls else math.inf
        return low, high

    def _distances(
        self,
        name,
        interval,
        belief,
        axis,
        sign,
        front,
        ladder=False,
        routes=None,
        detour: float | None = None,
        away: bool = False,
        fence: FenceAhead = NO_FENCE,
    ) -> tuple[list[tuple[float, float | None]], set[float]]:
        """Candidate travel distances of the manipulator (see the module docstring), each with
        the travel of the part it is meant for (``None`` for a push to the wall, a squeeze or a
        push cut short), and the distances among them that jam the part on an obstacle.
        ``detour``: a sideways travel round an obstacle (:meth:`_detours`); ``away``: the push
        moves the part away from its goal, so only the detour is offered; ``fence``: what the
        fences say of these pushes (:meth:`~arrange_up.planning.fences.Fences.ahead`)."""
        size = self.problem.table.size[axis]
        direction = _DIRECTION_OF[(axis, sign)]
        wall = _WALL_AHEAD[direction]
        nominal = self.checker.shadow_box(name, interval.center, (0.0, 0.0, 0.0))
        rear = sign * (nominal[axis] if sign > 0 else nominal[axis + 2])
        gap = rear - front  # nominal free travel before contact
        stall = self._stall(name, belief, axis, sign) if self.stall_per_area else 0.0
        if away:  # only the detour (_pushes_of does not call this for an away push without one)
            return self._cut_short(
                name, interval, axis, sign, front, gap, [(gap + detour + stall, detour)]
            )
        candidates = []
        train = self.wall_trains.get((name, direction), ())
        if (
            wall in self.problem.table.walls
            and train is not None
            and all(q in belief for q in train)
            and not (
                self.compliant
                and not self.settled_wall_pushes
                and self._settled((name, *train), belief, axis)
            )
        ):
            boundary = size if sign > 0 else 0.0
            candidates.append(
                self._stop_front(sign * boundary, (name, *train), belief, axis) - front
            )
        # A fence (a fixture on the table at the part's goal face) is pushed against as the
        # wall is; where a fence is needed and one is there or can be put down, the pushes
        # that end in the open along this axis are not offered: by the problem's own noise
        # they cannot stop the part within its tolerance (planning.fences).
        target = self.place_target(name, belief)
        fenced, levelling = fence.fenced, None
        # pushes meant to press the part against something fixed: not cut short (_cut_short)
        squeezes: set[float] = set()
        if fence.face is not None and not (
            self.compliant
            and not self.settled_wall_pushes
            and target is not None
            and self._inside_goal(interval, target, axis)
        ):
            candidates.append(self._stop_front(sign * fence.face, (name,), belief, axis) - front)
            squeezes.add(candidates[-1])
        if fenced:
            # a corner: the part first brought level with a fence of the other axis
            levelling = self.fences.level(name, interval, belief, axis, routes or {})
        travels: dict[float, float | None] = dict.fromkeys(candidates)
        # Free travel a distance must exceed by MIN_PUSH: to the centre state's contact, or, for
        # a narrowing push, to the contact of the rearmost state.
        least: dict[float, float] = {}
        if target is not None:
            travel = sign * (target[axis] - interval.center[axis])
            half = interval.half[axis]
            if fenced:
                # the fence's push (above) replaces those that end in the open, but for a
                # levelling push
                if levelling is not None:
                    level = sign * (levelling - interval.center[axis])
                    if level > MIN_PUSH:
                        travels.setdefault(gap + level + stall, level)
            elif fence.passing:
                # towards the goal, short of the fence still to be put down; no narrowing:
                # the fence does that
                aim = min(
                    travel,
                    sign
                    * (self.fences.passing_aim(name, interval, axis, sign) - interval.center[axis]),
                )
                if aim > MIN_PUSH:
                    travels.setdefault(gap + aim + stall, aim)
            elif travel > MIN_PUSH:
                travels.setdefault(gap + travel + stall, travel)
            elif not self._inside_goal(interval, target, axis) and travel + half > MIN_PUSH:
                # Narrowing: the centre is (about) on target but the spread misses the goal.
                # The push ends where the nominal part would sit at its target, so the states
                # behind it are swept up to the target and those ahead are left alone; a push
                # from the other side does the rest.
                d = gap + travel + stall
                travels.setdefault(d, None)
                least[d] = gap - half
                # A squeeze: pressed against an obstacle or a fixture ahead, as against a wall.
                face = self._squeeze_face(name, interval, belief, axis, sign)
                if face is not None:
                    squeezes.add(face - front)
                    travels.setdefault(face - front, None)
                    least[face - front] = gap - half
            if not fenced and self.mates:
                for d, part_travel in self._mating(name, interval, belief, target, axis, sign):
                    travels.setdefault(
                        gap + d + (stall if part_travel is not None else 0.0), part_travel
                    )
        else:
            # No goal position (the reference part of a relative goal).
            gather = self.mates.gather(name, interval.half[axis], axis)
            if gather is not None:
                travels.setdefault(gap + gather + stall, gather)
            if wall in self.problem.table.walls and self.mates.square(name, interval.half):
                # squared: pressed against the wall ahead, its turned states turn flat
                boundary = size if sign > 0 else 0.0
                press = self._stop_front(sign * boundary, (name,), belief, axis) - front
                travels.setdefault(press, None)
                squeezes.add(press)
            if ladder and not candidates and not self.push_distances:
                # A short ladder of travels, those that keep the part's nominal footprint on
                # the table.
                low, high = (nominal[axis], nominal[axis + 2])
                for d in LADDER:
                    shifted = (low + sign * d, high + sign * d)
                    if shifted[0] >= 0.0 and shifted[1] <= size:
                        travels.setdefault(gap + d + stall, d)
        if detour is not None:
            travels.setdefault(gap + detour + stall, detour)
        for d in self.push_distances:
            travels.setdefault(gap + d + stall, d)
        result: list[tuple[float, float | None]] = []
        for d in sorted(travels):
            if d > least.get(d, gap) + MIN_PUSH and all(
                abs(d - r) > DISTANCE_RESOLUTION for r, _ in result
            ):
                result.append((d, travels[d]))
        if self.obstacles:
            return self._cut_short(name, interval, axis, sign, front, gap, result, squeezes)
        return result, set()

    def _mating(
        self, name, interval, belief, target, axis, sign
    ) -> list[tuple[float, float | None]]:
        """The pushes of a part whose relative goal holds it against its mate ahead along the
        push (:mod:`arrange_up.planning.mating`), as ``(travel of the set point beyond the free
        travel, travel of the part or None)``: while the part misses its goal interval across
        the push, the goal-directed push stopped short by the goal tolerance, or by the part's
        spread relative to its mate where that is wider (a travel, solved for like the
        goal-directed one); and under the compliant controller, while the part misses its
        goal interval along the push, the seating push to the goal coordinate plus the part's
        wall overdrive (None: it stops at the contact)."""
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
            self.clearance_pushes
            and clear > MIN_PUSH
            and not self._inside_goal(interval, target, 1 - axis)
        ):
            pushes.append((clear, clear))
        over = self._overdrive(self.areas[name], axis)
        if over is not None and not self._inside_goal(interval, target, axis):
            pushes.append((travel + over, None))
        return pushes

    def _cut_short(self, name, interval, axis, sign, front, gap, result, squeezes=frozenset()):
        """``result`` (sorted ``(distance, travel)`` pairs) with the pushes that jam the part on
        an obstacle ahead in its swath cut short (module docstring): when a distance (but a
        squeeze's) would bring the part's shadow within ``GAP`` of the obstacle, the distance
        that stops it ``GAP`` short (the paddle's front ends there less the part's depth at its
        angle spread and the approach noise along the push) is added, if it moves the part more
        than ``MIN_PUSH``. Also returns the distances (but a squeeze's) that would drive some
        state of the part into the obstacle."""
        other = 1 - axis
        shadow = self.checker.shadow_box(name, interval.center, interval.half)
        stop = self.obstacles.face_ahead(
            far_face(shadow, axis, sign), (shadow[other], shadow[other + 2]), axis, sign
        )
        if stop is None:
            return result, set()
        # A state of the part meets the obstacle when the paddle's front ends less than the
        # part's depth before the face.
        nominal = self.checker.shadow_box(name, interval.center, (0.0, 0.0, 0.0))
        depth = nominal[axis + 2] - nominal[axis]
        jammed = {
            d
            for d, _ in result
            if d not in squeezes and front + d + depth > stop + DISTANCE_RESOLUTION
        }
        turned = self.checker.shadow_box(name, interval.center, (0.0, 0.0, interval.half[2]))
        short = stop - GAP - (turned[axis + 2] - turned[axis]) - self.push_unc[axis] - front
        if (
            short <= gap + MIN_PUSH
            or not any(d > short for d, _ in result if d not in squeezes)
            or any(abs(d - short) <= DISTANCE_RESOLUTION for d, _ in result)
        ):
            return result, jammed
        return sorted([*result, (short, None)]), jammed

    def _squeeze_face(self, name, interval, belief, axis, sign) -> float | None:
        """The signed coordinate of the face a squeeze presses ``name`` against along the push:
        the nearest near face ahead of an obstacle or of a fixture's shadow on the table that
        covers the part's centre across the push with a quarter of the part to spare; None if
        there is none (or the problem has neither)."""
        fixtures = tuple(
            self.checker.shadow_box(spec.name, iv.center, iv.half)
            for spec in self.problem.fixtures
            if (iv := belief.get(spec.name)) is not None
        )
        if not self.obstacles and not fixtures:
            return None
        other = 1 - axis
        nominal = self.checker.shadow_box(name, interval.center, (0.0, 0.0, 0.0))
        spare = 0.25 * (nominal[other + 2] - nominal[other])
        centre = interval.center[other]
        return self.obstacles.face_ahead(
            far_face(nominal, axis, sign),
            (centre - spare, centre + spare),
            axis,
            sign,
            fixtures,
            cover=True,
        )

    def _stop_front(
        self, stop: float, parts: tuple[str, ...], belief: IntervalBelief, axis: int
    ) -> float:
        """Where (signed coordinate along the push) a push of ``parts``, the pushed part and
        the train ahead of it, against the wall or fence face at ``stop`` sends the
        manipulator's front: the face itself; with ``compressed_wall_pushes`` under the
        compliant controller, the front of the compressed train (the parts' nominal extents
        along the push, at their belief centres) plus its
        :func:`~arrange_up.physics.stall.wall_overdrive`."""
        if not self.compressed_wall_pushes:
            return stop
        over = self._overdrive(sum(self.areas[q] for q in parts), axis)
        if over is None:
            return stop
        length = 0.0
        for q in parts:
            box = self.checker.shadow_box(q, belief.get(q).center, (0.0, 0.0, 0.0))  # type: ignore[union-attr]
            length += box[axis + 2] - box[axis]
        return wall_push_front(stop, length, over)

    def _overdrive(self, area: float, axis: int) -> float | None:
        """The problem's :func:`~arrange_up.physics.stall.wall_overdrive` for ``area`` square
        inches of parts pressed along ``axis`` (None under the servo)."""
        u = self.problem.uncertainty
        return wall_overdrive(
            self.problem.controller, u.friction, u.part_density, area, self.push_unc[axis]
        )

    def _settled(self, parts: tuple[str, ...], belief: IntervalBelief, axis: int) -> bool:
        """Whether every one of ``parts`` lies within its goal interval along ``axis`` in every
        state of ``belief`` (its interval inside the target +- the tolerance)."""
        for part in parts:
            target = self.place_target(part, belief)
            interval = belief.get(part)
            if target is None or interval is None:
                return False
            if not self._inside_goal(interval, target, axis):
                return False
        return True

    def _inside_goal(self, interval, target: Pose, axis: int) -> bool:
        """Whether ``interval`` lies inside ``target`` +- the goal tolerance along ``axis``."""
        tolerance = self.problem.goal.tolerance[axis] + 1e-9
        return abs(interval.center[axis] - target[axis]) + interval.half[axis] <= tolerance

    def _solve_distance(
        self, push: Push, name: str, axis: int, sign: int, travel: float, belief: IntervalBelief
    ) -> float:
        """The distance at which ``push`` moves ``name`` by ``travel`` along its direction in a
        noise-free simulation from the belief's centres, under the compliant controller: up to
        ``SOLVER_STEPS`` fixed-point steps ``d += travel - achieved`` from ``push.distance``
        (the stall changes little with the distance, so each step removes most of the error),
        stopping within ``SOLVER_TOLERANCE``. A simulation that does not end at rest, or a
        distance that falls to the free travel, keeps the last good distance."""
        # Imported here: the physics (pymunk) costs ~55 ms to import, which importing the
        # planner does not pay until a plan is made.
        from arrange_up.physics.simulation import simulate

        state = WorldState(tuple((n, iv.center) for n, iv in belief.objects))
        start = belief.get(name).center[axis]  # type: ignore[union-attr]
        distance = push.distance
        for _ in range(SOLVER_STEPS):
            outcome = simulate(self.problem, state, push)
            if not outcome.ok or name not in outcome.state:
                break
            error = travel - sign * (outcome.state.as_dict()[name][axis] - start)
            if abs(error) <= SOLVER_TOLERANCE or distance + error <= MIN_PUSH:
                break
            distance += error
            push = Push(push.manipulator, push.pose, round(float(distance), 4))
        return push.distance

    def _stall(self, name: str, belief: IntervalBelief, axis: int, sign: int) -> float:
        """The compliant controller's nominal stall pushing ``name`` (module docstring): the
        pushed part and the row of parts ahead of it within ``CONTACT_GAP``, by nominal
        boxes at the belief centres."""
        other = 1 - axis
        boxes = {
            n: self.checker.shadow_box(n, iv.center, (0.0, 0.0, 0.0))
            for n, iv in belief.objects
            if n in self.areas
        }
        row, box = [name], boxes[name]
        while True:
            front = box[axis + 2] if sign > 0 else -box[axis]
            ahead = [
                (rear, q)
                for q, b in boxes.items()
                if q not in row
                and min(b[other + 2], box[other + 2]) - max(b[other], box[other]) > 1e-6
                and -1e-6
                <= (rear := (b[axis] if sign > 0 else -b[axis + 2]) - front)
                <= CONTACT_GAP
            ]
            if not ahead:
                break
            _, nearest = min(ahead)
            row.append(nearest)
            box = boxes[nearest]
        return self.stall_per_area * sum(self.areas[q] for q in row)

    # -- pick ------------------------------------------------------------------------------
    def picks(self, belief: IntervalBelief) -> list[Pick]:
        """Picks of the fixtures and manipulators on the table, except a fence that holds a
        goal part at its goal while that part still has pushes to come
        (:meth:`~arrange_up.planning.fences.Fences.holding`)."""
        kinds = (ObjectKind.FIXTURE, ObjectKind.MANIPULATOR)
        keep = self.fences.holding(belief, self._part_inside(belief)) if self.fences.needs else ()
        return [
            Pick(name)
            for name in belief.names()
            if self.problem.object(name).kind in kinds and name not in keep
        ]

    def _part_inside(self, belief: IntervalBelief):
        """``inside(part, axis)``: whether ``part`` lies within its goal along ``axis``."""

        def inside(part: str, axis: int) -> bool:
            target, interval = self.place_target(part, belief), belief.get(part)
            return (
                target is not None
                and interval is not None
                and self._inside_goal(interval, target, axis)
            )

        return inside

    # -- helpers ---------------------------------------------------------------------------
    def _shadows(self, belief: IntervalBelief):
        return [(name, iv.center, iv.half) for name, iv in belief.objects]


def _describe(spec: ObjectSpec) -> _Manipulator:
    xmin, ymin, xmax, ymax = spec.shape.extent
    px, py = spec.push_direction
    length, thickness = (xmax - xmin, ymax - ymin) if py else (ymax - ymin, xmax - xmin)
    return _Manipulator(spec, length, thickness, math.atan2(py, px))


def _shrink(box, axis: int, margin: float):
    """``box`` narrowed by ``margin`` on both sides along ``axis`` (to its centre at most)."""
    low, high = box[axis] + margin, box[axis + 2] - margin
    if low > high:
        low = high = 0.5 * (box[axis] + box[axis + 2])
    bounds = list(box)
    bounds[axis], bounds[axis + 2] = low, high
    return tuple(bounds)


def _clean(pose: Pose) -> Pose:
    """Round a generated pose's position to 1e-6 in so plans print and compare cleanly. The
    angle is kept exact: it comes from exact axis directions (``-pi/2`` converts to exactly
    -90 degrees only unrounded)."""
    return (round(float(pose[0]), 6) + 0.0, round(float(pose[1]), 6) + 0.0, float(pose[2]) + 0.0)
