"""Wall trains: which goal parts the goal holds against which wall of the table.

A push of a part to the wall ahead is a step towards the goal only when the goal holds the part
against that wall, directly or through a train of touching goal parts (a row or column ending
at the wall), and the whole train ahead of it is already on the table; otherwise the push
carries it (and whatever is ahead) past the targets. The push distances
(:mod:`~arrange_up.planning.generators.distances`) offer a push to the wall only then, and the
fences (:mod:`arrange_up.planning.fences`) are not needed along an axis where such a wall does
the job.
"""

from __future__ import annotations

from arrange_up.geometry.boxes import box_row
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem
from arrange_up.planning.generators.common import DIRECTIONS, WALL_AHEAD

#: ``(part, direction)`` -> the train ahead of the part up to the wall, or None.
WallTrains = dict[tuple[str, str], tuple[str, ...] | None]


def wall_trains(problem: ArrangementProblem, checker: CollisionChecker) -> WallTrains:
    """For each part with an absolute goal and each direction: the train of goal parts that
    holds it against the wall ahead in the goal arrangement (parts touching in a row or column,
    ending at the wall), or None when the goal does not hold it there (empty for a relative
    goal)."""
    goal = problem.goal
    if goal.is_relative:
        return {}
    slack = 2.0 * max(goal.tolerance[0], goal.tolerance[1]) + 1e-6
    boxes = {p: checker.shadow_box(p, goal.target(p), (0.0, 0.0, 0.0)) for p in goal.parts}
    width, depth = problem.table.size
    trains: WallTrains = {}
    for part in goal.parts:
        for direction, (ux, uy) in DIRECTIONS.items():
            axis, sign = (0, int(ux)) if ux else (1, int(uy))
            train, front = box_row(boxes, part, axis, sign, slack)
            wall = (width if axis == 0 else depth) if sign > 0 else 0.0
            held = abs(sign * wall - front) <= slack
            trains[(part, direction)] = train if held else None
    return trains


def held_by_wall(problem: ArrangementProblem, trains: WallTrains) -> dict[tuple[str, int], bool]:
    """``(part, axis)`` -> True where the goal holds ``part`` against a wall the table has
    along ``axis`` (:class:`~arrange_up.planning.fences.Fences`' ``held_by_wall``)."""
    walls = set(problem.table.walls)
    return {
        (part, 0 if DIRECTIONS[direction][0] else 1): True
        for (part, direction), train in trains.items()
        if train is not None and WALL_AHEAD[direction] in walls
    }
