"""Convex decomposition of simple polygons: ear-clipping triangulation, then Hertel-Mehlhorn
merging, on the polygon's own vertices (no new points, no snapping)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from arrange_up.geometry.polygons import (
    Polygon,
    _cross3,
    ensure_ccw,
    is_convex,
    polygon_problem,
)
from arrange_up.geometry.se2 import Point

# Relative tolerance for "these three points are collinear": the sine of the turn angle.
# Small enough never to hide a real corner of a tabletop object, large enough to absorb
# the rounding of coordinates that were typed as decimals.
_COLLINEAR_SIN = 1e-12

#: Polygons of at most this many vertices get the best of 12 triangulations; bigger ones (far
#: beyond any tabletop part's outline) one, so that their decomposition costs a twelfth.
_SEVERAL_STARTS_UP_TO = 64

__all__ = ["decompose_convex"]


def _turn_sin(a: Point, b: Point, c: Point) -> float:
    """Sine of the turn at ``b`` on the path ``a -> b -> c`` (positive = left turn)."""
    la = math.hypot(b[0] - a[0], b[1] - a[1])
    lc = math.hypot(c[0] - b[0], c[1] - b[1])
    return _cross3(a, b, c) / (la * lc)


def _cross_all(a: Point, b: Point, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """:func:`_cross3` ``(a, b, p)`` for every point ``p = (x[k], y[k])``, with the same
    floating-point operations in the same order (so the same bits)."""
    return (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])


def _in_triangle_all(x: np.ndarray, y: np.ndarray, a: Point, b: Point, c: Point) -> np.ndarray:
    """Which points ``(x[k], y[k])`` are inside or on the boundary of the CCW triangle ``abc``."""
    return (
        (_cross_all(a, b, x, y) >= 0.0)
        & (_cross_all(b, c, x, y) >= 0.0)
        & (_cross_all(c, a, x, y) >= 0.0)
    )


def _ear_clip(pts: Polygon, start: int = 0) -> list[tuple[int, int, int]]:
    """Triangulate a simple CCW polygon by ear clipping; triangles as CCW index triples.

    An ear is a strictly convex vertex whose triangle with its two neighbours contains no other
    remaining vertex (boundary included, so no diagonal ever runs along or through the boundary).
    Straight (collinear) vertices are never ears, so no degenerate triangle is produced; they
    are clipped as corners of their neighbours' ears instead. Ears that are nearly straight are
    taken only when nothing better exists, to avoid sliver triangles. ``start`` rotates where
    the search begins, which gives different (equally valid) triangulations. O(n^3) in the worst
    case, each ear test one vectorised pass over the remaining vertices; polygons are capped at
    :data:`~arrange_up.geometry.polygons.MAX_POLYGON_VERTICES` vertices.
    """
    n = len(pts)
    xy = np.asarray(pts, dtype=float)
    idx = list(range(start, n)) + list(range(start))
    tris: list[tuple[int, int, int]] = []
    while len(idx) > 3:
        m = len(idx)
        rest = xy[idx]
        x, y = rest[:, 0], rest[:, 1]
        clipped = False
        for min_sin in (1e-9, 0.0):
            for k in range(m):
                i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % m]
                a, b, c = pts[i0], pts[i1], pts[i2]
                if _turn_sin(a, b, c) <= min_sin:
                    continue
                inside = _in_triangle_all(x, y, a, b, c)
                inside[[k - 1, k, (k + 1) % m]] = False  # the ear's own corners
                if inside.any():
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
    that a single arbitrary triangulation can miss; a polygon of more than 64 vertices gets one
    triangulation. Deterministic.

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
    starts = 12 if n <= _SEVERAL_STARTS_UP_TO else 1
    for start in range(min(n, starts)):
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
