"""The problem's shapes compiled once for the simulation: cffi vertex arrays of every body's
convex parts, per-unit-density mass integrals (area, moment, ``integral(|r| dA)`` for the
table friction), the walls and obstacles as static polygons in world coordinates, and the
exact penetration depths that a manipulator's landing is tested with."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

# pymunk's cffi binding: the Chipmunk2D C API that pymunk's classes wrap (pymunk ~= 7.3).
from pymunk._chipmunk_cffi import ffi, lib

from arrange_up.geometry.boxes import WALL_NAMES, box_corners, wall_boxes
from arrange_up.geometry.collision import PenetrationDepths
from arrange_up.geometry.se2 import transform_point
from arrange_up.model.problem import ArrangementProblem, ObjectKind, Table


def _abs_r_integral(poly: Sequence[tuple[float, float]]) -> float:
    """``integral(|r| dA)`` over a convex CCW polygon, ``r`` measured from the origin.

    Sum over edges of the signed integral over the triangle (origin, a, b): with ``p`` the
    distance from the origin to the edge's line and ``t`` the coordinate along it,
    ``integral = [p t |r| + p^3 asinh(t / p)] / 6`` between the edge's ends (polar coordinates,
    ``integral sec^3``). Exact for the origin inside or outside the polygon.
    """
    total = 0.0
    n = len(poly)
    for i in range(n):
        ax, ay = poly[i]
        bx, by = poly[(i + 1) % n]
        cross = ax * by - ay * bx
        ex, ey = bx - ax, by - ay
        length = math.hypot(ex, ey)
        if length == 0.0 or cross == 0.0:
            continue
        p = abs(cross) / length
        ex, ey = ex / length, ey / length
        ta, tb = ax * ex + ay * ey, bx * ex + by * ey
        value = (
            p * (tb * math.hypot(bx, by) - ta * math.hypot(ax, ay))
            + p**3 * (math.asinh(tb / p) - math.asinh(ta / p))
        ) / 6.0
        total += math.copysign(value, cross)
    return total


def _poly_area(poly: Sequence[tuple[float, float]]) -> float:
    n = len(poly)
    return 0.5 * sum(
        poly[i][0] * poly[(i + 1) % n][1] - poly[(i + 1) % n][0] * poly[i][1] for i in range(n)
    )


@dataclass(frozen=True)
class _Body:
    """An object's shape, ready to build: cffi vertex arrays and per-unit-density integrals."""

    kind: ObjectKind
    parts: tuple[tuple[int, object], ...]  # (vertex count, cpVect[] array) per convex part
    area: float
    part_moments: tuple[tuple[float, float], ...]  # (area_i, moment of part i per unit mass)
    abs_r: float  # integral(|r| dA) over the shape
    push_direction: tuple[float, float]
    radius: float  # largest distance of a vertex from the centroid (the compliant wrist's lever)


@dataclass(frozen=True)
class _Compiled:
    problem: ArrangementProblem
    bodies: dict[str, _Body]
    statics: tuple[tuple[int, object], ...]  # wall and obstacle polygons in world coordinates
    table: Table
    wall_thickness: float
    parts_area: float  # of all the problem's parts, for the force clip (push_force)
    depths: PenetrationDepths  # exact overlaps of shapes at poses (a paddle's landing)


_IDENTITY = ffi.new("cpTransform *", (1.0, 0.0, 0.0, 1.0, 0.0, 0.0))[0]
_CACHE: dict[int, _Compiled] = {}
_CACHE_SIZE = 16


def _compile(problem: ArrangementProblem, wall_thickness: float) -> _Compiled:
    key = id(problem)
    hit = _CACHE.get(key)
    if hit is not None and hit.problem is problem and hit.wall_thickness == wall_thickness:
        return hit
    bodies: dict[str, _Body] = {}
    statics: list[tuple[int, object]] = []
    # Walls in a fixed order, whatever the file's order: the space is built in that order.
    edges = [edge for edge in WALL_NAMES if edge in problem.table.walls]
    for box in wall_boxes(problem.table.size, edges, wall_thickness).values():
        statics.append((4, ffi.new("cpVect[]", box_corners(box))))
    for spec in problem.objects:
        parts = spec.shape.parts
        if spec.kind is ObjectKind.OBSTACLE:
            if spec.pose is None:
                raise ValueError(f"obstacle {spec.name!r} has no pose")
            for part in parts:
                world = [transform_point(point, spec.pose) for point in part]
                statics.append((len(world), ffi.new("cpVect[]", world)))
            continue
        areas = [_poly_area(part) for part in parts]
        moments = [
            lib.cpMomentForPoly(1.0, len(part), list(part), (0.0, 0.0), 0.0) for part in parts
        ]
        bodies[spec.name] = _Body(
            kind=spec.kind,
            parts=tuple((len(part), ffi.new("cpVect[]", list(part))) for part in parts),
            area=sum(areas),
            part_moments=tuple(zip(areas, moments, strict=True)),
            abs_r=sum(_abs_r_integral(part) for part in parts),
            push_direction=spec.push_direction,
            radius=spec.shape.radius,
        )
    parts_area = sum(spec.shape.area for spec in problem.parts)  # as push_force sums it
    compiled = _Compiled(
        problem,
        bodies,
        tuple(statics),
        problem.table,
        wall_thickness,
        parts_area,
        PenetrationDepths(problem),
    )
    if len(_CACHE) >= _CACHE_SIZE:
        _CACHE.pop(next(iter(_CACHE)))
    _CACHE[key] = compiled
    return compiled
