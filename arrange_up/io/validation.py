"""Semantic checks shared by the problem readers (YAML and PDDL).

A file can be well formed and still describe an impossible start: objects that overlap or
hang off the table. The readers find those facts here, once, and report each in their own
words and at their own positions in the file (the YAML reader quotes values in the file's
units and points at the YAML node; the PDDL reader speaks inches and points at the object's
``(x ...)`` fact).

:func:`check_placement` says, for each object placed at its nominal pose, whether its footprint
lies outside the table and which objects placed before it it overlaps, and by how much;
:func:`part_overlaps` which convex parts of one shape overlap (they may only touch).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from arrange_up.geometry import shapes as geometry
from arrange_up.model.problem import ConvexPolygon, Pose, Shape

__all__ = [
    "AREA_TOLERANCE",
    "BOUNDS_TOLERANCE",
    "Placed",
    "PlacementCheck",
    "check_placement",
    "part_overlaps",
]

#: Overlap area (square inches) above which two shapes count as overlapping; touching is fine.
AREA_TOLERANCE = 1e-9
#: How far (inches) a footprint may stick out of the table and still count as inside.
BOUNDS_TOLERANCE = 1e-9

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
