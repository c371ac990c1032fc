"""Belief shadows (thesis "Reliably arranging objects", section 2.1.2): regions containing a shape
at **every** pose of a pose interval, rotation included.

A pose interval is a pose plus half-widths ``(dx, dy, dtheta)``: the true pose is anywhere in
``[x-dx, x+dx] x [y-dy, y+dy] x [theta-dtheta, theta+dtheta]``. Both shadows here are
conservative by construction: :func:`shadow_box` is the exact smallest such box, and
:func:`shadow_hull` is a convex polygon containing the exact swept region (it over-approximates
the arcs traced by rotating vertices by at most ``r * (1 / cos(max_step / 2) - 1)``). The
thesis's formula, which places the shape only at the interval's end angles, can miss a corner
that swings past an axis direction mid-interval; ours cannot.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import shapely

from arrange_up.geometry.boxes import Box
from arrange_up.geometry.polygons import Polygon, _cross3, _points_array
from arrange_up.geometry.se2 import Point, Pose, transform_points

HalfWidths = tuple[float, float, float]
"""``(dx, dy, dtheta)`` of a symmetric pose interval."""

__all__ = ["HalfWidths", "ShapeVertices", "shadow_box", "shadow_hull", "shape_vertices"]


@dataclass(frozen=True, eq=False)
class ShapeVertices:
    """Precomputed per-vertex data for fast shadows of one shape.

    Build it with :func:`shape_vertices`. When built from parts, only the vertices of the
    shape's convex hull are kept: the extremes of the shape in any direction, at any rotation,
    are attained at them. All arrays are read-only (instances are shared through a cache).

    Attributes
    ----------
    points : (N, 2) array
        Vertices in the object frame.
    radii : (N,) array
        Their distances from the origin.
    radius : float
        ``max(radii)`` (:func:`shape_radius` of the hull).
    aug : (N, 4) array
        ``[vx, vy, vx / r, vy / r]``: coordinates and unit directions side by side, so that one
        matrix product gives both rotated offsets and the cosines :func:`shadow_box` tests.
    reach : (N, 4) array
        ``radii`` repeated in four columns (the extreme offset along ``+x, +y, -x, -y``).
    """

    points: np.ndarray
    radii: np.ndarray
    radius: float
    aug: np.ndarray = field(repr=False)
    reach: np.ndarray = field(repr=False)


def _convex_hull_points(p: np.ndarray) -> np.ndarray:
    """CCW convex hull vertices of a point set (Andrew's monotone chain, collinear dropped)."""
    pts = sorted(set(map(tuple, p.tolist())))
    if len(pts) <= 2:
        return np.asarray(pts, dtype=float).reshape(-1, 2)

    def half(seq: list[Point]) -> list[Point]:
        chain: list[Point] = []
        for q in seq:
            while len(chain) >= 2 and _cross3(chain[-2], chain[-1], q) <= 0.0:
                chain.pop()
            chain.append(q)
        return chain

    lower, upper = half(pts), half(pts[::-1])
    return np.asarray(lower[:-1] + upper[:-1], dtype=float)


def _make_shape_vertices(p: np.ndarray) -> ShapeVertices:
    if len(p) == 0:
        raise ValueError("shape has no vertices")
    if not np.all(np.isfinite(p)):
        raise ValueError("shape has non-finite coordinates")
    radii = np.hypot(p[:, 0], p[:, 1])
    # A vertex at the origin has no direction; any unit vector would do, zero is simplest (its
    # radius is 0, so whether it "hits" an axis direction cannot change the box).
    safe = np.where(radii > 0.0, radii, 1.0)
    aug = np.concatenate([p, p / safe[:, None]], axis=1)
    reach = np.repeat(radii[:, None], 4, axis=1)
    for arr in (p, radii, aug, reach):
        arr.setflags(write=False)  # shared through the cache: must not be mutated
    return ShapeVertices(points=p, radii=radii, radius=float(radii.max()), aug=aug, reach=reach)


@lru_cache(maxsize=4096)
def _cached_shape_vertices(parts: tuple[Sequence[Point], ...]) -> ShapeVertices:
    allpts = np.concatenate([_points_array(part) for part in parts])
    return _make_shape_vertices(_convex_hull_points(allpts))


def shape_vertices(parts: Sequence[Sequence[Point]] | np.ndarray | ShapeVertices) -> ShapeVertices:
    """Precomputed vertex data for :func:`shadow_box` / :func:`shadow_hull`.

    Accepts

    * a :class:`ShapeVertices` (returned as is);
    * an ``(N, 2)`` array of object-frame points: used as given (every point kept, nothing
      cached; hull reduction is skipped because it would cost more than it saves per call);
    * a sequence of parts. A hashable one (tuple of tuples, as in ``Shape.parts``) is looked up
      in an LRU cache (4096 shapes) so repeated calls cost one tuple hash; an unhashable one
      (lists) is processed afresh every call.
    """
    if isinstance(parts, ShapeVertices):
        return parts
    if isinstance(parts, np.ndarray):
        p = np.array(parts, dtype=float)  # a private copy: it is made read-only
        if p.ndim != 2 or p.shape[1] != 2:
            raise ValueError(f"expected an (N, 2) array of points, got shape {p.shape}")
        return _make_shape_vertices(p)
    try:
        return _cached_shape_vertices(parts)
    except TypeError:  # unhashable (lists)
        allpts = np.concatenate([_points_array(part) for part in parts])
        return _make_shape_vertices(_convex_hull_points(allpts))


def _check_half_widths(half_widths: HalfWidths) -> tuple[float, float, float]:
    dx, dy, dt = half_widths
    # `not (a >= 0)` also rejects NaN.
    if not (dx >= 0.0 and dy >= 0.0 and dt >= 0.0):
        raise ValueError(f"half-widths must be non-negative, got {half_widths}")
    return dx, dy, dt


def shadow_box(
    parts: Sequence[Polygon] | np.ndarray | ShapeVertices,
    pose: Pose,
    half_widths: HalfWidths,
) -> Box:
    """Smallest axis-aligned box containing the shape at every pose of the interval.

    Exact (up to rounding), rotation included. For a vertex at radius ``r`` and polar angle
    ``phi``, its world x over ``theta`` in ``[t - dt, t + dt]`` is ``x + r cos(theta + phi)``;
    the extremes are at the interval's ends or where ``theta + phi`` is a multiple of ``pi``
    (for y, ``pi/2`` plus a multiple of ``pi``), where the value is ``+-r``. So the box is the max
    / min over the end-angle positions and, for every vertex whose critical angle lies in the
    interval, ``+-r``; then widened by ``dx`` and ``dy``. A critical angle lies in the interval
    iff the vertex's direction at the mid angle ``t`` is within ``dt`` of that axis direction,
    i.e. its cosine with the axis is ``>= cos(dt)``; that test costs no trigonometry per
    vertex. With ``dtheta >= pi`` every orientation is possible and the box is the disc of
    radius :func:`shape_radius` widened.

    Parameters
    ----------
    parts
        The shape: convex parts (a hashable tuple of tuples is cached, see
        :func:`shape_vertices`), an ``(N, 2)`` vertex array, or a :class:`ShapeVertices`
        (fastest: no lookup at all). For hot loops, call :func:`shape_vertices` once.
    pose
        Nominal pose ``(x, y, theta)``.
    half_widths
        ``(dx, dy, dtheta)``, non-negative.

    Returns
    -------
    Box
        ``(xmin, ymin, xmax, ymax)`` as Python floats.

    Notes
    -----
    Vectorised over vertices with numpy (one 4x12 matrix product, one comparison, one
    ``where``, one reduction), no shapely and no Python loop over vertices (its cost:
    ``docs/design/geometry.md``). Shape data is cached per parts tuple (see
    :func:`shape_vertices`); an ``(N, 2)`` array input is re-processed on every call, so
    prefer parts or a :class:`ShapeVertices` in hot loops.
    """
    sv = shape_vertices(parts)
    dx, dy, dt = _check_half_widths(half_widths)
    x, y, t = pose
    if dt >= math.pi:
        r = sv.radius
        return (x - r - dx, y - r - dy, x + r + dx, y + r + dy)
    lo, hi = t - dt, t + dt
    c0, s0, c1, s1 = math.cos(lo), math.sin(lo), math.cos(hi), math.sin(hi)
    cm, sm = math.cos(t), math.sin(t)
    # One product gives, per vertex, 12 columns: its world offset along +x, +y, -x, -y at
    # theta = lo (0-3) and at theta = hi (4-7), and its unit direction along +x, +y, -x, -y at
    # the mid angle theta = t (8-11). Signs are folded in so that every extreme is a max.
    rot = np.array(
        [
            [c0, s0, -c0, -s0, c1, s1, -c1, -s1, 0.0, 0.0, 0.0, 0.0],
            [-s0, c0, s0, -c0, -s1, c1, s1, -c1, 0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, cm, sm, -cm, -sm],
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -sm, cm, sm, -cm],
        ]
    )
    cand = sv.aug @ rot
    # The vertex points exactly along an axis direction at some theta in the interval iff its
    # direction at the mid angle is within dt of that axis, i.e. the cosine is >= cos(dt).
    # Then its offset along that axis reaches r; otherwise the interval's ends are the extremes.
    hit = cand[:, 8:] >= math.cos(dt)
    cand[:, 8:] = np.where(hit, sv.reach, -np.inf)
    m = cand.max(axis=0).tolist()
    return (
        x - max(m[2], m[6], m[10]) - dx,
        y - max(m[3], m[7], m[11]) - dy,
        x + max(m[0], m[4], m[8]) + dx,
        y + max(m[1], m[5], m[9]) + dy,
    )


def shadow_hull(
    parts: Sequence[Polygon] | np.ndarray | ShapeVertices,
    pose: Pose,
    half_widths: HalfWidths,
    max_step: float = math.radians(5),
) -> shapely.Polygon:
    """A convex polygon containing the shape at every pose of the interval.

    Construction (each step keeps the guarantee): rotations are sampled over
    ``[t - dt, t + dt]`` at equal spacing ``step <= max_step``, both ends included. Between two
    samples a vertex at radius ``r`` traces an arc that bulges outside the chord, so for each gap
    we add the intersection of the arc's end tangents: the vertex rotated to the gap's mid angle
    with its radius scaled by ``1 / cos(step / 2)``; the arc lies in the triangle of that point
    and the two samples. Every placement of the shape is a convex combination of its rotated
    hull vertices, so it lies in the hull of these points. Translation uncertainty is a
    Minkowski sum with ``[-dx, dx] x [-dy, dy]`` (add its four corners to every point), and the
    convex hull of the result is returned. ``dtheta >= pi`` covers the full circle.

    The hull exceeds the exact swept region by at most ``radius * (1 / cos(step / 2) - 1)``
    (about 0.1 % of the radius for the default 5 degrees).

    Parameters
    ----------
    parts, pose, half_widths
        As for :func:`shadow_box`.
    max_step
        Largest angular spacing between samples, radians, in ``(0, pi/2]``.

    Raises
    ------
    ValueError
        For negative half-widths, a bad ``max_step``, or a shape with no area.
    """
    if not (0.0 < max_step <= 0.5 * math.pi):
        raise ValueError(f"max_step must be in (0, pi/2], got {max_step}")
    sv = shape_vertices(parts)
    dx, dy, dt = _check_half_widths(half_widths)
    x, y, t = pose
    dt = min(dt, math.pi)
    v = sv.points
    if dt == 0.0:
        pts = transform_points(v, (0.0, 0.0, t))
    else:
        gaps = max(1, math.ceil(2.0 * dt / max_step))
        step = 2.0 * dt / gaps
        thetas = t - dt + step * np.arange(gaps + 1)
        mids = thetas[:-1] + 0.5 * step
        scale = np.ones(len(thetas) + len(mids))
        scale[len(thetas) :] = 1.0 / math.cos(0.5 * step)
        ang = np.concatenate([thetas, mids])
        c, s = np.cos(ang)[:, None] * scale[:, None], np.sin(ang)[:, None] * scale[:, None]
        rx = v[None, :, 0] * c - v[None, :, 1] * s
        ry = v[None, :, 0] * s + v[None, :, 1] * c
        pts = np.stack([rx.ravel(), ry.ravel()], axis=1)
    corners = np.array([[-dx, -dy], [dx, -dy], [dx, dy], [-dx, dy]]) + (x, y)
    allpts = (pts[:, None, :] + corners[None, :, :]).reshape(-1, 2)
    hull = shapely.convex_hull(shapely.multipoints(allpts))
    if not isinstance(hull, shapely.Polygon) or hull.is_empty:
        raise ValueError("shape has no area: its shadow is not a polygon")
    return hull
