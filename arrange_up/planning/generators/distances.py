"""Push distances: how far the manipulator travels in each push of a part along a direction.

* to the wall ahead (the controller stalls when the train of parts is compressed against it),
  generated only when the goal holds the part against that wall, directly or through a train
  of touching goal parts that are all on the table already
  (:mod:`~arrange_up.planning.generators.wall_trains`) — never towards an edge without a wall,
  where it would only push parts off; under the compliant controller not once the part and
  that train all lie within their goal intervals along the push (pressing them into the wall
  again only perturbs them, a new belief each time, a plateau without end; under the servo
  the repeat is a no-op the search prunes as a duplicate), unless ``settled_wall_pushes`` (the
  planner sets it for semantics that predict rather than simulate a push, i.e. CBST: there a
  repeat is a duplicate, and it narrows intervals until later contacts are certain). The
  manipulator's front is sent to the wall itself, or with ``compressed_wall_pushes`` to the
  front of the compressed train plus its overdrive
  (:meth:`~arrange_up.planning.generators.stall.PushStall.stop_front`);
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
* **mating** (:mod:`~arrange_up.planning.generators.mating_pushes`);
* **a detour** round obstacles, and the distances **cut short** before one
  (:mod:`~arrange_up.planning.generators.detours`);
* **fences** (:mod:`arrange_up.planning.fences`): a push to a fence on the table (or to an
  obstacle standing at the goal face), as to a wall; along an axis that needs a fence no push
  that ends in the open while a fence stands there or can be put down where it presses the
  part, but for a levelling push where a corner needs the part brought level with its other
  fence first; where no fence can press it yet and a fixture is still to be put down, a
  *passing* push towards the goal that stops short of the fence's place.

The distances to a goal coordinate and the ``push_distances`` are lengthened by the compliant
controller's stall (:mod:`~arrange_up.planning.generators.stall`).
"""

from __future__ import annotations

from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem, ControllerKind
from arrange_up.planning.fences import NO_FENCE, FenceAhead, Fences
from arrange_up.planning.generators.common import (
    DIRECTION_OF,
    DISTANCE_RESOLUTION,
    MIN_PUSH,
    WALL_AHEAD,
    PushOptions,
)
from arrange_up.planning.generators.detours import Detours, Distances
from arrange_up.planning.generators.mating_pushes import MatingPushes
from arrange_up.planning.generators.stall import PushStall
from arrange_up.planning.generators.targets import GoalTargets
from arrange_up.planning.generators.wall_trains import WallTrains
from arrange_up.planning.mating import Mates
from arrange_up.planning.obstacles import Obstacles, far_face

#: Travels (in) offered to a part with no goal position of its own (the reference of a
#: relative goal), which goal-directed distances never move.
LADDER = (0.5, 1.0, 2.0)


class PushDistances:
    """The candidate distances of one problem's pushes (see the module docstring)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        checker: CollisionChecker,
        options: PushOptions,
        *,
        targets: GoalTargets,
        trains: WallTrains,
        stall: PushStall,
        fences: Fences,
        obstacles: Obstacles,
        mates: Mates,
        mating: MatingPushes,
        detours: Detours,
    ) -> None:
        self.problem = problem
        self.checker = checker
        self.options = options
        self.targets = targets
        self.trains = trains
        self.stall = stall
        self.fences = fences
        self.obstacles = obstacles
        self.mates = mates
        self.mating = mating
        self.detours = detours
        self.compliant = problem.controller.kind is ControllerKind.COMPLIANT
        self.push_distances = tuple(problem.planning.push_distances or ())

    def distances(
        self,
        name: str,
        interval: ObjectInterval,
        belief: IntervalBelief,
        axis: int,
        sign: int,
        front: float,
        ladder: bool = False,
        routes=None,
        detour: float | None = None,
        away: bool = False,
        fence: FenceAhead = NO_FENCE,
    ) -> tuple[Distances, set[float]]:
        """Candidate travel distances of the manipulator (see the module docstring), each with
        the travel of the part it is meant for (``None`` for a push to the wall, a squeeze or a
        push cut short), and the distances among them that jam the part on an obstacle.
        ``front`` is the signed coordinate of the manipulator's front at the start;
        ``detour``: a sideways travel round an obstacle
        (:meth:`~arrange_up.planning.generators.detours.Detours.detours`); ``away``: the push
        moves the part away from its goal, so only the detour is offered; ``fence``: what the
        fences say of these pushes (:meth:`~arrange_up.planning.fences.Fences.ahead`)."""
        size = self.problem.table.size[axis]
        direction = DIRECTION_OF[(axis, sign)]
        wall = WALL_AHEAD[direction]
        nominal = self.checker.shadow_box(name, interval.center, (0.0, 0.0, 0.0))
        rear = sign * (nominal[axis] if sign > 0 else nominal[axis + 2])
        gap = rear - front  # nominal free travel before contact
        stall = self.stall.stall(name, belief, axis, sign) if self.stall.per_area else 0.0
        if away:  # only the detour (the pushes do not ask for an away push without one)
            return self.detours.cut_short(
                name, interval, axis, sign, front, gap, [(gap + detour + stall, detour)]
            )
        candidates = []
        train = self.trains.get((name, direction), ())
        if (
            wall in self.problem.table.walls
            and train is not None
            and all(q in belief for q in train)
            and not (
                self.compliant
                and not self.options.settled_wall_pushes
                and self.targets.settled((name, *train), belief, axis)
            )
        ):
            boundary = size if sign > 0 else 0.0
            candidates.append(
                self.stall.stop_front(sign * boundary, (name, *train), belief, axis) - front
            )
        # A fence (a fixture on the table at the part's goal face) is pushed against as the
        # wall is; where a fence is needed and one is there or can be put down, the pushes
        # that end in the open along this axis are not offered: by the problem's own noise
        # they cannot stop the part within its tolerance (planning.fences).
        target = self.targets.place_target(name, belief)
        fenced, levelling = fence.fenced, None
        # pushes meant to press the part against something fixed: not cut short (cut_short)
        squeezes: set[float] = set()
        if fence.face is not None and not (
            self.compliant
            and not self.options.settled_wall_pushes
            and target is not None
            and self.targets.inside_goal(interval, target, axis)
        ):
            candidates.append(
                self.stall.stop_front(sign * fence.face, (name,), belief, axis) - front
            )
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
            elif not self.targets.inside_goal(interval, target, axis) and travel + half > MIN_PUSH:
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
                mating = self.mating.pushes(name, interval, belief, target, axis, sign)
                for d, part_travel in mating:
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
                press = self.stall.stop_front(sign * boundary, (name,), belief, axis) - front
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
        result: Distances = []
        for d in sorted(travels):
            if d > least.get(d, gap) + MIN_PUSH and all(
                abs(d - r) > DISTANCE_RESOLUTION for r, _ in result
            ):
                result.append((d, travels[d]))
        if self.obstacles:
            return self.detours.cut_short(name, interval, axis, sign, front, gap, result, squeezes)
        return result, set()

    def _squeeze_face(
        self, name: str, interval: ObjectInterval, belief: IntervalBelief, axis: int, sign: int
    ) -> float | None:
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
