"""Shapes at poses: the region a shape covers (:func:`footprint`) and its reach
(:func:`shape_radius`). A shape is a sequence of convex CCW polygons (its *parts*) in the
object's own frame; a :data:`Pose` places that frame in the world.

This was the whole plane geometry module; its other public names now live in the modules of the
room (:mod:`~arrange_up.geometry.se2`, :mod:`~arrange_up.geometry.polygons`,
:mod:`~arrange_up.geometry.decomposition`, :mod:`~arrange_up.geometry.shadows`,
:mod:`~arrange_up.geometry.boxes`) and are re-exported here, so ``arrange_up.geometry.shapes``
keeps every name it had.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely
import shapely.geometry.base

from arrange_up.geometry.boxes import (
    WALL_NAMES,
    Box,
    box_contains,
    box_corners,
    box_of,
    boxes_overlap,
    swept_box,
    wall_boxes,
)
from arrange_up.geometry.decomposition import decompose_convex
from arrange_up.geometry.polygons import (
    MAX_POLYGON_VERTICES,
    Polygon,
    _points_array,
    box_polygon,
    convex_penetration,
    ensure_ccw,
    is_convex,
    parts_centroid,
    polygon_centroid,
    polygon_problem,
    polygon_signed_area,
    translate_polygon,
)
from arrange_up.geometry.se2 import Point, Pose, transform_points
from arrange_up.geometry.shadows import (
    HalfWidths,
    ShapeVertices,
    shadow_box,
    shadow_hull,
    shape_vertices,
)

__all__ = [
    "MAX_POLYGON_VERTICES",
    "Box",
    "HalfWidths",
    "Point",
    "Polygon",
    "Pose",
    "ShapeVertices",
    "WALL_NAMES",
    "box_contains",
    "box_corners",
    "box_of",
    "box_polygon",
    "boxes_overlap",
    "convex_penetration",
    "decompose_convex",
    "ensure_ccw",
    "footprint",
    "is_convex",
    "parts_centroid",
    "polygon_centroid",
    "polygon_problem",
    "polygon_signed_area",
    "shadow_box",
    "shadow_hull",
    "shape_radius",
    "shape_vertices",
    "swept_box",
    "transform_points",
    "translate_polygon",
    "wall_boxes",
]


def footprint(parts: Sequence[Polygon], pose: Pose) -> shapely.geometry.base.BaseGeometry:
    """The region the shape covers at ``pose``: union of its transformed parts.

    A ``shapely`` Polygon for a connected shape (a MultiPolygon if the parts are disconnected).
    """
    if len(parts) == 0:
        raise ValueError("shape has no parts")
    polys = [shapely.Polygon(transform_points(_points_array(part), pose)) for part in parts]
    if len(polys) == 1:
        return polys[0]
    return shapely.union_all(polys)


def shape_radius(parts: Sequence[Sequence[Point]]) -> float:
    """Largest distance of any vertex from the object-frame origin."""
    return max(float(np.max(np.hypot(*_points_array(part).T))) for part in parts)
