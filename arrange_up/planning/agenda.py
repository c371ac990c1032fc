"""The goal agenda: a plan built one part (or a small group of parts) at a time.

A best-first search over the whole goal pays for the parts' interleavings: its cost grows
exponentially with the length of a row, because every belief with the same count of parts in
tolerance looks alike to the heuristic. A part whose goal is pressed against walls and parts
already finished, though, is one short search away: placed beside them and pushed against
them, its pose is certain. The agenda therefore

1. **orders the parts from the goal's geometry** (:func:`goal_order`): greedily, the next part
   is the one whose goal touches the most directions of support (walls, obstacles and fixtures
   standing on the table, and the parts already ordered), ties broken by more contacts, then by
   the distance of its goal from the anchor (the corner of two walls nearest the goal, else the
   nearest point of a support, else the goal's centre), then by the goal's own order. A part
   goes in after what it is pressed against, and a row is built from its wall outwards;
2. **searches one subgoal at a time** (:func:`plan_by_agenda`): subgoal k is the goal
   restricted to the first k parts of the order (the finished parts are held to their goal by
   the goal test; the parts still to come need not be on the table), searched from the belief
   the previous subgoal's plan reached, with a node budget of :func:`subgoal_budget` per part;
3. **backtracks** when a subgoal fails (no plan within its budget, or none at all): the part
   is searched together with the next one (a group of two), else the previous subgoal is
   searched again together with it, from the belief before it; groups stay within
   :data:`MAX_GROUP` parts. The plan is the concatenation of the subgoals' plans.

Nothing solvable by the full search is lost: where the agenda fails (a subgoal fails whatever
the grouping, or the agenda has spent the run's node limit), the full search runs with the
whole node limit in the time left. :class:`AgendaRecord` says which of them found the plan.

The agenda applies to absolute goals of two or more parts. A relative goal (its parts hold
their goal only with respect to a reference that may end anywhere) of at least
:data:`MIN_GROUNDED` parts, the reference included, on a table with a corner of two walls, is
first *grounded* (:func:`grounded`): the whole outline, in its own orientation (the reference
turned to 0), is put flush into a corner of two walls, the corner that then lies nearest the
reference, and that absolute goal is built part by part as above (the walls hold the reference
while its mates are pressed against it). The relative goal itself is then a last subgoal,
searched from the belief the grounded agenda reached: where every particle already holds it,
that search ends at once with no action. Where the grounded agenda fails, the full search
runs on the relative goal. A relative goal that is not grounded (fewer parts, no corner of two
walls, or no corner the outline fits in clear of the obstacles and fixtures) is searched whole.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import shapely
from shapely.affinity import translate
from shapely.geometry import Point, box
from shapely.geometry.base import BaseGeometry

from arrange_up.geometry.boxes import wall_boxes
from arrange_up.geometry.se2 import compose
from arrange_up.geometry.shapes import footprint
from arrange_up.model.problem import ArrangementProblem, Goal, ObjectKind, Pose
from arrange_up.planning.config import ProgressCallback
from arrange_up.search import SearchStatus

if TYPE_CHECKING:
    from arrange_up.planning.planner import PlanResult

__all__ = [
    "CONTACT_GAP",
    "MAX_GROUP",
    "MIN_GROUNDED",
    "MIN_SUBGOAL_NODES",
    "AgendaRecord",
    "SubSearch",
    "goal_order",
    "grounded",
    "parts_label",
    "plan_by_agenda",
    "restricted",
    "subgoal_budget",
]

#: Goal footprints closer than this (in) touch: goals are written flush, up to rounding.
CONTACT_GAP = 0.05
#: A contact shorter than this (in) is a corner meeting, which presses nothing.
MIN_CONTACT = 0.2
#: The fewest parts (the reference included) of a relative goal the agenda grounds in a corner.
MIN_GROUNDED = 3
#: The most parts one subgoal adds (a part, merged with its successor or its predecessor).
MAX_GROUP = 3
#: The fewest nodes a subgoal's search may expand per part it adds.
MIN_SUBGOAL_NODES = 50

#: The statuses that end the agenda and skip the full search: no time is left, the caller
#: asked to stop, or the problem is proven unsolvable.
_FINAL = frozenset({SearchStatus.TIMEOUT, SearchStatus.CANCELLED, SearchStatus.UNSOLVABLE})

#: One search of the planner: ``(problem, start, max_nodes, timeout, progress)`` to a
#: :class:`~arrange_up.planning.planner.PlanResult`; ``start`` None is the problem's initial
#: belief, ``timeout`` None no time limit.
SubSearch = Callable[
    [ArrangementProblem, Any, int, "float | None", ProgressCallback | None], "PlanResult"
]


@dataclass(frozen=True)
class AgendaRecord:
    """What the agenda did in one planning run.

    ``order``: the parts in the agenda's order; ``subgoals``: the parts each subgoal added, in
    the plan's order, when the agenda found the plan (else those it had finished when it
    failed); ``solved_by``: ``"agenda"`` or ``"full search"``, None when neither found a plan;
    ``expanded``: the nodes the agenda's searches expanded (the full search's come on top);
    ``failed_at``: the parts the agenda was adding when it gave up (None if it did not);
    ``grounded``: for a relative goal the agenda grounded (:func:`grounded`), the pose it gave
    the reference, in inches and radians (None for an absolute goal).
    """

    order: tuple[str, ...]
    subgoals: tuple[tuple[str, ...], ...]
    solved_by: str | None
    expanded: int
    failed_at: tuple[str, ...] | None = None
    grounded: Pose | None = None

    def line(self) -> str:
        """One line for the command line: which search found the plan, or where the agenda
        stopped."""
        n = len(self.subgoals)
        corner = "grounded in a corner; " if self.grounded is not None else ""
        if self.solved_by == "agenda":
            return (
                f"solved by the agenda ({corner}{n} subgoal{'s' if n != 1 else ''}: "
                f"{' '.join('+'.join(group) for group in self.subgoals)})"
            )
        done = sum(len(group) for group in self.subgoals)
        where = (
            f"the agenda failed at {parts_label(done, len(self.failed_at), len(self.order))} "
            f"({'+'.join(self.failed_at)}) after {self.expanded} nodes"
            if self.failed_at
            else f"the grounded agenda's plan missed the relative goal after {self.expanded} nodes"
            if self.grounded is not None and done == len(self.order)
            else f"the agenda stopped at part {done + 1} of {len(self.order)}"
        )
        if self.solved_by == "full search":
            return f"solved by the full search ({where})"
        return where

    def to_json(self) -> dict[str, Any]:
        """The record as plan files store it (``agenda``)."""
        return {
            "order": list(self.order),
            "subgoals": [list(group) for group in self.subgoals],
            "solved_by": self.solved_by,
            "expanded": self.expanded,
            "failed_at": None if self.failed_at is None else list(self.failed_at),
            "grounded": self.grounded is not None,
        }


def parts_label(before: int, count: int, total: int) -> str:
    """The parts a subgoal adds, counted in the agenda's order: ``"part 3 of 13"`` for one
    part after ``before`` finished ones, ``"parts 1-3 of 13"`` for a group of ``count``."""
    if count == 1:
        return f"part {before + 1} of {total}"
    return f"parts {before + 1}-{before + count} of {total}"


def subgoal_budget(max_nodes: int, parts: int) -> int:
    """The nodes a subgoal's search may expand per part it adds: an equal share of the run's
    node limit, at least :data:`MIN_SUBGOAL_NODES`."""
    return max(MIN_SUBGOAL_NODES, max_nodes // max(parts, 1))


def restricted(problem: ArrangementProblem, parts: tuple[str, ...]) -> ArrangementProblem:
    """``problem`` with its goal restricted to ``parts`` (same tolerance, absolute targets)."""
    keep = set(parts)
    goal = problem.goal
    targets = tuple((name, pose) for name, pose in goal.targets if name in keep)
    return dataclasses.replace(problem, goal=Goal(targets, goal.tolerance, goal.reference))


# -- grounding a relative goal ---------------------------------------------------------------
def grounded(problem: ArrangementProblem) -> ArrangementProblem | None:
    """``problem`` with its relative goal made absolute in a corner of two walls (module
    docstring), or None where the goal is absolute, has fewer than :data:`MIN_GROUNDED` parts
    (the reference included), or no corner of two walls holds the outline (its footprints with
    the reference at the origin, turned to 0) inside the table and clear of the obstacles and
    fixtures standing on it. The tolerance is the goal's."""
    goal = problem.goal
    reference = goal.reference
    if reference is None or len(goal.parts) + 1 < MIN_GROUNDED:
        return None
    outline = [(reference, (0.0, 0.0, 0.0)), *goal.targets]
    shapes = [footprint(problem.object(name).shape.parts, pose) for name, pose in outline]
    x0, y0, x1, y1 = shapely.union_all(shapes).bounds
    width, depth = problem.table.size
    standing = _standing(problem)
    walls = set(problem.table.walls)
    if x1 - x0 > width or y1 - y0 > depth:
        return None
    best: tuple[float, Pose] | None = None
    for side, end in (("left", "bottom"), ("right", "bottom"), ("left", "top"), ("right", "top")):
        if side not in walls or end not in walls:
            continue
        dx = -x0 if side == "left" else width - x1
        dy = -y0 if end == "bottom" else depth - y1
        if any(
            translate(shape, dx, dy).intersection(f).area > 1e-9
            for shape in shapes
            for f in standing
        ):
            continue
        corner = Point(0.0 if side == "left" else width, 0.0 if end == "bottom" else depth)
        distance = corner.distance(Point(dx, dy))
        if best is None or distance < best[0] - 1e-9:
            best = (distance, (dx, dy, 0.0))
    if best is None:
        return None
    origin = best[1]
    targets = tuple((name, compose(origin, pose)) for name, pose in outline)
    return dataclasses.replace(problem, goal=Goal(targets, goal.tolerance, None))


# -- the order -------------------------------------------------------------------------------
def goal_order(problem: ArrangementProblem) -> tuple[str, ...] | None:
    """The goal parts in the agenda's order (module docstring), or None where the agenda does
    not apply (a relative goal, or fewer than two parts)."""
    goal = problem.goal
    if goal.is_relative or len(goal.parts) < 2:
        return None
    shapes = {
        name: footprint(problem.object(name).shape.parts, goal.target(name)) for name in goal.parts
    }
    supports = _fixed_supports(problem)
    anchor = _anchor(problem, supports, shapes)
    distance = {name: shapes[name].centroid.distance(anchor) for name in goal.parts}
    rank = {name: k for k, name in enumerate(goal.parts)}
    fixed = {name: _sides(shape, supports) for name, shape in shapes.items()}
    order: list[str] = []
    left = list(goal.parts)

    def key(name: str) -> tuple[int, int, float, int]:
        sides = fixed[name] + _sides(shapes[name], [shapes[done] for done in order])
        return (-len(set(sides)), -len(sides), distance[name], rank[name])

    while left:
        best = min(left, key=key)
        order.append(best)
        left.remove(best)
    return tuple(order)


def _sides(shape: BaseGeometry, others: list[BaseGeometry]) -> list[int]:
    """The sides on which ``others`` press ``shape`` (:func:`_direction`), one per contact."""
    sides = (_direction(shape, other) for other in others)
    return [side for side in sides if side is not None]


def _fixed_supports(problem: ArrangementProblem) -> list[BaseGeometry]:
    """What a part can be pressed against before any part is placed: the walls, and the
    obstacles and fixtures standing on the table at the start (at their initial poses)."""
    walls = wall_boxes(problem.table.size, problem.table.walls).values()
    return [box(*bounds) for bounds in walls] + _standing(problem)


def _standing(problem: ArrangementProblem) -> list[BaseGeometry]:
    """The footprints of the obstacles and fixtures standing on the table at the start."""
    standing = []
    for spec in problem.objects:
        if spec.kind in (ObjectKind.OBSTACLE, ObjectKind.FIXTURE):
            initial = problem.initial_of(spec.name)
            if initial is not None:
                standing.append(footprint(spec.shape.parts, initial.pose))
    return standing


def _anchor(
    problem: ArrangementProblem, supports: list[BaseGeometry], shapes: dict[str, BaseGeometry]
) -> Point:
    """Where the agenda starts building: the corner of two walls nearest the goal's centre,
    else the nearest point of a support, else the goal's centre."""
    xs = [shape.centroid.x for shape in shapes.values()]
    ys = [shape.centroid.y for shape in shapes.values()]
    centre = Point(sum(xs) / len(xs), sum(ys) / len(ys))
    width, depth = problem.table.size
    walls = set(problem.table.walls)
    corners = [
        Point(x, y)
        for (side, x) in (("left", 0.0), ("right", width))
        for (end, y) in (("bottom", 0.0), ("top", depth))
        if side in walls and end in walls
    ]
    if corners:
        return min(corners, key=centre.distance)
    if supports:
        nearest = min(supports, key=centre.distance)
        return nearest.exterior.interpolate(nearest.exterior.project(centre))
    return centre


def _direction(shape: BaseGeometry, other: BaseGeometry) -> int | None:
    """The side (0: +x, 1: +y, 2: -x, 3: -y) on which ``other`` presses ``shape``, or None
    when they do not touch along a face (farther apart than :data:`CONTACT_GAP`, or meeting
    at a corner only)."""
    if shape.distance(other) > CONTACT_GAP:
        return None
    region = shape.buffer(CONTACT_GAP).intersection(other.buffer(CONTACT_GAP))
    x0, y0, x1, y1 = region.bounds
    if max(x1 - x0, y1 - y0) < MIN_CONTACT + 2 * CONTACT_GAP:
        return None
    dx = region.centroid.x - shape.centroid.x
    dy = region.centroid.y - shape.centroid.y
    return round(math.atan2(dy, dx) / (0.5 * math.pi)) % 4


# -- the search ------------------------------------------------------------------------------
def plan_by_agenda(
    problem: ArrangementProblem,
    search: SubSearch,
    *,
    start: Any,
    max_nodes: int,
    timeout: float | None,
    progress: ProgressCallback | None,
) -> PlanResult:
    """Plan for ``problem`` by the goal agenda, else by the full search (module docstring).

    ``search`` runs one search (:data:`SubSearch`); ``start`` is the belief to plan from (None:
    the problem's initial belief); ``max_nodes`` the run's node limit, which the agenda's
    searches share and the full search gets whole; ``timeout`` the seconds for all of them.
    ``progress`` receives each search's statistics with ``stage``: ``"part k of N (P)"``
    while the agenda adds part P as the k-th of N (``"parts j-k of N (P+Q)"`` for a group,
    :func:`parts_label`), ``"the relative goal"`` for the last search of a grounded relative
    goal, ``"full search"`` after the agenda failed.

    The result's statistics add up every search of the run (``max_nodes`` is the run's limit);
    :attr:`~arrange_up.planning.planner.PlanResult.agenda` records the agenda. When the agenda
    finds the plan, ``beliefs`` run through its subgoals' plans.
    """
    grounding = grounded(problem)
    absolute = grounding or problem  # the goal built part by part
    order = goal_order(absolute)
    if order is None:
        return search(problem, start, max_nodes, timeout, progress)
    started = time.monotonic()

    def left() -> float | None:
        return None if timeout is None else max(0.0, timeout - (time.monotonic() - started))

    def staged(stage: str) -> ProgressCallback | None:
        if progress is None:
            return None
        return lambda stats: progress({**stats, "stage": stage})

    per_part = subgoal_budget(max_nodes, len(order))
    done: list[tuple[tuple[str, ...], PlanResult]] = []
    spent: list[PlanResult] = []
    failed: set[tuple[int, int]] = set()  # (parts finished before, parts added) that failed
    position, size = 0, 1
    expanded = 0
    while position < len(order):
        group = order[position : position + size]
        nodes = min(size * per_part, max_nodes - expanded)
        if nodes <= 0:
            break
        belief = done[-1][1].beliefs[-1] if done else start  # type: ignore[index]  # solved
        stage = f"{parts_label(position, size, len(order))} ({'+'.join(group)})"
        result = search(
            restricted(absolute, order[: position + size]), belief, nodes, left(), staged(stage)
        )
        spent.append(result)
        expanded += result.statistics.expanded
        if result.solved:
            done.append((group, result))
            position, size = position + size, 1
            continue
        if result.status in _FINAL:
            record = _record(order, done, None, expanded, group)
            return _with_spent(result, spent, record, max_nodes)
        failed.add((position, size))
        retry = _regroup(position, size, done, failed, len(order))
        if retry is None:
            break
        position, size = retry
        while sum(len(group) for group, _ in done) > position:
            done.pop()  # backtracking: the previous subgoal is searched again
    else:
        if grounding is None:
            return _joined(done, spent, _record(order, done, "agenda", expanded, None), max_nodes)
        # the relative goal itself, from the belief the grounded agenda reached
        nodes = max(0, min(per_part, max_nodes - expanded))
        belief = done[-1][1].beliefs[-1]  # type: ignore[index]  # solved
        result = search(problem, belief, nodes, left(), staged("the relative goal"))
        spent.append(result)
        expanded += result.statistics.expanded
        if result.solved:
            done.append(((), result))
            record = _record(order, done, "agenda", expanded, None, grounding)
            return _joined(done, spent, record, max_nodes)
        if result.status in _FINAL:
            record = _record(order, done, None, expanded, None, grounding)
            return _with_spent(result, spent, record, max_nodes)
        position, size = len(order), 0
    failed_at = order[position : position + size] or None  # None: at the relative goal
    full = search(problem, start, max_nodes, left(), staged("full search"))
    solved_by = "full search" if full.solved else None
    record = _record(order, done, solved_by, expanded, failed_at, grounding)
    return _with_spent(full, spent, record, max_nodes)


def _regroup(
    position: int,
    size: int,
    done: list[tuple[tuple[str, ...], PlanResult]],
    failed: set[tuple[int, int]],
    parts: int,
) -> tuple[int, int] | None:
    """The next attempt after adding ``size`` parts at ``position`` failed: the same parts and
    the next one, else the previous subgoal's parts and these, from before it; None when both
    were tried or exceed :data:`MAX_GROUP`."""
    if size < MAX_GROUP and position + size < parts and (position, size + 1) not in failed:
        return position, size + 1
    if done:
        previous = len(done[-1][0])
        if previous + size <= MAX_GROUP and (position - previous, previous + size) not in failed:
            return position - previous, previous + size
    return None


def _record(
    order: tuple[str, ...],
    done: list[tuple[tuple[str, ...], PlanResult]],
    solved_by: str | None,
    expanded: int,
    failed_at: tuple[str, ...] | None,
    grounding: ArrangementProblem | None = None,
) -> AgendaRecord:
    """The record of a run whose finished subgoals are ``done`` (the relative goal's last
    search adds no parts, and is no subgoal); ``grounding`` the grounded goal the agenda
    built (:func:`grounded`), None for an absolute goal."""
    reference = None if grounding is None else grounding.goal.target(grounding.goal.parts[0])
    subgoals = tuple(group for group, _ in done if group)
    return AgendaRecord(order, subgoals, solved_by, expanded, failed_at, reference)


def _with_spent(
    result: PlanResult, spent: list[PlanResult], record: AgendaRecord, max_nodes: int
) -> PlanResult:
    """``result`` (the run's last search) with the statistics and refusals of every search of
    the run, and the agenda's record."""
    earlier = spent[:-1] if spent and spent[-1] is result else spent
    return dataclasses.replace(result.after(earlier, max_nodes), agenda=record)


def _joined(
    done: list[tuple[tuple[str, ...], PlanResult]],
    spent: list[PlanResult],
    record: AgendaRecord,
    max_nodes: int,
) -> PlanResult:
    """The agenda's plan: its subgoals' plans and beliefs one after the other, with the
    statistics and refusals of every search it ran."""
    results = [result for _, result in done]
    actions = tuple(action for result in results for action in result.actions or ())
    beliefs = (results[0].beliefs or ())[:1] + tuple(
        belief for result in results for belief in (result.beliefs or ())[1:]
    )
    joined = dataclasses.replace(results[-1], actions=actions, beliefs=beliefs)
    return _with_spent(joined, [*spent[:-1], joined], record, max_nodes)
