"""Axis-aligned boxes ``(xmin, ymin, xmax, ymax)``: bounding boxes, overlap and containment,
sweeps, and the table's walls."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np
import shapely.geometry.base

from arrange_up.geometry.polygons import Polygon, _points_array
from arrange_up.geometry.se2 import Point

Box = tuple[float, float, float, float]
"""``(xmin, ymin, xmax, ymax)``."""

WALL_NAMES: tuple[str, ...] = ("left", "right", "bottom", "top")

__all__ = [
    "WALL_NAMES",
    "Box",
    "box_contains",
    "box_corners",
    "box_of",
    "box_row",
    "boxes_overlap",
    "boxes_union",
    "swept_box",
    "wall_boxes",
]


def box_of(
    geom_or_points: shapely.geometry.base.BaseGeometry
    | np.ndarray
    | Sequence[Point]
    | Sequence[Sequence[Point]],
) -> Box:
    """Bounding box of a shapely geometry, an ``(N, 2)`` point set, or a sequence of polygons.

    Raises ``ValueError`` for empty input.
    """
    if isinstance(geom_or_points, shapely.geometry.base.BaseGeometry):
        if geom_or_points.is_empty:
            raise ValueError("empty geometry has no bounding box")
        xmin, ymin, xmax, ymax = geom_or_points.bounds
        return (float(xmin), float(ymin), float(xmax), float(ymax))
    try:
        p = _points_array(geom_or_points)
    except ValueError:  # ragged: a sequence of polygons (e.g. a shape's parts)
        p = np.concatenate([_points_array(poly) for poly in geom_or_points])
    if p.ndim == 3:  # equal-length polygons stack into (K, M, 2)
        p = p.reshape(-1, 2)
    if len(p) == 0:
        raise ValueError("no points: no bounding box")
    lo, hi = p.min(axis=0), p.max(axis=0)
    return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


def boxes_overlap(a: Box, b: Box, tol: float = 0.0) -> bool:
    """Whether the interiors of ``a`` and ``b`` overlap by more than ``tol`` along both axes.

    Boxes that only touch (shared edge or corner) do not overlap for ``tol >= 0``; a negative
    ``tol`` makes near-misses count as overlapping (a safety margin).
    """
    # min and max written out (the same values: the first argument unless the second is
    # smaller, resp. larger): this is one of a search's most frequent calls
    a0, a1, a2, a3 = a
    b0, b1, b2, b3 = b
    return ((b2 if b2 < a2 else a2) - (b0 if b0 > a0 else a0) > tol) and (
        (b3 if b3 < a3 else a3) - (b1 if b1 > a1 else a1) > tol
    )


def boxes_union(boxes: Iterable[Box]) -> Box:
    """The smallest box holding every box of ``boxes``; ``ValueError`` if there are none."""
    boxes = list(boxes)
    if not boxes:
        raise ValueError("no boxes: no union")
    return (
        min(b[0] for b in boxes),
        min(b[1] for b in boxes),
        max(b[2] for b in boxes),
        max(b[3] for b in boxes),
    )


def box_row(
    boxes: dict[str, Box], first: str, axis: int, sign: int, slack: float
) -> tuple[tuple[str, ...], float]:
    """The row of ``boxes`` that starts at ``first`` and runs along ``axis`` towards ``sign``
    (+1 or -1): each next box overlaps the previous one across the axis and its near face lies
    within ``slack`` of the previous one's far face. Returns the names after ``first``, in order,
    and the signed coordinate (``sign`` times the coordinate) of the last box's far face."""
    other = 1 - axis
    box, row = boxes[first], [first]
    while True:
        front = box[axis + 2] if sign > 0 else -box[axis]
        ahead = [
            q
            for q, b in boxes.items()
            if q not in row
            and min(b[other + 2], box[other + 2]) - max(b[other], box[other]) > 1e-6
            and abs((b[axis] if sign > 0 else -b[axis + 2]) - front) <= slack
        ]
        if not ahead:
            return tuple(row[1:]), front
        row.append(ahead[0])
        box = boxes[ahead[0]]


def box_contains(outer: Box, inner: Box, tol: float = 1e-9) -> bool:
    """Whether ``inner`` lies inside ``outer`` (boundaries may touch), allowing ``tol`` slack."""
    return (
        inner[0] >= outer[0] - tol
        and inner[1] >= outer[1] - tol
        and inner[2] <= outer[2] + tol
        and inner[3] <= outer[3] + tol
    )


def swept_box(box: Box, direction: tuple[float, float], distance: float) -> Box:
    """The region ``box`` covers while translated by ``distance`` along ``direction``.

    ``direction`` must be an axis-aligned unit vector (``(±1, 0)`` or ``(0, ±1)``) and
    ``distance >= 0``; the box grows on the side it moves towards. Raises ``ValueError``
    otherwise.
    """
    ux, uy = direction
    if not distance >= 0.0:
        raise ValueError(f"sweep distance must be non-negative, got {distance}")
    xmin, ymin, xmax, ymax = box
    if (ux, uy) == (1, 0):
        return (xmin, ymin, xmax + distance, ymax)
    if (ux, uy) == (-1, 0):
        return (xmin - distance, ymin, xmax, ymax)
    if (ux, uy) == (0, 1):
        return (xmin, ymin, xmax, ymax + distance)
    if (ux, uy) == (0, -1):
        return (xmin, ymin - distance, xmax, ymax)
    raise ValueError(f"direction must be (+-1, 0) or (0, +-1), got {direction}")


def wall_boxes(
    table_size: tuple[float, float], walls: Iterable[str], thickness: float = 1.0
) -> dict[str, Box]:
    """Boxes of rigid walls just outside the edges of the table ``[0, W] x [0, D]``.

    ``"left"`` is ``[-thickness, 0] x [-thickness, D + thickness]`` (it spans the table's side
    plus both corners, so walls meeting at a corner leave no gap); ``"right"`` is
    ``[W, W + thickness]`` over the same y range; ``"bottom"`` is
    ``[-thickness, W + thickness] x [-thickness, 0]`` and ``"top"`` the same x range over
    ``[D, D + thickness]``. Returned in the order given (duplicates collapse).

    Raises ``ValueError`` for an unknown wall name or a non-positive size or thickness.
    """
    w, d = table_size
    if not (w > 0 and d > 0 and thickness > 0):
        raise ValueError(
            f"table size and wall thickness must be positive: {table_size}, {thickness}"
        )
    t = thickness
    all_walls: dict[str, Box] = {
        "left": (-t, -t, 0.0, d + t),
        "right": (w, -t, w + t, d + t),
        "bottom": (-t, -t, w + t, 0.0),
        "top": (-t, d, w + t, d + t),
    }
    out: dict[str, Box] = {}
    for name in walls:
        if name not in all_walls:
            raise ValueError(f"unknown wall {name!r}; expected one of {', '.join(WALL_NAMES)}")
        out[name] = all_walls[name]
    return out


def box_corners(box: Box) -> Polygon:
    """The corners of ``box``, CCW from ``(xmin, ymin)``."""
    x0, y0, x1, y1 = box
    return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))
