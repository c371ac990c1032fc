"""The shape forms of the problem formats as :class:`~arrange_up.model.problem.Shape` values.

A shape is written as a box (``{box: [w, h]}``), a simple polygon (decomposed into convex
parts) or a list of convex parts. The YAML reader (:mod:`arrange_up.io.yaml_builder`) and the
shape catalogue (:mod:`arrange_up.io.shape_catalogue`) both build their shapes here, so a shape
is the same whichever file it was read from. The callers check their input first and report
problems in their own way; these functions expect valid geometry (inches).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

from arrange_up.geometry import shapes as geometry
from arrange_up.model.problem import ConvexPolygon, Point, Shape

__all__ = ["as_polygon", "box_shape", "ccw_polygon", "centred_shape", "convex_decomposition"]


def as_polygon(poly: Iterable[Any]) -> ConvexPolygon:
    """A polygon as a tuple of ``(x, y)`` float tuples (what :class:`Shape` stores)."""
    return tuple((float(x), float(y)) for x, y in poly)


def box_shape(width: float, height: float, name: str | None = None) -> Shape:
    """A ``width`` x ``height`` box centred on the origin, with ``Shape.box`` set."""
    parts = (as_polygon(geometry.ensure_ccw(geometry.box_polygon(width, height))),)
    return Shape(parts, box=(width, height), name=name)


def ccw_polygon(points: Sequence[Point]) -> ConvexPolygon:
    """A convex part given by its vertices, counter-clockwise."""
    return as_polygon(geometry.ensure_ccw(tuple(points)))


def convex_decomposition(points: Sequence[Point]) -> tuple[ConvexPolygon, ...]:
    """The convex parts (counter-clockwise) of the simple polygon ``points``."""
    return tuple(
        as_polygon(geometry.ensure_ccw(p))
        for p in geometry.decompose_convex(geometry.ensure_ccw(tuple(points)))
    )


def centred_shape(parts: tuple[ConvexPolygon, ...], name: str | None) -> Shape:
    """The shape of ``parts`` shifted so that its area centroid is the origin (a pose refers
    to the centroid)."""
    cx, cy = geometry.parts_centroid(parts)
    shifted = tuple(as_polygon(geometry.translate_polygon(p, -cx, -cy)) for p in parts)
    return Shape(shifted, name=name)
