"""Tests of arrange_up.geometry.se2 (poses, rotations, transforms) and of the penetration depth
of convex polygons."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arrange_up.geometry.polygons import box_polygon, convex_penetration
from arrange_up.geometry.se2 import (
    compose,
    inverse,
    relative,
    rotate,
    rotate_cs,
    transform_point,
    transform_points,
)

RNG = np.random.default_rng(7)
POSES = [tuple(float(v) for v in RNG.uniform(-20, 20, 2)) + (float(RNG.uniform(-7, 7)),)
         for _ in range(200)]  # fmt: skip
POINTS = [tuple(float(v) for v in RNG.uniform(-5, 5, 2)) for _ in range(200)]


def test_compose_and_inverse_are_a_group():
    for a, b in zip(POSES, POSES[1:], strict=False):
        identity = compose(a, inverse(a))
        assert identity == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)
        back = relative(a, compose(a, b))
        assert back == pytest.approx(b, abs=1e-12)
        assert compose(inverse(a), b) == pytest.approx(relative(a, b), abs=1e-12)


def test_rotate_is_the_rotation_of_the_transforms():
    for pose, point in zip(POSES, POINTS, strict=True):
        x, y = transform_point(point, pose)
        rx, ry = rotate(point, pose[2])
        assert (x, y) == pytest.approx((pose[0] + rx, pose[1] + ry), abs=1e-12)


def test_scalar_and_vectorised_transforms_agree_to_rounding():
    points = np.array(POINTS)
    for pose in POSES[:20]:
        many = transform_points(points, pose)
        one = np.array([transform_point(p, pose) for p in POINTS])
        assert np.allclose(many, one, rtol=0.0, atol=1e-12)


def test_the_operation_orders_are_those_the_replaced_code_used():
    # Bit for bit: the scalar helpers add the translation first, transform_points last.
    for (xr, yr, tr), (x, y, t) in zip(POSES, POSES[1:], strict=False):
        c, s = math.cos(tr), math.sin(tr)
        assert compose((xr, yr, tr), (x, y, t)) == (xr + c * x - s * y, yr + s * x + c * y, tr + t)
        dx, dy = x - xr, y - yr
        assert relative((xr, yr, tr), (x, y, t))[:2] == (c * dx + s * dy, -s * dx + c * dy)
        assert rotate((x, y), tr) == (x * c - y * s, x * s + y * c)
    part = np.array(POINTS[:8])
    for x, y, theta in POSES[:20]:
        c, s = math.cos(theta), math.sin(theta)
        want = np.empty_like(part)
        want[:, 0] = part[:, 0] * c - part[:, 1] * s + x
        want[:, 1] = part[:, 0] * s + part[:, 1] * c + y
        assert np.array_equal(transform_points(part, (x, y, theta)), want)


def test_quarter_turns_with_integer_cosines_are_exact():
    assert rotate_cs((2.5, -1.25), 0, 1) == (1.25, 2.5)
    assert rotate_cs((2.5, -1.25), -1, 0) == (-2.5, 1.25)
    # rotating by -alpha with (c, -s) is exactly the transposed product
    for x, y in POINTS:
        for c, s in ((1, 0), (0, 1), (-1, 0), (0, -1)):
            assert rotate_cs((x, y), c, -s) == (c * x + s * y, -s * x + c * y)


def test_convex_penetration_depth():
    square = np.array(box_polygon(1.0, 1.0))
    assert convex_penetration(square, square + (0.75, 0.0)) == pytest.approx(0.25)
    assert convex_penetration(square, square + (0.2, 0.9)) == pytest.approx(0.1)
    assert convex_penetration(square, square + (1.0, 0.0)) == 0.0  # touching is apart
    assert convex_penetration(square, square + (3.0, 3.0)) == 0.0
    turned = transform_points(square, (0.0, 0.0, math.pi / 4))
    # the turned square's corner reaches sqrt(2)/2 along +x
    depth = convex_penetration(turned, square + (1.0, 0.0))
    assert depth == pytest.approx(math.sqrt(0.5) - 0.5)
