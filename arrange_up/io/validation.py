"""Semantic checks shared by the problem readers (YAML and PDDL).

A file can be well formed and still describe an impossible start: objects that overlap or
hang off the table. The readers find those facts here, once, and report each in their own
words and at their own positions in the file (the YAML reader quotes values in the file's
units and points at the YAML node; the PDDL reader speaks inches and points at the object's
``(x ...)`` fact).

:func:`check_placement` says, for each object placed at its nominal pose, whether its footprint
lies outside the table and which objects placed before it it overlaps, and by how much;
:func:`part_overlaps` which convex parts of one shape overlap (they may only touch);
:func:`goal_outside` whether a goal pose can be met on the table; :func:`goal_overlaps` which
parts overlap at their goal poses; :func:`unsampleable` whether
collision-free initial states can be drawn from the initial uncertainty at all.

Plausibility bounds on numbers that are valid but meaningless are here too
(:data:`MAX_ANGLE`, :data:`MAX_FRICTION`), so both readers and the plan file reader use the same.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import shapely
from shapely import STRtree

from arrange_up.geometry import shapes as geometry
from arrange_up.geometry.se2 import transform_points
from arrange_up.model.problem import (
    ArrangementProblem,
    ConvexPolygon,
    InitialObject,
    Pose,
    Shape,
)
from arrange_up.model.units import ANGLE_UNITS

__all__ = [
    "AREA_TOLERANCE",
    "BOUNDS_TOLERANCE",
    "MAX_ANGLE",
    "MAX_FRICTION",
    "MAX_LISTED_OVERLAPS",
    "SAMPLE_DRAWS",
    "Placed",
    "PlacementCheck",
    "angle_problem",
    "check_placement",
    "goal_outside",
    "goal_overlaps",
    "part_overlaps",
    "unsampleable",
]

#: Overlap area (square inches) above which two shapes count as overlapping; touching is fine.
AREA_TOLERANCE = 1e-9
#: How far (inches) a footprint may stick out of the table and still count as inside.
BOUNDS_TOLERANCE = 1e-9

#: Largest angle magnitude (radians) accepted anywhere. Beyond it a double no longer resolves
#: the angle to 1e-9 rad (its spacing there is 2**-28 rad), so the angle means nothing: 1e300
#: degrees is refused rather than silently turned into some arbitrary orientation.
MAX_ANGLE = 2.0**24
#: Friction coefficients above this are warned about: real table-top materials stay below ~1.5
#: (rubber on rubber), and far higher values make every push stick.
MAX_FRICTION = 10.0
#: Overlapping pairs (of objects, or of a shape's convex parts) a reader lists one by one; it
#: says that there are more beyond them (a thousand objects stacked at one pose make half a
#: million pairs, which are neither worth computing nor reading).
MAX_LISTED_OVERLAPS = 100
#: Most objects (parts, manipulators, fixtures and obstacles together) a problem may declare.
#: A real tabletop problem has 10-20 parts; sampling the initial particles tests every pair of
#: footprints, so the work grows with the square of the count, and does not look at the
#: planner's timeout: 10,000 parts kept ``plan --timeout`` waiting far past it. A count beyond
#: this is refused when the file is read.
MAX_OBJECTS = 200
#: How far from the table an action's pose may be, and how wide an initial position spread,
#: in table sizes (the larger of its width and depth): :func:`pose_reach`. Pushes start just
#: off an edge and places stay on it; a pose thousands of tables away means nothing, a spread
#: wider than the table says no more than one as wide as it, and far enough out (1e300) a
#: part's outline collapses to no area in double precision.
MAX_POSE_REACH = 100
#: Why a spread beyond :func:`pose_reach` is refused, as the readers' messages say it.
WIDE_SPREAD = "a spread wider than the table says no more than one as wide as it"
#: Draws :func:`unsampleable` makes: the particle sampler gives up on a particle after as many.
SAMPLE_DRAWS = 1000

Bounds = tuple[float, float, float, float]


def pose_reach(table_size: Sequence[float]) -> float:
    """:data:`MAX_POSE_REACH` table sizes, in the table's units (inches inside the planner):
    the farthest a pose may lie beyond the table, the widest an initial position spread."""
    return MAX_POSE_REACH * max(table_size)


def too_many_objects(count: int) -> str | None:
    """The message refusing a problem that declares ``count`` objects, or ``None`` when that
    is at most :data:`MAX_OBJECTS`; shared by the YAML and PDDL readers."""
    if count <= MAX_OBJECTS:
        return None
    return (
        f"the problem declares {count} objects; expected at most {MAX_OBJECTS} (parts, "
        "manipulators, fixtures and obstacles together; a tabletop problem has tens)"
    )


@dataclass(frozen=True)
class Placed:
    """An object's shape at its nominal pose (inches, radians)."""

    name: str
    shape: Shape
    pose: Pose


@dataclass(frozen=True)
class PlacementCheck:
    """What :func:`check_placement` found about one placed object.

    ``outside`` is the footprint's bounds ``(xmin, ymin, xmax, ymax)`` (inches) when the
    footprint lies outside the table, else ``None``. ``overlaps`` lists ``(index, area)`` for
    every object placed *before* this one (``index`` into the sequence given to
    :func:`check_placement`) whose footprint it overlaps by more than :data:`AREA_TOLERANCE`
    square inches, in that sequence's order.
    """

    name: str
    outside: Bounds | None
    overlaps: tuple[tuple[int, float], ...]

    @property
    def ok(self) -> bool:
        return self.outside is None and not self.overlaps


def check_placement(
    placed: Sequence[Placed],
    table_size: tuple[float, float] | None,
    *,
    max_overlaps: int | None = None,
) -> list[PlacementCheck]:
    """One :class:`PlacementCheck` per object of ``placed``, in order.

    The table is ``[0, width] x [0, depth]`` for ``table_size = (width, depth)`` (inches); a
    footprint may stick out by :data:`BOUNDS_TOLERANCE`. ``table_size=None`` (a table that could
    not be read) skips the table check. Each pair of objects is checked once, the later one
    reporting the overlap with the earlier. With ``max_overlaps``, only the first that many
    overlapping pairs (by later object, then earlier) are found and the rest are not looked for.
    """
    footprints = [_footprint(item.shape, item.pose) for item in placed]
    overlapping = _overlapping(footprints, limit=max_overlaps)
    checks = []
    for j, (item, footprint) in enumerate(zip(placed, footprints, strict=True)):
        outside: Bounds | None = None
        if table_size is not None:
            width, depth = table_size
            xmin, ymin, xmax, ymax = footprint.bounds
            tol = BOUNDS_TOLERANCE
            if xmin < -tol or ymin < -tol or xmax > width + tol or ymax > depth + tol:
                outside = (xmin, ymin, xmax, ymax)
        checks.append(PlacementCheck(item.name, outside, tuple(overlapping.get(j, ()))))
    return checks


def _overlapping(
    footprints: Sequence[Any], *, earlier_first: bool = False, limit: int | None = None
) -> dict[int, list[tuple[int, float]]]:
    """``j -> [(i, area), ...]`` for the pairs ``i < j`` of ``footprints`` that overlap by more
    than :data:`AREA_TOLERANCE`, ``i`` ascending; ``area`` is that of ``footprints[j]``
    intersected with ``footprints[i]`` (``footprints[i]`` with ``footprints[j]`` when
    ``earlier_first``: the operand order of the area's last bits). With ``limit``, only the
    first ``limit`` pairs in ``(j, i)`` order.

    Only pairs whose bounding boxes meet are intersected (a shapely STRtree finds them), so
    many objects spread over a table cost about one intersection each, not one per pair; with
    ``limit``, in chunks until enough are found (a stack of objects at one pose has a pair for
    every two of them).
    """
    if len(footprints) < 2:
        return {}
    geoms = np.asarray(footprints, dtype=object)
    later, earlier = STRtree(geoms).query(geoms)
    keep = earlier < later
    later, earlier = later[keep], earlier[keep]
    order = np.lexsort((earlier, later))
    later, earlier = later[order], earlier[order]
    first, second = (earlier, later) if earlier_first else (later, earlier)
    found: dict[int, list[tuple[int, float]]] = {}
    count = 0
    for start in range(0, len(later), _CHUNK if limit is not None else max(1, len(later))):
        chunk = slice(start, start + _CHUNK) if limit is not None else slice(None)
        areas = shapely.area(shapely.intersection(geoms[first[chunk]], geoms[second[chunk]]))
        pairs = zip(later[chunk].tolist(), earlier[chunk].tolist(), areas.tolist(), strict=True)
        for j, i, area in pairs:
            if area > AREA_TOLERANCE:
                if limit is not None and count == limit:
                    return found
                found.setdefault(j, []).append((i, area))
                count += 1
    return found


#: Candidate pairs intersected at a time when only the first few overlaps are wanted.
_CHUNK = 4096


def part_overlaps(
    parts: Sequence[ConvexPolygon], *, max_overlaps: int | None = None
) -> list[tuple[int, int, float]]:
    """``(i, j, area)`` for every pair of convex parts ``i < j`` (indices into ``parts``, in the
    shape's frame) that overlap by more than :data:`AREA_TOLERANCE` square inches, ordered by
    ``j`` then ``i``; with ``max_overlaps``, only the first that many."""
    origin = (0.0, 0.0, 0.0)
    footprints = [geometry.footprint((part,), origin) for part in parts]
    overlapping = _overlapping(footprints, earlier_first=True, limit=max_overlaps)
    return [(i, j, area) for j, pairs in sorted(overlapping.items()) for i, area in pairs]


def angle_problem(value: float, unit: str = "rad") -> str | None:
    """Why the angle ``value`` (radians) is refused, or ``None`` when it is usable.

    The message states the limit in ``unit`` (a key of :data:`~arrange_up.model.units.ANGLE_UNITS`):
    the unit the angle was written in, which the caller's message quotes the angle in.
    """
    if math.isfinite(value) and abs(value) <= MAX_ANGLE:
        return None
    # One unit in a message: "1e+300 deg ... at most 1.67772e+07 rad" reads as a wrong bound.
    limit = MAX_ANGLE / ANGLE_UNITS[unit]
    return (
        f"expected an angle of magnitude at most {limit:g} {unit} (beyond it a double cannot "
        "resolve the orientation; give the angle modulo a full turn)"
    )


#: The share of a goal's x or y tolerance a part may overhang the table at its target pose before
#: :func:`goal_outside` says it sticks out.
OVERHANG_SHARE = 0.1


def goal_outside(
    shape: Shape, pose: Pose, tolerance: tuple[float, float], table_size: tuple[float, float]
) -> tuple[str, Bounds] | None:
    """Whether a part can meet an absolute goal ``pose`` (inches, radians) on the table.

    ``("unreachable", bounds)`` when the centroid cannot be on the table within the x/y
    ``tolerance`` (a part on the table has its centroid in the convex hull of its footprint,
    hence on the table); ``("sticks out", bounds)`` when the footprint at the target pose
    reaches beyond the table by more than :data:`OVERHANG_SHARE` of the tolerance (the goal may
    still be met by a pose within the tolerance); ``None`` otherwise. ``bounds`` is the
    footprint's
    ``(xmin, ymin, xmax, ymax)`` at the target pose.
    """
    width, depth = table_size
    x, y, _ = pose
    dx, dy = tolerance
    footprint = geometry.footprint(shape.parts, pose).bounds
    if x + dx < 0 or y + dy < 0 or x - dx > width or y - dy > depth:
        return "unreachable", footprint
    xmin, ymin, xmax, ymax = footprint
    # An overhang smaller than a tenth of the tolerance is the rounding of a decimal pose
    # against a wall (a centroid at 5/6 written 0.83), not a goal off the table.
    tx, ty = (max(BOUNDS_TOLERANCE, OVERHANG_SHARE * d) for d in (dx, dy))
    if xmin < -tx or ymin < -ty or xmax > width + tx or ymax > depth + ty:
        return "sticks out", footprint
    return None


def goal_overlaps(problem: ArrangementProblem) -> list[tuple[str, str, float]]:
    """The pairs of parts whose nominal footprints at their goal poses overlap, as ``(a, b,
    area)`` with ``area`` in square inches above :data:`AREA_TOLERANCE`, in the goal's order.

    For a relative goal the reference part stands at the origin of its own frame, where the
    other parts' targets are given. Such a goal is not impossible (a pose within the tolerance
    may separate the parts), but it is most likely a mistake: no plan reaches the nominal
    arrangement, and a search for one can run long before it says so.
    """
    goal = problem.goal
    entries = list(goal.targets)
    if goal.reference is not None:
        entries.insert(0, (goal.reference, (0.0, 0.0, 0.0)))
    footprints = [(name, _footprint(problem.object(name).shape, pose)) for name, pose in entries]
    found = []
    for i, (a, fa) in enumerate(footprints):
        for b, fb in footprints[i + 1 :]:
            if _overlap(fa, fb):
                found.append((a, b, float(fa.intersection(fb).area)))
    return found


def unsampleable(problem: ArrangementProblem, draws: int = SAMPLE_DRAWS) -> bool:
    """True when none of ``draws`` initial states drawn uniformly from the initial intervals is
    free of collisions (objects overlapping each other, an obstacle or a wall by more than
    :data:`AREA_TOLERANCE`, the test of ``CollisionChecker.state_collides``).

    The particle sampler draws the same way and gives up on a particle after
    :data:`SAMPLE_DRAWS` tries, so such a problem cannot be planned for. The draws are seeded
    (the answer depends on the problem only) and stop at the first collision-free state, so a
    problem with a sensible uncertainty costs one collision test. Problems whose nominal
    placement is already refused are not asked about.

    The cost stays near one collision test per draw whatever the shapes and the number of
    objects: footprints are moved copies of each shape's footprint at the origin, objects
    without uncertainty are tested once, pairs are found with an STRtree, and a draw first
    tries the pair that collided in the draw before.
    """
    entries = [entry for entry in problem.initial if any(entry.uncertainty)]
    if not entries:
        return False
    shapes = {spec.name: spec.shape for spec in problem.objects}
    # The fixed geometry of CollisionChecker: obstacles and the walls' boxes.
    fixed = [
        _footprint(spec.shape, spec.pose) for spec in problem.obstacles if spec.pose is not None
    ]
    walls = geometry.wall_boxes(problem.table.size, problem.table.walls)
    fixed += [shapely.box(*wall) for wall in walls.values()]
    still = [_footprint(shapes[e.name], e.pose) for e in problem.initial if not any(e.uncertainty)]
    if _overlapping(still) or _first_overlap(still, fixed) is not None:
        return True  # the objects that never move already collide: so does every draw
    others = np.asarray(still + fixed, dtype=object)
    tree = STRtree(others) if len(others) else None
    witness: tuple[int, int] | None = None  # (moving, moving) or (moving, -1 - other)
    index = {entry.name: k for k, entry in enumerate(problem.initial)}
    rng = random.Random(0)
    for _ in range(draws):
        # rng.uniform(-1, 1) for each coordinate of each entry, in order; it is -1 + 2 * random()
        draw = [-1.0 + 2.0 * rng.random() for _ in range(3 * len(index))]

        def footprint(entry: InitialObject, draw: list[float] = draw) -> Any:
            at = 3 * index[entry.name]
            pose = tuple(entry.pose[k] + draw[at + k] * entry.uncertainty[k] for k in range(3))
            return _footprint(shapes[entry.name], pose)  # type: ignore[arg-type]

        if witness is not None:
            i, j = witness
            other = footprint(entries[j]) if j >= 0 else others[-1 - j]
            if _overlap(footprint(entries[i]), other):
                continue  # this pair collides again: so does the draw
        witness = _collision([footprint(entry) for entry in entries], others, tree)
        if witness is None:
            return False
    return True


def _overlap(a: Any, b: Any) -> bool:
    return bool(a.intersects(b) and a.intersection(b).area > AREA_TOLERANCE)


def _first_overlap(footprints: Sequence[Any], others: Sequence[Any]) -> tuple[int, int] | None:
    """``(i, k)``: a footprint that overlaps one of ``others``, or ``None``."""
    if not footprints or not others:
        return None
    tree = STRtree(np.asarray(others, dtype=object))
    pairs = tree.query(np.asarray(footprints, dtype=object), predicate="intersects")
    for i, k in zip(pairs[0].tolist(), pairs[1].tolist(), strict=True):
        if _overlap(footprints[i], others[k]):
            return i, k
    return None


def _collision(footprints: list[Any], others: Any, tree: STRtree | None) -> tuple[int, int] | None:
    """A colliding pair of one draw: ``(i, j)`` for two moving footprints, ``(i, -1 - k)`` for
    a moving footprint and ``others[k]``; ``None`` when the draw is free of collisions."""
    if tree is not None:
        pairs = tree.query(np.asarray(footprints, dtype=object), predicate="intersects")
        for i, k in zip(pairs[0].tolist(), pairs[1].tolist(), strict=True):
            if _overlap(footprints[i], others[k]):
                return i, -1 - k
    for j, overlaps in _overlapping(footprints).items():
        return j, overlaps[0][0]
    return None


def _footprint(shape: Shape, pose: Pose) -> Any:
    """The region ``shape`` covers at ``pose``: its footprint at the origin (made once per shape,
    :func:`_at_origin`) moved by ``transform_points``, where
    :func:`~arrange_up.geometry.shapes.footprint` unites the moved parts at every pose. The same
    region up to rounding; the same coordinates for one-part shapes."""
    return shapely.transform(_at_origin(shape), lambda points: transform_points(points, pose))


@lru_cache(maxsize=256)
def _at_origin(shape: Shape) -> Any:
    """The footprint of ``shape`` at the origin (the placement and the sampling checks of one
    problem share it)."""
    return geometry.footprint(shape.parts, (0.0, 0.0, 0.0))
