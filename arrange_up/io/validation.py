"""Semantic checks shared by the problem readers (YAML and PDDL).

A file can be well formed and still describe an impossible start: objects that overlap or
hang off the table. The readers find those facts here, once, and report each in their own
words and at their own positions in the file (the YAML reader quotes values in the file's
units and points at the YAML node; the PDDL reader speaks inches and points at the object's
``(x ...)`` fact).

:func:`check_placement` says, for each object placed at its nominal pose, whether its footprint
lies outside the table and which objects placed before it it overlaps, and by how much;
:func:`part_overlaps` which convex parts of one shape overlap (they may only touch);
:func:`goal_outside` whether a goal pose can be met on the table; :func:`unsampleable` whether
collision-free initial states can be drawn from the initial uncertainty at all.

Plausibility bounds on numbers that are valid but meaningless are here too
(:data:`MAX_ANGLE`, :data:`MAX_FRICTION`), so both readers and the plan file reader use the same.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass

from arrange_up.geometry import shapes as geometry
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import ArrangementProblem, ConvexPolygon, Pose, Shape
from arrange_up.model.world import WorldState

__all__ = [
    "AREA_TOLERANCE",
    "BOUNDS_TOLERANCE",
    "MAX_ANGLE",
    "MAX_FRICTION",
    "SAMPLE_DRAWS",
    "Placed",
    "PlacementCheck",
    "angle_problem",
    "check_placement",
    "goal_outside",
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
#: Draws :func:`unsampleable` makes: the particle sampler gives up on a particle after as many.
SAMPLE_DRAWS = 1000

Bounds = tuple[float, float, float, float]


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
    placed: Sequence[Placed], table_size: tuple[float, float] | None
) -> list[PlacementCheck]:
    """One :class:`PlacementCheck` per object of ``placed``, in order.

    The table is ``[0, width] x [0, depth]`` for ``table_size = (width, depth)`` (inches); a
    footprint may stick out by :data:`BOUNDS_TOLERANCE`. ``table_size=None`` (a table that could
    not be read) skips the table check. Each pair of objects is checked once, the later one
    reporting the overlap with the earlier.
    """
    footprints = [geometry.footprint(item.shape.parts, item.pose) for item in placed]
    checks = []
    for j, (item, footprint) in enumerate(zip(placed, footprints, strict=True)):
        outside: Bounds | None = None
        if table_size is not None:
            width, depth = table_size
            xmin, ymin, xmax, ymax = footprint.bounds
            tol = BOUNDS_TOLERANCE
            if xmin < -tol or ymin < -tol or xmax > width + tol or ymax > depth + tol:
                outside = (xmin, ymin, xmax, ymax)
        overlaps = []
        for i in range(j):
            area = footprint.intersection(footprints[i]).area
            if area > AREA_TOLERANCE:
                overlaps.append((i, area))
        checks.append(PlacementCheck(item.name, outside, tuple(overlaps)))
    return checks


def part_overlaps(parts: Sequence[ConvexPolygon]) -> list[tuple[int, int, float]]:
    """``(i, j, area)`` for every pair of convex parts ``i < j`` (indices into ``parts``, in the
    shape's frame) that overlap by more than :data:`AREA_TOLERANCE` square inches, ordered by
    ``j`` then ``i``."""
    origin = (0.0, 0.0, 0.0)
    found = []
    for j in range(len(parts)):
        for i in range(j):
            a = geometry.footprint((parts[i],), origin)
            b = geometry.footprint((parts[j],), origin)
            area = float(a.intersection(b).area)
            if area > AREA_TOLERANCE:
                found.append((i, j, area))
    return found


def angle_problem(value: float) -> str | None:
    """Why the angle ``value`` (radians) is refused, or ``None`` when it is usable."""
    if math.isfinite(value) and abs(value) <= MAX_ANGLE:
        return None
    return (
        f"expected an angle of magnitude at most {MAX_ANGLE:g} rad (beyond it a double cannot "
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


def unsampleable(problem: ArrangementProblem, draws: int = SAMPLE_DRAWS) -> bool:
    """True when none of ``draws`` initial states drawn uniformly from the initial intervals is
    free of collisions (objects overlapping each other, an obstacle or a wall).

    The particle sampler draws the same way and gives up on a particle after
    :data:`SAMPLE_DRAWS` tries, so such a problem cannot be planned for. The draws are seeded
    (the answer depends on the problem only) and stop at the first collision-free state, so a
    problem with a sensible uncertainty costs one collision test. Problems whose nominal
    placement is already refused are not asked about.
    """
    entries = [entry for entry in problem.initial if any(entry.uncertainty)]
    if not entries:
        return False
    checker = CollisionChecker(problem)
    rng = random.Random(0)
    for _ in range(draws):
        poses = {
            entry.name: tuple(
                entry.pose[k] + rng.uniform(-1.0, 1.0) * entry.uncertainty[k] for k in range(3)
            )
            for entry in problem.initial
        }
        if not checker.state_collides(WorldState.from_mapping(problem, poses)):
            return False
    return True
