"""Polygons: validity, orientation, areas and centroids, convexity, and the penetration depth of
two convex polygons. numpy only.

A :data:`Polygon` is a tuple of ``(x, y)`` float pairs, counter-clockwise (positive signed area),
with no repeated closing vertex. Functions that *accept* polygons take any sequence of pairs
(lists, tuples, ``(N, 2)`` arrays) and either orientation unless they say otherwise; functions
that *return* polygons return CCW tuples of Python floats.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from arrange_up.geometry.se2 import Point

Polygon = tuple[Point, ...]
"""Counter-clockwise vertices, no repeated closing vertex."""

_TAU = 2.0 * math.pi

#: Most vertices a polygon may have. Tabletop parts have tens; the cap keeps every polygon
#: operation's cost bounded (validity is quadratic in the vertex count, decomposition worse), so
#: a huge outline is refused with a message instead of exhausting time or memory.
MAX_POLYGON_VERTICES = 1000
#: Segment pairs tested at once by the self-intersection test: bounds its temporary arrays
#: (about a hundred bytes a pair) whatever the vertex count.
_PAIRS_PER_CHUNK = 1 << 16

__all__ = [
    "MAX_POLYGON_VERTICES",
    "Polygon",
    "box_polygon",
    "convex_penetration",
    "ensure_ccw",
    "is_convex",
    "parts_centroid",
    "polygon_centroid",
    "polygon_problem",
    "polygon_signed_area",
    "translate_polygon",
]


def _points_array(poly: npt.ArrayLike) -> np.ndarray:
    """``poly`` as a float ``(N, 2)`` array; ``ValueError`` if it is not a list of pairs."""
    arr = np.asarray(poly, dtype=float)
    if arr.size == 0:
        return arr.reshape(0, 2)
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"expected a sequence of (x, y) points, got an array of shape {arr.shape}")
    return arr


def _as_polygon(arr: np.ndarray) -> Polygon:
    """``(N, 2)`` array -> tuple of float pairs (plain Python floats, hashable)."""
    return tuple((float(x), float(y)) for x, y in arr.tolist())


def polygon_signed_area(poly: Sequence[Point] | np.ndarray) -> float:
    """Signed area by the shoelace formula: positive for CCW, negative for CW.

    Any sequence of points is accepted (no validity check); fewer than 3 points give ``0.0``.
    """
    p = _points_array(poly)
    if len(p) < 3:
        return 0.0
    # Shift to the first vertex so the products stay small (less cancellation far from origin).
    q = p - p[0]
    x, y = q[:, 0], q[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _area_and_centroid(p: np.ndarray) -> tuple[float, np.ndarray]:
    """Signed area and area centroid of an ``(N, 2)`` polygon (centroid undefined if area 0)."""
    origin = p[0]
    q = p - origin
    x, y = q[:, 0], q[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * float(cross.sum())
    if area == 0.0:
        return 0.0, origin.copy()
    cx = float(((x + xn) * cross).sum()) / (6.0 * area)
    cy = float(((y + yn) * cross).sum()) / (6.0 * area)
    return area, origin + np.array([cx, cy])


def polygon_centroid(poly: Sequence[Point]) -> Point:
    """Area centroid of a simple polygon (either orientation).

    Raises
    ------
    ValueError
        If the polygon has fewer than 3 vertices or zero area (the centroid is undefined).
    """
    p = _points_array(poly)
    if len(p) < 3:
        raise ValueError("polygon has fewer than 3 vertices")
    area, c = _area_and_centroid(p)
    if area == 0.0:
        raise ValueError("polygon is degenerate (zero area)")
    return (float(c[0]), float(c[1]))


def parts_centroid(parts: Sequence[Sequence[Point]]) -> Point:
    """Area-weighted centroid of disjoint parts (interiors must not overlap; not checked).

    Each part is weighted by its absolute area, so the orientation of parts does not matter.

    Raises
    ------
    ValueError
        If there are no parts or their total area is zero.
    """
    total = 0.0
    acc = np.zeros(2)
    for part in parts:
        p = _points_array(part)
        if len(p) < 3:
            continue
        area, c = _area_and_centroid(p)
        total += abs(area)
        acc += abs(area) * c
    if total == 0.0:
        raise ValueError("parts have zero total area")
    return (float(acc[0] / total), float(acc[1] / total))


def _orient(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Twice the signed area of triangles ``(a, b, c)``, vectorised over leading axes."""
    twice_area: np.ndarray = (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (
        b[..., 1] - a[..., 1]
    ) * (c[..., 0] - a[..., 0])
    return twice_area


def _segments_intersect(
    p1: np.ndarray, p2: np.ndarray, q1: np.ndarray, q2: np.ndarray
) -> np.ndarray:
    """Whether closed segments ``p1p2`` and ``q1q2`` share a point (vectorised).

    Standard orientation test: the segments meet iff each one's endpoints are not strictly on
    the same side of the other's line *and* their bounding boxes overlap. The box test is what
    decides the all-collinear case (overlapping vs. disjoint collinear segments).
    """
    o1 = np.sign(_orient(p1, p2, q1))
    o2 = np.sign(_orient(p1, p2, q2))
    o3 = np.sign(_orient(q1, q2, p1))
    o4 = np.sign(_orient(q1, q2, p2))
    straddle = (o1 * o2 <= 0) & (o3 * o4 <= 0)
    boxes = (
        (np.minimum(p1[..., 0], p2[..., 0]) <= np.maximum(q1[..., 0], q2[..., 0]))
        & (np.minimum(q1[..., 0], q2[..., 0]) <= np.maximum(p1[..., 0], p2[..., 0]))
        & (np.minimum(p1[..., 1], p2[..., 1]) <= np.maximum(q1[..., 1], q2[..., 1]))
        & (np.minimum(q1[..., 1], q2[..., 1]) <= np.maximum(p1[..., 1], p2[..., 1]))
    )
    meet: np.ndarray = straddle & boxes
    return meet


def polygon_problem(poly: Sequence[Point]) -> str | None:
    """Why ``poly`` is not a valid simple polygon, or ``None`` if it is one.

    Either orientation is valid. The checks, in order (the first failing one is reported):

    * ``"is not a sequence of (x, y) points"``
    * ``"has fewer than 3 vertices"``
    * ``"has N vertices, more than the MAX vertices a polygon may have"`` (see
      :data:`MAX_POLYGON_VERTICES`); tested before any work that grows faster than the count
    * ``"has non-finite coordinates"`` (NaN or infinity)
    * ``"has repeated consecutive vertices"`` (including last == first: polygons are given
      without a closing vertex)
    * ``"is degenerate (zero area)"``: all vertices on one line (distance from the line at
      most ``1e-12`` times the polygon's size)
    * ``"intersects itself"``: two non-adjacent edges touch or cross, or two adjacent edges
      fold back over each other (a collinear overlap).

    Coordinates are compared exactly (no snapping), so the answer is that of the floats given.
    """
    try:
        p = _points_array(poly)
    except (ValueError, TypeError):
        return "is not a sequence of (x, y) points"
    n = len(p)
    if n < 3:
        return "has fewer than 3 vertices"
    if n > MAX_POLYGON_VERTICES:
        return f"has {n} vertices, more than the {MAX_POLYGON_VERTICES} vertices a polygon may have"
    if not np.all(np.isfinite(p)):
        return "has non-finite coordinates"
    nxt = np.roll(p, -1, axis=0)
    if np.any(np.all(p == nxt, axis=1)):
        return "has repeated consecutive vertices"
    # Degenerate means all vertices on one line (the region has no interior). Tested on the
    # vertices, not on the signed area: a bow-tie has zero signed area but is self-intersecting.
    rel = p - p[0]
    far = rel[np.argmax(np.einsum("ij,ij->i", rel, rel))]
    span2 = float(far @ far)
    if np.max(np.abs(rel[:, 0] * far[1] - rel[:, 1] * far[0])) <= 1e-12 * span2:
        return "is degenerate (zero area)"
    # Adjacent edges (a->b, b->c) share b; they overlap beyond it only if c folds back along ab.
    prv = np.roll(p, 1, axis=0)
    turn = _orient(prv, p, nxt)
    back = np.einsum("ij,ij->i", p - prv, nxt - p)
    if np.any((turn == 0.0) & (back < 0.0)):
        return "intersects itself"
    if n > 3:
        # Every pair of non-adjacent edges (edge i runs from p[i] to p[i+1]), a block of
        # edges i at a time against all edges j >= i + 2, so memory stays bounded.
        rows = max(1, _PAIRS_PER_CHUNK // n)
        for first in range(0, n - 2, rows):
            i, j = np.meshgrid(np.arange(first, min(first + rows, n - 2)), np.arange(n))
            keep = (j >= i + 2) & ~((i == 0) & (j == n - 1))  # edges 0 and n-1 share p[0]
            i, j = i[keep], j[keep]
            if np.any(_segments_intersect(p[i], nxt[i], p[j], nxt[j])):
                return "intersects itself"
    if polygon_signed_area(p) == 0.0:  # unreachable in exact arithmetic; a rounding safety net
        return "is degenerate (zero area)"
    return None


def ensure_ccw(poly: Sequence[Point]) -> Polygon:
    """``poly`` as a CCW tuple of float pairs, reversed if it was clockwise.

    The first vertex stays first. No validity check (see :func:`polygon_problem`).
    """
    p = _points_array(poly)
    if polygon_signed_area(p) < 0.0:
        p = np.concatenate([p[:1], p[:0:-1]])
    return _as_polygon(p)


def is_convex(poly: Sequence[Point], tol: float = 1e-12) -> bool:
    """Whether ``poly`` is a (weakly) convex polygon, in either orientation.

    Collinear (straight, 180 degree) vertices are allowed. A turn counts as "against" the
    orientation only if the sine of its angle is below ``-tol`` (scale-free). The total turning
    must be one full turn, which rejects self-intersecting stars whose turns all have one sign.
    Fewer than 3 vertices, repeated consecutive vertices or zero area give ``False``.
    """
    p = _points_array(poly)
    if len(p) < 3 or not np.all(np.isfinite(p)):
        return False
    area = polygon_signed_area(p)
    if area == 0.0:
        return False
    sign = 1.0 if area > 0.0 else -1.0
    e_in = p - np.roll(p, 1, axis=0)
    e_out = np.roll(p, -1, axis=0) - p
    len_in = np.hypot(e_in[:, 0], e_in[:, 1])
    len_out = np.hypot(e_out[:, 0], e_out[:, 1])
    if np.any(len_in == 0.0):
        return False
    cross = e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0]
    dot = np.einsum("ij,ij->i", e_in, e_out)
    if np.any(sign * cross < -tol * len_in * len_out):
        return False
    turning = np.arctan2(cross, dot).sum()
    return bool(abs(turning - sign * _TAU) < 1e-6)


def _cross3(a: Point, b: Point, c: Point) -> float:
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def box_polygon(width: float, height: float) -> Polygon:
    """Axis-aligned ``width x height`` rectangle centred at the origin, CCW from bottom-left.

    Raises ``ValueError`` unless both sizes are finite and positive.
    """
    if not (math.isfinite(width) and math.isfinite(height) and width > 0 and height > 0):
        raise ValueError(f"box size must be positive and finite, got {width} x {height}")
    w, h = 0.5 * float(width), 0.5 * float(height)
    return ((-w, -h), (w, -h), (w, h), (-w, h))


def translate_polygon(poly: Sequence[Point], dx: float, dy: float) -> Polygon:
    """``poly`` shifted by ``(dx, dy)``; vertex order (and so orientation) unchanged."""
    return tuple((float(x) + dx, float(y) + dy) for x, y in poly)


def convex_penetration(a: Sequence[Point] | np.ndarray, b: Sequence[Point] | np.ndarray) -> float:
    """Penetration depth of two convex polygons (``(N, 2)`` arrays or point sequences): the
    smallest overlap of their projections over the edge normals of both (separating axis
    theorem); ``0.0`` when a separating axis exists (touching counts as apart). Either
    orientation; degenerate (zero-length) edges are skipped.

    In plain Python floats: the polygons have a few vertices, where numpy's per-call overhead
    would dominate (every push of the simulation tests its paddle's landing with it)."""
    points_a = a.tolist() if isinstance(a, np.ndarray) else [(float(x), float(y)) for x, y in a]
    points_b = b.tolist() if isinstance(b, np.ndarray) else [(float(x), float(y)) for x, y in b]
    best = math.inf
    for poly in (points_a, points_b):
        n = len(poly)
        for i in range(n):
            x0, y0 = poly[i]
            x1, y1 = poly[(i + 1) % n]
            nx, ny = y1 - y0, x0 - x1
            length = math.hypot(nx, ny)
            if length <= 0.0:
                continue
            nx, ny = nx / length, ny / length
            on_a = [x * nx + y * ny for x, y in points_a]
            on_b = [x * nx + y * ny for x, y in points_b]
            overlap = min(max(on_a), max(on_b)) - max(min(on_a), min(on_b))
            if overlap <= 0.0:
                return 0.0
            best = min(best, overlap)
    return best
