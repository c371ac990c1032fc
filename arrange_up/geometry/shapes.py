"""Planar geometry for arrange-up: polygons, poses, convex decomposition and belief shadows.

This module is pure numpy + shapely: no physics, no planning, and no imports from the rest of
``arrange_up``, so every other module may depend on it.

Conventions (the contract every function here keeps):

* The world frame is the table's: ``x`` to the right, ``y`` up, angles in radians,
  counter-clockwise positive.
* A :data:`Polygon` is a tuple of ``(x, y)`` float pairs, counter-clockwise (positive signed
  area), with no repeated closing vertex. Functions that *accept* polygons take any sequence of
  pairs (lists, tuples, ``(N, 2)`` arrays) and either orientation unless they say otherwise;
  functions that *return* polygons return CCW tuples of Python floats.
* A shape is a sequence of convex CCW polygons (its *parts*) in the object's own frame; a
  :data:`Pose` ``(x, y, theta)`` places the object frame in the world: an object point ``p``
  lands at ``R(theta) @ p + (x, y)``.
* A pose interval is a pose plus half-widths ``(dx, dy, dtheta)``: the true pose is anywhere in
  ``[x-dx, x+dx] x [y-dy, y+dy] x [theta-dtheta, theta+dtheta]``.
* A :data:`Box` is ``(xmin, ymin, xmax, ymax)``.
* A *belief shadow* (thesis "Reliably arranging objects", §2.1.2) is a region containing the
  shape at **every** pose of an interval, rotation included. Both shadows here are
  conservative by construction: :func:`shadow_box` is the exact smallest such box, and
  :func:`shadow_hull` is a convex polygon containing the exact swept region (it over-approximates
  the arcs traced by rotating vertices by at most ``r * (1 / cos(max_step / 2) - 1)``).
  The thesis's formula, which places the shape only at the interval's end angles, can miss a
  corner that swings past an axis direction mid-interval; ours cannot.

Functions that need valid input check it and raise :class:`ValueError` (self-intersecting
polygons, negative half-widths, unknown wall names, ...); nothing here silently repairs input.
Low-level helpers (areas, transforms, box predicates) do no checking, for speed.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import shapely
import shapely.geometry.base

Point = tuple[float, float]
"""``(x, y)``."""
Polygon = tuple[Point, ...]
"""Counter-clockwise vertices, no repeated closing vertex."""
Pose = tuple[float, float, float]
"""``(x, y, theta)``: world position of the object frame's origin and its rotation (radians)."""
Box = tuple[float, float, float, float]
"""``(xmin, ymin, xmax, ymax)``."""

HalfWidths = tuple[float, float, float]
"""``(dx, dy, dtheta)`` of a symmetric pose interval."""

WALL_NAMES: tuple[str, ...] = ("left", "right", "bottom", "top")

_TAU = 2.0 * math.pi
# Relative tolerance for "these three points are collinear": the sine of the turn angle.
# Small enough never to hide a real corner of a tabletop object, large enough to absorb
# the rounding of coordinates that were typed as decimals.
_COLLINEAR_SIN = 1e-12

__all__ = [
    "Box",
    "HalfWidths",
    "Point",
    "Polygon",
    "Pose",
    "ShapeVertices",
    "WALL_NAMES",
    "box_contains",
    "box_of",
    "box_polygon",
    "boxes_overlap",
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


# --------------------------------------------------------------------------------------------
# Polygons
# --------------------------------------------------------------------------------------------


def _points_array(poly: Sequence[Point] | np.ndarray) -> np.ndarray:
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


def polygon_signed_area(poly: Sequence[Point]) -> float:
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
    return (b[..., 0] - a[..., 0]) * (c[..., 1] - a[..., 1]) - (b[..., 1] - a[..., 1]) * (
        c[..., 0] - a[..., 0]
    )


def _segments_intersect(p1, p2, q1, q2) -> np.ndarray:
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
    return straddle & boxes


def polygon_problem(poly: Sequence[Point]) -> str | None:
    """Why ``poly`` is not a valid simple polygon, or ``None`` if it is one.

    Either orientation is valid. The checks, in order (the first failing one is reported):

    * ``"is not a sequence of (x, y) points"``
    * ``"has fewer than 3 vertices"``
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
        # All pairs of non-adjacent edges at once; edge i runs from p[i] to p[i+1].
        i, j = np.triu_indices(n, k=2)
        keep = ~((i == 0) & (j == n - 1))  # edges 0 and n-1 are adjacent (share p[0])
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


def _turn_sin(a: Point, b: Point, c: Point) -> float:
    """Sine of the turn at ``b`` on the path ``a -> b -> c`` (positive = left turn)."""
    la = math.hypot(b[0] - a[0], b[1] - a[1])
    lc = math.hypot(c[0] - b[0], c[1] - b[1])
    return _cross3(a, b, c) / (la * lc)


def _in_triangle(p: Point, a: Point, b: Point, c: Point) -> bool:
    """Whether ``p`` is inside or on the boundary of the CCW triangle ``abc``."""
    return _cross3(a, b, p) >= 0.0 and _cross3(b, c, p) >= 0.0 and _cross3(c, a, p) >= 0.0


def _ear_clip(pts: Polygon, start: int = 0) -> list[tuple[int, int, int]]:
    """Triangulate a simple CCW polygon by ear clipping; triangles as CCW index triples.

    An ear is a strictly convex vertex whose triangle with its two neighbours contains no other
    remaining vertex (boundary included, so no diagonal ever runs along or through the boundary).
    Straight (collinear) vertices are never ears, so no degenerate triangle is produced; they
    are clipped as corners of their neighbours' ears instead. Ears that are nearly straight are
    taken only when nothing better exists, to avoid sliver triangles. ``start`` rotates where
    the search begins, which gives different (equally valid) triangulations. O(n^3), fine for
    object outlines of tens of vertices.
    """
    n = len(pts)
    idx = list(range(start, n)) + list(range(start))
    tris: list[tuple[int, int, int]] = []
    while len(idx) > 3:
        m = len(idx)
        clipped = False
        for min_sin in (1e-9, 0.0):
            for k in range(m):
                i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % m]
                a, b, c = pts[i0], pts[i1], pts[i2]
                if _turn_sin(a, b, c) <= min_sin:
                    continue
                if any(_in_triangle(pts[j], a, b, c) for j in idx if j not in (i0, i1, i2)):
                    continue
                tris.append((i0, i1, i2))
                del idx[k]
                clipped = True
                break
            if clipped:
                break
        if not clipped:  # only reachable through floating-point trouble on near-degenerate input
            raise ValueError("polygon could not be triangulated (numerically degenerate)")
    if _cross3(*(pts[i] for i in idx)) <= 0.0:
        raise ValueError("polygon could not be triangulated (numerically degenerate)")
    tris.append((idx[0], idx[1], idx[2]))
    return tris


def _hertel_mehlhorn(pts: Polygon, tris: list[tuple[int, int, int]]) -> list[list[int]]:
    """Merge triangles across diagonals while the union stays convex (Hertel & Mehlhorn 1983).

    Each diagonal is tried once: merging only ever widens the angles at a diagonal's endpoints,
    so a diagonal that cannot be removed now never can. Straight angles are accepted (the
    vertex stays, which keeps the pieces' shared edges identical, i.e. the decomposition
    conforming). The result has at most four times the minimum number of convex pieces.
    """
    pieces: dict[int, list[int]] = {k: list(t) for k, t in enumerate(tris)}
    owner: dict[tuple[int, int], int] = {}
    for k, t in pieces.items():
        for e in range(3):
            owner[(t[e], t[(e + 1) % 3])] = k
    diagonals = [(u, v) for (u, v) in owner if u < v and (v, u) in owner]
    # Remove long diagonals first: they tend to be the ones that split a piece badly.
    diagonals.sort(key=lambda d: -math.dist(pts[d[0]], pts[d[1]]))
    for u, v in diagonals:
        ka, kb = owner[(u, v)], owner[(v, u)]
        a, b = pieces[ka], pieces[kb]
        ia, ib = a.index(v), b.index(u)
        a_rot = a[ia:] + a[:ia]  # v ... u   (a contains the edge u -> v)
        b_rot = b[ib:] + b[:ib]  # u ... v
        merged = a_rot + b_rot[1:-1]
        # Only the angles at u and v change; check both stay convex (straight allowed).
        m = len(merged)
        iu = len(a_rot) - 1
        ok = True
        for i in (0, iu):
            if _turn_sin(pts[merged[i - 1]], pts[merged[i]], pts[merged[(i + 1) % m]]) < (
                -_COLLINEAR_SIN
            ):
                ok = False
                break
        if not ok:
            continue
        del pieces[kb]
        pieces[ka] = merged
        for e in range(m):
            owner[(merged[e], merged[(e + 1) % m])] = ka
    return list(pieces.values())


def decompose_convex(poly: Sequence[Point]) -> tuple[Polygon, ...]:
    """Split a simple polygon into convex CCW pieces.

    The pieces' union is exactly ``poly`` (they use only ``poly``'s own vertices), their
    interiors are pairwise disjoint, and the decomposition is conforming: neighbouring pieces
    share whole edges (a piece may keep a straight 180 degree vertex for that). Convex input
    (collinear vertices allowed) is returned as ``(ensure_ccw(poly),)``.

    Method: ear-clipping triangulation, then Hertel–Mehlhorn merging across diagonals. A few
    triangulations (ear search started at different vertices) are tried and the one giving the
    fewest pieces is kept, which finds the obvious decompositions (e.g. a tee in 2 or 3 pieces)
    that a single arbitrary triangulation can miss. Deterministic.

    Raises
    ------
    ValueError
        ``"polygon <reason>"`` with :func:`polygon_problem`'s reason for invalid input.
    """
    problem = polygon_problem(poly)
    if problem is not None:
        raise ValueError(f"polygon {problem}")
    pts = ensure_ccw(poly)
    if is_convex(pts):
        return (pts,)
    n = len(pts)
    best: list[list[int]] | None = None
    for start in range(min(n, 12)):
        pieces = _hertel_mehlhorn(pts, _ear_clip(pts, start))
        if best is None or len(pieces) < len(best):
            best = pieces
    assert best is not None
    # Canonical order: each piece starts at its lowest vertex index; pieces sorted by that.
    out = []
    for piece in best:
        k = piece.index(min(piece))
        out.append(piece[k:] + piece[:k])
    out.sort()
    return tuple(tuple(pts[i] for i in piece) for piece in out)


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


# --------------------------------------------------------------------------------------------
# Poses and shapes
# --------------------------------------------------------------------------------------------


def transform_points(points: np.ndarray, pose: Pose) -> np.ndarray:
    """Map ``(N, 2)`` object-frame points to the world: ``R(theta) @ p + (x, y)``.

    Returns a new ``(N, 2)`` float array. Computed element-wise (not with a matrix product) so
    that equal input points always give bit-identical outputs, whichever array they are in;
    :func:`footprint` relies on that for shared edges of neighbouring parts to stay shared.
    """
    p = np.asarray(points, dtype=float)
    x, y, theta = pose
    c, s = math.cos(theta), math.sin(theta)
    out = np.empty(p.shape, dtype=float)
    out[..., 0] = p[..., 0] * c - p[..., 1] * s + x
    out[..., 1] = p[..., 0] * s + p[..., 1] * c + y
    return out


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

    def half(seq: list) -> list:
        chain: list = []
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
def _cached_shape_vertices(parts: tuple) -> ShapeVertices:
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
        return _cached_shape_vertices(parts)  # type: ignore[arg-type]
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
    ``where``, one reduction), no shapely and no Python loop over vertices. About 10-15 us per
    call for small shapes, dominated by numpy's per-call overhead. Shape data is cached per
    parts tuple (see :func:`shape_vertices`); an ``(N, 2)`` array input is re-processed on
    every call, so prefer parts or a :class:`ShapeVertices` in hot loops.
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


# --------------------------------------------------------------------------------------------
# Boxes
# --------------------------------------------------------------------------------------------


def box_of(geom_or_points) -> Box:
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
    return (min(a[2], b[2]) - max(a[0], b[0]) > tol) and (min(a[3], b[3]) - max(a[1], b[1]) > tol)


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
