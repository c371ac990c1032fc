"""Pushes round obstacles (:mod:`arrange_up.planning.obstacles`).

* **A detour** (:meth:`Detours.detours`): where the straight push to the part's goal
  coordinate along one axis is blocked (an obstacle's box lies across the part's shadow,
  widened by ``obstacles.GAP``, before the goal), a push along the other axis, to the nearer
  side where the shadow (with the spread a push leaves across it) clears the blocking boxes by
  ``GAP`` and stays on the table, even away from the goal along that axis; not where the
  goal-directed push across already clears them.
* **Cut short** before an obstacle (:meth:`Detours.cut_short`): where one of the push
  distances (but a squeeze) would bring the part's shadow within ``GAP`` of an obstacle ahead
  in its swath, the distance that stops it ``GAP`` short (allowing for the part's depth at its
  angle spread and the approach noise). The pushes that would drive a state of the part into
  the obstacle stay offered only where no detour push of the part fits (a part lying on a wall
  cannot be pushed off it, so running it into a post and round its corner is its only way on).
* **Sweeps** (:meth:`Detours.sweeps`): a paddle whose travel would sweep it into an obstacle
  outside the part's swath is shifted along its long side, as beside walls and shadows, to
  pass it clear (:mod:`~arrange_up.planning.generators.approach`).

None of these rules changes anything on a table without obstacles (every shipped problem).
"""

from __future__ import annotations

from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.geometry.boxes import Box
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem
from arrange_up.planning.generators.common import DIRECTION_OF, DISTANCE_RESOLUTION, MIN_PUSH
from arrange_up.planning.generators.targets import GoalTargets
from arrange_up.planning.obstacles import GAP, Obstacles, far_face

#: Candidate push distances, each with the travel of the part it is meant for (or None).
Distances = list[tuple[float, float | None]]


class Detours:
    """The obstacle rules of one problem's pushes (see the module docstring)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        checker: CollisionChecker,
        obstacles: Obstacles,
        targets: GoalTargets,
    ) -> None:
        self.problem = problem
        self.checker = checker
        self.obstacles = obstacles
        self.targets = targets
        self.push_unc = problem.uncertainty.push

    def detours(
        self, name: str, interval: ObjectInterval, belief: IntervalBelief
    ) -> dict[str, float]:
        """The sideways travels that take ``name`` round the obstacles blocking its straight
        push to its goal coordinate, by direction (module docstring: at most one per blocked
        axis, to the nearer side where its shadow clears them by ``GAP`` and stays on the
        table)."""
        target = self.targets.place_target(name, belief)
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
                detours[DIRECTION_OF[(other, side)]] = t
        return detours

    def cut_short(
        self,
        name: str,
        interval: ObjectInterval,
        axis: int,
        sign: int,
        front: float,
        gap: float,
        result: Distances,
        squeezes: set[float] | frozenset[float] = frozenset(),
    ) -> tuple[Distances, set[float]]:
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

    def sweeps(
        self,
        distances: Distances,
        along: float,
        m_box: Box,
        part_box: Box,
        axis: int,
        sign: int,
    ) -> list[tuple[tuple[Box, ...], Distances]]:
        """``distances`` grouped by the obstacles the paddle's approach shadow would sweep into
        (outside the part's swath) on the way, in order: ``(obstacle boxes, distances)``. With
        no obstacle on the way (every distance of a problem without obstacles) one group."""
        if not self.obstacles:
            return [((), distances)]
        start = (along + m_box[axis], along + m_box[axis + 2])
        rear, front = (start[0], start[1]) if sign > 0 else (-start[1], -start[0])
        other = 1 - axis
        swath = (part_box[other], part_box[other + 2])
        groups: dict[tuple[Box, ...], Distances] = {}
        for d, travel in distances:
            hits = tuple(self.obstacles.swept(rear, front, d, swath, axis, sign))
            groups.setdefault(hits, []).append((d, travel))
        return list(groups.items())
