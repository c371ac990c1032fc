"""Tests for arrange_up.geometry.shapes: polygons, convex decomposition, belief shadows, boxes."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import shapely

from arrange_up.geometry.shapes import (
    MAX_POLYGON_VERTICES,
    ShapeVertices,
    box_contains,
    box_of,
    box_polygon,
    boxes_overlap,
    decompose_convex,
    ensure_ccw,
    footprint,
    is_convex,
    parts_centroid,
    polygon_centroid,
    polygon_problem,
    polygon_signed_area,
    shadow_box,
    shadow_hull,
    shape_radius,
    shape_vertices,
    swept_box,
    transform_points,
    translate_polygon,
    wall_boxes,
)


def _star(points: int, outer: float, inner: float) -> list[tuple[float, float]]:
    return [
        (
            (outer if k % 2 == 0 else inner) * math.cos(math.pi / 2 + k * math.pi / points),
            (outer if k % 2 == 0 else inner) * math.sin(math.pi / 2 + k * math.pi / points),
        )
        for k in range(2 * points)
    ]


TEE = [[0, 0], [3, 0], [3, 1], [2, 1], [2, 3], [1, 3], [1, 1], [0, 1]]

# Shared catalogue of valid simple polygons (lists, as a problem file would give them).
CATALOGUE: dict[str, list] = {
    "square": [[0, 0], [1, 0], [1, 1], [0, 1]],
    "rectangle": [[0, 0], [2.5, 0], [2.5, 0.15], [0, 0.15]],
    "house": [[0, 0], [2, 0], [2, 1], [1, 1.8], [0, 1]],
    "tee": TEE,
    "zed": [[0, 0], [2, 0], [2, 1], [3, 1], [3, 2], [1, 2], [1, 1], [0, 1]],
    "ell": [[0, 0], [2, 0], [2, 1], [1, 1], [1, 3], [0, 3]],
    "you": [[0, 0], [3, 0], [3, 3], [2, 3], [2, 1], [1, 1], [1, 3], [0, 3]],
    "comb": [
        [0, 0],
        [5, 0],
        [5, 3],
        [4, 3],
        [4, 1],
        [3, 1],
        [3, 3],
        [2, 3],
        [2, 1],
        [1, 1],
        [1, 3],
        [0, 3],
    ],  # fmt: skip
    "star5": _star(5, 1.0, 0.4),
    "star8": _star(8, 2.0, 0.7),
    "collinear_square": [[0, 0], [1, 0], [2, 0], [2, 1], [2, 2], [1, 2], [0, 2], [0, 1]],
    "collinear_ell": [[0, 0], [1, 0], [2, 0], [2, 1], [1, 1], [1, 2], [1, 3], [0, 3], [0, 1.5]],
    "clockwise_tee": TEE[::-1],
    "spiral": [[0, 0], [4, 0], [4, 4], [1, 4], [1, 2], [2, 2], [2, 3], [3, 3], [3, 1], [0, 1]],
}
CONVEX = ["square", "rectangle", "house", "collinear_square"]
NAMES = list(CATALOGUE)


def _random_star_shaped(seed: int, n: int = 12) -> list[tuple[float, float]]:
    """A random simple polygon: vertices at sorted random angles, random radii."""
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0, 2 * math.pi, n))
    radii = rng.uniform(0.3, 1.5, n)
    return [
        (float(r * math.cos(a)), float(r * math.sin(a))) for a, r in zip(angles, radii, strict=True)
    ]


def _centred_parts(poly) -> tuple:
    """A shape as the rest of arrange-up stores it: convex parts, centroid at the origin."""
    cx, cy = polygon_centroid(poly)
    return tuple(translate_polygon(p, -cx, -cy) for p in decompose_convex(poly))


def _vertices(parts) -> np.ndarray:
    return np.concatenate([np.asarray(p, dtype=float) for p in parts])


# --------------------------------------------------------------------------------------------
# Polygons and decomposition
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", NAMES)
def test_catalogue_is_valid(name):
    assert polygon_problem(CATALOGUE[name]) is None


@pytest.mark.parametrize(
    ("poly", "reason"),
    [
        ([[0, 0], [1, 1], [1, 0], [0, 1]], "intersects itself"),  # bow-tie
        ([[0, 0], [1, 0]], "fewer than 3 vertices"),
        ([], "fewer than 3 vertices"),
        ([[0, 0], [1, 1], [2, 2]], "zero area"),
        ([[0, 0], [1, 0], [1, 0], [1, 1]], "repeated consecutive vertices"),
        ([[0, 0], [1, 0], [1, 1], [0, 0]], "repeated consecutive vertices"),  # closing vertex
        ([[0, 0], [1, 0], [float("nan"), 1]], "non-finite"),
        ([[0, 0], [1, 0], [math.inf, 1]], "non-finite"),
        # Two squares pinched at one vertex (non-adjacent edges touch).
        ([[0, 0], [1, 0], [1, 1], [2, 1], [2, 2], [1, 2], [1, 1], [0, 1]], "intersects itself"),
        # A spike folding back along its own edge (collinear overlap of adjacent edges).
        ([[0, 0], [2, 0], [1, 0], [1, 1]], "intersects itself"),
        # Non-adjacent collinear overlap.
        ([[0, 0], [3, 0], [3, 1], [2, 0], [1, 0], [0, 1]], "intersects itself"),
        ([[0, 0, 0], [1, 0, 0], [1, 1, 0]], "not a sequence of (x, y) points"),
    ],
    ids=[
        "bowtie",
        "two-vertices",
        "empty",
        "collinear",
        "repeated",
        "closing-vertex",
        "nan",
        "inf",
        "pinched",
        "fold-back",
        "collinear-overlap",
        "3d",
    ],
)
def test_polygon_problem_catches(poly, reason):
    problem = polygon_problem(poly)
    assert problem is not None and reason in problem
    if reason != "not a sequence of (x, y) points":
        with pytest.raises(ValueError, match=reason.split(" (")[0]):
            decompose_convex(poly)


def test_orientation_helpers():
    square = CATALOGUE["square"]
    assert polygon_signed_area(square) == pytest.approx(1.0)
    assert polygon_signed_area(square[::-1]) == pytest.approx(-1.0)
    cw = CATALOGUE["clockwise_tee"]
    ccw = ensure_ccw(cw)
    assert polygon_signed_area(ccw) == pytest.approx(5.0)
    assert ccw[0] == tuple(map(float, cw[0]))  # first vertex kept
    assert ensure_ccw(square) == tuple((float(x), float(y)) for x, y in square)


def test_is_convex():
    assert is_convex(CATALOGUE["square"])
    assert is_convex(CATALOGUE["square"][::-1])  # either orientation
    assert is_convex(CATALOGUE["collinear_square"])  # straight vertices allowed
    assert not is_convex(TEE)
    assert not is_convex(CATALOGUE["star5"])
    pentagram = [
        (math.cos(math.pi / 2 + k * 4 * math.pi / 5), math.sin(math.pi / 2 + k * 4 * math.pi / 5))
        for k in range(5)
    ]
    assert not is_convex(pentagram)  # every turn has the same sign, but it winds twice
    assert not is_convex([[0, 0], [1, 0]])


def test_centroids():
    assert polygon_centroid(CATALOGUE["square"]) == pytest.approx((0.5, 0.5))
    # Tee: bar 3x1 (area 3, centroid (1.5, 0.5)) + stem 1x2 (area 2, centroid (1.5, 2)).
    assert polygon_centroid(TEE) == pytest.approx((1.5, 1.1))
    assert polygon_centroid(TEE[::-1]) == pytest.approx((1.5, 1.1))
    assert parts_centroid(decompose_convex(TEE)) == pytest.approx((1.5, 1.1))
    with pytest.raises(ValueError):
        polygon_centroid([[0, 0], [1, 1], [2, 2]])


def _check_decomposition(poly) -> tuple:
    pieces = decompose_convex(poly)
    target = shapely.Polygon(poly)
    for piece in pieces:
        assert is_convex(piece), piece
        assert polygon_signed_area(piece) > 0, piece
        assert polygon_problem(piece) is None
    assert sum(polygon_signed_area(p) for p in pieces) == pytest.approx(
        abs(polygon_signed_area(poly)), rel=1e-12
    )
    union = shapely.union_all([shapely.Polygon(p) for p in pieces])
    assert union.symmetric_difference(target).area < 1e-9
    for a, b in itertools.combinations(pieces, 2):
        assert shapely.Polygon(a).intersection(shapely.Polygon(b)).area < 1e-12
    return pieces


@pytest.mark.parametrize("name", NAMES)
def test_decompose_catalogue(name):
    pieces = _check_decomposition(CATALOGUE[name])
    if name in CONVEX:
        assert pieces == (ensure_ccw(CATALOGUE[name]),)
    else:
        assert len(pieces) >= 2


@pytest.mark.parametrize("seed", range(8))
def test_decompose_random_star_shaped(seed):
    _check_decomposition(_random_star_shaped(seed))


def test_decompose_tee_few_pieces():
    assert len(decompose_convex(TEE)) <= 3
    assert len(decompose_convex(TEE[::-1])) <= 3


# --------------------------------------------------------------------------------------------
# Poses and footprints
# --------------------------------------------------------------------------------------------


def test_box_polygon_and_translate():
    assert box_polygon(2, 1) == ((-1.0, -0.5), (1.0, -0.5), (1.0, 0.5), (-1.0, 0.5))
    assert polygon_signed_area(box_polygon(2, 1)) == pytest.approx(2.0)
    assert translate_polygon(((0, 0), (1, 0), (0, 1)), 2, 3) == ((2, 3), (3, 3), (2, 4))
    with pytest.raises(ValueError):
        box_polygon(0, 1)


def test_transform_points():
    pts = np.array([[1.0, 0.0], [0.0, 2.0]])
    out = transform_points(pts, (10.0, 20.0, math.pi / 2))
    np.testing.assert_allclose(out, [[10.0, 21.0], [8.0, 20.0]], atol=1e-12)
    np.testing.assert_allclose(transform_points(pts, (0, 0, 0)), pts)


@pytest.mark.parametrize("name", ["tee", "comb", "star5", "collinear_ell"])
def test_footprint_matches_transformed_polygon(name):
    poly = CATALOGUE[name]
    pose = (3.0, -1.0, 0.7)
    fp = footprint(decompose_convex(poly), pose)
    assert fp.geom_type == "Polygon" and len(fp.interiors) == 0
    expected = shapely.Polygon(transform_points(np.asarray(poly, dtype=float), pose))
    assert fp.area == pytest.approx(expected.area, rel=1e-12)
    assert fp.symmetric_difference(expected).area < 1e-9


def test_shape_radius():
    assert shape_radius((box_polygon(6, 8),)) == pytest.approx(5.0)
    assert shape_vertices((box_polygon(6, 8),)).radius == pytest.approx(5.0)


# --------------------------------------------------------------------------------------------
# Shadows
# --------------------------------------------------------------------------------------------


def _interval_samples(vertices, pose, half_widths, rng, n_uniform=100):
    """World vertex positions over many poses of the interval: uniform samples, the corners
    of the interval box, and every critical angle (a vertex pointing along an axis)."""
    x, y, t = pose
    dx, dy, dt = half_widths
    thetas = [t - dt + 2 * dt * rng.random(n_uniform), [t - dt, t, t + dt]]
    phi = np.arctan2(vertices[:, 1], vertices[:, 0])
    for k in range(-8, 9):
        crit = k * math.pi / 2 - phi
        thetas.append(crit[(crit >= t - dt) & (crit <= t + dt)])
    thetas = np.concatenate(thetas)[:, None]
    offsets = np.concatenate(
        [
            [[sx * dx, sy * dy] for sx in (-1, 1) for sy in (-1, 1)],
            (2 * rng.random((4, 2)) - 1) * (dx, dy),
        ]
    )
    wx = x + vertices[None, :, 0] * np.cos(thetas) - vertices[None, :, 1] * np.sin(thetas)
    wy = y + vertices[None, :, 0] * np.sin(thetas) + vertices[None, :, 1] * np.cos(thetas)
    rotated = np.stack([wx.ravel(), wy.ravel()], axis=1)
    return (rotated[None, :, :] + offsets[:, None, :]).reshape(-1, 2)


def _shapes_for_shadows():
    shapes = [_centred_parts(CATALOGUE[n]) for n in ("tee", "zed", "rectangle", "star5", "you")]
    shapes += [_centred_parts(_random_star_shaped(s, 7)) for s in (11, 12)]
    # Off-centre frame origin (pose origin outside the shape) must work too.
    shapes.append((translate_polygon(box_polygon(1, 2), 3.0, -2.0),))
    return shapes


HALF_WIDTHS = [
    (0.0, 0.0, 0.0),
    (0.1, 0.2, math.radians(10)),
    (0.0, 0.3, math.radians(60)),
    (0.5, 0.0, 2.0),
    (0.2, 0.2, math.pi - 1e-3),
    (0.1, 0.1, 4.0),
]


@pytest.mark.parametrize("half_widths", HALF_WIDTHS, ids=str)
def test_shadows_cover_every_pose_in_interval(half_widths):
    rng = np.random.default_rng(12345)
    for parts in _shapes_for_shadows():
        vertices = _vertices(parts)
        for _ in range(2):
            pose = (rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-math.pi, math.pi))
            pts = _interval_samples(vertices, pose, half_widths, rng)
            xmin, ymin, xmax, ymax = shadow_box(parts, pose, half_widths)
            assert np.all(pts[:, 0] >= xmin - 1e-9) and np.all(pts[:, 0] <= xmax + 1e-9)
            assert np.all(pts[:, 1] >= ymin - 1e-9) and np.all(pts[:, 1] <= ymax + 1e-9)
            hull = shadow_hull(parts, pose, half_widths)
            assert hull.is_valid and hull.equals(hull.convex_hull)
            assert np.max(shapely.distance(hull, shapely.points(pts))) <= 1e-9


@pytest.mark.parametrize("half_widths", HALF_WIDTHS, ids=str)
def test_shadow_box_is_tight_and_hull_is_close(half_widths):
    rng = np.random.default_rng(777)
    dx, dy, dt = half_widths
    for parts in _shapes_for_shadows():
        vertices = _vertices(parts)
        pose = (rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-math.pi, math.pi))
        # Dense sampling only (no critical angles): an independent estimate of the extremes.
        thetas = np.linspace(pose[2] - min(dt, math.pi), pose[2] + min(dt, math.pi), 100_001)
        c, s = np.cos(thetas)[:, None], np.sin(thetas)[:, None]
        wx = pose[0] + vertices[None, :, 0] * c - vertices[None, :, 1] * s
        wy = pose[1] + vertices[None, :, 0] * s + vertices[None, :, 1] * c
        dense = (wx.min() - dx, wy.min() - dy, wx.max() + dx, wy.max() + dy)
        box = shadow_box(parts, pose, half_widths)
        np.testing.assert_allclose(box, dense, atol=1e-6, rtol=0)
        # The hull over-approximates arcs by at most r (1 / cos(step / 2) - 1) <= ~0.1% of r.
        slack = shape_radius(parts) * (1 / math.cos(math.radians(5) / 2) - 1) + 1e-9
        hxmin, hymin, hxmax, hymax = box_of(shadow_hull(parts, pose, half_widths))
        assert hxmin >= box[0] - slack and hymin >= box[1] - slack
        assert hxmax <= box[2] + slack and hymax <= box[3] + slack


def test_naive_end_angle_box_misses_a_rotated_corner():
    """The thesis-style box (shape placed only at the interval's end angles) is not a shadow."""
    square = (box_polygon(1, 1),)
    pose, half_widths = (0.0, 0.0, math.radians(40)), (0.0, 0.0, math.radians(10))
    ends = [math.radians(30), math.radians(50)]
    naive = box_of(np.concatenate([transform_points(_vertices(square), (0, 0, a)) for a in ends]))
    # At theta = 45 degrees (inside the interval) a corner points straight up, at y = sqrt(1/2).
    at_45 = transform_points(_vertices(square), (0, 0, math.radians(45)))
    top = at_45[:, 1].max()
    assert top == pytest.approx(math.sqrt(0.5))
    assert top > naive[3] + 1e-3  # the naive box misses it
    ours = shadow_box(square, pose, half_widths)
    assert ours[3] == pytest.approx(math.sqrt(0.5), abs=1e-12)  # ours reaches exactly it
    assert box_contains(ours, box_of(at_45), tol=1e-12)
    assert shadow_hull(square, pose, half_widths).buffer(1e-12).covers(shapely.Polygon(at_45))


def test_shadow_box_special_cases():
    tee = _centred_parts(TEE)
    pose = (1.0, 2.0, 0.3)
    # No uncertainty: the footprint's bounding box.
    np.testing.assert_allclose(
        shadow_box(tee, pose, (0, 0, 0)), box_of(footprint(tee, pose)), atol=1e-12
    )
    # Full circle: the disc of the shape's radius.
    r = shape_radius(tee)
    np.testing.assert_allclose(
        shadow_box(tee, pose, (0.1, 0.2, math.pi)),
        (1 - r - 0.1, 2 - r - 0.2, 1 + r + 0.1, 2 + r + 0.2),
    )
    # Every accepted input form gives the same box (hull-reduced or not).
    hw = (0.1, 0.1, 0.4)
    expected = shadow_box(tee, pose, hw)
    lists = [[list(v) for v in part] for part in tee]
    for form in (shape_vertices(tee), _vertices(tee), lists):
        np.testing.assert_allclose(shadow_box(form, pose, hw), expected, atol=1e-12)
    assert isinstance(shape_vertices(tee), ShapeVertices)
    assert shape_vertices(tee) is shape_vertices(tee)  # cached
    with pytest.raises(ValueError):
        shadow_box(tee, pose, (0, -0.1, 0))
    with pytest.raises(ValueError):
        shadow_hull(tee, pose, (0, 0, 0), max_step=0)


# --------------------------------------------------------------------------------------------
# Boxes
# --------------------------------------------------------------------------------------------


def test_box_of():
    assert box_of([[0, 1], [2, -1], [1, 3]]) == (0.0, -1.0, 2.0, 3.0)
    assert box_of(shapely.Polygon([[0, 0], [2, 0], [2, 1]])) == (0.0, 0.0, 2.0, 1.0)
    assert box_of(decompose_convex(TEE)) == (0.0, 0.0, 3.0, 3.0)  # ragged parts
    assert box_of((box_polygon(2, 2), translate_polygon(box_polygon(2, 2), 5, 0))) == (
        -1.0,
        -1.0,
        6.0,
        1.0,
    )
    with pytest.raises(ValueError):
        box_of([])


def test_boxes_overlap_and_contain():
    a = (0.0, 0.0, 2.0, 2.0)
    assert boxes_overlap(a, (1.0, 1.0, 3.0, 3.0))
    assert not boxes_overlap(a, (2.0, 0.0, 4.0, 2.0))  # shared edge only
    assert not boxes_overlap(a, (2.0, 2.0, 4.0, 4.0))  # shared corner only
    assert not boxes_overlap(a, (5.0, 5.0, 6.0, 6.0))
    assert not boxes_overlap(a, (1.95, 0.0, 4.0, 2.0), tol=0.1)  # overlap 0.05 < tol
    assert boxes_overlap(a, (2.05, 0.0, 4.0, 2.0), tol=-0.1)  # negative tol: safety margin
    assert box_contains(a, (0.5, 0.5, 1.5, 1.5))
    assert box_contains(a, a)
    assert box_contains(a, (0.0, 0.0, 2.0 + 1e-12, 2.0))
    assert not box_contains(a, (0.5, 0.5, 2.5, 1.5))


def test_swept_box():
    b = (0.0, 0.0, 1.0, 2.0)
    assert swept_box(b, (1, 0), 3) == (0.0, 0.0, 4.0, 2.0)
    assert swept_box(b, (-1.0, 0.0), 3) == (-3.0, 0.0, 1.0, 2.0)
    assert swept_box(b, (0, 1), 0.5) == (0.0, 0.0, 1.0, 2.5)
    assert swept_box(b, (0, -1), 0.5) == (0.0, -0.5, 1.0, 2.0)
    assert swept_box(b, (1, 0), 0) == b
    with pytest.raises(ValueError):
        swept_box(b, (0.6, 0.8), 1)
    with pytest.raises(ValueError):
        swept_box(b, (1, 0), -1)


def test_wall_boxes():
    walls = wall_boxes((10.0, 6.0), ["left", "top"], thickness=0.5)
    assert list(walls) == ["left", "top"]
    assert walls["left"] == (-0.5, -0.5, 0.0, 6.5)
    assert walls["top"] == (-0.5, 6.0, 10.5, 6.5)
    all_walls = wall_boxes((10.0, 6.0), ["left", "right", "bottom", "top"])
    assert all_walls["right"] == (10.0, -1.0, 11.0, 7.0)
    assert all_walls["bottom"] == (-1.0, -1.0, 11.0, 0.0)
    table = (0.0, 0.0, 10.0, 6.0)
    for box in all_walls.values():
        assert not boxes_overlap(box, table)  # just outside, touching
    assert wall_boxes((10.0, 6.0), []) == {}
    with pytest.raises(ValueError, match="unknown wall"):
        wall_boxes((10.0, 6.0), ["front"])


def test_polygon_problem_refuses_more_vertices_than_the_cap() -> None:
    n = MAX_POLYGON_VERTICES + 1
    circle = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n)) for k in range(n)]
    assert polygon_problem(circle) == (
        f"has {n} vertices, more than the {MAX_POLYGON_VERTICES} vertices a polygon may have"
    )
    assert polygon_problem(circle[:-1]) is None


def test_self_intersection_found_across_chunks_of_a_big_polygon() -> None:
    # A 1000-vertex star whose vertex 10 is pulled across the outline to beyond vertex 510:
    # its edges cross edges some 500 apart, in another block of the chunked pair test.
    n = MAX_POLYGON_VERTICES
    star = [
        (
            (1.0 if k % 2 else 0.8) * math.cos(2 * math.pi * k / n),
            (1.0 if k % 2 else 0.8) * math.sin(2 * math.pi * k / n),
        )
        for k in range(n)
    ]
    assert polygon_problem(star) is None
    pulled = list(star)
    pulled[10] = (1.5 * star[510][0], 1.5 * star[510][1])
    assert polygon_problem(pulled) == "intersects itself"
    assert not shapely.Polygon(pulled).is_valid  # an independent opinion
